#!/bin/sh
# peers_bench.sh - sky-view factor: TERRASHADE against RVT_py, one run.
#
#   bench/peers_bench.sh [SIZE] [DIRS] [R_MAX]      (defaults: 1024 16 100)
#
# Generates a SIZE x SIZE fractal DEM with 10 m cells (bench/fractal_tif.py)
# and times, on the same DEM and in the same run, each as a whole process
# that reads the GeoTIFF and writes a Float32 GeoTIFF:
#   RVT_py 2.2.3 rvt.vis.sky_view_factor, DIRS directions, svf_r_max R_MAX px
#   gdal_translate -oo PRODUCT=svf, the same directions, MAX_DISTANCE R_MAX
#       cells, CURVATURE=NO, SVF_MODEL=solid_angle (RVT's definition;
#       tests/driver/test_rvt.py holds the two within 0.01)
#   gdal_translate -oo PRODUCT=svf, the same directions, unbounded (exact
#       horizons over the whole DEM, with Earth curvature: the default)
# and prints each one's pixel-directions per second and the ratios.
#
# RVT_py comes from a venv made by tests/rvt-venv.sh in $BUILDDIR/tests
# (pip, once; the same venv as `make check`'s comparison). The plugin is
# taken as in bench/driver_bench.sh (bench_common.sh). SAGA and GRASS are
# not Debian dependencies of this project and are not timed here.
set -eu

SIZE=${1:-1024}
DIRS=${2:-16}
R_MAX=${3:-100}
. "$(dirname "$0")/bench_common.sh"
bench_setup peers_bench
DEM="$WORK/fractal_${SIZE}.tif"
SRCDIR=$(cd "$(dirname "$0")/.." && pwd)
RVT_PY=$(sh "$SRCDIR/tests/rvt-venv.sh" "$BUILDDIR/tests/rvt-venv") || {
    echo "peers_bench: no RVT_py venv (tests/rvt-venv.sh failed)" >&2
    exit 1
}

echo "== DEM: $SIZE x $SIZE cells of 10 m (bench/fractal_tif.py, seed 42)"
"$PYTHON" "$SRCDIR/bench/fractal_tif.py" "$SIZE" "$DEM"
bench_machine

cat >"$WORK/rvt_svf.py" <<EOF
import sys
import numpy as np
from osgeo import gdal
import rvt.vis
src = gdal.Open(sys.argv[1])
z = src.GetRasterBand(1).ReadAsArray().astype(np.float32)
out = rvt.vis.sky_view_factor(dem=z, resolution=10.0, compute_svf=True,
                              compute_opns=False, svf_n_dir=$DIRS,
                              svf_r_max=$R_MAX, svf_noise=0, ve_factor=1)
dst = gdal.GetDriverByName("GTiff").Create(sys.argv[2], z.shape[1], z.shape[0],
                                           1, gdal.GDT_Float32)
dst.SetGeoTransform(src.GetGeoTransform())
dst.SetProjection(src.GetProjection())
dst.GetRasterBand(1).WriteArray(out["svf"].astype(np.float32))
dst = None
EOF

# wall seconds of one run of a command
wall() {
    rm -f "$WORK/out.tif"
    t0=$(date +%s.%N)
    "$@" >/dev/null
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'
}
rate() { # seconds -> M pixel-directions per second
    awk -v t="$1" -v n="$SIZE" -v k="$DIRS" 'BEGIN { printf "%.2f", n * n * k / t / 1e6 }'
}

DIST=$((R_MAX * 10))
TS_OPTS="-oo PRODUCT=svf -oo DIRECTIONS=$DIRS -oo START_AZIMUTH=0 -oo OUTPUT_TYPE=Float32"
echo "\$ $RVT_PY rvt_svf.py dem.tif out.tif        (svf_n_dir=$DIRS, svf_r_max=$R_MAX)"
T_RVT=$(wall "$RVT_PY" "$WORK/rvt_svf.py" "$DEM" "$WORK/out.tif")
echo "   RVT_py sky_view_factor:            $T_RVT s, $(rate "$T_RVT") M px·dir/s"
echo "\$ gdal_translate -q $TS_OPTS -oo MAX_DISTANCE=$DIST -oo CURVATURE=NO -oo SVF_MODEL=solid_angle TERRASHADE:dem.tif out.tif"
# shellcheck disable=SC2086
T_CAP=$(wall gdal_translate -q $TS_OPTS -oo MAX_DISTANCE=$DIST -oo CURVATURE=NO \
    -oo SVF_MODEL=solid_angle "TERRASHADE:$DEM" "$WORK/out.tif")
echo "   TERRASHADE svf, $DIST m (= RVT's): $T_CAP s, $(rate "$T_CAP") M px·dir/s"
echo "\$ gdal_translate -q $TS_OPTS TERRASHADE:dem.tif out.tif"
# shellcheck disable=SC2086
T_ALL=$(wall gdal_translate -q $TS_OPTS "TERRASHADE:$DEM" "$WORK/out.tif")
echo "   TERRASHADE svf, unbounded:         $T_ALL s, $(rate "$T_ALL") M px·dir/s"
awk -v r="$T_RVT" -v c="$T_CAP" -v a="$T_ALL" 'BEGIN {
    printf "== RVT_py / TERRASHADE (same distance) = %.1fx; RVT_py / TERRASHADE (unbounded) = %.1fx\n",
           r / c, r / a }'
