"""Every option does what it says; inline options equal open options."""
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)


def product(dem, **options):
    return T.read(T.conn(dem), options={k: v for k, v in options.items()})


class Options(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.z = T.fractal_dem(200, seed=7)
        cls.dem = T.write_tif(os.path.join(cls.dir, "fractal.tif"), cls.z,
                              UTM_GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def differs(self, a, b):
        self.assertFalse(np.array_equal(a, b, equal_nan=True))

    def test_inline_equals_open_options(self):
        combos = [
            {},
            {"PRODUCT": "shadow", "SUN_ELEVATION": 10, "SUN_AZIMUTH": 100},
            {"PRODUCT": "svf", "DIRECTIONS": 8, "MAX_DISTANCE": 500},
            {"PRODUCT": "horizon", "DIRECTIONS": 3, "START_AZIMUTH": 45},
            {"PRODUCT": "shade", "METHOD": "shm", "PENUMBRA_DEPTH": 5,
             "Z_FACTOR": 2, "OUTPUT_TYPE": "Float32", "CURVATURE": "NO"},
        ]
        with T.TempDir() as tmp:
            for c in combos:
                with self.subTest(**c):
                    a = T.translate(self.dem, os.path.join(tmp, "a.tif"), options=c)
                    b = T.translate(self.dem, os.path.join(tmp, "b.tif"), inline=c)
                    np.testing.assert_array_equal(T.read(a), T.read(b))
                    # and through the Python API
                    np.testing.assert_array_equal(
                        T.read(T.conn(self.dem, **c)), T.read(a))
            # half inline, half open options; keys are case-insensitive
            a = T.read(T.conn(self.dem, product="shadow", sun_elevation=10),
                       options={"Sun_Azimuth": 100})
            b = T.read(T.conn(self.dem), options={
                "PRODUCT": "shadow", "SUN_ELEVATION": 10, "SUN_AZIMUTH": 100})
            np.testing.assert_array_equal(a, b)

    def test_same_option_twice_with_same_value_is_fine(self):
        a = T.read(T.conn(self.dem, SUN_AZIMUTH=100), options={"SUN_AZIMUTH": 100})
        np.testing.assert_array_equal(a, product(self.dem, SUN_AZIMUTH=100))

    def test_sun_azimuth_and_elevation(self):
        base = product(self.dem, PRODUCT="shadow", SUN_ELEVATION=10)
        self.differs(base, product(self.dem, PRODUCT="shadow", SUN_ELEVATION=10,
                                   SUN_AZIMUTH=90))
        # 0 and 360 are the same direction
        np.testing.assert_array_equal(
            product(self.dem, PRODUCT="shadow", SUN_ELEVATION=10, SUN_AZIMUTH=0),
            product(self.dem, PRODUCT="shadow", SUN_ELEVATION=10, SUN_AZIMUTH=360))
        # -0 is 0, in the metadata too (it said SUN_AZIMUTH=-0: session 57's
        # audit), and so in the statistics' entry beside the DEM
        ds = gdal.OpenEx(T.conn(self.dem), gdal.OF_RASTER, open_options=["SUN_AZIMUTH=-0.0"])
        self.assertEqual(ds.GetMetadataItem("SUN_AZIMUTH"), "0")
        ds = None
        lower = product(self.dem, PRODUCT="shadow", SUN_ELEVATION=3)
        self.assertLess(np.nanmean(lower), np.nanmean(base))
        # sun below the horizontal, with an open sky beyond the edge
        # (EDGE=open): only cells whose horizon is lower still (overlooking
        # a valley, or the DEM's edge) see it
        night = product(self.dem, PRODUCT="shade", SUN_ELEVATION=-10,
                        OUTPUT_TYPE="Float32", EDGE="open")[0]
        hz = product(self.dem, PRODUCT="horizon", DIRECTIONS=1,
                     START_AZIMUTH=315, EDGE="open")[0]
        self.assertTrue(np.all(hz[night > 0] < -10 + 0.2667))
        self.assertLess(np.mean(night > 0), 0.2)
        self.assertTrue(np.any(night > 0))
        # with the Earth beyond the edge (the default) it lights nothing
        night = product(self.dem, PRODUCT="shade", SUN_ELEVATION=-10,
                        OUTPUT_TYPE="Float32")[0]
        self.assertFalse(np.any(night > 0))

    def test_directions_and_start_azimuth(self):
        hz = product(self.dem, PRODUCT="horizon", DIRECTIONS=4)
        hz8 = product(self.dem, PRODUCT="horizon", DIRECTIONS=8)
        self.assertEqual(hz.shape[0], 4)
        np.testing.assert_array_equal(hz8[::2], hz)  # 0,90,180,270 in both
        shifted = product(self.dem, PRODUCT="horizon", DIRECTIONS=4,
                          START_AZIMUTH=90)
        np.testing.assert_array_equal(shifted, np.roll(hz, -1, axis=0))
        svf4 = product(self.dem, PRODUCT="svf", DIRECTIONS=4)
        svf32 = product(self.dem, PRODUCT="svf", DIRECTIONS=32)
        self.differs(svf4, svf32)

    def test_method_and_penumbra_depth(self):
        exact = product(self.dem, PRODUCT="shadow", SUN_ELEVATION=15)
        shm = product(self.dem, PRODUCT="shadow", SUN_ELEVATION=15, METHOD="shm")
        agree = np.mean((exact >= 0.5) == (shm >= 0.5))
        print("exact and shm agree on lit/shadowed for %.1f%% of cells" % (100 * agree))
        self.assertGreater(agree, 0.9)
        self.assertTrue(set(np.unique(shm)) <= {0.0, 1.0}, "hard SHM shadows")
        soft = product(self.dem, PRODUCT="shadow", SUN_ELEVATION=15, METHOD="shm",
                       PENUMBRA_DEPTH=20)
        self.assertTrue(np.any((soft > 0) & (soft < 1)), "no soft edges")

    def test_z_factor_scales_heights(self):
        """Z_FACTOR=2 on the DEM = the DEM with heights doubled."""
        double = T.write_tif(os.path.join(self.dir, "double.tif"), self.z * 2,
                             UTM_GT, 32617)
        for p in ("shade", "shadow", "horizon"):
            a = product(self.dem, PRODUCT=p, Z_FACTOR=2, DIRECTIONS=4,
                        SUN_ELEVATION=20)
            b = product(double, PRODUCT=p, DIRECTIONS=4, SUN_ELEVATION=20)
            np.testing.assert_array_equal(a, b)
        self.differs(product(self.dem), product(self.dem, Z_FACTOR=2))

    def test_max_distance(self):
        """A bounded search sees less terrain: horizons never rise."""
        full = product(self.dem, PRODUCT="horizon", DIRECTIONS=4)
        near = product(self.dem, PRODUCT="horizon", DIRECTIONS=4, MAX_DISTANCE=300)
        self.assertTrue(np.all(near <= full + 1e-4))
        self.assertTrue(np.any(near < full - 0.5))

    def test_max_distance_shorter_than_a_cell_warns(self):
        """MAX_DISTANCE=10 on 30 m cells (10 cells meant, as RVT's radius is in
        pixels?) holds no other cell: a warning that says so and what 10 cells
        are; none at 30 m and beyond, nor for a product without it. (Until
        session 49 it said that nothing casts a shadow there, where the
        cell's own slope still does.)"""
        def warned(**oo):
            err = T.open_stderr(self.dem, **oo)
            return "MAX_DISTANCE" in err and err
        err = warned(PRODUCT="svf", MAX_DISTANCE=10)
        print(err.strip())
        self.assertIn("Warning 1: TERRASHADE: MAX_DISTANCE=10 m is shorter than the DEM's "
                      "cells (30 m): no other cell lies within it, so only the slope of a "
                      "cell's own surface there casts a shadow or raises a horizon. It is in "
                      "metres: 10 cells are 300 m", err)
        self.assertTrue(warned(PRODUCT="shadow", MAX_DISTANCE=10))
        self.assertFalse(warned(PRODUCT="svf", MAX_DISTANCE=30))
        self.assertFalse(warned(PRODUCT="svf"))

    def test_options_a_product_does_not_use_warn(self):
        """An option that does nothing for the product (SUN_AZIMUTH for svf,
        TILE_SIZE for farshadow: eleven were silent for svf alone) opens with
        one warning that names each and the products that use it; the
        options a product uses, and those of every product, say nothing."""
        err = T.open_stderr(self.dem, PRODUCT="svf", SUN_AZIMUTH=100, STEP_MINUTES=10)
        self.assertIn("Warning 1: TERRASHADE: PRODUCT=svf does not use SUN_AZIMUTH (an "
                      "option of shade, shadow and envlight), STEP_MINUTES (an option of "
                      "sunhours, insolation and daycycle): given, they do nothing here", err)
        self.assertEqual(err.count("does not use"), 1)
        err = T.open_stderr(self.dem, PRODUCT="farshadow", DATE="2026-06-21", TIMEZONE="Z",
                            TILE_SIZE=128)
        self.assertIn("PRODUCT=farshadow does not use TILE_SIZE (an option of shade, ", err)
        self.assertIn("given, it does nothing here", err)
        # options of the product that its other options leave without work
        err = T.open_stderr(self.dem, PRODUCT="shade", PRESSURE=900, DIRECTIONS=32)
        self.assertIn("PRODUCT=shade does not use DIRECTIONS (of the sky term, which "
                      "SKY_WEIGHT=0 leaves out), PRESSURE (it refracts and places a sun "
                      "computed from DATETIME): given, they do nothing here", err)
        # envlight under a sky without a sun: its options of the sun
        err = T.open_stderr(self.dem, PRODUCT="envlight", SKY="overcast", SUN_AZIMUTH=100)
        self.assertIn("PRODUCT=envlight does not use SUN_AZIMUTH (the sun's, and "
                      "SKY=overcast has none)", err)
        # a CIE type without a sun's term is named as given (it said
        # "SKY=uniform or overcast has none", until session 53)
        err = T.open_stderr(self.dem, PRODUCT="envlight", SKY="cie:3", SUN_AZIMUTH=100)
        self.assertIn("PRODUCT=envlight does not use SUN_AZIMUTH (the sun's, and "
                      "SKY=cie:3 has none)", err)
        for oo in (dict(PRODUCT="svf", DIRECTIONS=8, MAX_DISTANCE=500, THREADS=1),
                   dict(PRODUCT="envlight", SKY="clear", SUN_AZIMUTH=100),
                   dict(PRODUCT="shade", PRESSURE=900, DIRECTIONS=32, SKY_WEIGHT=0.3,
                        DATETIME="2026-06-21T12:00:00Z"),
                   dict(PRODUCT="shade", SUN_AZIMUTH=100, TILE_SIZE=128, Z_FACTOR=2),
                   dict(PRODUCT="sunhours", DATE="2026-06-21", TIMEZONE="Z",
                        STEP_MINUTES=10)):
            self.assertNotIn("does not use", T.open_stderr(self.dem, **oo), oo)

    def test_curvature_and_refraction(self):
        """On a big flat-topped DEM the Earth's curvature lowers far horizons;
        refraction k = 1 cancels it."""
        z = np.full((20, 400), 0, np.float32)
        z[:, 0] = 500  # a wall at the west edge, 12 km away from the east edge
        wall = T.write_tif(os.path.join(self.dir, "wall.tif"), z,
                           (600000, 30, 0, 4000000, 0, -30), 32617)
        west = lambda **o: product(wall, PRODUCT="horizon", DIRECTIONS=4,
                                   **o)[3, 10, -1]  # 270 deg, east edge
        flat, curved = west(CURVATURE="NO"), west(CURVATURE="YES")
        no_refraction = west(CURVATURE="YES", REFRACTION=0)
        cancelled = west(CURVATURE="YES", REFRACTION=1)
        print("horizon of a 500 m wall 12 km away: %.4f (flat), %.4f (k=0.13), "
              "%.4f (k=0), %.4f (k=1)" % (flat, curved, no_refraction, cancelled))
        self.assertLess(curved, flat)
        self.assertLess(no_refraction, curved)
        self.assertAlmostEqual(cancelled, flat, places=4)

    def test_sky_weight(self):
        sun = product(self.dem, OUTPUT_TYPE="Float32", SUN_ELEVATION=10)
        lit = product(self.dem, OUTPUT_TYPE="Float32", SUN_ELEVATION=10,
                      SKY_WEIGHT=0.3, DIRECTIONS=8)
        self.assertTrue(np.all(lit >= sun))
        dark = sun == 0
        self.assertTrue(dark.any())
        self.assertGreater(lit[dark].min(), 0, "the sky lights the shadows")
        self.assertLessEqual(lit[dark].max(), 0.3 + 1e-6)

    def test_band(self):
        two = T.write_tif(os.path.join(self.dir, "two.tif"),
                          np.stack([np.zeros_like(self.z), self.z]), UTM_GT, 32617)
        np.testing.assert_array_equal(product(two, BAND=2), product(self.dem))
        self.differs(product(two, BAND=1), product(self.dem))

    def test_threads_do_not_change_results(self):
        for p in ("shade", "shadow", "svf"):
            one = product(self.dem, PRODUCT=p, THREADS=1, DIRECTIONS=8,
                          SUN_ELEVATION=10, METHOD="exact")
            many = product(self.dem, PRODUCT=p, THREADS=7, DIRECTIONS=8,
                           SUN_ELEVATION=10)
            np.testing.assert_array_equal(one, many)

    def test_max_memory(self):
        ok = gdal.OpenEx(T.conn(self.dem), open_options=["MAX_MEMORY=10"])
        self.assertIsNotNone(ok)
        with self.assertRaises(RuntimeError) as e:
            gdal.OpenEx(T.conn(self.dem), open_options=[
                "MAX_MEMORY=1", "PRODUCT=horizon", "DIRECTIONS=64"])
        print(e.exception)
        self.assertIn("MAX_MEMORY", str(e.exception))

    def test_refraction_ranges(self):
        """PRESSURE and TEMPERATURE stay where the SPA's refraction holds
        (docs/driver.md): TEMPERATURE=-272.999 once gave a sun 16237 degrees
        high; now it is refused with the range, as are its neighbours."""
        day = ["PRODUCT=sunhours", "DATE=2026-06-21", "TIMEZONE=-05:00",
               "STEP_MINUTES=120"]
        cases = [
            ("TEMPERATURE=-272.999", "TEMPERATURE must be between -90 and 60, got -272.999"),
            ("TEMPERATURE=-90.5", "TEMPERATURE must be between -90 and 60, got -90.5"),
            ("TEMPERATURE=61", "TEMPERATURE must be between -90 and 60, got 61"),
            ("PRESSURE=299", "PRESSURE must be between 300 and 1100, got 299"),
            ("PRESSURE=1101", "PRESSURE must be between 300 and 1100, got 1101"),
        ]
        for item, sentence in cases:
            with self.subTest(item=item):
                with self.assertRaises(RuntimeError) as e:
                    gdal.OpenEx(T.conn(self.dem), open_options=day + [item])
                self.assertEqual(str(e.exception), "TERRASHADE: " + sentence)
        # the bounds themselves are accepted, and the sun stays in the sky
        for extreme in (["TEMPERATURE=-90", "PRESSURE=1100"], ["TEMPERATURE=60", "PRESSURE=300"]):
            ds = gdal.OpenEx(T.conn(self.dem), open_options=[
                "DATETIME=2026-06-21T06:00:00-04:00", "OUTPUT_TYPE=Float32"] + extreme)
            el = float(ds.GetMetadataItem("SUN_ELEVATION"))
            self.assertTrue(-90 <= el <= 90, el)
            ds = None


if __name__ == "__main__":
    unittest.main(verbosity=2)
