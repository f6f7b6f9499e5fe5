#!/usr/bin/python3
"""Checksums of every product through the driver, for refactors that must
not change behaviour (not part of make check).

For each DEM (jacksboro, lux_elev, a 512x512 fractal made here with a fixed
seed), each backend (c, opencl) and each product variant below, the driver's
output is read through GDAL and its bytes hashed (SHA-256, first 16 hex),
every NaN as the one quiet NaN (its payload bits say nothing, and a clang
build's OpenCL sky sums carried other ones through PoCL).

    /usr/bin/python3 tests/product_checksums.py > after.txt   # from the build dir
    diff tests/product_checksums.txt after.txt   # the record, kept up to date
    /usr/bin/python3 tests/product_checksums.py --save DIR     # also keep the arrays
    /usr/bin/python3 tests/product_checksums.py --compare DIR  # max |difference|
                                                               # against kept arrays
    /usr/bin/python3 tests/product_checksums.py --cross        # also max |C - OpenCL|
                                                               # per DEM and variant
    /usr/bin/python3 tests/product_checksums.py --cross-saved DIR  # the same, from
                                                               # arrays kept by --save

Run it from the top build directory (it uses plugin/.libs in place).
"""
import argparse
import hashlib
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "driver"))
import tsdriver as T  # noqa: E402  (sets GDAL_DRIVER_PATH)
from tsdriver import gdal, np  # noqa: E402

DAY = {"DATE": "2026-06-21", "TIMEZONE": "+00:00", "STEP_MINUTES": "30"}

# name -> open options (PROGRESS=no everywhere)
VARIANTS = {
    "shade": {},
    "shade_f32": {"OUTPUT_TYPE": "Float32"},
    "shade_sky": {"SKY_WEIGHT": "0.4", "DIRECTIONS": "8"},
    "shade_lowsun": {"SUN_AZIMUTH": "135", "SUN_ELEVATION": "8", "OUTPUT_TYPE": "Float32"},
    "shade_shm": {"METHOD": "shm", "SUN_ELEVATION": "12", "PENUMBRA_DEPTH": "20",
                  "OUTPUT_TYPE": "Float32"},
    "shade_datetime": {"DATETIME": "2026-12-21T09:00:00+00:00", "OUTPUT_TYPE": "Float32"},
    "shade_percell": {"DATETIME": "2026-12-21T09:00:00+00:00", "SUN_POSITION": "per_cell",
                      "OUTPUT_TYPE": "Float32"},
    "shadow": {"SUN_AZIMUTH": "135", "SUN_ELEVATION": "10"},
    "shadow_byte": {"SUN_AZIMUTH": "135", "SUN_ELEVATION": "10", "OUTPUT_TYPE": "Byte"},
    "shadow_shm": {"METHOD": "shm", "SUN_ELEVATION": "10"},
    "shadow_maxdist": {"SUN_ELEVATION": "5", "MAX_DISTANCE": "2000", "CURVATURE": "NO"},
    "horizon": {"DIRECTIONS": "8", "START_AZIMUTH": "10"},
    "svf": {"DIRECTIONS": "16"},
    "svf_byte": {"DIRECTIONS": "16", "OUTPUT_TYPE": "Byte"},
    "openness": {"DIRECTIONS": "16"},
    "sky": {"DIRECTIONS": "16", "Z_FACTOR": "2"},
    "sunhours": dict(DAY),
    "sunhours_fraction": dict(DAY, SUNHOURS_RULE="fraction"),
    "insolation": dict(DAY, LINKE_TURBIDITY="4"),
    "daycycle": dict(DAY, STEP_MINUTES="120"),
    "farshadow": dict(DAY, ATLAS_STEPS="6", FAR_THRESHOLD="32"),
    "svf_solid": {"DIRECTIONS": "16", "SVF_MODEL": "solid_angle"},
    "openness_negative": {"DIRECTIONS": "16", "OPENNESS": "negative"},
}

