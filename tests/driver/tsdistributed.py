"""Shared helpers of the terrashade.distributed tests (test_distributed*.py;
not a test itself): the package on sys.path, here and in the worker processes
that a test's own cluster spawns; the program's run; a DEM for each test
class, with gdal_translate's product of it to compare with, bit for bit.
"""
import glob
import os
import sys

import tsdriver as T
from tsdriver import gdal, np

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
PYTHONPATH = os.path.join(T.SRCDIR, "python")
sys.path.insert(0, PYTHONPATH)
HORIZON = {"PRODUCT": "horizon", "DIRECTIONS": 4}
SHADE = {"PRODUCT": "shade", "SUN_AZIMUTH": 300, "SUN_ELEVATION": 20}
# a day product computed by the driver window by window too (chunks of 64
# with their near field and the far grid): the windows still join bit for bit
SUNHOURS = {"PRODUCT": "sunhours", "DATE": "2024-12-21", "TIMEZONE": "-05:00",
            "STEP_MINUTES": 60, "TILE_SIZE": 64}


def distributed(args, ok=True, cwd=None, **env):
    return T.run(["/usr/bin/python3", "-m", "terrashade.distributed"] + list(args),
                 ok=ok, cwd=cwd, PYTHONPATH=PYTHONPATH, **env)


def partials(dest):
    """The partial files of runs writing DEST: DEST.<pid>.partial and
    DEST.<pid>.tiles.partial (and DEST.partial, their name until session 51)."""
    return glob.glob(glob.escape(dest) + ".*partial")


def bits(a):
    """The array's raw bits, so that NaN payloads and -0 compare too."""
    return a.view(np.uint8)


class DistributedCase(T.TempDirCase):
    """The tests' DEM (self.dem: 200 x 150, UTM, nodata) in a directory of
    their own (self.path), and what they check of the outputs."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        z = T.fractal_dem(200, seed=5)[:150]  # 200 x 150: windows of 64 are cut
        z[40:48, 100:130] = np.nan  # nodata in, nodata out
        cls.dem = T.write_tif(os.path.join(cls.dir, "dem.tif"), np.nan_to_num(z, nan=-9999),
                              UTM_GT, 32617, nodata=-9999)

    def path(self, name):
        return os.path.join(self.dir, name)

    def reference(self, options, name):
        return T.translate(self.dem, self.path(name), options)

    def assert_identical(self, got, want):
        a, b = gdal.Open(got), gdal.Open(want)
        self.assertEqual((a.RasterXSize, a.RasterYSize, a.RasterCount),
                         (b.RasterXSize, b.RasterYSize, b.RasterCount))
        self.assertEqual(a.GetGeoTransform(), b.GetGeoTransform())
        self.assertEqual(a.GetProjection(), b.GetProjection())
        self.assertEqual(a.GetMetadata(), b.GetMetadata())
        for i in range(1, a.RasterCount + 1):
            ba, bb = a.GetRasterBand(i), b.GetRasterBand(i)
            self.assertEqual(ba.DataType, bb.DataType)
            self.assertEqual(str(ba.GetNoDataValue()), str(bb.GetNoDataValue()))
            self.assertEqual(ba.GetDescription(), bb.GetDescription())
            self.assertEqual(ba.GetMetadata(), bb.GetMetadata())
            self.assertEqual(ba.GetUnitType(), bb.GetUnitType())
            xa, xb = ba.ReadAsArray(), bb.ReadAsArray()
            self.assertTrue(np.array_equal(bits(xa), bits(xb)),
                            "band %d differs in %d cells" % (i, np.sum(xa != xb)))
        print("%s: %d bands of %s, identical to gdal_translate" % (
            os.path.basename(got), a.RasterCount,
            gdal.GetDataTypeName(a.GetRasterBand(1).DataType)))

    def assert_nothing_left(self, dest):
        for p in [dest] + partials(dest):
            self.assertFalse(os.path.exists(p), "%s was left behind" % p)
