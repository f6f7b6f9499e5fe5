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
        """A float DEM with NaN, +inf and -inf and no declared nodata: those
        cells are nodata (the whole DEM and windows)."""
        with T.TempDir() as tmp:
            z = T.fractal_dem(160)
            z[10:20, 30:40] = np.nan
            z[40, 5] = np.inf
            z[70:72, 60:63] = -np.inf
            dem = T.write_tif(os.path.join(tmp, "nan.tif"), z, GT, 32617)
            for tile in (0, 64):
                out = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8, TILE_SIZE=tile), 1)
                np.testing.assert_array_equal(np.isnan(out), ~np.isfinite(z))

    def test_every_real_type_with_its_extreme_as_nodata(self):
        """A DEM of each real GDAL type whose void holds the type's extreme,
        declared as nodata: the same svf as the Float32 DEM of the same
        heights with NaN in the void; an overview level the product of the
        DEM as gdal_translate -ot Float32 -r average -outsize writes it; and
        no warning but GDAL's own (the driver asked an Int64/UInt64 band for
        its nodata as a double, and GDAL warned that it is approximate)."""
        z = np.round(T.fractal_dem(300, seed=5, relief=200.0)) - 80  # 20 .. 220 m
        void = np.zeros(z.shape, bool)
        void[40:90, 100:180] = True
        types = [(gdal.GDT_Byte, 255), (gdal.GDT_UInt16, 65535), (gdal.GDT_Int16, -32768),
                 (gdal.GDT_UInt32, 4294967295), (gdal.GDT_Int32, -2147483648),
                 (gdal.GDT_Int64, -2 ** 63), (gdal.GDT_UInt64, 2 ** 64 - 1),
                 (gdal.GDT_Float32, -3.4028234663852886e38),
                 (gdal.GDT_Float64, -1.7976931348623157e308)]
        svf = {"PRODUCT": "svf", "DIRECTIONS": 8}
        with T.TempDir() as tmp:
            ref = z.astype(np.float32)
            ref[void] = np.nan
            ref_dem = T.write_tif(os.path.join(tmp, "ref.tif"), ref, GT, 32617)
            want = T.read(T.translate(ref_dem, os.path.join(tmp, "ref_svf.tif"), svf), 1)
            srs = gdal.Open(ref_dem).GetProjection()
            for dtype, nodata in types:
                name = gdal.GetDataTypeName(dtype)
                with self.subTest(dtype=name):
                    a = z.astype({"Int64": np.int64, "UInt64": np.uint64}.get(name, np.float64))
                    a[void] = nodata
                    dem = os.path.join(tmp, name + ".tif")
                    ds = gdal.GetDriverByName("GTiff").Create(dem, 300, 300, 1, dtype)
                    ds.SetGeoTransform(GT)
                    ds.SetProjection(srs)
                    rb = ds.GetRasterBand(1)
                    {"Int64": rb.SetNoDataValueAsInt64,
                     "UInt64": rb.SetNoDataValueAsUInt64}.get(name, rb.SetNoDataValue)(nodata)
                    rb.WriteArray(a)
                    ds = rb = None
                    coarse = os.path.join(tmp, name + "_150.tif")
                    # (GDAL 3.6's gdal_translate drops a 64-bit integer nodata there)
                    keep = (["-a_nodata", repr(float(np.float32(nodata)))]
                            if "Int64" in name else [])
                    # GDAL's own warnings on that read (its resampling asks an
                    # Int64/UInt64 band for its nodata as a double), not the driver's
                    gdal_warnings = T.run(["gdal_translate", "-q", "-ot", "Float32", "-r",
                                           "average", "-outsize", "150", "150"] + keep
                                          + [dem, coarse]).stderr.count("Warning")
                    want_ovr = T.read(T.translate(coarse, os.path.join(tmp, name + "_c.tif"),
                                                  svf), 1)
                    for extra, expected, warnings in (
                            ([], want, 0), (["-outsize", "150", "150"], want_ovr, gdal_warnings)):
                        out = os.path.join(tmp, name + "_svf.tif")
                        p = T.run(["gdal_translate", "-q"] + T.oo_args(svf) + extra
                                  + [T.conn(dem), out])
                        self.assertLessEqual(p.stderr.count("Warning"), warnings, p.stderr)
                        np.testing.assert_array_equal(T.read(out, 1), expected)

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
