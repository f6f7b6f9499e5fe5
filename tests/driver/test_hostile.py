"""Hostile inputs through the real GDAL tools (issue 14, item 8): bad numbers
of every kind for every numeric option, malformed dates, times and offsets,
inline option syntax errors, unknown and duplicate options, odd
georeferencing, tiny, thin and empty DEMs, corrupt atlases and huge declared
sizes. Each case runs gdalinfo or gdal_translate and asserts the exit status
and the message (or, where the input is odd but valid, the right output);
a crash (a signal) always fails.

The numeric options and their ranges are read from the driver's own
open-option list, so an option added to the table is covered here without
editing this file. Cases whose current answer is wrong rather than an error
(issue 14: TEMPERATURE=-272.999, atlas metadata garbage, heights in feet)
are not asserted here; docs/testing.md lists them.
"""
import concurrent.futures
import os
import struct
import unittest
import xml.etree.ElementTree as ET
import zlib

import tsdriver as T
from tsdriver import gdal, np

DEM = T.LUX
GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
UTM = 32617
# Processes at once: the driver tests share a 2-core machine.
WORKERS = 2


def numeric_options():
    """(name, type, min, max) of every int and float open option."""
    xml = gdal.GetDriverByName("TERRASHADE").GetMetadataItem("DMD_OPENOPTIONLIST")
    out = []
    for o in ET.fromstring(xml).iter("Option"):
        if o.get("type") in ("int", "float"):
            out.append((o.get("name"), o.get("type"), float(o.get("min")),
                        float(o.get("max")) if o.get("max") is not None else None))
    return out


def bad_numbers(name, kind, lo, hi):
    """(value, text the message must hold) for one numeric option."""
    what = "a whole number" if kind == "int" else "a number"
    cases = [(v, "%s must be %s, got '%s'" % (name, what, v))
             for v in ("NaN", "nan", "inf", "-inf", "1e999", "-1e999", "west",
                       "12abc", "1,5")]
    cases.append(("", "%s needs a value" % name))
    if kind == "int":
        cases += [(v, "%s must be a whole number, got '%s'" % (name, v))
                  for v in ("2.5", "0x10", "1e3")]
        # whole, but beyond a long: its range, not "a whole number"
        cases.append(("99999999999999999999",
                      "%s must be between %d and " % (name, lo)))
        below, above = "%d" % (lo - 1), "%d" % (hi + 1 if hi is not None else 0)
    else:
        below = "%.17g" % (lo - 1000 if lo > -1e300 else -1e308)
        above = "%.17g" % (hi * 2 + 1) if hi is not None else None
    cases.append((below, "%s must be" % name))
    if hi is not None:
        cases.append((above, "%s must be" % name))
    return cases


def run_cases(cases):
    """Run [(name, argv, ok)] two at a time; returns {name: process or the
    AssertionError T.run raised (a crash, or the wrong exit status)}."""
    def one(case):
        name, argv, ok = case
        try:
            return name, T.run(argv, ok=ok)
        except AssertionError as e:
            return name, e
    with concurrent.futures.ThreadPoolExecutor(WORKERS) as pool:
        return dict(pool.map(one, cases))


def oo(options):
    return T.oo_args(dict(options))


def write_vrt(path, width, height, source, gt=GT, srs="EPSG:32617"):
    """A VRT of width x height Float32 cells whose top-left 64 x 64 come
    from band 1 of `source` (the rest reads as 0)."""
    gts = ", ".join("%.17g" % g for g in gt)
    with open(path, "w") as f:
        f.write('<VRTDataset rasterXSize="%d" rasterYSize="%d">' % (width, height)
                + ("<SRS>%s</SRS>" % srs if srs else "")
                + "<GeoTransform>%s</GeoTransform>" % gts
                + '<VRTRasterBand dataType="Float32" band="1"><SimpleSource>'
                + '<SourceFilename relativeToVRT="0">%s</SourceFilename>' % source
                + "<SourceBand>1</SourceBand>"
                + '<SrcRect xOff="0" yOff="0" xSize="64" ySize="64"/>'
                + '<DstRect xOff="0" yOff="0" xSize="64" ySize="64"/>'
                + "</SimpleSource></VRTRasterBand></VRTDataset>")
    return path


def with_crc(blob):
    """The atlas bytes with its header CRC32 (bytes 160..163) recomputed, so
    that the damage reaches the checks behind it."""
    b = bytearray(blob)
    b[160:164] = struct.pack("<I", zlib.crc32(bytes(b[:160])) & 0xFFFFFFFF)
    return bytes(b)


