"""CELL_SIZES: a projected DEM's cells measured on the grid or on the ground.

A Web Mercator DEM at 60 N has cells twice as long on the grid as on the
ground (the projection's scale 1 / cos 60); taken as they are, every slope
would be half what it is. CELL_SIZES=auto measures them on the ground
wherever the projection's scale departs from 1 by more than 1 %, and keeps
the grid's sizes elsewhere (UTM, national grids: every earlier result
unchanged). Checked against planes of known ground slope, whose horizon
uphill is atan(slope) exactly (CURVATURE=NO)."""
import math
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

A = 6378137.0                       # WGS 84, and Web Mercator's sphere
E2 = (1 / 298.257223563) * (2 - 1 / 298.257223563)
SLOPE = 0.2                         # ground rise over ground run
HORIZON = math.degrees(math.atan(SLOPE))


def mercator_lat(y):
    """Web Mercator's northing to latitude (radians)."""
    return 2 * math.atan(math.exp(y / A)) - math.pi / 2


def parallel_cell(px, y):
    """Ground length on the WGS 84 ellipsoid of px metres of Web Mercator
    easting at northing y: the arc of the parallel."""
    phi = mercator_lat(y)
    return px * math.cos(phi) / math.sqrt(1 - E2 * math.sin(phi) ** 2)


def meridian_arc(phi0, phi1, steps=200):
    """Ground length of the meridian between two latitudes (radians)."""
    h = (phi1 - phi0) / steps
    m = [A * (1 - E2) / (1 - E2 * math.sin(phi0 + (i + 0.5) * h) ** 2) ** 1.5
         for i in range(steps)]
    return sum(m) * h


