"""The QGIS Processing provider (plugin/qgis/terrashade), headless.

- the plugin's classFactory registers the provider with every product;
- each algorithm writes what gdal_translate writes with the same options
  (shade from an azimuth and from a date and time, svf, horizon, sunhours);
- bad input gives a QgsProcessingException: QGIS's own for a missing
  mandatory parameter, else the driver's sentence;
- qgis_process, QGIS's command line, finds the plugin through
  QGIS_PLUGINPATH, lists its algorithms and runs one.

QGIS runs in child processes (as in test_qgis.py) with HOME in a temporary
folder, so no user profile is read or written.
"""
import json
import os
import subprocess
import sys
import unittest

import tsdriver as T
from tsdriver import np

PLUGINS = os.path.join(T.SRCDIR, "plugin", "qgis")

CHILD = r"""
import json, os, sys
os.environ["QT_QPA_PLATFORM"] = "offscreen"
sys.path.insert(0, sys.argv[1])
sys.path.insert(0, "/usr/share/qgis/python/plugins")  # QGIS's own processing
from qgis.core import (QgsApplication, QgsProcessingException, QgsProcessingFeedback)
app = QgsApplication([], False)
app.setPrefixPath("/usr", True)
app.initQgis()
from processing.core.Processing import Processing
Processing.initialize()
import processing
import terrashade
plugin = terrashade.classFactory(None)
plugin.initProcessing()
reg = QgsApplication.processingRegistry()
result = {"algorithms": sorted(a.id() for a in reg.providerById("terrashade").algorithms())}
for name, alg, params in json.loads(sys.argv[2]):
    fb = QgsProcessingFeedback()
    try:
        out = processing.run(alg, params, feedback=fb)
        result[name] = {"output": out["OUTPUT"]}
    except QgsProcessingException as e:
        result[name] = {"error": str(e)}
plugin.unload()
result["unloaded"] = reg.providerById("terrashade") is None
print("RESULT " + json.dumps(result))
sys.stdout.flush()
os._exit(0)
"""


def qgis_env(home):
    return T.env(HOME=home, XDG_RUNTIME_DIR=home, QT_QPA_PLATFORM="offscreen",
                 QGIS_PLUGINPATH=PLUGINS)


class Processing(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.home = os.path.join(cls.dir, "home")
        os.mkdir(cls.home, 0o700)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def out(self, name):
        return os.path.join(self.dir, name + ".tif")

    def test_algorithms_equal_gdal_translate(self):
        J = T.JACKSBORO
        day = {"DATE": "2026-12-21", "TIMEZONE": "-05:00", "STEP_MINUTES": 30}
        cases = [
            ("shade", "terrashade:shade",
             {"INPUT": J, "SUN_AZIMUTH": 135, "SUN_ELEVATION": 20},
             {"PRODUCT": "shade", "SUN_AZIMUTH": 135, "SUN_ELEVATION": 20}),
            ("shade_time", "terrashade:shade",
             {"INPUT": J, "DATETIME": "2026-12-21T09:00:00-05:00", "SKY_WEIGHT": 0.3,
              "DIRECTIONS": 8},
             {"PRODUCT": "shade", "DATETIME": "2026-12-21T09:00:00-05:00",
              "SKY_WEIGHT": 0.3, "DIRECTIONS": 8}),
            ("svf", "terrashade:svf", {"INPUT": J, "DIRECTIONS": 8},
             {"PRODUCT": "svf", "DIRECTIONS": 8}),
            ("horizon", "terrashade:horizon", {"INPUT": J, "DIRECTIONS": 4},
             {"PRODUCT": "horizon", "DIRECTIONS": 4}),
            ("sunhours", "terrashade:sunhours", dict(day, INPUT=J),
             dict(day, PRODUCT="sunhours")),
        ]
        bad = [
            ("no_date", "terrashade:sunhours", {"INPUT": J, "TIMEZONE": "-05:00"}),
            ("bad_time", "terrashade:shade", {"INPUT": J, "DATETIME": "2026-12-21T09:00"}),
        ]
        runs = [(n, a, dict(p, OUTPUT=self.out(n))) for n, a, p, _ in cases]
        runs += [(n, a, dict(p, OUTPUT=self.out(n))) for n, a, p in bad]
        p = subprocess.run([sys.executable, "-c", CHILD, PLUGINS, json.dumps(runs)],
                           capture_output=True, text=True, timeout=600,
                           env=qgis_env(self.home))
        lines = [l for l in p.stdout.splitlines() if l.startswith("RESULT ")]
        self.assertTrue(lines, "QGIS produced no result (exit %d):\n%s\n%s" % (
            p.returncode, p.stdout, p.stderr))
        result = json.loads(lines[-1][len("RESULT "):])
        print("algorithms:", result["algorithms"])
        self.assertEqual(result["algorithms"], sorted(
            "terrashade:" + a for a in ("shade", "shadow", "horizon", "svf", "openness",
                                        "sky", "sunhours", "insolation")))
        self.assertTrue(result["unloaded"])
        for name, _, _, options in cases:
            with self.subTest(case=name):
                self.assertIn("output", result[name], result[name].get("error"))
                got = T.read(result[name]["output"])
                ref = T.read(T.translate(J, self.out(name + "_ref"), options))
                print("%-10s %s, equal to gdal_translate" % (name, got.shape))
                np.testing.assert_array_equal(got, ref)
        for name, _, _ in bad:
            print("%-10s -> %s" % (name, result[name].get("error")))
        # a missing day: QGIS itself names the mandatory parameter
        self.assertIn("DATE", result["no_date"].get("error", ""))
        # a time without an offset: the driver's sentence
        self.assertIn("TERRASHADE", result["bad_time"].get("error", ""))
        self.assertIn("offset", result["bad_time"]["error"])

    def test_qgis_process_command_line(self):
        """qgis_process.bin (Debian's qgis_process wrapper fails on a flag in
        /etc/default/qgis) with the plugin enabled in a fresh profile."""
        qp = "/usr/bin/qgis_process.bin"
        env = qgis_env(self.home)
        p = subprocess.run([qp, "plugins", "enable", "terrashade"], capture_output=True,
                           text=True, timeout=300, env=env)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        p = subprocess.run([qp, "list"], capture_output=True, text=True, timeout=300, env=env)
        self.assertIn("terrashade:sunhours", p.stdout, p.stderr)
        out = self.out("qp_svf")
        p = subprocess.run([qp, "run", "terrashade:svf", "--", "INPUT=" + T.JACKSBORO,
                            "DIRECTIONS=8", "OUTPUT=" + out], capture_output=True, text=True,
                           timeout=300, env=env)
        print(p.stdout[-600:])
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        ref = T.read(T.translate(T.JACKSBORO, self.out("qp_ref"),
                                 {"PRODUCT": "svf", "DIRECTIONS": 8}))
        np.testing.assert_array_equal(T.read(out), ref)
        p = subprocess.run([qp, "run", "terrashade:sunhours", "--", "INPUT=" + T.JACKSBORO,
                            "OUTPUT=" + self.out("qp_bad")], capture_output=True, text=True,
                           timeout=300, env=env)
        print((p.stdout + p.stderr)[-400:])
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("DATE", p.stdout + p.stderr)
        p = subprocess.run([qp, "run", "terrashade:sunhours", "--", "INPUT=" + T.JACKSBORO,
                            "DATE=2026-02-30", "TIMEZONE=Z", "OUTPUT=" + self.out("qp_bad")],
                           capture_output=True, text=True, timeout=300, env=env)
        print((p.stdout + p.stderr)[-400:])
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("there is no day 30", p.stdout + p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
