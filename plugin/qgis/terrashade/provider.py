"""The terrashade Processing provider: one algorithm per product."""
from qgis.core import QgsProcessingProvider

from .algorithms import make_algorithms


class TerrashadeProvider(QgsProcessingProvider):
    def id(self):
        return "terrashade"

    def name(self):
        return "terrashade"

    def longName(self):  # noqa: N802 (QGIS's name)
        return "terrashade: terrain shading with cast shadows"

    def loadAlgorithms(self):  # noqa: N802
        for alg in make_algorithms():
            self.addAlgorithm(alg)