class CellSizes(unittest.TestCase):
    N, PX = 160, 50.0                   # cells, Web Mercator metres
    Y_TOP = 8397000.0                   # about 60.2 N

    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        n, px, top = cls.N, cls.PX, cls.Y_TOP
        cls.gt = (1000000.0, px, 0, top, 0, -px)
        cls.ew = cls.row_cells(n)
        cls.east = cls.east_plane("east.tif", n)
        # rising north: SLOPE x the ground distance along the meridian
        south = mercator_lat(top - n * px)
        north = np.array([meridian_arc(south, mercator_lat(y)) for y in cls.rows(n)])
        cls.north = T.write_tif(os.path.join(cls.dir, "north.tif"),
                                np.repeat((SLOPE * north)[:, None], n, 1), cls.gt, 3857)

    @classmethod
    def rows(cls, n):
        """The northings of the grid's first n rows."""
        return cls.Y_TOP - (np.arange(n) + 0.5) * cls.PX

    @classmethod
    def row_cells(cls, n):
        """The ground east-west length of a cell in each of the first n rows."""
        return np.array([parallel_cell(cls.PX, y) for y in cls.rows(n)])

    @classmethod
    def east_plane(cls, name, n):
        """n x n cells of the grid rising east: SLOPE x the ground distance
        along each row."""
        z = SLOPE * (np.arange(n)[None, :] + 0.5) * cls.row_cells(n)[:, None]
        return T.write_tif(os.path.join(cls.dir, name), z, cls.gt, 3857)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def horizons(self, dem, **opts):
        o = dict(PRODUCT="horizon", DIRECTIONS=4, CURVATURE="NO")
        o.update(opts)
        return T.read(T.conn(dem, **o))            # bands: 0, 90, 180, 270 degrees

    def test_web_mercator_measured_on_the_ground(self):
        md = gdal.Open(T.conn(self.east)).GetMetadata()
        print({k: v for k, v in md.items() if k.startswith("CELL")})
        self.assertTrue(md["CELL_SIZE_SOURCE"].startswith("ground"), md["CELL_SIZE_SOURCE"])
        self.assertAlmostEqual(float(md["CELL_SIZE_X_NORTH"]) / self.ew[0], 1, 6)
        self.assertAlmostEqual(float(md["CELL_SIZE_X_SOUTH"]) / self.ew[-1], 1, 6)
        # the projection's scale about 1 / cos 60
        scale = md["CELL_SIZE_SOURCE"].split("scale ")[1].split(" to ")
        self.assertTrue(1.98 < float(scale[0]) <= float(scale[1].split()[0]) < 2.02, scale)

    def test_slopes_on_the_ground(self):
        """Uphill horizons are atan(0.2) = 11.31 deg, east and north; with the
        grid's sizes (CELL_SIZES=grid) they would be about half the slope."""
        for dem, band, name in ((self.east, 1, "east"), (self.north, 0, "north")):
            h = self.horizons(dem)[band][1:-1, 1:-1]
            err = np.abs(h - HORIZON)
            print("%s: median %.5f deg off atan(%.1f), p99 %.5f" %
                  (name, np.median(err), SLOPE, np.percentile(err, 99)))
            # east: each row's own ground size, exact; north: the mean of the
            # rows' sizes, which vary by 0.1 % over these 8 km of grid
            self.assertLess(np.median(err), 1e-3 if name == "east" else 0.02)
            self.assertLess(np.percentile(err, 99), 2e-3 if name == "east" else 0.05)
            g = self.horizons(dem, CELL_SIZES="grid")[band][1:-1, 1:-1]
            print("%s, CELL_SIZES=grid: median %.3f deg" % (name, np.median(g)))
            self.assertLess(np.median(g), 0.6 * HORIZON)

    def test_windows_and_overviews_measure_alike(self):
        """Chunks, their far grid and the overview levels take the DEM's own
        decision: two TILE_SIZEs give the same bits, the whole DEM the same
        horizons within the windows' stated error, level 1 the same slope."""
        z = T.fractal_dem(self.N, seed=8, relief=400.0)
        dem = T.write_tif(os.path.join(self.dir, "frac.tif"), z, self.gt, 3857)
        a = self.horizons(dem, TILE_SIZE=64, NEAR_DISTANCE=500)
        b = self.horizons(dem, TILE_SIZE=96, NEAR_DISTANCE=500)
        np.testing.assert_array_equal(a, b)
        whole = self.horizons(dem, TILE_SIZE=0)
        err = np.abs(a - whole)
        print("TILE_SIZE=64 vs 0: median %.5f, p99 %.5f, max %.4f deg" %
              (np.median(err), np.percentile(err, 99), err.max()))
        self.assertLessEqual(np.median(err), 0.01)
        self.assertLessEqual(np.percentile(err, 99), 0.1)
        big = self.east_plane("east_big.tif", 600)         # levels from 256 cells up
        ds = gdal.OpenEx(T.conn(big), open_options=["PRODUCT=horizon", "DIRECTIONS=4",
                                                    "CURVATURE=NO"])
        ovr = ds.GetRasterBand(2).GetOverview(0).ReadAsArray()[1:-1, 1:-1]
        print("overview level 1, east: median %.4f deg" % np.median(ovr))
        self.assertLess(abs(np.median(ovr) - HORIZON), 0.01)

    def test_jacksboro_in_web_mercator(self):
        """jacksboro (degrees) warped to Web Mercator (scale 1.24 there) casts
        the shadows it casts in degrees: sun 10 deg at 135, the degrees'
        result re-gridded by nearest neighbour, as test_georef.py does for
        UTM. Measured: 95.6 % of cells agree, 30.0 % shadowed in degrees
        against 30.8 % (ground) and 23.2 % (CELL_SIZES=grid: cells 1.24
        times too long, slopes 1.24 times too gentle)."""
        merc = os.path.join(self.dir, "jb3857.tif")
        T.run(["gdalwarp", "-q", "-overwrite", "-t_srs", "EPSG:3857", T.JACKSBORO, merc])
        src = gdal.Open(merc)
        gt, W, H = src.GetGeoTransform(), src.RasterXSize, src.RasterYSize
        sun = {"PRODUCT": "shadow", "SUN_ELEVATION": 10, "SUN_AZIMUTH": 135}
        geo = T.translate(T.JACKSBORO, os.path.join(self.dir, "geo.tif"), sun)
        back = os.path.join(self.dir, "geo_3857.tif")
        T.run(["gdalwarp", "-q", "-overwrite", "-t_srs", "EPSG:3857",
               "-te", gt[0], gt[3] + H * gt[5], gt[0] + W * gt[1], gt[3],
               "-tr", gt[1], -gt[5], "-r", "near", geo, back])
        a = T.read(back, 1)
        fa = None
        for mode in ("auto", "grid"):
            b = T.read(T.conn(merc, CELL_SIZES=mode, **sun), 1)
            ok = np.isfinite(a) & np.isfinite(b)
            sa, sb = a[ok] < 0.5, b[ok] < 0.5
            fa, fb = 100 * sa.mean(), 100 * sb.mean()
            print("CELL_SIZES=%s: agree %.2f%%, shadowed %.2f%% (degrees) vs %.2f%%" %
                  (mode, 100 * np.mean(sa == sb), fa, fb))
            if mode == "auto":
                self.assertGreaterEqual(np.mean(sa == sb), 0.94)
                self.assertLessEqual(abs(fa - fb), 2.0)
            else:
                self.assertGreater(abs(fa - fb), 4.0)

    def test_what_one_length_per_row_cannot_hold_is_said(self):
        """Web Mercator from 53 N to 70 N: the cells' north-south length varies
        by 73 %, which their mean cannot hold: a warning; the 8 km planes: none."""
        big = T.write_tif(os.path.join(self.dir, "tall.tif"), np.zeros((400, 40), "f4"),
                          (0, 10000.0, 0, 11000000.0, 0, -10000.0), 3857)
        p = T.run(["gdalinfo", T.conn(big)])
        print(p.stderr.strip())
        self.assertIn("north-south length by 73.", p.stderr)
        self.assertIn("warp it to a local projection", p.stderr)
        self.assertNotIn("Warning", T.run(["gdalinfo", T.conn(self.east)]).stderr)

    def test_utm_keeps_the_grid_unless_asked(self):
        """UTM at its central meridian: scale 0.9996, within 1 %: auto keeps
        the grid's 30 m (as gdaldem; every earlier result unchanged); ground
        gives 30 / 0.9996."""
        z = T.fractal_dem(64, seed=9)
        dem = T.write_tif(os.path.join(self.dir, "utm.tif"), z,
                          (500000 - 32 * 30.0, 30, 0, 4000000, 0, -30), 32617)
        md = gdal.Open(T.conn(dem)).GetMetadata()
        print(md["CELL_SIZE_SOURCE"])
        self.assertTrue(md["CELL_SIZE_SOURCE"].startswith("grid"))
        self.assertEqual(float(md["CELL_SIZE_X"]), 30.0)
        self.assertIn("0.9996", md["CELL_SIZE_SOURCE"])
        g = gdal.OpenEx(T.conn(dem), open_options=["CELL_SIZES=ground"]).GetMetadata()
        self.assertAlmostEqual(float(g["CELL_SIZE_X"]), 30 / 0.9996, 4)
        self.assertAlmostEqual(float(g["CELL_SIZE_Y"]), 30 / 0.9996, 3)
        np.testing.assert_array_equal(self.horizons(dem), self.horizons(dem, CELL_SIZES="grid"))

    def test_grids_the_projection_shears_are_refused(self):
        """A grid whose axes are not at right angles on the ground (a
        pseudocylindrical projection away from its central meridian) turns
        slopes, aspects and shadows by as much: a peak's shadow in
        Sinusoidal at 84 W 37 N pointed 31 degrees off the sun (session 58's
        CRS audit). Beyond 10 degrees it is refused, beyond 1 degree warned
        of; the same place in UTM, or Sinusoidal on its central meridian,
        opens without a word, whatever CELL_SIZES."""
        z = np.zeros((32, 32), np.float32)
        cases = [("+proj=sinu +lon_0=0 +R=6371007.181 +units=m", -84.25, "refused"),
                 ("+proj=moll +lon_0=0 +datum=WGS84 +units=m", -84.25, "refused"),
                 ("+proj=sinu +lon_0=-84 +R=6371007.181 +units=m", -84.25, None),
                 ("+proj=laea +lat_0=52 +lon_0=10 +x_0=4321000 +y_0=3210000 "
                  "+ellps=GRS80 +units=m", 40.0, "warned"),
                 ("EPSG:32617", -84.25, None)]
        # a world Mollweide: its shear lies off its axes, its corners outside
        # its domain (skipped whole until the review: it opened silently)
        world = T.write_tif(os.path.join(self.dir, "moll_world.tif"),
                            np.zeros((45, 90), np.float32),
                            (-18040095.7, 400891.0, 0, 9020047.8, 0, -400891.0),
                            "+proj=moll +lon_0=0 +datum=WGS84 +units=m")
        p = T.run(["gdalinfo", T.conn(world)], ok=False)
        self.assertIn("degrees from a right angle on the ground", p.stderr)
        # LAEA over the EU-DEM's extent: its shear warned of, and its scale
        # too, after it (the shear's sentence hid the scale's: the review)
        eu = T.write_tif(os.path.join(self.dir, "laea_eu.tif"), np.zeros((64, 64), np.float32),
                         (943609.0, 95233.0, 0, 6021050.0, 0, -79357.0), 3035)
        p = T.run(["gdalinfo", T.conn(eu)])
        self.assertRegex(p.stderr, r"up to [5-8]\.\d degrees from a right angle on the ground"
                                   r"[^\n]*; and the projection's scale varies by")
        for i, (crs, lon, said) in enumerate(cases):
            s = gdal.osr.SpatialReference()
            s.SetFromUserInput(crs)
            s.SetAxisMappingStrategy(gdal.osr.OAMS_TRADITIONAL_GIS_ORDER)
            wgs = gdal.osr.SpatialReference()
            wgs.ImportFromEPSG(4326)
            wgs.SetAxisMappingStrategy(gdal.osr.OAMS_TRADITIONAL_GIS_ORDER)
            lat = 60.0 if lon == 40.0 else 36.59
            x, y, _ = gdal.osr.CoordinateTransformation(wgs, s).TransformPoint(lon, lat)
            dem = T.write_tif(os.path.join(self.dir, "shear%d.tif" % i), z,
                              (x, 50.0, 0, y, 0, -50.0), crs)
            for mode in ("auto", "grid"):
                p = T.run(["gdalinfo", "-oo", "CELL_SIZES=" + mode, T.conn(dem)],
                          ok=said != "refused")
                with self.subTest(crs=crs, mode=mode):
                    print(crs, mode, "->", p.stderr.strip()[:160] or "(nothing said)")
                    if said is None:
                        self.assertNotIn("right angle", p.stderr)
                    else:
                        self.assertIn("degrees from a right angle on the ground", p.stderr)
                        self.assertIn("ERROR" if said == "refused" else "Warning", p.stderr)

    def test_columns_along_latitude_are_refused(self):
        """A geographic DEM whose geotransform is in EPSG:4326's own axis
        order (a VRT with dataAxisToSRSAxisMapping="1,2": x is latitude) was
        read as longitude first: its sun's site in Antarctica, its cells 4.5
        x 55.8 m (session 58's CRS audit). Refused, as a rotated grid is."""
        base = T.write_tif(os.path.join(self.dir, "latlon.tif"),
                           np.zeros((40, 30), np.float32), (0, 1, 0, 0, 0, -1), None)
        vrt = T.write_vrt(os.path.join(self.dir, "latlon.vrt"), base, 30, 40,
                          (36.63, -0.0004, 0, -84.3, 0, 0.0005), "EPSG:4326", axes="1,2")
        p = T.run(["gdalinfo", T.conn(vrt)], ok=False)
        self.assertIn("the DEM's columns run north-south", p.stderr)
        # GDAL's own order (GeoTIFF's) opens as before
        T.run(["gdalinfo", T.conn(T.JACKSBORO)])

    def test_bad_requests_are_errors(self):
        z = T.fractal_dem(32, seed=10)
        bare = T.write_tif(os.path.join(self.dir, "bare.tif"), z, (0, 30, 0, 0, 0, -30), None)
        for dem, value, text in (
                (T.JACKSBORO, "grid", "CELL_SIZES=grid: the DEM's CRS is geographic"),
                (bare, "ground", "CELL_SIZES=ground: the DEM has no CRS"),
                (self.east, "metres", "CELL_SIZES must be one of auto, grid, ground")):
            p = T.run(["gdal_translate"] + T.oo_args({"CELL_SIZES": value}) +
                      [T.conn(dem), os.path.join(self.dir, "x.tif")], ok=False)
            print(p.stderr.strip())
            self.assertNotEqual(p.returncode, 0)
            self.assertIn(text, p.stderr)


if __name__ == "__main__":
    unittest.main()
