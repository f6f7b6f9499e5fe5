/* The interior near field's pieces (near_field.c's near_run) in AVX-512,
 * with each piece's inner peak left to the few cells that may have one;
 * see near_run512.h. */
#include <math.h>

#include "near_run512.h"
#include "lane_hull.h"
#include "simd_clones.h"

/* Piece n's float constants for L metres per step, curvature c. */
static cm_fast_piece piece_consts(const ts_near_plan *p, int n, int flat_v, float L, float c)
{
    return cm_fast_piece_init(p->piece_du[n], p->piece_dv[n], flat_v, p->piece_sa[n],
                              p->piece_sb[n], L, c);
}

float ts_near_fast_cell(const ts_near_plan *p, const float *zrow, int x, float L, float c)
{
    const float t = (float)p->t;
    const int flat_v = fabs(p->t) <= 1e-12;
    float best = -INFINITY;
    for (int n = 0; n < p->npieces; n++) {
        const cm_fast_piece q = piece_consts(p, n, flat_v, L, c);
        const float *z = zrow + x;
        float m = cm_fast_piece_slope(q, t, z[p->piece_off[n][0]], z[p->piece_off[n][1]],
                                      z[p->piece_off[n][2]], z[p->piece_off[n][3]], z[0], L, c);
        best = m > best ? m : best;
    }
    return best;
}

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

/* The peaks of one piece's queued cells (n of them: cells x = qx[e], whose
 * P, beta, gamma are qP[x], qb[x], qg[x]) by cm_fast_piece_slope's float
 * operations: where the peak lies inside the piece, best[x] = fs > best[x]
 * ? fs : best[x] (the cells are distinct: a gather and a scatter). Cells
 * whose peak is a zero get redo[x] = 1; returns whether there was one. */
TS_AVX512 static int piece_peaks(const cm_fast_piece *q, float L, float c, const float *qP,
                                 const float *qb, const float *qg, const int *qx, int n,
                                 float *best, int *redo)
{
    int any = 0;
    const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
    const __m512 cLL = _mm512_set1_ps(q->cLL), invL = _mm512_set1_ps(q->invL);
    const __m512 cv = _mm512_set1_ps(c), Lv = _mm512_set1_ps(L);
    const __m512 sa = _mm512_set1_ps(q->sa), sb = _mm512_set1_ps(q->sb);
    for (int e = 0; e < n; e += 16) {
        const __mmask16 lanes = ts_first_lanes16(n - e);
        const __m512i x = _mm512_maskz_loadu_epi32(lanes, qx + e);
        const __m512 P = _mm512_mask_i32gather_ps(zero, lanes, x, qP, 4);
        const __m512 beta = _mm512_mask_i32gather_ps(zero, lanes, x, qb, 4);
        const __m512 gamma = _mm512_mask_i32gather_ps(zero, lanes, x, qg, 4);
        const __m512 g2 = _mm512_sub_ps(gamma, cLL);
        const __m512 r = _mm512_div_ps(P, g2);
        const __m512 ss = _mm512_sqrt_ps(_mm512_max_ps(r, zero));
        const __m512 sd = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(ss, zero, _CMP_GT_OQ), one, ss);
        const __m512 fs = _mm512_sub_ps(
            _mm512_mul_ps(_mm512_add_ps(_mm512_add_ps(_mm512_div_ps(P, sd), beta),
                                        _mm512_mul_ps(gamma, ss)),
                          invL),
            _mm512_mul_ps(_mm512_mul_ps(cv, ss), Lv));
        __mmask16 in = _mm512_mask_cmp_ps_mask(lanes, P, zero, _CMP_LT_OQ);
        in = _mm512_mask_cmp_ps_mask(in, g2, zero, _CMP_LT_OQ);
        in = _mm512_mask_cmp_ps_mask(in, ss, sa, _CMP_GT_OQ);
        in = _mm512_mask_cmp_ps_mask(in, ss, sb, _CMP_LT_OQ);
        const __m512 b = _mm512_mask_i32gather_ps(zero, in, x, best, 4);
        _mm512_mask_i32scatter_ps(best, _mm512_mask_cmp_ps_mask(in, fs, b, _CMP_GT_OQ), x, fs,
                                  4);
        const __mmask16 z = _mm512_mask_cmp_ps_mask(in, fs, zero, _CMP_EQ_OQ);
        if (z) {
            _mm512_mask_i32scatter_epi32(redo, z, x, _mm512_set1_epi32(1), 4);
            any = 1;
        }
    }
    return any;
}