# The world beyond the DEM edge (EDGE, docs/algorithms.md): the default,
# EDGE=horizon, since it became the default; the variants above run with
# EDGE=open (the behaviour before EDGE) wherever the product takes EDGE, so
# that their lines stay as they were. Printed last.
EDGE_VARIANTS = {
    "shade_edge": {"SUN_AZIMUTH": "135", "SUN_ELEVATION": "2", "OUTPUT_TYPE": "Float32"},
    "shade_edgeshm": {"METHOD": "shm", "SUN_ELEVATION": "1", "OUTPUT_TYPE": "Float32"},
    "shadow_edge": {"SUN_AZIMUTH": "135", "SUN_ELEVATION": "-0.5"},
    "shadow_edgenodata": {"SUN_ELEVATION": "5", "MAX_DISTANCE": "2000", "EDGE": "nodata"},
    "horizon_edge": {"DIRECTIONS": "8", "START_AZIMUTH": "10"},
    "svf_edge": {"DIRECTIONS": "16"},
    "openness_edge": {"DIRECTIONS": "16"},
    "openness_edgenodata": {"DIRECTIONS": "16", "MAX_DISTANCE": "3000", "EDGE": "nodata"},
    # (the negated DEM's rays see the DEM alone: openness_negative's sums)
    "openness_negedge": {"DIRECTIONS": "16", "OPENNESS": "negative"},
    "sky_edge": {"DIRECTIONS": "16", "CURVATURE": "NO"},
    "sunhours_edge": dict(DAY),
    "insolation_edge": dict(DAY, LINKE_TURBIDITY="4"),
    "envlight_edge": {"SKY": "cie:7", "SUN_AZIMUTH": "120", "SUN_ELEVATION": "25",
                      "DIRECTIONS": "8"},
}


def takes_edge():
    """The products whose options list EDGE (the driver's product table)."""
    import xml.etree.ElementTree as ET
    xml = gdal.GetDriverByName("TERRASHADE").GetMetadataItem("TERRASHADE_PRODUCTS")
    return {p.get("name") for p in ET.fromstring(xml)
            if "EDGE" in p.get("options").split(",")}


# Environment light (docs/envlight.md): printed after all the above, so that
# the earlier lines keep their places.
ENVMAPS = os.path.join(T.DATA, "envmaps")
SUNSET = os.path.join(ENVMAPS, "sunset.exr")
ENV_VARIANTS = {
    "envlight_sky": {"SKY": "cie:7", "SUN_AZIMUTH": "120", "SUN_ELEVATION": "25",
                     "DIRECTIONS": "8"},
    "envlight_map": {"ENV_MAP": SUNSET, "ENV_ROTATION": "45", "DIRECTIONS": "8"},
    "envlight_cube": {"ENV_MAP": os.path.join(ENVMAPS, "sunset_cube128.exr"),
                      "DIRECTIONS": "8", "ENV_NORMAL_STEPS": "33"},
    "envlight_byte": {"ENV_MAP": SUNSET, "OUTPUT_TYPE": "Byte", "DIRECTIONS": "8"},
    "shade_clearsky": {"SKY": "clear", "SKY_WEIGHT": "0.5", "DIRECTIONS": "8",
                       "DATETIME": "2026-06-21T08:00:00-05:00", "OUTPUT_TYPE": "Float32"},
    "shade_envmap": {"ENV_MAP": SUNSET, "SKY_WEIGHT": "0.3", "DIRECTIONS": "8"},
}

# Date ranges (docs/day-cycle.md, "date ranges"): printed after the above.
YEAR_VARIANTS = {
    "sunhours_range": {"START_DATE": "2026-06-01", "END_DATE": "2026-06-30",
                       "TIMEZONE": "+00:00"},
    "insolation_range": {"START_DATE": "2026-03-01", "END_DATE": "2026-03-21",
                         "TIMEZONE": "+00:00", "DAY_INTERVAL": "7",
                         "HORIZON_DIRECTIONS": "32"},
}

