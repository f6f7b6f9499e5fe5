"""Render docs/img/qgis_sunhours_dialog.png: the Processing dialog of
terrashade:sunhours with jacksboro.tif loaded, as QGIS shows it.

    QT_QPA_PLATFORM=offscreen /usr/bin/python3 samples/qgis_dialog.py [OUT.png]

Runs QGIS headless with a throw-away profile (HOME is set to a temporary
folder); needs python3-qgis. The plugin is taken from the build tree's
plugin/.libs where it is there (as samples/render.sh does), else from
wherever GDAL finds it. The picture is in the repository; run this only to
redo it (without OUT.png it is overwritten).
"""
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs", "img",
                                                         "qgis_sunhours_dialog.png")
HOME = tempfile.mkdtemp(prefix="qgis-home-")
os.environ.update(QT_QPA_PLATFORM="offscreen", HOME=HOME, XDG_RUNTIME_DIR=HOME)
# the plugin of this tree, before GDAL starts (else the provider has no
# algorithms: alg below was None, and the script ended in an AttributeError)
if os.path.exists(os.path.join(ROOT, "plugin", ".libs", "gdal_TERRASHADE.so")):
    os.environ["GDAL_DRIVER_PATH"] = os.path.join(ROOT, "plugin", ".libs")
sys.path.insert(0, os.path.join(ROOT, "plugin", "qgis"))
sys.path.insert(0, "/usr/share/qgis/python/plugins")

from qgis.core import QgsApplication, QgsProject, QgsRasterLayer  # noqa: E402

app = QgsApplication([], True)
app.setPrefixPath("/usr", True)
app.initQgis()
from processing.core.Processing import Processing  # noqa: E402
from processing.gui.AlgorithmDialog import AlgorithmDialog  # noqa: E402

Processing.initialize()
import terrashade  # noqa: E402

plugin = terrashade.classFactory(None)
plugin.initProcessing()
layer = QgsRasterLayer(os.path.join(HERE, "jacksboro.tif"), "jacksboro")
QgsProject.instance().addMapLayer(layer)
alg = QgsApplication.processingRegistry().algorithmById("terrashade:sunhours")
if alg is None:
    sys.exit("qgis_dialog.py: QGIS has no terrashade:sunhours: %s"
             % (plugin.provider.warningMessage() if getattr(plugin, "provider", None)
                else "the terrashade provider did not load"))
dialog = AlgorithmDialog(alg.create(), False, None)
dialog.setParameters({"INPUT": layer, "DATE": "2026-12-21", "TIMEZONE": "-05:00",
                      "STEP_MINUTES": 10})
dialog.resize(1000, 720)
dialog.show()
app.processEvents()
ok = dialog.grab().save(OUT)
print("wrote" if ok else "could not write", OUT)
sys.stdout.flush()
os._exit(0 if ok else 1)
