"""Shared helpers of the TERRASHADE driver tests (not a test itself).

The tests run from the top build directory (automake's test harness runs
them there and exports $srcdir). They use the plugin in place:
GDAL_DRIVER_PATH = <builddir>/plugin/.libs, set here before osgeo is
imported, and passed on to every GDAL tool they run.
"""
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

BUILDDIR = os.path.abspath(os.environ.get("TS_BUILDDIR", os.getcwd()))
SRCDIR = os.path.abspath(
    os.environ.get("srcdir")
    or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
PLUGIN_DIR = os.path.join(BUILDDIR, "plugin", ".libs")
PLUGIN = os.path.join(PLUGIN_DIR, "gdal_TERRASHADE.so")
CORE_REFERENCE = os.path.join(BUILDDIR, "tests", "driver", "core_reference")
DATA = os.path.join(SRCDIR, "tests", "data")
JACKSBORO = os.path.join(DATA, "jacksboro.tif")
LUX = os.path.join(DATA, "lux_elev.tif")

if not os.path.exists(PLUGIN):
    sys.exit("FAIL: %s is missing: the plugin was not built (did configure "
             "find GDAL? run make first)" % PLUGIN)

os.environ["GDAL_DRIVER_PATH"] = PLUGIN_DIR
os.environ.setdefault("GDAL_CACHEMAX", "256")
os.environ.pop("CPL_DEBUG", None)

import numpy as np  # noqa: E402
from osgeo import gdal, osr  # noqa: E402

gdal.UseExceptions()
osr.UseExceptions()

if gdal.GetDriverByName("TERRASHADE") is None:
    sys.exit("FAIL: GDAL did not load the TERRASHADE driver from %s" % PLUGIN_DIR)


def env(**extra):
    """Environment for a GDAL tool: the in-place plugin, plus extra."""
    e = dict(os.environ)
    e.update({k: str(v) for k, v in extra.items()})
    return e


def run(args, ok=True, cwd=None, **extra_env):
    """Run a command; check its exit status is 0 (ok=True) or not 0
    (ok=False), or either (ok=None: gdalmanage exits 0 on errors).

    Returns the CompletedProcess with .stdout/.stderr as text. A process
    killed by a signal (a crash) always fails the test."""
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True,
                       cwd=cwd, env=env(**extra_env), timeout=600)
    out = "$ %s\n%s%s" % (" ".join(map(str, args)), p.stdout, p.stderr)
    if p.returncode < 0:
        raise AssertionError("crashed with signal %d:\n%s" % (-p.returncode, out))
    if ok and p.returncode != 0:
        raise AssertionError("failed (exit %d):\n%s" % (p.returncode, out))
    if ok is False and p.returncode == 0:
        raise AssertionError("succeeded but should have failed:\n%s" % out)
    return p


def conn(dem, **inline):
    """TERRASHADE:KEY=VALUE,...:<dem> (or TERRASHADE:<dem>)."""
    if not inline:
        return "TERRASHADE:" + dem
    opts = ",".join("%s=%s" % kv for kv in inline.items())
    return "TERRASHADE:%s:%s" % (opts, dem)


def oo_args(options):
    args = []
    for k, v in options.items():
        args += ["-oo", "%s=%s" % (k, v)]
    return args


def open_stderr(dem, **options):
    """What `gdalinfo -nomd -oo KEY=VALUE ... TERRASHADE:dem` says on stderr
    (the driver's warnings); the dataset must open."""
    return run(["gdalinfo", "-nomd"] + oo_args(options) + [conn(dem)]).stderr


def translate_stderr(dem, **options):
    """What `gdal_translate -oo KEY=VALUE ... TERRASHADE:dem` (into memory)
    says on stderr: the warnings of the computation too; it must succeed."""
    return run(["gdal_translate", "-q"] + oo_args(options)
               + [conn(dem), "/vsimem/translate_stderr.tif"]).stderr


