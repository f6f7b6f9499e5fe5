"""terrashade.distributed: a product computed as window tasks on
dask.distributed equals gdal_translate of the same source, bit for bit.

- a LocalCluster of 2 worker processes (--workers 2), small windows (12 of
  them, the last column and row cut), for shade (Byte) and horizon (4 bands
  of Float32): every band's bits, the georeferencing, nodata, band
  descriptions and metadata equal gdal_translate's;
- an existing cluster (--scheduler) writing a COG: the same pixels, COG layout;
  a COG's tiles are gdal_translate -of COG's, whatever the window size, with
  no GDAL warning;
- a worker process that dies on its first task (a test hook in
  terrashade/windows.py, once per run) is replaced, Dask retries the window,
  and the result is still identical;
- a window that fails (no retries allowed) fails the run: exit 1, the
  older DEST untouched, no DEST.partial;
- an existing cluster lost during the run (its scheduler killed or stopped,
  its only worker killed): one sentence, exit 3 within seconds, no DEST.partial;
- bad input (an unreachable scheduler or one that is no address, an
  unwritable destination or one that is a directory, a SOURCE the driver
  refuses, bad tile sizes): a clear message, a non-zero exit and neither
  DEST nor DEST.partial left behind.
"""
import contextlib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import textwrap
import time
import unittest

import tsdriver as T
from tsdriver import gdal, np

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
PYTHONPATH = os.path.join(T.SRCDIR, "python")
sys.path.insert(0, PYTHONPATH)
HORIZON = {"PRODUCT": "horizon", "DIRECTIONS": 4}
SHADE = {"PRODUCT": "shade", "SUN_AZIMUTH": 300, "SUN_ELEVATION": 20}
# a day product computed by the driver window by window too (chunks of 64
# with their near field and the far grid): the windows still join bit for bit
SUNHOURS = {"PRODUCT": "sunhours", "DATE": "2024-12-21", "TIMEZONE": "-05:00",
            "STEP_MINUTES": 60, "TILE_SIZE": 64}


def distributed(args, ok=True, cwd=None, **env):
    return T.run(["/usr/bin/python3", "-m", "terrashade.distributed"] + list(args),
                 ok=ok, cwd=cwd, PYTHONPATH=PYTHONPATH, **env)


# dask-worker --preload: the worker's windows never finish, so that the run
# is surely under way when the test takes its cluster away; the first that
# starts says so by creating the file $TS_TEST_TASK_STARTED.
STALLED_TASKS = """
import os, time
from terrashade import windows

def read_window(*args):
    open(os.environ["TS_TEST_TASK_STARTED"], "w").close()
    time.sleep(600)

windows.read_window = read_window
"""


class ExternalCluster:
    """A context of dask-scheduler and dask-worker processes, each in a
    session of its own so that a test can kill or stop one of them; every
    process started here (the program's runs too) is killed at its end,
    whether the test passed or not."""

    def __init__(self, directory):
        self.dir = directory
        self.file = os.path.join(directory, "scheduler.json")
        self.procs = {}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for p in self.procs.values():
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
            p.communicate(timeout=30)

    def start(self, name, args, **env):
        """A process; a run's (name "run...") stderr is piped, the others' logged."""
        with open(os.path.join(self.dir, name + ".log"), "w") as log:
            self.procs[name] = subprocess.Popen(
                [str(a) for a in args], stdout=log, start_new_session=True,
                stderr=subprocess.PIPE if name.startswith("run") else subprocess.STDOUT,
                env=T.env(PYTHONPATH=PYTHONPATH, **env))
        return self.procs[name]

    def run(self, name, args):
        return self.start(name, ["/usr/bin/python3", "-m", "terrashade.distributed"] + args)

    def start_cluster(self, preload):
        self.start("scheduler", ["dask-scheduler", "--host", "127.0.0.1", "--port", 0,
                                 "--no-dashboard", "--scheduler-file", self.file])
        self.start("worker", ["dask-worker", "--scheduler-file", self.file, "--nthreads", 1,
                              "--no-nanny", "--no-dashboard", "--preload", preload,
                              "--local-directory", self.dir],
                   TS_TEST_TASK_STARTED=os.path.join(self.dir, "started"))
        self.wait_for(lambda: os.path.exists(self.file) and os.path.getsize(self.file),
                      "the scheduler's file")
        with open(self.file) as f:
            return json.load(f)["address"]

    def wait_for(self, done, what, seconds=60):
        for _ in range(int(seconds * 20)):
            if done():
                return
            for name, p in self.procs.items():
                if p.poll() is not None:
                    raise AssertionError("%s ended (exit %s) before %s:\n%s" % (
                        name, p.returncode, what,
                        self.stderr(p) if name.startswith("run") else self.log(name)))
            time.sleep(0.05)
        raise AssertionError("no %s within %d s" % (what, seconds))

    @staticmethod
    def stderr(p, timeout=None):
        """A run's stderr, read as bytes and decoded: text mode would turn the
        progress bar's carriage returns into line ends (a blank first line
        where the bar drew once)."""
        return p.communicate(timeout=timeout)[1].decode(errors="replace")

    def log(self, name):
        with open(os.path.join(self.dir, name + ".log")) as f:
            return f.read()

    def signal(self, name, sig):
        os.killpg(self.procs[name].pid, sig)


