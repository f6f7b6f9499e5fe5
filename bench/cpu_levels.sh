#!/bin/sh
# What a CPU without AVX-512 gets from the core sweep, timed on this one.
#
#   sh bench/cpu_levels.sh [SIZE] [DIRS] [DISTANCES] [REPEAT]
#   (defaults 2048 16 0,960 3; DISTANCES as ts_bench --max-distance)
#
# Builds bench/ts_bench three times from core/*.c (in $BUILD_DIR, default
# /tmp/ts_cpu_levels; CC and JOBS as bench/gpu.sh) and runs each in turn,
# REPEAT rounds, each round every build once:
#   shipped   the build as it ships (GCC's target_clones pick the AVX-512
#             clones here), TERRASHADE_SIMD=auto
#   avx2      one clone only, compiled for AVX2 and FMA (-mavx2 -mfma, no
#             contraction: the AVX2 clones' code), TERRASHADE_SIMD=avx2
#   baseline  one clone only, plain x86-64 (SSE2), TERRASHADE_SIMD=none
# so avx2 runs what a CPU with AVX2 and no AVX-512 runs (most desktops and
# laptops), baseline what an x86-64 CPU without AVX runs, on this CPU's
# cores and memory. Every build gives the same results
# (tests/driver/test_cpu_paths.py); this is their time.
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
SIZE=${1:-2048}
DIRS=${2:-16}
DISTANCES=${3:-0,960}
REPEAT=${4:-3}
CC=${CC:-cc}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
BUILD_DIR=${BUILD_DIR:-/tmp/ts_cpu_levels}
mkdir -p "$BUILD_DIR"

common="-std=c11 -D_GNU_SOURCE -pthread -I$top/core -I$top/tests"
core_flags="-O3 -ffp-contract=off -fno-math-errno -fno-trapping-math" # as core/Makefile.inc
one="-DTS_SIMD_CLONES= -DTS_PYR_FMA_CLONES="

build() { # name, extra flags
    dir=$BUILD_DIR/$1
    mkdir -p "$dir"
    rm -f "$dir"/*.o "$dir"/*.log "$dir"/ts_bench
    # core/ files that need libraries ts_bench does not use (OpenEXR, LZMA)
    # may fail to compile: the archive then lacks them, which the link
    # only minds if they are needed
    for f in "$top"/core/*.c; do
        printf '%s\n' "$f"
    done | xargs -P "$JOBS" -I{} sh -c \
        'o='"$dir"'/core_$(basename {} .c).o; '"$CC $common $core_flags $2"' -c {} -o $o 2>$o.log || rm -f $o'
    $CC $common -O2 -DTS_TEST_DATA="\"$top/tests/data\"" -c "$top/tests/test_dem.c" \
        -o "$dir/test_dem.o"
    $CC $common -O2 -c "$top/bench/ts_bench.c" -o "$dir/ts_bench.o"
    ar rcs "$dir/libcore.a" "$dir"/core_*.o
    $CC -pthread -o "$dir/ts_bench" "$dir/ts_bench.o" "$dir/test_dem.o" "$dir/libcore.a" -lm
}

echo "== building in $BUILD_DIR ($JOBS jobs)"
build shipped ""
build avx2 "$one -mavx2 -mfma"
build baseline "$one"

cmd="ts_bench --size $SIZE --dirs $DIRS --max-distance $DISTANCES --repeat 1"
echo "== machine: $(nproc) CPU(s), $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
echo "== $cmd, $REPEAT rounds (best of each)"
# the times of an earlier run that did not finish would join this table
rm -f "$BUILD_DIR"/times.* "$BUILD_DIR"/out
r=1
while [ "$r" -le "$REPEAT" ]; do
    for b in shipped:auto avx2:avx2 baseline:none; do
        name=${b%%:*}
        # ts_bench's own message (stderr) says why it failed
        TERRASHADE_SIMD=${b#*:} "$BUILD_DIR/$name/ts_bench" --size "$SIZE" --dirs "$DIRS" \
            --max-distance "$DISTANCES" --repeat 1 >"$BUILD_DIR/out" || {
            echo "cpu_levels.sh: the $name build's $cmd failed (exit $?)" >&2
            exit 1
        }
        # distances as ts_bench prints them (%g: 960, 95.5, 1e+06)
        sed -n "s/^horizon .*max distance *\([0-9][0-9.e+]*\) m: \([0-9.]*\) s.*/$name \1 \2/p" \
            "$BUILD_DIR/out" >>"$BUILD_DIR/times.$r"
    done
    r=$((r + 1))
done
[ -s "$BUILD_DIR/times.1" ] || {
    echo "cpu_levels.sh: no horizon times in ts_bench's output:" >&2
    cat "$BUILD_DIR/out" >&2
    exit 1
}
cat "$BUILD_DIR"/times.* | awk -v dirs="$DIRS" -v size="$SIZE" '
    { k = $1 " " $2; if (!(k in best) || $3 < best[k]) best[k] = $3;
      if (!($1 in seen)) { seen[$1] = 1; order[++n] = $1 }
      if (!($2 in dseen)) { dseen[$2] = 1; dist[++m] = $2 } }
    END {
        printf "%-9s", "build";
        for (j = 1; j <= m; j++) printf "  %-30s", (dist[j] == 0 ? "unbounded" : dist[j] " m");
        printf "\n";
        for (i = 1; i <= n; i++) {
            printf "%-9s", order[i];
            for (j = 1; j <= m; j++) {
                t = best[order[i] " " dist[j]];
                printf "  %6.3f s %6.1f M px-dir/s %5.2fx", t, size * size * dirs / t / 1e6,
                       t / best[order[1] " " dist[j]];
            }
            printf "\n";
        }
        printf "(x: the time against the shipped build at the same distance)\n";
    }'
rm -f "$BUILD_DIR"/times.* "$BUILD_DIR"/out
