"""Processing algorithms: one per TERRASHADE product.

Each algorithm turns its parameters into the driver's open options, opens
TERRASHADE:<dem> through GDAL and writes the result with gdal.Translate, so
it gives exactly what `gdal_translate -oo ... TERRASHADE:dem out.tif` gives.
The options, their ranges and their meaning are the driver's
(docs/driver.md); the tables below only say which product shows which.
"""
import os
import shlex

from osgeo import gdal
from qgis.core import (QgsProcessing, QgsProcessingAlgorithm, QgsProcessingException,
                       QgsProcessingParameterBoolean, QgsProcessingParameterDefinition,
                       QgsProcessingParameterEnum, QgsProcessingParameterNumber,
                       QgsProcessingParameterRasterDestination,
                       QgsProcessingParameterRasterLayer, QgsProcessingParameterString,
                       QgsRasterFileWriter)

DRIVER = "TERRASHADE"

# name: (kind, label, default, extra, advanced)
#   kind "float"/"int": extra = (minimum, maximum); "enum": extra = values
#   (the first is the default); "text": extra = optional (True: may be empty)
OPTIONS = {
    "SUN_AZIMUTH": ("float", "Sun azimuth (degrees clockwise from north)", 315.0,
                    (0.0, 360.0), False),
    "SUN_ELEVATION": ("float", "Sun elevation (degrees above the horizontal)", 45.0,
                      (-90.0, 90.0), False),
    "DATETIME": ("text", "Date and time instead of azimuth and elevation (ISO 8601 with "
                 "an offset, e.g. 2026-06-21T07:30:00+02:00)", "", True, False),
    "METHOD": ("enum", "Shadow method", None, ["exact", "shm"], False),
    "PENUMBRA_DEPTH": ("float", "Penumbra depth of METHOD=shm (metres, 0 = hard)", 0.0,
                       (0.0, 1e6), True),
    "SKY_WEIGHT": ("float", "Weight of the light of a uniform sky", 0.0, (0.0, 1.0), False),
    "DIRECTIONS": ("int", "Number of azimuths", 16, (1, 3600), False),
    "START_AZIMUTH": ("float", "First azimuth (degrees from north)", 0.0, (0.0, 360.0),
                      True),
    "OUTPUT_TYPE": ("enum", "Data type", None, ["AUTO", "Byte", "Float32"], True),
    "DATE": ("text", "Day (YYYY-MM-DD, local to the time zone)", "", False, False),
    "TIMEZONE": ("text", "Offset from UTC of the local day (e.g. +02:00, -05:00, Z)", "",
                 False, False),
    "STEP_MINUTES": ("int", "Time step (minutes)", 5, (1, 240), False),
    "SUNHOURS_RULE": ("enum", "What a time step counts", None, ["visible", "fraction"],
                      True),
    "LINKE_TURBIDITY": ("float", "Linke turbidity of the clear sky", 3.0, (1.0, 10.0),
                        False),
    "SUN_POSITION": ("enum", "Where the sun is computed from", None, ["center", "per_cell"],
                     True),
    "PRESSURE": ("float", "Mean air pressure (hPa, refraction of the sun)", 1013.25,
                 (1.0, 5000.0), True),
    "TEMPERATURE": ("float", "Mean air temperature (degrees Celsius, refraction)", 15.0,
                    (-272.0, 6000.0), True),
    # common to every product
    "BAND": ("int", "DEM band holding the heights", 1, (1, 65536), True),
    "Z_FACTOR": ("float", "Z factor (multiplies the heights, e.g. 0.3048 for feet)", 1.0,
                 (1e-9, 1e6), True),
    "MAX_DISTANCE": ("float", "Largest shadow-casting distance (metres, 0 = unbounded)", 0.0,
                     (0.0, 1e8), True),
    "CURVATURE": ("bool", "Earth curvature and refraction", True, None, True),
    "REFRACTION": ("float", "Refraction coefficient k", 0.13, (0.0, 1.0), True),
    "THREADS": ("int", "Worker threads (0 = one per core)", 0, (0, 1024), True),
    "BACKEND": ("enum", "Backend", None, ["auto", "opencl", "c"], True),
}
COMMON = ["BAND", "Z_FACTOR", "MAX_DISTANCE", "CURVATURE", "REFRACTION", "THREADS",
          "BACKEND"]
