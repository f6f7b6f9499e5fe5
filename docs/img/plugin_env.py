"""What the docs/img scripts share: GDAL pointed at the build tree's plugin
($BUILDDIR/plugin/.libs, BUILDDIR defaulting to the current directory), no
.aux.xml files, exceptions on, and the sample DEM."""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.abspath(os.environ.get("BUILDDIR", "."))
os.environ["GDAL_DRIVER_PATH"] = os.path.join(BUILD, "plugin", ".libs")
os.environ["GDAL_PAM_ENABLED"] = "NO"

import numpy as np  # noqa: E402
from osgeo import gdal  # noqa: E402
from PIL import Image  # noqa: E402

gdal.UseExceptions()
JACKSBORO = os.path.join(HERE, "..", "..", "samples", "jacksboro.tif")


def grey(a, lo=0.0, hi=1.0):
    """32 grey levels of a between lo (black; NaN too) and hi (white): a
    small PNG."""
    q = np.round(31 * np.clip((np.nan_to_num(a, nan=lo) - lo) / (hi - lo), 0, 1)) * (255 / 31)
    return Image.fromarray(q.astype(np.uint8))
