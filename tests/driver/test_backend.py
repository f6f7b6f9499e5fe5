"""BACKEND=auto|opencl|c: the same products on the C core and on OpenCL
(PoCL on the test machine), the metadata saying what ran, the fall back to
C with a warning when OpenCL was asked for and cannot run, bad values.

- BACKEND=c and BACKEND=opencl agree (docs/opencl.md tolerances: horizon
  angles and openness within 1e-3 deg, the 0..1 products within 1e-4 as
  Float32, Byte within 1 DN) on jacksboro and on a synthetic DEM with
  holes, and BACKEND says which ran (opencl must really run here);
- BACKEND=opencl (option or TERRASHADE_BACKEND) with
  TERRASHADE_OPENCL_DEVICE=99 gives the C results, a warning on stderr,
  BACKEND=c and BACKEND_FALLBACK_REASON; with BACKEND=auto the same fall
  back is silent (CPLDebug); a product computed chunk by chunk
  (TILE_SIZE) warns once and its BACKEND says what its chunks ran;
- BACKEND=bogus and TERRASHADE_BACKEND=cuda: non-zero exit, clear message;
- the default (auto) on a CPU OpenCL device runs C and says why;
- TERRASHADE_OPENCL_PROFILE and TERRASHADE_OPENCL_BUILD_OPTIONS (tuning aids);
- TERRASHADE_OPENCL_BATCH: the horizon streams' azimuths per OpenCL call,
  the same bits at any batch, bounded by MAX_MEMORY's room, bad values.
"""
import os
import sys
import unittest

import tsdriver as T
from tsdriver import gdal, np

# the tests decide the backend themselves
for _k in ("TERRASHADE_BACKEND", "TERRASHADE_OPENCL_DEVICE", "TERRASHADE_OPENCL_MAX_ALLOC"):
    os.environ.pop(_k, None)

GT = (600000, 30, 0, 4000000, 0, -30)

# (name, open options, tolerance: None = Byte within 1 DN)
PRODUCTS = [
    ("shade", {}, None),
    ("shade float sky", {"OUTPUT_TYPE": "Float32", "SKY_WEIGHT": 0.3, "DIRECTIONS": 8}, 1e-4),
    ("shade shm", {"OUTPUT_TYPE": "Float32", "METHOD": "shm", "PENUMBRA_DEPTH": 20}, 1e-4),
    ("shadow", {"PRODUCT": "shadow", "SUN_ELEVATION": 12}, 1e-4),
    ("shadow shm", {"PRODUCT": "shadow", "METHOD": "shm", "SUN_ELEVATION": 12}, 1e-4),
    ("horizon", {"PRODUCT": "horizon", "DIRECTIONS": 8, "START_AZIMUTH": 10}, 1e-3),
    ("svf", {"PRODUCT": "svf", "DIRECTIONS": 16}, 1e-4),
    ("sky", {"PRODUCT": "sky", "DIRECTIONS": 8}, 1e-4),
    ("openness", {"PRODUCT": "openness", "DIRECTIONS": 8}, 1e-3),
    # EDGE: horizon (the default) above; open and nodata (a search radius
    # that the shadow height map, which has none, runs on either backend)
    ("svf edge open", {"PRODUCT": "svf", "DIRECTIONS": 8, "EDGE": "open"}, 1e-4),
    ("shadow shm edge nodata", {"PRODUCT": "shadow", "METHOD": "shm", "SUN_ELEVATION": 12,
                                "EDGE": "nodata", "MAX_DISTANCE": 300}, 1e-4),
]


def backend_md(ds):
    return {k: v for k, v in ds.GetMetadata().items() if k.startswith("BACKEND")}


def compute(dem, options):
    """(bands as float64, BACKEND metadata at open, after computing, type)."""
    oo = ["%s=%s" % kv for kv in options.items()]
    ds = gdal.OpenEx(T.conn(dem), gdal.OF_RASTER, open_options=oo)
    before = backend_md(ds)
    arrays = []
    for b in range(1, ds.RasterCount + 1):
        rb = ds.GetRasterBand(b)
        a = rb.ReadAsArray().astype(np.float64)
        if rb.DataType == gdal.GDT_Byte:
            a[a == 0] = np.nan
        arrays.append(a)
    return np.array(arrays), before, backend_md(ds), ds.GetRasterBand(1).DataType


