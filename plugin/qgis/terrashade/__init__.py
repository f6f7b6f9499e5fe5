"""QGIS plugin entry point: registers the terrashade Processing provider."""


def classFactory(iface):  # noqa: N802 (QGIS's name)
    from .plugin import TerrashadePlugin
    return TerrashadePlugin(iface)
