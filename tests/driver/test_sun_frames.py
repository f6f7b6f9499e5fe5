"""The sun over DEMs in unusual frames (docs/driver.md, "Georeferencing").

- A CRS whose geographic CRS counts in grads or from another prime meridian
  (NTF (Paris): Lambert II, EPSG:27572, in grads from Paris; MGI (Ferro),
  EPSG:4805) puts the sun over the same place, and gives the same cell
  sizes, as EPSG:4326 or Lambert 93 there: its longitudes and latitudes
  were once taken as degrees from Greenwich (cells 10 % off, the sun 5
  degrees away, or a site 17 degrees of longitude off).
- A rotated pole (PROJ's ob_tran, CORDEX's and COSMO's grids) is a frame,
  not longitudes and latitudes: the sun is found at the real place and
  turned into the grid's azimuth, as in a projection.
- SUN_POSITION=per_cell where the sun's azimuth across the DEM turns
  through the direction opposite the centre's: each cell's sun is
  interpolated between its own lattice nodes, which were once each wrapped
  from the centre's azimuth, so that two nodes on either side were
  averaged the long way round (a band of cells lit from the wrong side).
"""
import math
import unittest

import tsdriver as T
from tsdriver import gdal, np, osr

DT = "2026-06-21T12:00:00Z"


md = T.metadata


def to_crs(epsg_or_proj, lon, lat):
    """(lon, lat) in degrees of WGS 84 to the CRS's (x, y)."""
    wgs, s = osr.SpatialReference(), osr.SpatialReference()
    wgs.ImportFromEPSG(4326)
    if isinstance(epsg_or_proj, int):
        s.ImportFromEPSG(epsg_or_proj)
    else:
        s.SetFromUserInput(epsg_or_proj)
    for r in (wgs, s):
        r.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    x, y, _ = osr.CoordinateTransformation(wgs, s).TransformPoint(lon, lat)
    return x, y