def synthetic(tmp):
    z = T.fractal_dem(150, seed=7, relief=600.0)[:, :133].copy()
    z[20:30, 40:52] = -9999
    z[::37, ::29] = -9999
    return T.write_tif(os.path.join(tmp, "synthetic.tif"), z, GT, 32617, nodata=-9999)


class Backend(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.dems = {"jacksboro": T.JACKSBORO, "synthetic": synthetic(cls.dir)}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def assert_same(self, name, c, cl, tol):
        np.testing.assert_array_equal(np.isnan(c), np.isnan(cl), name + ": nodata")
        both = ~np.isnan(c)
        d = np.abs(c - cl)[both]
        print("  %s: max |c - opencl| %.3g over %d cells" % (name, d.max() if d.size else 0,
                                                             d.size))
        self.assertLessEqual(d.max() if d.size else 0, 1 if tol is None else tol, name)

    def test_option_is_declared(self):
        import xml.etree.ElementTree as ET
        drv = gdal.GetDriverByName("TERRASHADE")
        opts = {o.get("name"): o for o in ET.fromstring(
            drv.GetMetadataItem(gdal.DMD_OPENOPTIONLIST))}
        o = opts["BACKEND"]
        self.assertEqual(o.get("type"), "string-select")
        self.assertEqual(o.get("default"), "auto")
        self.assertEqual([v.text for v in o], ["auto", "opencl", "c"])
        self.assertIn("TERRASHADE_BACKEND", o.get("description"))

    def test_c_backend_counts_the_cores_it_may_use(self):
        """THREADS=0 (the default) runs a thread per core this process may
        use: under taskset -c 0 one, not every online core (session 54's
        audit), as BACKEND_DEVICE says; the pixels are the same."""
        mine = sorted(os.sched_getaffinity(0))
        outs = []
        for cpus in (str(mine[0]), ",".join(map(str, mine))):
            out = os.path.join(self.dir, "cores_%d.tif" % len(outs))
            T.run(["taskset", "-c", cpus, "gdal_translate", "-q", "-oo", "PRODUCT=svf",
                   "-oo", "BACKEND=c", T.conn(T.LUX), out])
            outs.append(out)
        device = gdal.Open(outs[0]).GetMetadataItem("BACKEND_DEVICE")
        self.assertIn("CPU, 1 cores", device)
        device = gdal.Open(outs[1]).GetMetadataItem("BACKEND_DEVICE")
        self.assertIn("CPU, %d cores" % len(mine), device)
        np.testing.assert_array_equal(T.read(outs[0]), T.read(outs[1]))

    def test_c_and_opencl_agree(self):
        for dem_name, dem in self.dems.items():
            for name, options, tol in PRODUCTS:
                with self.subTest(dem=dem_name, product=name):
                    c, c0, c1, dt = compute(dem, dict(options, BACKEND="c"))
                    cl, cl0, cl1, _ = compute(dem, dict(options, BACKEND="opencl"))
                    print("%s %s: c %s, opencl %s" % (dem_name, name, c1, cl1))
                    self.assertEqual(c1["BACKEND"], "c")
                    self.assertTrue(c1["BACKEND_DEVICE"].startswith("CPU"))
                    self.assertNotIn("BACKEND_FALLBACK_REASON", c1)
                    self.assertEqual(cl1["BACKEND"], "opencl", cl1)
                    self.assertTrue(cl1["BACKEND_DEVICE"])
                    self.assertNotIn("BACKEND_FALLBACK_REASON", cl1)
                    # known at open already (GDAL tools copy metadata first)
                    self.assertEqual(c0, c1)
                    self.assertEqual(cl0, cl1)
                    if tol is None:
                        self.assertEqual(dt, gdal.GDT_Byte)
                    else:
                        self.assertEqual(dt, gdal.GDT_Float32)
                    self.assertEqual(c.shape, cl.shape)
                    self.assertTrue((~np.isnan(c)).any())
                    self.assert_same("%s %s" % (dem_name, name), c, cl, tol)

    def test_opencl_with_a_bad_device_falls_back_with_a_warning(self):
        dem = self.dems["synthetic"]
        for name, options, tol in PRODUCTS[:1] + PRODUCTS[5:7]:
            with self.subTest(product=name):
                ref = compute(dem, dict(options, BACKEND="c"))[0]
                out = os.path.join(self.dir, "fallback.tif")
                p = T.run(["gdal_translate", "-q"] + T.oo_args(dict(options, BACKEND="opencl"))
                          + [T.conn(dem), out], TERRASHADE_OPENCL_DEVICE=99)
                print(p.stderr)
                self.assertIn("Warning", p.stderr)
                self.assertIn("BACKEND=opencl was requested", p.stderr)
                self.assertIn("TERRASHADE_OPENCL_DEVICE=99", p.stderr)
                self.assertEqual(p.stderr.count("BACKEND=opencl was requested"), 1)
                md = gdal.Open(out).GetMetadata()
                self.assertEqual(md["BACKEND"], "c")
                self.assertTrue(md["BACKEND_DEVICE"].startswith("CPU"))
                self.assertIn("TERRASHADE_OPENCL_DEVICE=99", md["BACKEND_FALLBACK_REASON"])
                np.testing.assert_array_equal(T.read(out), ref)

    def test_windowed_opencl_with_a_bad_device_falls_back_with_a_warning(self):
        """A product computed chunk by chunk (TILE_SIZE) warns once too, also
        when its metadata was asked for first (gdal_translate does), and its
        BACKEND items say what the chunks ran. (Both were left to the first
        chunk, and only when nothing had asked for the metadata before: no
        warning from gdal_translate, BACKEND=opencl after a mixed run.)"""
        dem = self.dems["jacksboro"]
        options = {"PRODUCT": "svf", "DIRECTIONS": 4, "TILE_SIZE": 256}
        ref = compute(dem, dict(options, BACKEND="c"))[0]
        out = os.path.join(self.dir, "windowed.tif")
        p = T.run(["gdal_translate", "-q"] + T.oo_args(dict(options, BACKEND="opencl"))
                  + [T.conn(dem), out], TERRASHADE_OPENCL_DEVICE=99,
                  CPL_DEBUG="TERRASHADE")
        print(p.stderr)
        self.assertIn("computed chunk (1, 1)", p.stderr)  # really windowed
        self.assertEqual(p.stderr.count("BACKEND=opencl was requested"), 1)
        self.assertIn("TERRASHADE_OPENCL_DEVICE=99", p.stderr)
        np.testing.assert_array_equal(T.read(out), ref)
        code = ("import sys; sys.path.insert(0, %r); import tsdriver as T; "
                "from tsdriver import gdal; "
                "ds = gdal.OpenEx(T.conn(%r), open_options=%r); "
                "ds.GetRasterBand(1).Checksum(); "
                "print('BACKEND=' + ds.GetMetadataItem('BACKEND'))"
                % (os.path.dirname(os.path.abspath(__file__)), dem,
                   T.oo_args(dict(options, BACKEND="opencl"))[1::2]))
        p = T.run([sys.executable, "-c", code], TERRASHADE_OPENCL_DEVICE=99)
        print(p.stdout, p.stderr)
        self.assertIn("BACKEND=c\n", p.stdout)
        self.assertEqual(p.stderr.count("BACKEND=opencl was requested"), 1)
        # OpenCL runs the normals, C the capped sweeps: computed mixed (it
        # stayed opencl); a chunk's sweep is capped by its near field, which
        # the prediction does not foresee (opencl), MAX_DISTANCE's by
        # MAX_DISTANCE, which it does (mixed)
        for extra, why, predicted in [
                ({}, "bounded by its near field of 11837 m (TILE_SIZE=256", "opencl"),
                ({"MAX_DISTANCE": 500}, "a MAX_DISTANCE sweep runs on the C", "mixed")]:
            _, before, after, _ = compute(dem, dict(options, BACKEND="opencl", **extra))
            print(before, after)
            self.assertEqual(before["BACKEND"], predicted)
            self.assertEqual(after["BACKEND"], "mixed")
            self.assertIn(why, after["BACKEND_FALLBACK_REASON"])

    def test_env_opencl_with_a_bad_device_falls_back_with_a_warning(self):
        """TERRASHADE_BACKEND=opencl asks for OpenCL as the option does."""
        dem = self.dems["synthetic"]
        out = os.path.join(self.dir, "env.npy")
        code = ("import sys; sys.path.insert(0, %r); import tsdriver as T; "
                "from tsdriver import gdal, np; "
                "ds = gdal.OpenEx(T.conn(%r), open_options=['PRODUCT=svf', 'DIRECTIONS=8']); "
                "np.save(%r, ds.GetRasterBand(1).ReadAsArray()); "
                "md = ds.GetMetadata(); "
                "print('BACKEND=' + md['BACKEND']); "
                "print('REASON=' + md.get('BACKEND_FALLBACK_REASON', ''))"
                % (os.path.dirname(os.path.abspath(__file__)), dem, out))
        p = T.run([sys.executable, "-c", code], TERRASHADE_BACKEND="opencl",
                  TERRASHADE_OPENCL_DEVICE=99)
        print(p.stdout, p.stderr)
        self.assertIn("BACKEND=c\n", p.stdout)
        self.assertIn("REASON=TERRASHADE_OPENCL_DEVICE=99", p.stdout)
        self.assertIn("BACKEND=opencl was requested", p.stderr)
        ref = compute(dem, {"PRODUCT": "svf", "DIRECTIONS": 8, "BACKEND": "c"})[0][0]
        np.testing.assert_array_equal(np.load(out), ref)

    def test_auto_with_a_bad_device_falls_back_silently(self):
        dem = self.dems["synthetic"]
        out = os.path.join(self.dir, "auto.tif")
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=shadow", T.conn(dem), out],
                  TERRASHADE_OPENCL_DEVICE=99)
        self.assertNotIn("Warning", p.stderr)
        md = gdal.Open(out).GetMetadata()
        self.assertEqual(md["BACKEND"], "c")
        self.assertIn("TERRASHADE_OPENCL_DEVICE=99", md["BACKEND_FALLBACK_REASON"])
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=shadow", T.conn(dem), out],
                  TERRASHADE_OPENCL_DEVICE=99, CPL_DEBUG="TERRASHADE")
        self.assertIn("TERRASHADE_OPENCL_DEVICE=99", p.stderr)
        self.assertNotIn("Warning", p.stderr)

    def test_kernel_profile_and_build_options(self):
        """TERRASHADE_OPENCL_PROFILE=1 prints each kernel's device time at
        exit and changes no result; TERRASHADE_OPENCL_BUILD_OPTIONS reaches
        the kernels' build: a macro they test, at its default, changes
        nothing, and one that breaks the build falls back to C, saying so."""
        dem = self.dems["synthetic"]
        ref, out = (os.path.join(self.dir, n) for n in ("prof_ref.tif", "prof.tif"))
        base = ["gdal_translate", "-q", "-oo", "PRODUCT=horizon", "-oo", "DIRECTIONS=8",
                "-oo", "BACKEND=opencl", T.conn(dem)]
        p = T.run(base + [ref], TERRASHADE_OPENCL_PROFILE="0")
        self.assertNotIn("TERRASHADE_OPENCL_PROFILE", p.stderr)
        want = gdal.Open(ref)
        self.assertEqual(want.GetMetadataItem("BACKEND"), "opencl")
        want = want.ReadAsArray()
        for env in ({"TERRASHADE_OPENCL_PROFILE": "1"},
                    {"TERRASHADE_OPENCL_BUILD_OPTIONS": "-DTS_LOST_STEPS=8"}):
            with self.subTest(env=env):
                p = T.run(base + [out], **env)
                print(p.stderr)
                ds = gdal.Open(out)
                self.assertEqual(ds.GetMetadataItem("BACKEND"), "opencl")
                np.testing.assert_array_equal(ds.ReadAsArray(), want)
                if "TERRASHADE_OPENCL_PROFILE" in env:
                    self.assertIn("TERRASHADE_OPENCL_PROFILE: device time per kernel",
                                  p.stderr)
                    for k in ("ts_sweep_lines", "ts_sweep_fast", "ts_sweep_finish"):
                        self.assertRegex(p.stderr, r"\n  %s +[1-9]\d* +\d+\.\d{4} " % k)
        for bad, said in (("-DTS_FAR_SPREAD=(", "OpenCL kernels failed to build"),
                          ("-DTS_LOST_STEPS=8 " * 12, "TERRASHADE_OPENCL_BUILD_OPTIONS is 216 "
                           "characters long, more than the 200")):
            with self.subTest(bad=bad):
                p = T.run(base + [out], TERRASHADE_OPENCL_BUILD_OPTIONS=bad)
                print(p.stderr)
                self.assertIn("BACKEND=opencl was requested", p.stderr)
                self.assertIn(said, p.stderr)
                ds = gdal.Open(out)
                self.assertEqual(ds.GetMetadataItem("BACKEND"), "c")
                np.testing.assert_allclose(ds.ReadAsArray(), want, atol=1e-3)

    def test_opencl_batches(self):
        """The driver's horizon streams (svf, negative openness, envlight)
        sweep TERRASHADE_OPENCL_BATCH azimuths per OpenCL call, and
        METHOD=sh its swath in one call where the batch holds it, bit for
        bit what one azimuth a call gives (a last batch shorter); half of
        what MAX_MEMORY leaves bounds a batch; on a CPU device (PoCL here)
        the default is one a call; a value out of 1..256 is an error."""
        import re
        dem = self.dems["synthetic"]
        out = os.path.join(self.dir, "batch.tif")

        def run(options, batch, memory=None):
            args = ["gdal_translate", "-q"] + T.oo_args(dict(options, BACKEND="opencl"))
            if memory:
                args += ["-oo", "MAX_MEMORY=%d" % memory]
            env = {"CPL_DEBUG": "TERRASHADE"}
            if batch is not None:
                env["TERRASHADE_OPENCL_BATCH"] = str(batch)
            p = T.run(args + [T.conn(dem), out], **env)
            calls = re.search(r"\((\d+) call\(s\): (\d+) OpenCL, (\d+) C\)", p.stderr)
            self.assertIsNotNone(calls, p.stderr)
            # only METHOD=sh's lighting, which has no kernel, runs C: no
            # sweep fell back
            self.assertEqual(calls.group(3), "1" if options.get("METHOD") == "sh" else "0")
            return gdal.Open(out).ReadAsArray(), int(calls.group(2))

        # (options, its sweeps, the sweep calls at batch 16, 5, 7, 2); the
        # swath of METHOD=sh is swept in one call or one azimuth a call
        cases = [({"PRODUCT": "svf", "DIRECTIONS": 16}, 16, (1, 4, 3, 8)),
                 ({"PRODUCT": "openness", "OPENNESS": "negative", "DIRECTIONS": 16}, 16,
                  (1, 4, 3, 8)),
                 ({"PRODUCT": "envlight", "SKY": "uniform", "DIRECTIONS": 16}, 16, (1, 4, 3, 8)),
                 ({"METHOD": "sh", "OUTPUT_TYPE": "Float32"}, 3, (1, 1, 1, 3)),
                 ({"PRODUCT": "shadow", "METHOD": "sh", "SWATH_DIRECTIONS": 5}, 5,
                  (1, 1, 1, 5))]
        for options, sweeps, expect in cases:
            with self.subTest(options=options):
                want, one = run(options, 1)
                others = one - sweeps  # the calls besides the sweeps
                _, default = run(options, None)
                self.assertEqual(default, one, "a CPU device: one azimuth a call")
                for batch, calls in zip((16, 5, 7, 2), expect):
                    got, n = run(options, batch)
                    print(options, "batch", batch, ":", n - others, "sweep calls")
                    self.assertEqual(n - others, calls)
                    np.testing.assert_array_equal(got, want)
                if options.get("METHOD") == "sh":
                    continue  # (its wedge tables alone take 8 MiB)
                # a 150 x 133 DEM: planes of 78 KiB; MAX_MEMORY=1 leaves room
                # for a few more (the estimate, a few planes, from 1 MiB);
                # envlight's SKY holds 10 MiB of texels and table besides,
                # counted since session 56: 11 MiB leaves it as much
                memory = 11 if options.get("PRODUCT") == "envlight" else 1
                got, n = run(options, 16, memory)
                print(options, "batch 16, MAX_MEMORY=%d:" % memory, n - others, "sweep calls")
                self.assertLess(n - others, sweeps)
                self.assertGreater(n - others, 1)
                np.testing.assert_array_equal(got, want)
        # capped sweeps (MAX_DISTANCE here; a window's near field) run on C,
        # one azimuth a call whatever the batch
        for batch in ("1", "8"):
            p = T.run(["gdal_translate", "-q"] + T.oo_args(
                {"PRODUCT": "svf", "DIRECTIONS": 16, "MAX_DISTANCE": 300, "BACKEND": "opencl"})
                + [T.conn(dem), out], TERRASHADE_OPENCL_BATCH=batch, CPL_DEBUG="TERRASHADE")
            self.assertRegex(p.stderr, r"\(17 call\(s\): 1 OpenCL, 16 C\)")
        # a batch that OpenCL cannot take (its buffers over the limit) runs
        # on C as a whole: C's bits
        want = compute(dem, {"PRODUCT": "svf", "DIRECTIONS": 16, "BACKEND": "c"})[0][0]
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo", "DIRECTIONS=16", "-oo",
                   "BACKEND=opencl", T.conn(dem), out], TERRASHADE_OPENCL_BATCH="8",
                  TERRASHADE_OPENCL_MAX_ALLOC="4k")
        print(p.stderr)
        self.assertIn("BACKEND=opencl was requested", p.stderr)
        self.assertIn("TERRASHADE_OPENCL_MAX_ALLOC", p.stderr)
        ds = gdal.Open(out)
        np.testing.assert_array_equal(ds.ReadAsArray().astype(np.float64), want)
        for bad in ("0", "257", "x", "8k"):
            with self.subTest(bad=bad):
                p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo", "BACKEND=opencl",
                           T.conn(dem), out], ok=False, TERRASHADE_OPENCL_BATCH=bad)
                self.assertIn("TERRASHADE_OPENCL_BATCH must be an integer from 1 to 256, "
                              "got '%s'" % bad, p.stderr)

    def test_bad_values_are_errors(self):
        dem = self.dems["synthetic"]
        out = os.path.join(self.dir, "bad.tif")
        for args, extra, text in [
                (["-oo", "BACKEND=bogus", T.conn(dem)], {},
                 "BACKEND must be one of auto, opencl, c, got 'bogus'"),
                (["TERRASHADE:BACKEND=cuda:" + dem], {},
                 "BACKEND must be one of auto, opencl, c, got 'cuda'"),
                ([T.conn(dem)], {"TERRASHADE_BACKEND": "cuda"},
                 "TERRASHADE_BACKEND must be auto, c or opencl, got 'cuda'")]:
            with self.subTest(args=args, env=extra):
                p = T.run(["gdal_translate", "-q"] + args + [out], ok=False, **extra)
                print(p.stderr)
                self.assertIn(text, p.stderr)
        with self.assertRaises(RuntimeError) as e:
            gdal.OpenEx(T.conn(dem), open_options=["BACKEND=gpu"])
        self.assertIn("BACKEND must be one of auto, opencl, c, got 'gpu'", str(e.exception))

    def test_default_auto(self):
        """No option, no environment: the dispatcher decides; on a CPU OpenCL
        device (PoCL here) that is C, with the reason."""
        dem = self.dems["jacksboro"]
        _, before, md, _ = compute(dem, {"PRODUCT": "svf", "DIRECTIONS": 4})
        _, _, cl, _ = compute(dem, {"PRODUCT": "svf", "DIRECTIONS": 4, "BACKEND": "opencl"})
        print("auto:", md, "\nopencl:", cl)
        self.assertEqual(before, md)
        cpu_device = ("pthread" in cl["BACKEND_DEVICE"] or
                      "Portable Computing Language" in cl["BACKEND_DEVICE"])
        if md["BACKEND"] == "opencl":
            self.assertFalse(cpu_device, md)
            self.assertNotIn("BACKEND_FALLBACK_REASON", md)
        else:
            self.assertEqual(md["BACKEND"], "c")
            self.assertTrue(md["BACKEND_FALLBACK_REASON"])
        if cpu_device:
            self.assertEqual(md["BACKEND"], "c")
            self.assertIn("is a CPU", md["BACKEND_FALLBACK_REASON"])
        # products that make no backend call say nothing about one
        ds = gdal.OpenEx(T.conn(dem), open_options=[
            "PRODUCT=sunhours", "DATE=2026-06-21", "TIMEZONE=-05:00", "STEP_MINUTES=60"])
        ds.GetRasterBand(1).Checksum()
        self.assertEqual(backend_md(ds), {})

    def test_c_steps_are_said_before_computing(self):
        """Steps with no OpenCL path for their options run in C whatever the
        backend: BACKEND=opencl says so before computing (gdal_translate
        copies the metadata then), as after, and warns. The items once held
        'opencl' without a reason for a horizon capped by MAX_DISTANCE,
        which ran wholly in C, and the per-cell sun of shade ran in C
        without being counted at all."""
        dem = self.dems["jacksboro"]
        cases = [
            ({"PRODUCT": "horizon", "DIRECTIONS": 4, "MAX_DISTANCE": 300}, "c",
             "a MAX_DISTANCE sweep runs on the C backend"),
            ({"PRODUCT": "horizon", "DIRECTIONS": 4, "HORIZON_METHOD": "pyramid"}, "c",
             "HORIZON_METHOD=pyramid"),
            ({"PRODUCT": "svf", "DIRECTIONS": 8, "MAX_DISTANCE": 300}, "mixed",
             "a MAX_DISTANCE sweep runs on the C backend"),
            ({"PRODUCT": "shade", "SUN_POSITION": "per_cell",
              "DATETIME": "2026-06-21T12:00:00-05:00"}, "mixed", "SUN_POSITION=per_cell"),
        ]
        out = os.path.join(self.dir, "c_steps.tif")
        for options, backend, reason in cases:
            with self.subTest(options=options):
                _, before, after, _ = compute(dem, dict(options, BACKEND="opencl"))
                p = T.run(["gdal_translate", "-q"] + T.oo_args(dict(options, BACKEND="opencl"))
                          + [T.conn(dem), out])
                written = backend_md(gdal.Open(out))
                print(options, before, after, written)
                for md in (before, after, written):
                    self.assertEqual(md["BACKEND"], backend)
                    self.assertIn(reason, md["BACKEND_FALLBACK_REASON"])
                self.assertIn("ran on the C backend instead: " + reason, p.stderr)
        # a day product has no OpenCL step at all: said at open (once silent)
        p = T.run(["gdal_translate", "-q"] + T.oo_args({
            "PRODUCT": "sunhours", "DATE": "2026-06-21", "TIMEZONE": "Z", "STEP_MINUTES": 60,
            "BACKEND": "opencl"}) + [T.conn(dem), out])
        self.assertIn("BACKEND=opencl was requested, but PRODUCT=sunhours runs on the C "
                      "backend only", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
