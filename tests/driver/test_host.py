"""The driver as a guest in its host's process (QGIS, a Python script, a C
program): what the host does around it must not break it, and what it
does must not change the host (session 55's audit of host processes).

Each case runs in a child process, so that a crash or a hang fails the
test (T.run, with a timeout) rather than the suite.
"""
import os
import unittest

import tsdriver as T
from tsdriver import gdal

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)

DESTROY_WITH_OPEN = """
import ctypes, os, sys
from osgeo import gdal
gdal.UseExceptions()
name, options, reads = sys.argv[1], sys.argv[3:], sys.argv[2]
ds = gdal.OpenEx(name, gdal.OF_RASTER, open_options=options)
band = ds.GetRasterBand(1)
if 'block' in reads:
    band.ReadRaster(0, 0, 1, 1)
if 'overview' in reads and band.GetOverviewCount():
    band.GetOverview(0).ReadRaster(0, 0, 1, 1)
    print('overview read')
sys.stdout.flush()
ctypes.CDLL('libgdal.so.32').GDALDestroyDriverManager()
print('destroyed', flush=True)
os._exit(0)
"""

FLOATING_POINT = """
import ctypes, ctypes.util, hashlib, sys
from osgeo import gdal
gdal.UseExceptions()
libm = ctypes.CDLL(ctypes.util.find_library('m'))
FE_INVALID, FE_DIVBYZERO, FE_UPWARD, FE_ALL = 0x01, 0x04, 0x800, 0x3d
mode, name, options = sys.argv[1], sys.argv[2], sys.argv[3:]
if mode == 'traps':
    libm.feenableexcept(FE_INVALID | FE_DIVBYZERO)
elif mode == 'upward':
    libm.fesetround(FE_UPWARD)
libm.feclearexcept(FE_ALL)
ds = gdal.OpenEx(name, gdal.OF_RASTER, open_options=options)
data = ds.GetRasterBand(1).ReadAsArray().tobytes()
ds = None
print(hashlib.md5(data).hexdigest(), libm.fegetexcept(), libm.fegetround(),
      libm.fetestexcept(FE_INVALID | FE_DIVBYZERO))
"""

SIGNALS = """
import ctypes, sys, threading
from osgeo import gdal
gdal.UseExceptions()
libc = ctypes.CDLL(None)
class SigAction(ctypes.Structure):  # glibc's struct sigaction on Linux
    _fields_ = [('handler', ctypes.c_void_p), ('mask', ctypes.c_ulong * 16),
                ('flags', ctypes.c_int), ('restorer', ctypes.c_void_p)]
def handlers():
    out = {}
    for sig in range(1, 32):
        act = SigAction()
        if libc.sigaction(sig, None, ctypes.byref(act)) == 0:
            out[sig] = (act.handler, act.flags & ~0x04000000)  # (SA_RESTORER: glibc's)
    return out
def open_and_read(options):
    ds = gdal.OpenEx(sys.argv[1], gdal.OF_RASTER, open_options=options)
    ds.GetMetadata()
    ds.GetRasterBand(1).ReadRaster(0, 0, 8, 8)
    ds = None
if sys.argv[2] == 'preloaded':  # the host had LLVM already (Mesa's llvmpipe in QGIS)
    ctypes.CDLL('libLLVM-15.so.1')
before = handlers()
if sys.argv[2] == 'threads':  # four threads start OpenCL at once
    barrier = threading.Barrier(4)
    def work():
        barrier.wait()
        open_and_read(['PRODUCT=svf', 'BACKEND=opencl', 'DIRECTIONS=8'])
    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
else:
    for options in ([], ['PRODUCT=svf', 'BACKEND=opencl']):
        open_and_read(options)
after = handlers()
print('changed', sorted(sig for sig in before if before[sig] != after[sig]))
"""

