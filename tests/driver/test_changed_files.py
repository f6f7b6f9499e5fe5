"""The files a product is made of, changed on disk (a DEM regenerated
under the same name, a replaced ENV_MAP, a DEM rewritten while a dataset
on it stays open, as in a QGIS session left open):
- statistics saved for their former contents are not reported (nor copied
  into gdal_translate's output or QGIS's stretch) as the new product's;
  what the user set stays;
- a dataset opened before the DEM changed refuses to compute from it
  (whole, by chunks, an overview level), naming the cause, instead of
  mixing the two DEMs; opened again, it computes the new one;
- a DEM cut short is named in the error, with what to try."""
import gzip
import os
import unittest
import zipfile

import tsdriver as T
from exr_write import write_exr
from tsdriver import gdal, np


def write_dem(path, seed, n=96):
    T.write_tif(path, T.fractal_dem(n, seed=seed, relief=200.0),
                (500000, 10, 0, 4000000, 0, -10), 32617)


def saved_mean(path, **oo):
    """gdalinfo -stats of TERRASHADE:path: its band's STATISTICS_MEAN."""
    out = T.run(["gdalinfo", "-stats", T.conn(path, **oo)]).stdout
    return float(out.split("STATISTICS_MEAN=")[1].split()[0])


def true_mean(path, **oo):
    ds = gdal.OpenEx(T.conn(path), open_options=["%s=%s" % kv for kv in oo.items()])
    return float(np.nanmean(ds.GetRasterBand(1).ReadAsArray()))


