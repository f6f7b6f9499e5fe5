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

    def test_every_validity_the_dem_declares(self):
        """A nodata value beside a mask band, an alpha band beside a nodata
        value, and a Float32 or Int16 alpha band (gdalwarp -dstalpha), none
        of which GDAL's one mask combines: every invalid cell is nodata, as
        on the same DEM with NaN there (whole and windowed), and an
        overview level has no wall where the voids' zeros would stand."""
        z = T.fractal_dem(120, seed=3) + 500
        hole_nd, hole_m = np.zeros(z.shape, bool), np.zeros(z.shape, bool)
        hole_nd[20:30, 30:40] = True
        hole_m[70:80, 5:15] = True
        gdal.SetConfigOption("GDAL_TIFF_INTERNAL_MASK", "YES")
        try:
            with T.TempDir() as tmp:
                def dem(name, dtype, alpha_type=None, internal_mask=False):
                    """z with nodata 0 in hole_nd, and 1 in hole_m, which
                    the mask band or the alpha band marks."""
                    path = os.path.join(tmp, name)
                    bands = 2 if alpha_type else 1
                    ds = gdal.GetDriverByName("GTiff").Create(
                        path, z.shape[1], z.shape[0], bands, dtype)
                    ds.SetGeoTransform(GT)
                    ds.SetProjection(gdal.Open(ref).GetProjection())
                    rb = ds.GetRasterBand(1)
                    rb.WriteArray(np.where(hole_nd, 0, np.where(hole_m, 1, np.round(z))))
                    rb.SetNoDataValue(0)
                    if alpha_type:
                        ab = ds.GetRasterBand(2)
                        ab.SetColorInterpretation(gdal.GCI_AlphaBand)
                        ab.WriteArray(np.where(hole_m, 0, 255))
                    if internal_mask:
                        ds.CreateMaskBand(gdal.GMF_PER_DATASET)
                        rb.GetMaskBand().WriteArray(np.where(hole_m, 0, 255).astype(np.uint8))
                    ds = None
                    return path
                ref = T.write_tif(os.path.join(tmp, "ref.tif"),
                                  np.where(hole_nd | hole_m, np.nan, np.round(z)), GT, 32617)
                cases = {
                    "nodata and a mask band": dem("m.tif", gdal.GDT_Float32,
                                                  internal_mask=True),
                    "nodata and a Byte alpha": dem("a8.tif", gdal.GDT_Byte, gdal.GDT_Byte),
                    "nodata and a Float32 alpha": dem("af.tif", gdal.GDT_Float32,
                                                      gdal.GDT_Float32),
                    "nodata and an Int16 alpha": dem("ai.tif", gdal.GDT_Int16, gdal.GDT_Int16),
                }
                for name, path in cases.items():
                    if "Byte" in name:  # heights within a Byte: the reference too
                        zb = np.where(hole_nd | hole_m, np.nan, np.clip(np.round(z), 0, 255))
                        ref_p = T.write_tif(os.path.join(tmp, "ref8.tif"), zb, GT, 32617)
                    else:
                        ref_p = ref
                    for tile in (0, 64):
                        with self.subTest(case=name, tile=tile):
                            opts = dict(PRODUCT="svf", DIRECTIONS=8, TILE_SIZE=tile)
                            got = T.read(T.conn(path, **opts), 1)
                            want = T.read(T.conn(ref_p, **opts), 1)
                            np.testing.assert_array_equal(np.isnan(got), hole_nd | hole_m)
                            np.testing.assert_array_equal(got, want)
                # a warped DEM's alpha collar is nodata at every level, as
                # the same warp's NaN collar is
                big = T.write_tif(os.path.join(tmp, "big.tif"), T.fractal_dem(600) + 800,
                                  GT, 32617)
                alpha, nan = os.path.join(tmp, "alpha.tif"), os.path.join(tmp, "nan.tif")
                gdal.Warp(alpha, big, dstSRS="EPSG:32615", dstAlpha=True)
                gdal.Warp(nan, big, dstSRS="EPSG:32615", dstNodata=float("nan"))
                wds = gdal.Open(alpha)
                collar = wds.GetRasterBand(2).ReadAsArray() == 0
                self.assertTrue(collar.any())
                da = gdal.OpenEx(T.conn(alpha), open_options=["PRODUCT=svf", "DIRECTIONS=8"])
                dn = gdal.OpenEx(T.conn(nan), open_options=["PRODUCT=svf", "DIRECTIONS=8"])
                ra, rn = da.GetRasterBand(1), dn.GetRasterBand(1)
                np.testing.assert_array_equal(np.isnan(ra.ReadAsArray()), collar)
                self.assertGreater(ra.GetOverviewCount(), 0)
                for i in range(ra.GetOverviewCount()):
                    a, n = ra.GetOverview(i).ReadAsArray(), rn.GetOverview(i).ReadAsArray()
                    print("level %d: alpha %d NaN, NaN collar %d NaN, max |diff| %.3g" % (
                        i + 1, np.isnan(a).sum(), np.isnan(n).sum(), np.nanmax(abs(a - n))))
                    np.testing.assert_allclose(a, n, atol=1e-4)
        finally:
            gdal.SetConfigOption("GDAL_TIFF_INTERNAL_MASK", None)

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

    def test_voids_wider_than_max_distance_are_said(self):
        """A ray that meets no valid cell within MAX_DISTANCE has no horizon
        (-90): the cells along a nodata collar (gdalwarp's) or a lake left
        nodata, wider than the distance, read openness up to ~135-150
        degrees, unsaid until session 51. Now a warning names the void,
        whole and windowed, once; none without MAX_DISTANCE or where the
        voids are narrower than it."""
        z = T.fractal_dem(160, seed=5) + 400
        collar = z.copy()
        collar[:, :40] = np.nan          # 40 cells = 1200 m from the west edge
        lake = z.copy()
        lake[60:100, 70:110] = np.nan    # 40 x 40 cells inside
        with T.TempDir() as tmp:
            dems = {n: T.write_tif(os.path.join(tmp, n + ".tif"), a, GT, 32617)
                    for n, a in (("collar", collar), ("lake", lake))}
            said = {"collar": ("nodata along its edge (a collar", "1200 m across",
                               "EDGE=horizon does not raise them"),
                    "lake": ("nodata voids ", "m across")}
            for name, dem in dems.items():
                for window in ({}, {"TILE_SIZE": 64, "NEAR_DISTANCE": 900}):
                    with self.subTest(name=name, window=window):
                        err = T.translate_stderr(dem, PRODUCT="openness", MAX_DISTANCE=600,
                                                 DIRECTIONS=8, **window)
                        self.assertEqual(err.count("wider than MAX_DISTANCE=600 m"), 1, err)
                        for text in said[name]:
                            self.assertIn(text, err)
                        if not window:  # (a chunk may see part of the void)
                            self.assertIn("1200 m across" if name == "collar" else
                                          "1200 m across (row 60, cells 70 to 109)", err)
                        # the effect it warns of: open sky into the void
                        o = T.read(T.conn(dem, PRODUCT="openness", MAX_DISTANCE=600,
                                          DIRECTIONS=8, **window), 1)
                        self.assertGreater(np.nanmax(o), 120)
                        for quiet in (dict(MAX_DISTANCE=1500), {}):
                            err = T.translate_stderr(dem, PRODUCT="openness", DIRECTIONS=8,
                                                     **dict(window, **quiet))
                            self.assertNotIn("MAX_DISTANCE", err)


if __name__ == "__main__":
    unittest.main(verbosity=2)
