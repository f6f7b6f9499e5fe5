"""The QGIS Processing provider (plugin/qgis/terrashade), headless.

- the plugin's classFactory registers the provider with an algorithm per
  single-raster product, under the ids users' scripts know;
- every algorithm's parameters are the driver's: each open option that the
  driver's product table (metadata TERRASHADE_PRODUCTS) lists for the
  product is a parameter with the type, range, default and choices of the
  driver's open-option list (DMD_OPENOPTIONLIST), and there is no other;
- each algorithm writes what gdal_translate writes with the same options
  (shade from an azimuth and from a date and time, shadow with a choice and a
  boolean, svf, horizon, sunhours), and the gdal_translate command it logs
  writes the same pixels;
- bad input gives a QgsProcessingException with the driver's sentence, and
  a cancel one that says 'cancelled' (no output left), also with
  gdal.UseExceptions() turned on by someone else;
- qgis_process, QGIS's command line, finds the plugin through
  QGIS_PLUGINPATH, lists its algorithms and runs one.

QGIS runs in child processes (as in test_qgis.py) with HOME in a temporary
folder, so no user profile is read or written.
"""
import atexit
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

import tsdriver as T
from tsdriver import np

PLUGINS = os.path.join(T.SRCDIR, "plugin", "qgis")
ALGORITHMS = ["shade", "shadow", "horizon", "svf", "openness", "sky", "sunhours",
              "insolation", "envlight"]
# The provider's presentation rules (algorithms.py): a text option that is a
# file, and one picked from a list (its first entry leaves it unset).
FILE_OPTIONS = {"ENV_MAP"}
PICKED = {"SKY": ["(none)", "uniform", "overcast", "clear"] + ["cie:%d" % n
                                                             for n in range(1, 16)]}
SUNSET = os.path.join(T.DATA, "envmaps", "sunset.exr")
SET_BY_PROVIDER = {"PRODUCT", "PROGRESS"}  # the algorithm's product; QGIS's progress bar
# Numbers left empty by default, whose driver default depends on other options
# (STEP_MINUTES: 5 for one day, 30 for a date range); a value given is passed.
OPEN_DEFAULT = {"STEP_MINUTES"}
DBL_MAX = 1.7976931348623157e308  # QgsProcessingParameterNumber's bounds when unbounded

CHILD = r"""
import json, os, sys
os.environ["QT_QPA_PLATFORM"] = "offscreen"
sys.path.insert(0, sys.argv[1])
sys.path.insert(0, "/usr/share/qgis/python/plugins")  # QGIS's own processing
from qgis.core import (QgsApplication, QgsProcessingException, QgsProcessingFeedback,
                       QgsProcessingParameterDefinition, QgsProcessingParameterNumber)
app = QgsApplication([], False)
app.setPrefixPath("/usr", True)
app.initQgis()
from processing.core.Processing import Processing
Processing.initialize()
import processing
import terrashade
if sys.argv[3:] == ["exceptions"]:  # as another plugin or the console may set it
    from osgeo import gdal
    gdal.UseExceptions()
plugin = terrashade.classFactory(None)
plugin.initProcessing()
reg = QgsApplication.processingRegistry()
provider = reg.providerById("terrashade")


def describe(p):
    d = {"type": p.type(), "default": p.defaultValue(),
         "advanced": bool(p.flags() & QgsProcessingParameterDefinition.FlagAdvanced)}
    if p.type() == "number":
        d.update(minimum=p.minimum(), maximum=p.maximum(),
                 integer=p.dataType() == QgsProcessingParameterNumber.Integer)
    if p.type() == "enum":
        d["options"] = p.options()
    return d


class Log(QgsProcessingFeedback):
    def __init__(self, cancel=False):
        super().__init__()
        self.lines = []
        self.warnings = []
        self.cancel_on_progress = cancel  # the user's Cancel, once the bar moves

    def setProgress(self, progress):
        super().setProgress(progress)
        if self.cancel_on_progress and progress > 0:
            self.cancel()

    def pushInfo(self, info):
        self.lines.append(info)

    def pushWarning(self, warning):
        self.warnings.append(warning)


result = {"algorithms": sorted(a.id() for a in provider.algorithms()),
          "problem": provider.warningMessage(),
          "parameters": {a.name(): {p.name(): describe(p) for p in a.parameterDefinitions()}
                         for a in provider.algorithms()}}
from qgis.core import QgsCoordinateReferenceSystem, QgsRasterLayer
for name, alg, params in json.loads(sys.argv[2]):
    fb = Log(cancel=name.startswith("cancel"))
    if name.startswith("crs_"):  # a layer given another CRS in QGIS
        layer = QgsRasterLayer(params["INPUT"], name, "gdal")
        layer.setCrs(QgsCoordinateReferenceSystem("EPSG:4326"))
        params["INPUT"] = layer
    try:
        out = processing.run(alg, params, feedback=fb)
        result[name] = {"output": out["OUTPUT"], "log": fb.lines, "warnings": fb.warnings}
    except QgsProcessingException as e:
        result[name] = {"error": str(e), "warnings": fb.warnings}
# outputs loaded into a project: the algorithm sets the post-processor that
# draws a layer of several bands (not a colour image) as its first band in grey
from qgis.core import QgsProcessingContext, QgsProject, QgsRasterLayer
result["renderers"] = {}
# every run first, then every post-processor, as where two runs' outputs wait
# at once (two dialogs, a model): one slot for them all had lost the earlier
# runs' (session 57's review of the plugin)
waiting = []
for name in ("horizon", "range_default", "envlight", "svf"):
    if "output" not in result.get(name, {}):
        continue
    alg = [a for n, a, _ in json.loads(sys.argv[2]) if n == name][0]
    params = dict([p for n, _, p in json.loads(sys.argv[2]) if n == name][0])
    params["OUTPUT"] = params["OUTPUT"][:-4] + "_loaded.tif"
    context = QgsProcessingContext()
    context.addLayerToLoadOnCompletion(params["OUTPUT"], QgsProcessingContext.LayerDetails(
        name, QgsProject.instance(), name))
    processing.run(alg, params, context=context, feedback=Log())
    waiting.append((name, params, context))
for name, params, context in waiting:
    post = context.layerToLoadOnCompletionDetails(params["OUTPUT"]).postProcessor()
    layer = QgsRasterLayer(params["OUTPUT"], name)
    before = layer.renderer().type()
    if post is not None:
        post.postProcessLayer(layer, context, Log())
    r = layer.renderer()
    result["renderers"][name] = [before, r.type(), post is not None] + (
        [r.grayBand(), r.contrastEnhancement().minimumValue(),
         r.contrastEnhancement().maximumValue()] if r.type() == "singlebandgray" else [])
plugin.unload()
result["unloaded"] = reg.providerById("terrashade") is None
print("RESULT " + json.dumps(result))
sys.stdout.flush()
os._exit(0)
"""