FORK = """
import os, sys, time
from osgeo import gdal
gdal.UseExceptions()
def read(options):
    ds = gdal.OpenEx(sys.argv[1], gdal.OF_RASTER, open_options=options)
    out = ds.GetRasterBand(1).ReadRaster()
    ds = None
    return out
want = read(['PRODUCT=svf', 'BACKEND=opencl'])
pid = os.fork()
if pid == 0:
    ok = all(read(options) == want for options in (['PRODUCT=svf', 'BACKEND=opencl'],
                                                   ['PRODUCT=svf']))
    os._exit(0 if ok else 3)
start = time.time()
while time.time() - start < 60:
    done, status = os.waitpid(pid, os.WNOHANG)
    if done:
        print('child', os.waitstatus_to_exitcode(status))
        break
    time.sleep(0.1)
else:
    os.kill(pid, 9)
    print('child hung')
"""

SERVER = """
import http.server, re, sys, threading
from osgeo import gdal
gdal.UseExceptions()
data = open(sys.argv[1], 'rb').read()
sent = [0]
class Handler(http.server.BaseHTTPRequestHandler):
    # dem.tif to a client that sends X-Token: sesame (the caller's
    # GDAL_HTTP_HEADERS, which the product's reads must carry), 403 to
    # others; 404 for other names
    def log_message(self, *args):
        pass
    def allowed(self):
        if self.path != '/dem.tif':
            code = 404
        elif self.headers.get('X-Token') != 'sesame':
            code = 403
        else:
            return True
        self.send_response(code)
        self.send_header('Content-Length', '0')
        self.end_headers()
        return False
    def do_HEAD(self):
        if self.allowed():
            self.send_response(200)
            self.send_header('Content-Length', str(len(data)))
            self.send_header('Accept-Ranges', 'bytes')
            self.end_headers()
    def do_GET(self):
        if not self.allowed():
            return
        m = re.match(r'bytes=(\\d+)-(\\d*)', self.headers.get('Range', 'bytes=0-'))
        a, b = int(m.group(1)), min(int(m.group(2) or len(data) - 1), len(data) - 1)
        self.send_response(206)
        self.send_header('Content-Range', 'bytes %d-%d/%d' % (a, b, len(data)))
        self.send_header('Content-Length', str(b - a + 1))
        self.end_headers()
        self.wfile.write(data[a:b + 1])
        sent[0] += b - a + 1
server = http.server.ThreadingHTTPServer(('127.0.0.1', 0), Handler)
threading.Thread(target=server.serve_forever, daemon=True).start()
gdal.SetConfigOption('GDAL_DISABLE_READDIR_ON_OPEN', 'EMPTY_DIR')
url = '/vsicurl/http://127.0.0.1:%d/dem.tif' % server.server_address[1]
"""

THREAD_LOCAL = """
import sys
from osgeo import gdal
said = []
gdal.PushErrorHandler(lambda level, number, message: said.append(message))
gdal.SetThreadLocalConfigOption('CPL_DEBUG', 'TERRASHADE')
ds = gdal.OpenEx(sys.argv[1], gdal.OF_RASTER)
ds.GetMetadata()  # (as gdal_translate and QGIS do first: the read-ahead starts)
ds.GetRasterBand(1).Checksum()
print('\\n'.join(said))
"""

DAMAGED = """
import sys
from osgeo import gdal
gdal.UseExceptions()
def outcome(name):
    ds = gdal.OpenEx(name, gdal.OF_RASTER)
    ds.GetMetadata()  # (as gdal_translate and QGIS do first: the read-ahead starts)
    try:
        ds.GetRasterBand(1).Checksum()
        return 'read'
    except RuntimeError as e:
        return 'failed: %s' % e
print('dem', outcome(sys.argv[1]))
print('product', outcome('TERRASHADE:' + sys.argv[1]))
"""

