"""What the docs/img scripts share: GDAL pointed at the build tree's plugin
($BUILDDIR/plugin/.libs, BUILDDIR defaulting to the current directory), no
.aux.xml files, exceptions on, and the sample DEM."""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.abspath(os.environ.get("BUILDDIR", "."))
os.environ["GDAL_DRIVER_PATH"] = os.path.join(BUILD, "plugin", ".libs")
os.environ["GDAL_PAM_ENABLED"] = "NO"

from osgeo import gdal  # noqa: E402

gdal.UseExceptions()
JACKSBORO = os.path.join(HERE, "..", "..", "samples", "jacksboro.tif")
