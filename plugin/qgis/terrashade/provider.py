"""The terrashade Processing provider: one algorithm per product of the driver."""
import sys

from qgis.core import Qgis, QgsMessageLog, QgsProcessingProvider

from .algorithms import make_algorithms
from .driver_tables import DriverError


class TerrashadeProvider(QgsProcessingProvider):
    def __init__(self):
        super().__init__()
        self.problem = ""  # why no algorithm could be built, if so

    def id(self):
        return "terrashade"

    def name(self):
        return "terrashade"

    def longName(self):  # noqa: N802 (QGIS's name)
        return "terrashade: terrain shading with cast shadows"

    def warningMessage(self):  # noqa: N802
        return self.problem

    def loadAlgorithms(self):  # noqa: N802
        try:
            algorithms = make_algorithms()
        except DriverError as e:  # QGIS starts anyway; the log says what to do
            self.problem = str(e)
            QgsMessageLog.logMessage(self.problem, "terrashade", Qgis.Warning)
            # and stderr, which qgis_process shows (it prints no log): else
            # it said only 'Algorithm terrashade:shade not found!'
            print("terrashade: " + self.problem, file=sys.stderr)
            return
        self.problem = ""
        for alg in algorithms:
            self.addAlgorithm(alg)
