"""HORIZON_METHOD=pyramid through the driver: every product that uses
horizons runs with it and stays close to the exact sweep (the bounds below
are those of docs/methods.md, with room), the options reach the core, the
C backend runs it (BACKEND=opencl falls back, saying why), and bad input
gets a clear sentence."""
import unittest

import tsdriver as T
from tsdriver import gdal, np

PYR = {"HORIZON_METHOD": "pyramid"}


def compute(dem, options):
    """Bands as float64 (NaN = nodata) and the dataset's metadata."""
    oo = ["%s=%s" % kv for kv in options.items()]
    ds = gdal.OpenEx(T.conn(dem), gdal.OF_RASTER, open_options=oo)
    arrays = [ds.GetRasterBand(b).ReadAsArray().astype(np.float64)
              for b in range(1, ds.RasterCount + 1)]
    md = ds.GetMetadata()
    return np.array(arrays), md


def diff(a, b):
    """median, p99 and max of |a - b| over the cells valid in both."""
    ok = np.isfinite(a) & np.isfinite(b)
    d = np.abs(a[ok] - b[ok])
    return np.median(d), np.percentile(d, 99), d.max()


# (product options, quantity, bound on the median, bound on the p99) of
# |pyramid - exact| on jacksboro with 16 directions, k = 4, o = 0
PRODUCTS = [
    ({"PRODUCT": "svf", "OUTPUT_TYPE": "Float32"}, "svf", 0.02, 0.08),
    ({"PRODUCT": "sky", "OUTPUT_TYPE": "Float32"}, "sky", 0.02, 0.08),
    ({"PRODUCT": "openness"}, "degrees", 3.0, 10.0),
    ({"PRODUCT": "openness", "OPENNESS": "negative"}, "degrees", 3.0, 10.0),
    ({"PRODUCT": "horizon"}, "degrees", 3.0, 15.0),
    ({"PRODUCT": "shade", "SKY_WEIGHT": "0.5", "OUTPUT_TYPE": "Float32"}, "0..1", 0.01,
     0.05),
    ({"PRODUCT": "envlight", "SKY": "uniform", "OUTPUT_TYPE": "Float32"}, "E/pi", 0.03,
     0.10),
]


