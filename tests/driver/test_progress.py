"""Progress of the computation on stderr (PROGRESS=auto|yes|no).

The product is computed inside GDAL's first block read, where GDAL passes no
progress callback, so the driver prints its own line to stderr:
"TERRASHADE: computing svf of 200 x 200 cells: 0...10...100 - done in 0.1 s."

- yes: the line, for every product family (horizon sweeps, sky terms, day
  steps, atlas maps), ending at 100, numbers in order;
- no, and auto with stderr not a terminal: nothing;
- auto with stderr a terminal: the line, once the work has taken
  TERRASHADE_PROGRESS_AFTER seconds (default 1; 0 here, so that the test
  does not depend on the machine's speed);
- windowed (TILE_SIZE): a line per chunk, each computed inside a block read:
  "TERRASHADE: computing svf of chunk 2 of 4 (100 x 100 cells from column
  100, row 0): 0...100 - done in 0.1 s.";
- the result does not depend on the option; a bad value is an error;
- a read with a progress callback of its own (RasterIO's extra argument:
  ReadAsArray(callback=...), gdal.Translate's) tells it the fraction
  computed, and the computation stops when it returns 0: the read fails
  at once with CPLE_UserInterrupt, nothing of it is kept, and the next
  read computes the product again (whole DEM, chunk by chunk, block reads).
"""
import os
import pty
import re
import subprocess
import time
import unittest

import tsdriver as T
from tsdriver import gdal, np

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
LINE = re.compile(r"TERRASHADE: computing (\w+) of (\d+) x (\d+) cells: "
                  r"0((?:\.\.\.\d+)+) - done in [\d.]+ s\.")
CHUNK_LINE = re.compile(r"TERRASHADE: computing (\w+) of chunk (\d+) of (\d+) "
                        r"\((\d+) x (\d+) cells from column (\d+), row (\d+)\): "
                        r"0((?:\.\.\.\d+)+) - done in [\d.]+ s\.")
DAY = {"DATE": "2026-06-21", "TIMEZONE": "-04:00"}


class FractalCase(unittest.TestCase):
    """Tests on a SIDE x SIDE fractal DEM (seed SEED) in a temporary
    directory, cls.dem in cls.dir."""
    SIDE, SEED = 200, 3

    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.dem = T.write_tif(os.path.join(cls.dir, "fractal.tif"),
                              T.fractal_dem(cls.SIDE, seed=cls.SEED), UTM_GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)