# QGIS writes the statistics it computes beside the raster it reads
# (jacksboro.tif.aux.xml): it reads a copy, so the source tree stays clean
_J_DIR = tempfile.mkdtemp(prefix="tsqp-")
atexit.register(shutil.rmtree, _J_DIR, True)
J = shutil.copy(T.JACKSBORO, _J_DIR)
DAY = {"DATE": "2026-12-21", "TIMEZONE": "-05:00", "STEP_MINUTES": 30}
RANGE = {"START_DATE": "2026-06-01", "END_DATE": "2026-06-03", "DAY_INTERVAL": 2,
         "TIMEZONE": "-05:00"}
# name, algorithm, its parameters, the same as gdal_translate's open options
CASES = [
    ("shade", "terrashade:shade",
     {"INPUT": J, "SUN_AZIMUTH": 135, "SUN_ELEVATION": 20},
     {"PRODUCT": "shade", "SUN_AZIMUTH": 135, "SUN_ELEVATION": 20}),
    ("shade_time", "terrashade:shade",
     {"INPUT": J, "DATETIME": "2026-12-21T09:00:00-05:00", "SKY_WEIGHT": 0.3,
      "DIRECTIONS": 8},
     {"PRODUCT": "shade", "DATETIME": "2026-12-21T09:00:00-05:00",
      "SKY_WEIGHT": 0.3, "DIRECTIONS": 8}),
    ("shadow_shm", "terrashade:shadow",  # a choice by its index, a boolean
     {"INPUT": J, "SUN_ELEVATION": 15, "METHOD": 1, "PENUMBRA_DEPTH": 5,
      "CURVATURE": False},
     {"PRODUCT": "shadow", "SUN_ELEVATION": 15, "METHOD": "shm", "PENUMBRA_DEPTH": 5,
      "CURVATURE": "NO"}),
    ("svf", "terrashade:svf", {"INPUT": J, "DIRECTIONS": 8},
     {"PRODUCT": "svf", "DIRECTIONS": 8}),
    ("svf_short", "terrashade:svf",  # a warning of the driver, for the log
     {"INPUT": J, "DIRECTIONS": 4, "MAX_DISTANCE": 5},
     {"PRODUCT": "svf", "DIRECTIONS": 4, "MAX_DISTANCE": 5}),
    ("horizon", "terrashade:horizon", {"INPUT": J, "DIRECTIONS": 4},
     {"PRODUCT": "horizon", "DIRECTIONS": 4}),
    ("sunhours", "terrashade:sunhours", dict(DAY, INPUT=J),
     dict(DAY, PRODUCT="sunhours")),
    # STEP_MINUTES: empty is the driver's default (5 for a day, 30 for a range);
    # 5 given over a range is 5, although it is the option table's default
    ("sunhours_day5", "terrashade:sunhours",
     {"INPUT": J, "DATE": "2026-12-21", "TIMEZONE": "-05:00"},
     {"PRODUCT": "sunhours", "DATE": "2026-12-21", "TIMEZONE": "-05:00"}),
    ("range_step5", "terrashade:insolation", dict(RANGE, INPUT=J, STEP_MINUTES=5),
     dict(RANGE, PRODUCT="insolation", STEP_MINUTES=5)),
    ("range_default", "terrashade:insolation", dict(RANGE, INPUT=J),
     dict(RANGE, PRODUCT="insolation")),
    ("envlight", "terrashade:envlight",  # a file, a rotation
     {"INPUT": J, "ENV_MAP": SUNSET, "ENV_ROTATION": 30, "DIRECTIONS": 8},
     {"PRODUCT": "envlight", "ENV_MAP": SUNSET, "ENV_ROTATION": 30, "DIRECTIONS": 8}),
    ("shade_sky", "terrashade:shade",  # a sky picked from the list: cie:9
     {"INPUT": J, "SKY": 12, "SKY_WEIGHT": 0.5, "DIRECTIONS": 8},
     {"PRODUCT": "shade", "SKY": "cie:9", "SKY_WEIGHT": 0.5, "DIRECTIONS": 8}),
]
BAD = [
    ("no_date", "terrashade:sunhours", {"INPUT": J, "TIMEZONE": "-05:00"}),
    ("bad_time", "terrashade:shade", {"INPUT": J, "DATETIME": "2026-12-21T09:00"}),
]
# refused before anything is written (session 57's review of the plugin):
# name, algorithm, parameters with their own OUTPUT, words of the error
_ONTO = shutil.copy(T.JACKSBORO, os.path.join(_J_DIR, "onto.tif"))
_NOCRS = os.path.join(_J_DIR, "nocrs.tif")
_ENV = shutil.copy(SUNSET, os.path.join(_J_DIR, "env.exr"))
_LUX = shutil.copy(T.LUX, os.path.join(_J_DIR, "lux.tif"))
# a DEM whose .prj the output's would replace (SAGA writes dem.prj beside
# dem.sdat), and a GeoPackage of the user's with a vector layer
_BIL_DIR = os.path.join(_J_DIR, "bil")
os.mkdir(_BIL_DIR)
T.gdal.Translate(os.path.join(_BIL_DIR, "dem.bil"), T.LUX, format="EHdr")
with open(os.path.join(_BIL_DIR, "keep.prj"), "w") as _f:
    _f.write("a file of the user's\n")
