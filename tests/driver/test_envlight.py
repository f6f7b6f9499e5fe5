"""PRODUCT=envlight and the environment sky term of shade, through the driver.

- a constant environment of radiance 1 (an EXR written here, its cube copy
  made by OpenEXR's exrenvmap, and SKY=uniform) gives the sky product;
- a black map with one small bright patch shades like the sun there (the
  orientation of maps on the terrain);
- the lat-long and cube versions of tests/data/envmaps/sunset.exr give the
  same light; ENV_ROTATION=90 equals the map with its columns rolled by a
  quarter (and not rolled the other way);
- a /vsimem/ map, Byte output (exposure and the sRGB curve), colour
  interpretation and metadata;
- shade's sky term from SKY, and the sun with a CIE clear sky from DATETIME;
- bad input: a clear sentence and a non-zero exit of gdal_translate;
- MAX_MEMORY counts the light table and ENV_MAP decoded: refused at open,
  before either is built, with what needs the memory.
"""
import os
import shutil
import subprocess
import unittest

import tsdriver as T
from tsdriver import gdal, np
from exr_write import write_black_zip_exr, write_exr

SUNSET = os.path.join(T.DATA, "envmaps", "sunset.exr")
SUNSET_CUBE = os.path.join(T.DATA, "envmaps", "sunset_cube128.exr")


def envlight(dem, **options):
    """The envlight bands (3 x H x W floats) of dem with these options."""
    return T.read(T.conn(dem), options=dict(options, PRODUCT="envlight", PROGRESS="no"))


def luminance(rgb):
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


def latlong_direction(w, h, i, j):
    """Terrain azimuth and elevation (degrees) of lat-long pixel (i, j)
    (docs/envlight.md: column i at azimuth 360 i / (w - 1) - 180, row j at
    elevation 90 - 180 j / (h - 1))."""
    return 360.0 * i / (w - 1) - 180.0, 90.0 - 180.0 * j / (h - 1)


def srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


