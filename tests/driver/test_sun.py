"""The sun over a day (issue 5, items 3 and 5); the sun from DATETIME and
bad dates are test_sun_datetime.py's.

- sunhours on a flat plane is the astronomical day length within one step
  (against NOAA's sunrise equation, an independent reference) at latitudes
  from the equator to the Arctic circle; with SUNHOURS_RULE=fraction it is
  the time the sun's centre is up; per cell on a large extent
  (SUN_POSITION=per_cell), 0 in the polar night, 24 in the polar day; at
  the centre on such an extent, a warning that says so;
- insolation is beam + diffuse, plausible in size, larger on south slopes
  in winter; daycycle bands carry their time and sun and add up to sunhours
  with SUNHOURS_RULE=fraction;

test_year.py imports flat_dem (tsdriver's) and noaa_day_length from here.
"""
import math
import os
import unittest

import tsdriver as T
from tsdriver import flat_dem, gdal, np


def noaa_day_length(lat, lon, year, month, day, zenith=90.833):
    """Hours between sunrise and sunset (sun's centre at `zenith`: 90.833 =
    upper limb on the horizon with refraction) by NOAA's solar calculator
    equations (Meeus), declination at local solar noon. None in polar
    night or day."""
    a = (14 - month) // 12
    y, m = year + 4800 - a, month + 12 * a - 3
    jdn = day + (153 * m + 2) // 5 + 365 * y + y // 4 - y // 100 + y // 400 - 32045
    jd = jdn - 0.5 + (12.0 - lon / 15.0) / 24.0
    jc = (jd - 2451545.0) / 36525.0
    L = (280.46646 + jc * (36000.76983 + jc * 0.0003032)) % 360
    M = 357.52911 + jc * (35999.05029 - 0.0001537 * jc)
    r = math.radians
    C = (math.sin(r(M)) * (1.914602 - jc * (0.004817 + 0.000014 * jc))
         + math.sin(r(2 * M)) * (0.019993 - 0.000101 * jc)
         + math.sin(r(3 * M)) * 0.000289)
    omega = 125.04 - 1934.136 * jc
    app = L + C - 0.00569 - 0.00478 * math.sin(r(omega))
    eps0 = 23 + (26 + (21.448 - jc * (46.815 + jc * (0.00059 - jc * 0.001813))) / 60) / 60
    eps = eps0 + 0.00256 * math.cos(r(omega))
    decl = math.degrees(math.asin(math.sin(r(eps)) * math.sin(r(app))))
    c = (math.cos(r(zenith)) / (math.cos(r(lat)) * math.cos(r(decl)))
         - math.tan(r(lat)) * math.tan(r(decl)))
    if abs(c) > 1:
        return None
    return 8 * math.degrees(math.acos(c)) / 60.0