_FLT = os.path.join(_BIL_DIR, "flt.flt")  # EHdr with its header flt.hdr
T.gdal.Translate(_FLT, T.LUX, format="EHdr")
_USER_GPKG = os.path.join(_J_DIR, "user.gpkg")
_gpkg = T.gdal.GetDriverByName("GPKG").Create(_USER_GPKG, 0, 0, 0, T.gdal.GDT_Unknown)
_gpkg.CreateLayer("parcels")
_gpkg = None
# a projected CRS without an EPSG code: the layer's is its file's (the
# review: compared through GDAL's WKT1, every such DEM was refused)
_CUSTOM = os.path.join(_J_DIR, "custom_lcc.tif")
_src = T.gdal.Open(T.JACKSBORO)
T.write_tif(_NOCRS, T.read(T.JACKSBORO), _src.GetGeoTransform(), None)
T.write_tif(_CUSTOM, T.read(T.JACKSBORO), _src.GetGeoTransform(),
            "+proj=lcc +lat_1=33 +lat_2=45 +lat_0=39 +lon_0=-96 +x_0=0 +y_0=0 +ellps=intl "
            "+units=m +no_defs")
_src = None
REFUSED = [
    # GDAL deleted the output, the DEM itself, before the product was read
    ("onto_dem", "terrashade:shade", {"INPUT": _ONTO, "OUTPUT": _ONTO},
     "the DEM itself, which the algorithm reads"),
    # an environment map was replaced by a GeoTIFF, and the run succeeded (the review)
    ("onto_env_map", "terrashade:envlight",
     {"INPUT": J, "ENV_MAP": _ENV, "DIRECTIONS": 4, "OUTPUT": _ENV},
     "its environment map (ENV_MAP), which the algorithm reads"),
    # formats that drop bands or lose values, refused before the run
    ("xyz_horizon", "terrashade:horizon", {"INPUT": J, "DIRECTIONS": 4,
                                           "OUTPUT": os.path.join(_J_DIR, "hz.xyz")},
     "The output format XYZ does not keep the product's values"),
    # read back: SAGA's grid lost lux_elev's georeferencing (its cells not
    # quite square in x and y), with an error that did not fail the copy
    ("sdat_svf", "terrashade:svf", {"INPUT": _LUX, "DIRECTIONS": 4,
                                    "OUTPUT": os.path.join(_J_DIR, "svf.sdat")},
     "The output format SAGA did not keep the product"),
    # ... and what it wrote is removed, but for a file that was there before
    # (a DEM's .prj replaced by SAGA's was removed too: the fifth review)
    ("sdat_over_a_prj", "terrashade:svf",
     {"INPUT": _LUX, "DIRECTIONS": 4, "OUTPUT": os.path.join(_BIL_DIR, "keep.sdat")},
     "The output format SAGA did not keep the product"),
    # an output of the DEM's name is refused before (the sixth review)
    ("sdat_beside_bil", "terrashade:svf",
     {"INPUT": os.path.join(_BIL_DIR, "dem.bil"), "DIRECTIONS": 4,
      "OUTPUT": os.path.join(_BIL_DIR, "dem.sdat")},
     "has the name of the DEM itself"),
    # an output of the DEM's name: EHdr's flt.hdr replaced the DEM's, and the
    # DEM could not be read any more (the sixth review)
    ("name_of_the_dem", "terrashade:shade",
     {"INPUT": _FLT, "OUTPUT": os.path.join(_BIL_DIR, "flt.bil")},
     "has the name of the DEM itself"),
    # GDAL's copy replaces a GeoPackage whole: a vector layer was lost
    ("gpkg_of_the_user", "terrashade:shade", {"INPUT": J, "OUTPUT": _USER_GPKG},
     "is a GeoPackage that holds other layers"),
    # PNG holds bytes: svf's values were written as 0 and 1, and the run succeeded
    ("png_svf", "terrashade:svf", {"INPUT": J, "DIRECTIONS": 4,
                                   "OUTPUT": os.path.join(_J_DIR, "svf.png")},
     "The output format PNG cannot hold this product's Float32 values"),
    # lossy or redrawn: JPEG, MBTiles (reprojected), PDF wrote other values
    # and the run succeeded (the fourth review)
    ("jpg_shade", "terrashade:shade", {"INPUT": J, "OUTPUT": os.path.join(_J_DIR, "s.jpg")},
     "The output format JPEG does not keep the product's values as they are"),
    ("mbtiles_shade", "terrashade:shade",
     {"INPUT": J, "OUTPUT": os.path.join(_J_DIR, "s.mbtiles")},
     "The output format MBTiles does not keep the product's values as they are"),
    ("vrt_svf", "terrashade:svf", {"INPUT": J, "DIRECTIONS": 4,
                                   "OUTPUT": os.path.join(_J_DIR, "svf.vrt")},
     "A VRT output holds no pixels"),
    # the layer's CRS, set in QGIS, was not the file's: computed in the file's
    # (none: cells taken as metres) and reported a success
    ("crs_nocrs", "terrashade:svf", {"INPUT": _NOCRS, "DIRECTIONS": 4,
                                     "OUTPUT": os.path.join(_J_DIR, "crs.tif")},
     "The layer's CRS, EPSG:4326, is not its file's (none)"),
]
# the user cancels once the progress bar moves (Log in CHILD, by the name)
CANCEL = [("cancel_svf", "terrashade:svf", {"INPUT": J, "DIRECTIONS": 8}),
          # several bands: GDAL's failed copy left OUTPUT.aux.xml behind
          ("cancel_horizon", "terrashade:horizon", {"INPUT": J, "DIRECTIONS": 8})]


