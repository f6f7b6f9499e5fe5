#!/bin/sh
# svf_methods_bench.sh - svf through the driver: the pyramid against the
# exact sweep, whole gdal_translate processes, one run.
#
#   bench/svf_methods_bench.sh [SIZE] [DIRS] [REPEATS]   (defaults: 4096 64 2)
#
# Generates the SIZE x SIZE fractal DEM of driver_bench.sh (10 m cells,
# EPSG:32617, seed 42), then times, on it and in the same run,
#   gdal_translate -oo PRODUCT=svf -oo DIRECTIONS=DIRS -oo HORIZON_METHOD=exact
#   gdal_translate ... -oo HORIZON_METHOD=pyramid
# with every core (THREADS=0, the default) and with THREADS=1, each REPEATS
# times alternated, and prints the best wall time of each with the CPU time
# (user + system) of that run, and the ratios pyramid / exact. Issue 12's
# goal: pyramid svf with 64 directions at most 0.5x the exact sweep's time
# on the 4096^2 fractal. The core-only figure (no GDAL, no EDGE, the svf
# summed after each sweep) is bench/methods_bench's. Needs /usr/bin/time.
set -eu

SIZE=${1:-4096}
DIRS=${2:-64}
REPEATS=${3:-2}
. "$(dirname "$0")/bench_common.sh"
bench_setup svf_methods_bench
DEM="$WORK/fractal_${SIZE}.tif"

echo "== DEM: $SIZE x $SIZE cells of 10 m, EPSG:32617, Float32 (bench/fractal_tif.py, seed 42)"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM"
bench_machine

# one run: "wall cpu" in seconds
one_run() {
    rm -f "$WORK/out.tif"
    /usr/bin/time -f "%e %U %S" -o "$WORK/time.txt" gdal_translate -q -oo PRODUCT=svf \
        -oo DIRECTIONS="$DIRS" -oo HORIZON_METHOD="$1" -oo THREADS="$2" \
        "TERRASHADE:$DEM" "$WORK/out.tif" >/dev/null
    awk '{ printf "%.3f %.3f", $1, $2 + $3 }' "$WORK/time.txt"
}

for threads in 0 1; do
    best_e="" best_p=""
    i=0
    while [ "$i" -lt "$REPEATS" ]; do
        r=$(one_run exact "$threads")
        best_e=$(echo "$r $best_e" | awk '{ if (NF < 4 || $1 < $3) print $1, $2; else print $3, $4 }')
        r=$(one_run pyramid "$threads")
        best_p=$(echo "$r $best_p" | awk '{ if (NF < 4 || $1 < $3) print $1, $2; else print $3, $4 }')
        i=$((i + 1))
    done
    echo "\$ gdal_translate -q -oo PRODUCT=svf -oo DIRECTIONS=$DIRS -oo HORIZON_METHOD=exact|pyramid -oo THREADS=$threads TERRASHADE:$DEM out.tif  (best of $REPEATS)"
    echo "$best_e $best_p" | awk -v t="$threads" '{
        printf "   THREADS=%s: exact %.2f s (CPU %.2f s), pyramid %.2f s (CPU %.2f s)\n", t, $1, $2, $3, $4
        printf "   pyramid / exact = %.3f wall, %.3f CPU (goal <= 0.5)\n", $3 / $1, $4 / $2 }'
done
echo "== load $(cut -d' ' -f1-3 /proc/loadavg)"
