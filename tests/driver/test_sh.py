"""Order-4 SH light through the driver (core/terrashade_sh.h, docs/methods.md "sh").

- ENV_METHOD=sh with a constant environment (SKY=uniform) against the `sky`
  product: the truncation error is stated and at most 5 %;
- ENV_METHOD=sh against ENV_METHOD=table on the real maps (sunset, forest,
  city; tests/data/envmaps) and the standard skies, stated and bounded;
- METHOD=sh shade and shadow against METHOD=exact on jacksboro, stated and
  bounded; open flat ground gets exactly the exact sin(elevation) and a
  visible share of 1;
- BACKEND=opencl: the SH part runs in C, and the metadata says why;
- bad input: a clear sentence and a non-zero exit of gdal_translate.
"""
import os
import unittest

import tsdriver as T
from tsdriver import np

MAPS = [os.path.join(T.DATA, "envmaps", m + ".exr") for m in ("sunset", "forest", "city")]


def product(dem, **options):
    return T.read(T.conn(dem), options=dict(options, PROGRESS="no"))


def luminance(rgb):
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


def relative(a, b):
    """|a - b| / b over the cells valid in both."""
    v = np.isfinite(a) & np.isfinite(b) & (b > 0)
    return np.abs(a[v] - b[v]) / b[v]