def qgis_env(home):
    return T.env(HOME=home, XDG_RUNTIME_DIR=home, QT_QPA_PLATFORM="offscreen",
                 QGIS_PLUGINPATH=PLUGINS)


def driver_declares():
    """({option: <Option> element}, {product: <Product> element}) of the driver,
    read here from its metadata, independently of the plugin's reader."""
    drv = T.gdal.GetDriverByName("TERRASHADE")
    products = drv.GetMetadataItem("TERRASHADE_PRODUCTS")
    if not products:
        raise AssertionError("the driver has no metadata item TERRASHADE_PRODUCTS")
    return ({e.get("name"): e for e in
             ET.fromstring(drv.GetMetadataItem("DMD_OPENOPTIONLIST")).iter("Option")},
            {e.get("name"): e for e in ET.fromstring(products).iter("Product")})


def expected_parameter(option):
    """What describe() in CHILD must say of the parameter of this <Option>."""
    kind, default = option.get("type"), option.get("default")
    if option.get("name") in FILE_OPTIONS:
        return {"type": "file", "default": None}
    if option.get("name") in PICKED:
        return {"type": "enum", "options": PICKED[option.get("name")], "default": 0}
    if option.get("name") in OPEN_DEFAULT:
        default = None
    if kind in ("float", "int"):
        return {"type": "number", "integer": kind == "int",
                "minimum": float(option.get("min", -DBL_MAX)),
                "maximum": float(option.get("max", DBL_MAX)),
                "default": None if default in (None, "") else float(default)}
    if kind == "boolean":
        return {"type": "boolean", "default": default.upper() in ("YES", "TRUE", "ON", "1")}
    if kind == "string-select":
        values = [v.text for v in option.iter("Value")]
        return {"type": "enum", "options": values, "default": values.index(default)}
    return {"type": "string", "default": default or ""}


