/*
 * The interior near field's pieces (near_field.c's near_run: the float
 * fast path) in AVX-512 intrinsics, for CPUs that have it. The same float
 * operations give the same bits; what differs is that a piece's inner peak
 * (two divisions and a square root per cell) is solved only for the cells
 * where it may lie inside the piece: a division-free test with a margin
 * picks them, their indices are queued (compressed) and they are solved
 * sixteen at a time after the piece's run. The peaks then join best[] after the ends of
 * their piece rather than in their place among the pieces, which gives
 * the same maximum; only a peak that is exactly zero could tie a zero of
 * the other sign differently, and its cell is folded again in the pieces'
 * order (ts_near_fast_cell).
 */
#ifndef TS_NEAR_RUN512_H
#define TS_NEAR_RUN512_H

#include "near_field.h"

/* near_run's fold for cell x alone: the largest of the pieces' slopes in
 * the pieces' order (NaN slopes skipped), L metres per step, curvature c. */
float ts_near_fast_cell(const ts_near_plan *p, const float *zrow, int x, float L, float c);

/* near_run over cells x0 <= x < x1 (best[x], flag[x] as near_run leaves
 * them); queue: 5 (x1 - x0 + 16) floats of scratch. Returns 0, having done
 * nothing, where the CPU (or the build) has no AVX-512. */
int ts_near_run_avx512(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                       float L, float c, float *restrict best, float *restrict flag,
                       float *restrict queue);

#endif