TS_AVX512 static void run(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                          float L, float c, float *restrict best, float *restrict flag,
                          float *restrict queue)
{
    const int len = x1 - x0;
    /* the piece's P, beta, gamma by cell, the queued cells */
    float *qP = queue - x0, *qb = queue + (len + 16) - x0, *qg = queue + 2 * (len + 16) - x0;
    int *qx = (int *)(queue + 3 * (len + 16)), *redo = (int *)(queue + 4 * (len + 16)) - x0;
    int any_redo = 0;
    for (int x = x0; x < x1; x++) {
        best[x] = -INFINITY;
        flag[x] = 0.0f;
        redo[x] = 0;
    }
    const float t = (float)p->t;
    const int flat_v = fabs(p->t) <= 1e-12;
    const __m512 tv = _mm512_set1_ps(t), zero = _mm512_setzero_ps();
    const __m512i sign = _mm512_set1_epi32((int)0x80000000u);
    const __m512 one = _mm512_set1_ps(1.0f);
    const __m512i step = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    for (int n = 0; n < p->npieces; n++) {
        const float *c00 = zrow + p->piece_off[n][0], *c10 = zrow + p->piece_off[n][1];
        const float *c01 = zrow + p->piece_off[n][2], *c11 = zrow + p->piece_off[n][3];
        const cm_fast_piece q = piece_consts(p, n, flat_v, L, c);
        const __m512 a0 = _mm512_set1_ps(q.a0), b0 = _mm512_set1_ps(q.b0);
        const __m512 xt = _mm512_set1_ps(q.a0 * t + q.b0); /* X's factor in beta */
        const __m512 sb = _mm512_set1_ps(q.sb), inv_b = _mm512_set1_ps(q.inv_b);
        const __m512 cb = _mm512_set1_ps(q.cb), ka = _mm512_set1_ps(q.ka);
        const __m512 kb = _mm512_set1_ps(q.kb), kc = _mm512_set1_ps(q.kc);
        const __m512 ca = _mm512_set1_ps(q.ca), cLL = _mm512_set1_ps(q.cLL);
        /* The peak (r = P / g2 in (sa², sb²)) only where g2 < 0, P < 0 and
         * P lies between g2 sa² and g2 sb², widened by 2^-8 against the
         * products' roundings, or g2 is too small for them to be exact. */
        const __m512 lo = _mm512_set1_ps((float)(p->piece_sa[n] * p->piece_sa[n] * (1 - 0x1p-8)));
        const __m512 hi = _mm512_set1_ps((float)(p->piece_sb[n] * p->piece_sb[n] * (1 + 0x1p-8)));
        const __m512 tiny = _mm512_set1_ps(-0x1p-60f);
        int nq = 0;
        for (int x = x0; x < x1; x += 16) {
            const __mmask16 lanes = ts_first_lanes16(x1 - x);
            const __m512 h0 = _mm512_maskz_loadu_ps(lanes, c00 + x);
            const __m512 h1 = _mm512_maskz_loadu_ps(lanes, c10 + x);
            const __m512 h2 = _mm512_maskz_loadu_ps(lanes, c01 + x);
            const __m512 h3 = _mm512_maskz_loadu_ps(lanes, c11 + x);
            const __m512 h = _mm512_maskz_loadu_ps(lanes, zrow + x);
            const __m512 A = _mm512_sub_ps(h1, h0), B = _mm512_sub_ps(h2, h0);
            const __m512 X = _mm512_add_ps(_mm512_sub_ps(_mm512_sub_ps(h3, h1), h2), h0);
            const __m512 alpha = _mm512_add_ps(
                _mm512_add_ps(_mm512_add_ps(h0, _mm512_mul_ps(A, a0)), _mm512_mul_ps(B, b0)),
                _mm512_mul_ps(_mm512_mul_ps(X, a0), b0));
            const __m512 beta = _mm512_castsi512_ps(_mm512_xor_si512(
                _mm512_castps_si512(_mm512_add_ps(_mm512_add_ps(A, _mm512_mul_ps(B, tv)),
                                                  _mm512_mul_ps(X, xt))),
                sign));
            const __m512 gamma = _mm512_mul_ps(X, tv);
            const __m512 P = _mm512_sub_ps(alpha, h);
            const __m512 fb = _mm512_sub_ps(
                _mm512_mul_ps(_mm512_add_ps(_mm512_add_ps(P, _mm512_mul_ps(beta, sb)),
                                            _mm512_mul_ps(_mm512_mul_ps(gamma, sb), sb)),
                              inv_b),
                cb);
            const __m512 fa = _mm512_sub_ps(
                _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(P, ka), _mm512_mul_ps(beta, kb)),
                              _mm512_mul_ps(gamma, kc)),
                ca);
            const __m512 m = _mm512_max_ps(fa, fb); /* fa > fb ? fa : fb */
            _mm512_mask_storeu_ps(best + x, lanes,
                                  _mm512_max_ps(m, _mm512_maskz_loadu_ps(lanes, best + x)));
            const __mmask16 nan = _mm512_mask_cmp_ps_mask(lanes, m, m, _CMP_UNORD_Q);
            if (nan) {
                const __m512 f = _mm512_maskz_loadu_ps(lanes, flag + x);
                _mm512_mask_storeu_ps(flag + x, nan, _mm512_add_ps(f, one));
            }
            if (!q.has_sa)
                continue;
            const __m512 g2 = _mm512_sub_ps(gamma, cLL);
            __mmask16 k = _mm512_mask_cmp_ps_mask(lanes, g2, zero, _CMP_LT_OQ);
            k = _mm512_mask_cmp_ps_mask(k, P, zero, _CMP_LT_OQ);
            __mmask16 in = _mm512_mask_cmp_ps_mask(k, P, _mm512_mul_ps(g2, lo), _CMP_LT_OQ);
            in = _mm512_mask_cmp_ps_mask(in, P, _mm512_mul_ps(g2, hi), _CMP_GT_OQ);
            const __mmask16 cand = in | _mm512_mask_cmp_ps_mask(k, g2, tiny, _CMP_GT_OQ);
            _mm512_storeu_ps(qP + x, P);
            _mm512_storeu_ps(qb + x, beta);
            _mm512_storeu_ps(qg + x, gamma);
            _mm512_storeu_si512(qx + nq, _mm512_maskz_compress_epi32(
                                             cand, _mm512_add_epi32(_mm512_set1_epi32(x), step)));
            nq += __builtin_popcount(cand);
        }
        any_redo |= piece_peaks(&q, L, c, qP, qb, qg, qx, nq, best, redo);
    }
    /* a zero peak may tie a zero of the other sign that the pieces' order
     * would have kept: those cells as near_run folds them */
    for (int x = x0; any_redo && x < x1; x++)
        if (redo[x])
            best[x] = ts_near_fast_cell(p, zrow, x, L, c);
}

int ts_near_run_avx512(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                       float L, float c, float *restrict best, float *restrict flag,
                       float *restrict queue)
{
    if (ts_lane_vector_level() != 2)
        return 0;
    run(p, zrow, x0, x1, L, c, best, flag, queue);
    return 1;
}

#else

int ts_near_run_avx512(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                       float L, float c, float *restrict best, float *restrict flag,
                       float *restrict queue)
{
    (void)p;
    (void)zrow;
    (void)x0;
    (void)x1;
    (void)L;
    (void)c;
    (void)best;
    (void)flag;
    (void)queue;
    return 0;
}

#endif
