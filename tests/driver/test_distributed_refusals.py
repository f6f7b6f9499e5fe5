"""terrashade.distributed: what it refuses. Bad input (an unwritable
destination or one that is a directory or the DEM, a SOURCE the driver
refuses, bad tile sizes, a Python without GDAL's bindings): a clear message,
a non-zero exit and neither DEST nor DEST.partial left behind.
"""
import os
import unittest

import tsdistributed as TD
import tsdriver as T
from tsdriver import gdal
from tsdistributed import PYTHONPATH, distributed


class DistributedRefusals(TD.DistributedCase):
    def refused_before_work(self, dest, text, source=None, said=None):
        """A run to dest exits 1 with 'cannot write dest: text' (or said),
        before any work: no partial."""
        p = distributed(["--workers", 1, source or T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn(said or "cannot write %s: %s" % (dest, text), p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        self.assertEqual(TD.partials(dest), [])

    def test_destination_is_a_directory(self):
        """Refused before any work, not when the finished result is renamed."""
        dest = self.path("adir.tif")
        os.mkdir(dest)
        try:
            self.refused_before_work(dest, "it is a directory")
            self.assertEqual(os.listdir(dest), [])
        finally:
            os.rmdir(dest)

    def test_destination_is_a_pipe(self):
        """A pipe (or a device) as DEST was replaced by a regular file, with
        exit 0: the result is renamed into place (session 54's audit; as root,
        /dev/null). Refused before any work; the pipe stays a pipe."""
        import stat
        dest = self.path("fifo.tif")
        os.mkfifo(dest)
        try:
            self.refused_before_work(dest, "it is not a regular file")
            self.assertTrue(stat.S_ISFIFO(os.stat(dest).st_mode))
        finally:
            os.remove(dest)

    def test_driver_prefix_parts_kept(self):
        """In another driver's name only the file's part is made absolute:
        with a file named GTIFF_DIR and a folder named 1 in the working
        directory, GTIFF_DIR:1:dem.tif became /cwd/GTIFF_DIR:/cwd/1:/cwd/dem.tif,
        and the run failed; NETCDF:"dem.tif":z took a file z's path. An
        archive's relative path in /vsizip/ was left relative (session 54)."""
        from terrashade._distributed_inputs import absolute_source
        here = os.getcwd()
        work = self.path("prefix_parts")
        os.mkdir(work)
        try:
            os.chdir(work)
            for name in ("GTIFF_DIR", "dem.tif", "z", "a.zip"):
                open(name, "w").close()
            os.mkdir("1")
            self.assertEqual(absolute_source("TERRASHADE:GTIFF_DIR:1:dem.tif"),
                             "TERRASHADE:GTIFF_DIR:1:" + os.path.join(work, "dem.tif"))
            # nor what follows the file (a variable named as a file here)
            self.assertEqual(absolute_source('TERRASHADE:NETCDF:"dem.tif":z'),
                             'TERRASHADE:NETCDF:"%s":z' % os.path.join(work, "dem.tif"))
            # an archive's relative path, as the driver's levels take it
            self.assertEqual(absolute_source("TERRASHADE:/vsizip/a.zip/dem.tif"),
                             "TERRASHADE:/vsizip/%s/dem.tif" % os.path.join(work, "a.zip"))
            self.assertEqual(absolute_source("TERRASHADE:/vsizip/{a.zip}/dem.tif"),
                             "TERRASHADE:/vsizip/{%s}/dem.tif" % os.path.join(work, "a.zip"))
        finally:
            os.chdir(here)

    def test_partials_are_the_runs_own(self):
        """Two runs writing one DEST at once shared DEST.partial: the one
        still running wrote into the file the other had renamed to DEST
        (garbage there, after a success). Each run's partial is named by its
        machine, process and a random part now, and another's is never
        touched (on another host or in a container its process number says
        nothing here)."""
        from terrashade._distributed_output import partial_names
        dest = self.path("own.tif")
        a, b = partial_names(dest), partial_names(dest)
        self.assertNotEqual(a, b)
        self.assertTrue(a[1].startswith(dest + ".") and a[1].endswith(".partial"))
        others = [dest + ".partial", dest + ".otherhost-1-0123abcd.partial"]
        for f in others:
            with open(f, "w") as fh:
                fh.write("not ours")
        try:
            distributed(["--workers", 1, "--tile-size", 64, "-q", T.conn(self.dem), dest])
            self.assert_identical(dest, self.reference({}, "ref_own.tif"))
            self.assertEqual(sorted(TD.partials(dest)), sorted(others))
        finally:
            for f in others:
                os.remove(f)

    def test_a_worker_without_the_plugin_names_it(self):
        """A worker that joins after the start's check, without the plugin:
        GDAL's open failed with no message ('cannot open ...: ')."""
        p = T.run(["/usr/bin/python3", "-c",
                   "from terrashade import windows as W\n"
                   "W.read_window(%r, [], (0, 0, 8, 8), 'r')" % T.conn(self.dem)],
                  ok=False, PYTHONPATH=PYTHONPATH, GDAL_DRIVER_PATH="/nonexistent")
        self.assertIn("cannot find the TERRASHADE driver: set GDAL_DRIVER_PATH there "
                      "(now '/nonexistent')", p.stderr)

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
        self.assertEqual(TD.partials(dest), [])

    def test_destination_is_a_source_of_a_vrt_dem(self):
        """DEST naming a source of the VRT that SOURCE reads: the DEM's
        heights were replaced by the product, with exit 0 (session 54's
        paths audit)."""
        src = self.path("vrt_src.tif")
        T.shutil.copy(self.dem, src)
        vrt = self.path("via.vrt")
        gdal.BuildVRT(vrt, [src])
        with open(src, "rb") as f:
            before = f.read()
        self.refused_before_work(src, None, source=T.conn(vrt),
                                 said="DEST %s is a file of the DEM %s" % (src, vrt))
        with open(src, "rb") as f:
            self.assertEqual(f.read(), before)

    def test_destination_is_the_dems_archive(self):
        """DEST naming the archive SOURCE reads the DEM from (/vsizip/,
        /vsigzip/, braces, and a VRT's source inside a zip): the archive
        was replaced by the product with exit 0, the DEM lost (session 59's
        Python audit)."""
        import gzip
        import zipfile
        zipped, gz = self.path("dem.zip"), self.path("dem.tif.gz")
        with zipfile.ZipFile(zipped, "w") as z:
            z.write(self.dem, "dem.tif")
        with open(self.dem, "rb") as f, gzip.open(gz, "wb") as g:
            g.write(f.read())
        vrt = self.path("zipped.vrt")
        gdal.BuildVRT(vrt, ["/vsizip/%s/dem.tif" % zipped])
        # archives within archives: the outer file is the one replaced (the
        # first review: refused only where the outer name was a file itself)
        import tarfile
        tgz, zgz = self.path("dem.tar.gz"), self.path("nest.zip.gz")
        with tarfile.open(tgz, "w:gz") as t:
            t.add(self.dem, "dem.tif")
        with open(zipped, "rb") as f, gzip.open(zgz, "wb") as g:
            g.write(f.read())
        itself = "DEST %s is the DEM itself (its archive, for %s)"
        for archive, source, said in (
                (zipped, "/vsizip/%s/dem.tif" % zipped, itself),
                (zipped, "/vsizip/{%s}/dem.tif" % zipped, itself),
                (gz, "/vsigzip/%s" % gz, itself),
                (tgz, "/vsitar//vsigzip/%s/dem.tif" % tgz, itself),
                (zgz, "/vsizip/{/vsigzip/%s}/dem.tif" % zgz, itself),
                (zipped, vrt, "DEST %s is a file of the DEM %s")):
            with self.subTest(source=source):
                with open(archive, "rb") as f:
                    before = f.read()
                p = distributed(["--workers", 1, "--format", "GTiff", T.conn(source), archive],
                                ok=False)
                self.assertEqual(p.returncode, 1, p.stderr)
                self.assertIn(said % (archive, source), p.stderr)
                with open(archive, "rb") as f:
                    self.assertEqual(f.read(), before)
                self.assertEqual(TD.partials(archive), [])

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
             "cannot write %s." % missing_dir, missing_dir),
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