class Processing(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.home = os.path.join(cls.dir, "home")
        os.mkdir(cls.home, 0o700)
        runs = [(n, a, dict(p, OUTPUT=cls.out(n))) for n, a, p, _ in CASES]
        runs += [(n, a, dict(p, OUTPUT=cls.out(n))) for n, a, p in BAD + CANCEL]
        runs += [(n, a, p) for n, a, p, _ in REFUSED]
        # a layer source with QGIS's URI parts (a GDAL open option)
        # formats that keep the product: netCDF, whose bands read back as its
        # variables (a traceback: the third review), PNG for a Byte product
        runs += [("nc_horizon", "terrashade:horizon",
                  {"INPUT": J, "DIRECTIONS": 4, "OUTPUT": os.path.join(cls.dir, "hz.nc")}),
                 ("png_shade", "terrashade:shade",
                  {"INPUT": J, "OUTPUT": os.path.join(cls.dir, "shade.png")}),
                 # a folder that does not exist yet (GDAL creates none: the
                 # sixth review)
                 ("new_folder", "terrashade:svf",
                  {"INPUT": J, "DIRECTIONS": 4,
                   "OUTPUT": os.path.join(cls.dir, "new", "sub", "svf.tif")}),
                 # Idrisi keeps 7 decimals of degrees: its georeferencing is
                 # the same grid (refused at 1e-9: the fifth review)
                 ("rst_lux", "terrashade:svf",
                  {"INPUT": _LUX, "DIRECTIONS": 4, "OUTPUT": os.path.join(cls.dir, "lux.rst")})]
        runs += [("custom_crs", "terrashade:svf",
                  {"INPUT": _CUSTOM, "DIRECTIONS": 4, "OUTPUT": cls.out("custom_crs")})]
        runs += [("uri_option", "terrashade:svf",
                  {"INPUT": J + "|option:NUM_THREADS=1", "DIRECTIONS": 4,
                   "OUTPUT": cls.out("uri_option")})]
        cls.result, cls.child = cls.run_qgis(runs)
        # again with gdal.UseExceptions(): the errors, a warning and a cancel
        runs = [(n, a, dict(p, OUTPUT=cls.out(n + "_exc"))) for n, a, p, _ in CASES
                if n == "svf_short"]
        runs += [(n, a, dict(p, OUTPUT=cls.out(n + "_exc"))) for n, a, p in BAD + CANCEL]
        cls.result_exc, cls.child_exc = cls.run_qgis(runs, "exceptions")

    @classmethod
    def run_qgis(cls, runs, *mode):
        """(the child's result, what to say if there is none)."""
        p = subprocess.run([sys.executable, "-c", CHILD, PLUGINS, json.dumps(runs)]
                           + list(mode), capture_output=True, text=True, timeout=600,
                           env=qgis_env(cls.home))
        lines = [l for l in p.stdout.splitlines() if l.startswith("RESULT ")]
        return (json.loads(lines[-1][len("RESULT "):]) if lines else None,
                "QGIS produced no result (exit %d):\n%s\n%s" % (p.returncode, p.stdout,
                                                                  p.stderr))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    @classmethod
    def out(cls, name):
        return os.path.join(cls.dir, name + ".tif")

    def setUp(self):
        self.assertIsNotNone(self.result, self.child)

    def test_algorithms_are_the_products(self):
        r = self.result
        print("algorithms:", r["algorithms"], r["problem"])
        self.assertEqual(r["algorithms"], sorted("terrashade:" + a for a in ALGORITHMS))
        self.assertEqual(r["problem"], "")
        self.assertTrue(r["unloaded"])
        # the products left out are the day products whose band count follows
        # an option (time series), and only those
        _, products = driver_declares()
        for name, p in products.items():
            series = p.get("daily") == "yes" and bool(p.get("bands_option"))
            print("%-10s daily=%-3s bands=%s %-12s -> %s" % (
                name, p.get("daily"), p.get("bands"), p.get("bands_option", ""),
                "left out" if series else "algorithm"))
            self.assertEqual(name not in ALGORITHMS, series, name)

    def test_parameters_are_the_drivers_options(self):
        options, products = driver_declares()
        for alg in ALGORITHMS:
            params = self.result["parameters"][alg]
            listed = [n.strip() for n in products[alg].get("options").split(",") if n.strip()]
            wanted = [n for n in listed if n not in SET_BY_PROVIDER]
            with self.subTest(algorithm=alg):
                self.assertEqual(sorted(set(wanted) - set(params)), [],
                                 "options of the driver missing from terrashade:" + alg)
                self.assertEqual(sorted(set(params) - set(wanted) - {"INPUT", "OUTPUT"}), [],
                                 "parameters the driver does not list for " + alg)
                for name in wanted:
                    got = {k: params[name][k] for k in expected_parameter(options[name])}
                    self.assertEqual(got, expected_parameter(options[name]),
                                     "%s of terrashade:%s" % (name, alg))
            print("%-10s %2d parameters = the driver's options, %d advanced" % (
                alg, len(wanted), sum(params[n]["advanced"] for n in wanted if n in params)))

    def test_algorithms_equal_gdal_translate(self):
        result = self.result
        for name, _, _, options in CASES:
            with self.subTest(case=name):
                self.assertIn("output", result[name], result[name].get("error"))
                got = T.read(result[name]["output"])
                ref = T.read(T.translate(J, self.out(name + "_ref"), options))
                np.testing.assert_array_equal(got, ref)
                # the command in the log, run as it is written, writes the same
                same = [l for l in result[name]["log"] if l.startswith("Same as: ")]
                self.assertEqual(len(same), 1, result[name]["log"])
                args = shlex.split(same[0][len("Same as: "):])
                self.assertEqual(args[-1], result[name]["output"])
                T.run(args[:-1] + [self.out(name + "_log")])
                np.testing.assert_array_equal(T.read(self.out(name + "_log")), ref)
                # ... the same file: its storage and metadata too (session 46:
                # the command left out the format's creation options and PROGRESS)
                a = T.gdal.Open(result[name]["output"])
                b = T.gdal.Open(self.out(name + "_log"))
                self.assertEqual(a.GetMetadata("IMAGE_STRUCTURE"),
                                 b.GetMetadata("IMAGE_STRUCTURE"))
                self.assertEqual(a.GetMetadata(), b.GetMetadata())
                self.assertEqual(a.GetRasterBand(1).GetBlockSize(),
                                 b.GetRasterBand(1).GetBlockSize())
                a = b = None
                print("%-10s %s, equal to gdal_translate and to: %s" % (
                    name, got.shape, same[0][len("Same as: "):]))
                # the driver's warnings reach the Processing log, once each
                warned = result[name]["warnings"]
                if name == "svf_short":
                    self.assertEqual(len(warned), 1, warned)
                    self.assertIn("TERRASHADE: MAX_DISTANCE=5 m is shorter than the DEM's "
                                  "cells", warned[0])
                    print("%-10s warned: %s" % (name, warned[0]))
                else:
                    self.assertEqual(warned, [])
        # the range's 5-minute step was not dropped as "the default" (30 there)
        self.assertFalse(np.array_equal(T.read(result["range_step5"]["output"]),
                                        T.read(result["range_default"]["output"])))
        for name, _, _ in BAD:
            print("%-10s -> %s" % (name, result[name].get("error")))
        # no day: the driver's sentence names DATE (and DATETIME)
        self.assertIn("TERRASHADE", result["no_date"].get("error", ""))
        self.assertIn("DATE=YYYY-MM-DD", result["no_date"]["error"])
        # a time without an offset: the driver's sentence
        self.assertIn("TERRASHADE", result["bad_time"].get("error", ""))
        self.assertIn("offset", result["bad_time"]["error"])

    def test_refused_before_anything_is_written(self):
        """An output onto the DEM (GDAL deleted it before the product was
        read), a format that cannot hold the product or holds no pixels, a
        layer given another CRS in QGIS than its file's: refused with a
        sentence, the DEM untouched, nothing written (session 57's review of
        the plugin)."""
        for name, _alg, params, words in REFUSED:
            with self.subTest(name):
                r = self.result[name]
                print("%-10s -> %s" % (name, r.get("error")))
                self.assertIn(words, r.get("error", ""), r)
                if params["OUTPUT"] not in (params["INPUT"], params.get("ENV_MAP"),
                                            _USER_GPKG):
                    self.assertFalse(os.path.exists(params["OUTPUT"]))
        # SAGA's error, which did not fail the copy, is in the log (a failed
        # run logged none of GDAL's errors: the sixth review)
        self.assertTrue(any("Unable to set GeoTransform" in w
                            for w in self.result["sdat_svf"]["warnings"]),
                        self.result["sdat_svf"])
        self.assertIsNotNone(T.gdal.Open(_FLT))
        # (and the files the format wrote beside it, not the DEM's own)
        self.assertFalse([f for f in os.listdir(_J_DIR) if f.startswith("svf.")])
        left = os.listdir(_BIL_DIR)
        self.assertIn("dem.prj", left)
        self.assertIn("keep.prj", left)
        self.assertFalse([f for f in left if f.startswith(("dem.s", "keep.s"))
                          and f != "dem.stx"], left)
        held = T.gdal.OpenEx(_USER_GPKG, T.gdal.OF_VECTOR)
        self.assertEqual(held.GetLayerCount(), 1)
        held = None
        np.testing.assert_array_equal(T.read(_ONTO), T.read(T.JACKSBORO))
        with open(_ENV, "rb") as f, open(SUNSET, "rb") as g:
            self.assertEqual(f.read(), g.read())

    def test_formats_that_read_back_otherwise(self):
        """netCDF reads back a multi-band product as subdatasets, and PNG
        holds a Byte product: both keep the product, and the run succeeds
        (the read-back check failed netCDF with a traceback: the third
        review)."""
        for name in ("nc_horizon", "png_shade", "rst_lux", "new_folder"):
            with self.subTest(name):
                r = self.result[name]
                self.assertIn("output", r, r.get("error"))
                self.assertTrue(os.path.exists(r["output"]))
        ref = os.path.join(self.dir, "png_ref.tif")
        T.run(["gdal_translate", "-q", T.conn(J), ref])
        np.testing.assert_array_equal(T.read(self.result["png_shade"]["output"]), T.read(ref))

    def test_a_custom_crs_is_the_files(self):
        """A DEM in a projected CRS without an EPSG code runs: its layer's
        CRS is the file's (the review found every such DEM refused)."""
        r = self.result["custom_crs"]
        self.assertIn("output", r, r.get("error"))

    def test_layer_uri_parts(self):
        """A layer whose source carries QGIS's URI parts (|option:...): the
        file is the DEM, and the log says what is not passed (the driver
        was asked to open 'jacksboro.tif|option:NUM_THREADS=1')."""
        r = self.result["uri_option"]
        self.assertIn("output", r, r.get("error"))
        self.assertTrue(any("option:NUM_THREADS=1" in w and "not passed" in w
                            for w in r["warnings"]), r["warnings"])
        ref = os.path.join(self.dir, "uri_ref.tif")
        T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo", "DIRECTIONS=4",
               T.conn(J), ref])
        np.testing.assert_array_equal(T.read(r["output"]), T.read(ref))

    def test_loaded_outputs_of_several_bands_show_their_first_band(self):
        """QGIS draws a raster of three bands or more as red, green and blue
        from bands 1-3: horizon's first three azimuths, insolation's global,
        beam and diffuse made a colour picture of unrelated quantities. An
        output loaded into the project shows its first band in grey,
        stretched to its range; envlight's red, green and blue stay colour."""
        r = self.result["renderers"]
        print(r)
        for name in ("horizon", "range_default"):
            before, after, posted, band, lo, hi = r[name]
            self.assertTrue(posted)
            self.assertEqual((before, after, band), ("multibandcolor", "singlebandgray", 1))
            a = T.read(self.result[name]["output"], 1)
            self.assertAlmostEqual(lo, float(np.nanmin(a)), places=3)
            self.assertAlmostEqual(hi, float(np.nanmax(a)), places=3)
        self.assertEqual(r["envlight"][:2], ["multibandcolor", "multibandcolor"])
        self.assertEqual(r["svf"][:2], ["singlebandgray", "singlebandgray"])

    def test_cancel(self):
        """Cancel once the bar moves (the driver tells GDAL's copy its
        progress while it computes, so during the computation): the
        algorithm fails with 'cancelled' and leaves no output file."""
        for name, _alg, _params in CANCEL:
            with self.subTest(name):
                r = self.result[name]
                self.assertEqual(r.get("error"), "cancelled", r)
                self.assertFalse(os.path.exists(self.out(name)))
                self.assertFalse(os.path.exists(self.out(name) + ".aux.xml"))

    def test_with_gdal_exceptions(self):
        """gdal.UseExceptions() is global to osgeo.gdal, so another plugin or
        the console may turn it on: the driver's errors are still the
        algorithm's sentence, not a Python traceback ('Traceback ...
        RuntimeError: TERRASHADE: ...'), its warnings still reach the log, and
        a cancel is still 'cancelled'."""
        r = self.result_exc
        self.assertIsNotNone(r, self.child_exc)
        for name, _, _ in BAD:
            with self.subTest(case=name):
                print("%-10s -> %s" % (name, r[name].get("error")))
                self.assertEqual(r[name].get("error"), self.result[name]["error"])
                self.assertNotIn("Traceback", r[name]["error"])
        self.assertEqual(r["cancel_svf"].get("error"), "cancelled", r["cancel_svf"])
        self.assertFalse(os.path.exists(self.out("cancel_svf_exc")))
        self.assertIn("output", r["svf_short"], r["svf_short"].get("error"))
        self.assertEqual(r["svf_short"]["warnings"], self.result["svf_short"]["warnings"])

    def test_dem_names_the_driver_would_read_as_options(self):
        """A DEM named like inline options (a file 'a=b:c.tif', given relative)
        goes to the driver quoted, as docs/driver.md asks; other names as
        they are (session 46: 'PRODUCT=svf:x.tif' became PRODUCT=svf, given
        twice)."""
        sys.path.insert(0, PLUGINS)
        try:
            from terrashade.algorithms import connection
        finally:
            sys.path.remove(PLUGINS)
        for dem, want in (("a=b:c.tif", 'TERRASHADE:"a=b:c.tif"'),
                          ("PRODUCT=svf:x.tif", 'TERRASHADE:"PRODUCT=svf:x.tif"'),
                          ("/data/a=b:c.tif", 'TERRASHADE:"/data/a=b:c.tif"'),  # (harmless)
                          ("/data/dem.tif", "TERRASHADE:/data/dem.tif"),
                          ('NETCDF:"x.nc":z', 'TERRASHADE:NETCDF:"x.nc":z'),
                          ("x=1.tif", "TERRASHADE:x=1.tif")):
            self.assertEqual(connection(dem), want)
        here = os.getcwd()
        with T.TempDir() as d:
            with open(J, "rb") as f, open(os.path.join(d, "PRODUCT=svf:x.tif"), "wb") as g:
                g.write(f.read())
            try:
                os.chdir(d)  # the name relative, as qgis_process passes it
                ds = T.gdal.OpenEx(connection("PRODUCT=svf:x.tif"), T.gdal.OF_RASTER)
                self.assertEqual(ds.GetMetadataItem("PRODUCT"), "shade")
                ds = None
            finally:
                os.chdir(here)

    def test_the_files_a_name_reads(self):
        """The output check compares files of the OS: a /vsizip/ DEM's is its
        archive (writing over it deleted the DEM: the review)."""
        sys.path.insert(0, PLUGINS)
        try:
            from terrashade.algorithms import local_files
        finally:
            sys.path.remove(PLUGINS)
        with T.TempDir() as d:
            archive = os.path.join(d, "z.zip")
            import zipfile
            with zipfile.ZipFile(archive, "w") as z:
                z.write(J, "in/dem.tif")
            self.assertEqual(local_files("/vsizip/%s/in/dem.tif" % archive), [archive])
            self.assertEqual(local_files("/vsizip/{%s}/in/dem.tif" % archive), [archive])
            self.assertEqual(local_files("/vsicurl/http://example.com/dem.tif"), [])
            # (the third review: these missed the DEM's file, then deleted it)
            self.assertEqual(local_files("/vsisubfile/0_7994,%s" % J), [J])
            odd = os.path.join(d, "we{ird}.zip")
            shutil.copy(archive, odd)
            self.assertEqual(local_files("/vsizip/{%s}/in/dem.tif" % odd), [odd])
            self.assertEqual(local_files("/vsimem"), [])
            self.assertEqual(local_files(J), [J])

    def test_qgis_process_command_line(self):
        """qgis_process.bin (Debian's qgis_process wrapper fails on a flag in
        /etc/default/qgis) with the plugin enabled in a fresh profile."""
        qp = "/usr/bin/qgis_process.bin"
        env = qgis_env(self.home)
        p = subprocess.run([qp, "plugins", "enable", "terrashade"], capture_output=True,
                           text=True, timeout=300, env=env)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        p = subprocess.run([qp, "list"], capture_output=True, text=True, timeout=300, env=env)
        self.assertIn("terrashade:sunhours", p.stdout, p.stderr)
        out = self.out("qp_svf")
        p = subprocess.run([qp, "run", "terrashade:svf", "--", "INPUT=" + J,
                            "DIRECTIONS=8", "OUTPUT=" + out], capture_output=True, text=True,
                           timeout=300, env=env)
        print(p.stdout[-600:])
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        ref = T.read(T.translate(J, self.out("qp_ref"),
                                 {"PRODUCT": "svf", "DIRECTIONS": 8}))
        np.testing.assert_array_equal(T.read(out), ref)
        p = subprocess.run([qp, "run", "terrashade:sunhours", "--", "INPUT=" + J,
                            "OUTPUT=" + self.out("qp_bad")], capture_output=True, text=True,
                           timeout=300, env=env)
        print((p.stdout + p.stderr)[-400:])
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("DATE", p.stdout + p.stderr)
        p = subprocess.run([qp, "run", "terrashade:sunhours", "--", "INPUT=" + J,
                            "DATE=2026-02-30", "TIMEZONE=Z", "OUTPUT=" + self.out("qp_bad")],
                           capture_output=True, text=True, timeout=300, env=env)
        print((p.stdout + p.stderr)[-400:])
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("there is no day 30", p.stdout + p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
