/* TS_SIMD_CLONES: a function compiled for AVX-512, AVX2 and baseline x86-64,
 * chosen at load time (GCC's target_clones), so that a loop written once
 * runs at the widest vectors the CPU has. Elsewhere it is nothing. The
 * clones do the same float operations (no contraction under -std=c11), so
 * the results have the same bits at any width. */
#ifndef TS_SIMD_CLONES_H
#define TS_SIMD_CLONES_H

#if defined(TS_SIMD_CLONES)
/* given on the command line (bench/cpu_levels.sh: empty, to build one
 * CPU's code alone) */
#elif defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define TS_SIMD_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define TS_SIMD_CLONES
#endif

/* TS_AVX512: a function compiled for AVX-512 only (hand-written intrinsics),
 * called only where ts_cpu_vector_level() says the CPU has it: AVX-512F
 * with its 128- and 256-bit forms (VL) and byte and word masks (BW), which
 * that level asks for. */
#if defined(__GNUC__) && defined(__x86_64__)
#define TS_AVX512 __attribute__((target("avx512f,avx512vl,avx512bw")))
#include <immintrin.h>

/* The first n of sixteen AVX-512 lanes: none for n <= 0, all for n >= 16
 * (the mask of a vector's tail). */
static inline __mmask16 ts_first_lanes16(int n)
{
    return n >= 16 ? 0xFFFF : n <= 0 ? 0 : (__mmask16)((1u << n) - 1);
}
#endif

#endif
