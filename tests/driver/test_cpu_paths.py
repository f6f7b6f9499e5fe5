#!/usr/bin/python3
"""The paths a CPU without AVX-512 takes, run and checked on any CPU.

The C backend's hot loops are hand-written for AVX-512, with AVX2 and
portable C paths beside them (chosen by ts_cpu_vector_level), and the
per-cell loops are compiled three times (GCC's target_clones: AVX-512, AVX2,
baseline x86-64). The development and CI machines have AVX-512, so without
this suite the paths most users' CPUs run (AVX2 laptops, older servers)
would never be run by the tests. Two ways in:

- TERRASHADE_SIMD=avx2 or none caps the hand-written paths: every product
  variant of tests/product_checksums.py (C backend, jacksboro, lux_elev and a
  512 x 512 fractal) must give the same bits at every level.
- The C suites that hold the sweeps, shadows and SH light against the
  brute-force oracle and analytic cases run again with TERRASHADE_SIMD=none.
- qemu-x86_64 (Debian's qemu-user) emulates CPUs without AVX-512: without
  any AVX (-cpu Nehalem: the baseline clones, the portable paths and glibc's
  SSE2 libm) every variant on lux_elev agrees with the native run to a few
  float ulps (OpenEXR's DWA decoder picks an AVX or an SSE2 inverse DCT by
  the CPU and decodes a few of sunset.exr's values differently: measured
  2.4e-7 on envlight with that lat-long map, every other variant the same
  bits; session 56's audit found glibc's libm, blamed before, the same);
  with AVX2 (-cpu Haswell) the AVX2 clones give the native bits.

Run from the top build directory (make check does).
"""
import os
import shutil
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tsdriver as T  # noqa: E402
from tsdriver import np  # noqa: E402

CHECKSUMS = os.path.join(T.SRCDIR, "tests", "product_checksums.py")
QEMU = shutil.which("qemu-x86_64")
# the variants the AVX2 emulation runs (TCG's AVX2 is ~5x slower than its
# SSE), chosen to reach every file with clones: the normals, shading, sky
# sums, sweeps (unbounded, bounded, far field, EDGE raises), SH key light,
# pyramid, environment light and a date range's sun positions
HASWELL_VARIANTS = ("shade,shade_sky,svf,horizon_bounded,horizon_far,sunhours,"
                    "shade_sh,svf_pyramid,envlight_map,svf_edge,sunhours_range")


def checksum_lines(*args, qemu_cpu=None, **env):
    """Run product_checksums.py (C backend) with args and env; its lines."""
    cmd = [sys.executable, CHECKSUMS, "--backends", "c"] + list(args)
    if qemu_cpu:
        cmd = [QEMU, "-cpu", qemu_cpu] + cmd
    p = T.run(cmd, cwd=T.BUILDDIR, **env)
    return [line for line in p.stdout.splitlines() if line.strip()]


def device(simd):
    """BACKEND_DEVICE of a shade dataset on jacksboro under TERRASHADE_SIMD."""
    p = T.run(["gdalinfo", "-oo", "BACKEND=c", "TERRASHADE:" + T.JACKSBORO],
              TERRASHADE_SIMD=simd)
    return [line.split("=", 1)[1] for line in p.stdout.splitlines()
            if line.strip().startswith("BACKEND_DEVICE=")][0]


class VectorLevels(unittest.TestCase):
    def test_bad_value_is_an_error(self):
        for oo in (["PRODUCT=shade"], ["PRODUCT=sunhours", "DATE=2026-06-21", "TIMEZONE=Z"]):
            p = T.run(["gdalinfo"] + [a for o in oo for a in ("-oo", o)] +
                      ["TERRASHADE:" + T.JACKSBORO], ok=False, TERRASHADE_SIMD="sse4")
            self.assertIn("TERRASHADE_SIMD must be auto, avx512, avx2 or none, got 'sse4'",
                          p.stderr)

    def test_device_names_the_level(self):
        native = device("auto")
        self.assertRegex(native, r"^CPU, \d+ cores?, (AVX-512|AVX2|portable C)$")
        self.assertTrue(device("none").endswith(", portable C"))
        capped = device("AVX2")  # any case
        self.assertTrue(capped.endswith(", AVX2") or capped.endswith(", portable C"))
        if native.endswith("AVX-512"):
            self.assertTrue(capped.endswith(", AVX2"), capped)
            self.assertEqual(device("avx512"), native)

    def test_every_level_same_bits(self):
        auto = checksum_lines(TERRASHADE_SIMD="auto")
        self.assertGreater(len(auto), 150)
        for simd in ("avx2", "none"):
            capped = checksum_lines(TERRASHADE_SIMD=simd)
            differ = [(a, b) for a, b in zip(auto, capped) if a != b]
            self.assertEqual(len(capped), len(auto))
            self.assertEqual(differ, [], "TERRASHADE_SIMD=%s" % simd)
        print("TERRASHADE_SIMD=avx2 and none: %d product variants, the same bits as auto"
              % len(auto))


