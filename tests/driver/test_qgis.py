"""QGIS (headless) loads a TERRASHADE connection string as a valid raster
layer through its GDAL provider and reads a block equal to GDAL's, the
full resolution's statistics, a zoomed-out view from the first overview
level and a cell's value by identify. The layers are made from copies of
the DEMs: QGIS saves its histograms next to the DEM (PAM), which wrote
tests/data/jacksboro.tif.aux.xml (800 KB) into the source tree.

Needs python3-qgis (Debian: apt-get install qgis python3-qgis
qgis-providers); GDAL_DRIVER_PATH is set (by tsdriver) before QGIS starts.
Runs QGIS in a child process so that QGIS's exit cannot disturb the result.
"""
import json
import os
import shutil
import subprocess
import sys
import unittest

import tsdriver as T
from tsdriver import np

CHILD = r"""
import json, os, sys
os.environ["QT_QPA_PLATFORM"] = "offscreen"
from qgis.core import (QgsApplication, QgsPointXY, QgsRaster, QgsRasterLayer, QgsRectangle)
from qgis.core import QgsRasterBandStats as QgsRasterBandStatistics
app = QgsApplication([], False)
app.setPrefixPath("/usr", True)
app.initQgis()
result = {}
for name, uri in json.loads(sys.argv[1]).items():
    layer = QgsRasterLayer(uri, name, "gdal")
    r = {"valid": layer.isValid()}
    if not layer.isValid():  # (QgsError.summary() crashes on QGIS 3.22)
        err = layer.error()
        r["error"] = "; ".join(m.message() for m in err.messageList())
    if layer.isValid():
        prov = layer.dataProvider()
        r["bands"] = layer.bandCount()
        r["width"], r["height"] = layer.width(), layer.height()
        r["crs"] = layer.crs().authid()
        ext = layer.extent()
        # the north-west 10 x 8 cells
        px, py = ext.width() / layer.width(), ext.height() / layer.height()
        rect = QgsRectangle(ext.xMinimum(), ext.yMaximum() - 8 * py,
                            ext.xMinimum() + 10 * px, ext.yMaximum())
        block = prov.block(1, rect, 10, 8)
        r["block_valid"] = block.isValid()
        r["block"] = [[block.value(y, x) for x in range(10)] for y in range(8)]
        r["nodata"] = [[bool(block.isNoData(y, x)) for x in range(10)] for y in range(8)]
        st = prov.bandStatistics(1, QgsRasterBandStatistics.All, ext, 0)
        r["stats"] = [st.minimumValue, st.maximumValue, st.mean, st.elementCount]
        # zoomed out: the whole layer in 40 x 34 pixels (GDAL reads an overview)
        small = prov.block(1, ext, 40, 34)
        r["small"] = [[None if small.isNoData(y, x) else small.value(y, x)
                       for x in range(40)] for y in range(34)]
        # identify: the cell 60 columns, 40 rows in from the north-west
        pt = QgsPointXY(ext.xMinimum() + 60.5 * px, ext.yMaximum() - 40.5 * py)
        ident = prov.identify(pt, QgsRaster.IdentifyFormatValue)
        r["identify"] = ident.results().get(1) if ident.isValid() else "invalid"
    result[name] = r
print("RESULT " + json.dumps(result))
sys.stdout.flush()
os._exit(0)
"""


class Qgis(unittest.TestCase):
    def test_qgis_loads_and_reads(self):
        with T.TempDir() as home:  # QGIS writes its profile under $HOME
            os.chmod(home, 0o700)
            # copies: QGIS saves its statistics and histograms next to the
            # DEM (PAM), where they would be read back, stale, next time
            jacksboro = shutil.copy(T.JACKSBORO, home)
            lux = shutil.copy(T.LUX, home)
            uris = {
                "shade": T.conn(jacksboro),
                "shadow_inline": T.conn(jacksboro, PRODUCT="shadow", SUN_ELEVATION=10),
                "horizon": T.conn(jacksboro, PRODUCT="horizon", DIRECTIONS=4),
                "svf": T.conn(jacksboro, PRODUCT="svf", DIRECTIONS=4),
                "lux_nodata": T.conn(lux, PRODUCT="svf", DIRECTIONS=4),
            }
            p = subprocess.run([sys.executable, "-c", CHILD, json.dumps(uris)],
                               capture_output=True, text=True, timeout=300,
                               env=T.env(HOME=home, XDG_RUNTIME_DIR=home))
            lines = [l for l in p.stdout.splitlines() if l.startswith("RESULT ")]
            self.assertTrue(lines, "QGIS produced no result (exit %d):\n%s\n%s" % (
                p.returncode, p.stdout, p.stderr))
            result = json.loads(lines[-1][len("RESULT "):])
            for name, uri in uris.items():
                with self.subTest(layer=name):
                    self.check_layer(uri, result[name])
        self.assertEqual(result["horizon"]["bands"], 4)
        self.assertEqual(result["shade"]["crs"], "EPSG:4326")
        self.assertEqual((result["shade"]["width"], result["shade"]["height"]),
                         (403, 344))
        self.assertTrue(np.array(result["lux_nodata"]["nodata"]).any())

    def check_layer(self, uri, r):
        print("%s: valid=%s bands=%s size=%sx%s crs=%s stats=%s identify=%s" % (
            uri, r["valid"], r.get("bands"), r.get("width"), r.get("height"),
            r.get("crs"), r.get("stats"), r.get("identify")))
        self.assertTrue(r["valid"], r.get("error"))
        self.assertTrue(r["block_valid"])
        full = T.read(uri, 1)
        ref = full[:8, :10]
        got = np.array(r["block"], dtype=float)
        nodata = np.array(r["nodata"])
        np.testing.assert_array_equal(nodata, np.isnan(ref))
        np.testing.assert_allclose(got[~nodata], ref[~nodata], rtol=1e-6)
        # statistics: those of the full resolution (valid cells only)
        lo, hi, mean, count = r["stats"]
        valid = full[~np.isnan(full)]
        self.assertEqual(count, valid.size)
        np.testing.assert_allclose([lo, hi, mean], [valid.min(), valid.max(), valid.mean()],
                                   rtol=1e-5)
        # identify: the cell's value (None on nodata)
        self.assertFalse(np.isnan(full[40, 60]))
        self.assertAlmostEqual(r["identify"], full[40, 60], places=5)
        # zoomed out: values of the first overview level (the product of the
        # coarser DEM; a DEM of 256 cells or less has none)
        ds = T.gdal.OpenEx(uri)
        band = ds.GetRasterBand(1)
        self.assertEqual(band.GetOverviewCount(), 1 if r["width"] > 256 else 0)
        level1 = (band.GetOverview(0) if band.GetOverviewCount() else band).ReadAsArray()
        nd = band.GetNoDataValue()
        small = np.array([[np.nan if v is None else v for v in row] for row in r["small"]])
        shown = small[~np.isnan(small)]
        if nd is not None and not np.isnan(nd):
            shown = shown[shown != nd]
        self.assertTrue(shown.size)
        self.assertTrue(np.isin(shown.astype(np.float32), level1.astype(np.float32)).all())
        print("  zoomed out: %d values, %.0f %% of them also full-resolution values" % (
            shown.size, 100 * np.isin(shown.astype(np.float32), full.astype(np.float32)).mean()))


if __name__ == "__main__":
    unittest.main(verbosity=2)
