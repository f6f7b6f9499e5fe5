"""Heights no terrain has: an undeclared nodata value (-32768, -3.4e38...) is
an error that names the value, the cell and the remedy, never a silent
raster shaded around a 33 km deep hole; real extremes, exaggeration,
heights in another unit and other bodies are accepted. A colour image's
channel or a palette's classes are not heights either."""
import os
import unittest

import tsdriver as T
from tsdriver import gdal, np
from osgeo import osr

GT = (600000, 30, 0, 4000000, 0, -30)
UTM = 32617
# Mars, geographic, IAU's sphere-ish ellipsoid (no EPSG code)
MARS = "+proj=longlat +a=3396190 +b=3376200 +no_defs"


def failure(conn, extra=()):
    """gdal_translate of conn must fail; its stderr."""
    with T.TempDir() as tmp:
        p = T.run(["gdal_translate", "-q"] + list(extra)
                  + [conn, os.path.join(tmp, "o.tif")], ok=False)
    return p.stderr


class ImpossibleHeights(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmpdir = T.TempDir()
        cls.tmp = cls.tmpdir.__enter__()
        cls.z = T.fractal_dem(96, seed=4, relief=800.0)  # 100 .. 900 m

    @classmethod
    def tearDownClass(cls):
        cls.tmpdir.__exit__(None, None, None)

    def dem(self, name, z, srs=UTM, nodata=None, dtype=gdal.GDT_Float32):
        return T.write_tif(os.path.join(self.tmp, name), z, GT, srs, nodata, dtype)

    def with_void(self, value, rows=slice(40, 52), cols=slice(30, 47)):
        z = self.z.copy()
        z[rows, cols] = value
        return z

    def test_undeclared_int16_void_is_an_error_naming_it(self):
        """-32768 in an Int16 DEM without a nodata value: an error with the
        value, its first cell and the gdal_edit.py line that declares it."""
        dem = self.dem("int16.tif", np.round(self.with_void(-32768)), dtype=gdal.GDT_Int16)
        for p in ("shade", "svf", "horizon"):
            with self.subTest(product=p):
                err = failure(T.conn(dem, PRODUCT=p, DIRECTIONS=4))
                print(err.strip().splitlines()[0])
                self.assertIn("ERROR 5: TERRASHADE: the DEM", err)
                self.assertIn("holds a height no terrain has: -32768 m in band 1 at "
                              "column 30, row 40", err)
                self.assertIn("gdal_edit.py -a_nodata -32768 " + dem, err)

    def test_scaled_integer_voids_are_an_error(self):
        """The integer types' customary voids (Int16 -32768, UInt16 65535)
        undeclared in a DEM whose scale brings them within the Earth's
        heights (centimetres: a pit 327.68 m deep, a tower 655.35 m high;
        decimetres: 3.3 km deep, too gentle a step for a cliff) are an error
        naming the value and the cell, through the whole DEM, windows and an
        overview level; declared, they are nodata; a Float32 copy of the same
        values is taken as heights."""
        z = self.z - 100.0  # 0 .. 800 m
        for dtype, void, unit in ((gdal.GDT_Int16, -32768, 0.01),
                                  (gdal.GDT_UInt16, 65535, 0.01),
                                  (gdal.GDT_Int16, -32768, 0.1)):
            name = "%s_%g" % (gdal.GetDataTypeName(dtype), unit)
            raw = np.round(z / 0.1 if unit == 0.1 else z / 2.0 / unit)  # cm: 0 .. 400 m
            raw[40:52, 30:47] = void
            with self.subTest(dem=name):
                dem = self.dem(name + ".tif", raw, dtype=dtype)
                ds = gdal.Open(dem, gdal.GA_Update)
                ds.GetRasterBand(1).SetScale(unit)
                ds = None
                for extra in ({"TILE_SIZE": 0}, {"TILE_SIZE": 64}):
                    err = failure(T.conn(dem, PRODUCT="svf", DIRECTIONS=4, **extra))
                    self.assertIn("holds %d, the value %s DEMs leave in their voids, in band 1 "
                                  "at column 30, row 40 (%.6g m after its scale"
                                  % (void, gdal.GetDataTypeName(dtype), void * unit), err)
                    self.assertIn("gdal_edit.py -a_nodata %d %s" % (void, dem), err)
                # declared: nodata
                declared = self.dem(name + "_nd.tif", raw, dtype=dtype, nodata=void)
                ds = gdal.Open(declared, gdal.GA_Update)
                ds.GetRasterBand(1).SetScale(unit)
                ds = None
                out = T.read(T.conn(declared, PRODUCT="svf", DIRECTIONS=4), 1)
                np.testing.assert_array_equal(np.isnan(out), raw == void)
                # a Float32 copy: heights, as the message says
                copy = os.path.join(self.tmp, name + "_f32.tif")
                T.run(["gdal_translate", "-q", "-ot", "Float32", dem, copy])
                out = T.read(T.conn(copy, PRODUCT="svf", DIRECTIONS=4), 1)
                self.assertFalse(np.isnan(out).any())
        # a scale of 0 (every height the offset: a flat product, said by
        # nothing) and a scale or offset that is no number (no height at
        # all: an empty product) are errors, not a void
        for scale, offset, says in ((0, 100, "every height would be the offset, a flat plane"),
                                    (float("nan"), 0, "no height would be a number"),
                                    (0.01, float("inf"), "no height would be a number")):
            with self.subTest(scale=scale, offset=offset):
                flat = self.dem("scale.tif", np.arange(96 * 96).reshape(96, 96),
                                dtype=gdal.GDT_Int16)
                ds = gdal.Open(flat, gdal.GA_Update)
                ds.GetRasterBand(1).SetScale(scale)
                ds.GetRasterBand(1).SetOffset(offset)
                ds = None
                for extra in ({"TILE_SIZE": 0}, {"TILE_SIZE": 64}):
                    err = failure(T.conn(flat, PRODUCT="svf", DIRECTIONS=4, **extra))
                    self.assertIn("gives band 1 a scale of %g and an offset of %g: %s"
                                  % (scale, offset, says), err)
                    self.assertIn("gdal_edit.py -scale 1 -offset 0", err)
        # an overview level (a 600 x 600 DEM has one of 300 x 300): a coarse
        # cell all of whose cells are the void
        big = np.round(T.fractal_dem(600, seed=4, relief=300.0) / 0.01)
        big[401:420, 333:350] = -32768
        dem = self.dem("big_cm.tif", big, dtype=gdal.GDT_Int16)
        ds = gdal.Open(dem, gdal.GA_Update)
        ds.GetRasterBand(1).SetScale(0.01)
        ds = None
        err = failure(T.conn(dem), ["-outsize", "50%", "0", "-r", "nearest"])
        self.assertIn("holds -32768, the value Int16 DEMs leave in their voids, in band 1 "
                      "near column 334, row 402", err)

    def test_32_bit_voids_are_named_exactly(self):
        """The value the remedy declares is the band's own: an Int32 void
        -2147483648 was named from its float height, -2.14748365e+09, which
        declared (gdal_edit.py) matched no cell, and the error came back;
        so did UInt32's 4294967295 and an Int32 -99999999 (-100000000). The
        remedy as given makes them nodata."""
        for dtype, void in ((gdal.GDT_Int32, -2147483648), (gdal.GDT_UInt32, 4294967295),
                            (gdal.GDT_Int32, -99999999)):
            name = "%s_%d.tif" % (gdal.GetDataTypeName(dtype), void)
            z = np.round(self.z).astype(np.float64)  # (float32 holds 24 bits)
            z[40:52, 30:47] = void
            with self.subTest(dem=name):
                dem = self.dem(name, z, dtype=dtype)
                err = failure(T.conn(dem, PRODUCT="svf", DIRECTIONS=4))
                self.assertIn("gdal_edit.py -a_nodata %d %s" % (void, dem), err)
                T.run(["gdal_edit.py", "-a_nodata", str(void), dem])
                out = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=4), 1)
                np.testing.assert_array_equal(np.isnan(out), z == void)

    def test_declared_it_is_nodata(self):
        """The remedy the error gives works: the void is nodata in the output."""
        z = self.with_void(-32768)
        dem = self.dem("declared.tif", z, nodata=-32768)
        out = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8), 1)
        np.testing.assert_array_equal(np.isnan(out), z == -32768)
        self.assertTrue(np.all((out[z != -32768] >= 0) & (out[z != -32768] <= 1)))

    def test_float_extremes_in_every_path(self):
        """-3.4e38 (ArcGIS's float nodata) and 1e30, through the whole DEM,
        windows (TILE_SIZE) and an overview level (averaged: 'near')."""
        for value in (-3.4028234663852886e38, 1e30):
            dem = self.dem("f%g.tif" % value, self.with_void(value))
            with self.subTest(value=value, path="whole"):
                err = failure(T.conn(dem, TILE_SIZE=0))
                self.assertIn("holds a height no terrain has: %.6g m in band 1 at column 30, "
                              "row 40" % np.float32(value), err)
                self.assertIn("-a_nodata %.17g " % np.float32(value), err)
            with self.subTest(value=value, path="windows"):
                err = failure(T.conn(dem, TILE_SIZE=64))
                self.assertIn("holds a height no terrain has", err)
        # an overview level (a 600 x 600 DEM has one of 300 x 300): the
        # averaged cell says where it lies in the DEM
        big = T.fractal_dem(600, seed=4, relief=800.0)
        big[401:420, 333:350] = -3.4028234663852886e38
        dem = self.dem("big.tif", big)
        err = failure(T.conn(dem), ["-outsize", "50%", "0", "-r", "nearest"])
        self.assertRegex(err, r"no terrain has: -\d\.\d+e\+3[78] m \(averaged\) in band 1 near "
                              r"column 332, row 400")
        self.assertNotIn("-a_nodata", err)  # an average is not the DEM's value

    def test_float64_beyond_the_float_range(self):
        """A Float64 DEM's heights beyond the float range (1e39, 1e300)
        read as infinities, which are nodata: they were silently nodata
        (all of a 1e100 DEM, exit 0) until session 52; refused now as 1e30
        is, whole and windowed. (An overview level's average is GDAL's,
        which leaves such cells out as it does infinities.) Declared
        nodata -DBL_MAX, common in Float64 rasters, stays nodata."""
        z64 = self.z.astype(np.float64)
        for value in (1e39, 1e300):
            z = z64.copy()
            z[40:52, 30:47] = value
            dem = self.dem("f64_%g.tif" % value, z, dtype=gdal.GDT_Float64)
            for path, extra in (("whole", {"TILE_SIZE": 0}), ("windows", {"TILE_SIZE": 64})):
                with self.subTest(value=value, path=path):
                    err = failure(T.conn(dem, **extra))
                    self.assertIn("holds a value no terrain's height is: %.6g in band 1 at "
                                  "column 30, row 40, beyond the range of 32-bit floats"
                                  % value, err)
                    if path == "whole":  # the value to declare, whole
                        self.assertIn("gdal_edit.py -a_nodata %.17g " % value, err)
        z = z64.copy()
        z[40:52, 30:47] = -1.7976931348623157e308
        dem = self.dem("f64nd.tif", z, nodata=-1.7976931348623157e308, dtype=gdal.GDT_Float64)
        out = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8), 1)
        np.testing.assert_array_equal(np.isnan(out), z == -1.7976931348623157e308)

    def test_the_deepest_and_highest_terrain_are_accepted(self):
        """The Challenger Deep (-10 935 m) and Everest (8 849 m) are terrain:
        a DEM of 1 km cells that climbs from one to the other (206 m between
        neighbours) opens with no error and gives a finite result."""
        z = np.linspace(-10935.0, 8849.0, 97, dtype=np.float32)[None, :].repeat(64, 0)
        dem = T.write_tif(os.path.join(self.tmp, "extremes.tif"), z,
                          (500000, 1000, 0, 4000000, 0, -1000), UTM)
        out = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8), 1)
        self.assertTrue(np.isfinite(out).all())

    def test_an_undeclared_void_within_the_earths_heights_is_a_cliff(self):
        """-9999 (a void no nodata value declares) beside land is a cliff of
        10 km between cells 30 m apart: an error naming both cells and the
        void's value to declare; declared, the cells are nodata. The same
        in a geographic DEM (jacksboro, 3 arc-seconds)."""
        z = self.with_void(-9999.0)
        dem = self.dem("void9999.tif", z)
        for options in ({}, {"TILE_SIZE": 64}):
            with self.subTest(**options):
                err = failure(T.conn(dem, **options))
                print(err.strip().splitlines()[0])
                self.assertRegex(err, r"holds a cliff no terrain has: \d+(\.\d+)? m beside "
                                      r"-9999 m in band 1 at columns 29 and 30 of row 40, "
                                      r"cells about 30 m apart, where no terrain steps more "
                                      r"than 5000 m\.")
                self.assertIn("gdal_edit.py -a_nodata -9999 " + dem, err)
        declared = self.dem("void9999_declared.tif", z, nodata=-9999)
        out = T.read(T.conn(declared, PRODUCT="svf", DIRECTIONS=8), 1)
        np.testing.assert_array_equal(np.isnan(out), z == -9999)
        src = gdal.Open(T.JACKSBORO)
        j = src.GetRasterBand(1).ReadAsArray().astype(np.float32)
        j[200:230, 100:180] = -9999
        geo = T.write_tif(os.path.join(self.tmp, "jacksboro_void.tif"), j,
                          src.GetGeoTransform(), src.GetProjection())
        err = failure(T.conn(geo))
        self.assertIn("-9999 m in band 1 at columns 99 and 100 of row 200", err)

    def test_exaggeration_widens_the_limits_with_it(self):
        """Z_FACTOR=12 on heights up to 900 m (10.8 km) is an exaggeration the
        user asked for, equal to the DEM with its heights times 12; the same
        with an undeclared void is still an error, scaled."""
        dem = self.dem("exaggerated.tif", self.z)
        tall = self.dem("tall.tif", self.z * 12)
        o = {"PRODUCT": "svf", "DIRECTIONS": 8, "CURVATURE": "NO"}
        a = T.read(T.conn(dem, Z_FACTOR=12, **o), 1)
        self.assertTrue(np.isfinite(a).all())
        # the DEM made 10.8 km tall with no Z_FACTOR is beyond the Earth's terrain
        err = failure(T.conn(tall, **o))
        self.assertRegex(err, r"holds a height no terrain has: (9|10)\d\d\d(\.\d+)? m")
        void = self.dem("exaggerated_void.tif", self.with_void(-32768))
        err = failure(T.conn(void, Z_FACTOR=12))
        self.assertIn("-393216 m in band 1 at column 30, row 40", err)
        self.assertIn("times Z_FACTOR's exaggeration 12", err)
        self.assertIn("-a_nodata -32768 ", err)

    def test_feet_without_a_unit(self):
        """Heights in feet to 14 000 (Colorado) with no unit in the DEM:
        taken as metres they are higher than Everest, an error that names
        the unit; Z_FACTOR=0.3048 or the band's unit set make them metres."""
        ft = self.z / 900.0 * 14000.0
        dem = self.dem("feet.tif", ft)
        err = failure(T.conn(dem))
        self.assertIn("gdal_edit.py -units ft", err)
        a = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8, Z_FACTOR=0.3048), 1)
        self.assertTrue(np.isfinite(a).all())
        ds = gdal.Open(dem, gdal.GA_Update)
        ds.GetRasterBand(1).SetUnitType("ft")
        ds = None
        b = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8), 1)
        np.testing.assert_array_equal(a, b)

    def test_another_body_is_held_to_its_radius(self):
        """On Mars (a CRS whose ellipsoid is not the Earth's) Olympus Mons'
        21 km is terrain; a height beyond the planet's radius is not."""
        gt = (130.0, 0.01, 0, 20.0, 0, -0.01)
        z = self.z / 900.0 * 21000.0
        dem = T.write_tif(os.path.join(self.tmp, "mars.tif"), z, gt, MARS)
        a = T.read(T.conn(dem, PRODUCT="svf", DIRECTIONS=8, CURVATURE="NO"), 1)
        self.assertTrue(np.isfinite(a).all())
        z[5, 7] = -1e7
        dem = T.write_tif(os.path.join(self.tmp, "mars_void.tif"), z, gt, MARS)
        err = failure(T.conn(dem, CURVATURE="NO"))
        self.assertIn("-1e+07 m in band 1 at column 7, row 5, beyond the radius of the "
                      "CRS's body (3396190 m)", err)


