#!/usr/bin/python3
"""Draws cell_sizes.png (docs/driver.md, Georeferencing): samples/jacksboro.tif
warped to Web Mercator (EPSG:3857, whose scale is 1.24 at its 36.6 N) and its
cast shadows at a low sun (135/10, PRODUCT=shadow: the visible fraction of the
sun's disk) with CELL_SIZES=grid (the grid's "metres", as gdaldem takes them) and
auto (measured on the ground), beside the shadows of the DEM in degrees warped
the same way.

    BUILDDIR=. /usr/bin/python3 docs/img/cell_sizes.py   # writes beside itself

The plugin comes from $BUILDDIR/plugin/.libs (default: the current
directory). Needs numpy and PIL.
"""
import os
import tempfile

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from plugin_env import HERE, JACKSBORO as DEM, gdal, grey

SUN = ["PRODUCT=shadow", "SUN_AZIMUTH=135", "SUN_ELEVATION=10"]


def shadow(path, extra=()):
    ds = gdal.OpenEx("TERRASHADE:" + path, gdal.OF_RASTER, open_options=SUN + list(extra))
    a = ds.GetRasterBand(1).ReadAsArray().astype(np.float64)
    ds = None
    return a



def main():
    with tempfile.TemporaryDirectory() as tmp:
        merc = os.path.join(tmp, "merc.tif")
        gdal.Warp(merc, DEM, dstSRS="EPSG:3857")
        src = gdal.Open(merc)
        gt, w, h = src.GetGeoTransform(), src.RasterXSize, src.RasterYSize
        src = None
        geo = os.path.join(tmp, "geo.tif")
        ds = gdal.OpenEx("TERRASHADE:" + DEM, gdal.OF_RASTER, open_options=SUN)
        gdal.Translate(geo, ds)
        ds = None
        back = os.path.join(tmp, "geo_3857.tif")
        gdal.Warp(back, geo, dstSRS="EPSG:3857", outputBounds=(gt[0], gt[3] + h * gt[5],
                  gt[0] + w * gt[1], gt[3]), xRes=gt[1], yRes=-gt[5], resampleAlg="near")
        panels = [("in degrees (reference)", gdal.Open(back).ReadAsArray().astype(np.float64)),
                  ("Web Mercator, CELL_SIZES=grid", shadow(merc, ["CELL_SIZES=grid"])),
                  ("Web Mercator, CELL_SIZES=auto", shadow(merc))]
    pad, top = 6, 18
    img = Image.new("L", (len(panels) * (w + pad) + pad, h + top + 2 * pad), 255)
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default()
    ref = panels[0][1]
    for i, (label, a) in enumerate(panels):
        x = pad + i * (w + pad)
        img.paste(grey(a), (x, pad + top - 3))
        v = np.isfinite(a) & np.isfinite(ref)
        d.text((x, pad), "%s: %.1f %% shadowed" % (label, 100 * np.mean(a[v] < 0.5)),
               fill=0, font=font)
        print("%s: %.2f %% of cells in shadow (visible fraction < 0.5)" % (label, 100 * np.mean(a[v] < 0.5)))
    out = os.path.join(HERE, "cell_sizes.png")
    img.save(out, optimize=True)
    print("wrote " + out)


if __name__ == "__main__":
    main()
