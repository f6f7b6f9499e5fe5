/* METHOD=sh's basis and dot products over 16 cells in AVX-512; see
 * sh_block512.h. */
#include "sh_block512.h"

#include <math.h>

#include "lane_hull.h"
#include "sh_internal.h"
#include "simd_clones.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

/* r[k] := column k of the 16 x 16 rows r (row j's element k into lane j). */
TS_AVX512 static inline __attribute__((always_inline)) void transpose16(__m512 r[16])
{
    __m512 t[16];
    for (int i = 0; i < 8; i++) {
        t[2 * i] = _mm512_unpacklo_ps(r[2 * i], r[2 * i + 1]);
        t[2 * i + 1] = _mm512_unpackhi_ps(r[2 * i], r[2 * i + 1]);
    }
    for (int i = 0; i < 4; i++) {
        r[4 * i] = _mm512_shuffle_ps(t[4 * i], t[4 * i + 2], _MM_SHUFFLE(1, 0, 1, 0));
        r[4 * i + 1] = _mm512_shuffle_ps(t[4 * i], t[4 * i + 2], _MM_SHUFFLE(3, 2, 3, 2));
        r[4 * i + 2] = _mm512_shuffle_ps(t[4 * i + 1], t[4 * i + 3], _MM_SHUFFLE(1, 0, 1, 0));
        r[4 * i + 3] = _mm512_shuffle_ps(t[4 * i + 1], t[4 * i + 3], _MM_SHUFFLE(3, 2, 3, 2));
    }
    for (int i = 0; i < 2; i++)
        for (int q = 0; q < 4; q++) {
            t[8 * i + q] = _mm512_shuffle_f32x4(r[8 * i + q], r[8 * i + q + 4], 0x88);
            t[8 * i + q + 4] = _mm512_shuffle_f32x4(r[8 * i + q], r[8 * i + q + 4], 0xDD);
        }
    for (int q = 0; q < 8; q++) {
        r[q] = _mm512_shuffle_f32x4(t[q], t[q + 8], 0x88);
        r[q + 8] = _mm512_shuffle_f32x4(t[q], t[q + 8], 0xDD);
    }
}

/* a constant as a vector, for TS_SH_BASIS_K */
#define K(c) _mm512_set1_ps((float)(c))

TS_AVX512 static void block_shade(const float (*acc)[TS_SH_COEFFS], const float *nx,
                                  const float *ny, const float *nz, float scale, unsigned skip,
                                  float *shade)
{
    __m512 a[16];
    for (int j = 0; j < 16; j++)
        a[j] = _mm512_load_ps(acc[j]);
    transpose16(a);
    /* the basis over the cells: TS_SH_BASIS's formulas on vectors */
    __m512 Y[16];
    TS_SH_BASIS_K(__m512, K, _mm512_loadu_ps(nx), _mm512_loadu_ps(ny), _mm512_loadu_ps(nz), Y);
    /* ts_sh_sum16's tree over p_k = acc_k Y_k */
    __m512 p[16];
    for (int k = 0; k < 16; k++)
        p[k] = _mm512_mul_ps(a[k], Y[k]);
    for (int k = 0; k < 8; k++)
        p[k] = _mm512_add_ps(p[k], p[k + 8]);
    for (int k = 0; k < 4; k++)
        p[k] = _mm512_add_ps(p[k], p[k + 4]);
    const __m512 s = _mm512_add_ps(_mm512_add_ps(p[0], p[2]), _mm512_add_ps(p[1], p[3]));
    /* store_shade: t < 0 ? 0 : t, NaN kept */
    const __m512 t = _mm512_mul_ps(s, _mm512_set1_ps(scale));
    const __mmask16 neg = _mm512_cmp_ps_mask(t, _mm512_setzero_ps(), _CMP_LT_OQ);
    const __mmask16 nan = _mm512_cmp_ps_mask(t, t, _CMP_UNORD_Q);
    __m512 out = _mm512_mask_mov_ps(t, neg, _mm512_setzero_ps());
    out = _mm512_mask_mov_ps(out, nan, _mm512_set1_ps(NAN));
    _mm512_mask_storeu_ps(shade, (__mmask16)~skip, out);
}

int ts_sh_block_shade512(const float (*acc)[TS_SH_COEFFS], const float *nx, const float *ny,
                         const float *nz, float scale, unsigned skip, float *shade)
{
    if (ts_cpu_vector_level() != TS_CPU_VECTORS_AVX512)
        return 0;
    block_shade(acc, nx, ny, nz, scale, skip, shade);
    return 1;
}

#else

int ts_sh_block_shade512(const float (*acc)[TS_SH_COEFFS], const float *nx, const float *ny,
                         const float *nz, float scale, unsigned skip, float *shade)
{
    (void)acc, (void)nx, (void)ny, (void)nz, (void)scale, (void)skip, (void)shade;
    return 0;
}

#endif
