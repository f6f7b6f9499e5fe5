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
- the result does not depend on the option; a bad value is an error.
"""
import os
import pty
import re
import subprocess
import unittest

import tsdriver as T
from tsdriver import np

UTM_GT = (600000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
LINE = re.compile(r"TERRASHADE: computing (\w+) of (\d+) x (\d+) cells: "
                  r"0((?:\.\.\.\d+)+) - done in [\d.]+ s\.")
CHUNK_LINE = re.compile(r"TERRASHADE: computing (\w+) of chunk (\d+) of (\d+) "
                        r"\((\d+) x (\d+) cells from column (\d+), row (\d+)\): "
                        r"0((?:\.\.\.\d+)+) - done in [\d.]+ s\.")
DAY = {"DATE": "2026-06-21", "TIMEZONE": "-04:00"}


class Progress(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.dem = T.write_tif(os.path.join(cls.dir, "fractal.tif"),
                              T.fractal_dem(200, seed=3), UTM_GT, 32617)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

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


if __name__ == "__main__":
    unittest.main(verbosity=2)
