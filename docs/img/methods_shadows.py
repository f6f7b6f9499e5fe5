#!/usr/bin/python3
"""Draws methods_shadows.png (docs/methods.md): the shade of samples/jacksboro.tif
through the driver with every shadow method side by side (exact, shm, shadowmap,
sh, sh with pyramid horizons), at a low sun (135/10) and a higher one (315/30).

    BUILDDIR=. /usr/bin/python3 docs/img/methods_shadows.py   # writes beside itself

The plugin comes from $BUILDDIR/plugin/.libs (default: the current
directory). Needs numpy and PIL.
"""
import os

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from plugin_env import HERE, JACKSBORO as DEM, gdal, grey

METHODS = [("exact", {}), ("shm", {"METHOD": "shm"}), ("shadowmap", {"METHOD": "shadowmap"}),
           ("sh", {"METHOD": "sh"}),
           ("sh, pyramid horizons", {"METHOD": "sh", "HORIZON_METHOD": "pyramid"})]
SUNS = [(135, 10), (315, 30)]


def shade(sun, opts):
    oo = ["OUTPUT_TYPE=Float32", "SUN_AZIMUTH=%d" % sun[0], "SUN_ELEVATION=%d" % sun[1]]
    oo += ["%s=%s" % kv for kv in opts.items()]
    ds = gdal.OpenEx("TERRASHADE:" + DEM, gdal.OF_RASTER, open_options=oo)
    a = ds.GetRasterBand(1).ReadAsArray().astype(np.float64)
    ds = None
    return a



def main():
    rows = [[(label, shade(sun, opts)) for label, opts in METHODS] for sun in SUNS]
    h, w = rows[0][0][1].shape
    pad, top = 6, 18
    img = Image.new("L", (len(METHODS) * (w + pad) + pad, len(SUNS) * (h + top + pad) + pad),
                    255)
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default()
    for r, (sun, row) in enumerate(zip(SUNS, rows)):
        y = pad + r * (h + top + pad)
        for i, (label, a) in enumerate(row):
            x = pad + i * (w + pad)
            img.paste(grey(a), (x, y + top - 3))
            d.text((x, y), "%s, sun %d/%d" % (label, sun[0], sun[1]), fill=0, font=font)
    out = os.path.join(HERE, "methods_shadows.png")
    img.save(out, optimize=True)
    for sun, row in zip(SUNS, rows):
        exact = row[0][1]
        v = np.isfinite(exact)
        print("sun %d/%d: mean |shade - exact|: %s" % (sun + (", ".join(
            "%s %.4f" % (label, np.abs(a - exact)[v].mean()) for label, a in row[1:]),)))
    print("wrote " + out)


if __name__ == "__main__":
    main()
