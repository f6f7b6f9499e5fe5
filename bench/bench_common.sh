# bench_common.sh - the set-up the driver benchmarks share; sourced, not run.
#
#   . "$(dirname "$0")/bench_common.sh"
#   bench_setup NAME
#
# Takes the plugin from $BUILDDIR/plugin/.libs (BUILDDIR defaults to the
# current directory) when it has gdal_TERRASHADE.so, else from wherever GDAL
# finds it; stops with a sentence if GDAL cannot find the driver. Then makes
# the scratch directory $WORK, removed on exit; on an interrupt (INT, TERM)
# it is removed and the script exits (130, 143).

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
    trap 'rm -rf "$WORK"' EXIT
    # interrupted: the work directory goes, and so does the script (the
    # commands after it would only fail on the missing files)
    trap 'rm -rf "$WORK"; trap - EXIT; exit 130' INT
    trap 'rm -rf "$WORK"; trap - EXIT; exit 143' TERM
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

# bench_key NAME: NAME as part of a shell variable's name.
bench_key() {
    echo "$1" | tr -c 'A-Za-z0-9_\n' '_'
}

# bench_rounds "NAME ...": runs each named command (the caller's `cmd NAME`
# prints it, its paths in single quotes; it writes $WORK/out.tif) once per round, $REPEATS rounds, so
# that all of them see the host's speed of the same minutes (it drifts by
# tens of per cent from one minute to the next on shared machines); prints
# the commands and each round's wall times, and leaves each command's best
# in T_<bench_key NAME>, in seconds.
bench_rounds() {
    echo "== timing: $REPEATS rounds, each running every command once; best of each"
    for n in $1; do
        echo "\$ $(cmd "$n")"
    done
    r=0
    while [ "$r" -lt "$REPEATS" ]; do
        line="   round $((r + 1)):"
        for n in $1; do
            rm -f "$WORK/out.tif"
            t0=$(date +%s.%N)
            eval "$(cmd "$n")" >/dev/null
            t1=$(date +%s.%N)
            t=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
            line="$line $n $t"
            k=$(bench_key "$n")
            eval "prev=\${T_$k:-}"
            eval "T_$k=$(awk -v t="$t" -v p="$prev" 'BEGIN { print (p == "" || t < p) ? t : p }')"
        done
        echo "$line"
        r=$((r + 1))
    done
}
