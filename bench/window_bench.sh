#!/bin/sh
# window_bench.sh - windowed computation (TILE_SIZE, docs/windows.md): the
# latency and peak memory of one small window against the whole-DEM path,
# and the throughput of whole products, one run each in a fresh process.
#
#   bench/window_bench.sh [SIZES] [PRODUCT_OPTIONS...]
#       (defaults: "4096 16384", -oo PRODUCT=shade -oo BACKEND=c)
#
# For each SIZE: a SIZE x SIZE fractal DEM (bench/fractal_tif.py: 10 m cells,
# EPSG:32617; made once at the largest SIZE up to 4096, the smaller ones cut
# from it; above 4096, multiples of 4096 as a VRT mosaic of the 4096 one, no
# disk cost),
# then, timed with /usr/bin/time (wall seconds, peak resident MiB):
#   window  gdal_translate -srcwin 0 0 256 256 OPTIONS [-oo TILE_SIZE=T] TERRASHADE:dem out
#   whole   gdal_translate OPTIONS [-oo TILE_SIZE=T] TERRASHADE:dem out   (Mcells/s)
# for T = 0 (the whole DEM at once) and 2048, and the window
# with TILE_SIZE=512; then how far the whole product with TILE_SIZE=2048
# is from TILE_SIZE=0's (median, p99 and max |difference| over the largest
# value, share within 1 %). TILE_SIZE=0 on a
# DEM larger than the memory limit is refused, and printed so; any other
# failure stops the script with the command's error and exit status 1.
#
# The plugin is taken from $BUILDDIR/plugin/.libs (BUILDDIR defaults to the
# current directory) or from wherever GDAL finds it. Needs /usr/bin/python3
# with numpy and osgeo, and GNU time (/usr/bin/time).
set -eu

SIZES=${1:-"4096 16384"}
[ $# -gt 0 ] && shift
if [ $# -eq 0 ]; then
    set -- -oo PRODUCT=shade -oo BACKEND=c
fi
HERE=$(cd "$(dirname "$0")" && pwd)
# the DEM made: the largest SIZE, or 4096 when a SIZE is a mosaic of it
base=0
for n in $SIZES; do
    case $n in
    *[!0-9]* | "" | 0*)
        echo "window_bench: SIZES must be positive integers, got '$n'" >&2
        exit 2 ;;
    esac
    if [ "$n" -gt 4096 ] && [ $((n % 4096)) -ne 0 ]; then
        echo "window_bench: a SIZE above 4096 must be a multiple of 4096 (a mosaic), got $n" >&2
        exit 2
    fi
    [ "$n" -le "$base" ] || base=$n
done
[ "$base" -gt 0 ] || { echo "window_bench: no SIZES" >&2; exit 2; }
[ "$base" -le 4096 ] || base=4096
. "$(dirname "$0")/bench_common.sh"
bench_setup window_bench
"$PYTHON" "$HERE/fractal_tif.py" "$base" "$WORK/dem_$base.tif"

dem_of() { # the DEM of size $1: the one made, cut from it, or a mosaic of it
    if [ "$1" -le "$base" ]; then
        [ "$1" -eq "$base" ] || gdal_translate -q -srcwin 0 0 "$1" "$1" \
            "$WORK/dem_$base.tif" "$WORK/dem_$1.tif"
    else
        "$PYTHON" - "$1" "$WORK" <<'PY'
import sys
from osgeo import gdal
n, work = int(sys.argv[1]), sys.argv[2]
k = n // 4096
src = gdal.Open(work + "/dem_4096.tif")
parts = []
for j in range(k):
    for i in range(k):
        parts.append('<SimpleSource><SourceFilename relativeToVRT="1" shared="1">dem_4096.tif'
                     '</SourceFilename><SourceBand>1</SourceBand><SrcRect xOff="0" yOff="0" '
                     'xSize="4096" ySize="4096"/><DstRect xOff="%d" yOff="%d" xSize="4096" '
                     'ySize="4096"/></SimpleSource>' % (i * 4096, j * 4096))
wkt = src.GetProjection().replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;")
gt = ", ".join(repr(v) for v in src.GetGeoTransform())
open("%s/dem_%d.vrt" % (work, n), "w").write(
    '<VRTDataset rasterXSize="%d" rasterYSize="%d"><SRS>%s</SRS><GeoTransform>%s'
    '</GeoTransform><VRTRasterBand dataType="Float32" band="1">%s</VRTRasterBand>'
    '</VRTDataset>' % (n, n, wkt, gt, "".join(parts)))
PY
    fi
}

timed() { # label cells command...: one line of seconds, MiB, Mcells/s
    label=$1 cells=$2
    shift 2
    if /usr/bin/time -f "%e %M" -o "$WORK/time" "$@" >/dev/null 2>"$WORK/err"; then
        read -r sec kb <"$WORK/time"
        awk -v l="$label" -v s="$sec" -v k="$kb" -v c="$cells" 'BEGIN {
            printf "%-40s %8.2f s %8.0f MiB %8.1f Mcells/s\n", l, s, k / 1024, c / s / 1e6 }'
    else
        rc=$?
        # the driver's refusal for memory (MAX_MEMORY, or three quarters of
        # the physical memory) is a result; anything else is a failure
        if grep -q 'needs about [0-9]* MiB.*MAX_MEMORY' "$WORK/err"; then
            printf "%-40s refused: %s\n" "$label" "$(grep -m1 ERROR "$WORK/err" | cut -c1-160)"
        else
            echo "window_bench: $label failed (exit $rc): $*" >&2
            cat "$WORK/err" >&2
            exit 1
        fi
    fi
}

