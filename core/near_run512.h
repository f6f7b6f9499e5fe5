/*
 * The interior near field's pieces (near_field.c's near_run: the float
 * fast path) in AVX-512 intrinsics, for CPUs that have it. The same float
 * operations give the same bits; what differs is that a piece's inner peak
 * (two divisions and a square root per cell) is solved only for the cells
 * whose test (cm_fast_peak_test) says it has one: their indices are queued
 * (compressed) and they are solved sixteen at a time after the piece's
 * run. The maximum does not depend on the order in which the slopes join
 * it (near_merge then adds +0, so that a -0 becomes +0).
 */
#ifndef TS_NEAR_RUN512_H
#define TS_NEAR_RUN512_H

#include "near_field.h"

/* near_run over cells x0 <= x < x1 (best[x], flag[x] as near_run leaves
 * them; faster where best + x and zrow + x lie alike on 64-byte lines);
 * queue: 2 (x1 - x0) + 128 floats of scratch (the previous piece's slopes,
 * then two queues of cells). Returns 0, having done nothing, where the CPU
 * (or the build) has no AVX-512. */
int ts_near_run_avx512(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                       float L, float c, float *restrict best, float *restrict flag,
                       float *restrict queue);

#endif
