#!/usr/bin/python3
"""Convert the test DEMs (GeoTIFF) into the raw format the C tests read, so
that the core's tests never link GDAL. Run once from any directory:

    /usr/bin/python3 tests/data/make_raw.py

For each NAME.tif it writes
  NAME.f32  width*height little-endian float32 heights in metres, row 0 =
            north, NaN where the GeoTIFF has nodata;
  NAME.hdr  text: `key value` lines, then `cell_x_row` followed by one
            east-west cell size (metres) per row, row 0 first.

Cell sizes are geodesic lengths on WGS84 (no pyproj): along a parallel at
latitude phi, dlon radians span a*cos(phi)/sqrt(1-e2 sin^2 phi) * dlon; the
north-south size is the meridian arc a(1-e2)/(1-e2 sin^2 phi)^1.5 * dlat at
the latitude of the centre row, used as the constant cell_y.
"""
import math
import os
import sys

import numpy as np
from osgeo import gdal

A = 6378137.0
F = 1.0 / 298.257223563
E2 = F * (2.0 - F)

DEMS = ["jacksboro", "lux_elev"]


def parallel_length(lat_deg, dlon_deg):
    phi = math.radians(lat_deg)
    s = math.sin(phi)
    return A * math.cos(phi) / math.sqrt(1.0 - E2 * s * s) * math.radians(dlon_deg)


def meridian_length(lat_deg, dlat_deg):
    s = math.sin(math.radians(lat_deg))
    return A * (1.0 - E2) / (1.0 - E2 * s * s) ** 1.5 * math.radians(dlat_deg)


def convert(directory, name):
    ds = gdal.Open(os.path.join(directory, name + ".tif"))
    if ds is None:
        sys.exit("cannot open %s.tif" % name)
    gt = ds.GetGeoTransform()
    if gt[2] != 0 or gt[4] != 0 or gt[5] >= 0:
        sys.exit("%s: only north-up grids are supported" % name)
    band = ds.GetRasterBand(1)
    z = band.ReadAsArray().astype(np.float32)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        z[band.ReadAsArray() == nodata] = np.nan
    h, w = z.shape
    dlon, dlat = gt[1], -gt[5]
    lon0 = gt[0] + 0.5 * dlon          # centre of column 0
    lat0 = gt[3] - 0.5 * dlat          # centre of row 0 (north edge)
    lat_mid = lat0 - 0.5 * (h - 1) * dlat
    cell_y = meridian_length(lat_mid, dlat)
    cell_x_row = [parallel_length(lat0 - y * dlat, dlon) for y in range(h)]

    z.astype("<f4").tofile(os.path.join(directory, name + ".f32"))
    with open(os.path.join(directory, name + ".hdr"), "w") as f:
        f.write("# terrashade test DEM %s, written by make_raw.py from %s.tif\n"
                % (name, name))
        f.write("width %d\nheight %d\n" % (w, h))
        f.write("lon0 %.12f\nlat0 %.12f\n" % (lon0, lat0))
        f.write("dlon_deg %.15g\ndlat_deg %.15g\n" % (dlon, dlat))
        f.write("cell_y %.9f\n" % cell_y)
        f.write("cell_x_row\n")
        for c in cell_x_row:
            f.write("%.9f\n" % c)
    valid = z[np.isfinite(z)]
    print("%s: %d x %d, %.0f..%.0f m, %d nodata, cell_x %.3f..%.3f m, cell_y %.3f m"
          % (name, w, h, valid.min(), valid.max(), z.size - valid.size,
             min(cell_x_row), max(cell_x_row), cell_y))


def main():
    directory = os.path.dirname(os.path.abspath(__file__))
    for name in DEMS:
        convert(directory, name)


if __name__ == "__main__":
    main()