NETWORK_INFO = SERVER + """
gdal.SetConfigOption('GDAL_HTTP_HEADERS', 'X-Token: sesame')
gdal.Info('TERRASHADE:' + url)
print('info', sent[0], len(data))
ds = gdal.OpenEx('TERRASHADE:' + url, gdal.OF_RASTER)
print('read', ds.GetRasterBand(1).Checksum())
"""
PYTHON_VRT = """<VRTDataset rasterXSize="{w}" rasterYSize="{h}">
  <SRS>EPSG:32617</SRS>
  <GeoTransform>{gt}</GeoTransform>
  <VRTRasterBand dataType="Float32" band="1" subClass="VRTDerivedRasterBand">
    <PixelFunctionType>plus10</PixelFunctionType>
    <PixelFunctionLanguage>Python</PixelFunctionLanguage>
    <PixelFunctionCode><![CDATA[
def plus10(in_ar, out_ar, xoff, yoff, xsize, ysize, raster_xsize, raster_ysize, buf_radius,
           gt, **kwargs):
    out_ar[:] = in_ar[0] + 10
]]></PixelFunctionCode>
    <SimpleSource><SourceFilename relativeToVRT="0">{dem}</SourceFilename>
      <SourceBand>1</SourceBand></SimpleSource>
  </VRTRasterBand>
</VRTDataset>
"""

RASTERIO = """
import faulthandler, sys
import numpy as np
import rasterio
from rasterio.io import FilePath
faulthandler.dump_traceback_later(120, exit=True)  # a hang fails, with its stacks
vrt, dem = sys.argv[1], sys.argv[2]
# the pixel function two VRTs down (GDAL lists a VRT's direct sources only)
from osgeo import gdal
mid, top = vrt.replace('python.vrt', 'mid.vrt'), vrt.replace('python.vrt', 'top.vrt')
for name, source in ((mid, vrt), (top, mid)):
    built = gdal.BuildVRT(name, [source])
    built = None  # (written on closing)
# a DEM read by a Python pixel function: rasterio holds the GIL in checksum,
# statistics and close, which a read of the DEM on another thread waited for
for trial in range(3):
    for name in (vrt, top):
        with rasterio.Env(GDAL_VRT_ENABLE_PYTHON='YES'):
            with rasterio.open('TERRASHADE:' + name, PRODUCT='svf', DIRECTIONS=8) as ds:
                ds.tags()
                ds.checksum(1)
            with rasterio.open('TERRASHADE:' + name, PRODUCT='svf', DIRECTIONS=8) as ds:
                ds.tags()
                ds.statistics(1)
print('python pixel function done')
# a DEM as a Python file object (/vsipythonfilelike/), which GDAL reads
with open(dem, 'rb') as f:
    with rasterio.open('TERRASHADE:' + FilePath(f).name, PRODUCT='svf', DIRECTIONS=8) as ds:
        got = ds.read(1)
with rasterio.open('TERRASHADE:' + dem, PRODUCT='svf', DIRECTIONS=8) as ds:
    want = ds.read(1)
print('file object', np.array_equal(got, want, equal_nan=True))
# mode 'r+' writes a copy over the product on closing: refused, saying how
try:
    with rasterio.open('TERRASHADE:' + dem, 'r+', PRODUCT='svf', DIRECTIONS=8) as ds:
        ds.nodata = -1
except Exception as e:
    print('r+', 'A product is read-only' in str(e) and 'gdal_edit.py -ro' in str(e))
"""


