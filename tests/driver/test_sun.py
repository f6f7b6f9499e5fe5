"""The sun from a date and time (issue 5, items 2, 3 and 5).

- DATETIME places the sun with the SPA at the DEM's centre; the dataset
  metadata names the azimuth and elevation used; the result equals the
  product with SUN_AZIMUTH / SUN_ELEVATION set to them; a projected DEM gets
  its azimuth turned from true to grid north (meridian convergence);
- sunhours on a flat plane is the astronomical day length within one step
  (against NOAA's sunrise equation, an independent reference) at latitudes
  from the equator to the Arctic circle; with SUNHOURS_RULE=fraction it is
  the time the sun's centre is up; per cell on a large extent
  (SUN_POSITION=per_cell), 0 in the polar night, 24 in the polar day; at
  the centre on such an extent, a warning that says so;
- insolation is beam + diffuse, plausible in size, larger on south slopes
  in winter; daycycle bands carry their time and sun and add up to sunhours
  with SUNHOURS_RULE=fraction;
- bad input: malformed dates, a missing offset, latitudes beyond +/-90, a DEM
  without georeferencing, options that do not go together: clear errors.
"""
import math
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np, osr


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


def flat_dem(path, lat, lon, n=32, cell=0.0005, z=0.0):
    """A flat n x n DEM in EPSG:4326 centred at (lat, lon)."""
    gt = (lon - n * cell / 2, cell, 0, lat + n * cell / 2, 0, -cell)
    return T.write_tif(path, np.full((n, n), z, np.float32), gt, 4326)


md = T.metadata