class PortableOracles(unittest.TestCase):
    def test_c_suites_on_portable_paths(self):
        for suite in ("check_horizon", "check_sweep_lines", "check_analytic", "check_edge",
                      "check_shadow", "check_sh", "check_sh_swath_light"):
            p = T.run([os.path.join(T.BUILDDIR, "tests", suite)],
                      TERRASHADE_SIMD="none", CK_DEFAULT_TIMEOUT="600",
                      CK_TIMEOUT_MULTIPLIER="3")
            summary = [line for line in p.stdout.splitlines() if "Checks:" in line]
            print("TERRASHADE_SIMD=none %s: %s" % (suite, summary[-1] if summary else "?"))

    def test_shadowmap_raster_every_level(self):
        # check_shadowmap holds the C rasteriser to the portable loop's keys
        for simd in ("avx2", "none"):
            p = T.run([os.path.join(T.BUILDDIR, "tests", "check_shadowmap")],
                      TERRASHADE_SIMD=simd, CK_DEFAULT_TIMEOUT="600",
                      CK_TIMEOUT_MULTIPLIER="3")
            line = [x for x in p.stdout.splitlines() if x.startswith("rasteriser")]
            self.assertEqual(len(line), 1, p.stdout)
            print("TERRASHADE_SIMD=%s check_shadowmap: %s" % (simd, line[0]))


class EmulatedCpus(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if QEMU is None:
            raise AssertionError("qemu-x86_64 is missing: setup.sh installs qemu-user")
        cls.tmp = tempfile.mkdtemp(prefix="ts_cpu_")
        cls.native = os.path.join(cls.tmp, "native")
        checksum_lines("--dems", "lux", "--save", cls.native)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def compare(self, cpu, *args):
        """Each variant under qemu -cpu cpu against the native arrays: the
        number with the same bits, and the largest difference in float ulps
        (of the larger magnitude, at least 1)."""
        kept = os.path.join(self.tmp, cpu)
        lines = checksum_lines("--dems", "lux", "--save", kept, *args, qemu_cpu=cpu)
        same, worst = 0, (0.0, "")
        for line in lines:
            key = line.split()[0]
            a = np.load(os.path.join(kept, key + ".npy"))
            b = np.load(os.path.join(self.native, key + ".npy"))
            self.assertEqual(a.dtype, b.dtype, key)
            if a.dtype.kind == "f":
                self.assertTrue(np.array_equal(np.isnan(a), np.isnan(b)), key + ": nodata differs")
            if np.array_equal(a, b, equal_nan=a.dtype.kind == "f"):
                same += 1
                continue
            self.assertEqual(a.dtype.kind, "f", key + ": a Byte product differs")
            a64, b64 = a.astype(np.float64), b.astype(np.float64)
            scale = np.maximum(1.0, np.maximum(np.abs(a64), np.abs(b64)))
            ulps = np.nanmax(np.abs(a64 - b64) / scale) / np.finfo(np.float32).eps
            worst = max(worst, (float(ulps), key))
        return len(lines), same, worst

    def test_no_avx(self):
        """Nehalem: SSE4.2, no AVX, AVX2, FMA or AVX-512."""
        n, same, (ulps, key) = self.compare("Nehalem")
        print("qemu -cpu Nehalem: %d of %d variants the same bits, the rest within "
              "%.1f float ulps (%s)" % (same, n, ulps, key))
        self.assertGreater(n, 45)
        self.assertLessEqual(ulps, 4.0, key)
        self.assertGreaterEqual(same, n - 2)

    def test_avx2(self):
        """Haswell: AVX2 and FMA, no AVX-512."""
        n, same, (ulps, key) = self.compare("Haswell", "--only", HASWELL_VARIANTS)
        print("qemu -cpu Haswell: %d of %d variants the same bits" % (same, n))
        self.assertEqual(n, len(HASWELL_VARIANTS.split(",")))
        self.assertEqual(same, n, "%s differs by %.1f ulps" % (key, ulps))


if __name__ == "__main__":
    unittest.main(verbosity=2)
