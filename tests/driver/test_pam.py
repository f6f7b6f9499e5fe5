"""PAM goes next to the DEM, into the products' own <DEM>.terrashade.aux.xml
(not the DEM's .aux.xml), one entry per set of options, never into the
current directory; a nodata value, unit or colour the user sets there is
what the band reports, on that product and options only. Entries written
into the DEM's own .aux.xml before are still read. Threads saving several
products' statistics at once keep every entry, and so do processes, which
never touch the DEM's own file (its georeferencing, for a PNG DEM)."""
import gzip
import math
import os
import shutil
import subprocess
import unittest
import xml.etree.ElementTree as ET

import tsdriver as T
from tsdriver import gdal, np, osr


class Pam(unittest.TestCase):
    def setUp(self):
        self.tmp = T.TempDir()
        root = self.tmp.__enter__()
        self.demdir = os.path.join(root, "dems")
        self.cwd = os.path.join(root, "cwd")
        os.makedirs(self.demdir)
        os.makedirs(self.cwd)
        self.dem = os.path.join(self.demdir, "jacksboro.tif")
        shutil.copy(T.JACKSBORO, self.dem)

    def tearDown(self):
        self.tmp.__exit__(None, None, None)

    def assertCwdClean(self):
        left = os.listdir(self.cwd)
        print("files left in the current directory:", left)
        self.assertEqual(left, [])

    def test_gdalinfo_stats_in_a_temp_cwd(self):
        for name in (self.dem, os.path.relpath(self.dem, self.cwd)):
            for conn in (T.conn(name), T.conn(name, PRODUCT="svf", DIRECTIONS=4)):
                with self.subTest(conn=conn):
                    p = T.run(["gdalinfo", "-stats", conn], cwd=self.cwd)
                    self.assertIn("STATISTICS_MEAN", p.stdout)
                    self.assertCwdClean()
        aux = self.dem + ".terrashade.aux.xml"
        self.assertFalse(os.path.exists(self.dem + ".aux.xml"), os.listdir(self.demdir))
        self.assertTrue(os.path.exists(aux), os.listdir(self.demdir))
        subs = [s.get("name") for s in ET.parse(aux).getroot().iter("Subdataset")]
        print("subdatasets in %s: %s" % (os.path.basename(aux), subs))
        self.assertTrue(any("PRODUCT=shade" in s for s in subs))
        self.assertTrue(any("PRODUCT=svf" in s for s in subs))
        # the statistics come back from there
        p = T.run(["gdalinfo", T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)],
                  cwd=self.cwd)
        self.assertIn("STATISTICS_MEAN", p.stdout)
        self.assertCwdClean()

    def test_python_statistics(self):
        old = os.getcwd()
        os.chdir(self.cwd)
        try:
            ds = gdal.Open(T.conn(self.dem, PRODUCT="shadow", SUN_ELEVATION=10))
            ds.GetRasterBand(1).ComputeStatistics(False)
            ds.GetRasterBand(1).SetDescription("changed")
            ds = None
        finally:
            os.chdir(old)
        self.assertCwdClean()
        self.assertTrue(os.path.exists(self.dem + ".terrashade.aux.xml"))

    def test_chdir_before_the_save(self):
        """A DEM opened by a relative name, then a chdir before the dataset
        closes: the statistics go beside the DEM, not into the new current
        directory (they did until session 54)."""
        old = os.getcwd()
        os.chdir(self.demdir)
        try:
            ds = gdal.Open(T.conn("jacksboro.tif", PRODUCT="svf", DIRECTIONS=4))
            ds.GetRasterBand(1).ComputeStatistics(False)
            os.chdir(self.cwd)
            ds = None
        finally:
            os.chdir(old)
        self.assertCwdClean()
        self.assertTrue(os.path.exists(self.dem + ".terrashade.aux.xml"))

    def test_dem_without_a_file(self):
        """A /vsimem DEM: no .aux.xml anywhere, no error."""
        with open(T.LUX, "rb") as f:
            gdal.FileFromMemBuffer("/vsimem/pam_lux.tif", f.read())
        p = T.run(["gdalinfo", "-stats", T.conn(self.dem)], cwd=self.cwd)
        ds = gdal.Open(T.conn("/vsimem/pam_lux.tif"))
        ds.GetRasterBand(1).ComputeStatistics(False)
        ds = None
        self.assertCwdClean()
        gdal.Unlink("/vsimem/pam_lux.tif")
        self.assertNotIn("ERROR", p.stderr)

    @staticmethod
    def band_says(ds_or_name):
        """(nodata, unit, colour name) of band 1 of a dataset; NaN as "nan"
        so that tuples compare."""
        ds = gdal.Open(ds_or_name) if isinstance(ds_or_name, str) else ds_or_name
        b = ds.GetRasterBand(1)
        nd = b.GetNoDataValue()
        return ("nan" if nd is not None and math.isnan(nd) else nd, b.GetUnitType(),
                gdal.GetColorInterpretationName(b.GetColorInterpretation()))

    def test_user_nodata_unit_and_colour(self):
        """What SetNoDataValue, SetUnitType and SetColorInterpretation set
        is reported by the dataset, by its overview levels and after
        reopening; never by other options, another product or the DEM; the
        pixels stay the product's."""
        conn = T.conn(self.dem, PRODUCT="shade")
        own = self.band_says(conn)
        other_sun = T.conn(self.dem, PRODUCT="shade", SUN_AZIMUTH=200)
        svf = T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)
        others = {c: self.band_says(c) for c in (other_sun, svf, self.dem)}
        print("before:", own, others)
        self.assertEqual(own, (0.0, "", "Gray"))
        fresh_ds = gdal.Open(conn)
        fresh = fresh_ds.GetRasterBand(1).ReadAsArray()
        fresh_ds = None
        ds = gdal.Open(conn)
        b = ds.GetRasterBand(1)
        b.SetNoDataValue(7)
        b.SetUnitType("brightness")
        b.SetColorInterpretation(gdal.GCI_RedBand)
        mine = (7.0, "brightness", "Red")
        self.assertEqual(self.band_says(ds), mine)
        self.assertEqual(b.GetOverview(0).GetNoDataValue(), 7.0)
        self.assertEqual(b.GetOverview(0).GetUnitType(), "brightness")
        np.testing.assert_array_equal(b.ReadAsArray(), fresh)
        ds = b = None
        self.assertEqual(self.band_says(conn), mine)
        for c, said in others.items():
            self.assertEqual(self.band_says(c), said, c)
        # dropping the value set gives back the product's own, for good
        ds = gdal.Open(conn)
        ds.GetRasterBand(1).DeleteNoDataValue()
        ds = None
        self.assertEqual(self.band_says(conn)[0], 0.0)
        # the product's own cannot be dropped; a level takes nothing
        ds = gdal.Open(conn)
        with self.assertRaises(RuntimeError) as e:
            ds.GetRasterBand(1).DeleteNoDataValue()
        print(e.exception)
        self.assertIn("product's own", str(e.exception))
        self.assertIn("gdal_translate -a_nodata none", str(e.exception))
        self.assertEqual(gdal.GetLastErrorNo(), gdal.CPLE_NotSupported)
        with self.assertRaises(RuntimeError) as e:
            ds.GetRasterBand(1).GetOverview(0).SetNoDataValue(3)
        print(e.exception)
        self.assertIn("full-resolution band", str(e.exception))
        self.assertEqual(ds.GetRasterBand(1).GetNoDataValue(), 0.0)

    def test_scale_and_offset(self):
        """SetScale and SetOffset: kept, reported by the overview levels
        (they reported none, so gdal_translate -ovr 0 lost them: session
        57's GDAL API audit), refused on a level."""
        conn = T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)
        ds = gdal.Open(conn)
        b = ds.GetRasterBand(1)
        self.assertEqual((b.GetScale(), b.GetOffset()), (None, None))  # none set
        b.SetScale(0.5)
        b.SetOffset(10)
        self.assertEqual((b.GetOverview(0).GetScale(), b.GetOverview(0).GetOffset()),
                         (0.5, 10.0))
        with self.assertRaises(RuntimeError) as e:
            b.GetOverview(0).SetScale(2)
        self.assertIn("full-resolution band", str(e.exception))
        ds = b = None
        ds = gdal.Open(conn)
        b = ds.GetRasterBand(1)
        self.assertEqual((b.GetScale(), b.GetOffset()), (0.5, 10.0))
        self.assertEqual((b.GetOverview(0).GetScale(), b.GetOverview(0).GetOffset()),
                         (0.5, 10.0))
        ds = b = None
        out = os.path.join(self.tmp.path, "level.tif")
        T.run(["gdal_translate", "-q", "-ovr", "0", conn, out])
        ds = gdal.Open(out)
        self.assertEqual((ds.GetRasterBand(1).GetScale(), ds.GetRasterBand(1).GetOffset()),
                         (0.5, 10.0))

    def test_georeferencing_is_the_dems(self):
        """SetGeoTransform and SetSpatialRef on a product are refused: GDAL's
        PAM took them, saved them in the products' file and reported the
        DEM's all the same (session 57's GDAL API audit)."""
        conn = T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)
        ds = gdal.Open(conn)
        gt = ds.GetGeoTransform()
        srs = osr.SpatialReference()
        srs.ImportFromEPSG(4326)
        for call in (lambda: ds.SetGeoTransform([0, 1, 0, 0, 0, -1]),
                     lambda: ds.SetSpatialRef(srs)):
            with self.assertRaises(RuntimeError) as e:
                call()
            print(e.exception)
            self.assertIn("georeferencing is its DEM's", str(e.exception))
            self.assertIn("gdal_edit.py", str(e.exception))
        self.assertEqual(ds.GetGeoTransform(), gt)
        ds = None
        aux = self.dem + ".terrashade.aux.xml"
        if os.path.exists(aux):
            with open(aux) as f:
                text = f.read()
            self.assertNotIn("<GeoTransform>", text)
            self.assertNotIn("<SRS", text)

    def test_generic_delete_leaves_the_dem(self):
        """A product has no files of its own: GDAL's generic Delete through
        another driver (gdalmanage delete -f GTiff TERRASHADE:dem.tif)
        unlinked what the product's file list named, the DEM and the
        products' .aux.xml (session 57's GDAL API audit)."""
        conn = T.conn(self.dem)
        T.run(["gdalinfo", "-stats", conn], cwd=self.cwd)
        before = sorted(os.listdir(self.demdir))
        self.assertIn("jacksboro.tif.terrashade.aux.xml", before)
        ds = gdal.Open(conn)
        self.assertFalse(ds.GetFileList())
        ds = None
        p = T.run(["gdalmanage", "delete", "-f", "GTiff", conn], ok=None, cwd=self.cwd)
        print(p.stdout, p.stderr)
        self.assertIn("Unable to determine files associated", p.stderr)
        with self.assertRaises(RuntimeError):
            gdal.GetDriverByName("GTiff").Delete(conn)
        self.assertEqual(sorted(os.listdir(self.demdir)), before)
        self.assertIn("STATISTICS_MEAN", T.run(["gdalinfo", conn], cwd=self.cwd).stdout)

    def test_gdal_edit(self):
        """gdal_edit.py -ro on a connection string: kept in the DEM's
        .aux.xml, shown by gdalinfo, copied by gdal_translate. Without -ro
        the refusal says to use it."""
        conn = T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)
        p = T.run(["gdal_edit.py", "-a_nodata", "-1", conn], ok=False, cwd=self.cwd)
        self.assertIn("gdal_edit.py -ro", p.stderr)
        T.run(["gdal_edit.py", "-ro", "-a_nodata", "-1", "-units", "fraction", conn],
              cwd=self.cwd)
        self.assertCwdClean()
        info = T.run(["gdalinfo", conn]).stdout
        self.assertIn("NoData Value=-1", info)
        self.assertIn("Unit Type: fraction", info)
        out = os.path.join(self.tmp.path, "svf.tif")
        T.run(["gdal_translate", "-q", conn, out])
        self.assertEqual(self.band_says(out)[:2], (-1.0, "fraction"))
        # 16 directions, not 4: another entry
        self.assertEqual(self.band_says(T.conn(self.dem, PRODUCT="svf"))[:2], ("nan", ""))

    def test_a_failed_save_keeps_the_file(self):
        """A save that fails (a full disk; here a file-size limit) leaves the
        products' file as it was: GDAL rewrote it in place, and a write cut
        short left it truncated, every product's entries lost, the nodata
        and unit a user set among them (session 54's audit). The former
        bytes are written back, in place, and the dataset's close does not
        try again. A save changes the file, not what it is: a symbolic link
        stays one, and nothing is written where GDAL saves nothing
        (GDAL_PAM_ENABLED=NO: a first version of this fix, which saved to a
        copy renamed over the file, left an empty file there, and replaced
        links)."""
        conn = T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)
        T.run(["gdal_edit.py", "-ro", "-a_nodata", "7", "-units", "furlong", conn])
        T.run(["gdalinfo", "-stats", T.conn(self.dem)])
        aux = self.dem + ".terrashade.aux.xml"
        with open(aux, "rb") as f:
            before = f.read()
        # a limit above the file's size: the copy is written, GDAL's save of
        # one more entry into it is cut short
        limit = len(before) + 200
        child = ("import os, resource, signal\n"
                 "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
                 "resource.setrlimit(resource.RLIMIT_FSIZE, (%d, %d))\n"
                 "os.execvp('gdalinfo', ['gdalinfo', '-stats', '-oo', 'PRODUCT=openness', %r])\n"
                 % (limit, limit, T.conn(self.dem)))
        p = T.run(["/usr/bin/python3", "-c", child])  # (a warning: the product was shown)
        self.assertIn("nable to save auxiliary information", p.stderr)
        with open(aux, "rb") as f:
            self.assertEqual(f.read(), before)
        self.assertEqual(self.band_says(conn)[:2], (7.0, "furlong"))
        self.assertIn("Unable to save auxiliary information in %s" % aux, p.stderr)
        # a link stays a link, its target saved into
        store = os.path.join(self.tmp.path, "store.xml")
        shutil.move(aux, store)
        os.symlink(store, aux)
        T.run(["gdalinfo", "-stats", T.conn(self.dem, PRODUCT="sky", DIRECTIONS=4)])
        self.assertTrue(os.path.islink(aux))
        with open(store) as f:
            self.assertIn("PRODUCT=sky", f.read())
        # nothing written where GDAL saves nothing
        os.remove(aux)
        T.run(["gdalinfo", "-stats", conn], GDAL_PAM_ENABLED="NO")
        self.assertEqual(sorted(os.listdir(self.demdir)), ["jacksboro.tif"])

    def test_long_env_map_paths_are_two_entries(self):
        """Two ENV_MAP paths alike in their first 120 characters: two
        entries, each with its own statistics and nodata, and the whole
        path in the key and the metadata."""
        maps = os.path.join(self.tmp.path, "environment-maps-" + "x" * 100)
        os.makedirs(maps)
        paths = [shutil.copy(os.path.join(T.DATA, "envmaps", f), maps)
                 for f in ("city.exr", "forest.exr")]
        conns = [T.conn(self.dem, PRODUCT="envlight", ENV_MAP=p) for p in paths]
        means = []
        for c in conns:
            T.run(["gdalinfo", "-stats", c], cwd=self.cwd)
            ds = gdal.Open(c)
            means.append(float(ds.GetRasterBand(1).GetMetadataItem("STATISTICS_MEAN")))
            self.assertEqual(ds.GetMetadataItem("ENV_MAP"), paths[len(means) - 1])
            ds = None
        print("envlight means (city, forest):", means)
        self.assertNotAlmostEqual(means[0], means[1], 3)
        T.run(["gdal_edit.py", "-ro", "-a_nodata", "-1", conns[0]], cwd=self.cwd)
        self.assertEqual(self.band_says(conns[0])[0], -1.0)
        self.assertEqual(self.band_says(conns[1])[0], "nan")
        subs = [s.get("name") for s in
                ET.parse(self.dem + ".terrashade.aux.xml").getroot().iter("Subdataset")]
        for p in paths:
            self.assertTrue(any("ENV_MAP=" + p in s for s in subs), (p, subs))

    def test_atlas(self):
        """An atlas's band: the user's nodata and colour, kept in the
        atlas's .aux.xml."""
        tsa = os.path.join(self.demdir, "a.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + T.oo_args(dict(
            PRODUCT="farshadow", DATE="2026-12-21", TIMEZONE="-05:00", ATLAS_STEPS=2,
            FAR_THRESHOLD=4)) + [T.conn(self.dem), tsa])
        self.assertEqual(self.band_says(tsa), (255.0, "", "Gray"))
        ds = gdal.Open(tsa)
        ds.GetRasterBand(1).SetNoDataValue(1)
        ds.GetRasterBand(1).SetColorInterpretation(gdal.GCI_AlphaBand)
        ds = None
        self.assertEqual(self.band_says(tsa), (1.0, "", "Alpha"))
        ds = gdal.Open(tsa)
        self.assertEqual(ds.GetRasterBand(2).GetNoDataValue(), 255.0)
        self.assertTrue(os.path.exists(tsa + ".aux.xml"))

    def test_atlas_views_keep_their_own_entries(self):
        """An atlas read with SHADOWS=all is other pixels than the atlas
        alone: its statistics and histograms have an entry of their own in
        the atlas's .aux.xml. The two views shared one: each reported the
        other's statistics, and once the SHADOWS=all view had saved, the
        plain atlas said SHADOWS=all, so that gdal_translate -of TERRASHADE
        refused to copy it (session 57's GDAL API audit)."""
        tsa = os.path.join(self.demdir, "v.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + T.oo_args(dict(
            PRODUCT="farshadow", DATE="2026-12-21", TIMEZONE="-05:00", ATLAS_STEPS=4,
            FAR_THRESHOLD=24)) + [T.conn(self.dem), tsa])

        def mean(*oo):
            ds = gdal.OpenEx(tsa, gdal.OF_RASTER, open_options=list(oo))
            return ds.GetRasterBand(1).ComputeStatistics(False)[2]

        far, both = mean(), mean("SHADOWS=all")
        print("means: far %.4f, all %.4f" % (far, both))
        self.assertNotAlmostEqual(far, both, places=3)
        for oo, want in (((), far), (("SHADOWS=all",), both)):
            ds = gdal.OpenEx(tsa, gdal.OF_RASTER, open_options=list(oo))
            self.assertAlmostEqual(ds.GetRasterBand(1).GetStatistics(False, False)[2], want)
            ds.GetRasterBand(1).GetHistogram(0, 1, 2, approx_ok=0)
            ds = None
        ds = gdal.Open(tsa)
        self.assertIsNone(ds.GetMetadataItem("SHADOWS"))
        ds = None
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE", tsa,
               os.path.join(self.demdir, "copy.tsa")])
        # an entry of the file's top level (written before session 57) is
        # still read by the atlas's own view, and kept as its entry
        # (its statistics may be the other view's, which one entry served:
        # computed again, the review)
        with open(tsa + ".aux.xml", "w") as f:
            f.write('<PAMDataset><PAMRasterBand band="1"><NoDataValue>7</NoDataValue>'
                    '<Metadata><MDI key="STATISTICS_MEAN">%r</MDI><MDI key="STATISTICS_'
                    'MINIMUM">0</MDI><MDI key="STATISTICS_MAXIMUM">1</MDI><MDI key="'
                    'STATISTICS_STDDEV">0.5</MDI></Metadata>'
                    '</PAMRasterBand></PAMDataset>\n' % both)
        for trial in range(2):
            ds = gdal.Open(tsa)
            self.assertEqual(ds.GetRasterBand(1).GetNoDataValue(), 7.0)
            if trial == 0:
                self.assertEqual(ds.GetRasterBand(1).GetStatistics(False, False),
                                 [0, 0, 0, -1])
            ds.GetRasterBand(1).ComputeStatistics(False)
            ds = None
        ds = gdal.OpenEx(tsa, gdal.OF_RASTER, open_options=["SHADOWS=all"])
        self.assertEqual(ds.GetRasterBand(1).GetNoDataValue(), 255.0)
        ds = None
        # DEM= is read from the working directory: its entry is keyed by the
        # absolute path, so that two DEMs of one relative name keep their
        # own statistics (the review)
        other = os.path.join(self.cwd, "jacksboro.tif")
        T.run(["gdal_translate", "-q", "-scale", "0", "1", "0", "3", "-ot", "Float32",
               self.dem, other])
        means = []
        for folder in (self.demdir, self.cwd):
            old = os.getcwd()
            os.chdir(folder)
            try:
                ds = gdal.OpenEx(tsa, gdal.OF_RASTER,
                                 open_options=["SHADOWS=all", "DEM=jacksboro.tif"])
                self.assertEqual(ds.GetRasterBand(1).GetStatistics(False, False),
                                 [0, 0, 0, -1])
                means.append(ds.GetRasterBand(1).ComputeStatistics(False)[2])
                ds = None
            finally:
                os.chdir(old)
        print("SHADOWS=all means with DEM=jacksboro.tif in two folders:", means)
        self.assertNotAlmostEqual(means[0], means[1], places=3)
        with open(tsa + ".aux.xml") as f:
            text = f.read()
        self.assertIn('name="SHADOWS=all:DEM=%s"' % self.dem, text)
        self.assertIn('name="SHADOWS=all:DEM=%s"' % other, text)

    def test_atlas_statistics_follow_the_dems_contents(self):
        """SHADOWS=all's statistics are of the atlas's far shadows and the
        DEM's near ones: saved, then the DEM regenerated under its name
        with other heights, they were reported again as the view's (its
        entry kept no stamp of the DEM, as a product's does: session 57's
        closing note). Dropped now; the far view's, of the atlas alone,
        stay; and a copy of another atlas over the file drops those too."""
        d = os.path.join(self.demdir, "stamp")
        os.makedirs(d)
        dem = os.path.join(d, "dem.tif")
        T.run(["gdal_translate", "-q", self.dem, dem])
        tsa = os.path.join(d, "s.tsa")

        def atlas(src, out, steps):
            T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + T.oo_args(dict(
                PRODUCT="farshadow", DATE="2026-12-21", TIMEZONE="-05:00",
                ATLAS_STEPS=steps, FAR_THRESHOLD=24)) + [T.conn(src), out])

        atlas(dem, tsa, 4)

        def saved_and_computed(*oo):
            ds = gdal.OpenEx(tsa, gdal.OF_RASTER, open_options=list(oo))
            band = ds.GetRasterBand(1)
            saved = band.GetStatistics(False, False)
            computed = band.ComputeStatistics(False)
            ds = None
            return saved, computed

        _, far = saved_and_computed()
        _, both = saved_and_computed("SHADOWS=all")
        def same(a, b, msg=None):
            self.assertEqual(len(a), len(b), msg)
            for x, y in zip(a, b):
                self.assertAlmostEqual(x, y, places=9, msg=msg)

        same(saved_and_computed("SHADOWS=all")[0], both)
        # the same size and ground, other heights: other near shadows
        T.run(["gdal_translate", "-q", "-scale", "0", "1", "0", "3", "-ot", "Float32",
               self.dem, dem + ".new.tif"])
        os.replace(dem + ".new.tif", dem)
        saved, now = saved_and_computed("SHADOWS=all")
        print("SHADOWS=all mean before %.4f, after the DEM changed %.4f" % (both[2], now[2]))
        self.assertNotAlmostEqual(both[2], now[2], places=3)
        self.assertEqual(saved, [0, 0, 0, -1], "the former DEM's statistics reported")
        same(saved_and_computed("SHADOWS=all")[0], now)
        same(saved_and_computed()[0], far, "the far view's own were dropped")
        # another atlas written over the file (outside GDAL: its .aux.xml stays)
        atlas(dem, os.path.join(d, "other.tsa"), 2)
        shutil.copyfile(os.path.join(d, "other.tsa"), tsa)
        saved, _ = saved_and_computed()
        self.assertEqual(saved, [0, 0, 0, -1], "another atlas's file took these statistics")
        # a DEM from the standard input, GDAL's options with it or not, is
        # another DEM each run: no entry (with ?buffer_limit one was kept,
        # keyed by the name, which any DEM piped in then took: the review)
        with open(dem, "rb") as f, gzip.open(dem + ".gz", "wb") as g:
            g.write(f.read())
        for name, src in (("/vsistdin/", dem), ("/vsistdin?buffer_limit=-1", dem),
                          ("/vsigzip//vsistdin/", dem + ".gz")):
            with open(src, "rb") as stdin:
                p = subprocess.run(["gdalinfo", "-stats", "-oo", "SHADOWS=all", "-oo",
                                    "DEM=" + name, tsa], stdin=stdin, capture_output=True,
                                   text=True, env=T.env(), timeout=120)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(tsa + ".aux.xml") as f:
                self.assertNotIn("vsistdin", f.read(), name)

    def test_an_entry_in_the_dems_own_file_is_still_read(self):
        """Before session 48 the entries went into the DEM's .aux.xml: a
        nodata value set there is still what the band reports, and the
        next save goes to the products' own file."""
        conn = T.conn(self.dem, PRODUCT="svf", DIRECTIONS=4)
        T.run(["gdal_edit.py", "-ro", "-a_nodata", "-1", conn], cwd=self.cwd)
        own = self.dem + ".terrashade.aux.xml"
        os.rename(own, self.dem + ".aux.xml")  # where it was written then
        # another product's first save makes the products' file, without it
        T.run(["gdalinfo", "-stats", T.conn(self.dem, PRODUCT="shadow")], cwd=self.cwd)
        self.assertTrue(os.path.exists(own))
        self.assertEqual(self.band_says(conn)[0], -1.0)
        # and it moved there when that dataset closed
        os.remove(self.dem + ".aux.xml")
        self.assertEqual(self.band_says(conn)[0], -1.0)
        T.run(["gdal_edit.py", "-ro", "-units", "x", conn], cwd=self.cwd)
        self.assertEqual(self.band_says(conn)[:2], (-1.0, "x"))

    def test_a_lock_held_by_another_program(self):
        """Any process that may read the DEM's folder can hold its lock (the
        turns' flock): each turn of an open waited 30 s for it, gdalinfo of
        a product 61 s and with -stats 93 s (session 56's security audit).
        A load now waits 2 s and a save 10 s, and after a wait runs out the
        process's other turns of that kind (a save's: both kinds) on that
        folder go ahead at once; the statistics are still saved. (~15 s
        here: two loads' 2 s and a save's 10 s.)"""
        import fcntl
        import time
        fd = os.open(self.demdir, os.O_RDONLY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            t = time.monotonic()
            T.run(["gdalinfo", T.conn(self.dem)])
            T.run(["gdalinfo", "-stats", T.conn(self.dem, PRODUCT="svf", DIRECTIONS=8)])
            took = time.monotonic() - t
        finally:
            os.close(fd)
        print("two gdalinfo runs under a held lock: %.1f s" % took)
        self.assertLess(took, 40)
        subs = [s.get("name") for s in
                ET.parse(self.dem + ".terrashade.aux.xml").getroot().iter("Subdataset")]
        self.assertEqual(len(subs), 1, subs)

    def test_a_load_that_waited_long_leaves_saves_their_turns(self):
        """A load whose 2 s wait ran out lets this process's later loads go
        ahead at once, but not its saves, which still wait their turn (up
        to 10 s): until the second review of session 56, a save after such
        a load went ahead unlocked at once, where entries are lost. The
        lock is held for 6 s: the save waits for it."""
        import fcntl
        import threading
        import time
        fd = os.open(self.demdir, os.O_RDONLY)
        fcntl.flock(fd, fcntl.LOCK_EX)
        release = threading.Timer(6.0, lambda: os.close(fd))
        release.start()
        try:
            t = time.monotonic()
            p = T.run(["gdalinfo", "-stats", T.conn(self.dem, PRODUCT="svf", DIRECTIONS=8)],
                      CPL_DEBUG="TERRASHADE")
            took = time.monotonic() - t
        finally:
            release.join()
        said = [line for line in p.stderr.splitlines() if "no turn on the auxiliary" in line]
        print("%.1f s;" % took, "\n".join(said))
        self.assertTrue(said and all(line.endswith("(a load)") for line in said), said)
        self.assertGreater(took, 5.0)  # (the save waited for the lock's release)
        subs = [s.get("name") for s in
                ET.parse(self.dem + ".terrashade.aux.xml").getroot().iter("Subdataset")]
        self.assertEqual(len(subs), 1, subs)

    def test_a_wait_holds_no_other_folders_turns(self):
        """A thread whose save waits for another program's lock on its DEM's
        folder holds no thread of this process working on another folder:
        one mutex for the whole process held an unrelated DEM's open behind
        it for 9.9 s (session 59's concurrency audit)."""
        import fcntl
        import threading
        import time
        other = os.path.join(os.path.dirname(self.demdir), "other")
        os.makedirs(other)
        dem2 = os.path.join(other, "dem.tif")
        shutil.copy(self.dem, dem2)
        ds = gdal.OpenEx(T.conn(self.dem), gdal.OF_RASTER, open_options=["PRODUCT=shade"])
        ds.GetRasterBand(1).ComputeStatistics(False)
        fd = os.open(self.demdir, os.O_RDONLY)
        fcntl.flock(fd, fcntl.LOCK_EX)
        took = {}

        def save():
            nonlocal ds
            t = time.monotonic()
            ds = None  # its statistics saved: waits for the lock (10 s)
            took["save"] = time.monotonic() - t

        def open_other():
            time.sleep(0.5)
            t = time.monotonic()
            d2 = gdal.OpenEx(T.conn(dem2), gdal.OF_RASTER, open_options=["PRODUCT=svf"])
            d2.GetRasterBand(1).Checksum()
            took["other"] = time.monotonic() - t

        threads = [threading.Thread(target=save), threading.Thread(target=open_other)]
        try:
            for t in threads:
                t.start()
            for t in threads:
                t.join()
        finally:
            os.close(fd)
        print("save under a held lock %.1f s; another folder's product meanwhile %.1f s"
              % (took["save"], took["other"]))
        self.assertGreater(took["save"], 5.0)
        self.assertLess(took["other"], 3.0)

    def test_many_products_at_once(self):
        """Statistics of 8 products saved at once: by 4 threads of one
        process every entry is kept (GDAL rewrites an .aux.xml whole, and
        they lost each other's: 3 to 8 of 32 were left); by 2 x 8
        processes too (1 to 7 of 8 were left in each of 8 runs before
        processes took turns), and the DEM's own .aux.xml, which holds a
        PNG's georeferencing, is never touched (it was wiped in 2 to 5 runs
        of 12)."""
        import threading
        products = [dict(PRODUCT="shadow", SUN_ELEVATION=5 + 5 * i) for i in range(8)]
        errors = []

        def stats(items):
            try:
                for oo in items:
                    ds = gdal.Open(T.conn(self.dem, **oo))
                    ds.GetRasterBand(1).ComputeStatistics(False)
                    ds = None
            except Exception as e:  # noqa: BLE001 - reported below
                errors.append(e)
        threads = [threading.Thread(target=stats, args=(products[i::4],)) for i in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertEqual(errors, [])
        subs = [s.get("name") for s in
                ET.parse(self.dem + ".terrashade.aux.xml").getroot().iter("Subdataset")]
        print("entries after 4 threads:", len(subs))
        self.assertEqual(len(subs), 8, subs)
        # a PNG DEM, its georeferencing in its own .aux.xml
        png = os.path.join(self.demdir, "dem.png")
        z = T.fractal_dem(96, seed=3, relief=200.0)
        src = gdal.GetDriverByName("MEM").Create("", 96, 96, 1, gdal.GDT_UInt16)
        src.GetRasterBand(1).WriteArray((z - z.min()).astype(np.uint16))
        src.SetGeoTransform((500000.0, 10.0, 0, 4000000.0, 0, -10.0))
        utm = osr.SpatialReference()
        utm.ImportFromEPSG(32617)
        src.SetProjection(utm.ExportToWkt())
        gdal.GetDriverByName("PNG").CreateCopy(png, src)
        src = None
        own = open(png + ".aux.xml", "rb").read()
        import subprocess
        for batch in range(2):  # (one batch lost no entry in 1 run of 3 before)
            procs = [subprocess.Popen(["gdalinfo", "-stats",
                                       T.conn(png, **dict(oo, SUN_AZIMUTH=90 * batch))],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                      env=T.env()) for oo in products]
            for p in procs:
                p.wait(timeout=300)
                self.assertEqual(p.returncode, 0, p.stderr.read())
        self.assertEqual(open(png + ".aux.xml", "rb").read(), own)
        subs = [s.get("name") for s in
                ET.parse(png + ".terrashade.aux.xml").getroot().iter("Subdataset")]
        print("entries after 2 x 8 processes:", len(subs))
        self.assertEqual(len(subs), 16, subs)


if __name__ == "__main__":
    unittest.main(verbosity=2)
