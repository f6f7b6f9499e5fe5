"""Processing algorithms: one per single-raster TERRASHADE product.

The algorithms and their parameters are built when the provider loads, from
what the driver declares (driver_tables.py): a product of the driver's
product table is an algorithm terrashade:<product>, and each open option the
table lists for it is a parameter with the option's name, type, range,
default, choices and description. Each algorithm turns its parameters back
into open options, opens TERRASHADE:<dem> through GDAL and writes the result
with gdal.Translate, so it gives exactly what `gdal_translate -oo ...
TERRASHADE:dem out.tif` gives. Only presentation is written here.
"""
import contextlib
import os
import shlex
import sys

from osgeo import gdal
from qgis.core import (QgsContrastEnhancement, QgsDataProvider,
                       QgsProcessingAlgorithm, QgsProcessingException,
                       QgsProcessingLayerPostProcessorInterface,
                       QgsProcessingParameterBoolean, QgsProcessingParameterDefinition,
                       QgsProcessingParameterEnum, QgsProcessingParameterFile,
                       QgsProcessingParameterNumber,
                       QgsProcessingParameterRasterDestination,
                       QgsProcessingParameterRasterLayer, QgsProcessingParameterString,
                       QgsProviderRegistry, QgsRaster, QgsRasterBandStats,
                       QgsRasterFileWriter, QgsSingleBandGrayRenderer)
from qgis.PyQt import sip

from .driver_tables import DRIVER, is_yes, read_driver, single_raster

# Open options the provider sets itself, never parameters: the algorithm is the
# product, and QGIS shows the progress in its own bar.
FIXED = ("PRODUCT", "PROGRESS")
# Options shown outside "Advanced parameters"; every other one (a new one too)
# is advanced.
BASIC = ("SUN_AZIMUTH", "SUN_ELEVATION", "DATETIME", "METHOD", "SKY_WEIGHT", "DIRECTIONS",
         "DATE", "TIMEZONE", "STEP_MINUTES", "LINKE_TURBIDITY", "ENV_MAP", "SKY",
         "ENV_ROTATION")
# Text options better picked than typed: a file (its filter), and a list of
# values (a choice whose first entry, NONE, leaves the option unset).
FILES = {"ENV_MAP": "OpenEXR environment maps (*.exr *.EXR)"}
NONE = "(none)"
# Numbers whose driver default depends on the other options (STEP_MINUTES: 5
# for one day, 30 for a date range): optional parameters with no value, which
# leave the option to the driver; a value given is passed, even the table's.
OPEN_DEFAULT = ("STEP_MINUTES",)
PICKS = {"SKY": ["uniform", "overcast", "clear"] + ["cie:%d" % n for n in range(1, 16)]}
# Short labels where the description's first clause is too long (see label()).
LABELS = {
    "DIRECTIONS": "Number of azimuths",
    "SKY_WEIGHT": "Weight of the light of a uniform sky",
    "DATETIME": "Date and time (ISO 8601 with an offset)",
    "DATE": "Day (YYYY-MM-DD, local to the time zone)",
    "STEP_MINUTES": "Time step (minutes; empty: 5 for one day, 30 for a date range)",
    "Z_FACTOR": "Z factor (multiplies the heights, e.g. 0.3048 for feet)",
    "BACKEND": "Backend",
    "ENV_MAP": "Environment map (OpenEXR, lat-long or cube)",
    "SKY": "Standard sky (CIE)",
}
# Titles of the algorithms; a product not here is titled by its description.
TITLES = {"shade": "Hillshade with cast shadows", "shadow": "Cast shadows",
          "horizon": "Horizon angles", "svf": "Sky-view factor",
          "openness": "Openness", "sky": "Sky light", "sunhours": "Hours of sun",
          "insolation": "Clear-sky insolation", "envlight": "Environment light"}
BYTE_HELP = {
    "auto": "Byte 1..255 by default (0 = nodata); OUTPUT_TYPE=Float32 for the values.",
    "allowed": "Float32 by default; OUTPUT_TYPE=Byte scales it to 1..255 (0 = nodata).",
    "always": "Byte.",
    "never": "Float32.",
}


