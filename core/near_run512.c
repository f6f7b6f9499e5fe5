/* The interior near field's pieces (near_field.c's near_run) in AVX-512,
 * each piece's inner peak solved only for the few cells that have one;
 * see near_run512.h. */
#include <math.h>
#include <stdint.h>

#include "near_run512.h"
#include "lane_hull.h"
#include "simd_clones.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

/* Piece n's float constants for L metres per step, curvature c. */
static cm_fast_piece piece_consts(const ts_near_plan *p, int n, int flat_v, float L, float c)
{
    return cm_fast_piece_init(p->piece_du[n], p->piece_dv[n], flat_v, p->piece_sa[n],
                              p->piece_sb[n], p->t, L, c);
}

/* The inner peaks of one piece's queued cells (n of them: cells x = qx[e]),
 * by cm_fast_peak's float operations on the corners at offsets off from
 * each: best[x] = max(fs, best[x]) (the cells are distinct: a gather and a
 * scatter). */
TS_AVX512 static void piece_peaks(const cm_fast_piece *q, float t, float L, float c,
                                  const float *zrow, const ptrdiff_t off[4], const int *qx,
                                  int n, float *best)
{
    const __m512 zero = _mm512_setzero_ps(), tv = _mm512_set1_ps(t);
    const __m512 a0 = _mm512_set1_ps(q->a0), b0 = _mm512_set1_ps(q->b0);
    const __m512 xt = _mm512_set1_ps(q->a0 * t + q->b0);
    const __m512 cLL = _mm512_set1_ps(q->cLL), invL = _mm512_set1_ps(q->invL);
    const __m512 cv = _mm512_set1_ps(c), Lv = _mm512_set1_ps(L);
    const __m512 sa = _mm512_set1_ps(q->sa), sb = _mm512_set1_ps(q->sb);
    const __m512i sign = _mm512_set1_epi32((int)0x80000000u);
    for (int e = 0; e < n; e += 16) {
        const __mmask16 lanes = ts_first_lanes16(n - e);
        const __m512i x = _mm512_maskz_loadu_epi32(lanes, qx + e);
        const __m512 h = _mm512_mask_i32gather_ps(zero, lanes, x, zrow, 4);
        const __m512 h0 = _mm512_mask_i32gather_ps(zero, lanes, x, zrow + off[0], 4);
        const __m512 h1 = _mm512_mask_i32gather_ps(zero, lanes, x, zrow + off[1], 4);
        const __m512 h2 = _mm512_mask_i32gather_ps(zero, lanes, x, zrow + off[2], 4);
        const __m512 h3 = _mm512_mask_i32gather_ps(zero, lanes, x, zrow + off[3], 4);
        const __m512 A = _mm512_sub_ps(h1, h0), B = _mm512_sub_ps(h2, h0);
        const __m512 X = _mm512_add_ps(_mm512_sub_ps(_mm512_sub_ps(h3, h1), h2), h0);
        const __m512 alpha = _mm512_add_ps(
            _mm512_add_ps(_mm512_add_ps(h0, _mm512_mul_ps(A, a0)), _mm512_mul_ps(B, b0)),
            _mm512_mul_ps(_mm512_mul_ps(X, a0), b0));
        const __m512 beta = _mm512_castsi512_ps(_mm512_xor_si512(
            _mm512_castps_si512(
                _mm512_add_ps(_mm512_add_ps(A, _mm512_mul_ps(B, tv)), _mm512_mul_ps(X, xt))),
            sign));
        const __m512 gamma = _mm512_mul_ps(X, tv);
        const __m512 P = _mm512_sub_ps(alpha, h), g2 = _mm512_sub_ps(gamma, cLL);
        const __m512 r = _mm512_div_ps(P, g2);
        __m512 ss = _mm512_sqrt_ps(_mm512_mask_blend_ps(_mm512_cmp_ps_mask(r, zero, _CMP_GT_OQ),
                                                        zero, r));
        ss = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(ss, sa, _CMP_GT_OQ), sa, ss);
        ss = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(ss, sb, _CMP_LT_OQ), sb, ss);
        const __m512 fs = _mm512_sub_ps(
            _mm512_mul_ps(_mm512_add_ps(_mm512_add_ps(_mm512_div_ps(P, ss), beta),
                                        _mm512_mul_ps(gamma, ss)),
                          invL),
            _mm512_mul_ps(_mm512_mul_ps(cv, ss), Lv));
        const __m512 b = _mm512_mask_i32gather_ps(zero, lanes, x, best, 4);
        _mm512_mask_i32scatter_ps(best, _mm512_mask_cmp_ps_mask(lanes, fs, b, _CMP_GT_OQ), x, fs,
                                  4);
    }
}