class NotHeights(unittest.TestCase):
    def test_colour_and_palette_bands_are_refused(self):
        """An RGB picture's red channel and a land-cover palette are not
        heights: an error at open that names the band and the way out."""
        with T.TempDir() as tmp:
            rgb = os.path.join(tmp, "photo.tif")
            ds = gdal.GetDriverByName("GTiff").Create(rgb, 40, 30, 3, gdal.GDT_Byte,
                                                      ["PHOTOMETRIC=RGB"])
            ds.SetGeoTransform(GT)
            for b in range(3):
                ds.GetRasterBand(b + 1).Fill(50 * b + 10)
            ds = None
            classes = os.path.join(tmp, "classes.tif")
            ds = gdal.GetDriverByName("GTiff").Create(classes, 40, 30, 1, gdal.GDT_Byte)
            ds.SetGeoTransform(GT)
            ct = gdal.ColorTable()
            ct.SetColorEntry(1, (0, 128, 0, 255))
            ds.GetRasterBand(1).SetRasterColorTable(ct)
            ds.GetRasterBand(1).Fill(1)
            ds = None
            for dem, band, what in ((rgb, 1, "the Red channel of a colour image"),
                                    (rgb, 3, "the Blue channel of a colour image"),
                                    (classes, 1, "the class indices of a palette")):
                with self.subTest(dem=os.path.basename(dem), band=band):
                    p = T.run(["gdalinfo", "-nomd", T.conn(dem, BAND=band)], ok=False)
                    self.assertIn("ERROR 5: TERRASHADE: band %d of '%s' holds %s, not heights"
                                  % (band, dem, what), p.stderr)
                    self.assertIn("gdal_edit.py -colorinterp_%d gray" % band, p.stderr)
            # said to be heights, they are computed
            T.run(["gdal_edit.py", "-colorinterp_2", "gray", rgb])
            out = T.read(T.conn(rgb, BAND=2, PRODUCT="svf", DIRECTIONS=4), 1)
            np.testing.assert_allclose(out, 1.0, atol=1e-6)  # a flat band: open sky

    def test_complex_and_signed_byte_bands_are_refused(self):
        """A complex band (GDAL reads its real part alone) and signed bytes
        (GDAL 3.6 reads -8 as 248: a 256 m cliff between -1 and 0) are not
        heights GDAL hands over as they are: an error at open naming the
        band, the type and the way out, not a silent product."""
        z = T.fractal_dem(40, seed=3, relief=20.0) - 10.0  # -10 .. 10 m
        with T.TempDir() as tmp:
            for dtype in (gdal.GDT_CInt16, gdal.GDT_CInt32, gdal.GDT_CFloat32,
                          gdal.GDT_CFloat64):
                name = gdal.GetDataTypeName(dtype)
                dem = T.write_tif(os.path.join(tmp, name + ".tif"), np.round(z), GT, UTM,
                                  dtype=dtype)
                with self.subTest(dtype=name):
                    p = T.run(["gdalinfo", "-nomd", T.conn(dem)], ok=False)
                    self.assertIn("ERROR 5: TERRASHADE: band 1 of '%s' is complex (%s), "
                                  "not heights" % (dem, name), p.stderr)
                    self.assertIn("gdal_translate -ot Float32", p.stderr)
            signed = os.path.join(tmp, "signed.tif")
            ds = gdal.GetDriverByName("GTiff").Create(signed, 40, 40, 1, gdal.GDT_Byte,
                                                      ["PIXELTYPE=SIGNEDBYTE"])
            ds.SetGeoTransform(GT)
            ds.GetRasterBand(1).WriteArray(np.round(z).astype(np.int8).view(np.uint8))
            ds = None
            p = T.run(["gdalinfo", "-nomd", T.conn(signed)], ok=False)
            self.assertIn("ERROR 5: TERRASHADE: band 1 of '%s' holds signed bytes "
                          "(PIXELTYPE=SIGNEDBYTE)" % signed, p.stderr)
            # the remedy it gives makes an Int16 DEM of the same heights
            fixed = os.path.join(tmp, "fixed.tif")
            T.run(["gdal_calc.py", "--quiet", "-A", signed, "--type=Int16",
                   "--calc=A.astype(numpy.int16)-256*(A>127)", "--outfile=" + fixed])
            self.assertIn("gdal_calc.py -A '%s' --type=Int16 "
                          "--calc='A.astype(numpy.int16)-256*(A>127)'" % signed, p.stderr)
            np.testing.assert_array_equal(T.read(fixed, 1), np.round(z))
            T.read(T.conn(fixed, PRODUCT="svf", DIRECTIONS=4), 1)


