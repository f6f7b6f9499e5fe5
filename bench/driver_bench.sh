#!/bin/sh
# driver_bench.sh - the TERRASHADE driver against gdaldem hillshade, one run.
#
#   bench/driver_bench.sh [SIZE] [REPEATS]      (defaults: 4096 3)
#
# Generates a SIZE x SIZE fractal DEM with 10 m cells in EPSG:32617, then
# times, on the same DEM and in the same run,
#   gdaldem hillshade dem.tif out.tif                       (no cast shadows)
#   gdal_translate TERRASHADE:dem.tif out.tif              (cast shadows)
#   ... with METHOD=shm, METHOD=sh SWATH_DIRECTIONS=3 (sweeps, then pyramid
#   horizons) and METHOD=shadowmap (docs/methods.md)
# in REPEATS rounds that each run every command once (so that all of them see
# the host's speed of the same minutes), and prints the best wall time of each
# and the ratios.
# Goal: ratio <= 1.5.
#
# The plugin is taken from $BUILDDIR/plugin/.libs (BUILDDIR defaults to the
# current directory, i.e. run it from the build tree) or, if that has no
# gdal_TERRASHADE.so, from wherever GDAL finds it (GDAL_DRIVER_PATH or the
# installed plugin directory). Needs /usr/bin/python3 with numpy and osgeo.
set -eu

SIZE=${1:-4096}
REPEATS=${2:-3}
. "$(dirname "$0")/bench_common.sh"
bench_setup driver_bench
DEM="$WORK/fractal_${SIZE}.tif"

echo "== DEM: $SIZE x $SIZE cells of 10 m, EPSG:32617, Float32"
echo "   synthesis: spectral (FFT) fractal surface, amplitude ~ f^-1.1"
echo "   (power spectrum f^-2.2), fixed seed 42, scaled to 100..1500 m"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM"

bench_machine

# The commands, run in rounds (bench_rounds), each keeping its best.
NAMES="DEM TS SHM SH SHP SM"
cmd() {
    case "$1" in
    DEM) echo "gdaldem hillshade -q '$DEM' '$WORK/out.tif'" ;;
    TS) echo "gdal_translate -q TERRASHADE:'$DEM' '$WORK/out.tif'" ;;
    SHM) echo "gdal_translate -q -oo METHOD=shm TERRASHADE:'$DEM' '$WORK/out.tif'" ;;
    SH) echo "gdal_translate -q -oo METHOD=sh -oo SWATH_DIRECTIONS=3 TERRASHADE:'$DEM' '$WORK/out.tif'" ;;
    SHP) echo "gdal_translate -q -oo METHOD=sh -oo HORIZON_METHOD=pyramid TERRASHADE:'$DEM' '$WORK/out.tif'" ;;
    SM) echo "gdal_translate -q -oo METHOD=shadowmap TERRASHADE:'$DEM' '$WORK/out.tif'" ;;
    esac
}
bench_rounds "$NAMES"
echo "   gdaldem hillshade:             ${T_DEM} s"
echo "   TERRASHADE shade (cast shadows): ${T_TS} s"
echo "   TERRASHADE shade, METHOD=shm:    ${T_SHM} s  (for reference)"
echo "   TERRASHADE shade, METHOD=sh:     ${T_SH} s  (SH soft key light, 3 sweeps)"
echo "   TERRASHADE shade, METHOD=sh, pyramid: ${T_SHP} s  (the swath's horizons from the pyramid)"
echo "   TERRASHADE shade, METHOD=shadowmap: ${T_SM} s  (docs/methods.md)"
awk -v a="$T_TS" -v b="$T_DEM" -v c="$T_SHM" -v d="$T_SH" -v e="$T_SM" -v f="$T_SHP" 'BEGIN {
    printf "== ratio TERRASHADE / gdaldem = %.2f (goal <= 1.5)\n", a / b
    printf "   (METHOD=shm: %.2f; METHOD=sh: %.2f, with pyramid horizons %.2f, goal <= 2;\n",
           c / b, d / b, f / b
    printf "   METHOD=shadowmap: %.2f)\n", e / b }'
echo "   (CPL_DEBUG=TERRASHADE gdal_translate ... shows the driver's own timings)"
