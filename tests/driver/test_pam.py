"""PAM (.aux.xml) goes next to the DEM, one entry per set of options, never
into the current directory."""
import os
import shutil
import unittest
import xml.etree.ElementTree as ET

import tsdriver as T
from tsdriver import gdal


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
        aux = self.dem + ".aux.xml"
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
        self.assertTrue(os.path.exists(self.dem + ".aux.xml"))

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


if __name__ == "__main__":
    unittest.main(verbosity=2)
