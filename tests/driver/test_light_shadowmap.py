"""LIGHT_RADIUS and METHOD=shadowmap through the driver, on both backends.

- a pillar's penumbra on flat ground spans h/tan(e+r) .. h/tan(e-r) for the
  disk of LIGHT_RADIUS r (PRODUCT=shadow, METHOD=exact), BACKEND=c and
  BACKEND=opencl alike;
- METHOD=shadowmap on jacksboro agrees with the exact shadow on >= 97 % of
  the cells at 135/10 and 315/30, C and OpenCL within 1e-4; shade with it;
  no shadow under a light at 60 degrees or more, which nothing there can cast;
- bad values and combinations: a clear sentence, never a crash.
"""
import math
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

for _k in ("TERRASHADE_BACKEND", "TERRASHADE_OPENCL_DEVICE"):
    os.environ.pop(_k, None)

PILLAR_X, HEIGHT, WIDTH = 20, 50.0, 640


def array(dem, **options):
    oo = ["%s=%s" % kv for kv in options.items()]
    ds = gdal.OpenEx(T.conn(dem), gdal.OF_RASTER, open_options=oo)
    return ds.GetRasterBand(1).ReadAsArray().astype(np.float64), ds.GetMetadataItem("BACKEND")


class LightRadius(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        d = cls.tmp.__enter__()
        z = np.zeros((5, WIDTH), np.float32)
        z[2, PILLAR_X] = HEIGHT
        cls.dem = os.path.join(d, "pillar.tif")
        T.write_tif(cls.dem, z, (500000, 1, 0, 4000000, 0, -1), 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def test_pillar_penumbra(self):
        for backend in ("c", "opencl"):
            for el, r in ((20, 0.2666), (20, 2), (10, 5), (35, 1)):
                a, ran = array(self.dem, PRODUCT="shadow", SUN_AZIMUTH=270, SUN_ELEVATION=el,
                               LIGHT_RADIUS=r, CURVATURE="NO", OUTPUT_TYPE="Float32",
                               BACKEND=backend)
                self.assertEqual(ran, backend)
                row = a[2, PILLAR_X + 1:]
                start = 1 + int(np.argmax(row > 0))
                end = 1 + int(np.argmax(row >= 1))
                want0 = HEIGHT / math.tan(math.radians(el + r))
                want1 = HEIGHT / math.tan(math.radians(el - r))
                print("%s e=%g r=%g: penumbra %d..%d m, geometry %.2f..%.2f m"
                      % (backend, el, r, start, end, want0, want1))
                self.assertEqual(start, math.floor(want0) + 1)
                self.assertEqual(end, math.ceil(want1))

    def test_default_is_the_sun(self):
        a, _ = array(self.dem, PRODUCT="shadow", SUN_AZIMUTH=270, SUN_ELEVATION=20,
                     OUTPUT_TYPE="Float32")
        b, _ = array(self.dem, PRODUCT="shadow", SUN_AZIMUTH=270, SUN_ELEVATION=20,
                     OUTPUT_TYPE="Float32", LIGHT_RADIUS=0.2666)
        self.assertTrue(np.array_equal(a, b))


class Shadowmap(unittest.TestCase):
    def test_jacksboro(self):
        for az, el in ((135, 10), (315, 30)):
            ex, _ = array(T.JACKSBORO, PRODUCT="shadow", SUN_AZIMUTH=az, SUN_ELEVATION=el,
                          OUTPUT_TYPE="Float32", BACKEND="c")
            runs = {}
            for backend in ("c", "opencl"):
                sm, ran = array(T.JACKSBORO, PRODUCT="shadow", METHOD="shadowmap",
                                SUN_AZIMUTH=az, SUN_ELEVATION=el, OUTPUT_TYPE="Float32",
                                BACKEND=backend)
                self.assertEqual(ran, backend)
                runs[backend] = sm
            ok = ~np.isnan(ex)
            self.assertTrue(np.array_equal(ok, ~np.isnan(runs["c"])))
            agree = np.mean((ex[ok] >= 0.5) == (runs["c"][ok] >= 0.5))
            diff = np.nanmax(np.abs(runs["c"] - runs["opencl"]))
            print("jacksboro %g/%g: shadowmap agrees with exact on %.2f %%; |C - OpenCL| %.3g"
                  % (az, el, 100 * agree, diff))
            self.assertGreaterEqual(agree, 0.97)
            self.assertLessEqual(diff, 1e-4)

    def test_high_light_casts_no_shadow(self):
        """Nothing on jacksboro can shadow a light at 60 degrees or more (the
        exact shadow is 1 everywhere). The map once shadowed concave cells
        (valley floors), whose plane runs below their own triangles, by up to
        0.61 at 90 degrees (5112 cells >= 0.1, 3.7 %), 0.47 at 60; taps now
        compare the map with the receiver's own triangles."""
        for el in (60, 75, 90):
            for kernel in ("auto", "0.25"):
                for backend in ("c", "opencl"):
                    sm, ran = array(T.JACKSBORO, PRODUCT="shadow", METHOD="shadowmap",
                                    SUN_ELEVATION=el, PCF_KERNEL=kernel,
                                    OUTPUT_TYPE="Float32", BACKEND=backend)
                    self.assertEqual(ran, backend)
                    print("jacksboro 315/%g, PCF_KERNEL=%s, %s: lowest %.4f"
                          % (el, kernel, backend, np.nanmin(sm)))
                    self.assertGreaterEqual(np.nanmin(sm), 0.99, (el, kernel, backend))

    def test_shade_and_kernels(self):
        shade, _ = array(T.JACKSBORO, METHOD="shadowmap", SUN_AZIMUTH=200, SUN_ELEVATION=25)
        exact, _ = array(T.JACKSBORO, SUN_AZIMUTH=200, SUN_ELEVATION=25)
        self.assertGreater(np.mean(np.abs(shade - exact) <= 1), 0.97)
        hard, _ = array(T.JACKSBORO, PRODUCT="shadow", METHOD="shadowmap", PCF_KERNEL=0.5,
                        SUN_AZIMUTH=135, SUN_ELEVATION=10, OUTPUT_TYPE="Float32")
        soft, _ = array(T.JACKSBORO, PRODUCT="shadow", METHOD="shadowmap", PCF_KERNEL=4,
                        SHADOWMAP_SCALE=1, SUN_AZIMUTH=135, SUN_ELEVATION=10,
                        OUTPUT_TYPE="Float32")
        partial = lambda a: np.mean((a > 0) & (a < 1))  # noqa: E731
        self.assertGreater(partial(soft), 2 * partial(hard))


# (open options, text the message must hold)
BAD = [
    (["PCF_KERNEL=0", "METHOD=shadowmap", "PRODUCT=shadow"],
     "PCF_KERNEL must be greater than 0 and at most 64, got 0"),
    (["PCF_KERNEL=1000", "METHOD=shadowmap"], "PCF_KERNEL must be greater than 0 and at most 64"),
    (["PCF_KERNEL=-3", "METHOD=shadowmap"], "PCF_KERNEL must be greater than 0"),
    (["PCF_KERNEL=huge", "METHOD=shadowmap"], "PCF_KERNEL must be auto or a number, got 'huge'"),
    (["SHADOWMAP_SCALE=0.1", "METHOD=shadowmap"],
     "SHADOWMAP_SCALE must be between 0.25 and 8, got 0.1"),
    (["SHADOWMAP_SCALE=9", "METHOD=shadowmap"], "SHADOWMAP_SCALE must be between 0.25 and 8"),
    (["METHOD=shadowmap", "PRODUCT=svf"],
     "METHOD=shadowmap applies to PRODUCT=shade and PRODUCT=shadow only, not to PRODUCT=svf"),
    (["PCF_KERNEL=3"], "PCF_KERNEL applies to METHOD=shadowmap only"),
    (["SHADOWMAP_SCALE=4", "METHOD=shm"], "SHADOWMAP_SCALE applies to METHOD=shadowmap only"),
    (["METHOD=shadowmap", "MAX_DISTANCE=1000"],
     "MAX_DISTANCE does not apply to METHOD=shadowmap"),
    # the other methods once ignored PENUMBRA_DEPTH without a word
    (["PENUMBRA_DEPTH=500"], "PENUMBRA_DEPTH applies to METHOD=shm only"),
    (["PENUMBRA_DEPTH=500", "METHOD=sh"], "PENUMBRA_DEPTH applies to METHOD=shm only"),
    # one sentence, the open interval, below, at and above it
    (["LIGHT_RADIUS=0"], "LIGHT_RADIUS must be greater than 0 and less than 45 degrees, got 0"),
    (["LIGHT_RADIUS=-1"], "LIGHT_RADIUS must be greater than 0 and less than 45 degrees, got -1"),
    (["LIGHT_RADIUS=45"], "LIGHT_RADIUS must be greater than 0 and less than 45 degrees, got 45"),
    (["LIGHT_RADIUS=90"], "LIGHT_RADIUS must be greater than 0 and less than 45 degrees, got 90"),
    (["LIGHT_RADIUS=wide"], "LIGHT_RADIUS must be a number, got 'wide'"),
    (["LIGHT_RADIUS=2", "METHOD=shm"], "LIGHT_RADIUS does not apply to METHOD=shm"),
    (["LIGHT_RADIUS=2", "PRODUCT=svf"],
     "LIGHT_RADIUS applies to PRODUCT=shade and PRODUCT=shadow, not to PRODUCT=svf"),
]


class BadInput(unittest.TestCase):
    def test_open(self):
        for oo, text in BAD:
            with self.assertRaises(RuntimeError, msg=str(oo)) as cm:
                gdal.OpenEx(T.conn(T.LUX), gdal.OF_RASTER, open_options=oo)
            print("%-50s -> %s" % (" ".join(oo), cm.exception))
            self.assertIn(text, str(cm.exception))

    def test_shm_says_what_max_distance_bounds(self):
        """METHOD=shm's shadows follow every occluder to the DEM's edge:
        MAX_DISTANCE bounds its sky term and EDGE=nodata's reach only, and
        the dataset says so (it once took the option without a word)."""
        with T.TempDir() as d:
            out = os.path.join(d, "o.tif")
            for oo, said in ((["METHOD=shm", "MAX_DISTANCE=200"], True),
                             (["METHOD=shm"], False), (["MAX_DISTANCE=200"], False)):
                with self.subTest(oo=oo):
                    p = T.run(["gdal_translate", "-q"] + sum((["-oo", o] for o in oo), [])
                              + [T.conn(T.LUX), out])
                    self.assertEqual("MAX_DISTANCE=200 m bounds only its sky term" in p.stderr,
                                     said, p.stderr)
            # shadow has no sky term; and a distance under a cell says
            # nothing of the cell's own slope there, shm ignoring it
            p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=shadow", "-oo", "METHOD=shm",
                       "-oo", "MAX_DISTANCE=5", T.conn(T.LUX), out])
            self.assertIn("MAX_DISTANCE=5 m bounds only the reach of EDGE=nodata", p.stderr)
            self.assertNotIn("shorter than the DEM's cells", p.stderr)

    def test_low_light(self):
        """The light at or below the horizon is refused at open (gdalinfo, a
        QGIS layer), by SUN_ELEVATION or by a DATETIME at night, and
        gdal_translate exits non-zero."""
        for opts, said in ((["SUN_ELEVATION=-5"], "SUN_ELEVATION must be greater than 0"),
                           (["SUN_ELEVATION=0"], "SUN_ELEVATION must be greater than 0"),
                           (["DATETIME=2026-12-21T00:00:00+01:00"], "sun's elevation is -")):
            with self.subTest(options=opts):
                with self.assertRaises(RuntimeError) as cm:
                    gdal.OpenEx(T.conn(T.LUX), gdal.OF_RASTER,
                                open_options=["METHOD=shadowmap"] + opts)
                self.assertIn("METHOD=shadowmap needs the light above the horizon",
                              str(cm.exception))
                self.assertIn(said, str(cm.exception))
        # the same DATETIME by day opens
        ds = gdal.OpenEx(T.conn(T.LUX), gdal.OF_RASTER,
                         open_options=["METHOD=shadowmap", "DATETIME=2026-06-21T13:00:00+02:00"])
        self.assertEqual(ds.RasterCount, 1)
        with T.TempDir() as d:
            p = T.run(["gdal_translate", "-q", "-oo", "METHOD=shadowmap", "-oo",
                       "SUN_ELEVATION=0", T.conn(T.LUX), os.path.join(d, "o.tif")], ok=False)
            self.assertIn("SUN_ELEVATION must be greater than 0", p.stderr)
            self.assertFalse(os.path.exists(os.path.join(d, "o.tif")))

if __name__ == "__main__":
    unittest.main(verbosity=2)