# The other users of the hand-written vector code (TERRASHADE_SIMD,
# tests/driver/test_cpu_paths.py): METHOD=sh's 16-cell blocks, the bounded
# sweep's short, pruned (64-256 lags) and long (hybrid) windows, the windowed
# path's far field, the shadow map. Printed last.
CPU_VARIANTS = {
    "shade_sh": {"METHOD": "sh", "SUN_ELEVATION": "20", "OUTPUT_TYPE": "Float32"},
    "shadow_shadowmap": {"METHOD": "shadowmap", "SUN_ELEVATION": "15"},
    "horizon_bounded": {"DIRECTIONS": "8", "START_AZIMUTH": "10", "MAX_DISTANCE": "3000"},
    "horizon_far": {"DIRECTIONS": "8", "START_AZIMUTH": "10", "MAX_DISTANCE": "20000"},
    "svf_tiled": {"DIRECTIONS": "16", "TILE_SIZE": "128", "NEAR_DISTANCE": "2000"},
}

# Pyramid horizons (HORIZON_METHOD=pyramid, docs/methods.md): printed after
# the above.
PYRAMID_VARIANTS = {
    "horizon_pyramid": {"DIRECTIONS": "8", "START_AZIMUTH": "10", "HORIZON_METHOD": "pyramid",
                        "PYRAMID_OFFSET": "1"},
    "svf_pyramid": {"DIRECTIONS": "16", "HORIZON_METHOD": "pyramid"},
    "envlight_pyramid": {"SKY": "uniform", "DIRECTIONS": "8", "HORIZON_METHOD": "pyramid",
                         "PYRAMID_LEVEL_STEP": "2"},
}


