"""Georeferencing: size, geotransform and CRS kept; cell sizes in metres from
the CRS (geodesic for degrees, feet converted); rotated grids refused;
south-up and east-west grids handled; any GDAL name accepted."""
import math
import os
import shutil
import unittest
import zipfile

import tsdriver as T
from tsdriver import gdal, np, osr

US_FT = 1200.0 / 3937.0
FT = 0.3048


def dilate(m, k):
    out = m.copy()
    for dy in range(-k, k + 1):
        for dx in range(-k, k + 1):
            out |= np.roll(np.roll(m, dy, 0), dx, 1)
    return out


class Georef(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.utm = T.jacksboro_utm(cls.dir)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def test_size_geotransform_crs_kept(self):
        for dem in (T.JACKSBORO, self.utm, T.LUX):
            with self.subTest(dem=os.path.basename(dem)):
                out = T.translate(dem, os.path.join(self.dir, "out.tif"))
                a, b = gdal.Open(dem), gdal.Open(out)
                self.assertEqual((a.RasterXSize, a.RasterYSize),
                                 (b.RasterXSize, b.RasterYSize))
                self.assertEqual(a.GetGeoTransform(), b.GetGeoTransform())
                self.assertTrue(a.GetSpatialRef().IsSame(b.GetSpatialRef()))

    def test_geodesic_cell_sizes(self):
        """Per-row east-west sizes on the WGS 84 ellipsoid, N-S mean."""
        ds = gdal.Open(T.conn(T.JACKSBORO))
        gt = gdal.Open(T.JACKSBORO).GetGeoTransform()
        a, f = 6378137.0, 1 / 298.257223563
        e2 = f * (2 - f)

        def parallel(lat):
            phi = math.radians(lat)
            return a * math.cos(phi) / math.sqrt(1 - e2 * math.sin(phi) ** 2) \
                * math.radians(gt[1])

        def meridian(lat):  # metres per radian of latitude
            phi = math.radians(lat)
            return a * (1 - e2) / (1 - e2 * math.sin(phi) ** 2) ** 1.5

        north = gt[3] + 0.5 * gt[5]
        south = gt[3] + (ds.RasterYSize - 0.5) * gt[5]
        mid = gt[3] + ds.RasterYSize / 2 * gt[5]
        md = ds.GetMetadata()
        print({k: v for k, v in md.items() if k.startswith("CELL")})
        self.assertAlmostEqual(float(md["CELL_SIZE_X_NORTH"]) / parallel(north), 1, 6)
        self.assertAlmostEqual(float(md["CELL_SIZE_X_SOUTH"]) / parallel(south), 1, 6)
        self.assertAlmostEqual(float(md["CELL_SIZE_Y"]) /
                               (meridian(mid) * math.radians(-gt[5])), 1, 6)
        # about 74 m east-west and 93 m north-south, as the data README says
        self.assertAlmostEqual(float(md["CELL_SIZE_X"]), 74.6, 0)
        self.assertAlmostEqual(float(md["CELL_SIZE_Y"]), 92.5, 0)

    def test_origin_many_turns_round_measures_the_same_cells(self):
        """A geographic DEM whose longitudes lie many turns round (origin at
        lon 1e300, or 1e13) has the cells and the products of the same DEM
        within a turn: lon0 + dlon rounded to lon0, and until session 52
        the parallels had no width (an svf of cliffs, min 2e-6 against
        0.997, and a warning blaming Z_FACTOR)."""
        heights = T.fractal_dem(64, seed=4, relief=30.0)
        out = {}
        for lon in (10.0, 1e13, 1e300):
            dem = T.write_tif(os.path.join(self.dir, "lon%g.tif" % lon), heights,
                              (lon, 0.001, 0, 45.0, 0, -0.001), 4326)
            ds = gdal.Open(T.conn(dem))
            self.assertAlmostEqual(float(ds.GetMetadataItem("CELL_SIZE_X")), 78.8, 0)
            ds = None
            out[lon] = T.read(T.translate(dem, os.path.join(self.dir, "svf%g.tif" % lon),
                                          {"PRODUCT": "svf", "DIRECTIONS": "8"}))
        for lon in (1e13, 1e300):
            with self.subTest(lon=lon):
                np.testing.assert_allclose(out[lon], out[10.0], atol=1e-6)

    def test_geographic_and_utm_shadows_match(self):
        """jacksboro in degrees and warped to UTM 17N give the same shadows.

        The UTM DEM is a bilinear resampling onto 90 m cells (the source has
        74 x 93 m cells), which lowers ridge crests by metres, and the
        geographic result is re-gridded by nearest neighbour for the
        comparison, which moves edges by up to a cell; both move shadow
        edges, not shadows. Azimuths are relative to grid north, which in
        UTM is 1.94 deg off true north here (meridian convergence), so the
        UTM run gets the sun at the same true azimuth. Tolerances, measured
        and then padded: >= 93% of the cells (3-cell margin from nodata)
        agree on lit / shadowed (measured 94.7 to 95.3%); >= 90% of the
        disagreeing cells lie within 3 cells of a shadow edge (measured
        97-99%); the shadowed fraction differs by <= 4 points (measured 2.6,
        the UTM DEM's smoothed ridges casting slightly less shadow). The
        classic mistakes would fail it: a 25% error in the cell size (93 m
        taken for the east-west size; Z_FACTOR=1.25 as a stand-in) moves the
        shadowed fraction by 6 to 8 points, degrees taken as metres by ~50.
        """
        ds = gdal.Open(self.utm)
        gt, W, H = ds.GetGeoTransform(), ds.RasterXSize, ds.RasterYSize
        north = T.utm17_grid_north(-84.2458, 36.5896, 0.1)
        print("grid azimuth of true north: %.3f deg" % north)
        for el, az in ((5, 135), (10, 135), (10, 315)):
            geo = T.translate(T.JACKSBORO, os.path.join(self.dir, "geo.tif"), {
                "PRODUCT": "shadow", "SUN_ELEVATION": el, "SUN_AZIMUTH": az})
            geo_utm = os.path.join(self.dir, "geo_utm.tif")
            T.run(["gdalwarp", "-q", "-overwrite", "-t_srs", "EPSG:32617",
                   "-te", gt[0], gt[3] + H * gt[5], gt[0] + W * gt[1], gt[3],
                   "-tr", gt[1], -gt[5], "-r", "near", geo, geo_utm])
            a = T.read(geo_utm, 1)
            b = T.read(T.conn(self.utm, PRODUCT="shadow", SUN_ELEVATION=el,
                              SUN_AZIMUTH=round((az + north) % 360, 3)), 1)
            inner = ~dilate(np.isnan(a) | np.isnan(b), 3)
            sa, sb = a[inner] >= 0.5, b[inner] >= 0.5
            agree = np.mean(sa == sb)
            fa, fb = 100 * np.mean(~sa), 100 * np.mean(~sb)
            lit_b = b >= 0.5
            edge = (lit_b != np.roll(lit_b, 1, 0)) | (lit_b != np.roll(lit_b, 1, 1))
            dis = inner & ((a >= 0.5) != lit_b)
            near_edge = (dis & dilate(edge, 3)).sum() / max(dis.sum(), 1)
            print("sun %2d deg at %3d: agree %.2f%%, shadowed %.2f%% (degrees) vs "
                  "%.2f%% (UTM), %.1f%% of disagreements within 3 cells of an "
                  "edge" % (el, az, 100 * agree, fa, fb, 100 * near_edge))
            self.assertGreaterEqual(agree, 0.93)
            self.assertGreaterEqual(near_edge, 0.90)
            self.assertLessEqual(abs(fa - fb), 4.0)

    def feet_copy(self, unit, factor):
        """The UTM DEM in another linear unit: coordinates and heights."""
        z, gt, _ = T.read_dem(self.utm)
        gt_ft = tuple(v / factor for v in gt)
        path = os.path.join(self.dir, "utm_%s.tif" % unit)
        T.write_tif(path, np.where(np.isnan(z), -32768, z / factor), gt_ft,
                    "+proj=utm +zone=17 +datum=WGS84 +units=%s +no_defs" % unit,
                    nodata=-32768)
        return path

    def test_tall_geographic_dem_warns_of_turned_sweeps(self):
        """A geographic DEM from 65 to 70 N: its sweeps keep their direction
        in cells, taken at its central row, so that on its northern and
        southern rows azimuth 45 is swept as 41.8 and 47.8 (session 50's
        audit measured that on planes and peaks of known azimuth); the open
        says so, giving the turn, atan(|k - 1| / (2 sqrt k)) with k the
        rows' cos of latitude over the centre's. Not on jacksboro (0.1
        degrees tall), nor with METHOD=shadowmap, which takes each row's
        own width."""
        tall = os.path.join(self.dir, "tall.tif")
        T.write_tif(tall, np.zeros((1000, 40), np.float32), (10.0, 0.005, 0, 70.0, 0, -0.005),
                    4326)
        k = [math.cos(math.radians(lat)) / math.cos(math.radians(70.0 - 500.5 * 0.005))
             for lat in (70.0 - 0.0025, 65.0 + 0.0025)]
        turn = max(math.degrees(math.atan(abs(x - 1) / (2 * math.sqrt(x)))) for x in k)
        self.assertAlmostEqual(turn, 3.2, delta=0.05)
        said = T.open_stderr(tall, PRODUCT="horizon")
        print(said.strip())
        self.assertIn("an azimuth is swept up to %.1f degrees turned" % turn, said)
        self.assertNotIn("swept up to", T.open_stderr(tall, PRODUCT="shade", METHOD="shadowmap"))
        self.assertNotIn("swept up to", T.open_stderr(T.JACKSBORO, PRODUCT="horizon"))

    def test_feet_and_us_survey_feet(self):
        ref = T.read(T.conn(self.utm, PRODUCT="shadow", SUN_ELEVATION=10))
        for unit, factor in (("ft", FT), ("us-ft", US_FT)):
            with self.subTest(unit=unit):
                dem = self.feet_copy(unit, factor)
                ds = gdal.Open(T.conn(dem))
                self.assertAlmostEqual(float(ds.GetMetadataItem("CELL_SIZE_X")), 90, 4)
                got = T.read(T.conn(dem, PRODUCT="shadow", SUN_ELEVATION=10,
                                    Z_FACTOR=repr(factor)))
                print(T.describe("shadow, %s vs metres" % unit, got, ref))
                np.testing.assert_array_equal(np.isnan(got), np.isnan(ref))
                self.assertGreater(np.mean(np.abs(got - ref)[~np.isnan(ref)] < 1e-3),
                                   0.999)

    def test_rotated_or_sheared_geotransform_is_an_error(self):
        z = T.fractal_dem(64)
        for gt in ((600000, 30, 5, 4000000, 5, -30),   # rotated
                   (600000, 30, 3, 4000000, 0, -30)):  # sheared
            dem = T.write_tif(os.path.join(self.dir, "rot.tif"), z, gt, 32617)
            p = T.run(["gdal_translate", T.conn(dem),
                       os.path.join(self.dir, "x.tif")], ok=False)
            print(p.stderr.strip())
            self.assertIn("rotated or sheared", p.stderr)
            self.assertIn("gdalwarp", p.stderr)

    def test_south_up_and_east_west_grids(self):
        z = T.fractal_dem(96, seed=3)
        north_up = T.write_tif(os.path.join(self.dir, "nu.tif"), z,
                               (600000, 30, 0, 4000000, 0, -30), 32617)
        south_up = T.write_tif(os.path.join(self.dir, "su.tif"), z[::-1],
                               (600000, 30, 0, 4000000 - 96 * 30, 0, 30), 32617)
        east_west = T.write_tif(os.path.join(self.dir, "ew.tif"), z[:, ::-1],
                                (600000 + 96 * 30, -30, 0, 4000000, 0, -30), 32617)
        opts = dict(PRODUCT="shadow", SUN_ELEVATION=10, SUN_AZIMUTH=135)
        ref = T.read(T.conn(north_up, **opts), 1)
        np.testing.assert_array_equal(T.read(T.conn(south_up, **opts), 1), ref[::-1])
        np.testing.assert_array_equal(T.read(T.conn(east_west, **opts), 1),
                                      ref[:, ::-1])
        self.assertEqual(gdal.Open(T.conn(south_up)).GetGeoTransform(),
                         gdal.Open(south_up).GetGeoTransform())

    def test_no_crs_means_metres_with_a_warning(self):
        z = T.fractal_dem(64, seed=5)
        gt = (0, 30, 0, 0, 0, -30)
        bare = T.write_tif(os.path.join(self.dir, "bare.tif"), z, gt, None)
        utm = T.write_tif(os.path.join(self.dir, "z_utm.tif"), z, gt, 32617)
        p = T.run(["gdalinfo", T.conn(bare)])
        self.assertIn("has no CRS", p.stderr)
        np.testing.assert_array_equal(T.read(T.conn(bare)), T.read(T.conn(utm)))

    def test_local_crs_in_metres(self):
        """An engineering (local) CRS in metres: its cells are metres, as a
        projected CRS's, and nothing is said of an ellipsoid it does not
        have (PROJ's 'CRS has no geodetic CRS' came out as four ERROR
        lines, with exit 0; session 54's audit)."""
        z = T.fractal_dem(64, seed=5)
        gt = (0, 30, 0, 0, 0, -30)
        local = T.write_tif(os.path.join(self.dir, "local.tif"), z, gt,
                            'LOCAL_CS["site grid",LOCAL_DATUM["site",0],'
                            'UNIT["metre",1],AXIS["E",EAST],AXIS["N",NORTH]]')
        utm = T.write_tif(os.path.join(self.dir, "l_utm.tif"), z, gt, 32617)
        out = os.path.join(self.dir, "local_shade.tif")
        p = T.run(["gdal_translate", "-q", T.conn(local), out])
        self.assertNotIn("ERROR", p.stderr)
        np.testing.assert_array_equal(T.read(out), T.read(T.conn(utm)))

    def test_no_geotransform_means_1_m_cells_north_up(self):
        z = T.fractal_dem(64, seed=6)
        path = os.path.join(self.dir, "nogt.tif")
        ds = gdal.GetDriverByName("GTiff").Create(path, 64, 64, 1, gdal.GDT_Float32)
        ds.GetRasterBand(1).WriteArray(z)
        ds = None
        one = T.write_tif(os.path.join(self.dir, "one_m.tif"), z, (0, 1, 0, 0, 0, -1),
                          None)
        p = T.run(["gdalinfo", T.conn(path)])
        self.assertIn("has no geotransform", p.stderr)
        self.assertNotIn("Origin", p.stdout)  # and the output has none either
        opts = dict(PRODUCT="shadow", SUN_ELEVATION=10, SUN_AZIMUTH=135)
        np.testing.assert_array_equal(T.read(T.conn(path, **opts)),
                                      T.read(T.conn(one, **opts)))

    def test_control_points_say_warp_first(self):
        """A DEM georeferenced by ground control points (no geotransform) is
        computed on 1 m cells, and the warning says to warp it first."""
        z = T.fractal_dem(64, seed=6)
        path = os.path.join(self.dir, "gcps.tif")
        ds = gdal.GetDriverByName("GTiff").Create(path, 64, 64, 1, gdal.GDT_Float32)
        ds.GetRasterBand(1).WriteArray(z)
        srs = osr.SpatialReference()
        srs.ImportFromEPSG(32617)
        ds.SetGCPs([gdal.GCP(600000 + 30 * x, 4000000 - 30 * y, 0, x, y)
                    for x, y in ((0, 0), (64, 0), (0, 64))], srs.ExportToWkt())
        ds = None
        p = T.run(["gdalinfo", T.conn(path)])
        self.assertIn("has no geotransform: its cells are taken as 1 x 1 metre, row 0 north; "
                      "it is georeferenced by 3 ground control points, which terrashade does "
                      "not follow: warp it to a north-up grid first (gdalwarp dem.tif "
                      "north_up.tif)", p.stderr)

    def test_any_gdal_name(self):
        """/vsizip, /vsimem, colons and '=' in names, drive letters."""
        ref = T.read(T.conn(T.LUX, PRODUCT="svf", DIRECTIONS=4))
        d = os.path.join(self.dir, "run=1")
        os.makedirs(d, exist_ok=True)
        colon = os.path.join(d, "lux:elev:copy.tif")
        shutil.copy(T.LUX, colon)
        zpath = os.path.join(self.dir, "dem.zip")
        with zipfile.ZipFile(zpath, "w") as zf:
            zf.write(T.LUX, "sub/lux.tif")
        with open(T.LUX, "rb") as f:
            gdal.FileFromMemBuffer("/vsimem/lux.tif", f.read())
        for name in (colon, "/vsizip/%s/sub/lux.tif" % zpath, "/vsimem/lux.tif"):
            with self.subTest(name=name):
                got = T.read(T.conn(name, PRODUCT="svf", DIRECTIONS=4))
                np.testing.assert_array_equal(got, ref)
        # a relative name starting like KEY=VALUE: quote it
        shutil.copy(T.LUX, os.path.join(self.dir, "x=1.tif"))
        got = T.read('TERRASHADE:PRODUCT=svf,DIRECTIONS=4:"x=1.tif"'.replace(
            "x=1.tif", os.path.join(self.dir, "x=1.tif")))
        np.testing.assert_array_equal(got, ref)
        p = T.run(["gdalinfo", 'TERRASHADE:PRODUCT=svf,DIRECTIONS=4:"x=1.tif"'],
                  cwd=self.dir)
        self.assertIn("PRODUCT=svf", p.stdout)
        # a drive letter is part of the name, not an option segment
        for c in ("TERRASHADE:C:\\dem.tif", "TERRASHADE:PRODUCT=svf:C:\\dem.tif"):
            p = T.run(["gdalinfo", c], ok=False)
            self.assertIn("cannot open the DEM 'C:\\dem.tif'", p.stderr)
        gdal.Unlink("/vsimem/lux.tif")


if __name__ == "__main__":
    unittest.main(verbosity=2)
