#!/bin/sh
# bench/gpu.sh: the OpenCL backend on an NVIDIA GPU, C backend beside it.
#
# On a fresh Linux machine with an NVIDIA GPU and its driver, builds only
# what bench/cl_bench needs (core/ + cl/ + the test DEM generator: no GDAL,
# no autotools, one cc command per file), finds the NVIDIA OpenCL driver
# (writing a private ICD file for it when /etc/OpenCL/vendors has none),
# selects the NVIDIA device and runs cl_bench: every product's throughput on
# both backends, the largest |C - OpenCL| per product, and the horizons
# without the copy of their planes to the host; then once more, one repeat,
# with TERRASHADE_OPENCL_PROFILE=1 for the device time of each kernel.
# Prints the machine first.
#
# Usage: bench/gpu.sh [--quick] [--dry-run] [--size N] [--dirs D] [--repeat R]
#   --quick    1024² DEM, 16 directions, best of 2 (default 4096², 32, best of 3)
#   --dirs D   a multiple of 8 (cl_bench's batches of azimuths)
#   --dry-run  without an NVIDIA device, run on the default OpenCL device
#              (PoCL on a CPU), to test the script itself
# Environment: CC (default cc), JOBS (parallel compiles, default nproc),
# BUILD_DIR (default ${TMPDIR:-/tmp}/terrashade-gpu-bench), CL_INCLUDE (a
# directory holding CL/cl.h), OPENCL_LIB (the ICD loader, libOpenCL.so.1),
# NVIDIA_OPENCL_LIB (NVIDIA's OpenCL driver library, libnvidia-opencl.so.1:
# use it through a private ICD file whatever /etc/OpenCL/vendors holds).
# Needs: a C11 compiler, the OpenCL headers (opencl-headers, or the CUDA
# toolkit's), an ICD loader (ocl-icd-libopencl1, or the CUDA toolkit's).
set -eu

size=4096 dirs=32 repeat=3 dry=0
usage() { echo "usage: $0 [--quick] [--dry-run] [--size N] [--dirs D] [--repeat R]" >&2; exit 2; }
while [ $# -gt 0 ]; do
    case $1 in
    --quick) size=1024 dirs=16 repeat=2 ;;
    --dry-run) dry=1 ;;
    --size) [ $# -ge 2 ] || usage; size=$2; shift ;;
    --dirs) [ $# -ge 2 ] || usage; dirs=$2; shift ;;
    --repeat) [ $# -ge 2 ] || usage; repeat=$2; shift ;;
    *) usage ;;
    esac
    shift
done

top=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-cc}
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
BUILD_DIR=${BUILD_DIR:-${TMPDIR:-/tmp}/terrashade-gpu-bench}
mkdir -p "$BUILD_DIR/obj"
say() { printf '%s\n' "$*"; }
fail() { printf 'gpu.sh: %s\n' "$*" >&2; exit 1; }

# ------------------------------------------------------------- the machine
say "== machine"
say "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
say "host: $(uname -srm)"
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1)
say "CPU: ${cpu:-unknown}, $(nproc 2>/dev/null || echo '?') logical cores"
say "memory: $(awk '/^MemTotal/ {printf "%.1f GiB", $2 / 1048576}' /proc/meminfo 2>/dev/null)"
if command -v nvidia-smi >/dev/null 2>&1; then
    nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null |
        sed 's/^/GPU (nvidia-smi): /' || say "GPU (nvidia-smi): nvidia-smi failed"
else
    say "GPU (nvidia-smi): no nvidia-smi on this machine"
fi

# -------------------------------------------------------------- toolchain
say "== toolchain"
command -v "$CC" >/dev/null 2>&1 || fail "no C compiler '$CC' (set CC, or install gcc)"
say "compiler: $("$CC" --version 2>/dev/null | head -n 1)"

