"""Against a peer: SAGA GIS (Debian 12's saga 8.5, `saga_cmd ta_lighting`),
where its definitions match ours (docs/driver.md, the svf and openness
products).

- SAGA's "Sky View Factor" (tool 3, its SVF output) is the cosine-weighted
  sky with the horizon raised to at least 0: our `sky` product, within
  0.01 at the median and 0.02 at p95 (measured 0.003 and 0.010), and on an
  open 30 degree plane both give (1 + cos 30)/2 within 0.005.
- SAGA's Topographic Openness (tool 5, degrees, from the zenith) is
  Yokoyama's, as ours; its nearest-cell steps read 0.7-0.8 degrees lower
  than our exact horizons: the median difference lies within 0 and 1.5
  degrees, the correlation above 0.99.
"""
import os
import unittest

import numpy as np

import tsdriver as T

EPSG = 32616
RADIUS = 1500
DIRECTIONS = 32
MARGIN = 21  # cells: beyond SAGA's radius of 20 cells from the edge


class Saga(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.dem = T.jacksboro_utm16(cls.dir)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def saga(self, dem, tool, outputs, args):
        """saga_cmd ta_lighting TOOL on dem; {output name: array}."""
        grid = os.path.splitext(dem)[0] + ".sgrd"
        T.run(["saga_cmd", "io_gdal", "0", "-GRIDS", grid, "-FILES", dem])
        files = {o: os.path.join(self.dir, "saga_%s_%s.sgrd" % (tool, o)) for o in outputs}
        cmd = ["saga_cmd", "ta_lighting", str(tool), "-DEM", grid] + list(args)
        for o, f in files.items():
            cmd += ["-" + o, f]
        T.run(cmd)
        return {o: T.read(f[:-5] + ".sdat", band=1) for o, f in files.items()}

    def ours(self, dem, options):
        out = os.path.join(self.dir, "ours.tif")
        options = dict(options, DIRECTIONS=DIRECTIONS, MAX_DISTANCE=RADIUS, CURVATURE="NO",
                       EDGE="open", OUTPUT_TYPE="Float32", PROGRESS="no")
        return T.read(T.translate(dem, out, options), band=1)

    def differences(self, ours, theirs):
        inner = (slice(MARGIN, -MARGIN), slice(MARGIN, -MARGIN))
        a, b = ours[inner], theirs[inner]
        ok = np.isfinite(a) & np.isfinite(b)
        self.assertGreater(ok.sum(), 100000)
        return a[ok] - b[ok], np.corrcoef(a[ok], b[ok])[0, 1]

    def test_sky_is_sagas_sky_view_factor(self):
        theirs = self.saga(self.dem, 3, ["SVF"], ["-RADIUS", str(RADIUS), "-NDIRS",
                                                  str(DIRECTIONS), "-METHOD", "0"])["SVF"]
        d, corr = self.differences(self.ours(self.dem, {"PRODUCT": "sky"}), theirs)
        print("sky - SAGA SVF: median |d| %.4f, p95 %.4f, correlation %.4f" % (
            np.median(np.abs(d)), np.percentile(np.abs(d), 95), corr))
        self.assertLess(np.median(np.abs(d)), 0.01)
        self.assertLess(np.percentile(np.abs(d), 95), 0.02)
        self.assertGreater(corr, 0.99)
        # an open plane of 30 degrees: (1 + cos 30) / 2 in both
        n, cell = 81, 30.0
        yy, xx = np.mgrid[0:n, 0:n]
        plane = T.write_tif(os.path.join(self.dir, "plane30.tif"),
                            (2000 - np.tan(np.radians(30)) * xx * cell).astype(np.float32),
                            (500000, cell, 0, 4000000, 0, -cell), EPSG)
        want = (1 + np.cos(np.radians(30))) / 2
        theirs = self.saga(plane, 3, ["SVF"], ["-RADIUS", str(RADIUS), "-NDIRS",
                                               str(DIRECTIONS), "-METHOD", "0"])["SVF"]
        ours = self.ours(plane, {"PRODUCT": "sky"})
        self.assertAlmostEqual(ours[n // 2, n // 2], want, delta=0.005)
        self.assertAlmostEqual(theirs[n // 2, n // 2], want, delta=0.005)

    def test_openness(self):
        theirs = self.saga(self.dem, 5, ["POS", "NEG"], [
            "-RADIUS", str(RADIUS), "-NDIRS", str(DIRECTIONS), "-METHOD", "1", "-UNIT", "1",
            "-NADIR", "1"])
        for kind, output in (("positive", "POS"), ("negative", "NEG")):
            d, corr = self.differences(
                self.ours(self.dem, {"PRODUCT": "openness", "OPENNESS": kind}), theirs[output])
            print("%s openness - SAGA: median %.3f, p95 |d| %.3f, correlation %.4f" % (
                kind, np.median(d), np.percentile(np.abs(d), 95), corr))
            with self.subTest(openness=kind):
                self.assertTrue(0 < np.median(d) < 1.5, np.median(d))
                self.assertLess(np.percentile(np.abs(d), 95), 3)
                self.assertGreater(corr, 0.99)


if __name__ == "__main__":
    unittest.main(verbosity=2)
