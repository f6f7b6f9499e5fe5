"""The driver is registered, documented and installable.

- gdalinfo --formats lists TERRASHADE as a raster driver with virtual I/O
  that reads (TERRASHADE:<dem> and far-shadow atlases) and writes atlases
  by CreateCopy (*.tsa); gdalinfo --format TERRASHADE documents every option with its
  type, default, range and description;
- the plugin exports only GDALRegister_TERRASHADE and does not depend on a
  shared libterrashade (self-contained);
- make install puts gdal_TERRASHADE.so into the directory GDAL scans for
  plugins, and GDAL loads it from there;
- Identify is a silent prefix test: other files are not claimed.
"""
import os
import re
import subprocess
import unittest
import xml.etree.ElementTree as ET

import tsdriver as T

REQUIRED = ["PRODUCT", "SUN_AZIMUTH", "SUN_ELEVATION", "DIRECTIONS",
            "START_AZIMUTH", "METHOD", "PENUMBRA_DEPTH", "Z_FACTOR",
            "MAX_DISTANCE", "CURVATURE", "REFRACTION", "SKY_WEIGHT", "BAND",
            "THREADS", "OUTPUT_TYPE"]


def open_option_list():
    drv = T.gdal.GetDriverByName("TERRASHADE")
    return ET.fromstring(drv.GetMetadataItem(T.gdal.DMD_OPENOPTIONLIST))


