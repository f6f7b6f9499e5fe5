"""svf (SVF_MODEL=solid_angle) and openness (positive, negative) against
RVT_py (rvt-py 2.2.3 from PyPI), the Relief Visualization Toolbox
archaeologists and lidar users know.

RVT's sky_view_factor samples n directions (2 pi k / n counter-clockwise
from east: for n a multiple of 4 the same set of azimuths as DIRECTIONS=n,
START_AZIMUTH=0), at pixel-rounded points from 1 to svf_r_max pixels, with
no Earth curvature, and pads the DEM by mirroring it. So: the same
directions, MAX_DISTANCE = svf_r_max x cell size, CURVATURE=NO, and cells
farther than svf_r_max from the DEM's edge. The venv with rvt-py is made
by tests/rvt-venv.sh in the build directory; the test fails (never skips)
when it cannot be made.
"""
import os
import subprocess
import unittest

import tsdriver as T
from tsdriver import gdal, np

N_DIR = 32
R_MAX = 20          # RVT's svf_r_max, pixels
WINDOW = 140        # cells of the projected jacksboro the test uses
GOAL_SVF = 0.01     # mean |difference|, solid-angle svf
GOAL_OPNS = 0.5     # mean |difference|, degrees, both opennesses

RVT_SCRIPT = r"""
import sys
import numpy as np
import rvt.vis
dem = np.load(sys.argv[1])
res = float(sys.argv[2])
kw = dict(resolution=res, svf_n_dir=%d, svf_r_max=%d, svf_noise=0, ve_factor=1)
pos = rvt.vis.sky_view_factor(dem=dem, compute_svf=True, compute_opns=True, **kw)
# rvt.default.DefaultValues.get_neg_opns: openness of the negated DEM
neg = rvt.vis.sky_view_factor(dem=-1 * dem, compute_svf=False, compute_opns=True, **kw)
np.savez(sys.argv[3], svf=pos["svf"], opns=pos["opns"], neg_opns=neg["opns"])
""" % (N_DIR, R_MAX)


def rvt_python():
    """The venv's python with rvt-py, made once per build directory."""
    venv = os.path.join(T.BUILDDIR, "tests", "rvt-venv")
    script = os.path.join(T.SRCDIR, "tests", "rvt-venv.sh")
    p = subprocess.run(["sh", script, venv], capture_output=True, text=True,
                       timeout=900)
    if p.returncode != 0:
        raise AssertionError("FAIL: no rvt-py for the comparison with RVT_py "
                             "(tests/rvt-venv.sh %s exited %d):\n%s"
                             % (venv, p.returncode, p.stderr))
    return p.stdout.strip().splitlines()[-1]