def first_clause(text):
    """The description up to its first ';', ': ' or ', e.g.', without a short
    scope prefix such as 'shade only: ' or 'METHOD=shm: ', capitalised."""
    head = text.split("; ")[0]
    parts = head.split(": ")
    scope = parts[0]
    if len(parts) > 1 and len(scope.split()) <= 2 and (scope[:1].islower() or "=" in scope):
        parts = parts[1:]
    clause = parts[0].split(", e.g.")[0].strip()
    return clause[:1].upper() + clause[1:]


def label(option):
    return LABELS.get(option.name) or first_clause(option.description) or option.name


def default_value(option):
    """The option's declared default as the parameter's Python value."""
    d = option.default
    if option.kind == "bool":
        return is_yes(d)
    if option.kind == "choice":
        return option.values.index(d) if d in option.values else None
    if d is None or d == "":
        return None if option.kind in ("float", "int") else ""
    return {"float": float, "int": int}.get(option.kind, str)(d)


def make_parameter(option):
    name, text, default = option.name, label(option), default_value(option)
    if name in OPEN_DEFAULT:
        default = None
    if option.kind in ("float", "int"):
        bounds = [-sys.float_info.max if option.minimum is None else option.minimum,
                  sys.float_info.max if option.maximum is None else option.maximum]
        p = QgsProcessingParameterNumber(
            name, text, QgsProcessingParameterNumber.Double if option.kind == "float"
            else QgsProcessingParameterNumber.Integer, default, name in OPEN_DEFAULT, *bounds)
    elif option.kind == "bool":
        p = QgsProcessingParameterBoolean(name, text, default)
    elif option.kind == "choice":
        p = QgsProcessingParameterEnum(name, text, option.values, False, default)
    elif name in FILES:
        p = QgsProcessingParameterFile(name, text, QgsProcessingParameterFile.File, "", None,
                                       True, FILES[name])
    elif name in PICKS:
        p = QgsProcessingParameterEnum(name, text, [NONE] + PICKS[name], False, 0, True)
    else:  # empty text: the option is not given
        p = QgsProcessingParameterString(name, text, default, False, True)
    p.setHelp(option.description)
    if name not in BASIC:
        p.setFlags(p.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
    return p


def number_text(value):
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def connection(dem):
    """TERRASHADE:dem, the name quoted where the driver would read its start
    as inline options (a file 'a=b:c.tif': '=' before a ':'), as the driver
    asks (docs/driver.md); any other name as it is."""
    colon, eq = dem.find(":"), dem.find("=")
    if colon > 0 and 0 <= eq < colon and not dem.startswith('"'):
        dem = '"%s"' % dem
    return "%s:%s" % (DRIVER, dem)


def output_format(out):
    """(GDAL driver, creation options) of the output file out."""
    ext = os.path.splitext(out)[1].lstrip(".")
    fmt = (QgsRasterFileWriter.driverForExtension(ext) if ext else "") or "GTiff"
    creation = ["COMPRESS=DEFLATE", "TILED=YES", "BIGTIFF=IF_SAFER"] if fmt == "GTiff" else []
    return fmt, creation


def command_line(dem, options, out):
    """The gdal_translate command that writes the same file."""
    fmt, creation = output_format(out)
    args = ["gdal_translate", "-of", fmt]
    for c in creation:
        args += ["-co", c]
    for k, v in options.items():
        args += ["-oo", "%s=%s" % (k, v)]
    return " ".join(shlex.quote(a) for a in args + [connection(dem), out])


def layer_dem(layer, feedback=None):
    """The GDAL name of a layer's file: its source without the parts QGIS
    adds to a GDAL layer's URI (|option:KEY=VALUE, |credential:...), which
    GDAL read as part of the file's name ("cannot open the DEM
    'dem.tif|option:NUM_THREADS=1'"); what they set is not passed, and the
    log says so."""
    src = layer.source()
    cuts = [i for i in (src.find("|option:"), src.find("|credential:")) if i >= 0]
    if not cuts:
        return src
    dem = src[:min(cuts)]
    if feedback is not None:
        feedback.pushWarning("The layer's GDAL settings (%s) are not passed to terrashade, "
                             "which opens %s as it is." % (src[min(cuts) + 1:], dem))
    return dem


def check_layer_crs(layer, dem):
    """Refuses a layer whose CRS (set in QGIS) is not its file's: the driver
    reads the file, whose CRS measures the cells (a file without one, given
    EPSG:4326 in QGIS, was computed with its degrees taken as metres, and
    the run succeeded). The file's CRS is what QGIS's own GDAL provider reads
    for it (a custom CRS read through GDAL's WKT1 lost its conversion's name
    and never matched: the review)."""
    # (the provider alone: a layer validates a file without a CRS, which can
    # ask the user or take a default, and computes statistics for its
    # stretch, 1.5 s and a write into a VRT mosaic: the third review)
    own = QgsProviderRegistry.instance().createProvider(
        "gdal", layer.source(), QgsDataProvider.ProviderOptions())
    crs = layer.crs()
    if own is None or not own.isValid() or not crs.isValid() or crs == own.crs():
        return
    name = crs.authid() or crs.toProj() or crs.description()
    mine = own.crs()
    raise QgsProcessingException(
        "The layer's CRS, %s, is not its file's (%s): terrashade reads the file, whose CRS "
        "measures its cells. Assign the CRS to the file (gdal_edit.py -a_srs %s %s), or save "
        "the layer as a new file with it, and run on that."
        % (name, (mine.authid() or mine.toProj() or mine.description()) if mine.isValid()
           else "none", shlex.quote(name or "..."), shlex.quote(dem)))


def local_files(name):
    """The files of the OS a GDAL name reads: itself, or for a name in a
    virtual file system (/vsizip/archive.zip/dem.tif) the archive that holds
    it."""
    if not name.startswith("/vsi"):
        return [name]
    if "/" not in name[1:]:
        return []  # (/vsimem, /vsistdin)
    prefix, rest = name[:name.index("/", 1) + 1], name[name.index("/", 1) + 1:]
    if prefix == "/vsisubfile/" and "," in rest:  # /vsisubfile/offset_size,/data/dem.tif
        return local_files(rest.split(",", 1)[1])
    if rest.startswith("{"):  # /vsizip/{/data/a.zip}/dem.tif, braces nested as GDAL reads them
        depth = 0
        for i, c in enumerate(rest):
            depth += {"{": 1, "}": -1}.get(c, 0)
            if depth == 0:
                return local_files(rest[1:i])
        return []
    parts = rest.split("/")
    return [p for p in ("/".join(parts[:k]) for k in range(1, len(parts) + 1))
            if p and os.path.isfile(p)][:1]


def inputs(dem, options):
    """(file, what it is) for each file of the OS the algorithm reads: the
    DEM's (a VRT's sources, the archive of a /vsizip/ DEM) and ENV_MAP."""
    ds, _ = gdal_call(gdal.OpenEx, dem, gdal.OF_RASTER)
    files = (ds.GetFileList() or []) if ds is not None else []
    ds = None
    found = [(f, "the DEM itself" if f == dem else "one of its files (%s)" % f)
             for g in files for f in local_files(g)]
    if options.get("ENV_MAP"):
        found += [(f, "its environment map (ENV_MAP)") for f in local_files(options["ENV_MAP"])]
    return found


def check_output(out, found):
    """Refuses an output that is one of the files the algorithm reads
    (found: inputs()), the DEM, one of its files or ENV_MAP: GDAL deletes the output before the product is read, and the DEM
    was gone (an environment map was replaced, and the run succeeded: the
    reviews); and an existing GeoPackage that holds other layers, which
    GDAL's copy replaces whole (the fourth review: a vector layer was lost)."""
    target = os.path.realpath(out)
    for f, what in found:
        if os.path.realpath(f) == target or (
                os.path.exists(f) and os.path.exists(out) and os.path.samefile(f, out)):
            raise QgsProcessingException(
                "The output %s is %s, which the algorithm reads: writing it would delete "
                "it before the product is computed. Choose another file." % (out, what))
    # the files a format writes beside its output (EHdr's .hdr and .prj,
    # SAGA's .sgrd): over a DEM of the same name in the same folder, its
    # header was replaced and the DEM unreadable (the sixth review)
    stem = os.path.splitext(os.path.realpath(out))[0]
    for f, what in found:
        if os.path.splitext(os.path.realpath(f))[0] == stem:
            raise QgsProcessingException(
                "The output %s has the name of %s (%s), which the algorithm reads: the files "
                "its format writes beside it (a header, a .prj) would replace those. Choose "
                "another name." % (out, what.split(" (")[0], f))
    if output_format(out)[0] == "GPKG" and os.path.exists(out):
        gdal.PushErrorHandler("CPLQuietErrorHandler")
        try:
            held, _ = gdal_call(gdal.OpenEx, out, gdal.OF_RASTER | gdal.OF_VECTOR)
            others = held is not None and (held.GetLayerCount() > 0 or
                                           len(held.GetSubDatasets()) > 1)
            held = None
        finally:
            gdal.PopErrorHandler()
        if others:
            raise QgsProcessingException(
                "The output %s is a GeoPackage that holds other layers: GDAL's copy would "
                "replace it whole, and them with it. Choose a new file." % out)


# Output formats that keep a product's values as they are (each read back
# equal to the GeoTIFF by the fourth and fifth reviews), and those that keep
# a Byte product's only. The others change them: JPEG, WebP, KMZ are lossy,
# PDF redraws, MBTiles reprojects, XPM writes palette indices, XYZ and Golden
# Software's grid lose bands or cannot be read again, GRIB drops the NaN
# nodata and keeps micro-degrees; each was a success.
FAITHFUL = ("GTiff", "COG", "HFA", "netCDF", "AAIGrid", "ENVI", "EHdr", "ERS", "RST",
            "PCIDSK", "NITF", "BT", "SAGA", "GPKG", "KEA")
FAITHFUL_BYTE = ("PNG", "BMP", "GIF")


def check_format(fmt, ds):
    """Refuses an output format that does not keep the product's values (PNG
    or JPEG of Float32 values wrote svf as 0 and 1, and the run succeeded) or
    that holds no pixels (a VRT of the TERRASHADE: string, computed again at
    every read)."""
    if fmt == "VRT":
        raise QgsProcessingException(
            "A VRT output holds no pixels: it would name TERRASHADE:<dem> and compute it "
            "again at every read. Write a GeoTIFF (.tif).")
    kind = gdal.GetDataTypeName(ds.GetRasterBand(1).DataType)
    types = (gdal.GetDriverByName(fmt).GetMetadataItem(gdal.DMD_CREATIONDATATYPES)
             or "").split() if gdal.GetDriverByName(fmt) is not None else []
    if fmt in FAITHFUL_BYTE and kind != "Byte" or types and kind not in types:
        raise QgsProcessingException(
            "The output format %s cannot hold this product's %s values (it takes %s). Write a "
            "GeoTIFF (.tif)%s." % (fmt, kind, ", ".join(types) or "Byte",
                                   ", or set OUTPUT_TYPE=Byte where the product has it"
                                   if kind == "Float32" else ""))
    if fmt not in FAITHFUL + FAITHFUL_BYTE:
        raise QgsProcessingException(
            "The output format %s does not keep the product's values as they are (a lossy, "
            "display or tiled format). Write a GeoTIFF (.tif), or another format that keeps "
            "them (%s; %s for Byte products), and convert that if you need %s."
            % (fmt, ", ".join(FAITHFUL), ", ".join(FAITHFUL_BYTE), fmt))


class Warnings:
    """GDAL's warnings while it is pushed (gdal.PushErrorHandler), kept for the
    Processing log, where GDAL's own handler (stderr) would not show them."""

    def __init__(self):
        self.messages = []  # (level, message)

    def __call__(self, level, _number, message):
        if level in (gdal.CE_Warning, gdal.CE_Failure) and \
                (level, message) not in self.messages:
            self.messages.append((level, message))

    def said(self, error=None):
        """What goes to the log: the warnings, and the errors (where the run
        did not fail, errors that did not fail the copy: SAGA's "Unable to
        set GeoTransform" left a grid without its georeferencing, the fourth
        review), but for the failed run's own sentence, error."""
        return [m for level, m in self.messages
                if level == gdal.CE_Warning or not error or m not in error]


def translate(dem, options, out, feedback=None, found=()):
    """gdal_translate -oo ... TERRASHADE:dem out, with the feedback's
    progress and cancellation; the driver's warnings go to the feedback's
    log; raises QgsProcessingException on failure. found: the files the
    algorithm reads (inputs()), which a failed output's removal keeps."""
    if gdal.GetDriverByName(DRIVER) is None:
        raise QgsProcessingException("The TERRASHADE GDAL driver is not loaded any more.")
    warnings = Warnings()
    gdal.PushErrorHandler(warnings)
    error = None
    try:
        write(dem, options, out, feedback, found)
    except QgsProcessingException as e:
        error = str(e) or "failed"
        raise
    finally:
        gdal.PopErrorHandler()
        if feedback is not None:
            for message in warnings.said(error):
                feedback.pushWarning(message)


def gdal_call(function, *args, **kwargs):
    """(function's result, GDAL's last error message), the result None on a
    failure, whether or not gdal.UseExceptions() is on: it is global to
    osgeo.gdal, so another plugin or the Python console may have turned it
    on, and a RuntimeError would reach the user as a traceback."""
    gdal.ErrorReset()
    try:
        return function(*args, **kwargs), gdal.GetLastErrorMsg()
    except RuntimeError as e:
        return None, str(e)


def write(dem, options, out, feedback, found):
    ds, message = gdal_call(gdal.OpenEx, connection(dem), gdal.OF_RASTER,
                            open_options=["%s=%s" % kv for kv in options.items()])
    if ds is None:
        raise QgsProcessingException(message or "cannot open %s" % dem)
    fmt, creation = output_format(out)
    check_format(fmt, ds)

    def progress(done, _message, _data):
        if feedback is not None:
            feedback.setProgress(100.0 * done)
            return 0 if feedback.isCanceled() else 1
        return 1

    folder = os.path.dirname(os.path.abspath(out))
    with contextlib.suppress(OSError):  # (GDAL creates no folder: the sixth review)
        os.makedirs(folder, exist_ok=True)
    try:
        before = set(os.listdir(folder))
    except OSError:
        before = set()
    res, message = gdal_call(gdal.Translate, out, ds, options=gdal.TranslateOptions(
        format=fmt, creationOptions=creation, callback=progress))
    shape = (ds.RasterCount, ds.GetRasterBand(1).DataType, ds.RasterXSize, ds.RasterYSize,
             ds.GetGeoTransform(can_return_null=True))
    ds = None
    if res is None:
        # GDAL's failed copy of a multi-band product deletes the raster but
        # leaves its PAM sidecar (band descriptions): no output file means
        # none of it
        if not os.path.exists(out):
            with contextlib.suppress(OSError):
                os.remove(out + ".aux.xml")
        if feedback is not None and feedback.isCanceled():
            raise QgsProcessingException("cancelled")
        raise QgsProcessingException(message or "gdal.Translate failed")
    res.FlushCache()
    res = None
    # (only files the write made: SAGA's .prj replaced a .bil DEM's, the
    # fourth review, and is the DEM's still)
    kept = {os.path.join(folder, f) for f in before} | {f for f, _ in found}
    check_written(out, fmt, shape, kept)


def check_written(out, fmt, shape, kept):
    """Reads the output back: a format that dropped bands, narrowed the
    type, changed the grid or its georeferencing (SAGA for cells that are
    not square), or wrote what GDAL cannot read again, was a success that
    was not (the reviews); the file is removed and the run fails. shape:
    the product's (bands, type, width, height, geotransform)."""
    bands, kind, width, height, gt = shape
    gdal.PushErrorHandler("CPLQuietErrorHandler")  # (HFA's "NaN converted to INT_MAX")
    try:
        got, written = read_back(out)
    finally:
        gdal.PopErrorHandler()

    def same_place(read):
        """The same grid within what formats that write text keep (7 to 12
        decimals, micro-degrees): half a cell at the origin, 1 % of a cell's
        size; a lost georeferencing is another grid (the fourth review)."""
        if gt is None:
            return True
        if read is None:
            return False
        cell = max(abs(gt[1]), abs(gt[5]))
        return (all(abs(read[i] - gt[i]) <= 0.01 * cell for i in (1, 2, 4, 5)) and
                all(abs(read[i] - gt[i]) <= 0.5 * cell for i in (0, 3)))

    if got is not None and got[0] == bands and got[2:4] == (width, height) and \
            gdal.GetDataTypeSize(got[1]) >= gdal.GetDataTypeSize(kind) and same_place(got[4]):
        return
    for f in ({os.path.abspath(f) for f in written} - {os.path.abspath(k) for k in kept}) \
            | {out, out + ".aux.xml"}:
        with contextlib.suppress(OSError):
            os.remove(f)
    raise QgsProcessingException(
        "The output format %s did not keep the product (%s read back where %d band(s) of %s, "
        "%d x %d cells, were written, georeferenced). Write a GeoTIFF (.tif)."
        % (fmt, "nothing" if got is None else "%d band(s) of %s, %d x %d cells, %s" % (
            got[0], gdal.GetDataTypeName(got[1]), got[2], got[3],
            "georeferenced as written" if same_place(got[4]) else "another georeferencing"),
            bands, gdal.GetDataTypeName(kind), width, height))


def read_back(out):
    """(bands, type, width, height, geotransform) of the file written, or
    None; and the files it consists of."""
    back, _ = gdal_call(gdal.OpenEx, out, gdal.OF_RASTER)
    written = (back.GetFileList() or []) if back is not None else []  # (SAGA's .sgrd, .prj)
    if back is not None and back.RasterCount == 0:  # netCDF's bands are its variables
        subs = back.GetSubDatasets()
        count = len(subs)
        back = gdal_call(gdal.OpenEx, subs[0][0], gdal.OF_RASTER)[0] if subs else None
    elif back is not None:
        count = back.RasterCount
    got = None
    if back is not None and back.RasterCount > 0:
        got = (count, back.GetRasterBand(1).DataType, back.RasterXSize, back.RasterYSize,
               back.GetGeoTransform(can_return_null=True))
    back = None
    return got, written


class TerrashadeAlgorithm(QgsProcessingAlgorithm):
    def __init__(self, product, options):
        """product: a driver_tables.Product; options: its Options, in order."""
        super().__init__()
        self.product, self.options_used = product, options

    def createInstance(self):  # noqa: N802 (QGIS's names from here on)
        return TerrashadeAlgorithm(self.product, self.options_used)

    def name(self):
        return self.product.name

    def displayName(self):  # noqa: N802
        return TITLES.get(self.product.name) or first_clause(self.product.description)

    def group(self):
        return "Sun and time" if self.product.daily else "Terrain"

    def groupId(self):  # noqa: N802
        return "day" if self.product.daily else "terrain"

    def shortHelpString(self):  # noqa: N802
        p = self.product
        bands = p.bands + (" (set by %s)" % p.bands_option if p.bands_option else "")
        text = p.description[:1].upper() + p.description[1:]
        return ("%s.\n\nUnit: %s. Bands: %s. %s\n\nRuns the TERRASHADE GDAL driver with "
                "PRODUCT=%s; the parameters are the driver's open options (docs/driver.md)."
                % (text.rstrip("."), p.unit or "none", bands, BYTE_HELP.get(p.byte, ""),
                   p.name))

    def initAlgorithm(self, config=None):  # noqa: N802
        self.addParameter(QgsProcessingParameterRasterLayer(
            "INPUT", "Elevation model (DEM)"))
        for option in self.options_used:
            self.addParameter(make_parameter(option))
        self.addParameter(QgsProcessingParameterRasterDestination(
            "OUTPUT", self.displayName()))

    def option_text(self, option, parameters, context):
        """The open option a parameter stands for, or None for the driver's default."""
        name, kind = option.name, option.kind
        if name in OPEN_DEFAULT and parameters.get(name) in (None, ""):
            return None
        if name in PICKS:
            v = self.parameterAsEnum(parameters, name, context)
            return PICKS[name][v - 1] if v > 0 else None
        if name in FILES:
            text = (self.parameterAsFile(parameters, name, context) or "").strip()
            return text or None
        if kind == "choice":
            v = self.parameterAsEnum(parameters, name, context)
            text = option.values[v]
        elif kind == "bool":
            v = self.parameterAsBool(parameters, name, context)
            text = "YES" if v else "NO"
        elif kind == "float":
            v = self.parameterAsDouble(parameters, name, context)
            text = number_text(v)
        elif kind == "int":
            v = self.parameterAsInt(parameters, name, context)
            text = str(v)
        else:
            v = text = (self.parameterAsString(parameters, name, context) or "").strip()
            if not text:
                return None
        if name in OPEN_DEFAULT:
            return text
        return None if v == default_value(option) else text

    def open_options(self, parameters, context):
        """The driver's open options these parameters stand for."""
        opts = {"PRODUCT": self.product.name, "PROGRESS": "no"}
        for option in self.options_used:
            text = self.option_text(option, parameters, context)
            if text is not None:
                opts[option.name] = text
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
        dem = layer_dem(layer, feedback)
        check_layer_crs(layer, dem)
        out = self.parameterAsOutputLayer(parameters, "OUTPUT", context)
        opts = self.open_options(parameters, context)
        found = inputs(dem, opts)  # (the DEM opened once for both)
        check_output(out, found)
        feedback.pushInfo("Same as: " + command_line(dem, opts, out))
        feedback.pushInfo("Computing %s on the whole DEM first; the progress bar moves "
                          "while the result is written." % self.product.name)
        translate(dem, opts, out, feedback, found)
        if context.willLoadLayerOnCompletion(out):
            context.layerToLoadOnCompletionDetails(out).setPostProcessor(
                FirstBandGray.create())
        return {"OUTPUT": out}


class FirstBandGray(QgsProcessingLayerPostProcessorInterface):
    """Shows a loaded output of several bands that are not a colour image
    (horizon's azimuths, insolation's global, beam and diffuse) as its first
    band in grey, stretched from its minimum to its maximum: QGIS draws any
    raster of three bands or more as red, green and blue from bands 1-3,
    which made a picture of three unrelated quantities. envlight's red,
    green and blue bands keep QGIS's colour rendering."""

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802
        FirstBandGray.pending.pop(self.key, None)  # (QGIS deletes it with its context)
        provider = layer.dataProvider() if layer is not None else None
        if provider is None or provider.bandCount() < 2:
            return
        if provider.colorInterpretation(1) == QgsRaster.RedBand:  # a colour image
            return
        stats = provider.bandStatistics(1, QgsRasterBandStats.Min | QgsRasterBandStats.Max)
        renderer = QgsSingleBandGrayRenderer(provider, 1)
        contrast = QgsContrastEnhancement(provider.dataType(1))
        contrast.setContrastEnhancementAlgorithm(
            QgsContrastEnhancement.StretchToMinimumMaximum)
        if stats.maximumValue > stats.minimumValue:
            contrast.setMinimumValue(stats.minimumValue)
            contrast.setMaximumValue(stats.maximumValue)
        renderer.setContrastEnhancement(contrast)
        layer.setRenderer(renderer)
        layer.triggerRepaint()

    # QGIS deletes a post-processor with its context, and keeps no Python
    # reference to it: each is kept here until it has run. One slot for all
    # (as QGIS's docs show it) lost an earlier run's Python part, whose layer
    # was left unstyled, where two runs' outputs waited at once (two dialogs,
    # a model): session 57's review of the plugin.
    pending = {}

    def __init__(self):
        super().__init__()
        self.key = id(self)

    @staticmethod
    def create():
        # (those whose context QGIS has deleted unrun: a cancelled load, a
        # layer that failed to load; the review)
        for key in [k for k, p in FirstBandGray.pending.items() if sip.isdeleted(p)]:
            del FirstBandGray.pending[key]
        processor = FirstBandGray()
        FirstBandGray.pending[processor.key] = processor
        return processor


def make_algorithms():
    """One algorithm per single-raster product of the loaded driver; raises
    DriverError when the driver is missing or does not describe itself."""
    options, products = read_driver()
    return [TerrashadeAlgorithm(p, [options[n] for n in p.options if n not in FIXED])
            for p in products if single_raster(p)]

