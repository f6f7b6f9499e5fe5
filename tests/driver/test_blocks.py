"""Blocks: 256 x 256, any read order gives the same pixels, the product is
computed once per dataset, two datasets in two threads give the same
results as one at a time, and memory stays within the documented bound."""
import os
import random
import subprocess
import threading
import time
import unittest

import tsdriver as T
from tsdriver import gdal, np

GT = (600000, 30, 0, 4000000, 0, -30)


class ComputeCounter:
    """Counts the driver's 'computing PRODUCT' debug messages."""

    def __init__(self):
        self.count = 0
        self.lock = threading.Lock()

    def __call__(self, err_class, err_no, msg):
        if err_class == gdal.CE_Debug and msg.startswith("TERRASHADE: computing"):
            with self.lock:
                self.count += 1

    def __enter__(self):
        gdal.SetConfigOption("CPL_DEBUG", "TERRASHADE")
        gdal.PushErrorHandler(self)
        return self

    def __exit__(self, *exc):
        gdal.PopErrorHandler()
        gdal.SetConfigOption("CPL_DEBUG", None)


def open_ds(dem, **options):
    return gdal.OpenEx(T.conn(dem), gdal.OF_RASTER,
                       open_options=["%s=%s" % kv for kv in options.items()])


def read_blocks(ds, order):
    """Read every block of every band in `order`, assemble the arrays."""
    W, H = ds.RasterXSize, ds.RasterYSize
    out = np.full((ds.RasterCount, H, W), np.nan)
    for b, bx, by in order:
        rb = ds.GetRasterBand(b)
        x0, y0 = bx * 256, by * 256
        w, h = min(256, W - x0), min(256, H - y0)
        out[b - 1, y0:y0 + h, x0:x0 + w] = rb.ReadAsArray(x0, y0, w, h)
    return out


