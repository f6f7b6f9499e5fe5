"""QGIS (headless) loads a TERRASHADE connection string as a valid raster
layer through its GDAL provider and reads a block equal to GDAL's.

Needs python3-qgis (Debian: apt-get install qgis python3-qgis
qgis-providers); GDAL_DRIVER_PATH is set (by tsdriver) before QGIS starts.
Runs QGIS in a child process so that QGIS's exit cannot disturb the result.
"""
import json
import os
import subprocess
import sys
import unittest

import tsdriver as T
from tsdriver import np

CHILD = r"""
import json, os, sys
os.environ["QT_QPA_PLATFORM"] = "offscreen"
from qgis.core import QgsApplication, QgsRasterLayer, QgsRectangle
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
    result[name] = r
print("RESULT " + json.dumps(result))
sys.stdout.flush()
os._exit(0)
"""


class Qgis(unittest.TestCase):
    def test_qgis_loads_and_reads(self):
        uris = {
            "shade": T.conn(T.JACKSBORO),
            "shadow_inline": T.conn(T.JACKSBORO, PRODUCT="shadow", SUN_ELEVATION=10),
            "horizon": T.conn(T.JACKSBORO, PRODUCT="horizon", DIRECTIONS=4),
            "lux_nodata": T.conn(T.LUX, PRODUCT="svf", DIRECTIONS=4),
        }
        with T.TempDir() as home:  # QGIS writes its profile under $HOME
            os.chmod(home, 0o700)
            p = subprocess.run([sys.executable, "-c", CHILD, json.dumps(uris)],
                               capture_output=True, text=True, timeout=300,
                               env=T.env(HOME=home, XDG_RUNTIME_DIR=home))
        lines = [l for l in p.stdout.splitlines() if l.startswith("RESULT ")]
        self.assertTrue(lines, "QGIS produced no result (exit %d):\n%s\n%s" % (
            p.returncode, p.stdout, p.stderr))
        result = json.loads(lines[-1][len("RESULT "):])
        for name, uri in uris.items():
            with self.subTest(layer=name):
                r = result[name]
                print("%-14s valid=%s bands=%s size=%sx%s crs=%s" % (
                    name, r["valid"], r.get("bands"), r.get("width"),
                    r.get("height"), r.get("crs")))
                self.assertTrue(r["valid"], r.get("error"))
                self.assertTrue(r["block_valid"])
                ref = T.read(uri, 1)[:8, :10]
                got = np.array(r["block"], dtype=float)
                nodata = np.array(r["nodata"])
                np.testing.assert_array_equal(nodata, np.isnan(ref))
                np.testing.assert_allclose(got[~nodata], ref[~nodata], rtol=1e-6)
        self.assertEqual(result["horizon"]["bands"], 4)
        self.assertEqual(result["shade"]["crs"], "EPSG:4326")
        self.assertEqual((result["shade"]["width"], result["shade"]["height"]),
                         (403, 344))
        self.assertTrue(np.array(result["lux_nodata"]["nodata"]).any())


if __name__ == "__main__":
    unittest.main(verbosity=2)
