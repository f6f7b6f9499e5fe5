"""Nodata in, nodata out; degenerate DEMs do not crash."""
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

PRODUCTS = ["shade", "shadow", "horizon", "svf", "openness", "sky"]
GT = (600000, 30, 0, 4000000, 0, -30)


class Nodata(unittest.TestCase):
    def test_lux_elev_nodata_propagates(self):
        """lux_elev: -32768 around Luxembourg is the output's nodata."""
        dem_ds = gdal.Open(T.LUX)  # keep the dataset alive while using its band
        dem = dem_ds.GetRasterBand(1)
        self.assertEqual(dem.GetNoDataValue(), -32768)
        hole = dem.ReadAsArray() == -32768
        print("lux_elev: %d of %d cells are nodata" % (hole.sum(), hole.size))
        self.assertTrue(hole.any() and not hole.all())
        for p in PRODUCTS:
            with self.subTest(product=p):
                ds = gdal.OpenEx(T.conn(T.LUX), open_options=[
                    "PRODUCT=" + p, "DIRECTIONS=4", "SUN_ELEVATION=10"])
                for b in range(1, ds.RasterCount + 1):
                    rb = ds.GetRasterBand(b)
                    raw = rb.ReadAsArray()
                    if rb.DataType == gdal.GDT_Byte:
                        self.assertEqual(rb.GetNoDataValue(), 0)
                        np.testing.assert_array_equal(raw == 0, hole)
                    else:
                        self.assertTrue(np.isnan(rb.GetNoDataValue()))
                        np.testing.assert_array_equal(np.isnan(raw), hole)
                    # the mask GDAL derives from it agrees
                    np.testing.assert_array_equal(
                        rb.GetMaskBand().ReadAsArray() == 0, hole)

    def test_nodata_survives_gdal_translate(self):
        with T.TempDir() as tmp:
            out = T.translate(T.LUX, os.path.join(tmp, "s.tif"))
            ds = gdal.Open(out)
            self.assertEqual(ds.GetRasterBand(1).GetNoDataValue(), 0)
            out = T.translate(T.LUX, os.path.join(tmp, "v.tif"),
                              {"PRODUCT": "svf", "DIRECTIONS": 4})
            ds = gdal.Open(out)
            self.assertTrue(np.isnan(ds.GetRasterBand(1).GetNoDataValue()))

    def test_nan_heights_are_nodata(self):
        """A float DEM with NaN and no declared nodata."""
        with T.TempDir() as tmp:
            z = T.fractal_dem(64)
            z[10:20, 30:40] = np.nan
            dem = T.write_tif(os.path.join(tmp, "nan.tif"), z, GT, 32617)
            out = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8), 1)
            np.testing.assert_array_equal(np.isnan(out), np.isnan(z))

    def test_all_nodata(self):
        with T.TempDir() as tmp:
            dem = T.write_tif(os.path.join(tmp, "empty.tif"),
                              np.full((50, 70), -9999, np.float32), GT, 32617,
                              nodata=-9999)
            for p in PRODUCTS:
                with self.subTest(product=p):
                    out = T.translate(dem, os.path.join(tmp, p + ".tif"),
                                      {"PRODUCT": p, "DIRECTIONS": 4})
                    a = T.read(out)
                    self.assertTrue(np.isnan(a).all(), p)

    def test_tiny_dems(self):
        """1 x 1, 1 x N, N x 1 and 2 x 2 DEMs: every product, no crash."""
        with T.TempDir() as tmp:
            for shape in ((1, 1), (1, 7), (7, 1), (2, 2)):
                z = np.arange(np.prod(shape), dtype=np.float32).reshape(shape) * 10
                dem = T.write_tif(os.path.join(tmp, "tiny.tif"), z, GT, 32617)
                for p in PRODUCTS:
                    with self.subTest(shape=shape, product=p):
                        out = T.translate(dem, os.path.join(tmp, "o.tif"),
                                          {"PRODUCT": p, "DIRECTIONS": 4})
                        a = T.read(out)
                        self.assertEqual(a.shape[1:], shape)
                        self.assertFalse(np.isnan(a).any(), (shape, p))
            # a single flat cell under a 45 deg sun: N.L = sin 45
            one = T.write_tif(os.path.join(tmp, "one.tif"),
                              np.full((1, 1), 250, np.float32), GT, 32617)
            f = T.read(T.conn(one, OUTPUT_TYPE="Float32"), 1)
            self.assertAlmostEqual(f[0, 0], np.sin(np.radians(45)), 5)
            self.assertEqual(T.read(T.conn(one), 1)[0, 0], 181)  # 1 + 254 * 0.7071
            # a 1 x 1 geographic DEM
            geo = T.write_tif(os.path.join(tmp, "geo1.tif"),
                              np.full((1, 1), 250, np.float32),
                              (6.0, 0.001, 0, 49.6, 0, -0.001), 4326)
            self.assertAlmostEqual(T.read(T.conn(geo, OUTPUT_TYPE="Float32"), 1)[0, 0],
                                   np.sin(np.radians(45)), 5)


if __name__ == "__main__":
    unittest.main(verbosity=2)