SUN = ["SUN_AZIMUTH", "SUN_ELEVATION", "DATETIME", "PRESSURE", "TEMPERATURE"]
DAY = ["DATE", "TIMEZONE", "STEP_MINUTES", "SUN_POSITION", "PRESSURE", "TEMPERATURE"]

# product: (display name, help, option names)
PRODUCTS = [
    ("shade", "Hillshade with cast shadows",
     "Sun-lit relief as gdaldem hillshade (Horn normals, Lambert), times the visible "
     "fraction of the sun's disk above each cell's exact horizon: real cast shadows with "
     "penumbrae. Byte 1..255 by default (0 = nodata).",
     SUN + ["METHOD", "SKY_WEIGHT", "DIRECTIONS", "OUTPUT_TYPE"]),
    ("shadow", "Cast shadows",
     "Visible fraction of the sun's disk, 0 (full shadow) to 1 (lit).",
     SUN + ["METHOD", "PENUMBRA_DEPTH", "OUTPUT_TYPE"]),
    ("horizon", "Horizon angles",
     "One band per azimuth: the elevation angle of the horizon in degrees.",
     ["DIRECTIONS", "START_AZIMUTH"]),
    ("svf", "Sky-view factor",
     "Cosine-weighted visible fraction of the sky, 0..1 (1 on an open plane).",
     ["DIRECTIONS", "START_AZIMUTH", "OUTPUT_TYPE"]),
    ("openness", "Positive openness",
     "Mean of 90 degrees minus the horizon angle over the azimuths, degrees.",
     ["DIRECTIONS", "START_AZIMUTH"]),
    ("sky", "Sky light",
     "Irradiance from a uniform sky of unit radiance, 0..1.",
     ["DIRECTIONS", "START_AZIMUTH", "OUTPUT_TYPE"]),
    ("sunhours", "Hours of sun",
     "Hours of direct sun on a day, cast shadows included: on a flat open plane the "
     "astronomical day length.",
     DAY + ["SUNHOURS_RULE"]),
    ("insolation", "Clear-sky insolation",
     "Clear-sky irradiation of a day in Wh/m2 on each cell's own slope (ESRA model): "
     "band 1 global, band 2 beam, band 3 diffuse.",
     DAY + ["LINKE_TURBIDITY", "DIRECTIONS"]),
]


def driver_loaded():
    return gdal.GetDriverByName(DRIVER) is not None


def option_text(kind, value, extra):
    if kind == "bool":
        return "YES" if value else "NO"
    if kind == "enum":
        return extra[value]
    if kind == "int":
        return str(int(value))
    if kind == "float":
        return repr(float(value))
    return str(value).strip()


def command_line(dem, options, out):
    """The gdal_translate command that does the same."""
    args = ["gdal_translate"]
    for k, v in options.items():
        if k != "PROGRESS":
            args += ["-oo", "%s=%s" % (k, v)]
    return " ".join(shlex.quote(a) for a in args + ["%s:%s" % (DRIVER, dem), out])


def translate(dem, options, out, feedback=None):
    """gdal_translate -oo ... TERRASHADE:dem out, with the feedback's
    progress and cancellation; raises QgsProcessingException on failure."""
    if not driver_loaded():
        raise QgsProcessingException(
            "The TERRASHADE GDAL driver is not loaded. Install gdal_TERRASHADE.so into "
            "GDAL's plugin folder (make install), or start QGIS with GDAL_DRIVER_PATH "
            "set to the folder that holds it.")
    gdal.ErrorReset()
    ds = gdal.OpenEx("%s:%s" % (DRIVER, dem), gdal.OF_RASTER,
                     open_options=["%s=%s" % kv for kv in options.items()])
    if ds is None:
        raise QgsProcessingException(gdal.GetLastErrorMsg() or "cannot open %s" % dem)
    ext = os.path.splitext(out)[1].lstrip(".")
    fmt = QgsRasterFileWriter.driverForExtension(ext) if ext else ""
    fmt = fmt or "GTiff"
    creation = ["COMPRESS=DEFLATE", "TILED=YES", "BIGTIFF=IF_SAFER"] if fmt == "GTiff" else []

    def progress(done, _message, _data):
        if feedback is not None:
            feedback.setProgress(100.0 * done)
            return 0 if feedback.isCanceled() else 1
        return 1

    gdal.ErrorReset()
    res = gdal.Translate(out, ds, options=gdal.TranslateOptions(
        format=fmt, creationOptions=creation, callback=progress))
    ds = None
    if res is None:
        if feedback is not None and feedback.isCanceled():
            raise QgsProcessingException("cancelled")
        raise QgsProcessingException(gdal.GetLastErrorMsg() or "gdal.Translate failed")
    res.FlushCache()
    res = None