class Sun(T.TempDirCase):
    # ------------------------------------------------------------- sunhours

    def test_sunhours_flat_plane_is_the_day_length(self):
        """A step counts while any of the disk is up, so a flat plane gets
        sunrise to sunset (upper limb, refraction) within one 5-minute step,
        up to the long days and short days near the Arctic circle; weighted
        by the disk fraction it gets the time the centre is up."""
        cases = [(46.5, 7.9, "2026-06-21", "+02:00"), (46.5, 7.9, "2026-12-21", "+01:00"),
                 (-33.9, 18.4, "2026-06-21", "+02:00"), (0.2, -78.5, "2026-03-20", "-05:00"),
                 (36.6, -84.2, "2026-09-01", "-04:00"), (64.1, -21.9, "2026-06-01", "Z"),
                 (64.1, -21.9, "2026-12-21", "Z"), (-62.2, -58.9, "2026-06-21", "-03:00")]
        for lat, lon, date, tz in cases:
            with self.subTest(lat=lat, date=date):
                dem = flat_dem(os.path.join(self.dir, "flat.tif"), lat, lon)
                oo = {"PRODUCT": "sunhours", "DATE": date, "TIMEZONE": tz}
                h = T.read(T.conn(dem), 1, oo)
                f = T.read(T.conn(dem), 1, dict(oo, SUNHOURS_RULE="fraction"))
                y, mo, d = map(int, date.split("-"))
                astro = noaa_day_length(lat, lon, y, mo, d)
                centre = noaa_day_length(lat, lon, y, mo, d, 90.5667)
                print("flat plane at %5.1f, %s: sun hours %.4f..%.4f h, NOAA day length "
                      "%.4f h (%+.2f min); SUNHOURS_RULE=fraction %.4f h, centre up "
                      "%.4f h (%+.2f min)"
                      % (lat, date, h.min(), h.max(), astro, (h.mean() - astro) * 60,
                         f.mean(), centre, (f.mean() - centre) * 60))
                self.assertLess(h.max() - h.min(), 1e-3)
                self.assertLess(f.max() - f.min(), 1e-3)
                self.assertLessEqual(abs(h.mean() - astro) * 60, 5.0)  # one step
                self.assertLessEqual(abs(f.mean() - centre) * 60, 5.0)
                self.assertLess(f.mean(), h.mean())

    def test_sunhours_step_and_datetime(self):
        """STEP_MINUTES changes the sampling only; DATETIME names the day in
        its own offset (or TIMEZONE's)."""
        dem = flat_dem(os.path.join(self.dir, "flat.tif"), 46.5, 7.9)
        a = T.read(T.conn(dem), 1, {"PRODUCT": "sunhours", "DATE": "2026-06-21",
                                    "TIMEZONE": "+02:00", "STEP_MINUTES": 1})
        b = T.read(T.conn(dem), 1, {"PRODUCT": "sunhours",
                                    "DATETIME": "2026-06-21T23:59:00+02:00",
                                    "STEP_MINUTES": 1})
        np.testing.assert_array_equal(a, b)
        c = T.read(T.conn(dem), 1, {"PRODUCT": "sunhours",
                                    "DATETIME": "2026-06-21T21:59:00Z", "TIMEZONE": "+02:00",
                                    "STEP_MINUTES": 1})
        np.testing.assert_array_equal(a, c)
        # a leap second ends its day (as the next day's first second it
        # named the next day); a fraction's nines stay within their second
        for leap in ("2016-12-31T23:59:60Z", "2017-01-01T00:59:60.5+01:00",
                     "2016-12-31T23:59:59.99999999999999999Z"):
            ds = gdal.OpenEx(T.conn(dem), open_options=[
                "PRODUCT=sunhours", "DATETIME=" + leap, "TIMEZONE=Z"])
            self.assertIsNotNone(ds, leap)
            self.assertEqual(ds.GetMetadataItem("DAY_START"), "2016-12-31T00:00:00Z", leap)
        with self.assertRaisesRegex(RuntimeError, "only ends a UTC day"):
            gdal.OpenEx(T.conn(dem), open_options=[
                "PRODUCT=sunhours", "DATETIME=2026-06-21T12:00:60+02:00"])
        e = T.read(T.conn(dem), 1, {"PRODUCT": "sunhours", "DATE": "2026-06-21",
                                    "TIMEZONE": "+02:00", "STEP_MINUTES": 30})
        print("Bern, 2026-06-21: %.4f h (1-minute steps), %.4f h (30-minute steps)"
              % (a.mean(), e.mean()))
        self.assertLessEqual(abs(a.mean() - e.mean()), 0.5)

    def test_sunhours_jacksboro(self):
        h = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": "sunhours", "DATE": "2026-12-21",
                                            "TIMEZONE": "-05:00"})
        astro = noaa_day_length(36.59, -84.25, 2026, 12, 21)
        print("jacksboro, 2026-12-21: sun hours %.2f..%.2f (mean %.2f) h, day length "
              "%.2f h" % (h.min(), h.max(), h.mean(), astro))
        self.assertLess(h.max(), astro + 0.3)  # ridge tops see a little more
        self.assertLess(h.min(), astro - 1.5)  # valleys lose hours
        # steep north faces (> ~30 deg) see no sun at all in December
        self.assertGreaterEqual(h.min(), 0)
        self.assertLess(np.mean(h == 0), 0.01)
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=sunhours", "DATE=2026-12-21", "TIMEZONE=-05:00"])
        self.assertEqual(ds.GetRasterBand(1).GetUnitType(), "hour")
        m = ds.GetMetadata()
        self.assertEqual(m["DAY_START"], "2026-12-21T00:00:00-05:00")
        self.assertEqual(m["DAY_END"], "2026-12-22T00:00:00-05:00")
        self.assertNotIn("SUN_AZIMUTH", m)  # no single sun over a day

    def test_polar_night_and_day(self):
        dem = flat_dem(os.path.join(self.dir, "svalbard.tif"), 78.2, 15.6, z=10.0)
        night = T.read(T.conn(dem), 1, {"PRODUCT": "sunhours", "DATE": "2026-12-21",
                                        "TIMEZONE": "+01:00"})
        day = T.read(T.conn(dem), 1, {"PRODUCT": "sunhours", "DATE": "2026-06-21",
                                      "TIMEZONE": "+02:00"})
        print("Longyearbyen: %.3f h on 2026-12-21, %.3f h on 2026-06-21"
              % (night.max(), day.min()))
        self.assertEqual(night.max(), 0.0)
        self.assertAlmostEqual(day.min(), 24.0, places=3)
        ins = T.read(T.conn(dem), 1, {"PRODUCT": "insolation", "DATE": "2026-12-21",
                                      "TIMEZONE": "+01:00"})
        self.assertEqual(ins.max(), 0.0)
        with self.assertRaises(RuntimeError) as e:
            gdal.OpenEx(T.conn(dem), open_options=["PRODUCT=farshadow", "DATE=2026-12-21",
                                                   "TIMEZONE=+01:00"])
        print(e.exception)
        self.assertIn("the sun does not rise", str(e.exception))

    def test_per_cell_sun_on_a_large_extent(self):
        """A flat DEM from 56 N to 40 N: with SUN_POSITION=per_cell each row
        gets its own latitude's day length; at the centre, one for all."""
        n, cell = 32, 0.5
        gt = (0.0, cell, 0, 56.0, 0, -cell)
        dem = T.write_tif(os.path.join(self.dir, "europe.tif"),
                          np.zeros((n, n), np.float32), gt, 4326)
        oo = {"PRODUCT": "sunhours", "DATE": "2026-06-21", "TIMEZONE": "Z"}
        centre = T.read(T.conn(dem), 1, oo)
        per = T.read(T.conn(dem), 1, dict(oo, SUN_POSITION="per_cell"))
        self.assertLess(centre.max() - centre.min(), 1e-3)
        for row in (0, n // 2, n - 1):
            lat = 56.0 - (row + 0.5) * cell
            want = noaa_day_length(lat, 8.0, 2026, 6, 21)
            print("per cell, row %2d (lat %.2f): %.3f h, NOAA %.3f h; centre mode "
                  "%.3f h" % (row, lat, per[row, n // 2], want, centre[row, n // 2]))
            self.assertLessEqual(abs(per[row, n // 2] - want) * 60, 5.0)
        self.assertGreater(per[0].mean(), per[-1].mean() + 1.5)

    def test_per_cell_sun_over_the_world(self):
        """A world DEM of 4-degree cells: the suns' azimuths span the whole
        circle at every step. The day keeps its horizon planes across the
        steps (docs/day-cycle.md); with MAX_MEMORY leaving room for a few,
        the rest swept again at each step, every value is the same."""
        n_x, n_y = 90, 45
        yy, xx = np.mgrid[0:n_y, 0:n_x]
        z = (2000 * (1 + np.sin(xx * 0.7) * np.cos(yy * 0.9))).astype(np.float32)
        dem = T.write_tif(os.path.join(self.dir, "world.tif"), z,
                          (-180.0, 4.0, 0, 90.0, 0, -4.0), 4326)
        for product, band in (("sunhours", 1), ("daycycle", 7)):
            oo = {"PRODUCT": product, "DATE": "2026-06-21", "TIMEZONE": "Z",
                  "STEP_MINUTES": "60", "SUN_POSITION": "per_cell"}
            kept = T.read(T.conn(dem), band, oo)
            few = T.read(T.conn(dem), band, dict(oo, MAX_MEMORY="1"))
            self.assertTrue(np.array_equal(kept, few, equal_nan=True), product)
        # the June solstice: the Arctic has no night, the Antarctic no day
        self.assertTrue(np.all((kept >= 0) & (kept <= 1)))
        hours = T.read(T.conn(dem), 1, dict(oo, PRODUCT="sunhours"))
        self.assertGreater(hours[1].mean(), 20.0)
        self.assertLess(hours[-2].mean(), 1.0)
        self.assertTrue(np.all((hours >= 0) & (hours <= 24)))

    def test_per_cell_sun_on_coarse_cells_is_each_cells_sun(self):
        """A flat DEM of 3-degree cells from 50 S to 80 S, 0 to 90 E, on
        2026-06-01 (the sun grazes the horizon there): each cell gets the sun
        hours of a small DEM at its centre within one step. The lattice was 3 x
        3 nodes 43 degrees apart, and it interpolated refracted elevations
        across the refraction's cut-off (0.6 deg at sunrise): cells lost up to
        1.8 h."""
        n, cell = (10, 30), 3.0
        dem = T.write_tif(os.path.join(self.dir, "south.tif"), np.zeros(n, np.float32),
                          (0.0, cell, 0, -50.0, 0, -cell), 4326)
        oo = {"PRODUCT": "sunhours", "DATE": "2026-06-01", "TIMEZONE": "Z",
              "STEP_MINUTES": 10}
        per = T.read(T.conn(dem), 1, dict(oo, SUN_POSITION="per_cell"))
        worst = 0.0
        for row in range(0, 7):
            for col in (0, 10, 15, 29):
                lat, lon = -50.0 - (row + 0.5) * cell, (col + 0.5) * cell
                one = T.read(T.conn(flat_dem(os.path.join(self.dir, "one.tif"), lat, lon,
                                             n=4)), 1, oo)
                worst = max(worst, abs(per[row, col] - one.mean()))
        print("3-degree cells, 50-71 S, per cell: sun hours within %.3f h of each cell's "
              "own" % worst)
        self.assertLessEqual(worst, 10 / 60 + 1e-4)
        self.assertGreater(per[:6].min(), 3.0)  # the sun rises on every row to 66.5 S

    def test_centre_sun_on_a_large_extent_warns(self):
        """SUN_POSITION=center on a DEM that reaches more than a degree of
        arc from its centre: a warning that says how far and what to do
        (SUN_POSITION=per_cell where the product and method take it, else
        crop); none on a small extent, with per_cell, or with the sun given
        by SUN_AZIMUTH / SUN_ELEVATION (no place is needed)."""
        n, cell = 32, 0.5
        wide = T.write_tif(os.path.join(self.dir, "wide.tif"),
                           np.zeros((n, n), np.float32), (0.0, cell, 0, 56.0, 0, -cell), 4326)
        small = flat_dem(os.path.join(self.dir, "small.tif"), 47.0, 8.0)
        out = os.path.join(self.dir, "out.tif")
        day = {"PRODUCT": "sunhours", "DATE": "2026-06-21", "TIMEZONE": "Z"}
        instant = {"DATETIME": "2026-06-21T10:00:00Z"}

        def arc(lon1, lat1, lon2, lat2):
            r = math.radians
            c = (math.sin(r(lat1)) * math.sin(r(lat2)) +
                 math.cos(r(lat1)) * math.cos(r(lat2)) * math.cos(r(lon2 - lon1)))
            return math.degrees(math.acos(c))

        reach = max(arc(8.0, 48.0, lon, lat) for lon in (0.25, 15.75) for lat in (55.75, 40.25))
        self.assertAlmostEqual(reach, 9.5, delta=0.3)
        for oo, advice in ((day, "SUN_POSITION=per_cell computes the sun across the DEM"),
                           (instant, "SUN_POSITION=per_cell"),
                           (dict(instant, METHOD="shm"), "Crop the DEM"),
                           (dict(instant, METHOD="shadowmap"), "Crop the DEM"),
                           (dict(instant, LIGHT_RADIUS=1), "Crop the DEM"),
                           (dict(instant, PRODUCT="farshadow", FAR_THRESHOLD=8), "Crop the DEM")):
            p = T.run(["gdal_translate", "-q"] + T.oo_args(oo) + [T.conn(wide), out])
            # from the centre (8 E, 48 N) to the farthest corner cell's centre
            self.assertIn("the DEM reaches %.1f degrees of arc from its centre" % reach,
                          p.stderr)
            self.assertIn(advice, p.stderr)
            self.assertEqual(p.stderr.count("degrees of arc from its centre"), 1, p.stderr)
        for dem, oo in ((small, day), (small, instant),
                        (wide, dict(day, SUN_POSITION="per_cell")),
                        (wide, {"SUN_AZIMUTH": 135, "SUN_ELEVATION": 30})):
            p = T.run(["gdal_translate", "-q"] + T.oo_args(oo) + [T.conn(dem), out])
            self.assertNotIn("degrees of arc", p.stderr)

    def test_centre_sun_near_a_pole_warns_of_the_turn(self):
        """A geographic DEM at 85 N, 0.1 x 4 degrees, lies within 0.2 degrees
        of arc of its centre, but its columns' meridians turn by 2 degrees
        against each other, and with them the sun's azimuth on the grid: it
        warns (it did not). A UTM DEM as far from its central meridian at 80 N
        does not (grid north turns with the meridians), nor per_cell."""
        polar = T.write_tif(os.path.join(self.dir, "polar.tif"),
                            np.full((100, 400), 100.0, np.float32),
                            (0.0, 0.01, 0, 85.05, 0, -0.001), 4326)
        utm = T.write_tif(os.path.join(self.dir, "utm80.tif"),
                          np.full((100, 100), 100.0, np.float32),
                          (600000.0, 30, 0, 8880000.0, 0, -30), 32633)
        out = os.path.join(self.dir, "out.tif")
        instant = {"PRODUCT": "shadow", "DATETIME": "2026-03-25T12:00:00Z"}
        p = T.run(["gdal_translate", "-q"] + T.oo_args(instant) + [T.conn(polar), out])
        print(p.stderr.strip())
        self.assertIn("the DEM's meridians turn by up to 2.0 degrees against its grid from "
                      "its centre's (0.2 degrees of arc away)", p.stderr)
        self.assertIn("SUN_POSITION=per_cell computes the sun across the DEM", p.stderr)
        for dem, oo in ((polar, dict(instant, SUN_POSITION="per_cell")), (utm, instant)):
            p = T.run(["gdal_translate", "-q"] + T.oo_args(oo) + [T.conn(dem), out])
            self.assertNotIn("Warning", p.stderr)

    # ------------------------------------------------------------ insolation

    def test_insolation(self):
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=insolation", "DATE=2026-12-21", "TIMEZONE=-05:00",
            "DIRECTIONS=8", "STEP_MINUTES=10"])
        self.assertEqual(ds.RasterCount, 3)
        names = [ds.GetRasterBand(b).GetDescription() for b in (1, 2, 3)]
        self.assertEqual(names, ["insolation global", "insolation beam",
                                 "insolation diffuse"])
        self.assertEqual(ds.GetRasterBand(1).GetUnitType(), "Wh/m2")
        self.assertIn("ESRA", ds.GetMetadataItem("CLEAR_SKY_MODEL"))
        tot, beam, dif = (ds.GetRasterBand(b).ReadAsArray().astype(float) for b in (1, 2, 3))
        np.testing.assert_allclose(tot, beam + dif, rtol=1e-5, atol=1e-2)
        # slopes facing south get more than slopes facing north in December
        dem, gt, _ = T.read_dem(T.JACKSBORO)
        dy = np.gradient(dem.astype(float), axis=0)  # > 0: heights grow southward
        south = dy < -15    # falls to the south: faces south
        north = dy > 15
        print("jacksboro, 2026-12-21: global %.0f..%.0f Wh/m2; south faces %.0f, north "
              "faces %.0f; diffuse %.0f..%.0f" % (tot.min(), tot.max(), tot[south].mean(),
                                                  tot[north].mean(), dif.min(), dif.max()))
        self.assertGreater(tot[south].mean(), 1.5 * tot[north].mean())
        self.assertGreater(tot.min(), 0)
        self.assertLess(tot.max(), 6000)
        # a flat plane gets the clear-sky global horizontal irradiation of a
        # June day at 46.5 N: about 8 kWh/m2
        flat = flat_dem(os.path.join(self.dir, "flat.tif"), 46.5, 7.9, z=400)
        g = T.read(T.conn(flat), 1, {"PRODUCT": "insolation", "DATE": "2026-06-21",
                                     "TIMEZONE": "+02:00", "DIRECTIONS": 4})
        print("flat plane, Bern 400 m, 2026-06-21: %.0f Wh/m2" % g.mean())
        self.assertTrue(7000 < g.mean() < 9500)
        turbid = T.read(T.conn(flat), 1, {"PRODUCT": "insolation", "DATE": "2026-06-21",
                                          "TIMEZONE": "+02:00", "DIRECTIONS": 4,
                                          "LINKE_TURBIDITY": 6})
        self.assertLess(turbid.mean(), g.mean())

    # -------------------------------------------------------------- daycycle

    def test_daycycle(self):
        oo = {"PRODUCT": "daycycle", "DATE": "2026-06-21", "TIMEZONE": "-04:00",
              "STEP_MINUTES": 60}
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=["%s=%s" % kv for kv in oo.items()])
        self.assertEqual(ds.RasterCount, 24)
        b = ds.GetRasterBand(13)
        bm = b.GetMetadata()
        print("band 13:", b.GetDescription(), bm)
        self.assertEqual(b.GetDescription(), "2026-06-21T12:30:00-04:00")
        self.assertEqual(bm["TIME"], "2026-06-21T12:30:00-04:00")
        self.assertEqual(float(bm["DURATION_MINUTES"]), 60)
        self.assertGreater(float(bm["SUN_ELEVATION"]), 60)
        night = ds.GetRasterBand(1)
        self.assertLess(float(night.GetMetadataItem("SUN_ELEVATION")), -10)
        cube = T.read(T.conn(T.JACKSBORO), None, oo)
        self.assertEqual(cube.shape, (24, 344, 403))
        self.assertEqual(np.nanmax(cube[0]), 0.0)
        self.assertGreater(np.nanmean(cube[12]), 0.95)
        # the bands are the visible fractions: their sum is the sun hours
        # weighted by the fraction, and no more than the default's
        hours = T.read(T.conn(T.JACKSBORO), 1,
                       dict(oo, PRODUCT="sunhours", SUNHOURS_RULE="fraction"))
        np.testing.assert_allclose(cube.sum(axis=0), hours, atol=1e-4)
        visible = T.read(T.conn(T.JACKSBORO), 1, dict(oo, PRODUCT="sunhours"))
        step_h = 1.0
        np.testing.assert_allclose(np.sum(cube > 0, axis=0) * step_h, visible, atol=1e-4)
        # Byte like shadow: 1 + 254 v
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "%s=%s" % kv for kv in dict(oo, OUTPUT_TYPE="Byte").items()])
        self.assertEqual(ds.GetRasterBand(13).DataType, gdal.GDT_Byte)


if __name__ == "__main__":
    unittest.main(verbosity=2)
