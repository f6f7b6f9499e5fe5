#!/bin/sh
# Build a copy of the tree with AddressSanitizer and UBSan and run the C unit
# tests under it (leaks included). Usage: tests/run-sanitizers.sh [BUILDDIR]
set -eu
SRC=$(cd "$(dirname "$0")/.." && pwd)
B=${1:-$(mktemp -d)}
cd "$B"
[ -x "$SRC/configure" ] || (cd "$SRC" && autoreconf -fi)
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
"$SRC/configure" -q CFLAGS="$SAN -g -O1" CXXFLAGS="$SAN -g -O1" LDFLAGS="$SAN"
make -j"$(nproc)"
C_TESTS=$(cd "$SRC" && ls tests/check_*.c | sed 's/\.c$//' | tr '\n' ' ')
ASAN_OPTIONS=detect_leaks=1 make check TESTS="$C_TESTS"
