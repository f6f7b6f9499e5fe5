"""A year of sun: PRODUCT=sunhours and insolation over a date range
(START_DATE, END_DATE, DAY_INTERVAL, STEP_MINUTES, HORIZON_DIRECTIONS;
issue 13 item 3, the driver's side of core/sun_range.c).

- a 3-day range at DAY_INTERVAL=1 is the sum of the three one-day products
  (DATE, STEP_MINUTES=30) within the horizon interpolation's error, which
  the core measures (tests/check_sun_range, docs/day-cycle.md);
- a flat plane over the year 2026 at the defaults (interval 14, 30-minute
  steps) gets the sampled days' astronomical day lengths (NOAA's equations,
  an independent reference) weighted min(DAY_INTERVAL, days left), within
  the 30-minute steps' error, and the core's own figure;
- the metadata names the range, interval, step and directions used; the
  progress line comes; one day (DATE) is what it was: 5-minute steps, no
  range items;
- every bad input is a sentence and a non-zero exit through gdal_translate.
"""
import os
import re
import unittest

import tsdriver as T
from tsdriver import gdal, np
from test_sun import flat_dem, noaa_day_length

# the core's figures (tests/check_sun_range: flat plane at 46.5 N 7.4 E,
# TIMEZONE=+01:00, 2026, 30-minute steps): sun hours at interval 1 and 14
CORE_FLAT_YEAR = {1: 4481.0, 14: 4475.0}


def meta(conn, oo):
    ds = gdal.OpenEx(conn, gdal.OF_RASTER, open_options=["%s=%s" % kv for kv in oo.items()])
    return ds.GetMetadata()


def relative(a, b):
    """Mean and max |a - b| over valid cells, relative to b's mean."""
    ok = ~np.isnan(a) & ~np.isnan(b)
    d = np.abs(a[ok] - b[ok])
    m = b[ok].mean()
    return d.mean() / m, d.max() / m, d.max(), m