# The OpenCL headers: the system's, CL_INCLUDE, or the CUDA toolkit's.
cl_inc=
for d in "${CL_INCLUDE:-}" "" /usr/local/cuda/include /opt/cuda/include \
    /usr/local/cuda-*/include; do
    if printf '#define CL_TARGET_OPENCL_VERSION 120\n#include <CL/cl.h>\n' |
        "$CC" -E ${d:+-I"$d"} -x c - >/dev/null 2>&1; then
        cl_inc=${d:-system}
        break
    fi
done
[ -n "$cl_inc" ] || fail "the OpenCL headers (CL/cl.h) are missing: install opencl-headers
(Debian/Ubuntu: apt-get install opencl-headers), or set CL_INCLUDE to a directory
that holds CL/cl.h (the CUDA toolkit's include directory has one)"
say "OpenCL headers: $cl_inc"
if [ "$cl_inc" = system ]; then cl_inc=; fi

# The ICD loader to link with: -lOpenCL when the linker finds it, else a
# libOpenCL.so.1 (ocl-icd's, the Khronos loader, or the CUDA toolkit's).
printf 'int main(void){return 0;}\n' >"$BUILD_DIR/probe.c"
cl_lib=
if [ -n "${OPENCL_LIB:-}" ]; then
    cl_lib=$OPENCL_LIB
elif "$CC" "$BUILD_DIR/probe.c" -o "$BUILD_DIR/probe" -lOpenCL >/dev/null 2>&1; then
    cl_lib=-lOpenCL
else
    for f in $(ldconfig -p 2>/dev/null | awk '/libOpenCL\.so(\.1)? / {print $NF}') \
        /usr/lib/x86_64-linux-gnu/libOpenCL.so.1 /usr/lib64/libOpenCL.so.1 \
        /usr/lib/aarch64-linux-gnu/libOpenCL.so.1 /usr/local/cuda/lib64/libOpenCL.so.1 \
        /usr/local/cuda/lib64/libOpenCL.so; do
        [ -f "$f" ] && { cl_lib=$f; break; }
    done
fi
[ -n "$cl_lib" ] || fail "no OpenCL ICD loader (libOpenCL.so.1): install ocl-icd-libopencl1
(Debian/Ubuntu), or the CUDA toolkit, or set OPENCL_LIB to its path"
say "OpenCL ICD loader: $cl_lib"
cl_link=$cl_lib
case $cl_lib in /*) cl_link="$cl_lib -Wl,-rpath,$(dirname "$cl_lib")" ;; esac

# The NVIDIA OpenCL driver: the ICD file the loader reads, or one of ours
# pointing at libnvidia-opencl.so.1 (containers often have the library and
# no /etc/OpenCL/vendors/nvidia.icd).
nv_icd='' nv_lib=''
if [ -n "${NVIDIA_OPENCL_LIB:-}" ]; then
    [ -f "$NVIDIA_OPENCL_LIB" ] || fail "NVIDIA_OPENCL_LIB=$NVIDIA_OPENCL_LIB: no such file"
    nv_lib=$NVIDIA_OPENCL_LIB
else
    for d in ${OCL_ICD_VENDORS:-} /etc/OpenCL/vendors /usr/local/etc/OpenCL/vendors; do
        for f in "$d"/*.icd; do
            [ -f "$f" ] && grep -qi nvidia "$f" && { nv_icd=$f; break 2; }
        done
    done
fi
if [ -n "$nv_icd" ]; then
    say "NVIDIA ICD file: $nv_icd ($(cat "$nv_icd"))"
else
    [ -n "$nv_lib" ] ||
        for f in $(ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1 / {print $NF}') \
            /usr/lib/x86_64-linux-gnu/libnvidia-opencl.so.1 /usr/lib64/libnvidia-opencl.so.1 \
            /usr/lib/aarch64-linux-gnu/libnvidia-opencl.so.1 \
            /usr/local/nvidia/lib64/libnvidia-opencl.so.1 /usr/lib/libnvidia-opencl.so.1; do
            [ -f "$f" ] && { nv_lib=$f; break; }
        done
    if [ -n "$nv_lib" ]; then
        mkdir -p "$BUILD_DIR/icd"
        printf '%s\n' "$nv_lib" >"$BUILD_DIR/icd/nvidia.icd"
        # ocl-icd reads OCL_ICD_VENDORS, the Khronos loader OCL_ICD_FILENAMES
        export OCL_ICD_VENDORS="$BUILD_DIR/icd" OCL_ICD_FILENAMES="$nv_lib"
        say "NVIDIA ICD file: wrote a private one, $BUILD_DIR/icd/nvidia.icd -> $nv_lib"
    else
        say "NVIDIA OpenCL driver: none found (no nvidia .icd file, no libnvidia-opencl.so.1)"
        # nothing to build for: stop before the build's minute
        [ "$dry" = 1 ] || fail "no NVIDIA OpenCL driver on this machine (driver installed?
NVIDIA_OPENCL_LIB names libnvidia-opencl.so.1 where it is elsewhere); --dry-run runs on
another device"
    fi
fi
if command -v clinfo >/dev/null 2>&1; then
    clinfo -l 2>/dev/null | sed 's/^/clinfo: /' || true
fi

# ------------------------------------------------------------------ build
say "== build (in $BUILD_DIR, $JOBS jobs)"
# The kernels' sources, in the order cl/Makefile.inc lists them.
kernels=$(sed -n '/^TS_CL_KERNELS = /,/[^\\]$/p' "$top/cl/Makefile.inc" |
    sed -e 's/^TS_CL_KERNELS = //' -e 's/\\$//' | tr -s ' \t\n' ' ')
[ -n "$kernels" ] || fail "cannot read TS_CL_KERNELS from cl/Makefile.inc"
# shellcheck disable=SC2086
sh "$top/cl/embed.sh" "$top" $kernels >"$BUILD_DIR/ts_cl_kernels.c"

common="-std=c11 -D_GNU_SOURCE -pthread -I$top/core -I$top/cl -I$top/tests ${cl_inc:+-I$cl_inc}"
core_flags="-O3 -ffp-contract=off -fno-math-errno -fno-trapping-math" # as core/Makefile.inc
cl_flags="-O2 -DHAVE_OPENCL=1 -DCL_TARGET_OPENCL_VERSION=120"
# One line per file: "flags|source|object". core/ files that need libraries
# cl_bench does not use (LZMA, OpenEXR) may fail to compile here: the
# archive then lacks them, which the link only minds if they are needed.
{
    for f in "$top"/core/*.c; do
        printf '%s|%s|%s\n' "$core_flags" "$f" "core_$(basename "$f" .c).o"
    done
    for f in "$top"/cl/*.c "$BUILD_DIR/ts_cl_kernels.c"; do
        case $(basename "$f") in cl_stub.c) continue ;; esac
        printf '%s|%s|%s\n' "$cl_flags" "$f" "cl_$(basename "$f" .c).o"
    done
    printf '%s|%s|%s\n' "-O2 -DHAVE_OPENCL=1 -DTS_TEST_DATA='\"$top/tests/data\"'" \
        "$top/tests/test_dem.c" bench_test_dem.o
    printf '%s|%s|%s\n' "-O2 -DHAVE_OPENCL=1" "$top/bench/cl_bench.c" bench_cl_bench.o
} >"$BUILD_DIR/files"
rm -f "$BUILD_DIR"/obj/*.o "$BUILD_DIR"/obj/*.log
export CC common BUILD_DIR
# shellcheck disable=SC2016
tr '\n' '\0' <"$BUILD_DIR/files" | xargs -0 -P "$JOBS" -n 1 sh -c '
    flags=${1%%|*}; rest=${1#*|}; src=${rest%%|*}; obj=${rest#*|}
    eval "set -- $flags"
    $CC $common "$@" -c "$src" -o "$BUILD_DIR/obj/$obj" 2>"$BUILD_DIR/obj/$obj.log" ||
        rm -f "$BUILD_DIR/obj/$obj"' sh
skipped=
for f in "$top"/core/*.c; do
    o=core_$(basename "$f" .c).o
    [ -f "$BUILD_DIR/obj/$o" ] || skipped="$skipped $(basename "$f")"
done
[ -z "$skipped" ] || say "not compiled (libraries cl_bench does not need):$skipped"
for o in bench_cl_bench.o bench_test_dem.o cl_ts_cl_kernels.o; do
    [ -f "$BUILD_DIR/obj/$o" ] || { cat "$BUILD_DIR/obj/$o.log" >&2; fail "$o failed to compile"; }
done
for f in "$top"/cl/*.c; do
    o=cl_$(basename "$f" .c).o
    case $o in cl_cl_stub.o) continue ;; esac
    [ -f "$BUILD_DIR/obj/$o" ] || { cat "$BUILD_DIR/obj/$o.log" >&2; fail "$o failed to compile"; }
done
rm -f "$BUILD_DIR/libts_core.a" "$BUILD_DIR/libts_cl.a"
ar rcs "$BUILD_DIR/libts_core.a" "$BUILD_DIR"/obj/core_*.o
ar rcs "$BUILD_DIR/libts_cl.a" "$BUILD_DIR"/obj/cl_*.o
# shellcheck disable=SC2086
"$CC" -pthread -o "$BUILD_DIR/cl_bench" "$BUILD_DIR/obj/bench_cl_bench.o" \
    "$BUILD_DIR/obj/bench_test_dem.o" "$BUILD_DIR/libts_cl.a" "$BUILD_DIR/libts_core.a" \
    $cl_link -lm || fail "cl_bench failed to link"
say "built $BUILD_DIR/cl_bench"

# ----------------------------------------------------------------- device
say "== OpenCL devices (TERRASHADE_OPENCL_DEVICE value, platform:device, type, platform, device, version)"
"$BUILD_DIR/cl_bench" --list >"$BUILD_DIR/devices" 2>&1 || true
sed 's/^/  /' "$BUILD_DIR/devices"
nv=$(awk -F '\t' 'tolower($4) ~ /nvidia/ && $3 == "GPU" {print $1; exit}' "$BUILD_DIR/devices")
if [ -n "$nv" ]; then
    export TERRASHADE_OPENCL_DEVICE="$nv"
    say "using device $nv (NVIDIA)"
elif [ "$dry" = 1 ]; then
    say "no NVIDIA OpenCL device: DRY RUN on the default device (figures are not a GPU's)"
else
    fail "no NVIDIA OpenCL device among the devices above (driver loaded? nvidia-smi
works? the ICD file names a library that loads?); --dry-run runs on another device"
fi

# ------------------------------------------------------------------ bench
say "== cl_bench --size $size --dirs $dirs --repeat $repeat"
"$BUILD_DIR/cl_bench" --size "$size" --dirs "$dirs" --repeat "$repeat"
say "== kernel times: TERRASHADE_OPENCL_PROFILE=1 cl_bench --size $size --dirs $dirs --repeat 1 --no-streams"
say "(each launch waits for its event here, so the throughputs of this run are not the figures)"
# the kernel times are on stderr (at exit), the table again on stdout: only the former
if TERRASHADE_OPENCL_PROFILE=1 "$BUILD_DIR/cl_bench" --size "$size" --dirs "$dirs" --repeat 1 \
    --no-streams >"$BUILD_DIR/profile.out" 2>"$BUILD_DIR/profile"; then
    sed -n '/TERRASHADE_OPENCL_PROFILE/,$p' "$BUILD_DIR/profile"
else
    say "(the profile run failed:)"
    cat "$BUILD_DIR/profile"
fi
# The horizon sweep's own rate (issue 13's GPU goal): its kernels' device
# time, the transposes included (one of them may be another product's).
awk -v px="$size" -v dirs="$dirs" '
    $1 ~ /^ts_(sweep_lines|sweep_fast|sweep_finish|transpose)$/ { t += $3 }
    END { if (t > 0) printf "horizon sweep, kernels alone: %.1f ms = %.1f Mpx-dir/s\n",
                          1e3 * t, px * px * dirs / t / 1e6 }' "$BUILD_DIR/profile"
