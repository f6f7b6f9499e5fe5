"""terrashade.distributed: a product computed as window tasks on
dask.distributed equals gdal_translate of the same source, bit for bit.

- a LocalCluster of 2 worker processes (--workers 2), small windows (12 of
  them, the last column and row cut), for shade (Byte) and horizon (4 bands
  of Float32): every band's bits, the georeferencing, nodata, band
  descriptions and metadata equal gdal_translate's;
- a COG's tiles are gdal_translate -of COG's, whatever the window size, with
  no GDAL warning;
- a worker process that dies on its first task (a test hook in
  terrashade/windows.py, once per run) is replaced, Dask retries the window,
  and the result is still identical;
- a window that fails (no retries allowed) fails the run: exit 1, the
  older DEST untouched, no DEST.partial.

An existing cluster (--scheduler) is test_distributed_cluster.py's, what the
program refuses test_distributed_refusals.py's, Ctrl-C and SIGTERM
test_distributed_interrupts.py's; their shared helpers are tsdistributed.py.
"""
import os
import re
import textwrap
import unittest

import tsdistributed as TD
import tsdriver as T
from tsdistributed import HORIZON, PYTHONPATH, SHADE, SUNHOURS, distributed
from tsdriver import gdal, np


class Distributed(TD.DistributedCase):
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

    def test_chunks_placed_on_one_worker_each(self):
        """The windows of one driver chunk go to one worker, the chunks
        dealt round the workers in order, so that no chunk is computed by
        two (1024-cell windows of 4096-cell chunks went to any worker); the
        whole raster is one chunk where the driver does not window."""
        from terrashade import windows as W
        wins = W.windows(300, 200, 64)  # chunks of 128: 3 x 2
        at = W.placement(wins, 128, ["a", "b"])
        chunk_of = {}
        for (x, y, _, _), w in zip(wins, at):
            self.assertEqual(chunk_of.setdefault((x // 128, y // 128), w), w)
        self.assertEqual([chunk_of[(cx, cy)] for cy in range(2) for cx in range(3)],
                         ["a", "b", "a", "b", "a", "b"])
        self.assertEqual(set(W.placement(wins, 0, ["a", "b"])), {"a"})
        self.assertEqual(W.placement(wins, 128, []), [None] * len(wins))

    def test_local_cluster_products(self):
        for name, options in (("shade", SHADE), ("horizon", HORIZON), ("sunhours", SUNHOURS)):
            with self.subTest(product=name):
                dest = self.path("local_%s.tif" % name)
                p = distributed(["--workers", 2, "--tile-size", 64] + T.oo_args(options)
                                + [T.conn(self.dem), dest])
                self.assertIn("from 12 windows of 64 on 2 workers", p.stderr)
                self.assertIn("Completed", p.stderr)  # the Dask progress bar
                self.assertEqual(p.stdout, "")
                self.assertEqual(TD.partials(dest), [])
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
                    import logging
                    import distributed  # (a script that uses Dask itself)
                    print("exceptions after import:", gdal.GetUseExceptions())
                    logs = lambda: [h.level for h in logging.getLogger("distributed").handlers]
                    before = logs()
                    mine = lambda *_: None
                    signal.signal(signal.SIGTERM, mine)
                    for k in range(2):
                        rc = D.main(["--workers", "1", "--tile-size", "64", "-q", "-oo",
                                     "MAX_DISTANCE=1", "TERRASHADE:PRODUCT=svf,DIRECTIONS=4:"
                                     + sys.argv[1], sys.argv[2] + str(k) + ".tif"])
                        print("run", k, "rc", rc, file=sys.stderr)
                    # a usage error is returned as the command's status, not raised
                    print("bad tile size rc", D.main(["--tile-size", "17", "x", "y.tif"]))
                    print("exceptions after main:", gdal.GetUseExceptions())
                    print("Dask's log levels as they were:", logs() == before, before)
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
        self.assertIn("Dask's log levels as they were: True", p.stdout)
        self.assertIn("SIGTERM is mine: True", p.stdout)
        # its two warnings: MAX_DISTANCE=1 m against 30 m cells, and the
        # DEM's 900 m void wider than it
        self.assertIn("window (1, 8, 8) 2", p.stdout)
        self.assertIn("missing DEM raised: True", p.stdout)
        self.assertIn("bad tile size rc 2", p.stdout)
        said = "Warning 1: TERRASHADE: MAX_DISTANCE=1 m is shorter than the DEM's cells"
        self.assertEqual(p.stderr.count(said), 2, p.stderr)
        self.assertIn("run 1 rc 0", p.stderr)
        for k in range(2):
            self.assert_identical(self.path("script_out%d.tif" % k), self.reference(
                {"PRODUCT": "svf", "DIRECTIONS": 4, "MAX_DISTANCE": 1}, "ref_script.tif"))

    def test_relative_env_map_is_made_absolute(self):
        """As the DEM: a relative ENV_MAP, inline or by -oo, was read in each
        worker's working directory (on an existing cluster another map of
        that name: a forest's light under the sunset's metadata)."""
        from terrashade import distributed as D
        here = os.getcwd()
        os.chdir(self.dir)
        try:
            with open("env.exr", "wb") as f:
                f.write(b"v/1\x01")
            whole = os.path.join(os.path.realpath(self.dir), "env.exr")
            src, oo = D.absolute_env_map("TERRASHADE:PRODUCT=envlight,env_map=env.exr:dem.tif",
                                         ["DIRECTIONS=8", "env_map = gone.exr"])
            # (inline, moved to the open options: an absolute path may hold
            # the ':' or ',' that end an inline value)
            self.assertEqual(src, "TERRASHADE:PRODUCT=envlight:dem.tif")
            self.assertEqual(oo, ["DIRECTIONS=8", "env_map = gone.exr", "ENV_MAP=" + whole])
            self.assertEqual(D.absolute_env_map("TERRASHADE:ENV_MAP=env.exr:dem.tif",
                                                ["ENV_MAP=env.exr"]),
                             ("TERRASHADE:dem.tif", ["ENV_MAP=" + whole, "ENV_MAP=" + whole]))
            self.assertEqual(D.absolute_env_map("TERRASHADE:dem.tif", ["ENV_MAP=/abs.exr"]),
                             ("TERRASHADE:dem.tif", ["ENV_MAP=/abs.exr"]))
        finally:
            os.chdir(here)

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
        # the program's sentence alone: Dask's ERROR lines ("Couldn't gather
        # keys", "Shut down workers that don't have promised key") came first
        self.assertNotIn(" - ERROR - ", p.stderr)
        with open(dest) as f:
            self.assertEqual(f.read(), "an older result")  # DEST untouched
        os.remove(dest)
        self.assert_nothing_left(dest)


if __name__ == "__main__":
    unittest.main(verbosity=2)
