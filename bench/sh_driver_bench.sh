#!/bin/sh
# sh_driver_bench.sh - METHOD=sh (SWATH_DIRECTIONS=3 soft shade) against
# gdaldem hillshade and METHOD=exact, one run (docs/methods.md, "sh").
#
#   bench/sh_driver_bench.sh [SIZE] [REPEATS]      (defaults: 4096 2)
#
# On the same SIZE x SIZE fractal (bench/fractal_tif.py: 10 m cells,
# EPSG:32617) it times, best of REPEATS,
#   gdaldem hillshade dem.tif out.tif
#   gdal_translate -oo OUTPUT_TYPE=Byte TERRASHADE:dem.tif out.tif      (exact)
#   gdal_translate -oo METHOD=sh TERRASHADE:dem.tif out.tif             (3 sweeps)
# and prints the ratios. Goal: METHOD=sh within 2x gdaldem's time.
# Run from the build tree (as bench/driver_bench.sh).
set -eu

SIZE=${1:-4096}
REPEATS=${2:-2}
PYTHON=${PYTHON:-/usr/bin/python3}
BUILDDIR=${BUILDDIR:-$(pwd)}
if [ -f "$BUILDDIR/plugin/.libs/gdal_TERRASHADE.so" ]; then
    GDAL_DRIVER_PATH="$BUILDDIR/plugin/.libs"
    export GDAL_DRIVER_PATH
fi
if ! gdalinfo --formats | grep -q TERRASHADE; then
    echo "sh_driver_bench: GDAL cannot find the TERRASHADE driver; build it (make)" \
         "and run from the build directory, or set GDAL_DRIVER_PATH" >&2
    exit 1
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sh_driver_bench.XXXXXX")
trap 'rm -rf "$WORK"' EXIT INT TERM
DEM="$WORK/fractal_${SIZE}.tif"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM"
echo "== $SIZE x $SIZE fractal; $(nproc) CPU(s), load $(cut -d' ' -f1-3 /proc/loadavg)"

# best wall time of REPEATS runs of a command, in seconds
best_time() {
    best=""
    i=0
    while [ "$i" -lt "$REPEATS" ]; do
        rm -f "$WORK/out.tif"
        t0=$(date +%s.%N)
        "$@" >/dev/null
        t1=$(date +%s.%N)
        best=$(awk -v a="$t0" -v b="$t1" -v best="$best" \
            'BEGIN { t = b - a; if (best == "" || t < best) best = t; print best }')
        i=$((i + 1))
    done
    printf '%.3f' "$best"
}

T_DEM=$(best_time gdaldem hillshade -q "$DEM" "$WORK/out.tif")
echo "   gdaldem hillshade:            ${T_DEM} s"
T_EXACT=$(best_time gdal_translate -q -oo PROGRESS=no "TERRASHADE:$DEM" "$WORK/out.tif")
echo "   shade, METHOD=exact:          ${T_EXACT} s"
T_SH=$(best_time gdal_translate -q -oo PROGRESS=no -oo METHOD=sh -oo SWATH_DIRECTIONS=3 \
    "TERRASHADE:$DEM" "$WORK/out.tif")
echo "   shade, METHOD=sh (3 sweeps):  ${T_SH} s"
awk -v a="$T_SH" -v b="$T_DEM" -v c="$T_EXACT" 'BEGIN {
    printf "== METHOD=sh / gdaldem = %.2f (goal <= 2); METHOD=sh / exact = %.2f\n", a / b, a / c }'
