#!/usr/bin/python3
"""The benchmarks' DEM: an N x N spectral fractal GeoTIFF (bench/*.sh).

Usage: fractal_tif.py N PATH [BETA [CELL [RELIEF]]]
       (EPSG:32617, Float32, seed 42; CELL metres, default 10; heights
       100 .. 100 + RELIEF metres, default 1400)

The amplitude spectrum falls as f^-BETA (default 1.1, the driver benchmarks'
DEM: a rough surface, mean neighbour difference 39 m at 4096, median
horizon above 60 degrees); BETA = 1.8 is fBm of Hurst exponent 0.8 (power
f^-(2H + 2)), the character of bench/ts_bench's tdem_fbm and of real relief.
"""
import sys


def usage():
    sys.stderr.write("usage: fractal_tif.py N PATH [BETA [CELL [RELIEF]]]\n")
    sys.exit(2)


if len(sys.argv) < 3 or len(sys.argv) > 6:
    usage()
try:
    n, path = int(sys.argv[1]), sys.argv[2]
    beta = float(sys.argv[3]) if len(sys.argv) > 3 else 1.1
    cell = float(sys.argv[4]) if len(sys.argv) > 4 else 10.0
    relief = float(sys.argv[5]) if len(sys.argv) > 5 else 1400.0
except ValueError:
    usage()
import numpy as np
from osgeo import gdal, osr
if n < 2 or not cell > 0 or not relief > 0:
    sys.exit("fractal_tif.py: N must be >= 2, CELL and RELIEF > 0")
rng = np.random.default_rng(42)
f = np.hypot(np.fft.fftfreq(n)[None, :], np.fft.fftfreq(n)[:, None])
f[0, 0] = 1
spec = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))) / f ** beta
spec[0, 0] = 0
z = np.fft.ifft2(spec).real
z = (100 + relief * (z - z.min()) / (z.max() - z.min())).astype(np.float32)
ds = gdal.GetDriverByName("GTiff").Create(path, n, n, 1, gdal.GDT_Float32,
                                          ["TILED=YES"])
ds.SetGeoTransform((500000.0, cell, 0.0, 4000000.0, 0.0, -cell))
srs = osr.SpatialReference()
srs.ImportFromEPSG(32617)
ds.SetProjection(srs.ExportToWkt())
ds.GetRasterBand(1).WriteArray(z)
ds = None
