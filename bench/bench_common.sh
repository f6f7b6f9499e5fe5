# bench_common.sh - the set-up the driver benchmarks share; sourced, not run.
#
#   . "$(dirname "$0")/bench_common.sh"
#   bench_setup NAME
#
# Takes the plugin from $BUILDDIR/plugin/.libs (BUILDDIR defaults to the
# current directory) when it has gdal_TERRASHADE.so, else from wherever GDAL
# finds it; stops with a sentence if GDAL cannot find the driver. Then makes
# the scratch directory $WORK, removed on exit.

PYTHON=${PYTHON:-/usr/bin/python3}
BUILDDIR=${BUILDDIR:-$(pwd)}

bench_setup() {
    if [ -f "$BUILDDIR/plugin/.libs/gdal_TERRASHADE.so" ]; then
        GDAL_DRIVER_PATH="$BUILDDIR/plugin/.libs"
        export GDAL_DRIVER_PATH
    fi
    if ! gdalinfo --formats | grep -q TERRASHADE; then
        echo "$1: GDAL cannot find the TERRASHADE driver; build it (make)" \
             "and run from the build directory, or set GDAL_DRIVER_PATH" >&2
        exit 1
    fi
    WORK=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")
    trap 'rm -rf "$WORK"' EXIT INT TERM
}

# bench_machine: the machine in one line (CPUs, model, load, GDAL) and
# where the plugin comes from, as every driver bench prints it.
bench_machine() {
    echo "== machine: $(nproc 2>/dev/null || echo "?") CPU(s)," \
         "$(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -n 1);" \
         "load $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null);" \
         "GDAL $(gdal-config --version 2>/dev/null || gdalinfo --version)"
    echo "   GDAL_DRIVER_PATH=${GDAL_DRIVER_PATH:-<default>}"
}