class EnvLight(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmpdir = T.TempDir()
        cls.tmp = cls.tmpdir.__enter__()

    @classmethod
    def tearDownClass(cls):
        cls.tmpdir.__exit__(None, None, None)

    def path(self, name):
        return os.path.join(self.tmp, name)

    def test_constant_environment_is_the_sky_product(self):
        # a texel row cut by the horizon counts wholly on one side: maps of
        # 0.18 degree rows and faces (1024 x 512: 1.4e-3; 128 x 64: 0.3 %)
        const = write_exr(self.path("const.exr"), np.ones((1024, 2048, 3)))
        cube = self.path("const_cube.exr")
        T.run(["exrenvmap", "-c", "-w", "512", const, cube])
        self.assertIn("cube", T.run(["exrheader", cube]).stdout)
        for dirs in (8, 16):
            sky = T.read(T.conn(T.JACKSBORO), band=1,
                         options=dict(PRODUCT="sky", DIRECTIONS=dirs, PROGRESS="no"))
            for name, opts in (("map", dict(ENV_MAP=const)), ("cube", dict(ENV_MAP=cube)),
                               ("SKY=uniform", dict(SKY="uniform"))):
                rgb = envlight(T.JACKSBORO, DIRECTIONS=dirs, **opts)
                for c in range(3):
                    d = np.nanmax(np.abs(rgb[c] - sky))
                    print("DIRECTIONS=%d %s band %d: max |envlight - sky| %.3g"
                          % (dirs, name, c + 1, d))
                    self.assertLessEqual(d, 1e-3)
                    self.assertTrue(np.array_equal(np.isnan(rgb[c]), np.isnan(sky)))

    def test_coarse_maps_keep_their_light(self):
        # pixels wider than a degree are cut into parts: each part's light
        # came from the pixel's centre before (4 x 2 of radiance 1 lit flat
        # ground as 2, 6 x 3 as 0.59, a cube of 1-pixel faces as 0.67)
        sky = T.read(T.conn(T.JACKSBORO), band=1,
                     options=dict(PRODUCT="sky", DIRECTIONS=8, PROGRESS="no"))
        maps = [("latlong", 2, 4), ("latlong", 2, 2), ("latlong", 3, 6), ("latlong", 5, 10),
                ("cube", 6, 1), ("cube", 12, 2), ("cube", 18, 3)]
        for layout, h, w in maps:
            img = np.ones((h, w, 3)) * [1.0, 2.0, 3.0]
            path = write_exr(self.path("coarse_%s_%dx%d.exr" % (layout, w, h)), img,
                             envmap=layout)
            ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
                "PRODUCT=envlight", "ENV_MAP=" + path, "DIRECTIONS=8"])
            flat = [float(v) for v in ds.GetMetadataItem("ENV_FLAT_LIGHT").split(",")]
            rgb = envlight(T.JACKSBORO, ENV_MAP=path, DIRECTIONS=8)
            worst = max(np.nanmax(np.abs(rgb[c] / (c + 1) - sky)) for c in range(3))
            print("%s %d x %d: flat light %s, max |envlight / L - sky| %.2e"
                  % (layout, w, h, flat, worst))
            np.testing.assert_allclose(flat, [1, 2, 3], rtol=1e-4)
            self.assertLessEqual(worst, 5e-3)

    def test_bright_patch_shades_like_the_sun_there(self):
        w, h = 1024, 512
        i, j = 895, 170  # a pixel centre near azimuth 135, elevation 30
        az, el = latlong_direction(w, h, i, j)
        img = np.zeros((h, w, 3))
        img[j - 1:j + 2, i - 1:i + 2] = 5000.0
        patch = write_exr(self.path("patch.exr"), img)
        rgb = envlight(T.JACKSBORO, ENV_MAP=patch, DIRECTIONS=16)
        sun = T.read(T.conn(T.JACKSBORO), band=1, options=dict(
            PRODUCT="shade", OUTPUT_TYPE="Float32", SKY_WEIGHT=0, SUN_AZIMUTH=az,
            SUN_ELEVATION=el, PROGRESS="no"))
        ok = ~np.isnan(sun) & ~np.isnan(rgb[0])
        r = np.corrcoef(rgb[0][ok], sun[ok])[0, 1]
        # the same patch seen from the opposite side of the sky: no match
        opposite = T.read(T.conn(T.JACKSBORO), band=1, options=dict(
            PRODUCT="shade", OUTPUT_TYPE="Float32", SKY_WEIGHT=0,
            SUN_AZIMUTH=(az + 180) % 360, SUN_ELEVATION=el, PROGRESS="no"))
        r_opp = np.corrcoef(rgb[0][ok], opposite[ok])[0, 1]
        print("patch at azimuth %.3f, elevation %.3f: correlation with shade's direct "
              "term %.5f (sun opposite: %.3f)" % (az, el, r, r_opp))
        self.assertGreaterEqual(r, 0.99)
        self.assertLess(r_opp, 0.5)
        # colour: grey patch, equal bands
        self.assertTrue(np.allclose(rgb[0][ok], rgb[2][ok], rtol=1e-5, atol=1e-7))

    def test_latlong_and_cube_maps_agree(self):
        a = envlight(T.JACKSBORO, ENV_MAP=SUNSET)
        b = envlight(T.JACKSBORO, ENV_MAP=SUNSET_CUBE)
        for c in range(3):
            rel = np.abs(a[c] - b[c]) / a[c]
            med = np.nanmedian(rel)
            print("band %d: median relative difference lat-long vs cube %.5f, max %.4f"
                  % (c + 1, med, np.nanmax(rel)))
            self.assertLessEqual(med, 0.01)

    def test_rotation_is_a_roll_of_the_columns(self):
        # 129 columns: pixel centres every 360/128 degrees, the last column
        # on the first's meridian, so that a quarter turn is 32 columns
        rng = np.random.default_rng(3)
        w, h = 129, 65
        img = rng.uniform(0.2, 1.0, size=(h, w, 3))
        img[20:24, 40:44] = 40.0  # a bright spot, to make the direction plain
        img[:, 128] = img[:, 0]
        rolled = img.copy()
        rolled[:, :128] = np.roll(img[:, :128], 32, axis=1)
        rolled[:, 128] = rolled[:, 0]
        back = img.copy()
        back[:, :128] = np.roll(img[:, :128], -32, axis=1)
        back[:, 128] = back[:, 0]
        orig = write_exr(self.path("rot.exr"), img, envmap="latlong")
        roll = write_exr(self.path("rot_rolled.exr"), rolled, envmap="latlong")
        wrong = write_exr(self.path("rot_back.exr"), back, envmap="latlong")
        turned = envlight(T.JACKSBORO, ENV_MAP=orig, ENV_ROTATION=90, DIRECTIONS=12)
        want = envlight(T.JACKSBORO, ENV_MAP=roll, DIRECTIONS=12)
        other = envlight(T.JACKSBORO, ENV_MAP=wrong, DIRECTIONS=12)
        rel = np.nanmax(np.abs(turned - want) / want)
        rel_other = np.nanmax(np.abs(turned - other) / other)
        print("ENV_ROTATION=90 vs columns rolled a quarter: max relative difference %.3g "
              "(rolled the other way: %.3g)" % (rel, rel_other))
        self.assertLessEqual(rel, 1e-4)
        self.assertGreater(rel_other, 0.05)

    def test_vsimem_map(self):
        with open(SUNSET, "rb") as f:
            gdal.FileFromMemBuffer("/vsimem/envlight/sunset.exr", f.read())
        try:
            mem = envlight(T.JACKSBORO, ENV_MAP="/vsimem/envlight/sunset.exr")
        finally:
            gdal.Unlink("/vsimem/envlight/sunset.exr")
        disk = envlight(T.JACKSBORO, ENV_MAP=SUNSET)
        self.assertTrue(np.array_equal(mem, disk, equal_nan=True))

    def test_zipped_maps(self):
        """/vsizip/ and /vsigzip/ maps give the map's own light (GDAL 3.6's
        readers of them give short reads without their end-of-file flag,
        which refused every such map); a large file that is not OpenEXR is
        refused after its first four bytes (a 1.5 GB one was read whole:
        7 s and 2 GB of memory)."""
        import gzip
        import zipfile
        disk = envlight(T.JACKSBORO, ENV_MAP=SUNSET)
        zipped = self.path("maps.zip")
        with zipfile.ZipFile(zipped, "w", zipfile.ZIP_DEFLATED) as z:
            z.write(SUNSET, "sunset.exr")
        gz = self.path("sunset.exr.gz")
        with open(SUNSET, "rb") as f, gzip.open(gz, "wb") as g:
            g.write(f.read())
        for name in ("/vsizip/" + zipped + "/sunset.exr", "/vsigzip/" + gz):
            self.assertTrue(np.array_equal(envlight(T.JACKSBORO, ENV_MAP=name), disk,
                                           equal_nan=True), name)
        sparse = self.path("sparse.exr")
        with open(sparse, "wb") as f:
            f.truncate(1500 << 20)  # (sparse: no disk space)
        import time
        t0 = time.time()
        err = T.run(["gdalinfo", "-nomd"]
                    + T.oo_args(dict(PRODUCT="envlight", ENV_MAP=sparse))
                    + [T.conn(T.JACKSBORO)], ok=False).stderr
        print("a 1.5 GB file of zeros refused in %.2f s: %s" % (time.time() - t0, err))
        self.assertIn("is not an OpenEXR file", err)
        self.assertLess(time.time() - t0, 5.0)

    def test_channels_it_cannot_use(self):
        """A luminance/chroma map (Y, RY, BY) is read as grey from Y, with a
        warning (it was silent); the channels of a map without R, G, B or Y
        are listed whole, their bytes beyond ASCII as '?' (names cut to six
        bytes within a UTF-8 character left Python's error empty)."""
        self.flat_dem()
        yc = write_exr(self.path("yc.exr"), np.dstack([np.full((16, 32), v) for v in
                                                       (2.0, 0.3, -0.2)]),
                       names=("Y", "RY", "BY"))
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=envlight", "-oo", "ENV_MAP=" + yc,
                   T.conn(self.path("flat.tif")), self.path("yc.tif")])
        print(p.stderr.strip())
        self.assertIn("stores its colour as luminance and chroma", p.stderr)
        self.assertEqual(T.metadata(self.path("yc.tif"))["ENV_MAP_CHANNELS"], "Y")
        named = write_exr(self.path("named.exr"), np.ones((16, 32, 3)),
                          names=("diffuse.R", "diffuse.G", "\u65e5\u672c\u8a9e.B"))
        with self.assertRaises(RuntimeError) as cm:
            gdal.OpenEx(T.conn(self.path("flat.tif")),
                        open_options=["PRODUCT=envlight", "ENV_MAP=" + named])
        print(cm.exception)
        self.assertIn("(it has: diffuse.G, diffuse.R, ?????????.B)",
                      str(cm.exception))

    def flat_dem(self):
        path = self.path("flat.tif")
        if not os.path.exists(path):
            T.write_tif(path, np.full((24, 32), 250.0, np.float32),
                        (500000, 30, 0, 4000000, 0, -30), 32617)
        return path

    def test_byte_is_exposed_and_srgb_encoded(self):
        flat = self.flat_dem()
        f = envlight(flat, SKY="uniform")
        self.assertTrue(np.allclose(f, 1.0, atol=1e-4), f.min())
        ds = gdal.OpenEx(T.conn(flat), open_options=[
            "PRODUCT=envlight", "SKY=uniform", "OUTPUT_TYPE=Byte", "EXPOSURE=-1",
            "PROGRESS=no"])
        b = ds.ReadAsArray()
        md = ds.GetMetadata()
        self.assertEqual(ds.GetRasterBand(1).DataType, gdal.GDT_Byte)
        ds = None
        # 1 x 2^-1 = 0.5, sRGB 0.7354, 1 + 254 x 0.7354 = 187.8
        print("flat ground, SKY=uniform, EXPOSURE=-1: bytes", np.unique(b))
        self.assertTrue((b == 188).all())
        self.assertEqual(md["EXPOSURE"], "-1")
        self.assertIn("sRGB", md["TRANSFER"])
        # automatic: the brightest unshadowed surface is the flat one here
        auto = T.read(T.conn(flat), options=dict(PRODUCT="envlight", SKY="uniform",
                                                 OUTPUT_TYPE="Byte", PROGRESS="no"))
        self.assertTrue((auto == 255).all(), np.unique(auto))
        # a relief: the bytes follow the Float32 values through the curve
        fl = envlight(T.JACKSBORO, ENV_MAP=SUNSET)
        by = T.read(T.conn(T.JACKSBORO), options=dict(
            ENV_MAP=SUNSET, EXPOSURE=0.5, PRODUCT="envlight", OUTPUT_TYPE="Byte",
            PROGRESS="no"))
        want = np.floor(1 + 254 * srgb(fl * 2 ** 0.5) + 0.5)
        self.assertLessEqual(np.nanmax(np.abs(by - want)), 1)

    def test_a_map_that_is_no_file_is_refused_at_once(self):
        """An ENV_MAP that is a pipe waited forever in its open for a
        writer; a device could too: refused, as a folder is. Also inside
        GDAL's wrappers (/vsisubfile/ and /vsigzip/ of the pipe hung until
        session 56), and the standard input (/vsistdin/ waited for the
        host's)."""
        pipe = self.path("pipe.exr")
        os.mkfifo(pipe)
        for m, source in ((pipe, pipe), ("/dev/zero", "/dev/zero"),
                          ("/vsisubfile/0_0," + pipe, pipe), ("/vsigzip/" + pipe, pipe),
                          ("/vsizip/" + pipe + "/map.exr", pipe)):
            p = T.run(["timeout", "60", "gdalinfo", T.conn(T.JACKSBORO, PRODUCT="envlight"),
                       "-oo", "ENV_MAP=" + m], ok=False)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("ENV_MAP '%s' reads '%s', which is not a regular file" % (m, source),
                          p.stderr)
        # (a pipe that stays open as stdin: a read of it would wait)
        r, w = os.pipe()
        try:
            p = subprocess.run(["timeout", "60", "gdalinfo",
                                T.conn(T.JACKSBORO, PRODUCT="envlight"),
                                "-oo", "ENV_MAP=/vsistdin/"], stdin=r, capture_output=True,
                               text=True, env=T.env())
        finally:
            os.close(r)
            os.close(w)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn("ENV_MAP '/vsistdin/' reads the standard input", p.stderr)

    def open_peak(self, *args):
        """gdalinfo of an envlight of a 64^2 crop of jacksboro with these
        -oo arguments, in a child whose peak resident MiB is printed last:
        (the CompletedProcess, that MiB)."""
        dem = self.path("crop64.tif")
        if not os.path.exists(dem):
            T.run(["gdal_translate", "-q", "-outsize", 64, 64, T.JACKSBORO, dem])
        child = ("import resource, subprocess, sys\n"
                 "p = subprocess.run(sys.argv[1:])\n"
                 "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024)\n"
                 "sys.exit(p.returncode)")
        p = T.run(["/usr/bin/python3", "-c", child, "gdalinfo", "-nomd",
                   T.conn(dem, PRODUCT="envlight")] + list(args), ok=None)
        return p, int(p.stdout.split()[-1])

    def test_max_memory_counts_the_light_table(self):
        """A SKY's light table of DIRECTIONS=3600 x ENV_HORIZON_STEPS=3601
        (405 MiB kept, 1197 MiB while its double sums are built) opened
        under MAX_MEMORY=100 with a peak of 1254 MB (the table was counted
        nowhere, and its own 512 MiB limit reckoned 32 bytes a node)."""
        big = ["-oo", "SKY=clear", "-oo", "DIRECTIONS=3600", "-oo", "ENV_HORIZON_STEPS=3601"]
        for method in ("table", "sh"):
            p, peak = self.open_peak(*big + ["-oo", "MAX_MEMORY=100", "-oo",
                                             "ENV_METHOD=" + method])
            self.assertNotEqual(p.returncode, 0, method)
            self.assertIn("the light table of SKY=clear (DIRECTIONS=3600 x ENV_NORMAL_STEPS=0 "
                          "x ENV_HORIZON_STEPS=3601) needs about 1197 MiB while it is built "
                          "(406 MiB kept), more than the limit of 100 MiB (MAX_MEMORY); use "
                          "fewer DIRECTIONS or ENV_HORIZON_STEPS, or MAX_MEMORY=", p.stderr)
            self.assertLess(peak, 200, "the table was built before the refusal")
        # a table that fits the limit given opens
        p, peak = self.open_peak("-oo", "SKY=clear", "-oo", "DIRECTIONS=360",
                                 "-oo", "MAX_MEMORY=100")
        self.assertEqual(p.returncode, 0, p.stderr)

    def test_max_memory_counts_the_map_decoded(self):
        """A 404 KB ZIP-compressed map of 11584 x 5792 black pixels decodes
        to 12 bytes a pixel: it took 877 MB at open under MAX_MEMORY=64, its
        only limits TS_ENV_MAX_PIXELS and a 2 GiB file. Refused under a small
        MAX_MEMORY, before it is decoded; under the default (three quarters
        of the memory) it opens, as before."""
        bomb = write_black_zip_exr(self.path("bomb.exr"), 11584, 5792)
        self.assertLess(os.path.getsize(bomb), 500000)
        p, peak = self.open_peak("-oo", "ENV_MAP=" + bomb, "-oo", "MAX_MEMORY=64")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("decoding ENV_MAP '%s' (11584 x 5792 pixels, read as 12 bytes each, "
                      "into 1865346 texels) needs about 8" % bomb, p.stderr)
        self.assertIn("more than the limit of 64 MiB (MAX_MEMORY); use a smaller map",
                      p.stderr)
        self.assertLess(peak, 200, "the map was decoded before the refusal")
        p, peak = self.open_peak("-oo", "ENV_MAP=" + bomb)
        self.assertEqual(p.returncode, 0, p.stderr)
        print("the map under the default limit: peak %d MiB" % peak)
        self.assertGreater(peak, 768)  # its pixels alone: 768 MiB

    def test_bands_and_metadata(self):
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=envlight", "ENV_MAP=" + SUNSET_CUBE, "ENV_ROTATION=30"])
        self.assertEqual(ds.RasterCount, 3)
        self.assertEqual([ds.GetRasterBand(k).GetColorInterpretation() for k in (1, 2, 3)],
                         [gdal.GCI_RedBand, gdal.GCI_GreenBand, gdal.GCI_BlueBand])
        self.assertEqual(ds.GetRasterBand(1).DataType, gdal.GDT_Float32)
        md = ds.GetMetadata()
        ds = None
        self.assertEqual(md["ENV_MAP"], SUNSET_CUBE)
        self.assertEqual(md["ENV_MAP_LAYOUT"], "cube")
        self.assertEqual(md["ENV_MAP_SIZE"], "128 x 768")
        self.assertEqual(md["ENV_ROTATION"], "30")
        # a map, or a sky without a sun, is lit by no sun: none recorded
        # (SUN_AZIMUTH=315 read as the light's direction)
        self.assertNotIn("SUN_AZIMUTH", md)
        self.assertNotIn("PRESSURE", md)
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=envlight", "SKY=cie:7", "SUN_AZIMUTH=100", "SUN_ELEVATION=20"])
        self.assertEqual(ds.GetMetadataItem("SKY"), "cie:7")
        self.assertEqual(ds.GetMetadataItem("SUN_AZIMUTH"), "100")
        ds = None
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=[
            "PRODUCT=envlight", "SKY=overcast", "OUTPUT_TYPE=Byte"])
        self.assertIsNone(ds.GetMetadataItem("SUN_AZIMUTH"))
        self.assertEqual(ds.GetMetadataItem("EXPOSURE"), "0")  # not -0
        ds = None

    def test_shade_sky_term_from_a_sky(self):
        base = dict(PRODUCT="shade", OUTPUT_TYPE="Float32", SKY_WEIGHT=0.4, DIRECTIONS=8,
                    PROGRESS="no")
        uniform = T.read(T.conn(T.JACKSBORO), band=1, options=base)
        env = T.read(T.conn(T.JACKSBORO), band=1, options=dict(base, SKY="uniform"))
        d = np.nanmax(np.abs(uniform - env))
        print("shade: SKY=uniform vs the built-in uniform sky term: max |diff| %.3g" % d)
        self.assertLessEqual(d, 1e-3)
        # the sun and a CIE clear sky at 8 am on the solstice: one command
        t = T.translate(T.JACKSBORO, self.path("clear.tif"), options=dict(
            PRODUCT="shade", SKY="clear", SKY_WEIGHT=0.5, OUTPUT_TYPE="Float32",
            DATETIME="2026-06-21T08:00:00-05:00", PROGRESS="no"))
        clear = T.read(t, band=1)
        overcast = T.read(T.conn(T.JACKSBORO), band=1, options=dict(
            base, SKY="overcast", DATETIME="2026-06-21T08:00:00-05:00"))
        self.assertTrue(np.isfinite(clear).any() and np.nanmax(clear) <= 1.5)
        self.assertGreater(np.nanmax(np.abs(clear - overcast)), 0.01)
        # the map's sky term is normalised: 1 on open flat ground
        flat = self.flat_dem()
        s = T.read(T.conn(flat), band=1, options=dict(
            PRODUCT="shade", OUTPUT_TYPE="Float32", SKY_WEIGHT=1, SUN_ELEVATION=-10,
            ENV_MAP=SUNSET, PROGRESS="no"))
        self.assertTrue(np.allclose(s, 1.0, atol=1e-4), (np.nanmin(s), np.nanmax(s)))

    def test_sun_following_sky_at_night_warns(self):
        """SKY=clear (or a CIE type with a circumsolar region) with the sun
        below the horizon: the standard defines it for a sun above; the
        formula goes on, normalised, so a warning says it lights as by day.
        None for the skies that do not follow the sun, nor by day."""
        warned = "the CIE standard skies are defined for a sun above it"
        for sky, elevation, warns in (("clear", -90, True), ("cie:7", -5, True),
                                      ("cie:1", -90, False), ("overcast", -90, False),
                                      ("uniform", -90, False), ("clear", 10, False)):
            with self.subTest(sky=sky, elevation=elevation):
                err = T.open_stderr(T.JACKSBORO, PRODUCT="envlight", SKY=sky,
                                    SUN_ELEVATION=elevation)
                self.assertEqual(warned in err, warns, err)
        err = T.open_stderr(T.JACKSBORO, PRODUCT="envlight", SKY="clear", SUN_ELEVATION=-90)
        self.assertIn("Warning 1: TERRASHADE: SKY=clear with the sun 90.0 degrees below the "
                      "horizon: the CIE standard skies are defined for a sun above it.", err)

    def test_bad_input(self):
        truncated = self.path("truncated.exr")
        with open(SUNSET, "rb") as f:
            data = f.read()
        with open(truncated, "wb") as f:
            f.write(data[:len(data) // 2])
        text = self.path("text.exr")
        with open(text, "w") as f:
            f.write("this is not an OpenEXR file\n")
        nan = np.ones((16, 32, 3))
        nan[3, 5, 1] = np.nan
        nan = write_exr(self.path("nan.exr"), nan)
        wide = write_exr(self.path("wide.exr"), np.ones((10, 30, 3)))
        cases = [
            ("missing map", dict(ENV_MAP=self.path("nowhere.exr")), "no such file"),
            ("truncated map", dict(ENV_MAP=truncated), "damaged or truncated"),
            ("text named .exr", dict(ENV_MAP=text),
             "is not an OpenEXR file: it does not start with OpenEXR's magic number"),
            ("a NaN pixel", dict(ENV_MAP=nan), "NaN"),
            ("3:1 without envmap", dict(ENV_MAP=wide), "neither 2:1 (lat-long) nor 1:6"),
            ("ENV_MAP with SKY", dict(ENV_MAP=SUNSET, SKY="clear"),
             "SKY=clear excludes ENV_MAP"),
            ("cie:16", dict(SKY="cie:16"), "TERRASHADE: SKY must be uniform, overcast, "
             "clear or cie:N with N from 1 to 15, got 'cie:16'"),
            ("bad EXPOSURE", dict(SKY="uniform", OUTPUT_TYPE="Byte", EXPOSURE="bright"),
             "EXPOSURE must be AUTO or a number of stops"),
            ("EXPOSURE with Float32", dict(SKY="uniform", EXPOSURE="1"),
             "EXPOSURE applies to OUTPUT_TYPE=Byte"),
            ("no light", {}, "needs a light"),
            ("rotation of a sky", dict(SKY="overcast", ENV_ROTATION=10),
             "ENV_ROTATION turns ENV_MAP"),
            ("normal steps 1", dict(SKY="uniform", ENV_NORMAL_STEPS=1),
             "ENV_NORMAL_STEPS must be 0"),
            # even counts have no node at 0 degrees: flat open ground read 0.5 of a
            # uniform sky with 2 horizon steps, 0.875 with 4, 0.5 with 2 normal steps
            ("normal steps 2", dict(SKY="uniform", ENV_NORMAL_STEPS=2),
             "ENV_NORMAL_STEPS must be 0 (exact) or odd"),
            ("horizon steps 4", dict(SKY="uniform", ENV_HORIZON_STEPS=4),
             "ENV_HORIZON_STEPS must be odd"),
            ("horizon steps 2", dict(SKY="uniform", ENV_HORIZON_STEPS=2),
             "between 3 and 3601"),
        ]
        for name, opts, words in cases:
            with self.subTest(name):
                p = T.run(["gdal_translate", "-q"] + T.oo_args(dict(opts, PRODUCT="envlight"))
                          + [T.conn(T.JACKSBORO), self.path("bad.tif")], ok=False)
                print("%s: %s" % (name, p.stderr.strip()))
                self.assertIn(words, p.stderr)
                self.assertIn("TERRASHADE", p.stderr)
        # ENV_MAP for a product that cannot use it
        p = T.run(["gdal_translate", "-q", "-oo", "PRODUCT=svf", "-oo", "ENV_MAP=" + SUNSET,
                   T.conn(T.JACKSBORO), self.path("bad.tif")], ok=False)
        self.assertIn("ENV_MAP applies to PRODUCT=shade and PRODUCT=envlight, not to "
                      "PRODUCT=svf", p.stderr)
        p = T.run(["gdal_translate", "-q", "-oo", "SKY=clear",
                   T.conn(T.JACKSBORO), self.path("bad.tif")], ok=False)
        self.assertIn("SKY_WEIGHT > 0", p.stderr)
        # the light table's steps for shade's sky term without a SKY: it is
        # the sky-view factor's, which has no table (taken without a word
        # until session 57's audit); with a SKY they change its pixels
        for steps in ("ENV_HORIZON_STEPS=3", "ENV_NORMAL_STEPS=3"):
            p = T.run(["gdal_translate", "-q", "-oo", "SKY_WEIGHT=0.3", "-oo", steps,
                       T.conn(T.JACKSBORO), self.path("bad.tif")], ok=False)
            self.assertIn("%s sets the light table of SKY or ENV_MAP; without them "
                          "PRODUCT=shade's sky term is the sky-view factor's uniform sky"
                          % steps.split("=")[0], p.stderr)
            T.run(["gdal_translate", "-q", "-oo", "SKY_WEIGHT=0.3", "-oo", steps, "-oo",
                   "SKY=uniform", T.conn(T.JACKSBORO), self.path("ok.tif")])
            # without a sky term at all, SKY_WEIGHT is what to give (a SKY
            # alone was refused in turn: the review)
            p = T.run(["gdal_translate", "-q", "-oo", steps, T.conn(T.JACKSBORO),
                       self.path("bad.tif")], ok=False)
            self.assertIn("which SKY_WEIGHT=0 leaves out: give SKY_WEIGHT > 0 and a SKY or "
                          "ENV_MAP", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
