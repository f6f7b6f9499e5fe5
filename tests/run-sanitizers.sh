#!/bin/sh
# Build the C check programs with AddressSanitizer and UBSan and run every
# one of them (tests/check_*, tests/cl/check_opencl*) under it, leaks
# included; then the GDAL plugin, under three of the driver's tests.
# Usage: tests/run-sanitizers.sh [BUILDDIR]
#
# The tree may be configured and built in place (as CI leaves it after the
# normal build): a git checkout is copied into BUILDDIR (the files git
# tracks or would track, as they are in the working tree) and configured
# there, so its own configuration is never touched. A tree outside git must
# be unconfigured; it is then built out of tree in BUILDDIR.
# JOBS: make's parallelism (default: the number of CPUs). BUILDDIR defaults
# to a new temporary directory, removed after a clean run.
set -eu
SRC=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -gt 0 ]; then
    B=$1
    KEEP=1
else
    B=$(mktemp -d)
    KEEP=0
fi
mkdir -p "$B"
B=$(cd "$B" && pwd)
JOBS=${JOBS:-$(nproc)}
trap '[ $? = 0 ] || echo "$0: failed; the build and its test logs are in $B" >&2' EXIT

if git -C "$SRC" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    TOP=$B/src
    mkdir -p "$TOP"
    # tracked and untracked-but-not-ignored files: no build outputs
    (cd "$SRC" && git ls-files -z --cached --others --exclude-standard |
        tar --null --no-recursion --ignore-failed-read -T - -cf -) |
        tar -C "$TOP" -xf -
    (cd "$TOP" && autoreconf -fi >/dev/null)
    BUILD=$TOP
elif [ -f "$SRC/config.status" ]; then
    echo "$0: $SRC is configured in place and is not a git checkout; run" \
        "'make distclean' there first" >&2
    exit 1
else
    [ -x "$SRC/configure" ] || (cd "$SRC" && autoreconf -fi >/dev/null)
    TOP=$SRC
    BUILD=$B
fi

SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cd "$BUILD"
"$TOP/configure" -q CFLAGS="$SAN -g -O1" CXXFLAGS="$SAN -g -O1" LDFLAGS="$SAN"
C_TESTS=$(cd "$TOP" && ls tests/check_*.c tests/cl/check_*.c | sed 's/\.c$//' | tr '\n' ' ')
# the check programs and what they link first
make -j"$JOBS" $C_TESTS
# the sanitizers' ~3x slower code: each test case's own timeout tripled
# (check_horizon's threads case took 167 s of its 300 on a loaded 2-core
# machine, session 53; CK_DEFAULT_TIMEOUT leaves explicit timeouts as they are)
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    LSAN_OPTIONS=suppressions="$TOP/tests/lsan.supp" CK_TIMEOUT_MULTIPLIER=3 \
    make check-TESTS TESTS="$C_TESTS"
# The GDAL plugin too, under the driver's tests of hostile input, atlases
# and environment maps (until session 56 it ran under sanitizers in audits
# only): GDAL and Python are not instrumented, ASan is preloaded for them;
# the C backend (PoCL's LLVM replaces ASan's signal stack); no leak check
# (Python's own). Tests that cap the address space (ulimit -v) cannot run
# under ASan's shadow memory, so test_errors is not among them.
make -j"$JOBS" plugin/gdal_TERRASHADE.la
# (UBSan's runtime with ASan's: it brings libstdc++ in at the start, and
# without it ASan found no __cxa_throw to intercept when GDAL's C++ threw:
# "CHECK failed: asan_interceptors.cpp", CI of session 56)
ASAN_LIB="$(${CC:-gcc} -print-file-name=libasan.so) $(${CC:-gcc} -print-file-name=libubsan.so)"
for t in test_hostile test_atlas test_envlight; do
    if ! TS_BUILDDIR="$BUILD" TERRASHADE_BACKEND=c LD_PRELOAD="$ASAN_LIB" \
        ASAN_OPTIONS=detect_leaks=0:halt_on_error=1 \
        UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        /usr/bin/python3 -W ignore "$TOP/tests/driver/$t.py" > "$B/$t.log" 2>&1; then
        echo "$0: $t failed under the sanitizers:" >&2
        tail -n 80 "$B/$t.log" >&2
        exit 1
    fi
    echo "PASS (sanitized plugin): $t"
done
[ "$KEEP" = 1 ] || rm -rf "$B"
