"""Every product: bands, data types, nodata, descriptions, metadata, ranges.

Also: the default shade is gdaldem hillshade's (same defaults, same Horn
normals, same 1..255 scaling) wherever the sun is not hidden by terrain.
"""
import math
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

RANGES = {  # product: (data type, min, max) of valid cells
    "shade": (gdal.GDT_Byte, 1, 255),
    "shadow": (gdal.GDT_Float32, 0, 1),
    "svf": (gdal.GDT_Float32, 0, 1),
    "sky": (gdal.GDT_Float32, 0, 1),
    "openness": (gdal.GDT_Float32, 0, 180),
    "horizon": (gdal.GDT_Float32, -90, 90),
}


class Products(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.utm = T.jacksboro_utm(cls.dir)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def test_every_product(self):
        for product, (dtype, lo, hi) in RANGES.items():
            with self.subTest(product=product):
                ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
                    "PRODUCT=" + product, "DIRECTIONS=8", "SUN_ELEVATION=15"])
                bands = 8 if product == "horizon" else 1
                self.assertEqual(ds.RasterCount, bands)
                self.assertEqual(ds.GetMetadataItem("PRODUCT"), product)
                for b in range(1, bands + 1):
                    rb = ds.GetRasterBand(b)
                    self.assertEqual(rb.DataType, dtype)
                    self.assertEqual(rb.GetBlockSize(), [256, 256])
                    nd = rb.GetNoDataValue()
                    if dtype == gdal.GDT_Byte:
                        self.assertEqual(nd, 0)
                    else:
                        self.assertTrue(np.isnan(nd))
                    a = rb.ReadAsArray().astype(float)
                    valid = a[a != 0] if dtype == gdal.GDT_Byte else a[~np.isnan(a)]
                    self.assertEqual(valid.size, a.size, "jacksboro has no nodata")
                    print("%-8s band %d: %.4g .. %.4g" % (product, b, valid.min(),
                                                         valid.max()))
                    self.assertGreaterEqual(valid.min(), lo)
                    self.assertLessEqual(valid.max(), hi)
                    self.assertGreater(valid.max() - valid.min(), 0,
                                       "a constant product")

    def test_horizon_bands_name_their_azimuth(self):
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=horizon", "DIRECTIONS=16", "START_AZIMUTH=0"])
        self.assertEqual(ds.RasterCount, 16)
        for b in range(1, 17):
            rb = ds.GetRasterBand(b)
            az = (b - 1) * 22.5
            self.assertEqual(rb.GetDescription(), "azimuth %g" % az)
            self.assertEqual(float(rb.GetMetadataItem("AZIMUTH")), az)
            self.assertEqual(rb.GetUnitType(), "degree")
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=horizon", "DIRECTIONS=3", "START_AZIMUTH=350"])
        self.assertEqual([ds.GetRasterBand(b).GetMetadataItem("AZIMUTH")
                          for b in (1, 2, 3)], ["350", "110", "230"])

    def test_horizon_band_description_survives_gdal_translate(self):
        out = T.translate(T.JACKSBORO, os.path.join(self.dir, "hz.tif"),
                          {"PRODUCT": "horizon", "DIRECTIONS": 4})
        ds = gdal.Open(out)
        self.assertEqual(ds.RasterCount, 4)
        self.assertEqual(ds.GetRasterBand(2).GetDescription(), "azimuth 90")

    def test_dataset_metadata(self):
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "SUN_AZIMUTH=200", "SUN_ELEVATION=30.5"])
        md = ds.GetMetadata()
        print(md)
        self.assertEqual(md["PRODUCT"], "shade")
        self.assertEqual(md["SUN_AZIMUTH"], "200")
        self.assertEqual(md["SUN_ELEVATION"], "30.5")
        self.assertEqual(md["METHOD"], "exact")
        self.assertEqual(md["OUTPUT_TYPE"], "Byte")
        self.assertEqual(md["SOURCE_DEM"], T.JACKSBORO)
        self.assertEqual(md["SOURCE_CRS_KIND"], "geographic")

    def test_output_types(self):
        for product, default in [("shade", gdal.GDT_Byte), ("shadow", gdal.GDT_Float32),
                                 ("svf", gdal.GDT_Float32), ("sky", gdal.GDT_Float32)]:
            for ot, dt in [("AUTO", default), ("Byte", gdal.GDT_Byte),
                           ("Float32", gdal.GDT_Float32)]:
                ds = gdal.OpenEx(T.conn(T.LUX), open_options=[
                    "PRODUCT=" + product, "OUTPUT_TYPE=" + ot, "DIRECTIONS=4"])
                self.assertEqual(ds.GetRasterBand(1).DataType, dt, (product, ot))

    def test_shade_matches_gdaldem_where_sunlit(self):
        """Default shade = gdaldem hillshade -compute_edges (315 deg, 45 deg)
        outside shadows, on every cell."""
        ours = T.read(T.conn(self.utm), 1)
        ref_path = os.path.join(self.dir, "gdaldem.tif")
        T.run(["gdaldem", "hillshade", "-q", "-compute_edges", self.utm, ref_path])
        ref = T.read(ref_path, 1)
        lit = T.read(self.utm, 1, None)
        shadow = T.read(T.conn(self.utm, PRODUCT="shadow"), 1)
        # every cell, the DEM's edges and the cells beside nodata too: the
        # edges as gdaldem's -compute_edges (until session 56 only the
        # interior agreed: a missing neighbour took the centre's height, and
        # edge cells were off by up to 43 grey levels)
        inner = ~np.isnan(lit)
        sunlit = inner & (shadow == 1)
        diff = np.abs(ours[sunlit] - ref[sunlit])
        edge = np.zeros_like(inner)
        edge[[0, -1], :] = edge[:, [0, -1]] = True
        print("sunlit cells: %d (%d on the edges), max |ours - gdaldem| = %g DN, "
              "cast-shadow cells: %d" % (sunlit.sum(), (sunlit & edge).sum(), diff.max(),
                                         (inner & (shadow < 1)).sum()))
        self.assertGreater((sunlit & edge).sum(), 20)
        self.assertGreater(sunlit.sum(), 0.9 * inner.sum())
        self.assertLessEqual(diff.max(), 1)
        # in cast shadow, ours is darker than gdaldem
        shaded = inner & (shadow == 0)
        self.assertTrue(np.all(ours[shaded] <= ref[shaded]))

    def test_edges_as_gdaldem_compute_edges(self):
        """The DEM's edge cells have the slope of what they lie on, as
        gdaldem's -compute_edges extrapolates the row or column beyond: a
        plane rising 30 degrees to the north, east, south or west, facing a
        sun 30 degrees up, is 221 at its edges as inside (cos 30 deg; its
        edges across the slope were 184 until session 56: a missing
        neighbour took the centre's height); and on a rough DEM with no
        nodata every sunlit cell, its edges and corners, within 1 grey level
        of gdaldem -compute_edges, at three suns."""
        n, cell = 40, 30.0
        rows, cols = np.mgrid[0:n, 0:n].astype(np.float64)
        rise = math.tan(math.radians(30)) * cell
        # (each faces the sun: it rises away from it; gdaldem's four corner
        # cells halve a slope along the first and last rows, ours too)
        corners = np.zeros((n, n), bool)
        corners[[0, 0, -1, -1], [0, -1, 0, -1]] = True
        for name, z, az in (("south", rows * rise, 0), ("north", (n - rows) * rise, 180),
                            ("west", (n - cols) * rise, 90), ("east", cols * rise, 270)):
            dem = T.write_tif(os.path.join(self.dir, "plane_%s.tif" % name),
                              (500 + z).astype(np.float32),
                              (500000.0, cell, 0, 4000000.0, 0, -cell), 32617)
            a = T.read(T.conn(dem, SUN_AZIMUTH=az, SUN_ELEVATION=30, EDGE="open",
                              CURVATURE="NO"), 1)
            self.assertTrue((a[~corners] == 221).all(), (name, np.unique(a[~corners])))
        z = T.fractal_dem(128, seed=5, relief=400.0)
        rough = T.write_tif(os.path.join(self.dir, "rough.tif"), z.astype(np.float32),
                            (500000.0, 20.0, 0, 4000000.0, 0, -20.0), 32617)
        for az, alt in ((315, 45), (135, 30), (60, 60)):
            ref_path = os.path.join(self.dir, "rough_gdaldem.tif")
            T.run(["gdaldem", "hillshade", "-q", "-compute_edges", "-az", str(az), "-alt",
                   str(alt), rough, ref_path])
            ref = T.read(ref_path, 1)
            ours = T.read(T.conn(rough, SUN_AZIMUTH=az, SUN_ELEVATION=alt), 1)
            lit = T.read(T.conn(rough, PRODUCT="shadow", SUN_AZIMUTH=az, SUN_ELEVATION=alt),
                         1) == 1
            edge = np.zeros_like(lit)
            edge[[0, -1], :] = edge[:, [0, -1]] = True
            diff = np.abs(ours[lit] - ref[lit])
            print("%d/%d: %d sunlit cells (%d on the edges), max |ours - gdaldem| %g DN"
                  % (az, alt, lit.sum(), (lit & edge).sum(), diff.max()))
            self.assertGreater((lit & edge).sum(), 300)
            self.assertLessEqual(diff.max(), 1)

    def test_low_sun_casts_shadows(self):
        """At 5 deg the ridges of jacksboro shade whole valleys; at 80 deg no
        cell is in shadow."""
        low = T.read(T.conn(T.JACKSBORO, PRODUCT="shadow", SUN_ELEVATION=5,
                            SUN_AZIMUTH=135), 1)
        high = T.read(T.conn(T.JACKSBORO, PRODUCT="shadow", SUN_ELEVATION=80), 1)
        f_low, f_high = np.mean(low < 0.5), np.mean(high < 0.5)
        print("shadowed fraction: %.3f at 5 deg, %.3f at 80 deg" % (f_low, f_high))
        self.assertGreater(f_low, 0.05)
        self.assertEqual(f_high, 0)
        # penumbra: partly visible sun disks exist at low sun
        self.assertTrue(np.any((low > 0) & (low < 1)))

    def test_sky_products_on_a_plane(self):
        """A horizontal plane: svf 1 and sky 1 everywhere; in the interior
        openness 90 and horizon 0; at the edges, looking out, the sea-level
        plane beyond (EDGE=horizon, CURVATURE=NO: the horizontal), or
        nothing (EDGE=open: -90)."""
        with T.TempDir() as tmp:
            flat = T.write_tif(os.path.join(tmp, "flat.tif"),
                               np.full((40, 50), 100, np.float32),
                               (500000, 10, 0, 4000000, 0, -10), 32617)
            svf = T.read(T.conn(flat, PRODUCT="svf", DIRECTIONS=8), 1)
            sky = T.read(T.conn(flat, PRODUCT="sky", DIRECTIONS=8), 1)
            opn = T.read(T.conn(flat, PRODUCT="openness", DIRECTIONS=8,
                                CURVATURE="NO"), 1)
            hz = T.read(T.conn(flat, PRODUCT="horizon", DIRECTIONS=4,
                               CURVATURE="NO"))
            np.testing.assert_allclose(svf, 1, atol=1e-5)
            np.testing.assert_allclose(sky, 1, atol=1e-5)
            np.testing.assert_allclose(opn[1:-1, 1:-1], 90, atol=1e-3)
            inner = hz[:, 1:-1, 1:-1]
            np.testing.assert_allclose(inner, 0, atol=1e-3)
            # the sea-level plane beyond the edge facing outwards: 0
            np.testing.assert_array_equal(hz[0, 0, :], 0)   # north, row 0
            hz = T.read(T.conn(flat, PRODUCT="horizon", DIRECTIONS=4,
                               CURVATURE="NO", EDGE="open"))
            np.testing.assert_array_equal(hz[0, 0, :], -90)  # nothing beyond


    def test_sky_terms_stay_in_range_on_near_vertical_cells(self):
        """Spikes of up to 3000 m on 1 m cells: the svf and sky sums of
        near-vertical cells are 0 but for float rounding, which once left
        them at -1.4e-8 (and insolation's diffuse below 0); 0..1 and
        >= 0 as documented."""
        with T.TempDir() as tmp:
            z = np.random.RandomState(0).rand(32, 32).astype(np.float32) * 3000
            dem = T.write_tif(os.path.join(tmp, "spikes.tif"), z,
                              (500000, 1, 0, 4000000, 0, -1), 32617)
            for opts in ({"PRODUCT": "svf"}, {"PRODUCT": "sky"},
                         {"PRODUCT": "svf", "TILE_SIZE": 64},
                         {"PRODUCT": "svf", "HORIZON_METHOD": "pyramid"},
                         {"PRODUCT": "insolation", "DATE": "2026-06-21",
                          "TIMEZONE": "Z", "STEP_MINUTES": 60}):
                with self.subTest(**opts):
                    a = T.read(T.conn(dem, **opts))
                    self.assertFalse(np.isnan(a).any())
                    self.assertGreaterEqual(a.min(), 0)
                    if opts["PRODUCT"] != "insolation":
                        self.assertLessEqual(a.max(), 1)

if __name__ == "__main__":
    unittest.main(verbosity=2)