class ChangedFiles(T.TempDirCase):
    def test_statistics_of_a_regenerated_dem(self):
        """Until session 50 the statistics saved in <DEM>.terrashade.aux.xml
        outlived a DEM regenerated under its name (GDAL drops the DEM's own
        .aux.xml then, not the products'): 0.797 for svf's mean where it
        was 0.509. A nodata value the user set stays."""
        dem = os.path.join(self.dir, "regen.tif")
        write_dem(dem, 1)
        first = saved_mean(dem, PRODUCT="svf")
        T.run(["gdal_edit.py", "-ro", "-a_nodata", "-1", T.conn(dem, PRODUCT="svf")])
        os.remove(dem)
        write_dem(dem, 2)
        again = saved_mean(dem, PRODUCT="svf")
        want = true_mean(dem, PRODUCT="svf")
        print("svf's mean: first DEM %.6f, regenerated %.6f, reported %.6f"
              % (first, want, again))
        self.assertGreater(abs(first - want), 1e-3)
        self.assertAlmostEqual(again, want, places=5)
        ds = gdal.Open(T.conn(dem, PRODUCT="svf"))
        self.assertEqual(ds.GetRasterBand(1).GetNoDataValue(), -1.0)
        ds = None
        # the same contents: the saved statistics stand (no recomputation)
        self.assertEqual(saved_mean(dem, PRODUCT="svf"), again)

    def test_metadata_of_a_regenerated_dem_is_its_own(self):
        """GDAL's PAM saves a band's descriptions and metadata beside its
        statistics, and loaded them over what the driver computed: after one
        gdalinfo -stats, a day product of a DEM regenerated at another
        latitude kept the old site's times and sun (an atlas then stored
        them, and its near shadows took that sun), an svf's SOURCE_CRS_KIND
        stayed projected for a geographic DEM, and SOURCE_DEM kept the name
        it was first opened by. What the user set stays."""
        dem = os.path.join(self.dir, "site.tif")
        z = T.fractal_dem(64, seed=3, relief=200.0)

        def at(lat):
            if os.path.exists(dem):
                os.remove(dem)
            T.write_tif(dem, z, (10.0, 0.001, 0, lat, 0, -0.001), 4326)

        day = dict(PRODUCT="daycycle", DATE="2026-06-21", TIMEZONE="+0100",
                   STEP_MINUTES=120)

        def band2():
            ds = gdal.OpenEx(T.conn(dem), open_options=["%s=%s" % kv for kv in day.items()])
            b = ds.GetRasterBand(2)
            return b.GetDescription(), b.GetMetadataItem("SUN_ELEVATION")

        at(45.0)
        fresh45 = band2()
        T.run(["gdalinfo", "-stats", "-hist", T.conn(dem, **day)])
        T.run(["gdal_edit.py", "-ro", "-a_nodata", "-1", T.conn(dem, PRODUCT="svf")])
        T.run(["gdalinfo", "-stats", "-hist", T.conn(dem, PRODUCT="svf")])
        at(62.0)
        got = band2()
        os.rename(dem + ".terrashade.aux.xml", dem + ".aside")
        fresh62 = band2()
        os.rename(dem + ".aside", dem + ".terrashade.aux.xml")
        print("daycycle band 2 at 45 N %s, at 62 N %s, reported %s" % (fresh45, fresh62, got))
        self.assertNotEqual(fresh45, fresh62)
        self.assertEqual(got, fresh62)
        # SOURCE_DEM by the path it is opened with now, and the user's nodata
        ds = gdal.OpenEx(T.conn(os.path.abspath(dem)), open_options=["PRODUCT=svf"])
        self.assertEqual(ds.GetMetadataItem("SOURCE_DEM"), os.path.abspath(dem))
        self.assertEqual(ds.GetMetadataItem("SOURCE_CRS_KIND"), "geographic")
        self.assertEqual(ds.GetRasterBand(1).GetNoDataValue(), -1.0)
        ds = None

    def test_windows_have_their_own_statistics(self):
        """TILE_SIZE and MAX_MEMORY change pixels (chunks, a coarser far
        grid) where the options in the entry's key said nothing: TILE_SIZE=0
        and 256 shared one entry's statistics. The chunks and the far grid
        are in the key now."""
        dem = os.path.join(self.dir, "tiles.tif")
        write_dem(dem, 4, n=600)
        whole = saved_mean(dem, PRODUCT="svf", TILE_SIZE=0)
        tiled = saved_mean(dem, PRODUCT="svf", TILE_SIZE=128)
        want = true_mean(dem, PRODUCT="svf", TILE_SIZE=128)
        print("svf's mean: whole %.7f, TILE_SIZE=128 %.7f (computed %.7f)"
              % (whole, tiled, want))
        self.assertNotEqual(whole, want)
        self.assertAlmostEqual(tiled, want, places=6)

    def test_a_gzipped_dem_is_not_changed_by_reading_it(self):
        """/vsigzip/'s stat gives the time 0 once GDAL caches the file: every
        product of a /vsigzip/ DEM was refused as 'changed on disk' at its
        first read. Stamped by the .gz file itself, it computes, and a .gz
        rewritten under an open dataset is still caught."""
        import gzip
        import shutil
        dem = os.path.join(self.dir, "gz.tif")
        write_dem(dem, 6)
        with open(dem, "rb") as f, gzip.open(dem + ".gz", "wb") as g:
            shutil.copyfileobj(f, g)
        gz = "/vsigzip/" + dem + ".gz"
        np.testing.assert_array_equal(T.read(T.conn(gz, PRODUCT="svf")),
                                      T.read(T.conn(dem, PRODUCT="svf")))
        ds = gdal.OpenEx(T.conn(gz), open_options=["PRODUCT=svf"])
        os.utime(dem + ".gz", (1, 1))
        with self.assertRaises(RuntimeError) as e:
            ds.GetRasterBand(1).ReadAsArray()
        self.assertIn("changed on disk", str(e.exception))
        ds = None

    def test_a_deleted_dem_is_said_deleted(self):
        """A DEM deleted under an open dataset was said to have 'changed on
        disk'; it says deleted or moved now."""
        dem = os.path.join(self.dir, "gone.tif")
        write_dem(dem, 7)
        ds = gdal.OpenEx(T.conn(dem), open_options=["PRODUCT=svf"])
        os.remove(dem)
        with self.assertRaises(RuntimeError) as e:
            ds.GetRasterBand(1).ReadAsArray()
        self.assertIn("the DEM '%s' (its file '%s') was deleted or moved since this dataset "
                      "was opened" % (dem, dem),
                      str(e.exception))
        ds = None
        # a DEM named through another driver, rewritten: changed, not deleted
        # (its name is no file: it read as deleted)
        write_dem(dem, 7)
        ds = gdal.OpenEx(T.conn("GTIFF_DIR:1:" + dem), open_options=["PRODUCT=svf"])
        write_dem(dem, 8)
        with self.assertRaises(RuntimeError) as e:
            ds.GetRasterBand(1).ReadAsArray()
        self.assertIn("changed on disk", str(e.exception))
        ds = None

    def test_a_windowed_entry_from_before_its_key_had_the_chunks(self):
        """Session 51 put the chunks and far grid in a windowed product's
        key: an entry saved under the key without them keeps what the user
        set (nodata, unit), not its statistics, which may be the whole
        DEM's pixels'."""
        import re
        dem = os.path.join(self.dir, "oldkey.tif")
        write_dem(dem, 9, n=200)
        oo = ["PRODUCT=svf", "TILE_SIZE=64", "DIRECTIONS=4"]
        ds = gdal.OpenEx(T.conn(dem), open_options=oo)
        b = ds.GetRasterBand(1)
        b.SetNoDataValue(-7)
        b.SetUnitType("myunit")
        b.ComputeStatistics(False)
        b = ds = None
        aux = dem + ".terrashade.aux.xml"
        with open(aux) as f:
            text = f.read()
        self.assertIn(",WINDOWS=", text)
        with open(aux, "w") as f:
            f.write(re.sub(r",WINDOWS=[^\":<]*", "", text))
        ds = gdal.OpenEx(T.conn(dem), open_options=oo)
        b = ds.GetRasterBand(1)
        self.assertEqual((b.GetNoDataValue(), b.GetUnitType()), (-7.0, "myunit"))
        self.assertIsNone(b.GetMetadataItem("STATISTICS_MEAN"))
        b = ds = None

    def test_statistics_of_a_replaced_env_map(self):
        dem = os.path.join(self.dir, "env.tif")
        write_dem(dem, 3)
        light = os.path.join(self.dir, "light.exr")
        write_exr(light, np.ones((16, 32, 3)))
        first = saved_mean(dem, PRODUCT="envlight", ENV_MAP=light)
        write_exr(light, np.full((16, 32, 3), 3.0))
        again = saved_mean(dem, PRODUCT="envlight", ENV_MAP=light)
        print("envlight's mean under a map of 1, then of 3: %.6f, %.6f" % (first, again))
        self.assertAlmostEqual(again, 3 * first, places=4)

    def rewrite(self, dem, seed, n):
        """The DEM's heights rewritten in place (the same file)."""
        ds = gdal.Open(dem, gdal.GA_Update)
        ds.GetRasterBand(1).WriteArray(T.fractal_dem(n, seed=seed, relief=200.0))
        ds = None

    def test_a_dem_changed_under_an_open_dataset(self):
        for name, oo in (("whole", {}), ("by chunks", dict(TILE_SIZE=64)),
                         ("overview level 1", {})):
            with self.subTest(name):
                dem = os.path.join(self.dir, "open_%d.tif" % len(name))
                n = 600 if name.startswith("overview") else 96  # (levels down to ~256)
                write_dem(dem, 4, n)
                ds = gdal.OpenEx(T.conn(dem), open_options=[
                    "PRODUCT=svf"] + ["%s=%s" % kv for kv in oo.items()])
                band = ds.GetRasterBand(1)
                if name.startswith("overview"):
                    band = band.GetOverview(0)
                    self.assertIsNotNone(band)
                self.rewrite(dem, 5, n)
                with self.assertRaises(RuntimeError) as cm:
                    band.ReadAsArray()
                print("%s: %s" % (name, cm.exception))
                self.assertIn("changed on disk since this dataset was opened", str(cm.exception))
                self.assertIn("open it again", str(cm.exception))
                band = ds = None
                # opened again: the new DEM's product
                again = true_mean(dem, PRODUCT="svf", **oo)
                fresh = os.path.join(self.dir, "fresh_%d.tif" % len(name))
                gdal.Translate(fresh, dem)
                self.assertEqual(again, true_mean(fresh, PRODUCT="svf", **oo))

    def test_an_unchanged_dem_computes_after_a_while(self):
        """What does not change the DEM's contents does not count: reading
        it (its .aux.xml written beside it), a chmod, a hard link to it (a
        backup's), and a chdir after opening it by a relative path (each
        refused it during session 50, before the stamp left the change time
        out and kept absolute paths)."""
        dem = os.path.join(self.dir, "same.tif")
        write_dem(dem, 6)
        cwd = os.getcwd()
        os.chdir(self.dir)
        try:
            ds = gdal.OpenEx(T.conn("same.tif"), open_options=["PRODUCT=svf", "TILE_SIZE=64"])
            T.run(["gdalinfo", "-stats", dem])  # the DEM's own statistics saved
            os.chmod(dem, 0o640)
            os.link(dem, os.path.join(self.dir, "backup.tif"))
            os.chdir("/")
            a = ds.GetRasterBand(1).ReadAsArray()
        finally:
            os.chdir(cwd)
        self.assertTrue(np.isfinite(a).all())
        ds = None

    def test_chdir_archives_and_levels(self):
        """A chdir after opening the DEM by a relative name inside /vsizip/
        or /vsigzip/, or opening an overview level of a relative DEM: the
        stamp took the archive's relative name against the new directory
        ('deleted or moved since this dataset was opened'), and a level
        reopened the DEM by its relative name ('cannot open the DEM again';
        session 54's audit). Both are made absolute when the dataset opens."""
        dem = os.path.join(self.dir, "arch.tif")
        write_dem(dem, 9, n=300)
        with zipfile.ZipFile(os.path.join(self.dir, "arch.zip"), "w") as z:
            z.write(dem, "arch.tif")
        with open(dem, "rb") as f, gzip.open(dem + ".gz", "wb") as g:
            g.write(f.read())
        cwd = os.getcwd()
        for name in ("/vsizip/arch.zip/arch.tif", "/vsigzip/arch.tif.gz", "arch.tif"):
            os.chdir(self.dir)
            try:
                ds = gdal.OpenEx(T.conn(name), open_options=["PRODUCT=svf", "DIRECTIONS=4"])
                os.chdir("/")
                full = ds.GetRasterBand(1).ReadAsArray()
                level = ds.GetRasterBand(1).GetOverview(0).ReadAsArray()
            finally:
                os.chdir(cwd)
            self.assertTrue(np.isfinite(full).all(), name)
            self.assertEqual(level.shape, (150, 150), name)
            self.assertTrue(np.isfinite(level).all(), name)
            ds = None

    def test_chdir_names_that_stay_relative(self):
        """Names that stay relative to the working directory (another
        driver's name, vrt://): after a chdir an overview level reopened
        the name there, and read another directory's DEM of that name
        without a word (session 54's review). It is refused, saying why.
        A plain name starting with '{', and an archive's name in braces,
        are made absolute at open."""
        here, there = os.path.join(self.dir, "here"), os.path.join(self.dir, "there")
        os.makedirs(here, exist_ok=True)
        os.makedirs(there, exist_ok=True)
        write_dem(os.path.join(here, "dem.tif"), 11, n=300)
        write_dem(os.path.join(there, "dem.tif"), 12, n=300)
        T.shutil.copy(os.path.join(here, "dem.tif"), os.path.join(here, "{site}.tif"))
        with zipfile.ZipFile(os.path.join(here, "b.zip"), "w") as z:
            z.write(os.path.join(here, "dem.tif"), "dem.tif")
        cwd = os.getcwd()
        with open(os.path.join(here, "dem.tif"), "rb") as f, \
                gzip.open(os.path.join(here, "{g}.tif.gz"), "wb") as g:
            g.write(f.read())
        for name, ok in (("GTIFF_DIR:1:dem.tif", False), ("vrt://dem.tif?bands=1", False),
                         ("{site}.tif", True), ("/vsizip/{b.zip}/dem.tif", True),
                         ("/vsigzip/{g}.tif.gz", True)):
            with self.subTest(name=name):
                os.chdir(here)
                try:
                    ds = gdal.OpenEx(T.conn(name), open_options=["PRODUCT=svf", "DIRECTIONS=4"])
                    os.chdir(there)
                    full = ds.GetRasterBand(1).ReadAsArray()
                    if ok:
                        level = ds.GetRasterBand(1).GetOverview(0).ReadAsArray()
                    else:
                        with self.assertRaises(RuntimeError) as e:
                            ds.GetRasterBand(1).GetOverview(0).ReadAsArray()
                        self.assertIn("opens other files now than when this dataset was "
                                      "opened", str(e.exception))
                        self.assertIn("relative to the working directory", str(e.exception))
                finally:
                    os.chdir(cwd)
                self.assertTrue(np.isfinite(full).all())
                if ok:
                    self.assertTrue(np.isfinite(level).all())
                ds = None

    def test_overviews_added_after_open(self):
        """gdaladdo -ro on the DEM while a product of it is open (QGIS building
        pyramids): the level reads, the .ovr being the DEM's own; the check
        of a level's files (session 54) refused it for a while, blaming a
        change of directory."""
        dem = os.path.join(self.dir, "ovr_later.tif")
        write_dem(dem, 13, n=300)
        ds = gdal.OpenEx(T.conn(dem), open_options=["PRODUCT=svf", "DIRECTIONS=4"])
        T.run(["gdaladdo", "-q", "-ro", "-r", "average", dem, "2"])
        level = ds.GetRasterBand(1).GetOverview(0).ReadAsArray()
        self.assertTrue(np.isfinite(level).all())
        ds = None

    def test_a_vrt_whose_source_is_regenerated(self):
        """A VRT DEM's sources are its files too: statistics saved before
        its source was regenerated are dropped (the VRT itself did not
        change), and a dataset open across the change refuses."""
        src = os.path.join(self.dir, "src.tif")
        vrt = os.path.join(self.dir, "dem.vrt")
        write_dem(src, 8)
        gdal.BuildVRT(vrt, [src])
        first = saved_mean(vrt, PRODUCT="svf")
        ds = gdal.OpenEx(T.conn(vrt), open_options=["PRODUCT=svf"])
        os.remove(src)
        write_dem(src, 9)
        with self.assertRaises(RuntimeError) as cm:
            ds.GetRasterBand(1).ReadAsArray()
        self.assertIn("changed on disk", str(cm.exception))
        ds = None
        again, want = saved_mean(vrt, PRODUCT="svf"), true_mean(vrt, PRODUCT="svf")
        print("VRT svf mean: before %.6f, after %.6f, reported %.6f" % (first, want, again))
        self.assertGreater(abs(first - want), 1e-3)
        self.assertAlmostEqual(again, want, places=5)

    def test_a_dem_cut_short(self):
        """A GeoTIFF cut short (a copy interrupted): GDAL 3.6's direct read
        fails without a reason, and the error said only "cannot read the
        DEM"; it names the DEM and what to try, whole and by chunks."""
        dem = os.path.join(self.dir, "whole.tif")
        write_dem(dem, 7, 512)
        cut = os.path.join(self.dir, "cut.tif")
        with open(dem, "rb") as f, open(cut, "wb") as g:
            g.write(f.read()[:150000])
        for oo in (dict(PRODUCT="svf", TILE_SIZE=0), dict(PRODUCT="svf", TILE_SIZE=128)):
            p = T.run(["gdal_translate", "-q"] + T.oo_args(oo)
                      + [T.conn(cut), os.path.join(self.dir, "out.tif")], ok=False)
            print(p.stderr.strip().splitlines()[-1])
            self.assertIn("cannot read the DEM '%s'" % cut, p.stderr)
            self.assertIn("gdalinfo -checksum", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
