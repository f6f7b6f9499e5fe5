/* The widest hand-written vector code this process runs (AVX-512, AVX2 or
 * the portable C beside them), asked of the CPU once and capped by the
 * environment variable TERRASHADE_SIMD, so that the paths a CPU without
 * AVX-512 takes can be run, tested and timed on one that has it. */
#include <stdlib.h>
#include <strings.h>

#include "status_internal.h"
#include "terrashade.h"

ts_status ts_cpu_vectors_parse(const char *text, int *cap, ts_error *err)
{
    static const char *const names[] = {"none", "avx2", "avx512"}; /* by level */
    if (!text || !*text || !strcasecmp(text, "auto")) {
        *cap = TS_CPU_VECTORS_AVX512;
        return ts_ok(err);
    }
    for (int level = TS_CPU_VECTORS_NONE; level <= TS_CPU_VECTORS_AVX512; level++)
        if (!strcasecmp(text, names[level])) {
            *cap = level;
            return ts_ok(err);
        }
    return ts_fail(err, TS_ERR_ARG,
                   "TERRASHADE_SIMD must be auto, avx512, avx2 or none, got '%.40s'", text);
}

/* The CPU's own level: AVX-512 with its 256-bit forms and byte masks
 * (avx512vl, avx512bw: every AVX-512 CPU but the Xeon Phi has them), AVX2,
 * or neither. */
static int cpu_level(void)
{
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                   __builtin_cpu_supports("avx512bw")
               ? TS_CPU_VECTORS_AVX512
           : __builtin_cpu_supports("avx2") ? TS_CPU_VECTORS_AVX2
                                            : TS_CPU_VECTORS_NONE;
#else
    return TS_CPU_VECTORS_NONE; /* the vectorised paths are x86-64 only */
#endif
}

int ts_cpu_vector_level(void)
{
    static int known = -1; /* asked once: every pass of a run takes the same paths */
    int level = __atomic_load_n(&known, __ATOMIC_RELAXED);
    if (level < 0) {
        int cap;
        ts_error err;
        level = cpu_level();
        /* a bad value runs as auto here; opening a product refuses it */
        if (ts_cpu_vectors_parse(getenv("TERRASHADE_SIMD"), &cap, &err) == TS_OK && cap < level)
            level = cap;
        __atomic_store_n(&known, level, __ATOMIC_RELAXED);
    }
    return level;
}

const char *ts_cpu_vectors_name(int level)
{
    return level >= TS_CPU_VECTORS_AVX512 ? "AVX-512"
           : level == TS_CPU_VECTORS_AVX2 ? "AVX2"
                                          : "portable C";
}
