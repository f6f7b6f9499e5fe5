"""docs/img/shadowmap_vs_exact.png: jacksboro's shadow at sun 135/10, the
exact method and METHOD=shadowmap (PCF_KERNEL=auto) side by side, for the
sun's disk (top) and LIGHT_RADIUS=2 (bottom); white lit, black in shadow.

    GDAL_DRIVER_PATH=plugin/.libs /usr/bin/python3 samples/render_shadowmap.py [OUT.png]

Reads only jacksboro.tif beside this script.
"""
import os
import sys

import numpy as np
from osgeo import gdal

gdal.UseExceptions()
HERE = os.path.dirname(os.path.abspath(__file__))
DEM = os.path.join(HERE, "jacksboro.tif")
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "out", "shadowmap_vs_exact.png")
CROP = (slice(60, 220), slice(40, 240))  # rows, columns: ridges and valleys


def shadow(**options):
    oo = ["PRODUCT=shadow", "SUN_AZIMUTH=135", "SUN_ELEVATION=10", "OUTPUT_TYPE=Float32"]
    oo += ["%s=%s" % kv for kv in options.items()]
    ds = gdal.OpenEx("TERRASHADE:" + DEM, gdal.OF_RASTER, open_options=oo)
    return ds.GetRasterBand(1).ReadAsArray()[CROP]


panels = [[shadow(), shadow(METHOD="shadowmap")],
          [shadow(LIGHT_RADIUS=2), shadow(METHOD="shadowmap", LIGHT_RADIUS=2)]]
gap = 4
h, w = panels[0][0].shape
img = np.full((2 * h + gap, 2 * w + gap), 128, np.uint8)
for i in range(2):
    for j in range(2):
        a = np.nan_to_num(panels[i][j], nan=0.5)
        img[i * (h + gap):i * (h + gap) + h, j * (w + gap):j * (w + gap) + w] = \
            np.round(40 + 215 * a).astype(np.uint8)
os.makedirs(os.path.dirname(os.path.abspath(OUT)), exist_ok=True)
mem = gdal.GetDriverByName("MEM").Create("", img.shape[1], img.shape[0], 1, gdal.GDT_Byte)
mem.GetRasterBand(1).WriteArray(img)
gdal.GetDriverByName("PNG").CreateCopy(OUT, mem)
print("wrote", OUT)
