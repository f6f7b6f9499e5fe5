"""terrashade.distributed: what it refuses. Bad input (an unwritable
destination or one that is a directory or the DEM, a SOURCE the driver
refuses, bad tile sizes, a Python without GDAL's bindings): a clear message,
a non-zero exit and neither DEST nor DEST.partial left behind.
"""
import os
import unittest

import tsdistributed as TD
import tsdriver as T
from tsdistributed import PYTHONPATH, distributed


class DistributedRefusals(TD.DistributedCase):
    def test_destination_is_a_directory(self):
        """Refused before any work, not when the finished result is renamed."""
        dest = self.path("adir.tif")
        os.mkdir(dest)
        try:
            p = distributed(["--workers", 1, T.conn(self.dem), dest], ok=False)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("cannot write %s: it is a directory" % dest, p.stderr)
            self.assertNotIn("Traceback", p.stderr)
            self.assertEqual(os.listdir(dest), [])
            self.assertFalse(os.path.exists(dest + ".partial"))
        finally:
            os.rmdir(dest)

    def test_partial_name_is_a_directory(self):
        """DEST.partial taken by a directory: GDAL's reason, not the cleanup's
        IsADirectoryError, and the directory is left alone."""
        dest = self.path("taken.tif")
        os.mkdir(dest + ".partial")
        try:
            p = distributed(["--workers", 1, T.conn(self.dem), dest], ok=False)
            self.assertEqual(p.returncode, 1, p.stderr)
            self.assertIn("cannot write %s.partial: " % dest, p.stderr)
            self.assertTrue(os.path.isdir(dest + ".partial"))
            self.assertFalse(os.path.exists(dest))
        finally:
            os.rmdir(dest + ".partial")

    def test_destination_is_the_dem(self):
        """DEST naming the DEM (here by another path) is refused before any
        work: the rename at the end would replace the DEM by the product."""
        with open(self.dem, "rb") as f:
            before = f.read()
        dest = os.path.join(self.dir, ".", os.path.basename(self.dem))
        p = distributed(["--workers", 1, T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn("is the DEM itself", p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        with open(self.dem, "rb") as f:
            self.assertEqual(f.read(), before)
        self.assertFalse(os.path.exists(dest + ".partial"))

    def test_python_without_gdal(self):
        """A Python that cannot import osgeo (python3 first on PATH is often
        not the system one): a sentence and exit 1, even for --help."""
        blocked = ("import sys, runpy; sys.modules['osgeo'] = None; "
                   "sys.argv[0] = 'terrashade.distributed'; "
                   "runpy.run_module('terrashade.distributed', run_name='__main__')")
        for args in (["--help"], [T.conn(self.dem), self.path("nogdal.tif")]):
            with self.subTest(args[0]):
                p = T.run(["/usr/bin/python3", "-c", blocked] + args, ok=False,
                          PYTHONPATH=PYTHONPATH)
                self.assertEqual(p.returncode, 1, p.stderr)
                self.assertIn("terrashade.distributed: error: this Python", p.stderr)
                self.assertIn("cannot import GDAL's bindings", p.stderr)
                self.assertNotIn("Traceback", p.stderr)
        self.assert_nothing_left(self.path("nogdal.tif"))

    def test_bad_input(self):
        missing_dir = self.path("no/such/dir/out.tif")
        cases = [
            ("unwritable destination", [T.conn(self.dem)],
             "cannot write %s.partial" % missing_dir, missing_dir),
            ("driver refuses SOURCE", ["-oo", "PRODUCT=hillshade", T.conn(self.dem)],
             "PRODUCT must be one of", None),
            ("missing DEM", [T.conn(self.path("nodem.tif"))],
             "cannot open the DEM", None),
            ("not a TERRASHADE source", [self.dem],
             "SOURCE must be a TERRASHADE connection string", None),
            ("tile size not a multiple of 16", ["--tile-size", 100, T.conn(self.dem)],
             "must be a multiple of 16 between 16 and 65536 (GeoTIFF tiles are "
             "multiples of 16), got 100", None),
            ("tile size 0", ["--tile-size", 0, T.conn(self.dem)],
             "must be a multiple of 16", None),
            ("tile size not a number", ["--tile-size", "big", T.conn(self.dem)],
             "must be a whole number, got 'big'", None),
            ("unknown format", [T.conn(self.dem)], "cannot tell the format", "out.png"),
            # renamed into place at the end: a /vsi path failed only then, after
            # all the work (/vsimem/), or left an empty archive (/vsizip/)
            ("virtual DEST in memory", [T.conn(self.dem)],
             "cannot write /vsimem/out.tif: DEST must be a file path", "/vsimem/out.tif"),
            ("virtual DEST in a zip", [T.conn(self.dem)],
             "DEST must be a file path", "/vsizip/" + self.path("out.zip") + "/out.tif"),
        ]
        for what, args, message, dest in cases:
            with self.subTest(what):
                if not (dest and os.path.isabs(dest)):
                    dest = self.path(dest or "bad.tif")
                p = distributed(["--workers", 1] + args + [dest], ok=False)
                self.assertIn(message, p.stderr)
                self.assertNotIn("Traceback", p.stderr)
                self.assert_nothing_left(dest)
        self.assertFalse(os.path.exists(self.path("out.zip")), "an archive was left behind")


if __name__ == "__main__":
    unittest.main(verbosity=2)