def translate(dem, out, options=None, inline=None, extra=()):
    """gdal_translate TERRASHADE:... out.tif with -oo options; returns out."""
    run(["gdal_translate", "-q", "-of", "GTiff"] + oo_args(options or {})
        + list(extra) + [conn(dem, **(inline or {})), out])
    return out


def read(path, band=None, options=None):
    """All bands (3-D array) or one band (2-D) of a raster as float64 arrays,
    nodata (declared) as NaN. options: open options for TERRASHADE."""
    oo = ["%s=%s" % kv for kv in (options or {}).items()]
    ds = gdal.OpenEx(path, gdal.OF_RASTER, open_options=oo)
    bands = [band] if band else range(1, ds.RasterCount + 1)
    arrays = []
    for b in bands:
        rb = ds.GetRasterBand(b)
        a = rb.ReadAsArray().astype(np.float64)
        nd = rb.GetNoDataValue()
        if nd is not None and not np.isnan(nd):
            a[a == nd] = np.nan
        arrays.append(a)
    ds = None
    return arrays[0] if band else np.array(arrays)


def metadata(path, options=None):
    """The dataset's metadata (default domain), opened with these TERRASHADE
    open options."""
    oo = ["%s=%s" % kv for kv in (options or {}).items()]
    ds = gdal.OpenEx(path, gdal.OF_RASTER, open_options=oo)
    return ds.GetMetadata()


def read_dem(path, band=1):
    """The DEM as the driver sees it: float32 metres, NaN where masked."""
    ds = gdal.Open(path)
    rb = ds.GetRasterBand(band)
    z = rb.ReadAsArray().astype(np.float32)
    mask = rb.GetMaskBand().ReadAsArray()
    z[mask == 0] = np.nan
    gt = ds.GetGeoTransform()
    return z, gt, ds.GetProjection()


def write_tif(path, array, gt, srs, nodata=None, dtype=gdal.GDT_Float32):
    """Write a 2-D (or 3-D: bands first) array as GeoTIFF. srs: EPSG code,
    WKT/PROJ string or None."""
    a = np.asarray(array)
    if a.ndim == 2:
        a = a[None]
    ds = gdal.GetDriverByName("GTiff").Create(path, a.shape[2], a.shape[1],
                                              a.shape[0], dtype)
    ds.SetGeoTransform(gt)
    if srs is not None:
        s = osr.SpatialReference()
        if isinstance(srs, int):
            s.ImportFromEPSG(srs)
        else:
            s.SetFromUserInput(srs)
        ds.SetProjection(s.ExportToWkt())
    for i in range(a.shape[0]):
        rb = ds.GetRasterBand(i + 1)
        if nodata is not None:
            rb.SetNoDataValue(nodata)
        rb.WriteArray(a[i])
    ds = None
    return path


def write_vrt(path, source, width, height, gt, srs, axes=None):
    """A one-band Float32 VRT of band 1 of `source` (width x height cells),
    with geotransform gt and CRS srs (any text GDAL takes), its data axes
    `axes` ("1,2") where given: the CRSs and axis orders a GeoTIFF cannot
    hold (vertical, engineering with heights, a CRS's own axis order)."""
    from xml.sax.saxutils import escape, quoteattr
    mapping = " dataAxisToSRSAxisMapping=%s" % quoteattr(axes) if axes else ""
    with open(path, "w") as f:
        f.write('<VRTDataset rasterXSize="%d" rasterYSize="%d"><SRS%s>%s</SRS>'
                '<GeoTransform>%s</GeoTransform><VRTRasterBand dataType="Float32" '
                'band="1"><SimpleSource><SourceFilename relativeToVRT="0">%s'
                '</SourceFilename><SourceBand>1</SourceBand></SimpleSource>'
                '</VRTRasterBand></VRTDataset>' % (width, height, mapping, escape(srs),
                                                    ", ".join(map(repr, gt)), escape(source)))
    return path