/* A piece's constants as vectors (piece_vector's). */
typedef struct {
    __m512 tv, one, frac, inv_b, cb, cLL, ka, kbn, xt, invL;
    __m512i sign, step;
} piece_vectors;

/* One vector of cells from x (those of lanes) of one piece (cm_fast_piece's
 * float operations), its end's edge corners e0, e1 and has_sa constants;
 * a cell whose inner peak the test finds is appended to the queue qx
 * (*nq cells). */
TS_AVX512 static inline __attribute__((always_inline)) void
piece_vector(const piece_vectors *v, const float *const cn[4], const int e0, const int e1,
             const int has_sa, const float *restrict zrow, int x, __mmask16 lanes,
             float *restrict best, float *restrict flag, float *restrict prev, int *restrict qx,
             int *nq)
{
    __m512 c[4];
    for (int i = 0; i < 4; i++)
        c[i] = _mm512_maskz_loadu_ps(lanes, cn[i] + x);
    const __m512 h = _mm512_maskz_loadu_ps(lanes, zrow + x);
    const __m512 X = _mm512_add_ps(_mm512_sub_ps(_mm512_sub_ps(c[3], c[1]), c[2]), c[0]);
    const __m512 dz = _mm512_add_ps(_mm512_sub_ps(c[e0], h),
                                    _mm512_mul_ps(_mm512_sub_ps(c[e1], c[e0]), v->frac));
    const __m512 f = _mm512_sub_ps(_mm512_mul_ps(dz, v->inv_b), v->cb);
    __m512 m = _mm512_max_ps(f, _mm512_maskz_loadu_ps(lanes, best + x));
    if (!has_sa) { /* the ray's start */
        const __m512 A = _mm512_sub_ps(c[1], c[0]), B = _mm512_sub_ps(c[2], c[0]);
        const __m512 beta = _mm512_castsi512_ps(_mm512_xor_si512(
            _mm512_castps_si512(_mm512_add_ps(_mm512_add_ps(A, _mm512_mul_ps(B, v->tv)),
                                              _mm512_mul_ps(X, v->xt))),
            v->sign));
        m = _mm512_max_ps(_mm512_mul_ps(beta, v->invL), m);
    } else {
        const __m512 g2 = _mm512_sub_ps(_mm512_mul_ps(X, v->tv), v->cLL);
        const __m512 D = _mm512_sub_ps(_mm512_maskz_loadu_ps(lanes, prev + x), f);
        __mmask16 k = _mm512_mask_cmp_ps_mask(lanes, g2, _mm512_setzero_ps(), _CMP_LT_OQ);
        k = _mm512_mask_cmp_ps_mask(k, D, _mm512_mul_ps(g2, v->ka), _CMP_GT_OQ);
        k = _mm512_mask_cmp_ps_mask(k, D, _mm512_mul_ps(g2, v->kbn), _CMP_LT_OQ);
        _mm512_storeu_si512(qx + *nq, _mm512_maskz_compress_epi32(
                                          k, _mm512_add_epi32(_mm512_set1_epi32(x), v->step)));
        *nq += __builtin_popcount(k);
    }
    _mm512_mask_storeu_ps(best + x, lanes, m);
    _mm512_mask_storeu_ps(prev + x, lanes, f);
    const __m512 xx = _mm512_sub_ps(X, X); /* NaN where X is not finite */
    const __mmask16 bad = _mm512_mask_cmp_ps_mask(lanes, xx, xx, _CMP_UNORD_Q);
    if (bad) {
        const __m512 fl = _mm512_maskz_loadu_ps(lanes, flag + x);
        _mm512_mask_storeu_ps(flag + x, bad, _mm512_add_ps(fl, v->one));
    }
}

/* One piece over the vectors of cells from xs (the first one's lanes below
 * x0 masked off) to x1, has_sa constant: vector i's queued cells go to
 * qx[i & 1] (two shorter chains of counts). The vectors between the first
 * and the last are whole, and taken two at a time, so that the counts and
 * the masks stay out of memory. */
TS_AVX512 static inline __attribute__((always_inline)) void
piece_run(const piece_vectors *v, const float *const cn[4], const int e0, const int e1,
          const int has_sa, const float *restrict zrow, int xs, int x0, int x1,
          float *restrict best, float *restrict flag, float *restrict prev, int *const qx[2],
          int nq[2])
{
    int n0 = nq[0], n1 = nq[1], x = xs;
    int *restrict q0 = qx[0], *restrict q1 = qx[1];
#define PIECE_VECTOR(at, lanes, q, n)                                                          \
    piece_vector(v, cn, e0, e1, has_sa, zrow, at, lanes, best, flag, prev, q, &n)
    PIECE_VECTOR(x, ts_first_lanes16(x1 - x) & ~ts_first_lanes16(x0 - x), q0, n0);
    for (x += 16; x + 32 <= x1; x += 32) {
        PIECE_VECTOR(x, 0xFFFF, q1, n1);
        PIECE_VECTOR(x + 16, 0xFFFF, q0, n0);
    }
    if (x < x1)
        PIECE_VECTOR(x, ts_first_lanes16(x1 - x), q1, n1);
    if (x + 16 < x1)
        PIECE_VECTOR(x + 16, ts_first_lanes16(x1 - x - 16), q0, n0);
#undef PIECE_VECTOR
    nq[0] = n0;
    nq[1] = n1;
}

