"""gdal_translate TERRASHADE:... equals the core's own result.

tests/driver/core_reference (linked with libterrashade only, no GDAL) gets
the DEM as raw floats and the cell sizes, and computes each product; the
driver's output through gdal_translate must match it. On a projected DEM
the grids are identical, so the products must agree to float rounding
(1e-5; the reference reaches the sky terms through ts_horizon_compute +
ts_sky_terms, the driver through ts_horizon_sweep + ts_sky_accumulate). On
the geographic DEM the reference's per-row cell sizes come from the
parallel-arc formula N(phi) cos(phi) dlon, which differs from the driver's
geodesic by < 1e-9 relative, hence a looser 1e-4.
"""
import math
import os
import subprocess
import unittest

import tsdriver as T
from tsdriver import np

CASES = [
    ("shade", {}),
    ("shade", {"SUN_AZIMUTH": 250, "SUN_ELEVATION": 12}),
    ("shade", {"SKY_WEIGHT": 0.4, "DIRECTIONS": 8}),
    ("shade", {"METHOD": "shm", "PENUMBRA_DEPTH": 15, "SUN_ELEVATION": 20}),
    ("shadow", {"SUN_ELEVATION": 8, "SUN_AZIMUTH": 120}),
    ("shadow", {"SUN_ELEVATION": 8, "METHOD": "shm"}),
    ("shadow", {"SUN_ELEVATION": 5, "MAX_DISTANCE": 1500, "CURVATURE": "NO"}),
    ("horizon", {"DIRECTIONS": 6, "START_AZIMUTH": 10}),
    ("horizon", {"DIRECTIONS": 4, "REFRACTION": 0.5}),
    ("svf", {"DIRECTIONS": 12}),
    ("sky", {"DIRECTIONS": 12}),
    ("openness", {"DIRECTIONS": 12, "MAX_DISTANCE": 3000}),
    # EDGE (the cases above run with the default, horizon)
    ("shadow", {"SUN_ELEVATION": -0.5, "SUN_AZIMUTH": 200}),
    ("shade", {"METHOD": "shm", "SUN_ELEVATION": 1}),
    ("openness", {"DIRECTIONS": 8, "EDGE": "open"}),
    ("svf", {"DIRECTIONS": 8, "EDGE": "nodata", "MAX_DISTANCE": 2000}),
    ("shadow", {"SUN_ELEVATION": 8, "METHOD": "shm", "EDGE": "nodata",
                "MAX_DISTANCE": 2000}),
]


def core_reference(tmp, z, cell_x, cell_y, product, options, rows=None):
    raw = os.path.join(tmp, "dem.f32")
    out = os.path.join(tmp, "ref.f32")
    z.astype("<f4").tofile(raw)
    args = [T.CORE_REFERENCE, product, z.shape[1], z.shape[0], repr(cell_x),
            repr(cell_y), raw, out]
    args += ["%s=%s" % kv for kv in options.items()]
    if rows is not None:
        rows_file = os.path.join(tmp, "rows.f64")
        np.asarray(rows, dtype="<f8").tofile(rows_file)
        args.append("ROWS=" + rows_file)
    T.run(args)
    planes = options.get("DIRECTIONS", 16) if product == "horizon" else 1
    return np.fromfile(out, dtype="<f4").reshape(planes, *z.shape).astype(np.float64)


def driver(tmp, dem, product, options, output_type="Float32"):
    opts = dict(options, PRODUCT=product)
    if product in ("shade", "shadow", "svf", "sky"):
        opts["OUTPUT_TYPE"] = output_type
    out = T.translate(dem, os.path.join(tmp, "drv.tif"), opts)
    return T.read(out)


def parallel_arc_rows(gt, height):
    """East-west cell size of each row of a WGS 84 geographic grid."""
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    rows = []
    for y in range(height):
        phi = math.radians(gt[3] + (y + 0.5) * gt[5])
        n = a / math.sqrt(1 - e2 * math.sin(phi) ** 2)
        rows.append(n * math.cos(phi) * math.radians(abs(gt[1])))
    return rows


class CoreEqual(unittest.TestCase):
    def compare(self, dem, z, cell_x, cell_y, tol, rows=None):
        with T.TempDir() as tmp:
            for product, options in CASES:
                with self.subTest(product=product, **options):
                    ref = core_reference(tmp, z, cell_x, cell_y, product,
                                         options, rows)
                    got = driver(tmp, dem, product, options)
                    print(T.describe("%s %s" % (product, options), got, ref))
                    self.assertEqual(got.shape, ref.shape)
                    np.testing.assert_array_equal(np.isnan(got), np.isnan(ref))
                    np.testing.assert_allclose(got, ref, rtol=0, atol=tol)

    def test_projected_dem(self):
        """jacksboro warped to UTM (with a nodata border): identical grids."""
        with T.TempDir() as tmp:
            dem = T.jacksboro_utm(tmp)
            z, gt, _ = T.read_dem(dem)
            self.assertTrue(np.isnan(z).any(), "the warped DEM has a nodata border")
            self.compare(dem, z, abs(gt[1]), abs(gt[5]), 1e-5)

    def test_geographic_dem(self):
        """jacksboro in degrees: per-row geodesic cell sizes."""
        z, gt, _ = T.read_dem(T.JACKSBORO)
        ds = T.gdal.Open(T.conn(T.JACKSBORO))
        cell_y = float(ds.GetMetadataItem("CELL_SIZE_Y"))
        ds = None
        rows = parallel_arc_rows(gt, z.shape[0])
        self.compare(T.JACKSBORO, z, rows[len(rows) // 2], cell_y, 1e-4, rows)

    def test_byte_is_gdaldem_scaling_of_float(self):
        """Byte shade = 1 + 254 * Float32 shade rounded, 0 = nodata."""
        with T.TempDir() as tmp:
            dem = T.jacksboro_utm(tmp)
            f = driver(tmp, dem, "shade", {"SUN_ELEVATION": 20}, "Float32")[0]
            b = driver(tmp, dem, "shade", {"SUN_ELEVATION": 20}, "Byte")[0]
            f32 = f.astype(np.float32)
            scaled = (np.float32(1) + np.float32(254) * f32) + np.float32(0.5)
            expect = np.where(np.isnan(f), np.nan,
                              np.where(f <= 0, 1, np.minimum(255, np.floor(scaled))))
            print(T.describe("Byte vs 1 + 254 * Float32", b, expect))
            np.testing.assert_array_equal(b, expect)


if __name__ == "__main__":
    unittest.main(verbosity=2)
