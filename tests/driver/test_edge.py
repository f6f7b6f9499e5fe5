"""EDGE=horizon|open|nodata: what lies beyond the DEM's edge (docs/algorithms.md).

- a 40 x 40 DEM under a sun at -21 deg (night): lit cells with EDGE=open (the
  behaviour before EDGE), none with EDGE=horizon (the default), for shade and
  shadow, exact and shm; SUN_ELEVATION=-90 lights nothing;
- a flat DEM at 1000 m: openness 90 deg within the dip with horizon, up to
  about 152 at the edges with open, nodata on the edge band with nodata;
  negative openness the same with horizon as with open, a plane 90 at any
  height and a pit more;
  the horizon of an edge cell looking out is the analytic dip, and 0 without
  curvature;
- the day products: nodata at the edges with EDGE=nodata, no sun below the
  Earth's horizon with horizon;
- C and OpenCL agree in every mode; EDGE=foo and EDGE for farshadow are
  refused with a sentence.
"""
import math
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

GT = (600000, 30, 0, 4000000, 0, -30)
EARTH_RADIUS = 6371008.8
REFRACTION = 0.13


def dip(height, k=REFRACTION):
    """The sea-level horizon seen from `height` metres, degrees."""
    c = (1 - k) / (2 * EARTH_RADIUS)
    return -math.degrees(math.atan(2 * math.sqrt(height * c)))