class Progress(FractalCase):

    def translate(self, options, dem=None):
        out = os.path.join(self.dir, "out.tif")
        p = T.run(["gdal_translate", "-q"] + T.oo_args(options) +
                  [T.conn(dem or self.dem), out])
        return p.stderr, out

    def expect_line(self, stderr, product):
        m = LINE.search(stderr)
        self.assertIsNotNone(m, "no progress line in %r" % stderr)
        self.assertEqual(m.group(1), product)
        self.assertEqual((m.group(2), m.group(3)), ("200", "200"))
        numbers = [int(v) for v in m.group(4).split("...")[1:]]
        self.assertEqual(numbers, list(range(10, 101, 10)))

    def test_yes_for_every_product_family(self):
        cases = [
            ("horizon", {"DIRECTIONS": 8}),
            ("svf", {"DIRECTIONS": 8}),
            ("shade", {"SKY_WEIGHT": 0.3, "DIRECTIONS": 4}),
            ("sunhours", dict(DAY, STEP_MINUTES=30)),
            ("insolation", dict(DAY, STEP_MINUTES=60, DIRECTIONS=4)),
            ("daycycle", dict(DAY, STEP_MINUTES=120)),
            ("farshadow", dict(DAY, ATLAS_STEPS=6, FAR_THRESHOLD=20)),
        ]
        for product, extra in cases:
            with self.subTest(product=product):
                err, _ = self.translate(dict(extra, PRODUCT=product, PROGRESS="yes"))
                print(err.strip())
                self.expect_line(err, product)
        # with OpenCL forced (PoCL here), the same line
        err, _ = self.translate({"PRODUCT": "horizon", "DIRECTIONS": 8,
                                 "BACKEND": "opencl", "PROGRESS": "yes"})
        self.expect_line(err, "horizon")

    def test_no_and_auto_without_a_terminal(self):
        for mode in ("no", "auto"):
            p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo", "DIRECTIONS=8",
                       "-oo", "PROGRESS=" + mode, T.conn(self.dem),
                       os.path.join(self.dir, "quiet.tif")], TERRASHADE_PROGRESS_AFTER=0)
            self.assertNotIn("computing", p.stderr, mode)

    def test_auto_on_a_terminal(self):
        """stderr on a pseudo-terminal: the line comes (after 0 s)."""
        out = os.path.join(self.dir, "tty.tif")
        master, slave = pty.openpty()
        p = subprocess.run(["gdal_translate", "-q", "-oo", "PRODUCT=horizon",
                            "-oo", "DIRECTIONS=8", T.conn(self.dem), out],
                           stdout=subprocess.DEVNULL, stderr=slave,
                           env=T.env(TERRASHADE_PROGRESS_AFTER=0), timeout=600)
        os.close(slave)
        text = b""
        while True:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # the other end is closed
                break
            if not chunk:
                break
            text += chunk
        os.close(master)
        text = text.decode()
        print(text.strip())
        self.assertEqual(p.returncode, 0)
        m = LINE.search(text)
        self.assertIsNotNone(m, "no progress line on the terminal: %r" % text)
        self.assertTrue(m.group(4).endswith("...100"))

    def test_windows_a_line_per_chunk(self):
        """TILE_SIZE=100 on 200 x 200 cells: four chunks, a line each (the
        first also sweeps the far field); nothing without a terminal under
        auto; the same product either way."""
        opts = {"PRODUCT": "svf", "DIRECTIONS": 8, "TILE_SIZE": 100}
        err, a = self.translate(dict(opts, PROGRESS="yes"))
        print(err.strip())
        lines = CHUNK_LINE.findall(err)
        self.assertEqual(len(lines), 4, err)
        seen = set()
        for product, k, n, w, h, x0, y0, ticks in lines:
            self.assertEqual((product, n, w, h), ("svf", "4", "100", "100"))
            # chunk k is the k-th in row-major order of the 2 x 2 chunks
            self.assertEqual(int(k) - 1, int(y0) // 100 * 2 + int(x0) // 100)
            self.assertEqual([int(v) for v in ticks.split("...")[1:]], list(range(10, 101, 10)))
            seen.add(int(k))
        self.assertEqual(seen, {1, 2, 3, 4})
        p = T.run(["gdal_translate", "-q"] + T.oo_args(dict(opts, PROGRESS="auto")) +
                  [T.conn(self.dem), os.path.join(self.dir, "quiet_w.tif")],
                  TERRASHADE_PROGRESS_AFTER=0)
        self.assertNotIn("computing", p.stderr)
        np.testing.assert_array_equal(T.read(a), T.read(os.path.join(self.dir, "quiet_w.tif")))

    def test_same_result_and_bad_value(self):
        _, a = self.translate({"PRODUCT": "svf", "DIRECTIONS": 8, "PROGRESS": "yes"})
        ra = T.read(a)
        _, b = self.translate({"PRODUCT": "svf", "DIRECTIONS": 8, "PROGRESS": "no"})
        np.testing.assert_array_equal(ra, T.read(b))
        p = T.run(["gdal_translate", "-q", "-oo", "PROGRESS=sometimes", T.conn(self.dem),
                   os.path.join(self.dir, "bad.tif")], ok=False)
        print(p.stderr.strip())
        self.assertIn("PROGRESS", p.stderr)


class Stopper:
    """A RasterIO progress callback: keeps what it was told, and returns 0
    (stop) from its call `stop_at` on, or from the first that says
    `stop_from` or more (never if both are None)."""

    def __init__(self, stop_at=None, stop_from=None):
        self.stop_at, self.stop_from = stop_at, stop_from
        self.calls, self.told = 0, []

    def __call__(self, done, _message, _data):
        self.calls += 1
        self.told.append(done)
        if self.stop_from is not None:
            return 0 if done >= self.stop_from else 1
        return 0 if self.stop_at is not None and self.calls >= self.stop_at else 1


class CallerCancel(FractalCase):
    """The caller's progress callback stops the computation."""
    SIDE, SEED = 1024, 5  # svf with 32 directions takes a second or two

    def open(self, **opts):
        return gdal.OpenEx(T.conn(self.dem), open_options=["%s=%s" % kv for kv in opts.items()])

    def assertCancelled(self, read, errno=gdal.CPLE_UserInterrupt):
        """read() fails with the driver's cancel (the last error number
        CPLE_UserInterrupt unless errno is None); returns how long it
        took."""
        t = time.monotonic()
        with self.assertRaises(RuntimeError) as e:
            read()
        took = time.monotonic() - t
        print("cancelled in %.2f s: %s" % (took, e.exception))
        self.assertIn("was cancelled by the caller's progress callback", str(e.exception))
        if errno is not None:
            self.assertEqual(gdal.GetLastErrorNo(), errno)
        return took

    def test_whole_product(self):
        svf = dict(PRODUCT="svf", DIRECTIONS=32, PROGRESS="no")
        ds = self.open(**svf)
        counting = Stopper()
        t = time.monotonic()
        ref = ds.GetRasterBand(1).ReadAsArray(callback=counting)
        full = time.monotonic() - t
        print("uncancelled: %.2f s, %d calls of the callback" % (full, counting.calls))
        self.assertGreaterEqual(counting.calls, 32)  # an azimuth each, and GDAL's
        ds = None
        # the straight copy (DirectRead) and a read through the blocks (Float64)
        for buf_type in (None, gdal.GDT_Float64):
            with self.subTest(buf_type=buf_type):
                ds = self.open(**svf)
                b = ds.GetRasterBand(1)
                stop = Stopper(stop_at=3)
                took = self.assertCancelled(
                    lambda: b.ReadAsArray(buf_type=buf_type, callback=stop))
                self.assertEqual(stop.calls, 3)  # no call after the stop
                self.assertLess(took, 0.5 * full)
                # the next read, without a callback, computes it all again
                np.testing.assert_array_equal(b.ReadAsArray(), ref)
                ds = None
        # block reads (IReadBlock) after a cancel
        ds = self.open(**svf)
        b = ds.GetRasterBand(1)
        self.assertCancelled(lambda: b.ReadAsArray(callback=Stopper(stop_at=2)))
        block = np.frombuffer(b.ReadBlock(1, 2), dtype=np.float32).reshape(256, 256)
        np.testing.assert_array_equal(block, ref[512:768, 256:512])

    def test_translate(self):
        """gdal.Translate hands its callback to the reads: cancelling it
        stops the computation, and writes no file."""
        ds = self.open(PRODUCT="svf", DIRECTIONS=16, PROGRESS="no")
        out = os.path.join(self.dir, "cancelled.tif")
        # (gdal.Translate resets the error number as it cleans up)
        self.assertCancelled(lambda: gdal.Translate(out, ds, callback=Stopper(stop_at=3)),
                             errno=None)
        self.assertFalse(os.path.exists(out))

    def test_date_range_positions(self):
        """A date range's sun positions, found before its sweeps, report
        progress after each sampled day and take a cancel there (ten years
        at 1-minute steps were 16 s of silence, and a cancel waited for
        them); the bar only moves forward."""
        tiny = T.write_tif(os.path.join(self.dir, "tiny.tif"), T.fractal_dem(16, seed=7),
                           UTM_GT, 32617)
        for product in ("sunhours", "insolation"):
            with self.subTest(product=product):
                oo = ["PRODUCT=" + product, "START_DATE=2026-01-01", "END_DATE=2026-12-31",
                      "TIMEZONE=-05:00", "STEP_MINUTES=10", "DAY_INTERVAL=1", "PROGRESS=no",
                      "HORIZON_DIRECTIONS=4"]  # (the sweeps: a few reports)
                seen = []
                ds = gdal.OpenEx(T.conn(tiny), open_options=oo)
                ds.GetRasterBand(1).ReadAsArray(
                    callback=lambda done, _m, _d: seen.append(done) or 1)
                ds = None
                # (on 16 x 16 cells the sweeps are nothing beside 52 560 positions)
                early = [d for d in seen if 0 < d < 0.9]
                print("%s: %d reports, %d of them below 0.9" % (product, len(seen), len(early)))
                self.assertGreater(len(early), 50)  # (the driver passes on each 1 %)
                self.assertEqual(seen, sorted(seen))
                ds = gdal.OpenEx(T.conn(tiny), open_options=oo)
                stop = Stopper(stop_at=3)
                self.assertCancelled(lambda: ds.GetRasterBand(1).ReadAsArray(callback=stop))
                self.assertEqual(stop.calls, 3)
                ds = None

    def test_sh_pass(self):
        """METHOD=sh's SH pass after its sweeps (half the run with a swath
        of thousands, until session 47 without a report or a cancel)
        reports from 0.75 to 1 and stops where the callback asks; the bar
        only moves forward, and a cancelled product is computed whole by
        the next read."""
        small = T.write_tif(os.path.join(self.dir, "sh128.tif"), T.fractal_dem(128, seed=8),
                            UTM_GT, 32617)
        oo = ["PRODUCT=shade", "METHOD=sh", "SWATH_DIRECTIONS=360", "PROGRESS=no"]
        seen, at = [], []
        ds = gdal.OpenEx(T.conn(small), open_options=oo)
        t0 = time.monotonic()
        ref = ds.GetRasterBand(1).ReadAsArray(
            callback=lambda d, _m, _u: seen.append(d) or at.append(time.monotonic()) or 1)
        ds = None
        gaps = np.diff([t0] + at)
        print("METHOD=sh: %d reports in %.2f s, the longest gap %.2f s (at %.2f)"
              % (len(seen), at[-1] - t0, gaps.max(), seen[int(gaps.argmax())]))
        self.assertEqual(seen, sorted(seen))  # (check_sh_swath_light counts the pass's own)
        calls = []

        def stop_in_sh_pass(done, _m, _u):
            calls.append(done)
            return 0 if done > 0.8 else 1
        ds = gdal.OpenEx(T.conn(small), open_options=oo)
        self.assertCancelled(lambda: ds.GetRasterBand(1).ReadAsArray(callback=stop_in_sh_pass))
        self.assertGreater(calls[-1], 0.8)
        self.assertEqual(len([d for d in calls if d > 0.8]), 1)  # none after the stop
        np.testing.assert_array_equal(ds.GetRasterBand(1).ReadAsArray(), ref)
        ds = None

    def test_shadowmap(self):
        """METHOD=shadowmap's map and filter report in batches (until
        session 47 once, at the end: 18 s of a 2048^2 DEM at a 0.5 degree
        sun) and stop where the callback asks; the next read computes the
        same bits."""
        oo = ["PRODUCT=shade", "METHOD=shadowmap", "SUN_ELEVATION=0.5", "PROGRESS=no"]
        seen = []
        ds = gdal.OpenEx(T.conn(self.dem), open_options=oo)
        ref = ds.GetRasterBand(1).ReadAsArray(callback=lambda d, _m, _u: seen.append(d) or 1)
        ds = None
        inner = [d for d in seen if 0 < d < 1]
        print("METHOD=shadowmap: %d reports, %d between 0 and 1" % (len(seen), len(inner)))
        self.assertGreater(len(inner), 20)
        self.assertEqual(seen, sorted(seen))
        ds = gdal.OpenEx(T.conn(self.dem), open_options=oo)
        stop = Stopper(stop_at=5)
        self.assertCancelled(lambda: ds.GetRasterBand(1).ReadAsArray(callback=stop))
        self.assertEqual(stop.calls, 5)
        np.testing.assert_array_equal(ds.GetRasterBand(1).ReadAsArray(), ref)
        ds = None

    def test_windowed_progress_never_goes_back(self):
        """A windowed read's callback, told by GDAL's blocks and by each
        chunk's computation, hears one fraction that never goes back and
        ends at 1 (until session 49 it went back to 0 at each chunk: 18
        times in a ReadAsArray, 12 in a gdal.Translate), whole and in a
        window across chunks."""
        small = T.write_tif(os.path.join(self.dir, "mono.tif"),
                            T.fractal_dem(256, seed=7), UTM_GT, 32617)
        oo = ["PRODUCT=svf", "DIRECTIONS=8", "TILE_SIZE=64", "PROGRESS=no"]
        reads = (("ReadAsArray", lambda ds, cb: ds.GetRasterBand(1).ReadAsArray(callback=cb)),
                 ("a window", lambda ds, cb: ds.GetRasterBand(1).ReadAsArray(
                     40, 40, 150, 100, callback=cb)),
                 ("gdal.Translate", lambda ds, cb: gdal.Translate(
                     os.path.join(self.dir, "mono_out.tif"), ds, callback=cb)))
        for name, read in reads:
            with self.subTest(read=name):
                ds = gdal.OpenEx(T.conn(small), open_options=oo)
                told = Stopper()
                read(ds, told)
                ds = None
                print("%s: %d calls, from %.3f to %.3f" % (name, told.calls, told.told[0],
                                                           told.told[-1]))
                self.assertGreater(told.calls, 10)
                self.assertEqual(told.told, sorted(told.told))
                self.assertEqual(told.told[-1], 1.0)

    def test_chunks(self):
        """Chunk by chunk (TILE_SIZE): a chunk cancelled is computed again
        by the next read, the chunks computed before it are kept; a
        multi-band product's other bands, filled from the same chunks, keep
        no block of a cancelled read."""
        small = T.write_tif(os.path.join(self.dir, "small.tif"),
                            T.fractal_dem(256, seed=6), UTM_GT, 32617)
        # the read's fraction goes 1/n a chunk, and on (until session 49 each
        # chunk told 0 to 1 again): stopped where the chunk stop_at begins
        for opts, stop_at, chunks, band in (
                # the third of four chunks
                (dict(PRODUCT="svf", DIRECTIONS=8, TILE_SIZE=128), 3, 4, 1),
                # 16 chunks of 64 cells; a block of band 1 (the whole DEM)
                # computes them, filling the other bands' blocks in the same
                # pass (the cache holds 5): stopped at the tenth, band 2's
                # block half filled, which must not stay in GDAL's cache
                (dict(PRODUCT="horizon", DIRECTIONS=4, TILE_SIZE=64), 10, 16, 2)):
            with self.subTest(**opts):
                oo = ["%s=%s" % kv for kv in dict(opts, PROGRESS="no").items()]
                fresh = gdal.OpenEx(T.conn(small), open_options=oo)
                ref = fresh.ReadAsArray()
                fresh = None
                ds = gdal.OpenEx(T.conn(small), open_options=oo)
                stop = Stopper(stop_from=(stop_at - 1) / chunks)
                self.assertCancelled(lambda: ds.GetRasterBand(1).ReadAsArray(callback=stop))
                print("stopped at %.4f, after %d calls" % (stop.told[-1], stop.calls))
                self.assertEqual(stop.told, sorted(stop.told))
                self.assertAlmostEqual(stop.told[-1], (stop_at - 1) / chunks, places=12)
                np.testing.assert_array_equal(ds.GetRasterBand(band).ReadAsArray(),
                                              ref if ref.ndim == 2 else ref[band - 1])
                np.testing.assert_array_equal(ds.ReadAsArray(), ref)
                ds = None


class ReadFromItsOwnCallback(FractalCase):
    """A progress callback that reads the dataset being computed, on the
    computing thread (a GUI drawing a preview): that read fails with a
    sentence, and the outer read, and later ones, give the product. It hung
    the process for good (the whole product, an overview level, a day
    product) or, windowed, returned GDAL's unfilled block (garbage)."""
    SIDE, SEED = 600, 3  # an overview level

    def test_whole_overview_windowed_day(self):
        cases = [(dict(PRODUCT="svf", DIRECTIONS=8), None),
                 (dict(PRODUCT="svf", DIRECTIONS=8), 0),
                 (dict(PRODUCT="svf", DIRECTIONS=8, TILE_SIZE=128), None),
                 (dict(PRODUCT="sunhours", STEP_MINUTES=60, **DAY), None)]
        for opts, level in cases:
            with self.subTest(opts=opts, level=level):
                oo = ["%s=%s" % kv for kv in dict(opts, PROGRESS="no").items()]

                def band(ds):
                    b = ds.GetRasterBand(1)
                    return b if level is None else b.GetOverview(level)
                ref_ds = gdal.OpenEx(T.conn(self.dem), open_options=oo)
                ref = band(ref_ds).ReadAsArray()
                ds = gdal.OpenEx(T.conn(self.dem), open_options=oo)
                inner = []

                def cb(_done, _msg, _data):
                    if not inner:
                        # a read, statistics (GDAL's cache: zeros, once, and
                        # saved), and the metadata (it deadlocked)
                        for call in (lambda: band(ds).ReadAsArray(0, 0, 16, 16),
                                     lambda: band(ds).ComputeStatistics(False),
                                     lambda: band(ds).ComputeRasterMinMax(False)):
                            try:
                                inner.append(call())
                            except RuntimeError as e:
                                inner.append(str(e))
                        inner.append(ds.GetMetadata())
                    return 1
                out = band(ds).ReadAsArray(callback=cb)
                print(opts, level, [x if isinstance(x, str) else type(x) for x in inner[:3]])
                for said in inner[:3]:
                    self.assertIsInstance(said, str)
                    self.assertIn("was read from inside its own computation", said)
                self.assertIn("PRODUCT", inner[3])
                np.testing.assert_array_equal(out, ref)
                np.testing.assert_array_equal(band(ds).ReadAsArray(), ref)


if __name__ == "__main__":
    unittest.main(verbosity=2)