class Year(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        # a 64 x 64 cut of jacksboro (Tennessee, 36.3 N, geographic)
        cls.dem = os.path.join(cls.dir, "j64.tif")
        T.run(["gdal_translate", "-q", "-srcwin", "100", "100", "64", "64", T.JACKSBORO,
               cls.dem])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def product(self, options, dem=None, band=None):
        out = os.path.join(self.dir, "out.tif")
        T.translate(dem or self.dem, out, options)
        return T.read(out, band)

    def test_three_days_are_the_sum_of_their_days(self):
        days = ["2026-03-19", "2026-03-20", "2026-03-21"]
        zone = {"TIMEZONE": "-05:00"}
        # bounds: the core's measured errors on a 100 x 80 cut of jacksboro at
        # D = 64 (docs/day-cycle.md) are 0.16 % mean / 1.5 h max for sun
        # hours, 0.012 % mean / 1.45 % max for insolation; this cut: below
        bounds = {"sunhours": (0.004, 2.0), "insolation": (0.0005, 0.03)}
        for product in ("sunhours", "insolation"):
            with self.subTest(product=product):
                rng = self.product(dict(zone, PRODUCT=product, START_DATE=days[0],
                                        END_DATE=days[-1], DAY_INTERVAL=1))
                one = sum(self.product(dict(zone, PRODUCT=product, DATE=d, STEP_MINUTES=30))
                          for d in days)
                if product == "sunhours":
                    rng, one = rng[None], one[None]
                names = ["sunhours"] if product == "sunhours" else ["global", "beam",
                                                                     "diffuse"]
                for k, name in enumerate(names):
                    mean_rel, max_rel, max_abs, m = relative(rng[k], one[k])
                    print("3 days vs 3 x DATE, %-10s %-7s: mean |diff| %.4f %%, max %.3f "
                          "(%.3f %%) of the mean %.2f" % (product, name, 100 * mean_rel,
                                                           max_abs, 100 * max_rel, m))
                    np.testing.assert_array_equal(np.isnan(rng[k]), np.isnan(one[k]))
                    self.assertLessEqual(mean_rel, bounds[product][0], name)
                    if product == "sunhours":
                        self.assertLessEqual(max_abs, bounds[product][1])
                    else:
                        self.assertLessEqual(max_rel, bounds[product][1], name)
                # global = beam + diffuse, as for one day
                if product == "insolation":
                    np.testing.assert_allclose(rng[0], rng[1] + rng[2], rtol=1e-5)

    def test_flat_year_is_the_astronomical_sum(self):
        dem = flat_dem(os.path.join(self.dir, "flat.tif"), 46.5, 7.4, n=8)
        days = 365
        for interval in (14, 1):
            opts = {"PRODUCT": "sunhours", "START_DATE": "2026-01-01",
                    "END_DATE": "2026-12-31", "TIMEZONE": "+01:00"}
            if interval != 14:
                opts["DAY_INTERVAL"] = interval  # 14 is the default
            got = float(np.nanmean(self.product(opts, dem, 1)))
            astro = 0.0
            for b in range(0, days, interval):  # blocks, sampled at their middle
                d = b + (min(interval, days - b) - 1) // 2
                day = np.datetime64("2026-01-01") + np.timedelta64(d, "D")
                y, m, dd = (int(v) for v in str(day).split("-"))
                astro += min(interval, days - b) * noaa_day_length(46.5, 7.4, y, m, dd)
            print("flat plane 46.5 N 7.4 E, 2026, DAY_INTERVAL %2d, 30-min steps: %.3f h of "
                  "sun; NOAA day lengths %.3f h (%+.2f min a day); the core %.1f h" % (
                      interval, got, astro, (got - astro) * 60 / days,
                      CORE_FLAT_YEAR[interval]))
            # a step counts whole while any of the disk is up: half a step at
            # each end of a day at most, and the ends mostly cancel over a
            # year (the core's bound: 6 minutes a day)
            self.assertLessEqual(abs(got - astro), days * 0.1)
            # the driver places the sun as the core's test does
            self.assertLessEqual(abs(got - CORE_FLAT_YEAR[interval]), 1.0)

    def test_a_season_at_the_default_interval_is_its_days(self):
        """Spring on a flat plane at 46.5 N: the default DAY_INTERVAL=14 gives the
        every-day total within 0.5 %. Each sampled day stood for itself and the
        13 days after it, the shortest of them while the days lengthen: -2.45 %
        of sun hours and -4.96 % of insolation (a year's errors cancel)."""
        dem = flat_dem(os.path.join(self.dir, "flat.tif"), 46.5, 7.4, n=8)
        for product in ("sunhours", "insolation"):
            opts = {"PRODUCT": product, "START_DATE": "2026-03-01",
                    "END_DATE": "2026-05-31", "TIMEZONE": "+01:00"}
            every = float(np.nanmean(self.product(dict(opts, DAY_INTERVAL=1), dem, 1)))
            sampled = float(np.nanmean(self.product(opts, dem, 1)))
            print("flat plane, 2026-03-01..05-31, %s: every day %.1f, DAY_INTERVAL=14 %.1f "
                  "(%+.2f %%)" % (product, every, sampled, 100 * (sampled / every - 1)))
            self.assertLessEqual(abs(sampled / every - 1), 0.005, product)

    def test_metadata_and_progress(self):
        oo = {"PRODUCT": "insolation", "START_DATE": "2026-06-01", "END_DATE": "2026-06-30",
              "TIMEZONE": "-05:00", "HORIZON_DIRECTIONS": 32}
        md = meta(T.conn(self.dem), oo)
        want = {"START_DATE": "2026-06-01", "END_DATE": "2026-06-30", "DAY_INTERVAL": "14",
                "STEP_MINUTES": "30", "HORIZON_DIRECTIONS": "32", "RANGE_DAYS": "30",
                "RANGE_SAMPLED_DAYS": "3", "DAY_START": "2026-06-01T00:00:00-05:00",
                "DAY_END": "2026-07-01T00:00:00-05:00"}
        self.assertEqual({k: md.get(k) for k in want}, want)
        self.assertIn("RANGE_DAY_WEIGHT", md)
        # END_DATE defaults to START_DATE; STEP_MINUTES as given
        md = meta(T.conn(self.dem), {"PRODUCT": "sunhours", "START_DATE": "2026-06-01",
                                     "TIMEZONE": "Z", "STEP_MINUTES": 10})
        self.assertEqual((md["END_DATE"], md["STEP_MINUTES"], md["RANGE_DAYS"]),
                         ("2026-06-01", "10", "1"))
        out = os.path.join(self.dir, "progress.tif")
        p = T.run(["gdal_translate", "-q"] + T.oo_args(dict(oo, PROGRESS="yes")) +
                  [T.conn(self.dem), out])
        print(p.stderr.strip())
        m = re.search(r"TERRASHADE: computing insolation of 64 x 64 cells: 0((?:\.\.\.\d+)+)",
                      p.stderr)
        self.assertIsNotNone(m, p.stderr)
        self.assertEqual([int(v) for v in m.group(1).split("...")[1:]],
                         list(range(10, 101, 10)))

    def test_one_day_is_unchanged(self):
        """DATE: 5-minute steps unless given, no range items, and a range of that
        one day at the same step within the interpolation's error."""
        day = {"PRODUCT": "sunhours", "DATE": "2026-03-20", "TIMEZONE": "-05:00"}
        a = self.product(day, band=1)
        b = self.product(dict(day, STEP_MINUTES=5), band=1)
        np.testing.assert_array_equal(a, b)
        md = meta(T.conn(self.dem), day)
        self.assertEqual(md["STEP_MINUTES"], "5")
        self.assertNotIn("RANGE_DAYS", md)
        # nor a range's own settings (until session 49: DAY_INTERVAL=14 and
        # HORIZON_DIRECTIONS=64 on one day)
        self.assertNotIn("DAY_INTERVAL", md)
        self.assertNotIn("HORIZON_DIRECTIONS", md)
        self.assertEqual(md["DAY_END"], "2026-03-21T00:00:00-05:00")
        c = self.product({"PRODUCT": "sunhours", "START_DATE": "2026-03-20",
                          "TIMEZONE": "-05:00", "STEP_MINUTES": 5}, band=1)
        mean_rel, _, max_abs, m = relative(c, a)
        print("one day as a range vs DATE, 5-min steps: mean |diff| %.4f %%, max %.3f h of "
              "the mean %.2f h" % (100 * mean_rel, max_abs, m))
        self.assertLessEqual(mean_rel, 0.004)
        self.assertLessEqual(max_abs, 1.0)

    def test_start_azimuth_turns_the_sky_only(self):
        """START_AZIMUTH turns insolation's sky term (DIRECTIONS), not the
        HORIZON_DIRECTIONS planes the sun's beam is read from: until
        session 58 it turned those too, and a range's beam changed with it
        (by up to 336 Wh/m^2 in three days, session 58's audit) and differed
        from sunhours', which takes no START_AZIMUTH. The beam is now the
        same bits whatever START_AZIMUTH; the diffuse term from planes the
        stream sweeps anyway (5.625 = plane 1 of 64: every fourth plane
        from there) is the one of sky sweeps of its own (HORIZON_DIRECTIONS
        60: none shared), and a range of one day's is that day's (DATE)."""
        rng = {"PRODUCT": "insolation", "START_DATE": "2026-06-01", "END_DATE": "2026-06-03",
               "TIMEZONE": "-05:00", "DAY_INTERVAL": 1}
        base = self.product(rng)
        for start in (10, 5.625, 191.25):
            turned = self.product(dict(rng, START_AZIMUTH=start))
            with self.subTest(start=start):
                np.testing.assert_array_equal(turned[1], base[1])  # the beam
                self.assertGreater(np.nanmax(np.abs(turned[2] - base[2])), 0.1)
        shared = self.product(dict(rng, START_AZIMUTH=5.625))
        own = self.product(dict(rng, START_AZIMUTH=5.625, HORIZON_DIRECTIONS=60))
        np.testing.assert_allclose(shared[2], own[2], rtol=1e-5)
        one = {"PRODUCT": "insolation", "TIMEZONE": "-05:00", "STEP_MINUTES": 30,
               "START_AZIMUTH": 5.625}
        day = self.product(dict(one, DATE="2026-06-02"))
        as_range = self.product(dict(one, START_DATE="2026-06-02"))
        np.testing.assert_allclose(as_range[2], day[2], rtol=1e-5)

    def test_long_interval_warns(self):
        """A DAY_INTERVAL over 61 days over a range that long: one computed
        day stands for a stretch of the seasons, so a warning (a year at 365
        read 30 % more sun hours at Bern than at 14); none at the default,
        nor over a month, whatever the interval."""
        year = ["PRODUCT=sunhours", "START_DATE=2026-01-01", "END_DATE=2026-12-31",
                "TIMEZONE=-05:00"]
        for interval, warns in ((91, True), (365, True), (61, False), (14, False)):
            p = T.run(["gdalinfo"] + [a for o in year + ["DAY_INTERVAL=%d" % interval]
                                      for a in ("-oo", o)] + [T.conn(self.dem)])
            self.assertEqual("computes one day of every" in p.stderr, warns, p.stderr)
        p = T.run(["gdalinfo", "-oo", "PRODUCT=sunhours", "-oo", "START_DATE=2026-06-01",
                   "-oo", "END_DATE=2026-06-30", "-oo", "TIMEZONE=-05:00", "-oo",
                   "DAY_INTERVAL=100", T.conn(self.dem)])
        self.assertNotIn("computes one day of every", p.stderr)

    def test_polar_edge_warns(self):
        """A block of days across the edge of a polar night or midnight
        sun is counted from one day whose sun hours differ from its other
        days' by more than the seasons' curve (12 days ending in the polar
        night at 70 N read 6.2 h against 10.5 h): a warning whose flat
        ground figures are the product's own on a flat plane at interval 14
        and 1; none for a whole year there (-0.2 %), nor at 46.5 N."""
        cases = [(70.0, "2026-11-20", "2026-12-01", True),
                 (70.0, "2026-05-10", "2026-06-01", True),
                 (-78.0, "2026-04-20", "2026-05-10", True),
                 # a whole polar night within the block, its first and last
                 # days with sun: unwarned when only those two were looked at
                 (67.5, "2026-12-15", "2026-12-28", True),
                 (78.0, "2026-01-01", "2026-12-31", False),
                 (46.5, "2026-01-01", "2026-12-31", False)]
        for lat, start, end, warns in cases:
            with self.subTest(lat=lat, start=start):
                dem = flat_dem(os.path.join(self.dir, "flat%g.tif" % lat), lat, 20.0)
                oo = {"PRODUCT": "sunhours", "START_DATE": start, "END_DATE": end,
                      "TIMEZONE": "+01:00"}
                p = T.run(["gdalinfo"] + [a for kv in oo.items()
                                          for a in ("-oo", "%s=%s" % kv)] + [T.conn(dem)])
                self.assertEqual("crosses" in p.stderr or "cross the edge" in p.stderr,
                                 warns, p.stderr)
                if not warns:
                    continue
                sampled = T.read(T.conn(dem), 1, oo).mean()
                every = T.read(T.conn(dem), 1, dict(oo, DAY_INTERVAL=1)).mean()
                m = re.search(r"total is [-+]\d+ % off \(([-+][\d.]+) of ([\d.]+) hours\)",
                              p.stderr)
                self.assertIsNotNone(m, p.stderr)
                print("latitude %g, %s to %s: interval 14 %.1f h, every day %.1f h; warned: %s of "
                      "%s" % (lat, start, end, sampled, every, m.group(1), m.group(2)))
                self.assertAlmostEqual(float(m.group(2)), every, delta=0.05)
                self.assertAlmostEqual(float(m.group(1)), sampled - every, delta=0.05)

    def test_bad_input(self):
        zone = ["TIMEZONE=-05:00"]
        cases = [
            (["PRODUCT=sunhours", "END_DATE=2026-03-21"] + zone,
             "END_DATE=2026-03-21 needs START_DATE"),
            (["PRODUCT=sunhours", "START_DATE=2026-03-21", "END_DATE=2026-03-19"] + zone,
             "END_DATE=2026-03-19 is before START_DATE=2026-03-21"),
            (["PRODUCT=sunhours", "START_DATE=2026-03-19", "DAY_INTERVAL=0"] + zone,
             "DAY_INTERVAL must be between 1 and 366, got 0"),
            (["PRODUCT=insolation", "START_DATE=2026-03-19", "HORIZON_DIRECTIONS=2"] + zone,
             "HORIZON_DIRECTIONS must be between 4 and 3600, got 2"),
            (["PRODUCT=sunhours", "START_DATE=2026-03-19", "DATE=2026-03-19"] + zone,
             "give DATE (one day) or START_DATE (a date range), not both"),
            (["PRODUCT=sunhours", "START_DATE=2026-03-19", "DATETIME=2026-03-19T12:00Z"],
             "give DATETIME (its day) or START_DATE (a date range), not both"),
            (["PRODUCT=daycycle", "START_DATE=2026-03-19"] + zone,
             "applies to PRODUCT=sunhours and PRODUCT=insolation, not to PRODUCT=daycycle: "
             "give its day as DATE"),
            (["PRODUCT=farshadow", "START_DATE=2026-03-19", "END_DATE=2026-03-20"] + zone,
             "not to PRODUCT=farshadow"),
            (["PRODUCT=shade", "START_DATE=2026-03-19"] + zone, "not to PRODUCT=shade"),
            (["PRODUCT=sunhours", "START_DATE=2026-03-19"], "START_DATE=2026-03-19 needs "
             "TIMEZONE"),
            (["PRODUCT=sunhours", "START_DATE=2026-02-30"] + zone, "START_DATE"),
            (["PRODUCT=sunhours", "DATE=2026-03-19", "DAY_INTERVAL=7"] + zone,
             "DAY_INTERVAL applies to a date range"),
            (["PRODUCT=insolation", "DATE=2026-03-19", "HORIZON_DIRECTIONS=128"] + zone,
             "HORIZON_DIRECTIONS applies to a date range"),
            (["PRODUCT=sunhours", "START_DATE=1900-01-01", "END_DATE=2026-01-01"] + zone,
             "a century"),
            # a per-cell sun over a range (refused at open too, below)
            (["PRODUCT=sunhours", "START_DATE=2026-03-19", "SUN_POSITION=per_cell"] + zone,
             "SUN_POSITION=per_cell is not supported over a date range (START_DATE)"),
        ]
        # refused at open, as the other combinations: gdalinfo fails too
        p = T.run(["gdalinfo", "-oo", "PRODUCT=insolation", "-oo", "START_DATE=2026-03-19",
                   "-oo", "SUN_POSITION=per_cell"] + [a for o in zone for a in ("-oo", o)]
                  + [T.conn(self.dem)], ok=False)
        self.assertIn("SUN_POSITION=per_cell is not supported over a date range", p.stderr)
        out = os.path.join(self.dir, "bad.tif")
        for oo, text in cases:
            with self.subTest(oo=oo):
                p = T.run(["gdal_translate", "-q"] + [a for o in oo for a in ("-oo", o)] +
                          [T.conn(self.dem), out], ok=False)
                print("%-75s -> %s" % (" ".join(oo), p.stderr.strip().splitlines()[0][:160]))
                self.assertIn(text, p.stderr)
                self.assertIn("TERRASHADE", p.stderr)
            if os.path.exists(out):
                os.remove(out)
        # the sun's years (-2000 to 6000) at both ends of the day or range, at
        # open: a day ending past them opened, then failed on the first read
        # (the instant in UTC named: a day of 6000-12-31 west of Greenwich
        # ends in 6001, which the Julian day alone did not show)
        for oo, text in ((["PRODUCT=sunhours", "DATE=6000-12-31", "TIMEZONE=-01:00"],
                          "DATE: The instant 6001-01-01 01:00 UTC (Julian day"),
                         (["PRODUCT=insolation", "DATE=6001-01-01", "TIMEZONE=+01:00"],
                          "DATE: The instant 6001-01-01 23:00 UTC (Julian day"),
                         (["PRODUCT=sunhours", "START_DATE=6000-12-01", "END_DATE=6001-01-05",
                           "TIMEZONE=Z"], "END_DATE (the range's end): The instant 6001-01-06")):
            with self.subTest(oo=oo):
                p = T.run(["gdalinfo"] + [a for o in oo for a in ("-oo", o)] +
                          [T.conn(self.dem)], ok=False)
                self.assertIn(text, p.stderr)
                self.assertIn("must lie between the years -2000 and 6000", p.stderr)
        # a day that ends at the limit itself computes (its steps sample their
        # middles, before it)
        md = meta(T.conn(self.dem), {"PRODUCT": "sunhours", "DATE": "6000-12-31",
                                     "TIMEZONE": "Z", "STEP_MINUTES": 60})
        self.assertEqual(md["DAY_END"], "6001-01-01T00:00:00Z")
        # year 0 is a year of the range as of DATE (refused until session 49)
        md = meta(T.conn(self.dem), {"PRODUCT": "sunhours", "START_DATE": "0000-01-01",
                                     "END_DATE": "0000-01-10", "TIMEZONE": "Z"})
        self.assertEqual(md["RANGE_DAYS"], "10")
        # a DEM without a geotransform: the sentence names START_DATE
        nogt = os.path.join(self.dir, "nogt.tif")
        ds = gdal.GetDriverByName("GTiff").Create(nogt, 8, 8, 1, gdal.GDT_Float32)
        ds = None
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=sunhours", "-oo",
                   "START_DATE=2026-03-19", "-oo", "TIMEZONE=Z", T.conn(nogt), out], ok=False)
        self.assertIn("START_DATE needs a georeferenced DEM", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