class Registration(unittest.TestCase):
    def test_listed_by_gdalinfo(self):
        p = T.run(["gdalinfo", "--formats"])
        line = [l for l in p.stdout.splitlines() if "TERRASHADE" in l]
        print(line)
        self.assertEqual(len(line), 1, p.stdout)
        self.assertIn("-raster-", line[0])
        self.assertIn("(rwv)", line[0])  # read, CreateCopy (atlases), virtual I/O

    def test_format_documents_every_option(self):
        p = T.run(["gdalinfo", "--format", "TERRASHADE"])
        print(p.stdout)
        self.assertIn("Long Name: terrashade", p.stdout)
        self.assertIn("Help Topic:", p.stdout)
        self.assertIn("Connection prefix: TERRASHADE:", p.stdout)
        for name in REQUIRED:
            self.assertIn('name="%s"' % name, p.stdout)

    def test_option_list_declares_type_default_range(self):
        opts = {o.get("name"): o for o in open_option_list()}
        for name in REQUIRED + ["MAX_MEMORY"]:
            o = opts[name]
            self.assertTrue(o.get("description"), name)
            self.assertIsNotNone(o.get("default"), name)
            # Z_FACTOR: AUTO or a number, a string for GDAL
            self.assertIn(o.get("type"), ("float", "int", "boolean", "string-select")
                          + (("string",) if name == "Z_FACTOR" else ()), name)
            if o.get("type") in ("float", "int"):
                self.assertIsNotNone(o.get("min"), name)
            if o.get("type") == "string-select":
                self.assertIn(o.get("default"), [v.text for v in o], name)
        self.assertEqual(opts["SUN_AZIMUTH"].get("default"), "315")
        self.assertEqual(opts["SUN_ELEVATION"].get("default"), "45")
        self.assertEqual(opts["Z_FACTOR"].get("default"), "AUTO")
        self.assertEqual([v.text for v in opts["PRODUCT"]],
                         ["shade", "shadow", "horizon", "svf", "openness", "sky",
                          "sunhours", "insolation", "daycycle", "farshadow", "envlight"])
        for name in ("DATETIME", "DATE", "TIMEZONE", "STEP_MINUTES", "PRESSURE",
                     "TEMPERATURE", "DELTA_T", "SUN_POSITION", "LINKE_TURBIDITY",
                     "FAR_THRESHOLD", "ATLAS_STEPS", "SUNHOURS_RULE", "PROGRESS", "SHADOWS",
                     "DEM"):
            self.assertTrue(opts[name].get("description"), name)

    def test_driver_metadata(self):
        drv = T.gdal.GetDriverByName("TERRASHADE")
        md = drv.GetMetadata()
        self.assertEqual(md.get("DCAP_RASTER"), "YES")
        self.assertEqual(md.get("DCAP_VIRTUALIO"), "YES")
        self.assertEqual(md.get("DCAP_CREATECOPY"), "YES")
        self.assertEqual(md.get("DMD_EXTENSION"), "tsa")
        self.assertTrue(md.get("DMD_LONGNAME"))
        self.assertTrue(md.get("DMD_HELPTOPIC"))

    def test_identify_claims_only_the_prefix(self):
        self.assertEqual(T.gdal.IdentifyDriver(T.JACKSBORO).ShortName, "GTiff")
        drv = T.gdal.IdentifyDriver(T.conn(T.JACKSBORO))
        self.assertEqual(drv.ShortName, "TERRASHADE")
        # lower case prefix too, as GDAL prefixes usually are
        ds = T.gdal.Open("terrashade:" + T.JACKSBORO)
        self.assertEqual(ds.GetDriver().ShortName, "TERRASHADE")

    def test_exports_only_the_entry_point(self):
        p = T.run(["nm", "-D", "--defined-only", T.PLUGIN])
        text = [l.split()[-1] for l in p.stdout.splitlines()
                if re.search(r" [TDB] ", l)]
        print("exported:", text)
        self.assertEqual(text, ["GDALRegister_TERRASHADE"])
        ldd = T.run(["ldd", T.PLUGIN]).stdout
        self.assertNotIn("terrashade", ldd.lower())
        self.assertIn("libgdal", ldd)

    def test_make_install_into_gdal_plugin_dir(self):
        """make install (DESTDIR) puts the .so where GDAL looks for plugins."""
        plugindir = None
        with open(os.path.join(T.BUILDDIR, "Makefile")) as f:
            for line in f:
                m = re.match(r"^gdalplugindir = (.*)$", line.rstrip("\n"))
                if m:
                    plugindir = m.group(1).strip()
        self.assertTrue(plugindir, "gdalplugindir not in the Makefile")
        libs = T.run(["gdal-config", "--libs"]).stdout
        libdir = re.search(r"-L(\S+)", libs)
        libgdal = [os.path.join(libdir.group(1) if libdir else "/usr/lib", f)
                   for f in os.listdir(libdir.group(1) if libdir else "/usr/lib")
                   if f.startswith("libgdal.so")]
        strings = subprocess.run(["grep", "-a", "-o", "[[:print:]]*gdalplugins",
                                  libgdal[0]], capture_output=True, text=True).stdout
        print("configure's plugin dir:", plugindir)
        print("libgdal's built-in plugin path:", sorted(set(strings.split())))
        if "${" not in plugindir:
            self.assertIn(plugindir, strings.split(),
                          "GDAL does not scan %s" % plugindir)
        with T.TempDir() as dest:
            e = T.env(DESTDIR=dest)
            e.pop("MAKEFLAGS", None)
            e.pop("MFLAGS", None)
            p = subprocess.run(["make", "-C", T.BUILDDIR, "-s",
                                "install-gdalpluginLTLIBRARIES", "DESTDIR=" + dest],
                               capture_output=True, text=True, env=e)
            self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
            installed = os.path.join(dest + plugindir.replace("${prefix}", "/usr"),
                                     "gdal_TERRASHADE.so")
            found = [os.path.join(r, f) for r, _, fs in os.walk(dest) for f in fs]
            print("installed:", found)
            so = [f for f in found if f.endswith("/gdal_TERRASHADE.so")]
            self.assertEqual(len(so), 1, found)
            if "${" not in plugindir:
                self.assertEqual(so[0], installed)
            p = T.run(["gdalinfo", "--formats"],
                      GDAL_DRIVER_PATH=os.path.dirname(so[0]))
            self.assertIn("TERRASHADE", p.stdout)


if __name__ == "__main__":
    unittest.main(verbosity=2)
