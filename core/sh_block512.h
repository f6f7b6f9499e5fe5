/*
 * The last step of METHOD=sh's folded cells (core/sh_swath_light.c) for 16
 * cells at once in AVX-512 intrinsics: each cell's 16 folded coefficients
 * times the SH basis at its normal, summed. The cell-by-cell form works on
 * one cell's coefficients in a vector but its basis in scalars; here the 16
 * cells' coefficients are transposed so that the basis, the products and
 * the sums run over the cells, sixteen at a time. The same float operations
 * in the same order (TS_SH_BASIS's formulas themselves, through
 * TS_SH_BASIS_K on vectors; ts_sh_sum16's tree; store_shade's clamp), so the
 * same bits.
 */
#ifndef TS_SH_BLOCK512_H
#define TS_SH_BLOCK512_H

#include "terrashade_sh.h"

/* shade[j] = scale * sum_k acc[j][k] Y_k(nx[j], ny[j], nz[j]), clamped below
 * at 0 (NaN stays NaN), for the 16 cells j not in `skip` (bit j); acc is 64-byte
 * aligned. Returns 0, having done nothing, where the CPU (or the build) has
 * no AVX-512. */
int ts_sh_block_shade512(const float (*acc)[TS_SH_COEFFS], const float *nx, const float *ny,
                         const float *nz, float scale, unsigned skip, float *shade);

#endif
