#!/bin/sh
# overview_bench.sh - time to read each overview level of a TERRASHADE
# product, as a program zoomed out reads it, one run.
#
#   bench/overview_bench.sh [SIZE] [PRODUCT_OPTIONS...]
#       (defaults: 4096, -oo PRODUCT=svf -oo DIRECTIONS=8)
#
# Generates a SIZE x SIZE fractal DEM (the one of bench/driver_bench.sh:
# 10 m cells, EPSG:32617, Float32, seed 42), then for level 0 (the full
# resolution) and each overview level k = 1, 2, ... times
#   gdal_translate [-ovr k-1] PRODUCT_OPTIONS TERRASHADE:dem.tif out.tif
# in a fresh process (the level is computed from the DEM read at its size,
# then written), and prints each time and its ratio to level 0.
#
# The plugin is taken from $BUILDDIR/plugin/.libs (BUILDDIR defaults to the
# current directory, i.e. run it from the build tree) or from wherever GDAL
# finds it. Needs /usr/bin/python3 with numpy and osgeo.
set -eu

SIZE=${1:-4096}
[ $# -gt 0 ] && shift
if [ $# -eq 0 ]; then
    set -- -oo PRODUCT=svf -oo DIRECTIONS=8
fi
. "$(dirname "$0")/bench_common.sh"
bench_setup overview_bench
DEM="$WORK/fractal_${SIZE}.tif"

echo "== DEM: $SIZE x $SIZE cells of 10 m, EPSG:32617, Float32 (fractal, seed 42)"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM"

bench_machine
echo "== options: $*"
LEVELS=$(gdalinfo "$@" "TERRASHADE:$DEM" | sed -n 's/^ *Overviews: //p' | head -n 1 |
         tr ',' '\n' | grep -c x || true)

seconds() {
    t0=$(date +%s.%N)
    "$@" >/dev/null
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'
}

T0=""
k=0
while [ "$k" -le "$LEVELS" ]; do
    rm -f "$WORK/out.tif"
    if [ "$k" -eq 0 ]; then
        T=$(seconds gdal_translate -q "$@" "TERRASHADE:$DEM" "$WORK/out.tif")
        T0=$T
    else
        T=$(seconds gdal_translate -q -ovr $((k - 1)) "$@" "TERRASHADE:$DEM" \
            "$WORK/out.tif")
    fi
    DIM=$(gdalinfo "$WORK/out.tif" | sed -n 's/^Size is \(.*\), \(.*\)/\1 x \2/p')
    awk -v k="$k" -v d="$DIM" -v t="$T" -v t0="$T0" 'BEGIN {
        printf "   level %d (%s): %7.3f s  (%.1fx faster than level 0)\n",
               k, d, t, t0 / t }'
    k=$((k + 1))
done
echo "   (gdal_translate [-ovr k-1] $* TERRASHADE:dem.tif out.tif, fresh process each)"
