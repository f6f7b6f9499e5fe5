"""The driver under the user's locale (docs/driver.md, "Locale").

QGIS (Qt) and scripts that call locale.setlocale switch the process to the
user's locale. The driver reads and writes numbers and compares names in
the "C" locale whatever the process's (plugin/tsd_entry_state.h): under de_DE,
whose decimal separator is a comma, the defaults LIGHT_RADIUS=0.2666,
REFRACTION=0.13 and PRESSURE=1013.25 once read as 0 (a shadow product came
out all nodata, others silently without refraction), metadata and atlas
files were written with commas, and under tr_TR "directions" did not match
"DIRECTIONS". Each case runs in a child /usr/bin/python3 that sets the
locale before GDAL loads the driver, as QGIS does, against the same in the
"C" locale: the same bits, the same metadata. The locales are compiled
here with localedef (Debian's `locales` package, installed by setup.sh)
into a directory of their own (LOCPATH), so the machine's are not needed.
"""
import json
import os
import subprocess
import sys
import unittest

import tsdriver as T

LOCALES = {"de_DE.UTF-8": ("de_DE", "UTF-8"), "tr_TR.UTF-8": ("tr_TR", "UTF-8")}

# The child: set the locale, then load GDAL (its drivers register then),
# open each case, print one JSON line per case.
CHILD = r"""
import hashlib, json, locale, sys
loc = sys.argv[1]
if loc != "C":
    locale.setlocale(locale.LC_ALL, loc)
from osgeo import gdal
gdal.UseExceptions()
out = {"decimal_point": locale.localeconv()["decimal_point"]}
drv = gdal.GetDriverByName("TERRASHADE")
out["optionlist_has_comma_number"] = any(
    ch.isdigit() and nxt == "," and nn.isdigit()
    for ch, nxt, nn in zip(*[drv.GetMetadataItem("DMD_OPENOPTIONLIST")[i:] for i in range(3)]))
for case in json.loads(sys.argv[2]):
    name, opts = case["name"], case["opts"]
    try:
        ds = gdal.OpenEx(name, gdal.OF_RASTER, open_options=opts)
        h = hashlib.md5()
        nodata_only = True
        for b in range(1, ds.RasterCount + 1):
            band = ds.GetRasterBand(b)
            a = band.ReadAsArray()
            h.update(a.tobytes())
            nd = band.GetNoDataValue()
            nodata_only &= bool((a != a).all() if nd is None or nd != nd else (a == nd).all())
        band1 = ds.GetRasterBand(1)
        out[case["key"]] = {"md5": h.hexdigest(), "all_nodata": nodata_only,
                            "md": ds.GetMetadata(), "band1": band1.GetMetadata(),
                            "desc1": band1.GetDescription()}
        ds = None
    except Exception as e:
        out[case["key"]] = {"error": str(e)}
print(json.dumps(out))
"""


class Locale(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        d = cls.dir = cls.tmp.__enter__()
        cls.locpath = os.path.join(d, "locales")
        os.makedirs(cls.locpath)
        for name, (src, charmap) in LOCALES.items():
            p = subprocess.run(["localedef", "-i", src, "-f", charmap,
                                os.path.join(cls.locpath, name)],
                               capture_output=True, text=True)
            if p.returncode not in (0, 1):  # 1: warnings only
                raise AssertionError("localedef %s failed (is Debian's locales package "
                                     "installed? setup.sh installs it):\n%s%s"
                                     % (name, p.stdout, p.stderr))
        # an atlas written in the "C" locale, to open under the others
        cls.atlas = os.path.join(d, "day.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE", "-oo", "PRODUCT=farshadow",
               "-oo", "DATE=2024-06-21", "-oo", "TIMEZONE=-05:00", "-oo", "ATLAS_STEPS=8",
               "-oo", "FAR_THRESHOLD=32", T.conn(T.JACKSBORO), cls.atlas])
        dem = T.conn(T.JACKSBORO)
        cls.cases = [
            # the defaults' decimals (LIGHT_RADIUS): all nodata under de_DE once
            {"key": "shadow", "name": dem, "opts": ["PRODUCT=shadow", "SUN_ELEVATION=5"]},
            # a decimal the user gives
            {"key": "shade", "name": dem,
             "opts": ["PRODUCT=shade", "SUN_ELEVATION=30.5", "OUTPUT_TYPE=Float32"]},
            # REFRACTION's default, and the bands' azimuths as text
            {"key": "horizon", "name": dem,
             "opts": ["PRODUCT=horizon", "DIRECTIONS=7", "START_AZIMUTH=2.5"]},
            # PRESSURE's default (refused as 0 once)
            {"key": "sunhours", "name": dem,
             "opts": ["PRODUCT=sunhours", "DATE=2024-06-21", "TIMEZONE=-05:00",
                      "STEP_MINUTES=60"]},
            # an atlas's options, written as text in the "C" locale
            {"key": "atlas", "name": cls.atlas, "opts": []},
            # lower-case names and values with an "i" (tr_TR's dotless i)
            {"key": "lower", "name": dem, "opts": ["product=horizon", "directions=4"]},
            # a number in an error message
            {"key": "error", "name": dem, "opts": ["METHOD=shadowmap", "SHADOWMAP_SCALE=9"]},
        ]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def child(self, loc):
        p = subprocess.run([sys.executable, "-c", CHILD, loc, json.dumps(self.cases)],
                           capture_output=True, text=True, timeout=600,
                           env=T.env(LOCPATH=self.locpath, LC_ALL="C"))
        self.assertEqual(p.returncode, 0, "child under %s:\n%s" % (loc, p.stderr))
        return json.loads(p.stdout.strip().splitlines()[-1])

    def test_the_same_under_every_locale(self):
        c = self.child("C")
        for key in ("shadow", "shade", "horizon", "sunhours", "atlas", "lower"):
            self.assertNotIn("error", c[key], key)
        self.assertFalse(c["shadow"]["all_nodata"])
        self.assertEqual(c["horizon"]["desc1"], "azimuth 2.5")
        self.assertIn("0.25", c["error"]["error"])
        for loc in LOCALES:
            with self.subTest(locale=loc):
                other = self.child(loc)
                self.assertEqual(other["decimal_point"], ",",
                                 "the child did not switch to %s" % loc)
                self.assertFalse(other["optionlist_has_comma_number"],
                                 "the open-option list has a decimal comma under %s" % loc)
                for key in ("shadow", "shade", "horizon", "sunhours", "atlas", "lower"):
                    self.assertEqual(other[key], c[key], "%s under %s" % (key, loc))
                self.assertEqual(other["error"], c["error"])


if __name__ == "__main__":
    unittest.main()