echo "window_bench: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), options: $*"
for n in $SIZES; do
    dem_of "$n"
    dem=$(ls "$WORK"/dem_"$n".* | head -n1)
    timed "$n^2 window 256^2, TILE_SIZE=512" 65536 \
        gdal_translate -q -srcwin 0 0 256 256 "$@" -oo TILE_SIZE=512 \
        "TERRASHADE:$dem" "$WORK/w.tif"
    for t in 0 2048; do
        timed "$n^2 window 256^2, TILE_SIZE=$t" 65536 \
            gdal_translate -q -srcwin 0 0 256 256 "$@" -oo TILE_SIZE=$t \
            "TERRASHADE:$dem" "$WORK/w.tif"
        timed "$n^2 whole product, TILE_SIZE=$t" $((n * n)) \
            gdal_translate -q -co TILED=YES -co COMPRESS=DEFLATE "$@" -oo TILE_SIZE=$t \
            "TERRASHADE:$dem" "$WORK/all_$t.tif"
    done
    # the windowed product against the whole DEM's, where both were made
    if [ -f "$WORK/all_0.tif" ] && [ -f "$WORK/all_2048.tif" ]; then
        "$PYTHON" - "$WORK/all_0.tif" "$WORK/all_2048.tif" "$n" <<'PY'
import sys
import numpy as np
from osgeo import gdal
a, b = gdal.Open(sys.argv[1]), gdal.Open(sys.argv[2])
x = a.ReadAsArray().astype(np.float64)
y = b.ReadAsArray().astype(np.float64)
d = np.abs(x - y)[np.isfinite(x) & np.isfinite(y)]
s = np.nanmax(np.abs(x))
print("%s^2 TILE_SIZE=2048 against 0, of the largest value: median %.1e, p99 %.1e, "
      "max %.3f; %.3f %% of values within 1 %%; nodata %s"
      % (sys.argv[3], np.median(d) / s, np.percentile(d, 99) / s, d.max() / s,
         100 * np.mean(d <= 0.01 * s),
         "the same" if np.array_equal(np.isnan(x), np.isnan(y)) else "DIFFERS"))
PY
    fi
    rm -f "$WORK"/all_*.tif
done