class NotTerrainScale(unittest.TestCase):
    """A DEM steeper than 85 degrees nearly everywhere is not terrain at its
    cells' scale: a warning at open that says what is likely wrong."""

    def test_degrees_under_a_projected_crs(self):
        with T.TempDir() as tmp:
            src = gdal.Open(T.JACKSBORO)
            mistag = os.path.join(tmp, "mistag.tif")
            ds = gdal.GetDriverByName("GTiff").CreateCopy(mistag, src)
            srs = osr.SpatialReference()
            srs.ImportFromEPSG(UTM)
            ds.SetProjection(srs.ExportToWkt())
            ds = None
            err = T.open_stderr(mistag)
            print(err.strip())
            self.assertRegex(err, r"Warning 1: TERRASHADE: the DEM '.*mistag.tif' is steeper "
                                  r"than 85 degrees at \d+ % of the 256 x 256 cells at its "
                                  r"centre: its cells \(0.000833333 x 0.000833333 m\)")
            self.assertIn("projected CRS (WGS 84 / UTM zone 17N)", err)

    def test_heights_in_millimetres(self):
        """A polder of 1 m cells, 0 to 5 m high, in millimetres (within the
        Earth's heights, so only its slopes give it away)."""
        with T.TempDir() as tmp:
            z = T.fractal_dem(256, seed=2, relief=5.0) - 100.0
            gt = (120000, 1, 0, 480000, 0, -1)
            m = T.write_tif(os.path.join(tmp, "m.tif"), z, gt, 28992)
            mm = T.write_tif(os.path.join(tmp, "mm.tif"), z * 1000, gt, 28992)
            self.assertIn("steeper than 85 degrees", T.open_stderr(mm))
            # in metres, or with the unit's factor, it is terrain
            self.assertNotIn("steeper", T.open_stderr(m))
            self.assertNotIn("steeper", T.open_stderr(mm, Z_FACTOR=0.001))

    def test_real_and_rough_terrain_pass(self):
        """jacksboro, lux_elev, and a 10 m fractal far rougher than terrain
        (1400 m of relief, the benches' DEM) open without the warning."""
        with T.TempDir() as tmp:
            rough = os.path.join(tmp, "rough.tif")
            T.run(["/usr/bin/python3", os.path.join(T.SRCDIR, "bench", "fractal_tif.py"),
                   "512", rough])
            for dem in (T.JACKSBORO, T.LUX, rough):
                with self.subTest(dem=os.path.basename(dem)):
                    self.assertNotIn("steeper", T.open_stderr(dem))


if __name__ == "__main__":
    unittest.main(verbosity=2)