class Blocks(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        z = T.fractal_dem(640, seed=11)[:600, :]   # 3 x 3 blocks, partial edges
        z[100:130, 500:560] = np.nan
        cls.dem = T.write_tif(os.path.join(cls.dir, "dem.tif"), z, GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def test_block_size(self):
        ds = open_ds(self.dem)
        self.assertEqual(ds.GetRasterBand(1).GetBlockSize(), [256, 256])

    def test_any_read_order_same_result(self):
        opts = dict(PRODUCT="horizon", DIRECTIONS=3, SUN_ELEVATION=10)
        ref = T.read(T.conn(self.dem), options=opts)
        blocks = [(b, bx, by) for b in (1, 2, 3) for by in range(3) for bx in range(3)]
        orders = {"row-major": blocks, "reversed": blocks[::-1],
                  "column-major": sorted(blocks, key=lambda t: (t[1], t[2], t[0]))}
        rnd = random.Random(5)
        for i in range(3):
            o = list(blocks)
            rnd.shuffle(o)
            orders["random %d" % i] = o
        with ComputeCounter() as counter:
            for name, order in orders.items():
                with self.subTest(order=name):
                    ds = open_ds(self.dem, **opts)
                    got = read_blocks(ds, order)
                    ds = None
                    np.testing.assert_array_equal(got, ref)
            # unaligned windows, the last one first
            ds = open_ds(self.dem, **opts)
            for x0, y0, w, h in ((600, 550, 40, 50), (0, 0, 1, 1), (100, 200, 333, 300)):
                np.testing.assert_array_equal(
                    ds.GetRasterBand(2).ReadAsArray(x0, y0, w, h),
                    ref[1, y0:y0 + h, x0:x0 + w])
            ds = None
        print("datasets opened: %d, products computed: %d" % (len(orders) + 1,
                                                             counter.count))
        self.assertEqual(counter.count, len(orders) + 1)

    def test_computed_once_per_dataset(self):
        """Every block of every band of one dataset, read twice: one
        computation; downsampled reads (twice): one more, of the overview
        level they read (docs/driver.md, Overviews)."""
        with ComputeCounter() as counter:
            ds = open_ds(self.dem, PRODUCT="horizon", DIRECTIONS=4)
            for rep in range(2):
                for b in range(1, 5):
                    ds.GetRasterBand(b).ReadAsArray()
                    ds.FlushCache()  # drop GDAL's block cache: ours stays
            ds.GetRasterBand(3).ComputeStatistics(False)
            self.assertEqual(counter.count, 1)
            for rep in range(2):
                ds.GetRasterBand(1).ReadAsArray(buf_xsize=64, buf_ysize=60)
                ds.FlushCache()
            ds = None
        print("products computed: %d" % counter.count)
        self.assertEqual(counter.count, 2)

    def test_opening_computes_nothing(self):
        with ComputeCounter() as counter:
            ds = open_ds(self.dem, PRODUCT="svf")
            ds.GetMetadata()
            ds.GetGeoTransform()
            ds = None
        self.assertEqual(counter.count, 0)

    def test_two_datasets_in_two_threads(self):
        configs = [dict(PRODUCT="shadow", SUN_ELEVATION=8),
                   dict(PRODUCT="svf", DIRECTIONS=16),
                   dict(PRODUCT="shade", SUN_AZIMUTH=100, SKY_WEIGHT=0.3),
                   dict(PRODUCT="shadow", SUN_ELEVATION=8)]  # same as the first
        sequential = [T.read(T.conn(self.dem), options=c) for c in configs]
        for first, second in ((0, 1), (2, 3), (0, 3)):
            results, errors = {}, []

            def work(i):
                try:  # (GDAL's Python bindings release the GIL while reading)
                    results[i] = T.read(T.conn(self.dem), options=configs[i])
                except Exception as e:  # reported below
                    errors.append(e)

            threads = [threading.Thread(target=work, args=(i,)) for i in (first, second)]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            self.assertEqual(errors, [])
            for i in (first, second):
                np.testing.assert_array_equal(results[i], sequential[i])

    def test_concurrent_gdal_translate(self):
        """Two gdal_translate processes at once, the same results."""
        with T.TempDir() as tmp:
            outs = [os.path.join(tmp, "a.tif"), os.path.join(tmp, "b.tif")]
            procs = [subprocess.Popen(["gdal_translate", "-q", "-oo", "PRODUCT=sky",
                                       T.conn(self.dem), o], env=T.env())
                     for o in outs]
            self.assertEqual([p.wait() for p in procs], [0, 0])
            np.testing.assert_array_equal(T.read(outs[0]), T.read(outs[1]))

    def test_memory_is_bounded(self):
        """Peak memory of gdal_translate <= the documented bound: the DEM as
        float + the product + working planes (normals, one horizon plane,
        one accumulator) + GDAL's block cache + the program itself. The sky
        products stream one direction at a time: 32 directions cost no more
        than 4."""
        with T.TempDir() as tmp:
            n = 2048
            dem = T.write_tif(os.path.join(tmp, "big.tif"), T.fractal_dem(n), GT, 32617)
            plane = n * n * 4 / 2 ** 20

            def peak(args):
                """The process's VmHWM (peak resident set), polled until it
                exits (rusage would report the parent's RSS, inherited
                through fork and exec)."""
                # the C backend's planes: BACKEND=auto would probe OpenCL,
                # whose runtime (PoCL loads LLVM, ~75 MiB) is not the driver's
                p = subprocess.Popen(args, env=T.env(GDAL_CACHEMAX=32,
                                                     TERRASHADE_BACKEND="c"))
                hwm = 0
                while p.poll() is None:
                    try:
                        with open("/proc/%d/status" % p.pid) as f:
                            for line in f:
                                if line.startswith("VmHWM:"):
                                    hwm = max(hwm, int(line.split()[1]))
                    except OSError:
                        pass
                    time.sleep(0.005)
                self.assertEqual(p.returncode, 0, args)
                self.assertGreater(hwm, 0)
                return hwm / 1024.0  # MiB

            out = os.path.join(tmp, "o.tif")
            base = peak(["gdal_translate", "-q", dem, out])
            for opts, planes in ((["PRODUCT=shade"], 1 + 1 + 4),
                                 (["PRODUCT=svf", "DIRECTIONS=4"], 1 + 1 + 4),
                                 (["PRODUCT=svf", "DIRECTIONS=32"], 1 + 1 + 4),
                                 (["PRODUCT=shadow"], 1 + 1)):
                args = ["gdal_translate", "-q"]
                for o in opts:
                    args += ["-oo", o]
                mib = peak(args + [T.conn(dem), out])
                bound = base + planes * plane + 32
                print("%-30s peak %6.0f MiB, bound %6.0f MiB (plain copy %.0f MiB, "
                      "one plane %.0f MiB)" % (" ".join(opts), mib, bound, base, plane))
                self.assertLessEqual(mib, bound)


if __name__ == "__main__":
    unittest.main(verbosity=2)
