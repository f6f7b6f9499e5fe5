"""terrashade: Python tools around the TERRASHADE GDAL driver.

terrashade.distributed runs a product over a large DEM as window tasks on
dask.distributed (python3 -m terrashade.distributed --help).
"""
__version__ = "0.2.0"
