#!/bin/sh
# Build the C check programs with AddressSanitizer and UBSan and run every
# one of them (tests/check_*, tests/cl/check_opencl*) under it, leaks
# included. Usage: tests/run-sanitizers.sh [BUILDDIR]
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
# only the check programs and what they link, not the GDAL plugin
make -j"$JOBS" $C_TESTS
# the sanitizers' ~3x slower code: each test case's own timeout tripled
# (check_horizon's threads case took 167 s of its 300 on a loaded 2-core
# machine, session 53; CK_DEFAULT_TIMEOUT leaves explicit timeouts as they are)
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    LSAN_OPTIONS=suppressions="$TOP/tests/lsan.supp" CK_TIMEOUT_MULTIPLIER=3 \
    make check-TESTS TESTS="$C_TESTS"
[ "$KEEP" = 1 ] || rm -rf "$B"
