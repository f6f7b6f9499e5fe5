#!/bin/sh
# voids_bench.sh - what scattered nodata costs: svf and a day of sun hours
# on the same DEM with a fraction of its cells made nodata, one run.
#
#   bench/voids_bench.sh [SIZE] [FRACTIONS] [REPEATS]   (defaults: 1024 0.01,0.1,0.5 2)
#
# Generates a SIZE x SIZE DEM of 1 m cells, fBm of Hurst exponent 0.8 with
# 150 m of relief (bench/fractal_tif.py SIZE DEM 1.8 1 150, seed 42: the
# character of a lidar DEM), and copies of it with each FRACTION of its
# cells nodata, scattered (numpy seed 7; lidar DEMs have such voids where
# no return came back: water, dark roofs), then times whole gdal_translate
# processes of
#   PRODUCT=svf DIRECTIONS=32
#   PRODUCT=sunhours DATE=2026-06-21 TIMEZONE=-05:00   (one day, default steps;
#                                  the DEM lies at 81 W)
# on each, in REPEATS rounds that each run every command once, and prints
# the best wall time of each and its ratio to the DEM without voids. A cell
# whose near field touches nodata is solved in double precision (the
# vectorised form of cm_near_exact) where the others take the float fast
# path, so the ratio stays above 1.
set -eu

SIZE=${1:-1024}
FRACTIONS=${2:-0.01,0.1,0.5}
REPEATS=${3:-2}
. "$(dirname "$0")/bench_common.sh"
bench_setup voids_bench
DEM="$WORK/fbm_${SIZE}.tif"

echo "== DEM: $SIZE x $SIZE cells of 1 m, EPSG:32617, Float32, fBm (Hurst 0.8), 150 m of relief"
echo "   (bench/fractal_tif.py $SIZE DEM 1.8 1 150, seed 42), and copies with FRACTION of the cells nodata"
"$PYTHON" "$(dirname "$0")/fractal_tif.py" "$SIZE" "$DEM" 1.8 1 150
FLIST=$(echo "$FRACTIONS" | tr ',' ' ')
for f in $FLIST; do
    "$PYTHON" - "$DEM" "$WORK/voids_$(bench_key "$f").tif" "$f" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src, dst, frac = sys.argv[1], sys.argv[2], float(sys.argv[3])
if not 0 <= frac < 1:
    sys.exit("voids_bench.sh: a FRACTION must be in [0, 1), got %s" % sys.argv[3])
ds = gdal.GetDriverByName("GTiff").CreateCopy(dst, gdal.Open(src), options=["TILED=YES"])
band = ds.GetRasterBand(1)
z = band.ReadAsArray()
z[np.random.default_rng(7).random(z.shape) < frac] = -9999
band.SetNoDataValue(-9999)
band.WriteArray(z)
ds = None
PY
done
bench_machine

# the commands: product:fraction (0: the DEM itself)
RUNS=""
for p in svf sunhours; do
    RUNS="$RUNS $p:0"
    for f in $FLIST; do
        RUNS="$RUNS $p:$f"
    done
done

cmd() {
    product=$(echo "$1" | cut -d: -f1)
    f=$(echo "$1" | cut -d: -f2)
    src="$DEM"
    [ "$f" = 0 ] || src="$WORK/voids_$(bench_key "$f").tif"
    case $product in
    svf) opts="-oo PRODUCT=svf -oo DIRECTIONS=32" ;;
    *) opts="-oo PRODUCT=sunhours -oo DATE=2026-06-21 -oo TIMEZONE=-05:00" ;;
    esac
    echo "gdal_translate -q $opts 'TERRASHADE:$src' '$WORK/out.tif'"
}

bench_rounds "$RUNS"

for p in svf sunhours; do
    eval "base=\$T_$(bench_key "$p:0")"
    echo "   $p, no voids: $base s"
    for f in $FLIST; do
        eval "t=\$T_$(bench_key "$p:$f")"
        awk -v t="$t" -v b="$base" -v f="$f" \
            'BEGIN { printf "     %5.1f %% voids %7.3f s, %.2fx the DEM without\n", 100 * f, t, t / b }'
    done
done
echo "== load $(cut -d' ' -f1-3 /proc/loadavg)"