class TerrashadeAlgorithm(QgsProcessingAlgorithm):
    def __init__(self, product, title, help_text, names):
        super().__init__()
        self.product, self.title, self.help_text = product, title, help_text
        self.names = list(dict.fromkeys(names + COMMON))  # once each, in order

    def createInstance(self):  # noqa: N802 (QGIS's names from here on)
        return TerrashadeAlgorithm(self.product, self.title, self.help_text, self.names)

    def name(self):
        return self.product

    def displayName(self):  # noqa: N802
        return self.title

    def group(self):
        return "Sun and time" if self.product in ("sunhours", "insolation") else "Terrain"

    def groupId(self):  # noqa: N802
        return "day" if self.product in ("sunhours", "insolation") else "terrain"

    def shortHelpString(self):  # noqa: N802
        return (self.help_text + "\n\nRuns the TERRASHADE GDAL driver with PRODUCT=%s; "
                "the options are the driver's (docs/driver.md)." % self.product)

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterRasterLayer(
            "INPUT", "Elevation model (DEM)"))
        for name in self.names:
            kind, label, default, extra, advanced = OPTIONS[name]
            if kind in ("float", "int"):
                p = QgsProcessingParameterNumber(
                    name, label, QgsProcessingParameterNumber.Double if kind == "float"
                    else QgsProcessingParameterNumber.Integer, default, False, *extra)
            elif kind == "bool":
                p = QgsProcessingParameterBoolean(name, label, default)
            elif kind == "enum":
                p = QgsProcessingParameterEnum(name, label, extra, False, 0)
            else:
                p = QgsProcessingParameterString(name, label, default, False, extra)
            if advanced:
                p.setFlags(p.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
            self.addParameter(p)
        self.addParameter(QgsProcessingParameterRasterDestination("OUTPUT", self.title))

    def options(self, parameters, context):
        """The driver's open options these parameters stand for."""
        opts = {"PRODUCT": self.product, "PROGRESS": "no"}
        for name in self.names:
            kind, _, _, extra, _ = OPTIONS[name]
            if kind == "float":
                v = self.parameterAsDouble(parameters, name, context)
            elif kind == "int":
                v = self.parameterAsInt(parameters, name, context)
            elif kind == "bool":
                v = self.parameterAsBool(parameters, name, context)
            elif kind == "enum":
                v = self.parameterAsEnum(parameters, name, context)
            else:
                v = self.parameterAsString(parameters, name, context)
                if not v or not v.strip():
                    continue
            if (v == 0 if kind == "enum" else v == OPTIONS[name][2]):
                continue  # the driver's default: no need to say it
            opts[name] = option_text(kind, v, extra)
        if "DATETIME" in opts:  # the date and time place the sun
            opts.pop("SUN_AZIMUTH", None)
            opts.pop("SUN_ELEVATION", None)
        return opts

    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802
        layer = self.parameterAsRasterLayer(parameters, "INPUT", context)
        if layer is None:
            raise QgsProcessingException("No elevation model was given.")
        dem = layer.source()
        if layer.providerType() != "gdal" or dem.upper().startswith(DRIVER + ":"):
            raise QgsProcessingException(
                "The elevation model must be a raster file read through GDAL (got %s, "
                "provider %s)." % (dem, layer.providerType()))
        out = self.parameterAsOutputLayer(parameters, "OUTPUT", context)
        opts = self.options(parameters, context)
        feedback.pushInfo("Same as: " + command_line(dem, opts, out))
        feedback.pushInfo("Computing %s on the whole DEM first; the progress bar moves "
                          "while the result is written." % self.product)
        translate(dem, opts, out, feedback)
        return {"OUTPUT": out}


def make_algorithms():
    return [TerrashadeAlgorithm(*p) for p in PRODUCTS]
