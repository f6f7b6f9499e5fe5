#!/bin/sh
# Build the libFuzzer targets of tests/fuzz/ with clang (Debian's), ASan and
# UBSan, straight from the sources: no autotools, no configure.
#
# Usage: tests/fuzz/build.sh [OUTDIR]      (default: tests/fuzz/build)
#   CC=clang-15 tests/fuzz/build.sh        (another clang)
#
# Every core/*.c goes into one static archive (so a file added to core/ is
# built without touching this script, and each target links only what it
# uses), plus the plugin's plain-C parsers. fuzz_exr is built only once
# core/terrashade_env.h declares ts_env_load_exr_memory. Prints the names of
# the targets built, one a line, on stdout's last lines ("built: NAME").
set -eu
SRC=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${1:-$SRC/tests/fuzz/build}
CC=${CC:-clang}
mkdir -p "$OUT/obj"
OUT=$(cd "$OUT" && pwd)

if ! command -v "$CC" >/dev/null 2>&1; then
    echo "fuzz/build: $CC not found (apt-get install clang)" >&2
    exit 1
fi
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined"
# Warnings are the gcc build's business for core/ and plugin/; the targets get them.
# environment maps of at most 2^20 pixels (terrashade_env.h): a legal 2^26-pixel
# map takes longer than libFuzzer's per-input timeout under ASan
CFLAGS="-std=c11 -D_GNU_SOURCE -DTS_ENV_MAX_PIXELS=((size_t)1<<20) -g -O1 -fno-omit-frame-pointer -Werror=implicit-function-declaration $SAN"
WARN="-Wall -Wextra"
INC="-I$SRC/core -I$SRC/plugin -I$SRC/cl"
LIBS="-llzma -lm -lpthread"
# The EXR reader of core/ (when it lands) needs OpenEXRCore.
if grep -lq 'openexr\|OpenEXR' "$SRC"/core/*.c 2>/dev/null; then
    INC="$INC $(pkg-config --cflags OpenEXR)"
    LIBS="$(pkg-config --libs OpenEXR) -lstdc++ $LIBS"
fi

# Compile one C file into $OUT/obj (only when the source is newer).
compile() { # src obj extra-flags
    if [ ! -f "$2" ] || [ "$1" -nt "$2" ] || [ -n "$(find "$SRC/core" "$SRC/plugin" \
            -name '*.h' -newer "$2" 2>/dev/null | head -n1)" ]; then
        # shellcheck disable=SC2086
        "$CC" $CFLAGS $3 $INC -c "$1" -o "$2"
    fi
}

# The core: every core/*.c, instrumented for coverage (fuzzer-no-link).
rm -f "$OUT/libcore_fuzz.a"
objs=""
for c in "$SRC"/core/*.c; do
    o="$OUT/obj/core_$(basename "$c" .c).o"
    compile "$c" "$o" "-fsanitize=fuzzer-no-link"
    objs="$objs $o"
done
# The core's C++ pieces (the OpenEXR C++ decoder for what OpenEXRCore
# cannot decode).
for c in "$SRC"/core/*.cpp; do
    [ -e "$c" ] || continue
    o="$OUT/obj/core_$(basename "$c" .cpp).o"
    if [ ! -f "$o" ] || [ "$c" -nt "$o" ]; then
        # shellcheck disable=SC2086
        "${CXX:-clang++}" -std=c++17 -g -O1 -fno-omit-frame-pointer $SAN \
            -fno-sanitize=vptr,function -fsanitize=fuzzer-no-link $INC -c "$c" -o "$o"
    fi
    objs="$objs $o"
done
# The plugin's C side (the option and product tables, the parsers and what
# they link to: its headers reach GDAL's C API for the DEM and the CRS) and
# the backend dispatcher with its no-OpenCL stub: every plugin/*.c is taken,
# so that a file split off the option code is built without touching this
# script.
INC="$INC $(gdal-config --cflags)"
LIBS="$LIBS $(gdal-config --libs) -lproj"
for c in "$SRC"/plugin/*.c "$SRC"/cl/backend.c "$SRC"/cl/cl_stub.c; do
    o="$OUT/obj/$(basename "$(dirname "$c")")_$(basename "$c" .c).o"
    compile "$c" "$o" "-fsanitize=fuzzer-no-link"
    objs="$objs $o"
done
# shellcheck disable=SC2086
ar rcs "$OUT/libcore_fuzz.a" $objs

TARGETS="fuzz_options fuzz_datetime fuzz_atlas"
if grep -q 'ts_env_load_exr_memory' "$SRC/core/terrashade_env.h"; then
    TARGETS="$TARGETS fuzz_exr"
else
    echo "fuzz/build: fuzz_exr skipped: core/terrashade_env.h does not declare" \
         "ts_env_load_exr_memory yet" >&2
fi
for t in $TARGETS; do
    # shellcheck disable=SC2086
    "$CC" $CFLAGS $WARN -fsanitize=fuzzer $INC "$SRC/tests/fuzz/$t.c" \
        "$OUT/libcore_fuzz.a" $LIBS -o "$OUT/$t"
done
for t in $TARGETS; do
    echo "built: $t"
done