class Host(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.dem = T.write_tif(os.path.join(cls.dir, "dem.tif"), T.fractal_dem(320, seed=4),
                              UTM_GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def test_destroy_driver_manager_with_datasets_open(self):
        """GDALDestroyDriverManager (QGIS's exitQgis, a C host's end) closes
        every open dataset in any order: a product's destructor closed its
        DEM again after GDAL had (SIGSEGV), unread, windowed or with an
        overview level read; so did an atlas opened with SHADOWS=all."""
        atlas = os.path.join(self.dir, "day.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE", "-oo", "PRODUCT=farshadow",
               "-oo", "DATE=2026-06-21", "-oo", "TIMEZONE=-04:00", "-oo", "ATLAS_STEPS=4",
               "-oo", "FAR_THRESHOLD=8", "-oo", "PROGRESS=no", T.conn(self.dem), atlas])
        cases = [(T.conn(self.dem), "none", []),
                 (T.conn(self.dem), "block", []),
                 (T.conn(self.dem), "block overview", []),
                 (T.conn(self.dem), "none", ["PRODUCT=svf", "TILE_SIZE=128"]),
                 (T.conn(self.dem), "block overview", ["PRODUCT=svf", "TILE_SIZE=128"]),
                 (atlas, "none", ["SHADOWS=all"])]
        for name, reads, options in cases:
            with self.subTest(name=name, reads=reads, options=options):
                p = T.run(["/usr/bin/python3", "-c", DESTROY_WITH_OPEN, name, reads] + options)
                self.assertIn("destroyed", p.stdout)
                if "overview" in reads:
                    self.assertIn("overview read", p.stdout)

    def test_floating_point_environment(self):
        """A host's floating-point traps (feenableexcept) made the core's
        first division by zero a SIGFPE, and another rounding mode changed
        the bits (until session 55). The driver runs with traps off and
        rounding to nearest, and gives the host back its own environment,
        with no exception flag of its own raised."""
        env_map = os.path.join(T.DATA, "envmaps", "forest.exr")
        for options in (["PRODUCT=shade", "BACKEND=c", "THREADS=1"],
                        ["PRODUCT=svf", "DIRECTIONS=8"],
                        ["PRODUCT=svf", "DIRECTIONS=8", "TILE_SIZE=128"],
                        ["PRODUCT=shade", "METHOD=sh"],
                        ["PRODUCT=sunhours", "DATE=2026-06-21", "TIMEZONE=-04:00"],
                        ["PRODUCT=envlight", "DIRECTIONS=8", "ENV_MAP=" + env_map]):
            with self.subTest(options=options):
                plain = T.run(["/usr/bin/python3", "-c", FLOATING_POINT, "plain",
                               T.conn(self.dem)] + options).stdout.split()
                for mode, traps, rounding in (("traps", "5", "0"), ("upward", "0", "2048")):
                    got = T.run(["/usr/bin/python3", "-c", FLOATING_POINT, mode,
                                 T.conn(self.dem)] + options).stdout.split()
                    self.assertEqual(got, [plain[0], traps, rounding, "0"], mode)

    def test_opencl_leaves_the_signals_alone(self):
        """PoCL's LLVM took 15 signals over for the whole process as OpenCL
        started (BACKEND=auto does, for the metadata, even for gdalinfo):
        a host's SIGUSR1 handler (Python's faulthandler) was never called,
        and SIGXFSZ no longer ignored. Until session 55; and four threads
        starting OpenCL at once left LLVM's handlers in about one run in
        six, and so did every start in a host that had loaded LLVM
        before (session 55's reviews)."""
        for how in ("one", "preloaded", "threads"):
            with self.subTest(how=how):
                for trial in range(3 if how == "threads" else 1):
                    p = T.run(["/usr/bin/python3", "-c", SIGNALS, T.conn(self.dem), how])
                    self.assertEqual(p.stdout.strip(), "changed []")

    def test_fork_after_opencl(self):
        """A child forked after its parent had set OpenCL up (multiprocessing's
        fork, a prefork server) waited for ever on the drivers' threads,
        which stayed in the parent; it now runs the C backend, with a
        warning where BACKEND=opencl asked for OpenCL."""
        p = T.run(["/usr/bin/python3", "-c", FORK, T.conn(self.dem)])
        self.assertIn("child 0", p.stdout)
        self.assertIn("OpenCL was set up in the parent of this process before the fork",
                      p.stderr)

    def test_the_dem_read_ahead_is_the_callers(self):
        """The DEM is read on a thread of the driver's while OpenCL is
        probed (GetMetadata, which gdal_translate and QGIS call first): until
        session 55 it took none of the caller's thread-local configuration
        (a /vsicurl/ DEM's headers, as GDAL 3.7's gdal.config_options sets
        them: its read failed where the caller's own succeeds), GDAL's
        messages on it bypassed the caller's error handler, and a network
        DEM was downloaded whole for gdalinfo."""
        # the caller's thread-local configuration (here CPL_DEBUG): the
        # thread's own debug line reaches the caller's handler
        said = T.run(["/usr/bin/python3", "-c", THREAD_LOCAL, T.conn(self.dem)]).stdout
        self.assertIn("read the DEM ahead, on a thread of its own", said)
        # a damaged tile of a 1024² DEM, outside the open's 256 x 256 sample
        # at the centre: the product's read fails as the DEM's does, GDAL's
        # words to the caller (until session 55 it read, a tile of zeros
        # shaded, with the decoder's error on stderr)
        big = T.write_tif(os.path.join(self.dir, "big.tif"), T.fractal_dem(1024, seed=5),
                          UTM_GT, 32617)
        tiled = os.path.join(self.dir, "tiled.tif")
        T.run(["gdal_translate", "-q", "-co", "TILED=YES", "-co", "COMPRESS=DEFLATE", big,
               tiled])
        damaged = os.path.join(self.dir, "damaged.tif")
        T.run(["gdal_translate", "-q", "-co", "TILED=YES", "-co", "BLOCKXSIZE=64", "-co",
               "BLOCKYSIZE=64", "-co", "COMPRESS=DEFLATE", big, damaged])
        ds = gdal.Open(damaged)
        offset = int(ds.GetRasterBand(1).GetMetadataItem("BLOCK_OFFSET_0_0", "TIFF"))
        ds = None
        with open(damaged, "r+b") as f:
            f.seek(offset)
            f.write(b"\0" * 8)
        p = T.run(["/usr/bin/python3", "-c", DAMAGED, damaged])
        said = dict(line.split(" ", 1) for line in p.stdout.splitlines())
        self.assertTrue(said["dem"].startswith("failed"), said)
        self.assertTrue(said["product"].startswith("failed"), said)
        self.assertNotIn("ZIPDecode", p.stderr)
        # and a DEM over the network is not read ahead: gdalinfo downloaded
        # it all (until session 55), for its metadata alone
        p = T.run(["/usr/bin/python3", "-c", NETWORK_INFO, tiled])
        sent, size = map(int, p.stdout.split("info ")[1].split()[:2])
        self.assertLess(sent, size / 2, p.stdout)  # (the open reads 256 x 256 cells)
        self.assertIn("read ", p.stdout)

    def test_rasterio_hosts(self):
        """Through rasterio (session 55's audit): a DEM whose reading runs
        Python (a VRT's Python pixel function) deadlocked in checksum,
        statistics or close after tags() in 6 of 9 runs (the DEM's
        read-ahead thread waited for the GIL that rasterio held while it
        waited for the thread); a DEM as a Python file object failed ("Read
        not implemented for /vsipythonfilelike/") where GDAL reads it, as
        the driver asked GeoTIFF for direct reads; mode 'r+' failed on
        closing with a sentence about deleting, none about read-only."""
        ds = gdal.Open(self.dem)
        vrt = os.path.join(self.dir, "python.vrt")
        with open(vrt, "w") as f:
            f.write(PYTHON_VRT.format(w=ds.RasterXSize, h=ds.RasterYSize, dem=self.dem,
                                      gt=", ".join(map(repr, ds.GetGeoTransform()))))
        ds = None
        p = T.run(["/usr/bin/python3", "-c", RASTERIO, vrt, self.dem])
        self.assertIn("python pixel function done", p.stdout)
        self.assertIn("file object True", p.stdout)
        self.assertIn("r+ True", p.stdout)


if __name__ == "__main__":
    unittest.main(verbosity=2)