class Sun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    # ------------------------------------------------------------ DATETIME

    def test_datetime_places_the_sun(self):
        """At solar noon of the June solstice the sun stands at 90 - lat + 23.44
        degrees, due south; the metadata says so, with the names of the values."""
        conn = T.conn(T.JACKSBORO)
        m = md(conn, {"PRODUCT": "shadow", "DATETIME": "2026-06-21T13:36:00-04:00"})
        print({k: v for k, v in m.items() if k.startswith("SUN") or "MERID" in k})
        lat = float(m["SUN_SITE_LATITUDE"])
        self.assertAlmostEqual(lat, 36.5896, places=3)
        self.assertAlmostEqual(float(m["SUN_SITE_LONGITUDE"]), -84.2458, places=3)
        self.assertAlmostEqual(float(m["SUN_ELEVATION"]), 90 - lat + 23.44, delta=0.3)
        self.assertAlmostEqual(float(m["SUN_AZIMUTH_TRUE"]), 180, delta=3)
        self.assertEqual(m["SUN_AZIMUTH"], m["SUN_AZIMUTH_TRUE"])  # geographic grid
        self.assertEqual(float(m["MERIDIAN_CONVERGENCE"]), 0)
        self.assertEqual(m["SUN_TIME"], "2026-06-21T13:36:00-04:00")
        self.assertEqual(m["DATETIME"], "2026-06-21T13:36:00-04:00")

    def test_datetime_equals_the_explicit_sun(self):
        """DATETIME gives the pixels of SUN_AZIMUTH / SUN_ELEVATION set to the
        values it reports, for shadow and shade; Z and an offset name the
        same instant; inline, the time is written without colons."""
        dt = "2026-12-21T08:40:00-05:00"
        for product in ("shadow", "shade"):
            conn = T.conn(T.JACKSBORO)
            a = T.read(conn, 1, {"PRODUCT": product, "DATETIME": dt})
            m = md(conn, {"PRODUCT": product, "DATETIME": dt})
            b = T.read(conn, 1, {"PRODUCT": product, "SUN_AZIMUTH": m["SUN_AZIMUTH"],
                                 "SUN_ELEVATION": m["SUN_ELEVATION"]})
            d = np.nanmax(np.abs(a - b))
            print("%s at %s (az %s, el %s): max |DATETIME - explicit| = %.2g, %.1f%% in "
                  "shadow" % (product, dt, m["SUN_AZIMUTH"], m["SUN_ELEVATION"], d,
                              100 * np.mean(a < (0.5 if product == "shadow" else 60))))
            self.assertLessEqual(d, 2e-3 if product == "shadow" else 1)
        z = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": "shadow",
                                            "DATETIME": "2026-12-21T13:40:00Z"})
        a = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": "shadow", "DATETIME": dt})
        np.testing.assert_array_equal(z, a)
        inline = T.read(T.conn(T.JACKSBORO, PRODUCT="shadow",
                               DATETIME="2026-12-21T084000-0500"), 1)
        np.testing.assert_array_equal(inline, a)
        inline = T.read(T.conn(T.JACKSBORO, PRODUCT="shadow", DATETIME="20261221T1340Z"), 1)
        np.testing.assert_array_equal(inline, a)

    def test_a_night_datetime_warns(self):
        """21:00 of June 21 meant in Tennessee but written with Z (UTC) puts the
        sun 10.9 degrees below the horizon: a warning with the mean solar time
        and the longitude's offset; the shadow is computed (all of it shadowed).
        Just after sunset (-1 degree, a high summit may still see it) and at
        noon there is none."""
        conn = T.conn(T.JACKSBORO)
        err = T.open_stderr(T.JACKSBORO, PRODUCT="shadow", DATETIME="2026-06-21T02:00:00Z")
        print(err.strip())
        self.assertIn("Warning 1: TERRASHADE: DATETIME=2026-06-21T02:00:00Z puts the sun's "
                      "centre 10.9 degrees below the horizon at the DEM's centre (mean solar "
                      "time 20:23 there): it is night, no terrain sees the sun, and its direct "
                      "light is nil everywhere. If that is not the time meant, check "
                      "DATETIME's offset from UTC (Z is UTC itself; mean solar time at "
                      "longitude -84.2 is UTC-05:37)", err)
        night = T.read(conn, 1, {"PRODUCT": "shadow", "DATETIME": "2026-06-21T02:00:00Z"})
        self.assertEqual(np.nanmax(night), 0)
        for dt in ("2026-06-22T01:00:00Z", "2026-06-21T12:00:00-05:00"):
            with self.subTest(dt=dt):
                self.assertNotIn("below the horizon", T.open_stderr(T.JACKSBORO, DATETIME=dt))
        # noon of the polar night: no offset would help, the warning says why
        polar = flat_dem(os.path.join(self.dir, "svalbard.tif"), 78.2, 15.6)
        for sp in ("center", "per_cell"):
            err = T.open_stderr(polar, PRODUCT="shadow", SUN_POSITION=sp,
                                DATETIME="2026-12-21T12:00:00+01:00")
            print(err.strip())
            self.assertIn("The sun stays below every horizon for 12 hours either side (polar "
                          "night): no time of that day lights the DEM", err)
            self.assertNotIn("check DATETIME's offset", err)

    def test_a_day_of_a_far_offset_warns(self):
        """A day product's TIMEZONE more than 4 hours from the mean solar time
        at the DEM's centre (modulo a day) puts its midnight in daylight:
        a warning, which no real zone gets (-05:00 and -04:00 at jacksboro,
        84.2 W; +14:00 at 157 W is 0.5 hours from it)."""
        out = os.path.join(self.dir, "zone.tif")
        day = ["-oo", "PRODUCT=sunhours", "-oo", "DATE=2026-06-21", "-oo", "STEP_MINUTES=60"]
        for tz, warns in (("+07:00", True), ("Z", True), ("-05:00", False),
                          ("-04:00", False)):
            p = T.run(["gdal_translate", "-q"] + day + ["-oo", "TIMEZONE=" + tz,
                                                        T.conn(T.JACKSBORO), out])
            self.assertEqual("hours from the mean solar time" in p.stderr, warns, (tz, p.stderr))
        line = flat_dem(os.path.join(self.dir, "line.tif"), 1.9, -157.4)
        p = T.run(["gdal_translate", "-q"] + day + ["-oo", "TIMEZONE=+14:00", T.conn(line),
                                                    out])
        self.assertNotIn("hours from the mean solar time", p.stderr)
        # the centre's solar time, not a lattice corner's (150 degrees of
        # longitude: the western corner's is 5.6 hours from -05:00)
        wide = T.write_tif(os.path.join(self.dir, "wide150.tif"), np.zeros((40, 150), np.float32),
                           (-160.0, 1.0, 0, 40.0, 0, -1.0), 4326)
        p = T.run(["gdal_translate", "-q"] + day + ["-oo", "TIMEZONE=-05:00", "-oo",
                                                    "SUN_POSITION=per_cell", T.conn(wide), out])
        self.assertNotIn("hours from the mean solar time", p.stderr)
        p = T.run(["gdal_translate", "-q"] + day + ["-oo", "TIMEZONE=-00:30", T.conn(line),
                                                    out])
        self.assertIn("TIMEZONE's offset (-00:30)", p.stderr)
        # the day of a DATETIME: its own offset (no warning until session 49)
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=sunhours", "-oo", "STEP_MINUTES=60",
                   "-oo", "DATETIME=2026-06-21T17:00:00Z", T.conn(T.JACKSBORO), out])
        self.assertIn("DATETIME's offset (+00:00) is 5.6 hours from the mean solar time", p.stderr)
        # TIMEZONE given with it sets the day: named as the one at fault
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=sunhours", "-oo", "STEP_MINUTES=60",
                   "-oo", "DATETIME=2026-06-21T12:00:00-05:00", "-oo", "TIMEZONE=+10:00",
                   T.conn(T.JACKSBORO), out])
        self.assertIn("TIMEZONE's offset (+10:00) is", p.stderr)
        # a day product without georeferencing is not told to give the sun
        # by hand, which it refuses
        nogt = os.path.join(self.dir, "nogt.tif")
        ds = gdal.GetDriverByName("GTiff").Create(nogt, 8, 8, 1, gdal.GDT_Float32)
        ds = None
        p = T.run(["gdalinfo", "-oo", "PRODUCT=sunhours", "-oo", "DATE=2026-06-21", "-oo",
                   "TIMEZONE=Z", T.conn(nogt)], ok=False)
        self.assertIn("DATE needs a georeferenced DEM", p.stderr)
        self.assertNotIn("SUN_AZIMUTH", p.stderr)
        # beyond every civil zone: +21:00 for -03:00 names the day before,
        # which modulo a day is 0 hours from Brasilia's solar time
        bra = flat_dem(os.path.join(self.dir, "bra.tif"), -15.8, -47.9)
        for tz in ("+21:00", "-23:59", "+14:30"):
            p = T.run(["gdal_translate", "-q"] + day + ["-oo", "TIMEZONE=" + tz, T.conn(bra),
                                                        out])
            self.assertIn("TIMEZONE's offset (%s) is beyond every civil time zone (-12:00 to "
                          "+14:00)" % tz, p.stderr)
        p = T.run(["gdal_translate", "-q"] + day + ["-oo", "TIMEZONE=-03:00", T.conn(bra), out])
        self.assertNotIn("TIMEZONE's offset", p.stderr)

    def test_a_per_cell_night_is_night_at_every_site(self):
        """A 20 x 20 degree DEM at dusk, per cell: the sun has set in the east
        (6.4 degrees down at the lattice's middle node) but not in the west,
        which is lit: no night warning (there was one, from that node's sun,
        with node 0's longitude). Later it has set everywhere: the warning
        gives the highest site's depth and longitude."""
        dem = os.path.join(self.dir, "wide.tif")
        T.write_tif(dem, np.full((20, 20), 100.0), [0, 1, 0, 20, 0, -1], 4326)
        opts = dict(PRODUCT="shadow", SUN_POSITION="per_cell")
        dusk = dict(opts, DATETIME="2026-03-20T17:15:00Z")
        err = T.open_stderr(dem, **dusk)
        lit = T.read(T.conn(dem), 1, dusk)
        print("dusk: %.0f%% lit; %s" % (100 * np.mean(lit > 0), err.strip()))
        self.assertGreater(np.mean(lit > 0), 0.3)
        self.assertNotIn("below the horizon", err)
        err = T.open_stderr(dem, **dict(opts, DATETIME="2026-03-20T19:30:00Z"))
        print(err.strip())
        self.assertIn("puts the sun's centre 19.9 degrees below the horizon at the highest of "
                      "the SUN_POSITION=per_cell sites (mean solar time 19:32 there)", err)
        self.assertIn("mean solar time at longitude 0.5 is UTC+00:02", err)

    def test_per_cell_site_is_the_centre(self):
        """The lattice has an odd number of nodes a side, so the middle node,
        whose sun the metadata reports, is the DEM's centre, as without
        per_cell (it was 15 cells off on jacksboro, a corner of a 20-cell
        DEM)."""
        wide = os.path.join(self.dir, "wide20.tif")
        T.write_tif(wide, np.full((20, 20), 100.0), [0, 1, 0, 20, 0, -1], 4326)
        for dem in (T.JACKSBORO, wide):
            opts = {"PRODUCT": "shadow", "DATETIME": "2026-03-20T12:00:00Z"}
            centre = md(T.conn(dem), opts)
            per = md(T.conn(dem), dict(opts, SUN_POSITION="per_cell"))
            for k in ("SUN_SITE_LONGITUDE", "SUN_SITE_LATITUDE", "SUN_ELEVATION"):
                print("%s %s: centre %s, per cell %s" % (os.path.basename(dem), k, centre[k],
                                                         per[k]))
                self.assertAlmostEqual(float(per[k]), float(centre[k]), places=6)

    def test_per_cell_datetime_on_a_small_extent(self):
        """SUN_POSITION=per_cell over jacksboro (0.3 x 0.3 deg): the sun moves
        by ~0.2 deg across it, so the shadows barely change."""
        dt = "2026-12-21T08:40:00-05:00"
        for product in ("shadow", "shade"):
            a = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": product, "DATETIME": dt})
            b = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": product, "DATETIME": dt,
                                                "SUN_POSITION": "per_cell"})
            lit_a, lit_b = a >= (0.5 if product == "shadow" else 128), \
                b >= (0.5 if product == "shadow" else 128)
            agree = np.mean(lit_a == lit_b)
            print("%s, per cell vs centre: lit/unlit agree in %.3f%% of cells, mean %.4f vs "
                  "%.4f" % (product, 100 * agree, a.mean(), b.mean()))
            self.assertGreater(agree, 0.97)

    def test_grid_north_of_a_projected_dem(self):
        """jacksboro in UTM 17N lies west of the central meridian: grid north
        is west of true north by about (lon - lon0) sin(lat) ~ 1.85 deg. The
        driver turns the sun's true azimuth into the grid's and says by how
        much; the true azimuth matches the geographic DEM's."""
        utm = T.jacksboro_utm(self.dir)
        dt = "2026-06-21T09:00:00-04:00"
        mu = md(T.conn(utm), {"PRODUCT": "shadow", "DATETIME": dt})
        mg = md(T.conn(T.JACKSBORO), {"PRODUCT": "shadow", "DATETIME": dt})
        lat, lon = float(mu["SUN_SITE_LATITUDE"]), float(mu["SUN_SITE_LONGITUDE"])
        wgs, u = osr.SpatialReference(), osr.SpatialReference()
        wgs.ImportFromEPSG(4326)
        u.ImportFromEPSG(32617)
        for s in (wgs, u):
            s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        ct = osr.CoordinateTransformation(wgs, u)
        x0, y0, _ = ct.TransformPoint(lon, lat)
        x1, y1, _ = ct.TransformPoint(lon, lat + 0.01)
        north = math.degrees(math.atan2(x1 - x0, y1 - y0))
        conv = float(mu["MERIDIAN_CONVERGENCE"])
        print("UTM: convergence %.4f deg (osr: %.4f, (lon + 81) sin(lat): %.4f); sun true "
              "%s, grid %s; geographic DEM: %s" % (
                  conv, -north, (lon + 81) * math.sin(math.radians(lat)),
                  mu["SUN_AZIMUTH_TRUE"], mu["SUN_AZIMUTH"], mg["SUN_AZIMUTH"]))
        self.assertAlmostEqual(conv, -north, delta=0.01)
        self.assertAlmostEqual(conv, (lon + 81) * math.sin(math.radians(lat)), delta=0.05)
        self.assertAlmostEqual(float(mu["SUN_AZIMUTH"]),
                               (float(mu["SUN_AZIMUTH_TRUE"]) - conv) % 360, places=4)
        self.assertAlmostEqual(float(mu["SUN_AZIMUTH_TRUE"]), float(mg["SUN_AZIMUTH"]),
                               delta=0.05)
        self.assertAlmostEqual(float(mu["SUN_ELEVATION"]), float(mg["SUN_ELEVATION"]),
                               delta=0.05)

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
            self.assertEqual(p.stderr.count("Warning"), 1, p.stderr)
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

    # ------------------------------------------------------------ bad input

    def test_bad_input(self):
        nogt = os.path.join(self.dir, "nogt.tif")
        ds = gdal.GetDriverByName("GTiff").Create(nogt, 8, 8, 1, gdal.GDT_Float32)
        ds.GetRasterBand(1).Fill(100)
        ds = None
        nocrs = T.write_tif(os.path.join(self.dir, "nocrs.tif"),
                            np.zeros((8, 8), np.float32), (0, 30, 0, 0, 0, -30), None)
        polar = T.write_tif(os.path.join(self.dir, "beyond.tif"),
                            np.zeros((8, 8), np.float32), (0, 1, 0, 94, 0, -1), 4326)
        J = T.conn(T.JACKSBORO)
        day = ["DATE=2026-06-21", "TIMEZONE=+02:00"]
        cases = [
            (J, ["PRODUCT=shadow", "DATETIME=2026-13-01T10:00Z"], "month"),
            (J, ["PRODUCT=shadow", "DATETIME=yesterday"], "Cannot read 'yesterday'"),
            (J, ["PRODUCT=shadow", "DATETIME=2026-06-21T07:30:00"],
             "an offset from UTC is required"),
            (J, ["PRODUCT=shadow", "DATETIME=2026-02-29T07:30:00Z"], "DATETIME"),
            (J, ["PRODUCT=shadow", "DATETIME=2026-06-21T25:00:00Z"], "DATETIME"),
            (J, ["PRODUCT=sunhours", "DATE=2026-02-30", "TIMEZONE=Z"], "there is no day 30"),
            (J, ["PRODUCT=sunhours", "DATE=21/06/2026", "TIMEZONE=Z"], "YYYY-MM-DD"),
            (J, ["PRODUCT=sunhours", "DATE=2026-06-21"], "needs TIMEZONE"),
            (J, ["PRODUCT=sunhours", "DATE=2026-06-21", "TIMEZONE=Europe/Zurich"],
             "named time zones are not supported"),
            (J, ["PRODUCT=sunhours"], "PRODUCT=sunhours needs a day"),
            (J, ["PRODUCT=sunhours", "DATETIME=2026-06-21T07:30Z"] + day,
             "not both"),
            (J, ["PRODUCT=shadow", "DATETIME=2026-06-21T07:30Z", "SUN_AZIMUTH=100"],
             "DATETIME places the sun"),
            (J, ["PRODUCT=shade", "DATE=2026-06-21", "TIMEZONE=Z"],
             "give the sun's instant as DATETIME"),
            (J, ["PRODUCT=svf", "DATETIME=2026-06-21T07:30Z"], "not to PRODUCT=svf"),
            (J, ["PRODUCT=sunhours", "OUTPUT_TYPE=Byte"] + day, "in hours"),
            (J, ["PRODUCT=farshadow", "SUN_POSITION=per_cell"] + day, "SUN_POSITION=center"),
            (J, ["PRODUCT=shadow", "SUN_POSITION=per_cell"], "needs the sun from DATETIME"),
            # once taken without a word (shade went exact, shadow took the centre's sun)
            (J, ["PRODUCT=shade", "METHOD=shm", "SUN_POSITION=per_cell",
                 "DATETIME=2026-06-21T07:30Z"], "METHOD=shm builds its shadow height maps"),
            (J, ["PRODUCT=shadow", "METHOD=shm", "SUN_POSITION=per_cell",
                 "DATETIME=2026-06-21T07:30Z"], "needs SUN_POSITION=center"),
            (J, ["PRODUCT=sunhours", "PRESSURE=0"] + day, "PRESSURE must be between 300 and 1100"),
            (J, ["PRODUCT=sunhours", "TEMPERATURE=-300"] + day, "TEMPERATURE must be"),
            (J, ["PRODUCT=sunhours", "DELTA_T=9000"] + day, "DELTA_T must be between"),
            (J, ["PRODUCT=sunhours", "STEP_MINUTES=0"] + day, "STEP_MINUTES must be between"),
            (J, ["PRODUCT=insolation", "LINKE_TURBIDITY=0.5"] + day, "LINKE_TURBIDITY"),
            (J, ["PRODUCT=sunhours", "SUNHOURS_RULE=centre"] + day, "SUNHOURS_RULE"),
            (J, ["PRODUCT=sunhours", "DATE=7000-01-01", "TIMEZONE=Z"], "valid"),
            (T.conn(nogt), ["PRODUCT=shadow", "DATETIME=2026-06-21T07:30Z"],
             "DATETIME needs a georeferenced DEM"),
            (T.conn(nogt), ["PRODUCT=sunhours"] + day, "has no geotransform"),
            (T.conn(nocrs), ["PRODUCT=sunhours"] + day, "has no CRS"),
            (T.conn(polar), ["PRODUCT=sunhours"] + day, "beyond the poles"),
        ]
        for conn, oo, text in cases:
            with self.subTest(oo=oo):
                with self.assertRaises(RuntimeError) as e:
                    ds = gdal.OpenEx(conn, gdal.OF_RASTER, open_options=oo)
                    ds.GetRasterBand(1).Checksum()
                print("%-60s -> %s" % (" ".join(oo), str(e.exception)[:150]))
                self.assertIn(text, str(e.exception))
                self.assertIn("TERRASHADE", str(e.exception))
        # and through the tools: non-zero exit, no output, no crash
        out = os.path.join(self.dir, "bad.tif")
        p = T.run(["gdal_translate", "-oo", "PRODUCT=sunhours", "-oo", "DATE=2026-06-21",
                   T.conn(T.JACKSBORO), out], ok=False)
        self.assertIn("needs TIMEZONE", p.stderr)
        self.assertFalse(os.path.exists(out))

    def test_without_georeferencing_the_classic_sun_still_works(self):
        nogt = os.path.join(self.dir, "nogt2.tif")
        ds = gdal.GetDriverByName("GTiff").Create(nogt, 8, 8, 1, gdal.GDT_Float32)
        ds.GetRasterBand(1).Fill(100)
        ds = None
        a = T.read(T.conn(nogt), 1, {"PRODUCT": "shadow", "SUN_ELEVATION": 30})
        self.assertEqual(np.nanmin(a), 1.0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
