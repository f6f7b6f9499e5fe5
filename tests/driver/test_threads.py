"""Threads: what docs/driver.md promises (Blocks, memory, threads).

Supported: one dataset per thread. Two threads, each with its own dataset
of the same DEM (product or atlas), read at the same moment, get exactly
the pixels a single thread gets. One dataset shared by two threads is not
recommended, but its reads take turns (GDAL 3.6's block cache of a dataset
is not thread-safe: until session 49 the second thread got a windowed
chunk's block unfilled, zeros and garbage), so they too get the single
thread's pixels.

A host's thread may have a small stack (Python's threading.stack_size, a
JVM's -Xss, ulimit -s for a tool's main thread): the driver's work and the
OpenCL drivers' probe run in 64 KiB (until session 55 METHOD=sh took 150 KB
of the caller's stack and PoCL's probe of the CPU overflowed it, SIGSEGV).
"""
import os
import resource
import subprocess
import threading
import unittest

import tsdriver as T
from tsdriver import gdal, np

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
TRIALS = 3


def read_all(name, options):
    ds = gdal.OpenEx(name, gdal.OF_RASTER, open_options=options)
    out = np.stack([ds.GetRasterBand(b).ReadAsArray()
                    for b in range(1, ds.RasterCount + 1)])
    ds = None
    return out


def at_once(task):
    """task(i, start) in two threads i = 0, 1; each calls start() (a barrier)
    just before the read to time; their results."""
    barrier = threading.Barrier(2)
    results, errors = [None, None], []

    def work(i):
        try:
            results[i] = task(i, lambda: barrier.wait(timeout=60))
        except Exception as e:  # reported by the main thread
            errors.append(e)
            barrier.abort()

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    if errors:
        raise errors[0]
    return results


def in_two_threads(name, options):
    """Both threads open their own dataset, then read it at once."""
    def task(i, start):
        ds = gdal.OpenEx(name, gdal.OF_RASTER, open_options=options)
        start()
        out = np.stack([ds.GetRasterBand(b).ReadAsArray()
                        for b in range(1, ds.RasterCount + 1)])
        ds = None
        return out
    return at_once(task)


def shared_by_two_threads(ds, windows):
    """Two threads read windows of band 1 of the same dataset at once."""
    def task(i, start):
        start()
        return ds.GetRasterBand(1).ReadAsArray(*windows[i])
    return at_once(task)


class WithADem(unittest.TestCase):
    """A 96² fractal DEM of seed SEED in a temporary directory."""
    SEED = 5

    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.dem = T.write_tif(os.path.join(cls.dir, "dem.tif"),
                              T.fractal_dem(96, seed=cls.SEED), UTM_GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)


