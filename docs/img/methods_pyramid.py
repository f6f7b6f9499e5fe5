#!/usr/bin/python3
"""Draws methods_pyramid.png (docs/methods.md): the sky-view factor of
samples/jacksboro.tif through the driver, exact and HORIZON_METHOD=pyramid
(PYRAMID_OFFSET 0 and 2), 32 directions, and |pyramid - exact| x 10.

    BUILDDIR=. /usr/bin/python3 docs/img/methods_pyramid.py   # writes beside itself

The plugin comes from $BUILDDIR/plugin/.libs (default: the current
directory). Needs numpy and PIL.
"""
import os

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from plugin_env import HERE, JACKSBORO as DEM, gdal, grey

BASE = {"PRODUCT": "svf", "DIRECTIONS": "32", "OUTPUT_TYPE": "Float32"}


def svf(**extra):
    oo = ["%s=%s" % kv for kv in dict(BASE, **extra).items()]
    ds = gdal.OpenEx("TERRASHADE:" + DEM, gdal.OF_RASTER, open_options=oo)
    return ds.GetRasterBand(1).ReadAsArray().astype(np.float64)



def main():
    exact = svf()
    p0 = svf(HORIZON_METHOD="pyramid")
    p2 = svf(HORIZON_METHOD="pyramid", PYRAMID_OFFSET="2")
    lo, hi = np.percentile(exact, 1), 1.0
    panels = [("exact (sweep)", grey(exact, lo, hi)),
              ("pyramid, PYRAMID_OFFSET=0", grey(p0, lo, hi)),
              ("pyramid, PYRAMID_OFFSET=2", grey(p2, lo, hi)),
              ("|offset 0 - exact| x 10", grey(10 * np.abs(p0 - exact), 0, 1))]
    w, h = exact.shape[1], exact.shape[0]
    pad, top = 6, 18
    img = Image.new("L", (len(panels) * (w + pad) + pad, h + top + pad), 255)
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default()
    for i, (label, panel) in enumerate(panels):
        x = pad + i * (w + pad)
        img.paste(panel, (x, top))
        d.text((x, 3), label, fill=0, font=font)
    out = os.path.join(HERE, "methods_pyramid.png")
    img.save(out, optimize=True)
    print("wrote %s; svf |pyramid - exact| median/p99: o=0 %.4f/%.4f, o=2 %.4f/%.4f" % (
        out, np.median(np.abs(p0 - exact)), np.percentile(np.abs(p0 - exact), 99),
        np.median(np.abs(p2 - exact)), np.percentile(np.abs(p2 - exact), 99)))


if __name__ == "__main__":
    main()