class AgainstRVT(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        d = cls.tmp.__enter__()
        utm = T.jacksboro_utm(d)
        ds = gdal.Open(utm)
        w, h = ds.RasterXSize, ds.RasterYSize
        ds = None
        cls.dem = os.path.join(d, "window.tif")
        T.run(["gdal_translate", "-q", "-srcwin", (w - WINDOW) // 2, (h - WINDOW) // 2,
               WINDOW, WINDOW, utm, cls.dem])
        z, gt, _ = T.read_dem(cls.dem)
        assert not np.isnan(z).any(), "the window must lie inside jacksboro's footprint"
        assert abs(gt[1]) == abs(gt[5]), "RVT wants square cells"
        cls.cell = abs(gt[1])
        np.save(os.path.join(d, "dem.npy"), z)
        script = os.path.join(d, "rvt_run.py")
        with open(script, "w") as f:
            f.write(RVT_SCRIPT)
        out = os.path.join(d, "rvt.npz")
        T.run([rvt_python(), script, os.path.join(d, "dem.npy"), cls.cell, out])
        cls.rvt = dict(np.load(out))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def ours(self, **opts):
        base = {"DIRECTIONS": N_DIR, "START_AZIMUTH": 0, "MAX_DISTANCE": R_MAX * self.cell,
                "CURVATURE": "NO", "BACKEND": "c", "OUTPUT_TYPE": "Float32"}
        base.update(opts)
        if opts["PRODUCT"] == "openness":
            del base["OUTPUT_TYPE"]
        return T.read(T.conn(self.dem), band=1, options=base)

    def agree(self, name, ours, theirs, goal):
        inner = (slice(R_MAX, -R_MAX), slice(R_MAX, -R_MAX))
        d = np.abs(ours[inner] - theirs[inner])
        self.assertFalse(np.isnan(d).any(), name)
        corr = np.corrcoef(ours[inner].ravel(), theirs[inner].ravel())[0, 1]
        print("%s vs RVT_py (%d directions, r_max %d px = %g m, %d interior cells): "
              "mean |diff| %.4g, max %.4g, bias %.4g, correlation %.4f (goal: mean <= %g)"
              % (name, N_DIR, R_MAX, R_MAX * self.cell, d.size, d.mean(), d.max(),
                 (ours[inner] - theirs[inner]).mean(), corr, goal))
        self.assertLessEqual(d.mean(), goal, name)
        return d.mean()

    def test_svf_solid_angle(self):
        svf = self.ours(PRODUCT="svf", SVF_MODEL="solid_angle")
        self.agree("svf solid_angle", svf, self.rvt["svf"], GOAL_SVF)

    def test_svf_radiative_is_not_rvts(self):
        """The default (radiative) is a different quantity: on this terrain it
        differs from RVT's by more than the solid-angle model does."""
        rad = self.ours(PRODUCT="svf")
        sol = self.ours(PRODUCT="svf", SVF_MODEL="solid_angle")
        inner = (slice(R_MAX, -R_MAX), slice(R_MAX, -R_MAX))
        d_rad = np.abs(rad - self.rvt["svf"])[inner].mean()
        d_sol = np.abs(sol - self.rvt["svf"])[inner].mean()
        print("svf radiative vs RVT_py: mean |diff| %.4g (solid_angle: %.4g)" % (d_rad, d_sol))
        self.assertGreater(d_rad, d_sol)

    def test_openness_positive(self):
        op = self.ours(PRODUCT="openness", OPENNESS="positive")
        self.agree("openness positive (deg)", op, self.rvt["opns"], GOAL_OPNS)

    def test_openness_negative(self):
        on = self.ours(PRODUCT="openness", OPENNESS="negative")
        self.agree("openness negative (deg)", on, self.rvt["neg_opns"], GOAL_OPNS)


class Options(unittest.TestCase):
    """SVF_MODEL and OPENNESS: their effect on a cone, and bad values."""

    def test_cone(self):
        """Closed forms at a cone's tip, along the grid's axes (DIRECTIONS=4:
        the sweep's lines run through the cells; on other azimuths they
        interpolate across the tip's kink)."""
        n, mid, cell, slope = 61, 30, 10.0, 25.0
        yy, xx = np.mgrid[0:n, 0:n]
        pit = (np.hypot(xx - mid, yy - mid) * cell * np.tan(np.radians(slope))).astype(np.float32)
        opts = {"DIRECTIONS": 4, "CURVATURE": "NO", "MAX_DISTANCE": 200, "BACKEND": "c"}
        with T.TempDir() as d:
            for name, z in (("pit", pit), ("peak", -pit)):
                path = T.write_tif(os.path.join(d, name + ".tif"), z,
                                   (500000, cell, 0, 4000000, 0, -cell), 32633)
                got = {}
                for key, o in (("radiative", {"PRODUCT": "svf"}),
                               ("solid", {"PRODUCT": "svf", "SVF_MODEL": "solid_angle"}),
                               ("pos", {"PRODUCT": "openness", "OPENNESS": "positive"}),
                               ("neg", {"PRODUCT": "openness", "OPENNESS": "negative"})):
                    got[key] = T.read(T.conn(path), band=1, options=dict(opts, **o))[mid, mid]
                print(name, got)
                b = slope if name == "pit" else -slope
                self.assertAlmostEqual(got["solid"], 1 - np.sin(np.radians(max(b, 0))), delta=1e-4)
                self.assertAlmostEqual(got["pos"], 90 - b, delta=1e-3)
                self.assertAlmostEqual(got["neg"], 90 + b, delta=1e-3)
                if name == "pit":
                    # radiative at the bottom of the pit: the flat-cell form 1 - mean sin^2
                    self.assertAlmostEqual(got["radiative"], 1 - np.sin(np.radians(b)) ** 2,
                                           delta=1e-4)

    def test_negative_without_curvature(self):
        """OPENNESS=negative sweeps the negated DEM without the curvature
        correction (docs/driver.md): with the default CURVATURE it is the
        positive openness of -z with CURVATURE=NO EDGE=open, on a DEM wide
        enough (15 km) for the correction to show if it were applied."""
        y, x = np.mgrid[0:512, 0:512].astype(float)
        z = 800 + 300 * np.sin(x / 37.0) * np.cos(y / 53.0) + 150 * np.sin((x + 2 * y) / 91.0)
        gt = (500000, 30.0, 0, 4000000, 0, -30.0)
        with T.TempDir() as d:
            pos = T.write_tif(os.path.join(d, "z.tif"), z.astype(np.float32), gt, 32617)
            neg = T.write_tif(os.path.join(d, "negz.tif"), (-z).astype(np.float32), gt, 32617)
            on = T.read(T.conn(pos), band=1, options={"PRODUCT": "openness", "DIRECTIONS": 16,
                                                      "OPENNESS": "negative"})
            ref = T.read(T.conn(neg), band=1, options={"PRODUCT": "openness", "DIRECTIONS": 16,
                                                       "CURVATURE": "NO", "EDGE": "open"})
        diff = np.abs(on - ref)
        print("negative openness vs positive openness of -z without curvature: max |diff| "
              "%.3g deg, mean %.3g" % (diff.max(), diff.mean()))
        self.assertFalse(np.isnan(diff).any())
        self.assertLess(diff.max(), 1e-5)

    def test_bad_values(self):
        for opt, value, sentence in (
                ("SVF_MODEL", "zaksek", "SVF_MODEL must be one of radiative, solid_angle, "
                                        "got 'zaksek'"),
                ("OPENNESS", "both", "OPENNESS must be one of positive, negative, got 'both'")):
            p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo",
                       "%s=%s" % (opt, value), T.conn(T.LUX), "/vsimem/x.tif"], ok=False)
            self.assertIn(sentence, p.stderr)
        for product, opt, sentence in (
                ("shade", "SVF_MODEL=solid_angle",
                 "SVF_MODEL=solid_angle applies to PRODUCT=svf only, not to PRODUCT=shade"),
                ("svf", "OPENNESS=negative",
                 "OPENNESS=negative applies to PRODUCT=openness only, not to PRODUCT=svf")):
            p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=" + product, "-oo", opt,
                       T.conn(T.LUX), "/vsimem/x.tif"], ok=False)
            self.assertIn(sentence, p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
