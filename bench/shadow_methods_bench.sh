#!/bin/sh
# shadow_methods_bench.sh - every shadow method against the exact one: the
# numbers of docs/methods.md's shadow table, in one run.
#
#   bench/shadow_methods_bench.sh [SIZE] [REPEATS]      (defaults: 4096 2)
#
# Generates two SIZE x SIZE fractal DEMs (10 m cells, EPSG:32617, seed 42):
# driver_bench.sh's, very rough (amplitude f^-1.1), and fBm of Hurst exponent
# 0.8 (f^-1.8, the character of real relief), then runs
# bench/shadow_methods.py: for METHOD=exact, shm, shadowmap, sh and sh with
# HORIZON_METHOD=pyramid, the agreement of PRODUCT=shadow with the exact
# method on jacksboro, lux_elev and both fractals at the suns 135/10 and
# 315/30, and the time, CPU and peak memory of PRODUCT=shade on the rough
# fractal with BACKEND=c and BACKEND=opencl beside
# gdaldem hillshade; then the markdown table. Takes about 4 minutes at 4096
# on two cores. Needs /usr/bin/python3 with numpy and osgeo, /usr/bin/time.
set -eu

SIZE=${1:-4096}
REPEATS=${2:-2}
. "$(dirname "$0")/bench_common.sh"
# what the run needs, checked before the minutes of its agreement phase
missing=
for c in gdaldem gdal_translate gdalinfo; do
    command -v "$c" >/dev/null 2>&1 || missing="$missing $c,"
done
[ -x /usr/bin/time ] || missing="$missing /usr/bin/time (GNU time),"
"$PYTHON" -c 'import numpy; from osgeo import gdal' >/dev/null 2>&1 ||
    missing="$missing $PYTHON with numpy and osgeo,"
for f in jacksboro lux_elev; do
    [ -f "$(dirname "$0")/../tests/data/$f.tif" ] || missing="$missing tests/data/$f.tif,"
done
if [ -n "$missing" ]; then
    echo "shadow_methods_bench: needs${missing%,}: not found" >&2
    exit 1
fi
bench_setup shadow_methods_bench
DEM="$WORK/fractal_${SIZE}.tif"
FBM="$WORK/fbm_${SIZE}.tif"

echo "== DEMs: $SIZE x $SIZE cells of 10 m, EPSG:32617, Float32 (bench/fractal_tif.py, seed 42):"
echo "   rough (amplitude f^-1.1, driver_bench.sh's) and fBm (f^-1.8, Hurst 0.8)"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$FBM" 1.8
bench_machine
"$PYTHON" "$(dirname "$0")/shadow_methods.py" "$DEM" "$FBM" "$WORK" "$REPEATS"