def fractal_dem(n, seed=1, relief=300.0):
    """A reproducible fractal DEM (spectral synthesis, beta = 2.2)."""
    rng = np.random.default_rng(seed)
    fx = np.fft.fftfreq(n)[None, :]
    fy = np.fft.fftfreq(n)[:, None]
    f = np.hypot(fx, fy)
    f[0, 0] = 1.0
    spec = (rng.normal(size=(n, n)) + 1j * rng.normal(size=(n, n))) / f ** 1.1
    spec[0, 0] = 0
    z = np.real(np.fft.ifft2(spec))
    z = (z - z.min()) / (z.max() - z.min()) * relief + 100.0
    return z.astype(np.float32)


def flat_dem(path, lat, lon, n=32, cell=0.0005, z=0.0):
    """A flat n x n DEM in EPSG:4326 centred at (lat, lon)."""
    gt = (lon - n * cell / 2, cell, 0, lat + n * cell / 2, 0, -cell)
    return write_tif(path, np.full((n, n), z, np.float32), gt, 4326)


_UTM = {}


def jacksboro_utm(tmp):
    """jacksboro warped to UTM 17N (EPSG:32617), 90 m, bilinear, Float32
    with -32768 as nodata outside the source footprint."""
    out = os.path.join(tmp, "jacksboro_utm.tif")
    if not os.path.exists(out):
        run(["gdalwarp", "-q", "-t_srs", "EPSG:32617", "-tr", "90", "90",
             "-r", "bilinear", "-ot", "Float32", "-dstnodata", "-32768",
             JACKSBORO, out])
    return out


def jacksboro_utm16(tmp):
    """jacksboro warped to UTM 16N (EPSG:32616), 75 m, bilinear, Float32,
    cut to a rectangle inside the source footprint (no nodata): the DEM
    that GRASS and SAGA shade beside the driver."""
    out = os.path.join(tmp, "jacksboro_utm16.tif")
    if not os.path.exists(out):
        run(["gdalwarp", "-q", "-t_srs", "EPSG:32616", "-te", "732000", "4037700",
             "760800", "4068000", "-tr", "75", "75", "-r", "bilinear", "-ot", "Float32",
             JACKSBORO, out])
    return out


def utm17_grid_north(lon, lat, dlat):
    """The azimuth (degrees clockwise from UTM 17N's grid north) of true
    north at (lon, lat): the grid bearing from there to dlat degrees
    north."""
    wgs, utm = osr.SpatialReference(), osr.SpatialReference()
    wgs.ImportFromEPSG(4326)
    utm.ImportFromEPSG(32617)
    for s in (wgs, utm):
        s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    ct = osr.CoordinateTransformation(wgs, utm)
    x0, y0, _ = ct.TransformPoint(lon, lat)
    x1, y1, _ = ct.TransformPoint(lon, lat + dlat)
    return math.degrees(math.atan2(x1 - x0, y1 - y0))


class TempDir:
    """with TempDir() as d: ...  (removed afterwards)"""

    def __enter__(self):
        self.path = tempfile.mkdtemp(prefix="tsdriver-")
        return self.path

    def __exit__(self, *exc):
        shutil.rmtree(self.path, ignore_errors=True)


class TempDirCase(unittest.TestCase):
    """A test class whose tests share a TempDir, self.dir, removed once the
    last of them has run."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.addClassCleanup(cls.tmp.__exit__, None, None, None)


def describe(name, a, b):
    """One line comparing two arrays, for the test output."""
    d = np.abs(a - b)
    both = ~np.isnan(a) & ~np.isnan(b)
    return "%s: max |diff| %.3g over %d cells, nodata masks %s" % (
        name, np.nanmax(d[both]) if both.any() else 0.0, both.sum(),
        "equal" if np.array_equal(np.isnan(a), np.isnan(b)) else "DIFFER")
