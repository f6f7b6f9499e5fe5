"""The driver publishes its product table as the driver item
TERRASHADE_PRODUCTS (read by the QGIS provider), and what it says is what
the driver does:

- one <Product> per value of the PRODUCT option, in the same order, each
  with a description, a unit, a band count, daily, byte and options;
- every listed option is an open option of TERRASHADE:<dem> (PRODUCT itself
  and the atlas-only options are not listed);
- opening a dataset agrees with the list: its unit and band count (with the
  default options), its data type (byte: auto = Byte by default, allowed =
  Float32 by default and Byte on request, never = Byte refused, always =
  Byte only), a day product needs a day, and an option the list leaves out
  is refused where tsd_options_check refuses it (DATE with shade, METHOD=shm
  with svf, DATETIME with horizon, MAX_DISTANCE with farshadow).
"""
import os
import unittest
import xml.etree.ElementTree as ET

import tsdriver as T
from tsdriver import gdal

DAY = ["DATE=2026-06-21", "TIMEZONE=-05:00"]  # jacksboro, Tennessee


def products():
    drv = gdal.GetDriverByName("TERRASHADE")
    text = drv.GetMetadataItem("TERRASHADE_PRODUCTS")
    if text is None:
        raise AssertionError("the driver has no TERRASHADE_PRODUCTS item")
    root = ET.fromstring(text)
    assert root.tag == "Products", root.tag
    return [p.attrib for p in root.findall("Product")]


def open_options():
    drv = gdal.GetDriverByName("TERRASHADE")
    root = ET.fromstring(drv.GetMetadataItem(gdal.DMD_OPENOPTIONLIST))
    return {o.get("name"): o for o in root.findall("Option")}


def needs_light(p):
    """The products of environment light (those that take EXPOSURE) need
    ENV_MAP or SKY."""
    return "EXPOSURE" in p["options"].split(",")


def open_product(name, extra=()):
    """Open PRODUCT=name on jacksboro (with a day for the day products, a
    sky for envlight)."""
    p = {q["name"]: q for q in products()}[name]
    opts = ["PRODUCT=" + name] + (DAY if p["daily"] == "yes" else []) + list(extra)
    if needs_light(p) and not any(o.startswith(("SKY=", "ENV_MAP=")) for o in opts):
        opts.append("SKY=uniform")
    return gdal.OpenEx(T.conn(T.JACKSBORO), open_options=opts)