class Threads(WithADem):

    def same_in_threads(self, name, options):
        single = read_all(name, options)
        for trial in range(TRIALS):
            for i, got in enumerate(in_two_threads(name, options)):
                with self.subTest(trial=trial, thread=i):
                    np.testing.assert_array_equal(got, single)

    def test_products_one_dataset_per_thread(self):
        for options in (["PRODUCT=shade", "SUN_ELEVATION=10", "THREADS=2"],
                        ["PRODUCT=svf", "DIRECTIONS=8", "OUTPUT_TYPE=Float32"],
                        ["PRODUCT=sunhours", "DATE=2026-06-21", "TIMEZONE=-04:00",
                         "STEP_MINUTES=60"]):
            with self.subTest(options=options):
                self.same_in_threads(T.conn(self.dem), options + ["PROGRESS=no"])

    def test_one_dataset_shared_reads_take_turns(self):
        """One windowed product read by two threads at once, the same chunk
        and overlapping windows, fresh each trial: both get the single
        thread's pixels (the second waits for the first)."""
        big = T.write_tif(os.path.join(self.dir, "big.tif"), T.fractal_dem(192, seed=8),
                          UTM_GT, 32617)
        options = ["PRODUCT=svf", "DIRECTIONS=8", "TILE_SIZE=64", "PROGRESS=no"]
        single = read_all(T.conn(big), options)[0]
        for windows in (((0, 0, 192, 192), (0, 0, 192, 192)),
                        ((0, 0, 128, 128), (32, 32, 160, 160))):
            for trial in range(TRIALS):
                ds = gdal.OpenEx(T.conn(big), gdal.OF_RASTER, open_options=options)
                got = shared_by_two_threads(ds, windows)
                ds = None
                for i, (x, y, w, h) in enumerate(windows):
                    with self.subTest(windows=windows, trial=trial, thread=i):
                        np.testing.assert_array_equal(got[i], single[y:y + h, x:x + w])

    def test_atlas_one_dataset_per_thread(self):
        atlas = os.path.join(self.dir, "day.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE", "-oo", "PRODUCT=farshadow",
               "-oo", "DATE=2026-06-21", "-oo", "TIMEZONE=-04:00", "-oo", "ATLAS_STEPS=4",
               "-oo", "FAR_THRESHOLD=8", "-oo", "PROGRESS=no", T.conn(self.dem), atlas])
        self.same_in_threads(atlas, ["SHADOWS=all"])

    def test_atlas_one_dataset_shared_reads_take_turns(self):
        """One atlas read whole by two threads at once, fresh each trial:
        both get the single thread's pixels. Until session 52 an atlas's
        reads did not take turns as a product's do, and 4 of 20 such reads
        came back with blocks unfilled (nodata among the 0/1 maps; with
        SHADOWS=all impossible values such as 2, 4, 7)."""
        dem = T.write_tif(os.path.join(self.dir, "dem256.tif"), T.fractal_dem(256, seed=3),
                          UTM_GT, 32617)
        atlas = os.path.join(self.dir, "shared.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE", "-oo", "PRODUCT=farshadow",
               "-oo", "DATE=2026-06-21", "-oo", "TIMEZONE=-04:00", "-oo", "ATLAS_STEPS=12",
               "-oo", "FAR_THRESHOLD=16", "-oo", "PROGRESS=no", T.conn(dem), atlas])
        for options in ([], ["SHADOWS=all"]):
            single = read_all(atlas, options)
            for trial in range(2 * TRIALS):
                ds = gdal.OpenEx(atlas, gdal.OF_RASTER, open_options=options)

                def task(i, start):
                    start()
                    return ds.ReadAsArray()
                got = at_once(task)
                ds = None
                for i in range(2):
                    with self.subTest(options=options, trial=trial, thread=i):
                        np.testing.assert_array_equal(got[i], single)


SMALL_STACK = 64 << 10
SMALL_STACK_OPTIONS = (["PRODUCT=svf", "DIRECTIONS=8"],  # BACKEND=auto: OpenCL's probe
                       ["PRODUCT=shade", "METHOD=sh"],
                       ["PRODUCT=envlight", "DIRECTIONS=8",
                        "ENV_MAP=" + os.path.join(T.DATA, "envmaps", "forest.exr")])

IN_A_SMALL_THREAD = """
import sys, threading
from osgeo import gdal
gdal.UseExceptions()
out = {}
def work():
    ds = gdal.OpenEx(sys.argv[1], gdal.OF_RASTER, open_options=sys.argv[3:])
    out['sum'] = repr(float(ds.GetRasterBand(1).ReadAsArray().astype('float64').sum()))
    ds = None
threading.stack_size(int(sys.argv[2]))
t = threading.Thread(target=work)
t.start()
t.join()
print(out['sum'])
"""


class SmallStacks(WithADem):
    SEED = 6

    def test_a_python_thread_of_64_kib(self):
        """Each product read on a thread of 64 KiB sums as on the main
        thread (a crash fails T.run)."""
        for options in SMALL_STACK_OPTIONS:
            with self.subTest(options=options):
                want = float(read_all(T.conn(self.dem), options)[0].astype(np.float64).sum())
                p = T.run(["/usr/bin/python3", "-c", IN_A_SMALL_THREAD, T.conn(self.dem),
                           SMALL_STACK] + options)
                self.assertEqual(float(p.stdout.split()[-1]), want)

    def test_gdal_translate_under_ulimit_s_64(self):
        """gdal_translate with a 64 KiB stack (ulimit -s 64) writes the
        product it writes with the usual 8 MiB."""
        def small_stack():
            resource.setrlimit(resource.RLIMIT_STACK, (SMALL_STACK, SMALL_STACK))
        for options in SMALL_STACK_OPTIONS:
            with self.subTest(options=options):
                want = read_all(T.conn(self.dem), options)
                out = os.path.join(self.dir, "small.tif")
                args = ["gdal_translate", "-q"] + T.oo_args(
                    dict(o.split("=", 1) for o in options)) + [T.conn(self.dem), out]
                p = subprocess.run(args, env=T.env(), capture_output=True, text=True,
                               preexec_fn=small_stack, timeout=600)
                self.assertEqual(p.returncode, 0, p.stderr)
                np.testing.assert_array_equal(read_all(out, []), want)


if __name__ == "__main__":
    unittest.main(verbosity=2)