class Pyramid(unittest.TestCase):
    def test_products_close_to_exact(self):
        for options, unit, want_median, want_p99 in PRODUCTS:
            name = " ".join("%s=%s" % kv for kv in options.items())
            with self.subTest(name):
                exact, _ = compute(T.JACKSBORO, options)
                pyr, md = compute(T.JACKSBORO, dict(options, **PYR))
                self.assertEqual(md["HORIZON_METHOD"], "pyramid")
                self.assertEqual(exact.shape, pyr.shape)
                self.assertTrue(np.isfinite(pyr).all(), "jacksboro has no nodata")
                med, p99, worst = diff(exact, pyr)
                print("jacksboro %-45s |pyramid - exact| (%s): median %.4f p99 %.4f "
                      "max %.4f" % (name, unit, med, p99, worst))
                self.assertLessEqual(med, want_median)
                self.assertLessEqual(p99, want_p99)
                self.assertGreater(worst, 0, "the pyramid must not be the sweep")

    def test_offset_brings_svf_closer(self):
        exact, _ = compute(T.JACKSBORO, {"PRODUCT": "svf", "OUTPUT_TYPE": "Float32"})
        last = None
        for offset in ("0", "1", "2", "4"):
            pyr, md = compute(T.JACKSBORO, dict(PYR, PRODUCT="svf", OUTPUT_TYPE="Float32",
                                                PYRAMID_OFFSET=offset))
            self.assertEqual(float(md["PYRAMID_OFFSET"]), float(offset))
            med, p99, _ = diff(exact, pyr)
            print("jacksboro svf PYRAMID_OFFSET=%s: median %.4f p99 %.4f" % (offset, med, p99))
            if last is not None:
                self.assertLessEqual(p99, last * 1.05)
            last = p99
        self.assertLessEqual(last, 0.03)

    def test_nodata_stays_nodata(self):
        """lux_elev: nodata outside Luxembourg in, nodata out; all else finite."""
        dem = T.read_dem(T.LUX)[0]
        for product in ("svf", "openness", "horizon"):
            with self.subTest(product):
                pyr, _ = compute(T.LUX, dict(PYR, PRODUCT=product, DIRECTIONS="8"))
                for band in pyr:
                    np.testing.assert_array_equal(np.isnan(band), np.isnan(dem))

    def test_level_step_changes_the_result(self):
        a, _ = compute(T.LUX, dict(PYR, PRODUCT="svf", OUTPUT_TYPE="Float32"))
        b, md = compute(T.LUX, dict(PYR, PRODUCT="svf", OUTPUT_TYPE="Float32",
                                    PYRAMID_LEVEL_STEP="2"))
        self.assertEqual(float(md["PYRAMID_LEVEL_STEP"]), 2.0)
        self.assertGreater(np.nanmax(np.abs(a - b)), 1e-4)

    def test_opencl_falls_back_to_c(self):
        _, exact_md = compute(T.LUX, {"PRODUCT": "svf", "BACKEND": "opencl"})
        _, md = compute(T.LUX, dict(PYR, PRODUCT="svf", BACKEND="opencl"))
        print("BACKEND=opencl, pyramid: %s" % {k: v for k, v in md.items()
                                               if k.startswith("BACKEND")})
        self.assertIn(md["BACKEND"], ("c", "mixed"))
        if exact_md["BACKEND"] == "opencl":  # OpenCL runs here: the pyramid's reason
            self.assertEqual(md["BACKEND"], "mixed")  # the normals still run on OpenCL
            self.assertIn("HORIZON_METHOD=pyramid runs on the C backend",
                          md["BACKEND_FALLBACK_REASON"])
        else:
            self.assertTrue(md["BACKEND_FALLBACK_REASON"])

    def test_bad_input(self):
        cases = [
            ({"HORIZON_METHOD": "fast"}, "HORIZON_METHOD must be one of exact, pyramid"),
            (dict(PYR, PYRAMID_LEVEL_STEP="0.5"),
             "PYRAMID_LEVEL_STEP must be between 1 and 16, got 0.5"),
            (dict(PYR, PYRAMID_LEVEL_STEP="17"), "PYRAMID_LEVEL_STEP must be between 1 and 16"),
            (dict(PYR, PYRAMID_OFFSET="-1"), "PYRAMID_OFFSET must be between 0 and 64, got -1"),
            (dict(PYR, PYRAMID_OFFSET="many"), "PYRAMID_OFFSET must be a number"),
            (dict(PYR, PRODUCT="shadow"),
             "HORIZON_METHOD=pyramid applies to PRODUCT=shadow with METHOD=sh"),
            (dict(PYR, PRODUCT="shadow", METHOD="shm"),
             "HORIZON_METHOD=pyramid applies to PRODUCT=shadow with METHOD=sh"),
            # (exact, the default, is warned of as doing nothing there:
            # test_products_table)
            ({"PRODUCT": "sunhours", "DATE": "2026-06-21", "TIMEZONE": "Z",
              "HORIZON_METHOD": "pyramid"},
             "HORIZON_METHOD applies to the products whose horizons the pyramid can give"),
            ({"PRODUCT": "daycycle", "DATE": "2026-06-21", "TIMEZONE": "Z",
              "PYRAMID_OFFSET": "1"},
             "PYRAMID_OFFSET applies to the products whose horizons the pyramid can give"),
            ({"PRODUCT": "svf", "PYRAMID_OFFSET": "1"},
             "PYRAMID_OFFSET applies with HORIZON_METHOD=pyramid"),
            (dict(PYR, PRODUCT="shade"), "SKY_WEIGHT=0 leaves out"),
        ]
        for options, text in cases:
            with self.subTest(options=options):
                oo = ["%s=%s" % kv for kv in options.items()]
                with self.assertRaises(RuntimeError) as e:
                    gdal.OpenEx(T.conn(T.LUX), gdal.OF_RASTER, open_options=oo)
                print("%-60s -> %s" % (options, e.exception))
                self.assertIn(text, str(e.exception))
        # and through a tool: a non-zero exit with the sentence
        p = T.run(["gdalinfo", "-oo", "HORIZON_METHOD=pyramid", "-oo", "PRODUCT=shadow",
                   T.conn(T.LUX)], ok=False)
        self.assertIn("HORIZON_METHOD=pyramid applies to PRODUCT=shadow with METHOD=sh",
                      p.stderr)

    def test_option_list_and_products(self):
        drv = gdal.GetDriverByName("TERRASHADE")
        products = drv.GetMetadataItem("TERRASHADE_PRODUCTS")
        for line in products.split("<Product ")[1:]:
            name = line.split("'")[1]
            takes = "HORIZON_METHOD" in line
            # shadow: METHOD=sh's key light
            self.assertEqual(takes, name in ("shade", "shadow", "horizon", "svf", "openness",
                                             "sky", "envlight"), name)
            self.assertEqual("PYRAMID_OFFSET" in line, takes, name)
        self.assertIn("PYRAMID_LEVEL_STEP", drv.GetMetadataItem(gdal.DMD_OPENOPTIONLIST))


if __name__ == "__main__":
    unittest.main(verbosity=2)
