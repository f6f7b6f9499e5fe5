#!/bin/sh
# bounded_driver_bench.sh - MAX_DISTANCE through the driver against the
# unbounded sweep: issue 10 item 3's own example, one run.
#
#   bench/bounded_driver_bench.sh [SIZE] [DISTANCES] [REPEATS] [CELL] [RELIEF]
#                                 (defaults: 1000 30,100,500 2 1 150)
#
# Generates a SIZE x SIZE DEM of CELL m cells, fBm of Hurst exponent 0.8 with
# RELIEF m of relief (bench/fractal_tif.py, seed 42; the defaults have the
# character of a lidar DEM), then times whole gdal_translate processes of
#   PRODUCT=horizon DIRECTIONS=4      (the issue: 4.4 s bounded, 0.6 s not)
#   PRODUCT=svf DIRECTIONS=32         (the issue: 52 s bounded, 2 s not)
# unbounded and with each MAX_DISTANCE (metres), in REPEATS rounds that each
# run every command once (so that all of them see the host's speed of the
# same minutes), and prints the best wall time of each and its ratio to the
# unbounded run of the same product. Goal: <= 1.5 at every distance. The
# core's figure, without GDAL's reading and writing, is bench/ts_bench's
# (--size 1000 --cell 1 --relief 150 --dirs 32 --max-distance 0,30,100,...).
set -eu

SIZE=${1:-1000}
DISTANCES=${2:-30,100,500}
REPEATS=${3:-2}
CELL=${4:-1}
RELIEF=${5:-150}
. "$(dirname "$0")/bench_common.sh"
bench_setup bounded_driver_bench
DEM="$WORK/fbm_${SIZE}.tif"

echo "== DEM: $SIZE x $SIZE cells of $CELL m, EPSG:32617, Float32, fBm (Hurst 0.8), $RELIEF m of relief"
echo "   (bench/fractal_tif.py $SIZE DEM 1.8 $CELL $RELIEF, seed 42)"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM" 1.8 "$CELL" "$RELIEF"
bench_machine

# the commands: product:directions:distance (0: unbounded)
DLIST=$(echo "$DISTANCES" | tr ',' ' ')
RUNS=""
for p in horizon:4 svf:32; do
    RUNS="$RUNS $p:0"
    for d in $DLIST; do
        RUNS="$RUNS $p:$d"
    done
done

cmd() {
    product=$(echo "$1" | cut -d: -f1)
    dirs=$(echo "$1" | cut -d: -f2)
    dist=$(echo "$1" | cut -d: -f3)
    echo "gdal_translate -q -oo PRODUCT=$product -oo DIRECTIONS=$dirs -oo MAX_DISTANCE=$dist" \
         "'TERRASHADE:$DEM' '$WORK/out.tif'"
}

bench_rounds "$RUNS"

for p in horizon:4 svf:32; do
    eval "base=\$T_$(bench_key "$p:0")"
    echo "   $(echo "$p" | cut -d: -f1), $(echo "$p" | cut -d: -f2) directions, unbounded: $base s"
    for d in $DLIST; do
        eval "t=\$T_$(bench_key "$p:$d")"
        awk -v t="$t" -v b="$base" -v d="$d" \
            'BEGIN { printf "     MAX_DISTANCE=%-6s %7.3f s, %.2fx the unbounded (goal <= 1.5)\n", d, t, t / b }'
    done
done