class Edge(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        d = cls.tmp.__enter__()
        cls.rough = T.write_tif(os.path.join(d, "rough.tif"),
                                T.fractal_dem(40, seed=3, relief=300.0), GT, 32617)
        cls.flat = T.write_tif(os.path.join(d, "flat.tif"),
                               np.full((40, 40), 1000, np.float32), GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def lit(self, dem, **options):
        a = T.read(T.conn(dem), 1, dict(options, OUTPUT_TYPE="Float32"))
        self.assertFalse(np.isnan(a).any())
        return int((a > 0).sum())

    def test_night(self):
        for product in ("shade", "shadow"):
            for method in ("exact", "shm"):
                with self.subTest(product=product, method=method):
                    sun = dict(PRODUCT=product, METHOD=method, SUN_AZIMUTH=315)
                    before = self.lit(self.rough, SUN_ELEVATION=-21, EDGE="open", **sun)
                    print("  %s %s, sun at -21 deg: %d of 1600 lit with EDGE=open"
                          % (product, method, before))
                    self.assertGreater(before, 0)
                    self.assertEqual(self.lit(self.rough, SUN_ELEVATION=-21, **sun), 0)
                    self.assertEqual(self.lit(self.rough, SUN_ELEVATION=-21, EDGE="horizon",
                                              **sun), 0)
                    self.assertEqual(self.lit(self.rough, SUN_ELEVATION=-90, **sun), 0)
        # half the sun's disk above an open sky at the outward edge
        self.assertGreater(self.lit(self.rough, PRODUCT="shadow", SUN_ELEVATION=-90,
                                    EDGE="open"), 0)
        # the sun placed by date and time, per cell: midnight at 36 N
        for product in ("shade", "shadow"):
            night = dict(PRODUCT=product, DATETIME="2026-06-21T05:00:00Z",
                         SUN_POSITION="per_cell")
            before = self.lit(self.rough, EDGE="open", **night)
            print("  %s per cell at midnight: %d lit with EDGE=open" % (product, before))
            self.assertGreater(before, 0)
            self.assertEqual(self.lit(self.rough, **night), 0)

    def test_sun_just_below_the_earths_horizon(self):
        """On the flat DEM at 1000 m the dip is -0.947 deg: a sun's disk
        entirely below it lights nothing, a sun at -0.1 deg every cell. A
        short MAX_DISTANCE does not let peaks see a sun below the Earth's
        horizon either."""
        for method in ("exact", "shm"):
            with self.subTest(method=method):
                o = dict(PRODUCT="shadow", SUN_AZIMUTH=200, METHOD=method)
                self.assertEqual(self.lit(self.flat, SUN_ELEVATION=dip(1000) - 0.3, **o), 0)
                if method == "exact":
                    self.assertEqual(self.lit(self.flat, SUN_ELEVATION=-0.1, **o), 1600)
                o = dict(o, SUN_ELEVATION=-2, MAX_DISTANCE=60)
                before = self.lit(self.rough, EDGE="open", **o)
                print("  %s, sun at -2 deg, MAX_DISTANCE=60: %d lit with EDGE=open"
                      % (method, before))
                self.assertGreater(before, 0)
                self.assertEqual(self.lit(self.rough, **o), 0)

    def test_flat_openness(self):
        o = dict(PRODUCT="openness", DIRECTIONS=16)
        horizon = T.read(T.conn(self.flat), 1, o)
        open_ = T.read(T.conn(self.flat), 1, dict(o, EDGE="open"))
        nodata = T.read(T.conn(self.flat), 1, dict(o, EDGE="nodata", MAX_DISTANCE=100))
        print("  flat 1000 m: openness %.4f..%.4f (horizon), %.4f..%.4f (open)"
              % (horizon.min(), horizon.max(), open_.min(), open_.max()))
        self.assertGreaterEqual(horizon.min(), 90.0 - 1e-4)
        self.assertLessEqual(horizon.max(), 90.0 - dip(1000) + 1e-4)
        self.assertGreater(horizon.max(), 90.5)  # a corner looks out half the time
        self.assertGreater(open_.max(), 150.0)
        # cells within 100 m of the edge (3 rows of 30 m cells) are nodata
        band = np.ones((40, 40), bool)
        band[3:-3, 3:-3] = False
        np.testing.assert_array_equal(np.isnan(nodata), band)
        np.testing.assert_allclose(nodata[~band], 90.0, atol=1e-3)

    def test_negative_openness_does_not_depend_on_height(self):
        """Negative openness sweeps the negated DEM; the negated sea-level
        plane beyond the edge once stood as a wall above it (a plane at
        2000 m read 59.4 deg in its middle, a pit 3000 m deep was capped at
        90). With EDGE=horizon it sees the DEM alone, as EDGE=open: a plane
        reads 90 wherever a ray has terrain, whatever its height, with
        either horizon method, and a pit more than 90 (114.5 deg at the
        bottom of this one, exact; the pyramid's coarse levels see little of
        the plane beyond the rim: 90.5)."""
        d = self.tmp.path
        o = dict(PRODUCT="openness", OPENNESS="negative", DIRECTIONS=16)
        y, x = np.mgrid[0:40, 0:40]
        r = np.hypot(x - 20, y - 20)
        for method in ("exact", "pyramid"):
            m = dict(o, HORIZON_METHOD=method)
            for height in (0, 1000, 2000):
                flat = T.write_tif(os.path.join(d, "flat_%d.tif" % height),
                                   np.full((40, 40), height, np.float32), GT, 32617)
                a = T.read(T.conn(flat), 1, m)
                with self.subTest(method=method, height=height):
                    np.testing.assert_allclose(a[1:-1, 1:-1], 90.0, atol=1e-3)
                    np.testing.assert_array_equal(
                        a, T.read(T.conn(flat), 1, dict(m, EDGE="open")))
            # a conical pit 300 m deep and 300 m across in a plane at 2000 m:
            # walls of 45 deg around its bottom
            z = (2000 - 300 * np.clip(1 - r / 10, 0, 1)).astype(np.float32)
            pit = T.write_tif(os.path.join(d, "pit.tif"), z, GT, 32617)
            a = T.read(T.conn(pit), 1, m)
            print("  negative openness (%s): plane 90 at 0, 1000 and 2000 m; pit bottom %.2f"
                  % (method, a[20, 20]))
            with self.subTest(method=method, pit=True):
                if method == "exact":  # (the rim's plane, 600 m off at the edge: 26.6 deg up)
                    self.assertGreater(a[20, 20], 110.0)
                np.testing.assert_array_equal(a, T.read(T.conn(pit), 1, dict(m, EDGE="open")))

    def test_dip_of_an_edge_cell(self):
        o = dict(PRODUCT="horizon", DIRECTIONS=4)
        h = T.read(T.conn(self.flat), None, o)  # bands: north, east, south, west
        print("  horizon of the west edge looking west: %.6f deg, analytic %.6f"
              % (h[3][20, 0], dip(1000)))
        self.assertAlmostEqual(h[3][20, 0], dip(1000), delta=1e-5)
        self.assertAlmostEqual(h[0][0, 17], dip(1000), delta=1e-5)
        h = T.read(T.conn(self.flat), None, dict(o, REFRACTION=0))
        self.assertAlmostEqual(h[1][5, 39], dip(1000, 0.0), delta=1e-5)
        h = T.read(T.conn(self.flat), None, dict(o, CURVATURE="NO"))
        self.assertEqual(h[2][39, 4], 0.0)  # the sea-level plane: the horizontal
        h = T.read(T.conn(self.flat), None, dict(o, EDGE="open"))
        self.assertEqual(h[3][20, 0], -90.0)

    def test_day_products(self):
        """EDGE=nodata: nodata where a ray toward the sun (or the sky term's
        directions) leaves the DEM within MAX_DISTANCE: within 60 m of the
        edge (two cells), the southern and eastern ones among them (the sun
        of a June day at 36 N), and nowhere else; elsewhere the values of
        EDGE=open."""
        day = dict(DATE="2026-06-21", TIMEZONE="+00:00", STEP_MINUTES=60)
        year = dict(START_DATE="2026-06-01", END_DATE="2026-06-30", TIMEZONE="+00:00")
        band = np.ones((40, 40), bool)
        band[2:-2, 2:-2] = False
        cases = [("sunhours", day, 1), ("insolation", day, 1), ("daycycle", day, 13),
                 ("sunhours", year, 1), ("insolation", year, 2)]
        for product, when, b in cases:
            with self.subTest(product=product, range="START_DATE" in when):
                o = dict(when, PRODUCT=product, MAX_DISTANCE=60)
                nodata = T.read(T.conn(self.rough), b, dict(o, EDGE="nodata"))
                open_ = T.read(T.conn(self.rough), b, dict(o, EDGE="open"))
                blank = np.isnan(nodata)
                print("  %s%s: %d nodata cells" % (product, " (range)" if "START_DATE" in when
                                                   else "", blank.sum()))
                self.assertFalse((blank & ~band).any())
                self.assertTrue(blank[:, 38:].all())  # the morning sun, to the east
                if product != "daycycle":  # 07:00 local: the sun is not south yet
                    self.assertTrue(blank[38:, :].all())
                np.testing.assert_array_equal(nodata[~blank], open_[~blank])
        # the flat DEM at 1000 m: the sun counts from when it clears the dip,
        # as the day products always did (EDGE=open keeps that floor)
        o = dict(day, PRODUCT="sunhours", STEP_MINUTES=5)
        horizon = T.read(T.conn(self.flat), 1, o)
        open_ = T.read(T.conn(self.flat), 1, dict(o, EDGE="open"))
        np.testing.assert_array_equal(horizon, open_)

    def test_backends_agree(self):
        cases = [
            dict(PRODUCT="shade", SUN_ELEVATION=3, OUTPUT_TYPE="Float32"),
            dict(PRODUCT="shade", METHOD="shm", SUN_ELEVATION=3, OUTPUT_TYPE="Float32"),
            dict(PRODUCT="shadow", SUN_ELEVATION=-0.5, SUN_AZIMUTH=100),
            dict(PRODUCT="horizon", DIRECTIONS=8, START_AZIMUTH=5),
            dict(PRODUCT="svf", DIRECTIONS=8),
            dict(PRODUCT="sky", DIRECTIONS=8),
            dict(PRODUCT="openness", DIRECTIONS=8),
            dict(PRODUCT="openness", OPENNESS="negative", DIRECTIONS=8),
            dict(PRODUCT="envlight", SKY="overcast", DIRECTIONS=8),
        ]
        for edge in ("horizon", "open", "nodata"):
            for case in cases:
                with self.subTest(edge=edge, **case):
                    o = dict(case, EDGE=edge)
                    c = T.read(T.conn(self.rough), None, dict(o, BACKEND="c"))
                    cl = T.read(T.conn(self.rough), None, dict(o, BACKEND="opencl"))
                    np.testing.assert_array_equal(np.isnan(c), np.isnan(cl))
                    if not np.isnan(c).all():
                        self.assertLessEqual(np.nanmax(np.abs(c - cl)), 1e-3)

    def test_below_sea_level_warns(self):
        """Heights below sea level under EDGE=horizon (the default): the
        sea-level sphere beyond the edges stands as a wall above them (a
        plane at -4000 m was all in shadow at a 10 degree sun, svf 0.03), so
        the first read warns once, whole or chunk by chunk; EDGE=open lights
        the plane, and a sea a few decimetres below 0 says nothing."""
        deep = T.write_tif(os.path.join(self.tmp.path, "deep.tif"),
                           np.full((160, 160), -4000, np.float32), GT, 32617)
        shallow = T.write_tif(os.path.join(self.tmp.path, "shallow.tif"),
                              np.full((40, 40), -0.4, np.float32), GT, 32617)
        want = ("Warning 1: TERRASHADE: the DEM's heights reach -4000.0 m, below sea level: "
                "with EDGE=horizon (the default) the ground beyond the DEM's edges is the "
                "sea-level sphere, which stands as a wall above them")
        for oo in ({}, {"TILE_SIZE": 64}, {"PRODUCT": "svf"}):
            with self.subTest(**oo):
                err = T.translate_stderr(deep, **oo)
                self.assertIn(want, err)
                self.assertEqual(err.count("below sea level"), 1)
        self.assertEqual(self.lit(deep, PRODUCT="shadow", SUN_ELEVATION=10), 0)
        self.assertEqual(self.lit(deep, PRODUCT="shadow", SUN_ELEVATION=10, EDGE="open"),
                         160 * 160)
        for dem, oo in ((deep, {"EDGE": "open"}), (deep, {"EDGE": "nodata"}), (shallow, {})):
            with self.subTest(dem=os.path.basename(dem), **oo):
                self.assertNotIn("below sea level", T.translate_stderr(dem, **oo))

    def test_bad_values(self):
        p = T.run(["gdalinfo", T.conn(self.flat, PRODUCT="svf", EDGE="foo")], ok=False)
        self.assertIn("EDGE must be one of horizon, open, nodata, got 'foo'", p.stderr)
        p = T.run(["gdalinfo", T.conn(self.flat, PRODUCT="farshadow", DATE="2026-06-21",
                                      TIMEZONE="Z", EDGE="nodata")], ok=False)
        self.assertIn("EDGE applies to", p.stderr)
        self.assertIn("not to PRODUCT=farshadow", p.stderr)

    def test_unbounded_nodata_warns_and_shadowmap_refuses_it(self):
        """EDGE=nodata without MAX_DISTANCE blanks every cell (every ray
        leaves the DEM): a warning says so, where gdalinfo -stats only said
        "no valid pixels"; none with MAX_DISTANCE. METHOD=shadowmap, which
        takes no MAX_DISTANCE, left every cell valid under it: refused."""
        err = T.translate_stderr(self.flat, PRODUCT="svf", EDGE="nodata")
        self.assertIn("EDGE=nodata without MAX_DISTANCE makes nodata every cell that casts "
                      "a ray", err)
        self.assertTrue(np.isnan(T.read(T.conn(self.flat), 1,
                                        dict(PRODUCT="svf", EDGE="nodata"))).all())
        self.assertNotIn("EDGE=nodata", T.translate_stderr(self.flat, PRODUCT="svf",
                                                           EDGE="nodata", MAX_DISTANCE=100))
        p = T.run(["gdalinfo", T.conn(self.flat, METHOD="shadowmap", EDGE="nodata")], ok=False)
        self.assertIn("EDGE=nodata does not apply to METHOD=shadowmap", p.stderr)

    def test_metadata_lists_edge_where_it_applies(self):
        import xml.etree.ElementTree as ET
        xml = gdal.GetDriverByName("TERRASHADE").GetMetadataItem("TERRASHADE_PRODUCTS")
        takes = {p.get("name") for p in ET.fromstring(xml)
                 if "EDGE" in p.get("options").split(",")}
        self.assertEqual(takes, {"shade", "shadow", "horizon", "svf", "openness", "sky",
                                 "sunhours", "insolation", "daycycle", "envlight"})
        ds = gdal.OpenEx(T.conn(self.flat), open_options=["PRODUCT=svf", "EDGE=nodata"])
        self.assertEqual(ds.GetMetadataItem("EDGE"), "nodata")
        ds = gdal.OpenEx(T.conn(self.flat), open_options=["PRODUCT=horizon"])
        self.assertEqual(ds.GetMetadataItem("EDGE"), "horizon")
        ds = gdal.OpenEx(T.conn(self.flat), open_options=[
            "PRODUCT=farshadow", "DATE=2026-06-21", "TIMEZONE=Z"])
        self.assertIsNone(ds.GetMetadataItem("EDGE"))


if __name__ == "__main__":
    unittest.main(verbosity=2)