class ProductsItem(unittest.TestCase):
    def test_products_are_the_product_option_values(self):
        names = [p["name"] for p in products()]
        values = [v.text for v in open_options()["PRODUCT"].findall("Value")]
        print("products:", names)
        self.assertEqual(names, values)
        for p in products():
            for key in ("description", "unit", "bands", "daily", "byte", "options"):
                self.assertIn(key, p, p["name"])
            self.assertTrue(p["description"], p["name"])
            self.assertIn(p["daily"], ("yes", "no"))
            self.assertIn(p["byte"], ("auto", "allowed", "never", "always"))
            self.assertGreaterEqual(int(p["bands"]), 1)

    def test_listed_options_are_open_options(self):
        opts = open_options()
        for p in products():
            listed = p["options"].split(",")
            self.assertEqual(len(listed), len(set(listed)), p["name"])
            for name in listed:
                self.assertIn(name, opts, "%s lists %s" % (p["name"], name))
            for name in ("PRODUCT", "SHADOWS", "DEM"):
                self.assertNotIn(name, listed, p["name"])
            for general in ("BAND", "Z_FACTOR", "CELL_SIZES", "THREADS", "PROGRESS", "MAX_MEMORY"):
                self.assertIn(general, listed, p["name"])
            # the byte rule and OUTPUT_TYPE say the same
            self.assertEqual("OUTPUT_TYPE" in listed, p["byte"] in ("auto", "allowed"),
                             p["name"])
            # a day product takes a day; the others do not
            self.assertEqual("DATE" in listed, p["daily"] == "yes", p["name"])
            self.assertEqual("TIMEZONE" in listed, p["daily"] == "yes", p["name"])

    def test_datasets_agree_with_the_list(self):
        for p in products():
            with self.subTest(p["name"]):
                ds = open_product(p["name"])
                band = ds.GetRasterBand(1)
                dtype = gdal.GetDataTypeName(band.DataType)
                print("%-10s bands %3d (listed %3s), unit %-6r type %-7s byte=%s" % (
                    p["name"], ds.RasterCount, p["bands"], band.GetUnitType(), dtype,
                    p["byte"]))
                self.assertEqual(ds.RasterCount, int(p["bands"]))
                self.assertEqual(band.GetUnitType(), p["unit"])
                self.assertEqual(dtype, "Byte" if p["byte"] in ("auto", "always")
                                 else "Float32")
                if p["byte"] == "never":
                    with self.assertRaises(RuntimeError) as e:
                        open_product(p["name"], ["OUTPUT_TYPE=Byte"])
                    self.assertIn("OUTPUT_TYPE=Byte is only for", str(e.exception))
                elif p["byte"] == "always":
                    with self.assertRaises(RuntimeError):
                        open_product(p["name"], ["OUTPUT_TYPE=Float32"])
                else:
                    ds = open_product(p["name"], ["OUTPUT_TYPE=Byte"])
                    self.assertEqual(ds.GetRasterBand(1).DataType, gdal.GDT_Byte)
                if p["daily"] == "yes":
                    with self.assertRaises(RuntimeError) as e:
                        gdal.OpenEx(T.conn(T.JACKSBORO),
                                    open_options=["PRODUCT=" + p["name"]])
                    self.assertIn("needs a day", str(e.exception))
                if needs_light(p):
                    with self.assertRaises(RuntimeError) as e:
                        gdal.OpenEx(T.conn(T.JACKSBORO),
                                    open_options=["PRODUCT=" + p["name"]])
                    self.assertIn("needs a light", str(e.exception))

    def test_options_left_out_are_refused(self):
        listed = {p["name"]: p["options"].split(",") for p in products()}
        cases = [("DATE", "sunhours", "shade", DAY, "DATE applies to the day products"),
                 ("METHOD", "shadow", "svf", ["METHOD=shm"], "METHOD=shm applies to"),
                 ("DATETIME", "shade", "horizon", ["DATETIME=2026-06-21T12:00:00-05:00"],
                  "DATETIME applies to"),
                 ("MAX_DISTANCE", "sunhours", "farshadow", ["MAX_DISTANCE=100"],
                  "MAX_DISTANCE does not apply"),
                 ("SKY", "envlight", "svf", ["SKY=overcast"], "SKY applies to")]
        for option, takes, refuses, values, text in cases:
            with self.subTest(option):
                self.assertIn(option, listed[takes])
                self.assertNotIn(option, listed[refuses])
                self.assertIsNotNone(open_product(takes, values))
                with self.assertRaises(RuntimeError) as e:
                    open_product(refuses, values)
                print("%s with %s: %s" % (option, refuses, e.exception))
                self.assertIn(text, str(e.exception))

    def test_options_at_their_defaults_are_warned_of(self):
        """An option of other products given with its declared default is no
        mistake of meaning (docs/driver.md, "Which options apply"): the
        dataset opens with the warning that names it, as METHOD=exact with
        svf always did. HORIZON_METHOD=exact with sunhours (whose sweeps are
        exact), PYRAMID_*, ENV_ROTATION=0, the ENV_*_STEPS, EXPOSURE=AUTO
        and, with ENV_MAP, SUN_AZIMUTH=315 were refused until session 58's
        audit; other values still are."""
        envmap = os.path.join(T.DATA, "envmaps", "sunset.exr")
        cases = [("sunhours", ["HORIZON_METHOD=exact", "PYRAMID_LEVEL_STEP=4",
                               "PYRAMID_OFFSET=0"], ["HORIZON_METHOD=pyramid"]),
                 ("farshadow", ["PYRAMID_OFFSET=0"], ["PYRAMID_OFFSET=8"]),
                 ("svf", ["ENV_ROTATION=0", "ENV_HORIZON_STEPS=181", "ENV_NORMAL_STEPS=0",
                          "EXPOSURE=AUTO"], ["ENV_ROTATION=10"]),
                 ("horizon", ["EXPOSURE=auto"], ["EXPOSURE=1"]),
                 ("envlight", ["ENV_MAP=" + envmap, "SUN_AZIMUTH=315"],
                  ["ENV_MAP=" + envmap, "SUN_AZIMUTH=200"]),
                 # beside other options: the sun of a time, Float32's
                 # exposure, the table of a sky term not asked for (the review)
                 ("shade", ["DATETIME=2026-06-21T12:00:00-05:00", "SUN_AZIMUTH=315",
                            "SUN_ELEVATION=45"],
                  ["DATETIME=2026-06-21T12:00:00-05:00", "SUN_ELEVATION=30"]),
                 ("daycycle", ["SUN_ELEVATION=45"], ["SUN_ELEVATION=30"]),
                 ("envlight", ["OUTPUT_TYPE=Float32", "EXPOSURE=AUTO"],
                  ["OUTPUT_TYPE=Float32", "EXPOSURE=2"]),
                 ("shade", ["SKY_WEIGHT=0", "ENV_HORIZON_STEPS=181", "ENV_ROTATION=0"],
                  ["ENV_HORIZON_STEPS=31"])]
        for name, defaults, refused in cases:
            with self.subTest(name):
                said = []
                gdal.PushErrorHandler(lambda cls, no, msg: said.append(msg))
                try:
                    ds = open_product(name, defaults)
                finally:
                    gdal.PopErrorHandler()
                said = " ".join(said)
                self.assertIsNotNone(ds)
                self.assertIn("nothing here", said)
                enablers = ("ENV_MAP=", "DATETIME=", "OUTPUT_TYPE=", "SKY_WEIGHT=")
                for d in defaults:  # (but what makes the others do nothing)
                    if not d.startswith(enablers):
                        self.assertIn(d.split("=")[0], said)
                ds = None
                with self.assertRaises(RuntimeError) as e:
                    open_product(name, refused)
                print("%s: %s" % (name, e.exception))

    def test_what_the_table_says_is_what_the_bands_are(self):
        """Session 58's options audit: insolation's first band was 'total'
        in the product's description and 'global' in its band description
        and the docs (now 'global' everywhere); farshadow's OUTPUT_TYPE=Byte,
        what it writes, was warned of as doing nothing; a geographic DEM's
        MERIDIAN_CONVERGENCE read -0.000000."""
        p = {q["name"]: q for q in products()}
        self.assertIn("global, beam, diffuse", p["insolation"]["description"])
        ds = open_product("insolation")
        self.assertEqual(ds.GetRasterBand(1).GetDescription(), "insolation global")
        ds = None
        for value in ("Byte", "AUTO"):
            said = []
            gdal.PushErrorHandler(lambda cls, no, msg: said.append(msg))
            try:
                ds = open_product("farshadow", ["OUTPUT_TYPE=" + value, "ATLAS_STEPS=2"])
            finally:
                gdal.PopErrorHandler()
            self.assertIsNotNone(ds)
            self.assertFalse([m for m in said if "OUTPUT_TYPE" in m], said)
            ds = None
        ds = open_product("shade", ["DATETIME=2026-06-21T12:00:00-05:00"])
        self.assertEqual(ds.GetMetadataItem("MERIDIAN_CONVERGENCE"), "0.000000")


if __name__ == "__main__":
    unittest.main(verbosity=2)
