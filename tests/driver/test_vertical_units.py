"""Z_FACTOR=AUTO (the default): heights in the DEM's vertical unit become
metres, from the vertical CRS or the band's unit type; a number overrides;
the metadata says which factor was used and why (docs/driver.md)."""
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np

# NAD83 / North Carolina (ftUS): cells in US survey feet
NC_GT = (2000000.0, 100.0, 0.0, 600000.0, 0.0, -100.0)
FT_US = 1200.0 / 3937.0
OPTIONS = {"PRODUCT": "shadow", "SUN_ELEVATION": "6", "SUN_AZIMUTH": "120",
           "PROGRESS": "no"}


def opened(dem, **options):
    oo = ["%s=%s" % kv for kv in dict(OPTIONS, **options).items()]
    return gdal.OpenEx(T.conn(dem), gdal.OF_RASTER, open_options=oo)


class VerticalUnits(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        d = cls.dir = cls.tmp.__enter__()
        cls.z = T.fractal_dem(64, seed=11, relief=2000.0)  # the numbers in the file
        # heights in US survey feet, said by a compound CRS (NAVD88 height (ftUS))
        cls.ftus = T.write_tif(os.path.join(d, "ftus.tif"), cls.z, NC_GT, "EPSG:2264+6360")
        # heights in feet, said by the band's unit only
        cls.ft = T.write_tif(os.path.join(d, "ft.tif"), cls.z, NC_GT, 2264)
        ds = gdal.Open(cls.ft, gdal.GA_Update)
        ds.GetRasterBand(1).SetUnitType("ft")
        ds = None
        # nothing says the unit: metres
        cls.plain = T.write_tif(os.path.join(d, "plain.tif"), cls.z, NC_GT, 2264)
        # the same terrain converted to metres beforehand
        cls.m_ftus = T.write_tif(os.path.join(d, "m_ftus.tif"),
                                 (cls.z.astype(np.float64) * FT_US).astype(np.float32),
                                 NC_GT, 2264)
        cls.m_ft = T.write_tif(os.path.join(d, "m_ft.tif"),
                               (cls.z.astype(np.float64) * 0.3048).astype(np.float32),
                               NC_GT, 2264)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def check(self, dem, factor, source, same_as, **options):
        ds = opened(dem, **options)
        md = ds.GetMetadata()
        print(os.path.basename(dem), options, "->", md["Z_FACTOR"], "(%s)" % md["Z_FACTOR_SOURCE"])
        self.assertEqual(md["Z_FACTOR"], "%.10g" % factor)
        self.assertEqual(md["Z_FACTOR_SOURCE"], source)
        got = ds.GetRasterBand(1).ReadAsArray()
        ds = None
        want = T.read(T.conn(same_as), band=1, options=OPTIONS)
        np.testing.assert_array_equal(got, want)
        return got

    def test_compound_crs_in_us_survey_feet(self):
        got = self.check(self.ftus, FT_US, "vertical unit US survey foot, from the CRS",
                         self.m_ftus)
        # as metres the terrain would be 3.28 times too steep: other shadows
        self.assertFalse(np.array_equal(got, T.read(T.conn(self.plain), band=1,
                                                    options=OPTIONS)))

    def test_products_carry_no_vertical_crs(self):
        """Shading is no height: a product of a DEM in a compound CRS
        reports its horizontal part only (its overview levels are set up
        alike), so that
        gdalwarp does not convert its values by the vertical unit (an svf
        of a DEM in NAVD88 feet, warped to UTM, read 0.295 for 0.969 until
        session 58's CRS audit). Its heights are still taken in feet, and an
        atlas of it reads its near shadows from the compound DEM."""
        ds = opened(self.ftus, PRODUCT="svf", OUTPUT_TYPE="Float32")
        srs = ds.GetSpatialRef()
        self.assertFalse(srs.IsCompound())
        self.assertTrue(srs.IsProjected())
        self.assertEqual(ds.GetMetadataItem("Z_FACTOR"), "%.10g" % FT_US)
        want = ds.GetRasterBand(1).ComputeStatistics(False)[2]
        ds = None
        out = os.path.join(self.dir, "svf_utm.tif")
        T.run(["gdalwarp", "-q", "-overwrite", "-t_srs", "EPSG:32617"] +
              T.oo_args(dict(OPTIONS, PRODUCT="svf")) + [T.conn(self.ftus), out])
        ds = gdal.Open(out)
        got = ds.GetRasterBand(1).ComputeStatistics(False)[2]
        ds = None
        print("svf mean %.4f, warped to UTM %.4f" % (want, got))
        self.assertAlmostEqual(got, want, delta=0.02)
        # the DEM as a VRT too, whose data axes gdalbuildvrt writes out
        # ("1,2,3": left on two axes, the product's CRS differed from the
        # same CRS read elsewhere, and its atlas's SHADOWS=all was refused:
        # the review)
        vrt = os.path.join(self.dir, "ftus.vrt")
        T.run(["gdalbuildvrt", "-q", vrt, self.ftus])
        plain = gdal.osr.SpatialReference()
        plain.ImportFromEPSG(2264)
        plain.SetAxisMappingStrategy(gdal.osr.OAMS_TRADITIONAL_GIS_ORDER)
        for dem in (self.ftus, vrt):
            ds = opened(dem)
            self.assertTrue(ds.GetSpatialRef().IsSame(plain), dem)
            self.assertEqual(ds.GetSpatialRef().GetDataAxisToSRSAxisMapping(), [1, 2])
            ds = None
            tsa = os.path.join(self.dir, "ftus.tsa")
            T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + T.oo_args(dict(
                PRODUCT="farshadow", DATE="2026-06-21", TIMEZONE="-05:00", ATLAS_STEPS=2,
                FAR_THRESHOLD=8)) + [T.conn(dem), tsa])
            ds = gdal.OpenEx(tsa, gdal.OF_RASTER, open_options=["SHADOWS=all"])
            self.assertIsNotNone(ds.GetRasterBand(1).Checksum())
            ds = None

    def test_a_vertical_crs_alone_scales_only(self):
        """A DEM whose CRS is a vertical one alone (a VRT's SRS EPSG:6360):
        its unit scales the heights, and it places nothing: the DEM opens
        as one without a CRS, with a warning that says which it has (it
        said "the DEM has no CRS", beside three PROJ errors on asking it for
        an ellipsoid: session 58's CRS audit), and its products carry none.
        A local CRS is SOURCE_CRS_KIND=local (it said projected)."""
        vrt = T.write_vrt(os.path.join(self.dir, "vertical.vrt"), self.plain, 64, 64, NC_GT,
                          "EPSG:6360")
        p = T.run(["gdalinfo", T.conn(vrt, **OPTIONS)])
        print(p.stderr.strip())
        self.assertNotIn("ERROR", p.stderr)
        self.assertIn("the DEM has a vertical CRS only (NAVD88 height (ftUS))", p.stderr)
        self.assertIn("SOURCE_CRS_KIND=none", p.stdout)
        self.assertIn("Z_FACTOR=%.10g" % FT_US, p.stdout)
        ds = opened(vrt)
        self.assertIsNone(ds.GetSpatialRef())
        ds = None
        # and where a CRS on the ground is needed, it says which it has
        for options, said in ((dict(OPTIONS, CELL_SIZES="ground"),
                               "CELL_SIZES=ground: the DEM has a vertical CRS only"),
                              ({"PRODUCT": "shadow", "DATETIME": "2026-06-21T1200Z"},
                               "has a vertical CRS only")):
            p = T.run(["gdalinfo", T.conn(vrt, **options)], ok=False)
            self.assertIn(said, p.stderr)
        local = T.write_tif(os.path.join(self.dir, "local.tif"), self.z, NC_GT,
                            'LOCAL_CS["site",UNIT["metre",1]]')
        ds = opened(local)
        self.assertEqual(ds.GetMetadataItem("SOURCE_CRS_KIND"), "local")
        ds = None
        # an engineering CRS in feet with heights in NAVD88 feet: local, its
        # cells in its feet (taken as no CRS, 3.3 times too long, beside
        # four PROJ errors: the review), its heights in the vertical unit
        eng = ('ENGCRS["site ft",EDATUM["d"],CS[Cartesian,2],AXIS["x",east,LENGTHUNIT['
               '"foot",0.3048]],AXIS["y",north,LENGTHUNIT["foot",0.3048]]]')
        vert = ('VERTCRS["NAVD88 height (ftUS)",VDATUM["North American Vertical Datum 1988"],'
                'CS[vertical,1],AXIS["gravity-related height (H)",up,LENGTHUNIT['
                '"US survey foot",0.304800609601219]],ID["EPSG",6360]]')
        both = T.write_vrt(os.path.join(self.dir, "engvert.vrt"), self.plain, 64, 64, NC_GT,
                           'COMPOUNDCRS["site ft+NAVD88",%s,%s]' % (eng, vert))
        p = T.run(["gdalinfo", T.conn(both, **OPTIONS)])
        self.assertNotIn("ERROR", p.stderr)
        self.assertNotIn("no CRS", p.stderr)
        self.assertIn("SOURCE_CRS_KIND=local", p.stdout)
        self.assertIn("CELL_SIZE_X=%.6f" % (NC_GT[1] * 0.3048), p.stdout)
        self.assertIn("Z_FACTOR=%.10g" % FT_US, p.stdout)

    def test_band_unit_feet(self):
        self.check(self.ft, 0.3048, "band unit ft", self.m_ft)

    def test_band_units_in_metric_multiples(self):
        """Heights in centimetres or millimetres (integer DEMs often are), said
        by the band's unit in any spelling: the terrain in metres."""
        m = T.write_tif(os.path.join(self.dir, "m_small.tif"), self.z / 100.0, NC_GT, 32617)
        for unit, factor in (("cm", 0.01), ("centimetres", 0.01), ("Millimeters", 0.001)):
            with self.subTest(unit=unit):
                path = T.write_tif(os.path.join(self.dir, "u_%s.tif" % unit),
                                   self.z / 100.0 / factor, NC_GT, 32617)
                ds = gdal.Open(path, gdal.GA_Update)
                ds.GetRasterBand(1).SetUnitType(unit)
                ds = None
                ds = opened(path)
                self.assertEqual(ds.GetMetadataItem("Z_FACTOR_SOURCE"), "band unit " + unit)
                self.assertAlmostEqual(float(ds.GetMetadataItem("Z_FACTOR")), factor, 12)
                got = ds.GetRasterBand(1).ReadAsArray()
                ds = None
                want = T.read(T.conn(m), band=1, options=OPTIONS)
                np.testing.assert_allclose(got, want, atol=1e-5)

    def test_band_unit_spellings(self):
        """The spellings of feet and metres that DEMs carry (underscores,
        hyphens, case, plurals, a datum word after the unit): the same factor
        as the plain name, said in the metadata as the band spells it."""
        for unit, factor in (("usft", FT_US), ("ft_US", FT_US), ("us_survey_foot", FT_US),
                             ("US Survey Feet", FT_US), ("survey foot", FT_US),
                             ("U.S. survey foot", FT_US), ("ft asl", 0.3048),
                             ("Feet (NAVD88)", 0.3048),
                             ("m AMSL", 1.0), ("Meters", 1.0), ("metre-height", 1.0),
                             ("feet US", FT_US), ("foot (US survey)", FT_US),
                             ("m.a.s.l.", 1.0)):
            with self.subTest(unit=unit):
                path = os.path.join(self.dir, "spelled.tif")
                T.write_tif(path, self.z, NC_GT, 2264)
                ds = gdal.Open(path, gdal.GA_Update)
                ds.GetRasterBand(1).SetUnitType(unit)
                ds = None
                ds = opened(path)
                self.assertEqual(ds.GetMetadataItem("Z_FACTOR"), "%.10g" % factor)
                self.assertEqual(ds.GetMetadataItem("Z_FACTOR_SOURCE"), "band unit " + unit)
                ds = None
                self.assertNotIn("Warning", T.open_stderr(path))

    def test_unknown_band_unit_warns(self):
        """A band unit that is not a length terrashade knows: metres, with a
        warning that names it and the factors to give (until session 49 the
        heights were taken as metres without a word)."""
        path = os.path.join(self.dir, "unknown.tif")
        T.write_tif(path, self.z, NC_GT, 32617)
        ds = gdal.Open(path, gdal.GA_Update)
        ds.GetRasterBand(1).SetUnitType("dam")
        ds = None
        err = T.open_stderr(path)
        self.assertIn("Warning 1: TERRASHADE: the DEM's band gives its heights' unit as 'dam', "
                      "which is not a length terrashade knows: they are taken as metres. Give "
                      "Z_FACTOR, the metres of one unit (0.3048 for feet, 0.3048006096 for US "
                      "survey feet), or 1 if they are metres", err)
        self.assertEqual(err.count("Warning"), 1)
        self.assertNotIn("heights' unit", T.open_stderr(path, Z_FACTOR="10"))

    def test_crs_and_band_disagree_warns(self):
        """A compound CRS in US survey feet and a band unit of metres: the CRS
        wins, as documented, and a warning says so with the other factor."""
        path = T.write_tif(os.path.join(self.dir, "conflict.tif"), self.z, NC_GT,
                           "EPSG:2264+6360")
        ds = gdal.Open(path, gdal.GA_Update)
        ds.GetRasterBand(1).SetUnitType("m")
        ds = None
        ds = opened(path)
        self.assertEqual(ds.GetMetadataItem("Z_FACTOR"), "%.10g" % FT_US)
        ds = None
        err = T.open_stderr(path)
        self.assertIn("the DEM's CRS gives its heights in US survey foot, its band in 'm': the "
                      "CRS's unit is used (Z_FACTOR=0.3048006096). If the heights are in m, "
                      "give Z_FACTOR=1", err)
        self.assertNotIn("Warning", T.open_stderr(self.ftus))

    def test_no_unit_is_metres(self):
        self.check(self.plain, 1.0,
                   "no vertical unit in the CRS or the band: heights taken as metres",
                   self.plain)

    def test_no_unit_on_a_grid_in_feet_warns(self):
        """A state plane grid in US survey feet whose heights say no unit: taken
        as metres, with a warning that gives the factor of feet; none where the
        unit is said (CRS, band) or Z_FACTOR is given, nor on a grid in metres."""
        err = T.open_stderr(self.plain)
        print(err.strip())
        self.assertIn("Warning 1: TERRASHADE: the DEM '%s' is gridded in US survey foot (its "
                      "CRS), but nothing says its heights' unit: they are taken as metres. If "
                      "they are in US survey foot too, as on most such grids, give "
                      "Z_FACTOR=0.3048006096 or say so (gdal_edit.py -units 'US survey foot' "
                      "'%s')" % (self.plain, self.plain), err)
        for dem, oo in ((self.ftus, {}), (self.ft, {}), (self.plain, {"Z_FACTOR": "1"}),
                        (T.jacksboro_utm(self.dir), {})):
            with self.subTest(dem=os.path.basename(dem), **oo):
                self.assertNotIn("heights' unit", T.open_stderr(dem, **oo))

    def test_number_overrides(self):
        self.check(self.ftus, 1.0, "given as Z_FACTOR", self.plain, Z_FACTOR="1")
        self.check(self.ft, FT_US, "given as Z_FACTOR", self.m_ftus, Z_FACTOR=repr(FT_US))
        # AUTO given explicitly is the default
        self.check(self.ftus, FT_US, "vertical unit US survey foot, from the CRS",
                   self.m_ftus, Z_FACTOR="auto")

    def test_sample_dems_stay_in_metres(self):
        """jacksboro and lux_elev say no vertical unit: factor 1, as before."""
        for dem in (T.JACKSBORO, T.LUX):
            ds = opened(dem)
            self.assertEqual(ds.GetMetadataItem("Z_FACTOR"), "1")
            self.assertEqual(ds.GetMetadataItem("Z_FACTOR_SOURCE"),
                             "no vertical unit in the CRS or the band: heights taken as metres")
            ds = None

    def test_not_a_number(self):
        with self.assertRaises(RuntimeError) as e:
            opened(self.plain, Z_FACTOR="feet")
        self.assertEqual(str(e.exception),
                         "TERRASHADE: Z_FACTOR must be AUTO or a number, got 'feet'")


if __name__ == "__main__":
    unittest.main(verbosity=2)