def fractal_dem(path, n=512, seed=7):
    """Spectral-synthesis fractal (beta 2.2), 30 m cells, UTM 33N."""
    rng = np.random.default_rng(seed)
    fx = np.fft.fftfreq(n)[:, None]
    fy = np.fft.fftfreq(n)[None, :]
    f = np.sqrt(fx * fx + fy * fy)
    f[0, 0] = 1.0
    spec = (rng.normal(size=(n, n)) + 1j * rng.normal(size=(n, n))) / f ** 1.1
    spec[0, 0] = 0
    z = np.real(np.fft.ifft2(spec))
    z = (z - z.min()) / (z.max() - z.min()) * 1500.0 + 200.0
    drv = gdal.GetDriverByName("GTiff")
    ds = drv.Create(path, n, n, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((500000.0, 30.0, 0.0, 5200000.0, 0.0, -30.0))
    ds.SetProjection(_utm33())
    ds.GetRasterBand(1).WriteArray(z.astype(np.float32))
    ds = None


def _utm33():
    from osgeo import osr
    s = osr.SpatialReference()
    s.ImportFromEPSG(32633)
    return s.ExportToWkt()


def canonical_nans(a):
    """a with every NaN the quiet NaN of its type (0x7fc00000 in float32)."""
    if a.dtype.kind != "f":
        return a
    return np.where(np.isnan(a), np.array(np.nan, dtype=a.dtype), a)


def read_all(ds):
    bands = [ds.GetRasterBand(i + 1) for i in range(ds.RasterCount)]
    return np.stack([b.ReadAsArray() for b in bands])


def max_abs_diff(a, b):
    """Largest |a - b| over the cells valid in both, and whether nodata
    (NaN) falls on the same cells."""
    a = a.astype(np.float64)
    b = b.astype(np.float64)
    same_nan = np.array_equal(np.isnan(a), np.isnan(b))
    d = np.abs(a - b)
    return (float(np.nanmax(d)) if np.isfinite(d).any() else 0.0), same_nan


def cross_line(key, c, cl):
    m, same_nan = max_abs_diff(c, cl)
    return "%-28s max|C - OpenCL| %.3g%s" % (key, m, "" if same_nan else "  NODATA DIFFERS")


def cross_saved(path):
    """--cross-saved: max |C - OpenCL| from arrays kept by --save."""
    for f in sorted(os.listdir(path)):
        parts = f[:-len(".npy")].split(".")
        if not f.endswith(".npy") or len(parts) != 3 or parts[1] != "c":
            continue
        other = os.path.join(path, "%s.opencl.%s.npy" % (parts[0], parts[2]))
        if os.path.exists(other):
            print(cross_line("%s.%s" % (parts[0], parts[2]),
                             np.load(os.path.join(path, f)), np.load(other)), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--save", metavar="DIR", help="also save every array as .npy")
    ap.add_argument("--compare", metavar="DIR", help="max |diff| against saved arrays")
    ap.add_argument("--only", help="comma-separated variant names")
    ap.add_argument("--backends", default="c,opencl")
    ap.add_argument("--dems", default="jacksboro,lux,fractal",
                    help="comma-separated DEMs of jacksboro, lux, fractal")
    ap.add_argument("--cross", action="store_true",
                    help="also print max |C - OpenCL| per DEM and variant")
    ap.add_argument("--cross-saved", metavar="DIR",
                    help="only print max |C - OpenCL| from arrays kept by --save")
    args = ap.parse_args()
    if args.cross_saved:
        cross_saved(args.cross_saved)
        return
    tmp = tempfile.mkdtemp(prefix="ts_cksum_")
    fractal = os.path.join(tmp, "fractal.tif")
    dems = {"jacksboro": T.JACKSBORO, "lux": T.LUX, "fractal": fractal}
    wanted = args.dems.split(",")
    if set(wanted) - set(dems):
        ap.error("--dems: unknown %s" % ",".join(sorted(set(wanted) - set(dems))))
    dems = {k: v for k, v in dems.items() if k in wanted}
    if "fractal" in dems:
        fractal_dem(fractal)
    variants = dict(VARIANTS, **ENV_VARIANTS, **YEAR_VARIANTS, **EDGE_VARIANTS,
                    **PYRAMID_VARIANTS, **CPU_VARIANTS)
    edge_products = takes_edge()
    names = args.only.split(",") if args.only else list(variants)
    if args.save:
        os.makedirs(args.save, exist_ok=True)
    worst = 0.0
    crossed = []
    # the variants of the first group come first in the record, each group
    # DEM by DEM, so that added groups append lines to it
    for group in (VARIANTS, ENV_VARIANTS, YEAR_VARIANTS, EDGE_VARIANTS, PYRAMID_VARIANTS,
                  CPU_VARIANTS):
        for dem_name, dem in dems.items():
            kept = {}
            for backend in args.backends.split(","):
                for name in [n for n in names if n in group]:
                    product = name.split("_")[0]
                    oo = dict(variants[name], PRODUCT=product, BACKEND=backend,
                              PROGRESS="no")
                    if group is not EDGE_VARIANTS and product in edge_products:
                        oo["EDGE"] = "open"  # the record from before EDGE
                    if dem_name == "lux" and name == "svf_tiled":
                        # 2000 m is 3.4 of lux's cells, refused since session
                        # 51 where lux fits in one tile (the whole DEM, the
                        # same pixels without it)
                        del oo["NEAR_DISTANCE"]
                    ds = gdal.OpenEx("TERRASHADE:" + dem,
                                     open_options=["%s=%s" % kv for kv in oo.items()])
                    a = read_all(ds)
                    ds = None
                    key = "%s.%s.%s" % (dem_name, backend, name)
                    h = hashlib.sha256(canonical_nans(a).tobytes()).hexdigest()[:16]
                    line = "%-34s %s %s %s" % (key, a.dtype, "x".join(map(str, a.shape)), h)
                    if args.save:
                        np.save(os.path.join(args.save, key + ".npy"), a)
                    if args.compare:
                        ref = np.load(os.path.join(args.compare, key + ".npy"))
                        m, same_nan = max_abs_diff(a, ref)
                        worst = max(worst, m)
                        line += "  max|diff| %.3g%s" % (m, "" if same_nan else
                                                         "  NODATA DIFFERS")
                    if args.cross:
                        kept[(backend, name)] = a
                    print(line, flush=True)
            if args.cross:
                crossed += [cross_line("%s.%s" % (dem_name, name), kept[("c", name)],
                                       kept[("opencl", name)])
                            for name in names
                            if ("c", name) in kept and ("opencl", name) in kept]
    for line in crossed:
        print(line)
    if args.compare:
        print("worst max|diff| %.3g" % worst)


if __name__ == "__main__":
    main()