class TestSH(unittest.TestCase):
    def test_constant_environment_against_sky(self):
        for dirs in (16, 32):
            sky = product(T.JACKSBORO, PRODUCT="sky", DIRECTIONS=dirs)[0]
            sh = product(T.JACKSBORO, PRODUCT="envlight", SKY="uniform", DIRECTIONS=dirs,
                         ENV_METHOD="sh")
            r = relative(sh[0], sky)
            print("SKY=uniform through SH against sky, %d directions: relative difference "
                  "median %.2f %%, p99 %.2f %%, max %.2f %%" % (
                      dirs, 100 * np.median(r), 100 * np.percentile(r, 99), 100 * r.max()))
            self.assertLess(r.max(), 0.05)  # the goal: truncation <= 5 %
            self.assertTrue(np.array_equal(sh[0], sh[2]))  # grey
            self.assertTrue(np.array_equal(np.isnan(sh[0]), np.isnan(sky)))

    def test_sh_against_table_on_maps_and_skies(self):
        cases = [(os.path.basename(m), dict(ENV_MAP=m)) for m in MAPS]
        cases += [("SKY=" + s, dict(SKY=s)) for s in ("uniform", "overcast", "clear")]
        for name, light in cases:
            with self.subTest(name):
                table = luminance(product(T.JACKSBORO, PRODUCT="envlight", DIRECTIONS=32,
                                          **light))
                sh = luminance(product(T.JACKSBORO, PRODUCT="envlight", DIRECTIONS=32,
                                       ENV_METHOD="sh", **light))
                r = relative(sh, table)
                v = np.isfinite(sh) & np.isfinite(table)
                corr = np.corrcoef(sh[v], table[v])[0, 1]
                print("%s: SH against the table, luminance: median %.2f %%, p99 %.2f %%, "
                      "max %.2f %%, correlation %.4f" % (
                          name, 100 * np.median(r), 100 * np.percentile(r, 99),
                          100 * r.max(), corr))
                # measured: median <= 4.7 %, p99 <= 9.1 %, correlation >= 0.986
                self.assertLess(np.median(r), 0.06)
                self.assertLess(np.percentile(r, 99), 0.11)
                self.assertGreater(corr, 0.98)

    def test_key_light_against_exact(self):
        # measured: mean |difference| 0.024, 0.063, 0.030; correlation 0.988, 0.937, 0.976
        bounds = {(315, 45): 0.035, (135, 10): 0.08, (315, 30): 0.045}
        for (az, el), bound in bounds.items():
            sun = dict(SUN_AZIMUTH=az, SUN_ELEVATION=el, OUTPUT_TYPE="Float32")
            exact = product(T.JACKSBORO, PRODUCT="shade", **sun)[0]
            sh = product(T.JACKSBORO, PRODUCT="shade", METHOD="sh", **sun)[0]
            d = np.abs(sh - exact)
            v = np.isfinite(d)
            corr = np.corrcoef(sh[v], exact[v])[0, 1]
            se = product(T.JACKSBORO, PRODUCT="shadow", SUN_AZIMUTH=az, SUN_ELEVATION=el)[0]
            ss = product(T.JACKSBORO, PRODUCT="shadow", METHOD="sh", SUN_AZIMUTH=az,
                         SUN_ELEVATION=el)[0]
            agree = ((ss[v] > 0.5) == (se[v] > 0.5)).mean()
            print("sun %d/%d: shade sh - exact: mean %.4f, median %.4f, p99 %.4f, max %.4f, "
                  "correlation %.4f; shadow: mean |difference| %.4f, lit/shadowed (0.5) "
                  "agreement %.1f %%" % (az, el, d[v].mean(), np.median(d[v]),
                                         np.percentile(d[v], 99), d[v].max(), corr,
                                         np.abs(ss[v] - se[v]).mean(), 100 * agree))
            self.assertLess(d[v].mean(), bound)
            self.assertGreater(corr, 0.93)
            self.assertTrue(np.array_equal(np.isnan(sh), np.isnan(exact)))
            self.assertTrue(((sh[v] >= 0) & (sh[v] <= 1)).all())

    def test_pyramid_horizons(self):
        # HORIZON_METHOD=pyramid gives METHOD=sh the pyramid's horizons (B-spline);
        # measured: shade mean |difference| to exact 0.0611, 0.0178, 0.0182,
        # correlation 0.915, 0.988, 0.994; shadow agreement 80.6, 97.8, 100 %
        bounds = {(135, 10): (0.075, 0.90), (315, 30): (0.025, 0.98),
                  (315, 45): (0.025, 0.98)}
        for (az, el), (bound, min_corr) in bounds.items():
            sun = dict(SUN_AZIMUTH=az, SUN_ELEVATION=el, OUTPUT_TYPE="Float32")
            exact = product(T.JACKSBORO, PRODUCT="shade", **sun)[0]
            sh = product(T.JACKSBORO, PRODUCT="shade", METHOD="sh", HORIZON_METHOD="pyramid",
                         **sun)[0]
            swept = product(T.JACKSBORO, PRODUCT="shade", METHOD="sh", **sun)[0]
            d = np.abs(sh - exact)
            v = np.isfinite(d)
            corr = np.corrcoef(sh[v], exact[v])[0, 1]
            print("sun %d/%d, pyramid horizons: shade sh - exact: mean %.4f, correlation "
                  "%.4f; max |pyramid - swept| %.4f" % (
                      az, el, d[v].mean(), corr, np.abs(sh - swept)[v].max()))
            self.assertLess(d[v].mean(), bound)
            self.assertGreater(corr, min_corr)
            self.assertTrue(np.array_equal(np.isnan(sh), np.isnan(exact)))
            self.assertGreater(np.abs(sh - swept)[v].max(), 0.01)  # not the sweep's
        # shadow takes it with METHOD=sh (and SKY_WEIGHT=0 is no objection then)
        share = product(T.JACKSBORO, PRODUCT="shadow", METHOD="sh", HORIZON_METHOD="pyramid",
                        SUN_AZIMUTH=315, SUN_ELEVATION=45)[0]
        v = np.isfinite(share)
        self.assertTrue(((share[v] >= 0) & (share[v] <= 1)).all())

    def test_flat_ground(self):
        with T.TempDir() as d:
            flat = T.write_tif(os.path.join(d, "flat.tif"), np.full((48, 48), 100.0),
                               [0, 30, 0, 1440, 0, -30], 32617)
            for el in (5, 30, 60, 80):
                sun = dict(SUN_ELEVATION=el, CURVATURE="NO")
                sh = product(flat, PRODUCT="shade", METHOD="sh", OUTPUT_TYPE="Float32",
                             **sun)[0]
                share = product(flat, PRODUCT="shadow", METHOD="sh", **sun)[0]
                self.assertLess(np.abs(sh - np.sin(np.radians(el))).max(), 1e-5)
                self.assertLess(np.abs(share - 1).max(), 1e-5)
            # a sun below the horizontal lights nothing
            dark = product(flat, PRODUCT="shadow", METHOD="sh", SUN_ELEVATION=-5)[0]
            self.assertEqual(np.abs(dark).max(), 0)

    def test_light_radius_and_swath(self):
        sun = dict(PRODUCT="shadow", METHOD="sh", SUN_AZIMUTH=135, SUN_ELEVATION=10)
        small = product(T.JACKSBORO, **sun)[0]
        wide = product(T.JACKSBORO, LIGHT_RADIUS=20, **sun)[0]
        one = product(T.JACKSBORO, SWATH_DIRECTIONS=1, **sun)[0]
        v = np.isfinite(small)
        # a disk reaching 10 degrees below the horizontal: a quarter of it is gone
        print("shadow sh mean: LIGHT_RADIUS 0.2666 %.3f, 20 %.3f; SWATH_DIRECTIONS 1 %.3f" % (
            small[v].mean(), wide[v].mean(), one[v].mean()))
        self.assertLess(wide[v].mean(), small[v].mean() - 0.1)
        self.assertGreater(np.abs(one[v] - small[v]).max(), 0.01)

    def test_tiny_light_radius_is_a_point(self):
        # a swath 1e-38 degrees wide made wedge tables of float zeros: every
        # cell 1 (no shadow) or NaN; below 0.01 degrees (TS_SH_KEY_RADIUS_MIN)
        # order 4 sees a point, the same shade as at 0.01
        for name in ("shadow", "shade"):
            sun = dict(PRODUCT=name, METHOD="sh", SUN_AZIMUTH=135, SUN_ELEVATION=10,
                       OUTPUT_TYPE="Float32")
            floor = product(T.JACKSBORO, LIGHT_RADIUS=0.01, **sun)[0]
            wider = product(T.JACKSBORO, LIGHT_RADIUS=0.02, **sun)[0]
            v = np.isfinite(floor)
            self.assertGreater(v.mean(), 0.99)
            # (a cell whose horizon lies within 0.02 degrees of the sun sees
            # more of the wider disk: 0.7 % of cells by more than 1e-4, up
            # to 0.009, on jacksboro)
            diff = np.abs(wider[v] - floor[v])
            self.assertLess(np.percentile(diff, 99), 1e-4)
            self.assertLess(diff.max(), 0.02)
            self.assertLess(floor[v].min(), 0.1)  # shadows are there
            for r in (1e-38, 1e-50, 1e-300):
                tiny = product(T.JACKSBORO, LIGHT_RADIUS=r, **sun)[0]
                np.testing.assert_array_equal(tiny, floor, err_msg="%s %g" % (name, r))

    def test_opencl_falls_back_with_a_reason(self):
        ds = T.gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=shade", "METHOD=sh", "BACKEND=opencl", "PROGRESS=no"])
        ds.GetRasterBand(1).ReadAsArray()
        md = ds.GetMetadata()
        print("BACKEND=%s, reason: %s" % (md.get("BACKEND"), md.get("BACKEND_FALLBACK_REASON")))
        self.assertIn(md.get("BACKEND"), ("mixed", "c"))
        self.assertTrue(md.get("BACKEND_FALLBACK_REASON"))
        self.assertEqual(md.get("METHOD"), "sh")

    def test_bad_input(self):
        cases = [
            ("SWATH_DIRECTIONS=0", dict(PRODUCT="shade", METHOD="sh", SWATH_DIRECTIONS=0),
             "SWATH_DIRECTIONS must be between 1 and 3600, got 0"),
            ("LIGHT_RADIUS=0", dict(PRODUCT="shade", METHOD="sh", LIGHT_RADIUS=0),
             "LIGHT_RADIUS must be greater than 0"),
            ("LIGHT_RADIUS=-1", dict(PRODUCT="shadow", METHOD="sh", LIGHT_RADIUS=-1),
             "LIGHT_RADIUS must be greater than 0"),
            ("LIGHT_RADIUS=45", dict(PRODUCT="shade", METHOD="sh", LIGHT_RADIUS=45),
             "LIGHT_RADIUS must be greater than 0 and less than 45 degrees, got 45"),
            ("LIGHT_RADIUS=90", dict(PRODUCT="shade", METHOD="sh", LIGHT_RADIUS=90),
             "LIGHT_RADIUS must be greater than 0"),
            ("ENV_METHOD=sh on shade", dict(PRODUCT="shade", ENV_METHOD="sh"),
             "ENV_METHOD=sh applies to PRODUCT=envlight only, not to PRODUCT=shade"),
            ("ENV_METHOD=sh on svf", dict(PRODUCT="svf", ENV_METHOD="sh"),
             "ENV_METHOD=sh applies to PRODUCT=envlight only, not to PRODUCT=svf"),
            ("ENV_METHOD=fast", dict(PRODUCT="envlight", SKY="uniform", ENV_METHOD="fast"),
             "ENV_METHOD must be one of table, sh"),
            ("METHOD=sh on svf", dict(PRODUCT="svf", METHOD="sh"),
             "METHOD=sh applies to PRODUCT=shade and PRODUCT=shadow only"),
            ("SWATH_DIRECTIONS without sh", dict(PRODUCT="shade", SWATH_DIRECTIONS=5),
             "give METHOD=sh with it"),
            ("per-cell sun", dict(PRODUCT="shade", METHOD="sh", SUN_POSITION="per_cell",
                                  DATETIME="2026-06-21T08:00:00-05:00"),
             "SUN_POSITION=per_cell needs METHOD=exact"),
        ]
        with T.TempDir() as d:
            for name, opts, words in cases:
                with self.subTest(name):
                    p = T.run(["gdal_translate", "-q"] + T.oo_args(opts)
                              + [T.conn(T.JACKSBORO), os.path.join(d, "bad.tif")], ok=False)
                    print("%s: %s" % (name, p.stderr.strip()))
                    self.assertIn(words, p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