class SunFrames(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def dem(self, name, crs, x0, y0, cell, n=41, slope=0.0):
        """n x n cells centred on (x0, y0) of the CRS, rising toward grid
        north by `slope` of the cells' own size a row."""
        rows = np.arange(n, dtype=np.float64)[:, None] * np.ones((1, n))
        z = 500 + slope * (n - rows) * abs(cell[1])
        gt = (x0 - cell[0] * n / 2, cell[0], 0, y0 + cell[1] * n / 2, 0, -cell[1])
        return T.write_tif("%s/%s.tif" % (self.dir, name), z.astype(np.float32), gt, crs)

    def sun(self, path):
        m = md(T.conn(path), {"PRODUCT": "shade", "DATETIME": DT})
        return {k: float(m[k]) for k in ("SUN_SITE_LONGITUDE", "SUN_SITE_LATITUDE",
                                         "SUN_AZIMUTH_TRUE", "SUN_AZIMUTH", "SUN_ELEVATION",
                                         "MERIDIAN_CONVERGENCE")}

    def test_grads_and_other_prime_meridians(self):
        lon, lat = 2.5, 48.6  # near Paris
        ref = self.sun(self.dem("wgs84", 4326, lon, lat, (0.0005, 0.0005)))
        cases = {27572: (50.0, 50.0), 2154: (50.0, 50.0), 4807: (0.0005, 0.0005),
                 4805: (0.0005, 0.0005)}
        for crs, cell in cases.items():
            x, y = to_crs(crs, lon, lat)
            s = self.sun(self.dem("c%d" % crs, crs, x, y, cell))
            print("EPSG:%d: site %.5f %.5f, sun %.3f / %.3f (EPSG:4326: %.5f %.5f, %.3f / %.3f)"
                  % (crs, s["SUN_SITE_LONGITUDE"], s["SUN_SITE_LATITUDE"],
                     s["SUN_AZIMUTH_TRUE"], s["SUN_ELEVATION"], ref["SUN_SITE_LONGITUDE"],
                     ref["SUN_SITE_LATITUDE"], ref["SUN_AZIMUTH_TRUE"], ref["SUN_ELEVATION"]))
            # datum shifts (NTF, MGI against WGS 84) are ~100 m: 0.002 degrees
            self.assertAlmostEqual(s["SUN_SITE_LONGITUDE"], lon, delta=0.003, msg=crs)
            self.assertAlmostEqual(s["SUN_SITE_LATITUDE"], lat, delta=0.003, msg=crs)
            self.assertAlmostEqual(s["SUN_AZIMUTH_TRUE"], ref["SUN_AZIMUTH_TRUE"], delta=0.01)
            self.assertAlmostEqual(s["SUN_ELEVATION"], ref["SUN_ELEVATION"], delta=0.01)

    def test_cells_of_a_grads_projection(self):
        """A plane rising 0.2 of a cell a cell toward grid north: its horizon
        north is atan(0.2 k), k the projection's scale there (1.0004 in
        Lambert II, 0.9997 in Lambert 93); it read 10.2 degrees in Lambert
        II, its cells taken 10 % too long."""
        lon, lat = 2.337229, 48.6
        for crs, k in ((27572, 1.0004), (2154, 0.9997)):
            x, y = to_crs(crs, lon, lat)
            path = self.dem("plane%d" % crs, crs, x, y, (50.0, 50.0), slope=0.2)
            ds = gdal.OpenEx(T.conn(path), gdal.OF_RASTER, open_options=[
                "PRODUCT=horizon", "DIRECTIONS=4", "CURVATURE=NO", "EDGE=open"])
            h = ds.GetRasterBand(1).ReadAsArray()[20, 20]
            print("EPSG:%d: horizon north %.4f, expected %.4f" % (
                crs, h, math.degrees(math.atan(0.2 * k))))
            self.assertAlmostEqual(h, math.degrees(math.atan(0.2 * k)), delta=0.01)

    def test_rotated_pole(self):
        rot = ("+proj=ob_tran +o_proj=longlat +o_lon_p=0 +o_lat_p=39.25 +lon_0=18 "
               "+datum=WGS84 +no_defs")
        rx, ry = -25.0, 20.0  # rotated coordinates: about 37.4 W, 61.2 N
        s = osr.SpatialReference()
        s.SetFromUserInput(rot)
        wgs = osr.SpatialReference()
        wgs.ImportFromEPSG(4326)
        for r in (s, wgs):
            r.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        ct = osr.CoordinateTransformation(s, wgs)
        lon, lat, _ = ct.TransformPoint(rx, ry)
        # grid north's true direction: a step north in the rotated grid
        lon2, lat2, _ = ct.TransformPoint(rx, ry + 1e-4)
        dx = (lon2 - lon) * math.cos(math.radians(lat))
        grid_north_true = math.degrees(math.atan2(dx, lat2 - lat))
        got = self.sun(self.dem("rotated", rot, rx, ry, (0.01, 0.01), n=21))
        ref = self.sun(self.dem("rotref", 4326, lon, lat, (0.001, 0.001), n=21))
        print("rotated pole: site %.4f %.4f (real %.4f %.4f), sun true %.3f (%.3f), "
              "grid %.3f, convergence %.3f (grid north at true %.3f)" % (
                  got["SUN_SITE_LONGITUDE"], got["SUN_SITE_LATITUDE"], lon, lat,
                  got["SUN_AZIMUTH_TRUE"], ref["SUN_AZIMUTH_TRUE"], got["SUN_AZIMUTH"],
                  got["MERIDIAN_CONVERGENCE"], grid_north_true))
        self.assertAlmostEqual(got["SUN_SITE_LONGITUDE"], lon, delta=1e-3)
        self.assertAlmostEqual(got["SUN_SITE_LATITUDE"], lat, delta=1e-3)
        self.assertAlmostEqual(got["SUN_AZIMUTH_TRUE"], ref["SUN_AZIMUTH_TRUE"], delta=0.01)
        self.assertAlmostEqual(got["SUN_ELEVATION"], ref["SUN_ELEVATION"], delta=0.01)
        # the sun's grid azimuth: its true one from grid north's direction
        self.assertAlmostEqual(got["SUN_AZIMUTH"],
                               (got["SUN_AZIMUTH_TRUE"] - grid_north_true) % 360, delta=0.1)

    def test_per_cell_sun_through_the_opposite_azimuth(self):
        """A band around the world at 60 N rising north (0.09), 1 degree cells:
        at 03:00 UTC the sun's azimuth at 162.5 E is opposite the centre's
        (0.5 E). Each cell's shade there against that of a 3-column DEM of
        its own, whose sun is its centre's."""
        nx, ny, dy = 360, 60, 0.01
        z = (100 + 100.0 * (ny - np.arange(ny)))[:, None] * np.ones((1, nx))
        gt = (-180.0, 1.0, 0, 60.0, 0, -dy)
        band = T.write_tif(self.dir + "/band.tif", z.astype(np.float32), gt, 4326)
        opts = ["PRODUCT=shade", "OUTPUT_TYPE=Float32", "DATETIME=2026-06-21T03:00:00Z",
                "EDGE=open"]
        ds = gdal.OpenEx(T.conn(band), gdal.OF_RASTER, open_options=opts +
                         ["SUN_POSITION=per_cell"])
        row = ds.GetRasterBand(1).ReadAsArray()[ny // 2]
        worst = 0.0
        for col in range(338, 348):  # 158.5 .. 167.5 E
            own = T.write_tif(self.dir + "/col%d.tif" % col,
                              z[:, col - 1:col + 2].astype(np.float32),
                              (-180.0 + col - 1, 1.0, 0, 60.0, 0, -dy), 4326)
            d2 = gdal.OpenEx(T.conn(own), gdal.OF_RASTER, open_options=opts)
            ref = d2.GetRasterBand(1).ReadAsArray()[ny // 2, 1]
            worst = max(worst, abs(float(row[col]) - float(ref)))
            print("%.1f E: per cell %.5f, its own sun %.5f" % (col - 179.5, row[col], ref))
        self.assertLess(worst, 0.002)

    def test_per_cell_sun_around_the_subsolar_point(self):
        """A world DEM at noon UTC on the June solstice holds the subsolar
        point (0, 23.4 N), around which the sun's azimuth turns a whole
        circle, so that no unwrapping of the lattice's azimuths is free of
        a seam. Cells beside it (here from the subsolar point east, rows
        22.5 and 23.5 N) took azimuths averaged across it: shade 0.096
        where its own sun gives 0.63. Each against a 3 x 3 DEM of its own."""
        lat = 89.5 - np.arange(180)
        # rising 0.3 to the east (heights in units of 2 km, Z_FACTOR)
        z = np.arange(360)[None, :] * 111000.0 * np.cos(np.radians(lat))[:, None] * 0.3 / 2000
        world = T.write_tif(self.dir + "/world.tif", z.astype(np.float32),
                            (-180.0, 1.0, 0, 90.0, 0, -1.0), 4326)
        opts = ["PRODUCT=shade", "OUTPUT_TYPE=Float32", "DATETIME=2026-06-21T12:00:00Z",
                "SKY_WEIGHT=0", "CURVATURE=NO", "EDGE=open", "Z_FACTOR=2000"]
        ds = gdal.OpenEx(T.conn(world), gdal.OF_RASTER,
                         open_options=opts + ["SUN_POSITION=per_cell"])
        a = ds.GetRasterBand(1).ReadAsArray()
        worst = 0.0
        for lon in (40.5, 60.5, 80.5):
            for la in (24.5, 23.5, 22.5, 21.5):
                x, y = int(lon + 179.5), int(89.5 - la)
                own = T.write_tif(self.dir + "/own.tif", z[y - 1:y + 2, x - 1:x + 2].astype(
                    np.float32), (lon - 1.5, 1.0, 0, la + 1.5, 0, -1.0), 4326)
                d2 = gdal.OpenEx(T.conn(own), gdal.OF_RASTER, open_options=opts)
                ref = float(d2.GetRasterBand(1).ReadAsArray()[1, 1])
                d2 = None
                worst = max(worst, abs(float(a[y, x]) - ref))
                print("%.1f E %.1f N: per cell %.4f, its own sun %.4f" % (lon, la, a[y, x], ref))
        self.assertLess(worst, 0.01)

    def test_per_cell_sun_beside_the_zenith(self):
        """Within a degree or two of the subsolar point (here 0, 1.9 E at
        noon UTC on 20 March 2026) the sun's elevation is a cone and its
        azimuth turns a whole circle: bilinear in the nodes' angles, the
        cells took a sun up to 0.44 deg lower and 3 deg off in direction
        (pvlib's SPA beside it; session 56), here on slopes of 17 degrees
        shade up to 0.005 off. The nodes' sun vectors are interpolated now. Each
        cell against a 3 x 3 DEM of its own, on slopes rising east and
        north."""
        n, cell = 40, 0.25
        lat = -5 + cell * (n - 0.5 - np.arange(n))
        lon = -5 + cell * (0.5 + np.arange(n))
        ys = (n - 0.5 - np.arange(n))[:, None] * np.ones((1, n))
        xs = np.ones((n, 1)) * (0.5 + np.arange(n))[None, :]
        opts = ["PRODUCT=shade", "OUTPUT_TYPE=Float32", "DATETIME=2026-03-20T12:00:00Z",
                "SKY_WEIGHT=0", "CURVATURE=NO", "EDGE=open", "Z_FACTOR=1000"]
        worst = 0.0
        for name, axis in (("east", xs), ("north", ys)):
            # rising 0.3 a cell's own length (heights in km, Z_FACTOR)
            z = axis * cell * 111.2 * 0.3 * (np.cos(np.radians(lat))[:, None]
                                            if name == "east" else 1.0)
            dem = T.write_tif("%s/zenith_%s.tif" % (self.dir, name), z.astype(np.float32),
                              (-5.0, cell, 0, 5.0, 0, -cell), 4326)
            ds = gdal.OpenEx(T.conn(dem), gdal.OF_RASTER,
                             open_options=opts + ["SUN_POSITION=per_cell"])
            a = ds.GetRasterBand(1).ReadAsArray()
            ds = None
            for y, x in ((20, 27), (21, 28), (19, 29), (20, 30), (22, 26), (18, 27)):
                own = T.write_tif(self.dir + "/own.tif", z[y - 1:y + 2, x - 1:x + 2].astype(
                    np.float32), (lon[x] - 1.5 * cell, cell, 0, lat[y] + 1.5 * cell, 0, -cell),
                    4326)
                d2 = gdal.OpenEx(T.conn(own), gdal.OF_RASTER, open_options=opts)
                ref = float(d2.GetRasterBand(1).ReadAsArray()[1, 1])
                d2 = None
                worst = max(worst, abs(float(a[y, x]) - ref))
                print("%s: %.3f E %.3f N: per cell %.5f, its own sun %.5f"
                      % (name, lon[x], lat[y], a[y, x], ref))
        self.assertLess(worst, 0.001)

    def test_per_cell_sun_near_a_pole(self):
        """A ring of the world at 89-90 N in cells of 1.8 x 0.05 degrees: its
        lattice's nodes, 2 degrees of arc apart, were ~20 degrees of
        longitude apart, and the suns' directions interpolated between them
        came 1.7 deg too high (session 56's audit of per_cell against pvlib;
        the angles interpolated before 0f2b7c0 were 0.07 off). The lattice is
        closer where its suns' grid azimuths turn by more than 2 degrees
        between nodes. Each cell's elevation (a flat DEM's Float32 shade is
        its sine) against a 3 x 3 DEM of its own."""
        nx, ny, dx, dy = 200, 20, 1.8, 0.05
        z = np.zeros((ny, nx), np.float32)
        ring = T.write_tif(self.dir + "/ring.tif", z, (-180.0, dx, 0, 90.0, 0, -dy), 4326)
        opts = ["PRODUCT=shade", "OUTPUT_TYPE=Float32", "DATETIME=2026-06-21T10:00:00Z",
                "SKY_WEIGHT=0", "CURVATURE=NO", "EDGE=open"]
        ds = gdal.OpenEx(T.conn(ring), gdal.OF_RASTER, open_options=opts +
                         ["SUN_POSITION=per_cell"])
        a = ds.GetRasterBand(1).ReadAsArray()
        ds = None
        worst = 0.0
        for y, x in ((18, 5), (18, 103), (10, 57), (2, 151), (19, 190)):
            own = T.write_tif(self.dir + "/own.tif", np.zeros((3, 3), np.float32),
                              (-180.0 + (x - 1) * dx, dx, 0, 90.0 - (y - 1) * dy, 0, -dy),
                              4326)
            d2 = gdal.OpenEx(T.conn(own), gdal.OF_RASTER, open_options=opts)
            ref = float(d2.GetRasterBand(1).ReadAsArray()[1, 1])
            d2 = None
            e, e_ref = (math.degrees(math.asin(v)) for v in (float(a[y, x]), ref))
            worst = max(worst, abs(e - e_ref))
            print("%.1f E %.3f N: per cell %.4f deg, its own sun %.4f"
                  % (-180 + (x + 0.5) * dx, 90 - (y + 0.5) * dy, e, e_ref))
        self.assertLess(worst, 0.01)
        # a polar stereographic grid around the pole keeps its lattice: its
        # grid azimuths do not turn (a first version took the turn across the
        # pole, two 180s wrapped apart, as 360 degrees: 21 x 181 nodes; the
        # third review of session 56)
        for epsg in (3413, 3031):
            polar = T.write_tif("%s/polar_%d.tif" % (self.dir, epsg),
                                np.zeros((600, 600), np.float32),
                                (-300000.0, 1000.0, 0, 300000.0, 0, -1000.0), epsg)
            p = T.run(["gdalinfo", "-oo", "DATETIME=2026-06-21T10:00:00Z", "-oo",
                       "SUN_POSITION=per_cell", T.conn(polar)], CPL_DEBUG="TERRASHADE")
            self.assertIn("the sun: a lattice of 21 x 21 sites", p.stderr)
        p = T.run(["gdalinfo", "-oo", "DATETIME=2026-06-21T10:00:00Z", "-oo",
                   "SUN_POSITION=per_cell", T.conn(ring)], CPL_DEBUG="TERRASHADE")
        self.assertIn("the sun: a lattice of 181 x", p.stderr)

    def test_a_pole_by_rounding(self):
        """A polar cap whose top is the pole give or take rounding (90 + 1e-13)
        opens; one 0.6 of a cell past it is off by more than rounding and
        not grid-registered (a row centred on the pole: half a cell), and
        the message says so (it once said 'cannot compute the north-south
        cell size' and 'not in degrees of a geographic CRS')."""
        z = np.zeros((50, 72), np.float32)
        for top, ok in ((90 + 1e-13, True), (90.000001, True), (90.03, False)):
            path = T.write_tif(self.dir + "/cap.tif", z, (-180.0, 5.0, 0, top, 0, -0.05), 4326)
            r = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo", "DIRECTIONS=4",
                       T.conn(path), self.dir + "/cap_svf.tif"], ok=ok)
            if not ok:
                self.assertIn("0.60 of a cell) past the pole", r.stderr)


if __name__ == "__main__":
    unittest.main()