/* One piece over cells x0 <= x < x1 (piece_run, with and without the
 * ray's start), its end's edge corners e0, e1 constants, so that they are
 * registers; the cells whose inner peak the test finds are queued in qx[0]
 * and qx[1], nq their counts. */
TS_AVX512 static inline __attribute__((always_inline)) void
piece_cells(const cm_fast_piece *q, const float *const cn[4], const int e0, const int e1,
            float t, const float *restrict zrow, int xs, int x0, int x1, float *restrict best,
            float *restrict flag, float *restrict prev, int *const qx[2], int nq[2])
{
    const piece_vectors v = {
        .tv = _mm512_set1_ps(t),
        .one = _mm512_set1_ps(1.0f),
        .frac = _mm512_set1_ps(q->frac),
        .inv_b = _mm512_set1_ps(q->inv_b),
        .cb = _mm512_set1_ps(q->cb),
        .cLL = _mm512_set1_ps(q->cLL),
        .ka = _mm512_set1_ps(q->ka),
        .kbn = _mm512_set1_ps(q->kbn),
        .xt = _mm512_set1_ps(q->a0 * t + q->b0),
        .invL = _mm512_set1_ps(q->invL),
        .sign = _mm512_set1_epi32((int)0x80000000u),
        .step = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
    };
    if (q->has_sa)
        piece_run(&v, cn, e0, e1, 1, zrow, xs, x0, x1, best, flag, prev, qx, nq);
    else
        piece_run(&v, cn, e0, e1, 0, zrow, xs, x0, x1, best, flag, prev, qx, nq);
}

TS_AVX512 static void run(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                          float L, float c, float *restrict best, float *restrict flag,
                          float *restrict queue)
{
    /* The cells' vectors start where zrow's heights start a 64-byte line
     * (the first one's lanes below x0 masked off), so that the loads of h,
     * and of best and prev where the caller put best in zrow's phase, do
     * not straddle two lines: 0.5-15 % of the run (docs/performance-history.md,
     * session 22). */
    const int xs = x0 - (int)(((uintptr_t)(zrow + x0) / sizeof(float)) & 15);
    const int len = x1 - xs;
    /* the slopes at the previous piece's end by cell (in zrow's phase too);
     * the queued cells */
    float *prev = (float *)(((uintptr_t)queue + 63) & ~(uintptr_t)63) - xs;
    int *const q0 = (int *)(prev + xs + len + 16);
    int *const qx[2] = {q0, q0 + len / 2 + 32};
    for (int x = x0; x < x1; x++) {
        best[x] = -INFINITY;
        flag[x] = 0.0f;
    }
    const float t = (float)p->t;
    const int flat_v = fabs(p->t) <= 1e-12;
    for (int n = 0; n < p->npieces; n++) {
        const float *const cn[4] = {zrow + p->piece_off[n][0], zrow + p->piece_off[n][1],
                                    zrow + p->piece_off[n][2], zrow + p->piece_off[n][3]};
        const cm_fast_piece q = piece_consts(p, n, flat_v, L, c);
        int nq[2] = {0, 0};
        /* the end's edge: 00-01 (a new step), 00-10 or 01-11 (a new row) */
#define PIECE_CELLS(a, b)                                                                      \
    piece_cells(&q, cn, a, b, t, zrow, xs, x0, x1, best, flag, prev, qx, nq)
        switch (q.e0 * 4 + q.e1) {
        case 0 * 4 + 2: PIECE_CELLS(0, 2); break;
        case 2 * 4 + 0: PIECE_CELLS(2, 0); break;
        case 0 * 4 + 1: PIECE_CELLS(0, 1); break;
        case 1 * 4 + 0: PIECE_CELLS(1, 0); break;
        case 2 * 4 + 3: PIECE_CELLS(2, 3); break;
        default: PIECE_CELLS(3, 2); break;
        }
#undef PIECE_CELLS
        for (int b = 0; b < 2; b++)
            piece_peaks(&q, t, L, c, zrow, p->piece_off[n], qx[b], nq[b], best);
    }
}

int ts_near_run_avx512(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                       float L, float c, float *restrict best, float *restrict flag,
                       float *restrict queue)
{
    if (ts_cpu_vector_level() != TS_CPU_VECTORS_AVX512)
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
