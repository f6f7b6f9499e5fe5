#!/bin/sh
# distributed_bench.sh - a product through terrashade.distributed (Dask, one
# task per window) against one process (gdal_translate), on the same DEM.
#
#   bench/distributed_bench.sh [SIZE] [WORKERS] [TILE] [-oo KEY=VALUE ...]
#   (defaults: 2048, one per core, 1024, PRODUCT=horizon DIRECTIONS=16)
#
# Generates a SIZE x SIZE fractal DEM (tests/driver/tsdriver.py, 10 m cells,
# EPSG:32617), then times once each, on the same machine and DEM:
#   gdal_translate -oo ... TERRASHADE:dem.tif one.tif         (THREADS = all cores)
#   python3 -m terrashade.distributed --workers WORKERS --tile-size TILE
#           -oo ... TERRASHADE:dem.tif dist.tif               (cluster start included)
# checks that the two outputs are identical, and prints the wall times and
# throughputs in cells per second. Run from the build directory after make.
set -eu

SIZE=${1:-2048}
WORKERS=${2:-$(nproc)}
TILE=${3:-1024}
[ $# -ge 3 ] && shift 3 || shift $#
OO=${*:-"-oo PRODUCT=horizon -oo DIRECTIONS=16"}
PYTHON=${PYTHON:-/usr/bin/python3}
BUILDDIR=${BUILDDIR:-$(pwd)}
SRCDIR=$(cd "$(dirname "$0")/.." && pwd)
GDAL_DRIVER_PATH="$BUILDDIR/plugin/.libs"
PYTHONPATH="$SRCDIR/python"
export GDAL_DRIVER_PATH PYTHONPATH
# terrashade.distributed runs on Dask: checked before the DEM is made
if ! why=$("$PYTHON" -c 'import dask, distributed' 2>&1); then
    echo "distributed_bench: needs dask and distributed, which $PYTHON cannot import" \
         "(Debian/Ubuntu: apt-get install python3-distributed; or pip install" \
         "'dask[distributed]'): $(printf '%s\n' "$why" | tail -n 1)" >&2
    exit 1
fi

WORK=$(mktemp -d "${TMPDIR:-/tmp}/distributed_bench.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
trap 'rm -rf "$WORK"; trap - EXIT; exit 130' INT
trap 'rm -rf "$WORK"; trap - EXIT; exit 143' TERM
DEM="$WORK/fractal_${SIZE}.tif"
# tsdriver.py stops with a message if the plugin was not built here
TS_BUILDDIR="$BUILDDIR" "$PYTHON" - "$SIZE" "$DEM" "$SRCDIR/tests/driver" <<'EOF'
import sys
sys.path.insert(0, sys.argv[3])
import tsdriver as T
T.write_tif(sys.argv[2], T.fractal_dem(int(sys.argv[1]), seed=42, relief=1400.0),
            (500000.0, 10.0, 0.0, 4000000.0, 0.0, -10.0), 32617)
EOF

echo "== machine: $(nproc) CPU(s), $(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -n 1)"
echo "   memory: $(awk '/MemTotal/ {printf "%.1f GiB", $2 / 1048576}' /proc/meminfo);" \
     "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "   GDAL $(gdal-config --version 2>/dev/null || echo '?');" \
     "dask $("$PYTHON" -c 'import dask, distributed; print(dask.__version__, "/ distributed", distributed.__version__)')"
echo "== DEM: $SIZE x $SIZE fractal, 10 m cells, Float32; options: $OO"

seconds() { # wall time of a command, in seconds; its stderr in $WORK/err
    t0=$(date +%s.%N)
    "$@" >/dev/null 2>"$WORK/err" || { cat "$WORK/err" >&2; exit 1; }
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }'
}

# shellcheck disable=SC2086 # $OO is a list of -oo KEY=VALUE words
set -- gdal_translate -q $OO "TERRASHADE:$DEM" "$WORK/one.tif"
echo "\$ $*"
T_ONE=$(seconds "$@")
set -- "$PYTHON" -m terrashade.distributed --workers "$WORKERS" --tile-size "$TILE" \
    $OO "TERRASHADE:$DEM" "$WORK/dist.tif"
echo "\$ $*"
T_DIST=$(seconds "$@")
tail -n 1 "$WORK/err" | tr '\r' '\n' | tail -n 1

"$PYTHON" - "$WORK/one.tif" "$WORK/dist.tif" <<'EOF'
import sys
import numpy as np
from osgeo import gdal
a, b = (gdal.Open(p).ReadAsArray() for p in sys.argv[1:])
print("== outputs identical:", "yes" if np.array_equal(a.view(np.uint8), b.view(np.uint8)) else "NO")
EOF
awk -v n="$SIZE" -v a="$T_ONE" -v b="$T_DIST" -v w="$WORKERS" -v t="$TILE" 'BEGIN {
    c = n * n
    printf "== one process (gdal_translate):         %7.2f s  %7.2f Mcells/s\n", a, c / a / 1e6
    printf "== distributed (%d workers, tiles of %d): %7.2f s  %7.2f Mcells/s  (%.2fx)\n",
           w, t, b, c / b / 1e6, a / b }'
echo "   load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