def files_open(path):
    """In this process (run on a worker): how many descriptors hold path open."""
    fds = "/proc/self/fd"
    count = 0
    for fd in os.listdir(fds):
        try:
            count += os.path.realpath(os.readlink(os.path.join(fds, fd))) == path
        except OSError:
            pass
    return count


def bits(a):
    """The array's raw bits, so that NaN payloads and -0 compare too."""
    return a.view(np.uint8)


class Distributed(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        z = T.fractal_dem(200, seed=5)[:150]  # 200 x 150: windows of 64 are cut
        z[40:48, 100:130] = np.nan  # nodata in, nodata out
        cls.dem = T.write_tif(os.path.join(cls.dir, "dem.tif"), np.nan_to_num(z, nan=-9999),
                              UTM_GT, 32617, nodata=-9999)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def path(self, name):
        return os.path.join(self.dir, name)

    def reference(self, options, name):
        return T.translate(self.dem, self.path(name), options)

    def assert_identical(self, got, want):
        a, b = gdal.Open(got), gdal.Open(want)
        self.assertEqual((a.RasterXSize, a.RasterYSize, a.RasterCount),
                         (b.RasterXSize, b.RasterYSize, b.RasterCount))
        self.assertEqual(a.GetGeoTransform(), b.GetGeoTransform())
        self.assertEqual(a.GetProjection(), b.GetProjection())
        self.assertEqual(a.GetMetadata(), b.GetMetadata())
        for i in range(1, a.RasterCount + 1):
            ba, bb = a.GetRasterBand(i), b.GetRasterBand(i)
            self.assertEqual(ba.DataType, bb.DataType)
            self.assertEqual(str(ba.GetNoDataValue()), str(bb.GetNoDataValue()))
            self.assertEqual(ba.GetDescription(), bb.GetDescription())
            self.assertEqual(ba.GetMetadata(), bb.GetMetadata())
            self.assertEqual(ba.GetUnitType(), bb.GetUnitType())
            xa, xb = ba.ReadAsArray(), bb.ReadAsArray()
            self.assertTrue(np.array_equal(bits(xa), bits(xb)),
                            "band %d differs in %d cells" % (i, np.sum(xa != xb)))
        print("%s: %d bands of %s, identical to gdal_translate" % (
            os.path.basename(got), a.RasterCount,
            gdal.GetDataTypeName(a.GetRasterBand(1).DataType)))

    def assert_nothing_left(self, dest):
        for p in (dest, dest + ".partial", dest + ".tiles.partial"):
            self.assertFalse(os.path.exists(p), "%s was left behind" % p)

    def test_windows_and_internal_tiles(self):
        from terrashade import distributed as D, windows as W
        for width, height, tile in ((200, 150, 64), (1024, 1024, 1024), (1, 1, 16),
                                    (5000, 33, 1040)):
            cover = np.zeros((height, width), np.int32)
            for x, y, w, h in W.windows(width, height, tile):
                self.assertTrue(0 < w <= tile and 0 < h <= tile)
                cover[y:y + h, x:x + w] += 1
            self.assertTrue((cover == 1).all(), "windows of %d miss or overlap" % tile)
        # the output's tiles divide the window: a window covers whole tiles
        self.assertEqual([D.block_size(t) for t in (16, 64, 496, 512, 1024, 1040, 3072)],
                         [16, 64, 496, 512, 512, 16, 512])

    def test_local_cluster_products(self):
        for name, options in (("shade", SHADE), ("horizon", HORIZON), ("sunhours", SUNHOURS)):
            with self.subTest(product=name):
                dest = self.path("local_%s.tif" % name)
                p = distributed(["--workers", 2, "--tile-size", 64] + T.oo_args(options)
                                + [T.conn(self.dem), dest])
                self.assertIn("from 12 windows of 64 on 2 workers", p.stderr)
                self.assertIn("Completed", p.stderr)  # the Dask progress bar
                self.assertEqual(p.stdout, "")
                self.assertFalse(os.path.exists(dest + ".partial"))
                self.assertEqual(gdal.Open(dest).GetRasterBand(1).GetBlockSize(), [64, 64])
                self.assert_identical(dest, self.reference(options, "ref_%s.tif" % name))

    def test_warnings_said_once(self):
        """The driver's warnings are said once, by the client: each worker
        process of a local cluster printed its own copy on the same terminal
        (three with two workers, -q or not, until session 46)."""
        options = {"PRODUCT": "svf", "DIRECTIONS": 4, "MAX_DISTANCE": 1}
        for quiet in ([], ["-q"]):
            with self.subTest(quiet=quiet):
                dest = self.path("warned.tif")
                p = distributed(["--workers", 2, "--tile-size", 64] + quiet
                                + T.oo_args(options) + [T.conn(self.dem), dest])
                said = "Warning 1: TERRASHADE: MAX_DISTANCE=1 m is shorter than the DEM's cells"
                self.assertEqual(p.stderr.count(said), 1, p.stderr)
                self.assert_identical(dest, self.reference(options, "ref_warned.tif"))

    def test_a_script_keeps_its_own_settings(self):
        """From a script: importing the package leaves GDAL's exceptions as
        they were (it turned them on for the whole process), main() run
        twice says its warnings each time (the second said none) and gives
        SIGTERM back to the script's handler, and read_window works with
        exceptions off."""
        script = self.path("script.py")
        with open(script, "w") as f:
            f.write(textwrap.dedent('''\
                import signal, sys
                from osgeo import gdal
                gdal.DontUseExceptions()
                from terrashade import distributed as D, windows as W


                def main():  # (the workers import this file: spawn)
                    print("exceptions after import:", gdal.GetUseExceptions())
                    mine = lambda *_: None
                    signal.signal(signal.SIGTERM, mine)
                    for k in range(2):
                        rc = D.main(["--workers", "1", "--tile-size", "64", "-q", "-oo",
                                     "MAX_DISTANCE=1", "TERRASHADE:PRODUCT=svf,DIRECTIONS=4:"
                                     + sys.argv[1], sys.argv[2] + str(k) + ".tif"])
                        print("run", k, "rc", rc, file=sys.stderr)
                    print("exceptions after main:", gdal.GetUseExceptions())
                    print("SIGTERM is mine:", signal.getsignal(signal.SIGTERM) is mine)
                    w, a, said = W.read_window("TERRASHADE:PRODUCT=svf,DIRECTIONS=4:"
                                               + sys.argv[1], ["MAX_DISTANCE=1"],
                                               (0, 0, 8, 8), "r")
                    print("window", a.shape, len(said))
                    try:
                        W.read_window("TERRASHADE:" + sys.argv[1] + ".missing", [], (0, 0, 8, 8), "r")
                    except RuntimeError as e:
                        print("missing DEM raised:", "cannot open" in str(e))


                if __name__ == "__main__":
                    main()
                '''))
        p = T.run(["/usr/bin/python3", script, self.dem, self.path("script_out")],
                  PYTHONPATH=PYTHONPATH)
        print(p.stdout)
        self.assertIn("exceptions after import: 0", p.stdout)
        self.assertIn("exceptions after main: 0", p.stdout)
        self.assertIn("SIGTERM is mine: True", p.stdout)
        self.assertIn("window (1, 8, 8) 1", p.stdout)
        self.assertIn("missing DEM raised: True", p.stdout)
        said = "Warning 1: TERRASHADE: MAX_DISTANCE=1 m is shorter than the DEM's cells"
        self.assertEqual(p.stderr.count(said), 2, p.stderr)
        self.assertIn("run 1 rc 0", p.stderr)
        for k in range(2):
            self.assert_identical(self.path("script_out%d.tif" % k), self.reference(
                {"PRODUCT": "svf", "DIRECTIONS": 4, "MAX_DISTANCE": 1}, "ref_script.tif"))

    def test_inline_options_as_the_driver_reads_them(self):
        """THREADS and PROGRESS given inline are left to the user, also where
        the driver's parser allows blanks around a key: the program added
        its own THREADS=1 beside ' THREADS=2', and every task failed with
        'THREADS is given twice'."""
        from terrashade import distributed as D
        for inline in ("PRODUCT=shade,THREADS=2,progress=no",
                       "PRODUCT=shade, THREADS=2,PROGRESS =no",
                       " PRODUCT=shade ,  THREADS  =2, progress=no"):
            with self.subTest(inline):
                self.assertEqual(D.given_keys("TERRASHADE:%s:%s" % (inline, self.dem), []),
                                 {"PRODUCT", "THREADS", "PROGRESS"})
        # no inline segment: a DEM name with '=' and ',' but no identifier key
        self.assertEqual(D.given_keys("TERRASHADE:/d=1,e/dem.tif", ["threads=3"]), {"THREADS"})
        dest = self.path("inline_blanks.tif")
        distributed(["--workers", 2, "--tile-size", 64, "-q",
                     "TERRASHADE:PRODUCT=shade, THREADS=2, PROGRESS=no:" + self.dem, dest])
        self.assert_identical(dest, self.reference(
            {"PRODUCT": "shade", "THREADS": 2, "PROGRESS": "no"}, "ref_inline.tif"))

    def test_older_dest_sidecars_are_not_read_back(self):
        """An older DEST's statistics (.aux.xml) and external overviews (.ovr)
        go with it, as gdal_translate deletes them: they described the old
        product and were read back for the new one (QGIS's statistics and
        zoomed-out view: the svf's overview under a shade)."""
        dest = self.path("rewritten.tif")
        distributed(["--workers", 1, "-q", "-oo", "PRODUCT=svf", T.conn(self.dem), dest])
        T.run(["gdalinfo", "-stats", dest])  # writes dest.aux.xml
        T.run(["gdaladdo", "-q", "-ro", dest, "2"])  # writes dest.ovr
        self.assertTrue(os.path.exists(dest + ".aux.xml") and os.path.exists(dest + ".ovr"))
        shade = {"PRODUCT": "shade", "OUTPUT_TYPE": "Float32"}
        distributed(["--workers", 1, "-q"] + T.oo_args(shade) + [T.conn(self.dem), dest])
        ref = self.reference(shade, "ref_rewritten.tif")
        T.run(["gdaladdo", "-q", "-ro", ref, "2"])
        T.run(["gdalinfo", "-stats", ref])
        got, want = gdal.Open(dest), gdal.Open(ref)
        a, b = got.GetRasterBand(1), want.GetRasterBand(1)
        # (the reference's read back from its .aux.xml, to 14 digits)
        np.testing.assert_allclose(a.GetStatistics(False, True), b.GetStatistics(False, True),
                                   rtol=1e-12)
        self.assertEqual(a.GetOverviewCount(), 0)
        self.assertFalse(os.path.exists(dest + ".ovr"))

    def test_creation_options_are_the_users(self):
        """-co overrides the program's own creation options: GDAL takes the
        first of a repeated name, and the program put its own first, so
        -co BIGTIFF=YES, -co BLOCKXSIZE=... (GeoTIFF) or -co BLOCKSIZE=... (COG)
        were ignored without a word."""
        for dest, co, block in (("co.tif", ["BIGTIFF=YES", "BLOCKXSIZE=32", "BLOCKYSIZE=32",
                                            "COMPRESS=DEFLATE"], [32, 32]),
                                ("co.cog.tif", ["BIGTIFF=YES", "BLOCKSIZE=128"], [128, 128])):
            with self.subTest(dest):
                dest = self.path(dest)
                distributed(["--workers", 1, "--tile-size", 64, "-q"] + T.oo_args(SHADE)
                            + [a for c in co for a in ("-co", c)] + [T.conn(self.dem), dest])
                with open(dest, "rb") as f:
                    self.assertEqual(f.read(4), b"II+\x00", "not a BigTIFF")
                ds = gdal.Open(dest)
                self.assertEqual(ds.GetRasterBand(1).GetBlockSize(), block)
                ds = None
                self.assert_identical(dest, self.reference(SHADE, "ref_co.tif"))

    def test_dem_without_georeferencing(self):
        """A DEM with no geotransform (the driver takes its cells as 1 m,
        row 0 north, and says so): the product has none either, as
        gdal_translate writes it, not the default (0, 1, 0, 0, 0, 1), whose
        rows run south to north."""
        plain = self.path("plain.tif")
        ds = gdal.GetDriverByName("GTiff").Create(plain, 60, 40, 1, gdal.GDT_Float32)
        ds.GetRasterBand(1).WriteArray(T.fractal_dem(60, seed=2)[:40] * 0.05)
        ds = None
        dest = self.path("plain_shade.tif")
        distributed(["--workers", 1, "--tile-size", 32, "-q", T.conn(plain), dest])
        ref = T.translate(plain, self.path("ref_plain.tif"), {})
        got, want = gdal.Open(dest), gdal.Open(ref)
        self.assertIsNone(want.GetGeoTransform(can_return_null=True))
        self.assertIsNone(got.GetGeoTransform(can_return_null=True))
        got = want = None
        self.assert_identical(dest, ref)

    def test_existing_cluster_writes_cog(self):
        from dask.distributed import LocalCluster
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None, scheduler_port=0)
        try:
            dest = self.path("cluster.cog.tif")
            # inline options, as a caller that cannot pass -oo would give them
            src = "TERRASHADE:PRODUCT=horizon,DIRECTIONS=4:" + self.dem
            distributed(["--scheduler", cluster.scheduler_address, "--tile-size", 64,
                         src, dest])
        finally:
            cluster.close()
        self.assertEqual(gdal.Open(dest).GetMetadata("IMAGE_STRUCTURE").get("LAYOUT"), "COG")
        self.assert_identical(dest, self.reference(HORIZON, "ref_cog.tif"))

    def test_cog_tiles_are_the_cog_drivers(self):
        """A COG's internal tiles are the COG driver's (512, as gdal_translate
        -of COG writes them), whatever the window size: the COG is copied
        from the windows' tiled GeoTIFF, so its tiles need not be theirs. The
        program gave it the window's tiles, and GDAL warned, even with -q,
        "Warning 6: '64' is an unexpected value for BLOCKSIZE creation option
        that should be >= 128." for --tile-size 64 or less, and for sizes
        whose tiles are small (1040: tiles of 16)."""
        ref = self.path("ref_tiles.cog.tif")
        p = T.run(["gdal_translate", "-q", "-of", "COG"] + T.oo_args(SHADE)
                  + [T.conn(self.dem), ref])
        self.assertEqual(p.stderr, "")
        for tile in (64, 1040):
            with self.subTest(tile=tile):
                dest = self.path("tiles%d.cog.tif" % tile)
                p = distributed(["--workers", 1, "--tile-size", tile, "-q"] + T.oo_args(SHADE)
                                + [T.conn(self.dem), dest])
                self.assertEqual(p.stderr, "")  # no warning
                got, want = gdal.Open(dest), gdal.Open(ref)
                self.assertEqual(got.GetMetadata("IMAGE_STRUCTURE").get("LAYOUT"), "COG")
                a, b = got.GetRasterBand(1), want.GetRasterBand(1)
                self.assertEqual(a.GetBlockSize(), [512, 512])
                self.assertEqual(a.GetBlockSize(), b.GetBlockSize())
                self.assertEqual(a.GetOverviewCount(), b.GetOverviewCount())
                got = want = a = b = None
                self.assert_identical(dest, ref)

    def test_existing_cluster_reads_the_dem_of_each_run(self):
        """A worker keeps its dataset open between the tasks of a run, not
        between runs: a DEM rewritten at the same path between two runs on
        the same cluster gave the first run's product again, silently; and
        after a run the workers held its datasets (here the DEM's file) until
        the next one."""
        from dask.distributed import Client, LocalCluster
        dem = self.path("rewritten_dem.tif")
        with open(self.dem, "rb") as f, open(dem, "wb") as g:
            g.write(f.read())
        svf = {"PRODUCT": "svf", "DIRECTIONS": 8, "TILE_SIZE": 64}  # windowed: holds the DEM
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None, scheduler_port=0)
        try:
            for run in (1, 2):
                if run == 2:  # the same name, steeper terrain
                    ds = gdal.Open(dem, gdal.GA_Update)
                    band = ds.GetRasterBand(1)
                    z = band.ReadAsArray()
                    band.WriteArray(np.where(z == -9999, z, 3 * z))
                    ds = None
                dest = self.path("rerun%d.tif" % run)
                distributed(["--scheduler", cluster.scheduler_address, "--tile-size", 64,
                             "-q"] + T.oo_args(svf) + [T.conn(dem), dest])
                self.assert_identical(dest, T.translate(dem, self.path("ref_rerun%d.tif" % run),
                                                        svf))
                # the workers outlive the run, but not its datasets (their far
                # grid and cached chunks: GiB for a large horizon)
                with Client(cluster) as client:
                    held = client.run(files_open, os.path.realpath(dem))
                self.assertEqual(sorted(held.values()), [0, 0], "the DEM held after the run")
        finally:
            cluster.close()

    def test_existing_cluster_reads_the_clients_relative_dem(self):
        """A relative DEM in SOURCE is the client's file: the workers of an
        existing cluster, started elsewhere, resolved it in their own working
        directory and read another DEM of that name there, silently."""
        from dask.distributed import Client, LocalCluster
        client_dir, worker_dir = self.path("client_dir"), self.path("worker_dir")
        for d in (client_dir, worker_dir):
            os.makedirs(d, exist_ok=True)
        with open(self.dem, "rb") as f, open(os.path.join(client_dir, "rel.tif"), "wb") as g:
            g.write(f.read())
        other = os.path.join(worker_dir, "rel.tif")  # the same name, other terrain
        T.run(["gdal_translate", "-q", "-scale", "0", "1", "0", "3", "-ot", "Float32",
               self.dem, other])
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None, scheduler_port=0)
        svf = {"PRODUCT": "svf", "DIRECTIONS": 4}
        # the file inside another driver's name too (session 46: it failed,
        # 'cannot open the DEM GTIFF_DIR:1:rel.tif', on such a cluster)
        sources = {"relative.tif": "TERRASHADE:rel.tif",
                   "relative_dir.tif": "TERRASHADE:GTIFF_DIR:1:rel.tif"}
        try:
            with Client(cluster) as client:  # the workers' working directory
                client.run(os.chdir, worker_dir)
            for name, source in sources.items():
                distributed(["--scheduler", cluster.scheduler_address, "--tile-size", 64,
                             "-q"] + T.oo_args(svf) + [source, self.path(name)],
                            cwd=client_dir)
        finally:
            cluster.close()
        for name, source in sources.items():
            ref = self.path("ref_" + name)  # gdal_translate where the client runs
            T.run(["gdal_translate", "-q"] + T.oo_args(svf) + [source, ref], cwd=client_dir)
            self.assert_identical(self.path(name), ref)

    def test_cluster_without_workers(self):
        """A cluster with no worker at the start: the run waits --timeout for
        one to join (they may still be starting), then says so, exit 2
        (session 46: it failed at once, exit 1, whatever --timeout said)."""
        with ExternalCluster(self.path("")) as c:
            c.start("scheduler", ["dask-scheduler", "--host", "127.0.0.1", "--port", 0,
                                  "--no-dashboard", "--scheduler-file", c.file])
            c.wait_for(lambda: os.path.exists(c.file) and os.path.getsize(c.file),
                       "the scheduler's file")
            with open(c.file) as f:
                address = json.load(f)["address"]
            dest = self.path("no_workers.tif")
            start = time.monotonic()
            p = distributed(["--scheduler", address, "--timeout", 2, "-q",
                             T.conn(self.dem), dest], ok=False)
            took = time.monotonic() - start
            print("  no workers: exit %d after %.1f s: %s"
                  % (p.returncode, took, p.stderr.strip()))
            self.assertEqual(p.returncode, 2)
            self.assertIn("has no workers (none joined within 2 s, --timeout)", p.stderr)
            self.assertGreaterEqual(took, 2.0)
            self.assert_nothing_left(dest)

    def test_killed_worker_is_retried(self):
        flag = self.path("crashed")
        dest = self.path("retried.tif")
        distributed(["--workers", 2, "--tile-size", 64] + T.oo_args(HORIZON)
                    + [T.conn(self.dem), dest], TERRASHADE_DISTRIBUTED_CRASH_ONCE=flag)
        self.assertTrue(os.path.exists(flag), "no worker was killed")
        self.assert_identical(dest, self.reference(HORIZON, "ref_retried.tif"))

    def test_failed_window_leaves_nothing(self):
        # no retries allowed: the killed worker's window fails the run
        dest = self.path("failed.tif")
        with open(dest, "w") as f:
            f.write("an older result")
        p = distributed(["--workers", 2, "--tile-size", 64] + T.oo_args(HORIZON)
                        + [T.conn(self.dem), dest], ok=False,
                        TERRASHADE_DISTRIBUTED_CRASH_ONCE=self.path("crashed_once"),
                        DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES=0)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertRegex(p.stderr, r"terrashade.distributed: error: the window "
                         r"\(xoff, yoff, xsize, ysize\) = \(\d+, \d+, \d+, \d+\) of "
                         + re.escape(T.conn(self.dem)) + " failed: KilledWorker")
        with open(dest) as f:
            self.assertEqual(f.read(), "an older result")  # DEST untouched
        os.remove(dest)
        self.assert_nothing_left(dest)

    def test_cluster_lost_during_the_run(self):
        """The scheduler of an existing cluster killed (its connection
        closes), stopped (it answers nothing: a machine or network gone), or
        its only worker killed, while the run waits for windows: one
        sentence that says what was lost, exit 3 within seconds, the older
        DEST untouched and no DEST.partial. The program waited for ever on a
        stopped scheduler or a cluster without workers, and printed Dask's
        tracebacks (its progress bar's thread) and, ten seconds after the
        scheduler died, 'OSError: Timed out trying to connect'."""
        preload = self.path("stalled_tasks.py")
        with open(preload, "w") as f:
            f.write(STALLED_TASKS)
        for lost, sig, said in (
                ("scheduler", signal.SIGKILL,
                 "lost the Dask scheduler at {address} during the run, after 0 of 12 windows: "
                 "its connection closed"),
                ("scheduler", signal.SIGSTOP,
                 "lost the Dask scheduler at {address} during the run, after 0 of 12 windows: "
                 "it did not answer for 2 s (--timeout)"),
                ("worker", signal.SIGKILL,
                 "lost the workers of the Dask cluster at {address} during the run, after 0 "
                 "of 12 windows: the scheduler has had none for 2 s (--timeout)")):
            directory = self.path("lost_%s_%s" % (lost, sig.name))
            os.mkdir(directory)
            with self.subTest(lost=lost, signal=sig.name), ExternalCluster(directory) as cluster:
                address = cluster.start_cluster(preload)
                dest = os.path.join(directory, "out.tif")
                with open(dest, "w") as f:
                    f.write("an older result")
                # the first with Dask's progress bar, whose thread printed a traceback
                quiet = [] if lost == "scheduler" and sig == signal.SIGKILL else ["-q"]
                p = cluster.run("run", ["--scheduler", address, "--timeout", 2, "--tile-size",
                                        64] + quiet + T.oo_args(SHADE) + [T.conn(self.dem), dest])
                cluster.wait_for(lambda: os.path.exists(os.path.join(directory, "started")),
                                 "a task")
                t0 = time.time()
                cluster.signal(lost, sig)
                err = cluster.stderr(p, 60)  # a hang fails here, not in CI's limit
                took = time.time() - t0
                print("%s %s: exit %d after %.1f s" % (lost, sig.name, p.returncode, took))
                self.assertEqual(p.returncode, 3, err)
                # one sentence on a line of its own (after the bar's, whose draws
                # each start with a carriage return), no traceback
                lines = err.rstrip("\n").split("\n")
                self.assertTrue(lines[-1].startswith("terrashade.distributed: error: "
                                                     + said.format(address=address)), err)
                self.assertEqual([line for line in lines[:-1] if "% Completed" not in line],
                                 [], err)
                self.assertIn("; nothing written to %s: run the command again" % dest, err)
                # at once when its connection closes, else after --timeout (2 s) and
                # up to a second between checks: generous bounds for a loaded machine
                self.assertLess(took, 5 if sig == signal.SIGKILL and lost == "scheduler"
                                else 10)
                with open(dest) as f:
                    self.assertEqual(f.read(), "an older result")
                os.remove(dest)
                self.assert_nothing_left(dest)
                if sig == signal.SIGSTOP:  # and at the start: not reached, as when absent
                    p = cluster.run("run_at_start", ["--scheduler", address, "--timeout", 2,
                                                     "-q", T.conn(self.dem), dest])
                    err = cluster.stderr(p, 60)
                    self.assertEqual(p.returncode, 2, err)
                    self.assertIn("cannot reach the Dask scheduler at %s within 2 s" % address,
                                  err)
                    self.assertNotIn("Traceback", err)
                    self.assert_nothing_left(dest)

    def test_unreachable_scheduler(self):
        with socket.socket() as s:  # a port nobody listens on
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        dest = self.path("unreachable.tif")
        p = distributed(["--scheduler", "tcp://127.0.0.1:%d" % port, "--timeout", 2,
                         T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("cannot reach the Dask scheduler at tcp://127.0.0.1:%d within 2 s"
                      % port, p.stderr)
        self.assert_nothing_left(dest)

    def test_malformed_scheduler_address(self):
        for address, reason in [("scheduler", "missing port number"),
                                ("bogus://host:8786", "unknown address scheme")]:
            with self.subTest(address):
                dest = self.path("malformed.tif")
                p = distributed(["--scheduler", address, "--timeout", 2, T.conn(self.dem),
                                 dest], ok=False)
                self.assertEqual(p.returncode, 2, p.stderr)
                self.assertIn("--scheduler %s is not a Dask scheduler address such as "
                              "tcp://host:8786 (%s" % (address, reason), p.stderr)
                self.assertNotIn("Traceback", p.stderr)
                self.assert_nothing_left(dest)
        # a TLS address without Dask's TLS settings: what to set, not a TypeError
        dest = self.path("tls.tif")
        p = distributed(["--scheduler", "tls://127.0.0.1:8786", "--timeout", 2,
                         T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("--scheduler tls://127.0.0.1:8786 needs Dask's TLS settings", p.stderr)
        self.assertNotIn("TypeError:", p.stderr.split("needs Dask's TLS settings")[0])
        self.assert_nothing_left(dest)

    def test_destination_is_a_directory(self):
        """Refused before any work, not when the finished result is renamed."""
        dest = self.path("adir.tif")
        os.mkdir(dest)
        try:
            p = distributed(["--workers", 1, T.conn(self.dem), dest], ok=False)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("cannot write %s: it is a directory" % dest, p.stderr)
            self.assertNotIn("Traceback", p.stderr)
            self.assertEqual(os.listdir(dest), [])
            self.assertFalse(os.path.exists(dest + ".partial"))
        finally:
            os.rmdir(dest)

    def test_partial_name_is_a_directory(self):
        """DEST.partial taken by a directory: GDAL's reason, not the cleanup's
        IsADirectoryError, and the directory is left alone."""
        dest = self.path("taken.tif")
        os.mkdir(dest + ".partial")
        try:
            p = distributed(["--workers", 1, T.conn(self.dem), dest], ok=False)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("cannot write %s.partial: " % dest, p.stderr)
            self.assertTrue(os.path.isdir(dest + ".partial"))
            self.assertFalse(os.path.exists(dest))
        finally:
            os.rmdir(dest + ".partial")

    def test_destination_is_the_dem(self):
        """DEST naming the DEM (here by another path) is refused before any
        work: the rename at the end would replace the DEM by the product."""
        with open(self.dem, "rb") as f:
            before = f.read()
        dest = os.path.join(self.dir, ".", os.path.basename(self.dem))
        p = distributed(["--workers", 1, T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn("is the DEM itself", p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        with open(self.dem, "rb") as f:
            self.assertEqual(f.read(), before)
        self.assertFalse(os.path.exists(dest + ".partial"))

    def start_signalled_run(self, dest):
        """A run of the horizon product into dest, to be signalled: in its own
        session (the shell's job control may ignore SIGINT)."""
        return subprocess.Popen(
            ["/usr/bin/python3", "-m", "terrashade.distributed", "--workers", "1",
             "--tile-size", "64", "-q"] + T.oo_args(HORIZON) + [T.conn(self.dem), dest],
            stderr=subprocess.PIPE, text=True, start_new_session=True,
            env=T.env(PYTHONPATH=PYTHONPATH),
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))

    def test_interrupted_run_leaves_nothing(self):
        """Ctrl-C (SIGINT) and SIGTERM (what timeout, Slurm, systemd or
        Kubernetes send) during a run: the partial file is removed, an older
        DEST stays as it was, exit 130 or 143. SIGTERM ended the program on
        the spot and left DEST.partial behind. At once, and 0.4 and 0.8 s
        into the cluster's start (a cluster cut short there was left to
        Dask's exit handler, which printed tracebacks)."""
        dest = self.path("interrupted.tif")
        for sig, code, said, delay in ((signal.SIGINT, 130, "interrupted", 0.0),
                                       (signal.SIGTERM, 143, "terminated", 0.0),
                                       (signal.SIGINT, 130, "interrupted", 0.4),
                                       (signal.SIGINT, 130, "interrupted", 0.8)):
            with self.subTest(said, delay=delay):
                with open(dest, "w") as f:
                    f.write("an older result")
                p = self.start_signalled_run(dest)
                for _ in range(600):  # created before the cluster starts
                    if os.path.exists(dest + ".partial") or p.poll() is not None:
                        break
                    time.sleep(0.05)
                time.sleep(delay)
                self.assertIsNone(p.poll(), "the run ended before the signal")
                p.send_signal(sig)
                err = p.communicate(timeout=120)[1]
                self.assertEqual(p.returncode, code, err)
                self.assertIn("terrashade.distributed: %s; nothing written to %s"
                              % (said, dest), err)
                # while the cluster starts: it is closed, not left to Dask's
                # exit handler (its tracebacks until session 49)
                self.assertNotIn("Traceback", err)
                with open(dest) as f:
                    self.assertEqual(f.read(), "an older result")
                os.remove(dest)
                self.assert_nothing_left(dest)

    def test_interrupt_after_dest_is_written(self):
        """Ctrl-C once DEST is in place, while the cluster closes (~0.6 s):
        DEST is the whole new product, and the message says so (until
        session 49 it said 'nothing written' over the new DEST). The signal
        goes as soon as DEST is replaced; a run that ends first exits 0."""
        dest = self.path("late.tif")
        with open(dest, "w") as f:
            f.write("an older result")
        before = os.stat(dest).st_ino
        p = self.start_signalled_run(dest)
        for _ in range(60000):
            if p.poll() is not None or os.stat(dest).st_ino != before:
                break
            time.sleep(0.002)
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
        err = p.communicate(timeout=120)[1]
        print("exit %d: %s" % (p.returncode, err.strip()))
        self.assertIn(p.returncode, (0, 130), err)
        self.assertNotIn("nothing written", err)
        if p.returncode == 130:
            self.assertIn("terrashade.distributed: interrupted while closing the cluster; "
                          "%s was written in full" % dest, err)
        ds = gdal.Open(dest)
        self.assertEqual((ds.RasterXSize, ds.RasterYSize), (200, 150))
        ds = None

    def test_python_without_gdal(self):
        """A Python that cannot import osgeo (python3 first on PATH is often
        not the system one): a sentence and exit 1, even for --help."""
        blocked = ("import sys, runpy; sys.modules['osgeo'] = None; "
                   "sys.argv[0] = 'terrashade.distributed'; "
                   "runpy.run_module('terrashade.distributed', run_name='__main__')")
        for args in (["--help"], [T.conn(self.dem), self.path("nogdal.tif")]):
            with self.subTest(args[0]):
                p = T.run(["/usr/bin/python3", "-c", blocked] + args, ok=False,
                          PYTHONPATH=PYTHONPATH)
                self.assertEqual(p.returncode, 1, p.stderr)
                self.assertIn("terrashade.distributed: error: this Python", p.stderr)
                self.assertIn("cannot import GDAL's bindings", p.stderr)
                self.assertNotIn("Traceback", p.stderr)
        self.assert_nothing_left(self.path("nogdal.tif"))

    def test_bad_input(self):
        missing_dir = self.path("no/such/dir/out.tif")
        cases = [
            ("unwritable destination", [T.conn(self.dem)],
             "cannot write %s.partial" % missing_dir, missing_dir),
            ("driver refuses SOURCE", ["-oo", "PRODUCT=hillshade", T.conn(self.dem)],
             "PRODUCT must be one of", None),
            ("missing DEM", [T.conn(self.path("nodem.tif"))],
             "cannot open the DEM", None),
            ("not a TERRASHADE source", [self.dem],
             "SOURCE must be a TERRASHADE connection string", None),
            ("tile size not a multiple of 16", ["--tile-size", 100, T.conn(self.dem)],
             "must be a multiple of 16 between 16 and 65536 (GeoTIFF tiles are "
             "multiples of 16), got 100", None),
            ("tile size 0", ["--tile-size", 0, T.conn(self.dem)],
             "must be a multiple of 16", None),
            ("tile size not a number", ["--tile-size", "big", T.conn(self.dem)],
             "must be a whole number, got 'big'", None),
            ("unknown format", [T.conn(self.dem)], "cannot tell the format", "out.png"),
            # renamed into place at the end: a /vsi path failed only then, after
            # all the work (/vsimem/), or left an empty archive (/vsizip/)
            ("virtual DEST in memory", [T.conn(self.dem)],
             "cannot write /vsimem/out.tif: DEST must be a file path", "/vsimem/out.tif"),
            ("virtual DEST in a zip", [T.conn(self.dem)],
             "DEST must be a file path", "/vsizip/" + self.path("out.zip") + "/out.tif"),
        ]
        for what, args, message, dest in cases:
            with self.subTest(what):
                if not (dest and os.path.isabs(dest)):
                    dest = self.path(dest or "bad.tif")
                p = distributed(["--workers", 1] + args + [dest], ok=False)
                self.assertIn(message, p.stderr)
                self.assertNotIn("Traceback", p.stderr)
                self.assert_nothing_left(dest)
        self.assertFalse(os.path.exists(self.path("out.zip")), "an archive was left behind")


if __name__ == "__main__":
    unittest.main(verbosity=2)