def patch(blob, offset, fmt, value):
    b = bytearray(blob)
    struct.pack_into(fmt, b, offset, value)
    return bytes(b)


class Hostile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.count = 0

    @classmethod
    def tearDownClass(cls):
        print("hostile cases run: %d" % cls.count)
        cls.tmp.__exit__(None, None, None)

    def path(self, name):
        return os.path.join(self.dir, name)

    def check_failures(self, cases):
        """cases: [(name, argv, text)]: each must exit with 1, saying text
        (a string, or a tuple of strings that must all be there)."""
        results = run_cases([(n, argv, False) for n, argv, _ in cases])
        for name, argv, text in cases:
            with self.subTest(name):
                Hostile.count += 1
                p = results[name]
                if isinstance(p, AssertionError):
                    raise p
                self.assertEqual(p.returncode, 1, p.stderr)
                for t in (text,) if isinstance(text, str) else text:
                    self.assertIn(t, p.stderr)

    # ------------------------------------------------------------ numbers

    def test_bad_numbers_for_every_numeric_option(self):
        opts = numeric_options()
        self.assertGreaterEqual(len(opts), 15, "the option list lost its numbers")
        cases = []
        for name, kind, lo, hi in opts:
            for value, text in bad_numbers(name, kind, lo, hi):
                cases.append(("%s=%r" % (name, value),
                              ["gdalinfo", "-nomd", "-oo", "%s=%s" % (name, value),
                               T.conn(DEM)], text))
        self.check_failures(cases)

    def test_bad_numbers_inline(self):
        """The same checks reach options written in the connection string."""
        cases = [("inline %s=%s" % (k, v), ["gdalinfo", "-nomd", T.conn(DEM, **{k: v})], t)
                 for k, v, t in (
                     ("SUN_AZIMUTH", "nan", "SUN_AZIMUTH must be a number, got 'nan'"),
                     ("SUN_ELEVATION", "-inf", "SUN_ELEVATION must be a number, got '-inf'"),
                     ("Z_FACTOR", "1e999", "Z_FACTOR must be AUTO or a number, got '1e999'"),
                     ("DIRECTIONS", "2.5", "DIRECTIONS must be a whole number, got '2.5'"),
                     ("THREADS", "0x10", "THREADS must be a whole number, got '0x10'"),
                     ("STEP_MINUTES", "0", "STEP_MINUTES must be between 1 and 240, got 0"),
                     ("Z_FACTOR", "0", "Z_FACTOR must be greater than 0"),
                     ("SUN_ELEVATION", "90.0001",
                      "SUN_ELEVATION must be between -90 and 90, got 90.0001"))]
        self.check_failures(cases)

    # ------------------------------------------------- dates, times, offsets

    def test_malformed_datetimes(self):
        bad = [("2026-13-01T00:00Z", "month 13 is not between 1 and 12"),
               ("2026-02-30T00:00Z", "day 30 is not between 1 and 28"),
               ("2025-02-29T12:00Z", "2025 is not a leap year"),
               ("2026-06-21T24:00Z", "hour 24 is not between 0 and 23"),
               ("2026-06-21T12:60Z", "minute 60 is not between 0 and 59"),
               ("2026-06-21T12:00:61Z", "second 61 is not in [0, 60]"),
               ("2026-06-21T12:00+24:00", "offset +24:00 is out of range"),
               ("2026-06-21T12:00-02:60", "offset -02:60 is out of range"),
               ("2026-06-21T12:00", "an offset from UTC is required"),
               ("2026-06-21", "a time of day and an offset"),
               ("21/06/2026 12:00Z", "expected YYYY-MM-DDThh:mm:ss"),
               ("2026-6-21T12:00Z", "expected YYYY-MM-DDThh:mm:ss"),
               ("-2026-06-21T12:00Z", "expected YYYY-MM-DDThh:mm:ss"),
               ("2026-06-21T12:00Zjunk", "unexpected text 'junk' after the offset"),
               ("2026-06-21T12:00CEST", "unexpected 'C' where the offset"),
               ("2026-06-21T12:00:00.Z", "expected digits after the decimal point"),
               ("tomorrow", "expected YYYY-MM-DDThh:mm:ss")]
        cases = [("DATETIME=" + v, ["gdalinfo", "-nomd", "-oo", "DATETIME=" + v, T.conn(DEM)],
                  ("DATETIME: Cannot read '%s'" % v, why)) for v, why in bad]
        # the basic form of inline options is read as the extended one, then refused
        cases.append(("DATETIME basic, no offset", ["gdalinfo", "-nomd", T.conn(
            DEM, DATETIME="2026-06-21T1200")], ("Cannot read '2026-06-21T12:00'",
                                                "an offset from UTC is required")))
        long_value = "2026-06-21T12:00:00." + "9" * 80 + "Z"
        cases.append(("DATETIME too long", ["gdalinfo", "-nomd", "-oo",
                                            "DATETIME=" + long_value, T.conn(DEM)],
                      "DATETIME is too long"))
        self.check_failures(cases)

    def test_malformed_dates_and_offsets(self):
        day = ["-oo", "PRODUCT=sunhours"]
        cases = []
        for v, why in (("2026-06-31", "2026-06 has 30 days, there is no day 31"),
                       ("2026-00-10", "month 0 does not exist"),
                       ("2025-02-29", "2025-02 has 28 days"),
                       ("2026-6-1", "expected YYYY-MM-DD"),
                       ("20260621", "expected YYYY-MM-DD"),
                       ("2026/06/21", "expected YYYY-MM-DD"),
                       ("2026-06-21T00:00Z", "a date is YYYY-MM-DD alone, here followed by 'T00:00Z'"),
                       ("yesterday", "expected YYYY-MM-DD")):
            cases.append(("DATE=" + v, ["gdalinfo", "-nomd"] + day +
                          ["-oo", "DATE=" + v, "-oo", "TIMEZONE=Z", T.conn(DEM)],
                          "DATE: Cannot read '%s' as a date: %s" % (v, why)))
        for v, why in (("+24:00", "is out of range (at most 23:59)"),
                       ("+02:60", "is out of range (at most 23:59)"),
                       ("+99", "is out of range (at most 23:59)"),
                       ("Europe/Zurich", "named time zones are not supported"),
                       ("CET", "named time zones are not supported"),
                       ("+2", "expected Z (or UTC), +hh:mm"),
                       ("+02:0", "expected Z (or UTC), +hh:mm"),
                       ("02:00", "expected Z (or UTC), +hh:mm"),
                       ("UTC+2", "expected Z (or UTC), +hh:mm"),
                       ("-", "expected Z (or UTC), +hh:mm")):
            head = ("The offset from UTC '%s'" if "range" in why else
                    "Cannot read '%s' as an offset from UTC") % v
            cases.append(("TIMEZONE=" + v, ["gdalinfo", "-nomd"] + day +
                          ["-oo", "DATE=2026-06-21", "-oo", "TIMEZONE=" + v, T.conn(DEM)],
                          ("TIMEZONE: " + head, why)))
        self.check_failures(cases)

    def test_dates_that_do_not_fit_the_product(self):
        c = T.conn(DEM)
        cases = [
            ("DATE with shade", ["gdalinfo", "-nomd", "-oo", "DATE=2026-06-21", c],
             "DATE applies to the day products"),
            ("DATE without TIMEZONE", ["gdalinfo", "-nomd", "-oo", "PRODUCT=sunhours",
                                       "-oo", "DATE=2026-06-21", c],
             "DATE=2026-06-21 needs TIMEZONE"),
            ("TIMEZONE alone", ["gdalinfo", "-nomd", "-oo", "TIMEZONE=+02:00", c],
             "TIMEZONE applies with DATE"),
            ("DATE and DATETIME", ["gdalinfo", "-nomd", "-oo", "PRODUCT=sunhours", "-oo",
                                   "DATE=2026-06-21", "-oo", "TIMEZONE=Z", "-oo",
                                   "DATETIME=2026-06-21T12:00Z", c],
             "give DATE (with TIMEZONE) or DATETIME, not both"),
            ("day product without a day",
             ["gdalinfo", "-nomd", "-oo", "PRODUCT=insolation", c],
             "PRODUCT=insolation needs a day"),
            ("SUN_AZIMUTH with DATETIME", ["gdalinfo", "-nomd", "-oo", "SUN_AZIMUTH=90",
                                           "-oo", "DATETIME=2026-06-21T12:00Z", c],
             "DATETIME places the sun: do not give SUN_AZIMUTH with it"),
            ("DATETIME with svf", ["gdalinfo", "-nomd", "-oo", "PRODUCT=svf", "-oo",
                                   "DATETIME=2026-06-21T12:00Z", c],
             "DATETIME applies to PRODUCT=shade"),
            ("per_cell without a time",
             ["gdalinfo", "-nomd", "-oo", "SUN_POSITION=per_cell", c],
             "SUN_POSITION=per_cell needs the sun from DATETIME or DATE"),
        ]
        self.check_failures(cases)

    # --------------------------------------- inline syntax, unknown, twice

    def test_inline_syntax_errors(self):
        d = DEM
        cases = [
            ("empty item", "TERRASHADE:PRODUCT=svf,,DIRECTIONS=4:" + d,
             "cannot open the DEM 'PRODUCT=svf,,DIRECTIONS=4:%s'" % d),
            ("trailing comma", "TERRASHADE:PRODUCT=svf,:" + d,
             "cannot open the DEM 'PRODUCT=svf,:%s'" % d),
            ("key without value", "TERRASHADE:PRODUCT=svf,DIRECTIONS:" + d,
             "cannot open the DEM 'PRODUCT=svf,DIRECTIONS:%s'" % d),
            ("key not an identifier", "TERRASHADE:SUN-AZIMUTH=3:" + d,
             "cannot open the DEM 'SUN-AZIMUTH=3:%s'" % d),
            ("two colons", "TERRASHADE:PRODUCT=svf::" + d,
             "cannot open the DEM ':%s'" % d),
            ("value starting with =", "TERRASHADE:PRODUCT==svf:" + d,
             "PRODUCT must be one of shade, shadow, horizon"),
            ("unterminated quote", 'TERRASHADE:PRODUCT=svf:"' + d,
             "cannot open the DEM '\"%s'" % d),
            ("options and no DEM", "TERRASHADE:PRODUCT=svf,DIRECTIONS=4", "names no DEM"),
            ("options and an empty DEM", "TERRASHADE:PRODUCT=svf:", "names no DEM"),
            ("quotes around nothing", 'TERRASHADE:PRODUCT=svf:""', "names no DEM"),
            ("prefix and colon only", "TERRASHADE::", "cannot open the DEM ':'"),
            ("colons of an extended DATETIME inline",
             "TERRASHADE:DATETIME=2026-06-21T07:30:00+02:00:" + d,
             "DATETIME: Cannot read '2026-06-21T07'"),
            ("empty inline value", "TERRASHADE:SUN_AZIMUTH=:" + d,
             "SUN_AZIMUTH needs a value"),
        ]
        self.check_failures([(n, ["gdalinfo", "-nomd", c], t) for n, c, t in cases])

    def test_unknown_and_duplicate_options(self):
        c = T.conn(DEM)
        cases = [
            ("unknown -oo", ["-oo", "COLOR=red"], c, "unknown option 'COLOR'"),
            ("unknown inline", [], "TERRASHADE:COLOR=red:" + DEM, "unknown option 'COLOR'"),
            ("misspelt", ["-oo", "SUN_ELEVATON=10"], c, "unknown option 'SUN_ELEVATON'"),
            ("atlas DEM option", ["-oo", "DEM=x.tif"], c,
             "DEM is an open option of far-shadow atlas files"),
            ("no '='", ["-oo", "PRODUCT"], c, "option 'PRODUCT' is not of the form KEY=VALUE"),
            ("twice inline", [], "TERRASHADE:PRODUCT=svf,PRODUCT=sky:" + DEM,
             "PRODUCT is given twice, as svf and as sky"),
            ("twice, other case", [], "TERRASHADE:product=svf,PRODUCT=SKY:" + DEM,
             "PRODUCT is given twice, as svf and as SKY"),
            ("inline and -oo", ["-oo", "DIRECTIONS=8"], "TERRASHADE:DIRECTIONS=4:" + DEM,
             "DIRECTIONS is given twice, as 4 and as 8"),
            ("twice -oo", ["-oo", "SUN_AZIMUTH=10", "-oo", "SUN_AZIMUTH=11"], c,
             "SUN_AZIMUTH is given twice, as 10 and as 11"),
            ("bad select", ["-oo", "METHOD=fast"], c, "METHOD must be one of exact, shm"),
            ("bad backend", ["-oo", "BACKEND=cuda"], c,
             "BACKEND must be one of auto, opencl, c"),
            ("bad boolean", ["-oo", "CURVATURE=2"], c, "CURVATURE must be YES or NO, got '2'"),
            ("farshadow Float32", ["-oo", "PRODUCT=farshadow", "-oo", "DATE=2026-06-21",
                                   "-oo", "TIMEZONE=Z", "-oo", "OUTPUT_TYPE=Float32"], c,
             "PRODUCT=farshadow is binary"),
            ("farshadow MAX_DISTANCE", ["-oo", "PRODUCT=farshadow", "-oo", "DATE=2026-06-21",
                                        "-oo", "TIMEZONE=Z", "-oo", "MAX_DISTANCE=100"], c,
             "MAX_DISTANCE does not apply to PRODUCT=farshadow"),
        ]
        self.check_failures([(n, ["gdalinfo", "-nomd"] + a + [conn], t)
                             for n, a, conn, t in cases])

    def test_same_option_twice_with_the_same_value_is_once(self):
        Hostile.count += 1
        twice = T.read("TERRASHADE:PRODUCT=svf,DIRECTIONS=4,product=SVF:" + DEM)
        once = T.read(T.conn(DEM, PRODUCT="svf", DIRECTIONS=4))
        np.testing.assert_array_equal(twice, once)

    def test_other_spellings_of_one_value_are_once(self):
        # the text options were compared as text: SKY=cie9 inline (no colons
        # there) and -oo SKY=cie:9, QGIS's spelling, were "given twice"
        day = ["-oo", "PRODUCT=sunhours", "-oo", "DATE=2026-06-21"]
        same = [
            ("SKY", ["-oo", "PRODUCT=envlight", "-oo", "SKY=cie:9"], "SKY=cie9"),
            ("TIMEZONE", day + ["-oo", "TIMEZONE=-05:00"], "TIMEZONE=-0500"),
            ("TIMEZONE Z", day + ["-oo", "TIMEZONE=Z"], "TIMEZONE=+0000"),
            ("DATETIME", ["-oo", "DATETIME=2026-06-21T14:00:00-05:00"],
             "DATETIME=20260621T1400-0500"),
            ("EXPOSURE", ["-oo", "PRODUCT=envlight", "-oo", "SKY=uniform", "-oo",
                          "OUTPUT_TYPE=Byte", "-oo", "EXPOSURE=1"], "EXPOSURE=1.0"),
            # AUTO, the declared default, is no mistake with Float32
            ("EXPOSURE=AUTO, Float32", ["-oo", "PRODUCT=envlight", "-oo", "SKY=uniform",
                                        "-oo", "EXPOSURE=AUTO"], "OUTPUT_TYPE=Float32"),
        ]
        results = run_cases([(n, ["gdalinfo", "-nomd"] + a + ["TERRASHADE:%s:%s" % (i, DEM)],
                              True) for n, a, i in same])
        for name, _, _ in same:
            with self.subTest(name):
                Hostile.count += 1
                if isinstance(results[name], AssertionError):
                    raise results[name]
        other = [
            ("SKY", ["-oo", "PRODUCT=envlight", "-oo", "SKY=cie:8"], "SKY=cie9",
             "SKY is given twice, as cie9 and as cie:8"),
            ("DATETIME", ["-oo", "DATETIME=2026-06-21T14:00:00-04:00"],
             "DATETIME=20260621T1400-0500", "DATETIME is given twice"),
            # the same instant in another offset names another local day
            ("DATETIME offset", ["-oo", "DATETIME=2026-06-21T19:00:00Z"],
             "DATETIME=20260621T1400-0500", "DATETIME is given twice"),
        ]
        self.check_failures([(n, ["gdalinfo", "-nomd"] + a + ["TERRASHADE:%s:%s" % (i, DEM)],
                              t) for n, a, i, t in other])

    # --------------------------------------------------- georeferencing

    def test_odd_georeferencing_is_refused(self):
        z = T.fractal_dem(64, seed=7)
        src = T.write_tif(self.path("src.tif"), z, GT, UTM)
        gts = [("rotated", (600000, 30, 5, 4000000, 5, -30), "rotated or sheared"),
               ("sheared", (600000, 30, 3, 4000000, 0, -30), "rotated or sheared"),
               ("zero cell width", (600000, 0, 0, 4000000, 0, -30),
                "the DEM's pixel size is zero (GT[1] = 0, GT[5] = -30)"),
               ("zero cell height", (600000, 30, 0, 4000000, 0, 0),
                "the DEM's pixel size is zero (GT[1] = 30, GT[5] = 0)"),
               ("NaN cell size", (600000, float("nan"), 0, 4000000, 0, -30),
                "the DEM's geotransform is not finite"),
               ("infinite origin", (float("inf"), 30, 0, 4000000, 0, -30),
                "the DEM's geotransform is not finite")]
        cases = [(n, ["gdal_translate", "-q", T.conn(write_vrt(self.path("g%d.vrt" % i), 64,
                                                               64, src, gt)),
                      self.path("g%d.tif" % i)], t)
                 for i, (n, gt, t) in enumerate(gts)]
        geo = [("beyond the pole", (0, 0.1, 0, 95, 0, -0.1),
                "the DEM reaches beyond the poles (latitudes 88.6 to 95)"),
               ("more than 360 degrees", (-180, 10, 0, 80, 0, -1),
                "the DEM spans 640 degrees of longitude"),
               # grid-registered (node) grids: which rows and column to crop, and how
               ("a row on the north pole", (0, 0.5, 0, 90.25, 0, -0.5),
                "its northern row lies on the pole, as in a grid-registered grid; crop "
                "those cells off, e.g. gdal_translate -projwin 0 89.75 32 58.25 "),
               ("a row on the south pole, a repeated meridian",
                (-180 - 180 / 63, 360 / 63, 0, -58.25, 0, -0.5),
                "its southern row lies on the pole, its last column on the first "
                "meridian again")]
        for i, (n, gt, t) in enumerate(geo):
            dem = T.write_tif(self.path("geo%d.tif" % i), z, gt, 4326)
            cases.append((n, ["gdal_translate", "-q", T.conn(dem),
                              self.path("geo%d_out.tif" % i)], t))
        # session 57's fuzzing: cells no float holds read NaN or nodata
        # everywhere (and a NaN reached an int); Web Mercator corners at
        # 1e17 m took GDAL's inverse minutes, an open that never ended
        beyond = [("cells of 1e-320", (0, 1e-320, 0, 0, 0, -1e-320), None,
                   "the DEM's cells measure 9.99989e-321 to 9.99989e-321 m, outside the "
                   "1e-30 to 1e+08 m that terrashade computes with"),
                  ("cells of 1e-40 m in UTM", (600000, 1e-40, 0, 4000000, 0, -1e-40), UTM,
                   "outside the 1e-30 to 1e+08 m"),
                  ("cells of 1e9 m", (0, 1e9, 0, 0, 0, -1e9), None,
                   "outside the 1e-30 to 1e+08 m"),
                  ("Web Mercator at 1e17 m", (1e17, 30, 0, 2e7, 0, -30), 3857,
                   "the DEM's corners lie up to 1e+17 m from its CRS's origin, more than "
                   "twice around the Earth")]
        for i, (n, gt, crs, t) in enumerate(beyond):
            dem = T.write_tif(self.path("far%d.tif" % i), z, gt, crs)
            cases.append((n, ["timeout", "60", "gdal_translate", "-q", T.conn(dem),
                              self.path("far%d_out.tif" % i)], t))
        self.check_failures(cases)
        for i in range(len(gts)):
            self.assertFalse(os.path.exists(self.path("g%d.tif" % i)), "an output was written")

    def test_no_crs_and_no_geotransform(self):
        """No CRS and no geotransform: 1 m cells, said in two warnings, and
        the product keeps the DEM's size and has no georeferencing either."""
        Hostile.count += 1
        z = T.fractal_dem(32, seed=8)
        path = self.path("bare.tif")
        ds = gdal.GetDriverByName("GTiff").Create(path, 32, 32, 1, gdal.GDT_Float32)
        ds.GetRasterBand(1).WriteArray(z)
        ds = None
        out = self.path("bare_out.tif")
        p = T.run(["gdal_translate", "-q", T.conn(path), out])
        self.assertEqual(p.returncode, 0)
        self.assertIn("has no geotransform: its cells are taken as 1 x 1 metre", p.stderr)
        self.assertIn("has no CRS", p.stderr)
        ds = gdal.Open(out)
        self.assertEqual((ds.RasterXSize, ds.RasterYSize), (32, 32))
        self.assertEqual(ds.GetProjection(), "")

    def test_tiny_and_thin_flat_dems_give_the_right_values(self):
        """1 x 1, 1 x N and N x 1 flat DEMs: shade (Float32) is sin(45 deg)
        everywhere, as Lambert's law says for a level cell; a sun 10 deg up
        lights every cell fully."""
        for shape in ((1, 1), (1, 9), (9, 1)):
            dem = T.write_tif(self.path("flat_%dx%d.tif" % shape),
                              np.full(shape, 321.0, np.float32), GT, UTM)
            with self.subTest(shape=shape):
                Hostile.count += 1
                shade = T.read(T.conn(dem, OUTPUT_TYPE="Float32"), 1)
                self.assertEqual(shade.shape, shape)
                np.testing.assert_allclose(shade, np.sin(np.radians(45)), atol=1e-5)
                lit = T.read(T.conn(dem, PRODUCT="shadow", SUN_ELEVATION=10), 1)
                np.testing.assert_allclose(lit, 1.0, atol=1e-6)

    def test_all_nodata_dem_gives_all_nodata(self):
        dem = T.write_tif(self.path("nodata.tif"), np.full((12, 17), -9999, np.float32),
                          GT, UTM, nodata=-9999)
        nan_dem = T.write_tif(self.path("nan.tif"), np.full((12, 17), np.nan, np.float32),
                              GT, UTM)
        for path in (dem, nan_dem):
            for product in ("shade", "svf", "horizon"):
                with self.subTest(dem=os.path.basename(path), product=product):
                    Hostile.count += 1
                    out = T.translate(path, self.path("nd_out.tif"),
                                      {"PRODUCT": product, "DIRECTIONS": 4})
                    self.assertTrue(np.isnan(T.read(out)).all())

    def test_huge_declared_sizes(self):
        z = T.fractal_dem(64, seed=9)
        src = T.write_tif(self.path("huge_src.tif"), z, GT, UTM)
        huge = write_vrt(self.path("huge.vrt"), 1000000, 1000000, src)
        # (cells of 1 cm: at 30 m its 60 million km are no terrain, refused first)
        wide = write_vrt(self.path("wide.vrt"), 2000000000, 1, src,
                         (600000, 0.01, 0, 4000000, 0, -0.01))
        cases = [
            ("10^6 x 10^6 VRT, gdalinfo", ["gdalinfo", "-nomd", T.conn(huge)],
             ("on this 1000000 x 1000000 DEM needs about", "set MAX_MEMORY to change")),
            ("10^6 x 10^6 VRT, svf", ["gdalinfo", "-nomd", "-oo", "PRODUCT=svf", T.conn(huge)],
             "PRODUCT=svf with 1 band(s) on this 1000000 x 1000000 DEM"),
            ("10^6 x 10^6 VRT, a small window", ["gdal_translate", "-q", "-srcwin", "0", "0",
                                                 "16", "16", T.conn(huge),
                                                 self.path("hw.tif")],
             "1000000 x 1000000 DEM needs about"),
            ("10^6 x 10^6 VRT, farshadow", ["gdalinfo", "-nomd", "-oo", "PRODUCT=farshadow",
                                            "-oo", "DATE=2026-06-21", "-oo", "TIMEZONE=Z",
                                            T.conn(huge)],
             "PRODUCT=farshadow with 158 band(s) on this 1000000 x 1000000 DEM"),
            # (windows of 4096 x 1 cells and their cache of the whole row:
            # about 8 GiB, within some machines' three quarters of memory)
            ("2*10^9 x 1 VRT", ["gdalinfo", "-nomd", "-oo", "MAX_MEMORY=2000", T.conn(wide)],
             "2000000000 x 1 DEM needs about"),
        ]
        self.check_failures(cases)
        self.assertFalse(os.path.exists(self.path("hw.tif")))

    # ----------------------------------------------------------- atlases

    def atlas(self):
        path = self.path("lux.tsa")
        if not os.path.exists(path):
            T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] +
                  oo({"PRODUCT": "farshadow", "DATE": "2026-06-21", "TIMEZONE": "+02:00",
                      "FAR_THRESHOLD": 8, "ATLAS_STEPS": 6}) + [T.conn(DEM), path])
        with open(path, "rb") as f:
            return f.read()

    def test_corrupt_atlases(self):
        a = self.atlas()
        _, text_off, _, dict_off, dict_n, idx_off = struct.unpack_from(
            "<6Q", a, 104)
        blobs = [
            ("empty file", b"", "not recognized as a supported file format"),
            ("magic only", a[:8], "the atlas is truncated: 8 bytes"),
            ("truncated header", a[:100],
             "the atlas is truncated or its header is damaged (header of 168 bytes in a "
             "100-byte file)"),
            ("header only", a[:168], "lies beyond the end of the 168-byte file"),
            ("last byte cut", a[:-1],
             "lies beyond the end of the %d-byte file" % (len(a) - 1)),
            ("half", a[:len(a) // 2], "the atlas is truncated"),
            ("wrong magic", b"\x89TSATLAZ" + a[8:],
             "not recognized as a supported file format"),
            ("version 1 (no checksum of its steps and text)", patch(a, 8, "<I", 1),
             "the atlas has format version 1"),
            ("version 3", patch(a, 8, "<I", 3), "the atlas has format version 3"),
            ("version garbage", patch(a, 8, "<I", 0xDEADBEEF),
             "the atlas has format version 3735928559"),
            ("header size too small", patch(a, 12, "<I", 8),
             "the atlas is truncated or its header is damaged (header of 8 bytes"),
            ("flipped width", patch(a, 16, "<I", struct.unpack_from("<I", a, 16)[0] ^ 0x80),
             "the atlas's header is damaged (CRC32 mismatch)"),
            ("flipped CRC", patch(a, 160, "<I", struct.unpack_from("<I", a, 160)[0] ^ 1),
             "the atlas's header is damaged (CRC32 mismatch)"),
            ("steps-and-text CRC flipped", patch(a, 164, "<I",
                                                  struct.unpack_from("<I", a, 164)[0] ^ 1),
             "the atlas's step table or metadata text is damaged (CRC32 mismatch)"),
            ("zero width", with_crc(patch(a, 16, "<I", 0)),
             "the atlas's header is inconsistent"),
            ("2^31 maps", with_crc(patch(a, 24, "<I", 1 << 31)),
             "the atlas's header is inconsistent"),
            ("tile 16", with_crc(patch(a, 28, "<I", 16)), "tile 16"),
            ("3-byte indices", with_crc(patch(a, 36, "<I", 3)), "3-byte indices"),
            ("no tiles", with_crc(patch(a, 40, "<I", 0)), "0 tiles"),
            ("section past the end", with_crc(patch(a, 128, "<Q", len(a) + 1)),
             "lies beyond the end of the %d-byte file" % len(a)),
            ("section length wraps", with_crc(patch(a, 152, "<Q", 2 ** 64 - 1)),
             "lies beyond the end"),
            ("section inside the header", with_crc(patch(a, 112, "<Q", 16)),
             "lies beyond the end"),
            ("NUL in the metadata", patch(a, text_off + 3, "<B", 0),
             "the atlas's step table or metadata text is damaged (CRC32 mismatch)"),
            ("flipped dictionary byte", patch(a, dict_off + dict_n // 2, "<B",
                                              a[dict_off + dict_n // 2] ^ 0x10),
             "the atlas is damaged: its tile dictionary words (LZMA) do not decode"),
            ("flipped index byte", patch(a, idx_off + 20, "<B", a[idx_off + 20] ^ 0x04),
             "the atlas is damaged: its index maps (LZMA) do not decode"),
            ("dictionary one tile short",
             with_crc(patch(a, 40, "<I", struct.unpack_from("<I", a, 40)[0] - 1)),
             "the atlas is damaged: its tile dictionary words (LZMA) do not decode"),
        ]
        cases = []
        for i, (name, blob, text) in enumerate(blobs):
            path = self.path("bad%02d.tsa" % i)
            with open(path, "wb") as f:
                f.write(blob)
            cases.append((name, ["gdalinfo", "-nomd", path], text))
        cases += [
            ("bad SHADOWS", ["gdalinfo", "-nomd", "-oo", "SHADOWS=near", self.path("lux.tsa")],
             "SHADOWS must be one of far, all"),
            ("DEM option on an atlas", ["gdalinfo", "-nomd", "-oo", "PRODUCT=shade",
                                        self.path("lux.tsa")],
             "an atlas takes the open options"),
        ]
        self.check_failures(cases)

    def test_an_intact_atlas_still_reads(self):
        """The control for the cases above: the atlas they damage is good."""
        Hostile.count += 1
        self.atlas()
        ds = gdal.Open(self.path("lux.tsa"))
        self.assertEqual(ds.RasterCount, 6)
        a = ds.GetRasterBand(1).ReadAsArray()
        self.assertTrue(set(np.unique(a)) <= {0, 1, 255})


if __name__ == "__main__":
    unittest.main(verbosity=2)
