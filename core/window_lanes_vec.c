/* The window hulls of a lockstep block of capped sweep lines, eight lines
 * per AVX-512 vector; see window_lanes.h. Per line the same double
 * operations in the same order as ts_window_hull_slide and
 * ts_window_hull_query (window_hull.h), so the results are the same bit
 * for bit; a window that must be rebuilt is rebuilt by the scalar
 * ts_window_hull_refill. */
#include <limits.h>
#include <stddef.h>

#include "window_lanes.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

_Static_assert(sizeof(ts_hull_pt) == 3 * sizeof(double) && offsetof(ts_hull_pt, g) == sizeof(double) &&
                   offsetof(ts_hull_pt, k) == 2 * sizeof(double),
               "ts_hull_pt is laid out as the gathers read it");

#define AVX512 __attribute__((target("avx512f")))
#define ALWAYS AVX512 static inline __attribute__((always_inline))

/* Eight lines: where their arrays start, in points of L->pts. */
typedef struct {
    const double *pd;   /* L->pts as doubles */
    const int *pi;      /* and as ints */
    __m256i raw, back, front, undo, undo_n; /* raw, back, front, undo points (points), undo
                                               sizes (ints) */
} lanes8;

ALWAYS __mmask8 mask_of(__m256i v)
{
    return (__mmask8)_mm256_movemask_ps(_mm256_castsi256_ps(v));
}

ALWAYS __m256i ones_where(__mmask8 m)
{
    return _mm512_castsi512_si256(_mm512_maskz_set1_epi32((__mmask16)m, 1));
}

/* b where m, else a (AVX-512F has no 256-bit masked moves) */
ALWAYS __m256i sel(__m256i a, __mmask8 m, __m256i b)
{
    return _mm512_castsi512_si256(
        _mm512_mask_mov_epi32(_mm512_castsi256_si512(a), (__mmask16)m, _mm512_castsi256_si512(b)));
}

ALWAYS __mmask8 lt(__m256i a, __m256i b)
{
    return mask_of(_mm256_cmpgt_epi32(b, a));
}

ALWAYS __mmask8 eq(__m256i a, __m256i b)
{
    return mask_of(_mm256_cmpeq_epi32(a, b));
}

/* Field f (0: d, 1: g) of point p (an index into the array at base) of
 * each line, where m. */
ALWAYS __m512d field(const lanes8 *W, __mmask8 m, __m256i base, __m256i p, int f)
{
    __m256i i = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(base, p),
                                                    _mm256_set1_epi32(3)),
                                 _mm256_set1_epi32(f));
    return _mm512_mask_i32gather_pd(_mm512_setzero_pd(), m, i, W->pd, 8);
}

/* Field k of point p, where m; -1 elsewhere. */
ALWAYS __m256i field_k(const lanes8 *W, __mmask8 m, __m256i base, __m256i p)
{
    __m256i i = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(base, p),
                                                    _mm256_set1_epi32(6)),
                                 _mm256_set1_epi32(4));
    return _mm512_castsi512_si256(_mm512_mask_i32gather_epi32(
        _mm512_set1_epi32(-1), (__mmask16)m, _mm512_castsi256_si512(i), W->pi, 4));
}

/* Point p of the array at base := (d, g, k), where m. */
ALWAYS void put_point(const lanes8 *W, __mmask8 m, __m256i base, __m256i p, __m512d d, __m512d g,
                      __m256i k)
{
    const __m256i at = _mm256_mullo_epi32(_mm256_add_epi32(base, p), _mm256_set1_epi32(3));
    _mm512_mask_i32scatter_pd((double *)W->pd, m, at, d, 8);
    _mm512_mask_i32scatter_pd((double *)W->pd, m, _mm256_add_epi32(at, _mm256_set1_epi32(1)), g, 8);
    const __m256i kat = _mm256_add_epi32(_mm256_add_epi32(at, at), _mm256_set1_epi32(4));
    _mm512_mask_i32scatter_epi32((int *)W->pi, (__mmask16)m, _mm512_castsi256_si512(kat),
                                 _mm512_castsi256_si512(k), 4);
}

ALWAYS __m256i load8i(__mmask8 m, const int *p)
{
    return _mm512_castsi512_si256(_mm512_maskz_loadu_epi32((__mmask16)m, p));
}

ALWAYS void store8i(int *p, __mmask8 m, __m256i v)
{
    _mm512_mask_storeu_epi32(p, (__mmask16)m, _mm512_castsi256_si512(v));
}

ALWAYS __m512d load8f(__mmask8 m, const float *p)
{
    return _mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_maskz_loadu_ps((__mmask16)m, p)));
}

/* One move of a climb for the lines of `active`: from point j to point
 * j + dir (dir = +-1) where the slope seen from (d, g) grows (dir > 0:
 * grows or stays, the test (P[j + 1].g - g) (d - P[j].d) >= (P[j].g - g)
 * (d - P[j + 1].d); dir < 0: strictly grows); dj, gj: point j's fields.
 * Returns the lines that moved. */
ALWAYS __mmask8 move(const lanes8 *W, __mmask8 active, __m256i base, int dir, __m512d d,
                     __m512d g, __m256i *j, __m512d *dj, __m512d *gj)
{
    const __m256i jn = _mm256_add_epi32(*j, _mm256_set1_epi32(dir));
    const __m512d dn = field(W, active, base, jn, 0), gn = field(W, active, base, jn, 1);
    const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(gn, g), _mm512_sub_pd(d, *dj));
    const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(*gj, g), _mm512_sub_pd(d, dn));
    const __mmask8 go = dir > 0 ? _mm512_mask_cmp_pd_mask(active, lhs, rhs, _CMP_GE_OQ)
                                : _mm512_mask_cmp_pd_mask(active, lhs, rhs, _CMP_GT_OQ);
    *j = sel(*j, go, jn);
    *dj = _mm512_mask_mov_pd(*dj, go, dn);
    *gj = _mm512_mask_mov_pd(*gj, go, gn);
    return go;
}

/* ts_hull_climb on the hulls at base of n points (lines of m, n > 0) from
 * j, seen from (d, g); *dj, *gj: the fields of the point it ends on. */
ALWAYS __m256i climb(const lanes8 *W, __mmask8 m, __m256i base, __m256i n, __m256i j, __m512d d,
                     __m512d g, __m512d *dj, __m512d *gj)
{
    const __m256i one = _mm256_set1_epi32(1), zero = _mm256_setzero_si256();
    j = _mm256_min_epi32(j, _mm256_sub_epi32(n, one));
    *dj = field(W, m, base, j, 0);
    *gj = field(W, m, base, j, 1);
    __mmask8 moved = 0;
    for (__mmask8 up = m & lt(_mm256_add_epi32(j, one), n); up;) {
        up = move(W, up, base, 1, d, g, &j, dj, gj);
        moved |= up;
        up &= lt(_mm256_add_epi32(j, one), n);
    }
    /* a line that went up has just failed the test down (the same products) */
    for (__mmask8 down = m & ~moved & mask_of(_mm256_cmpgt_epi32(j, zero)); down;)
        down = move(W, down, base, -1, d, g, &j, dj, gj) & mask_of(_mm256_cmpgt_epi32(j, zero));
    return j;
}

/* ts_window_hull_query for the lines of m, seen from (d, g), with their
 * fingers on the front and the back at ff and fb (by line): the
 * occluder's step (-1: none) and its distance from the point (0: none). */
ALWAYS void query(const lanes8 *W, __mmask8 m, __m512d d, __m512d g, __m256i nf, __m256i nb,
                  int *ff, int *fb, __m256i *k_out, __m256 *dd_out)
{
    const __m256i zero = _mm256_setzero_si256();
    const __mmask8 mf = m & mask_of(_mm256_cmpgt_epi32(nf, zero));
    const __mmask8 mb = m & mask_of(_mm256_cmpgt_epi32(nb, zero));
    __m512d bd = _mm512_setzero_pd(), bg = bd, ad = bd, ag = bd;
    __m256i f0 = zero, f1 = zero;
    if (mf) {
        f0 = climb(W, mf, W->front, nf, load8i(mf, ff), d, g, &bd, &bg);
        store8i(ff, mf, f0);
    }
    if (mb) {
        f1 = climb(W, mb, W->back, nb, load8i(mb, fb), d, g, &ad, &ag);
        store8i(fb, mb, f1);
    }
    __m256i bk = field_k(W, mf, W->front, f0);
    const __m256i ak = field_k(W, mb, W->back, f1);
    /* the back's wins where the front has none or it is strictly steeper */
    const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(ag, g), _mm512_sub_pd(d, bd));
    const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(bg, g), _mm512_sub_pd(d, ad));
    const __mmask8 take = mb & (~mf | _mm512_mask_cmp_pd_mask(mf, lhs, rhs, _CMP_GT_OQ));
    bd = _mm512_mask_mov_pd(bd, take, ad);
    bk = sel(bk, take, ak);
    const __mmask8 found = mf | mb;
    *k_out = sel(_mm256_set1_epi32(-1), found, bk);
    *dd_out = _mm512_maskz_cvtpd_ps(found, _mm512_sub_pd(d, bd));
}

/* Lines j..j+7 of those of `lanes`. */
AVX512 static void step8(const ts_window_lanes *L, const ts_lane_step *s, int j, __mmask8 lanes,
                         const ts_lane_occluders *occ)
{
    const __m256i one = _mm256_set1_epi32(1);
    const __m512d c = _mm512_set1_pd(s->c);
    const __m256i n = _mm256_set1_epi32(L->n);
    lanes8 W;
    W.pd = (const double *)L->pts;
    W.pi = (const int *)L->pts;
    W.raw = _mm256_mullo_epi32(_mm256_add_epi32(_mm256_set1_epi32(j),
                                                _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)),
                               _mm256_set1_epi32((int)L->lane_pts));
    W.back = _mm256_add_epi32(W.raw, n);
    W.front = _mm256_add_epi32(W.back, n);
    W.undo = _mm256_add_epi32(W.front, n);
    /* undo sizes: ints after the undo points */
    W.undo_n = _mm256_mullo_epi32(_mm256_add_epi32(W.undo, n), _mm256_set1_epi32(6));
    const __m512d d = _mm512_maskz_loadu_pd(lanes, s->d + j);
    const __m512d cdd = _mm512_mul_pd(_mm512_mul_pd(c, d), d);
    /* the sample */
    const __m512d hs = load8f(lanes, s->hs + j);
    const __mmask8 push = _mm512_mask_cmp_pd_mask(lanes, hs, hs, _CMP_ORD_Q);
    __m256i rn = load8i(lanes, L->raw_n + j);
    put_point(&W, push, W.raw, rn, d, _mm512_sub_pd(hs, cdd), _mm256_set1_epi32(s->k));
    rn = _mm256_add_epi32(rn, ones_where(push));
    store8i(L->raw_n + j, lanes, rn);
    /* samples now near_skip behind enter the back */
    const __m512d near = _mm512_set1_pd(s->near_skip), cap = _mm512_set1_pd(L->cap);
    __m256i in = load8i(lanes, L->in + j), nb = load8i(lanes, L->nb + j);
    __mmask8 enter = lanes & lt(in, rn);
    enter = _mm512_mask_cmp_pd_mask(enter, _mm512_sub_pd(d, field(&W, enter, W.raw, in, 0)), near,
                                    _CMP_GE_OQ);
    while (enter) {
        const __m512d pd = field(&W, enter, W.raw, in, 0), pg = field(&W, enter, W.raw, in, 1);
        const __m256i pk = field_k(&W, enter, W.raw, in);
        in = _mm256_add_epi32(in, ones_where(enter));
        /* pop while (S[m - 2].g - p.g) (p.d - S[m - 1].d) >= (S[m - 1].g - p.g) (p.d - S[m - 2].d) */
        __m256i m = nb;
        __mmask8 pop = enter & mask_of(_mm256_cmpgt_epi32(m, one));
        while (pop) {
            const __m256i a = _mm256_sub_epi32(m, _mm256_set1_epi32(2)), b = _mm256_sub_epi32(m, one);
            const __m512d ad = field(&W, pop, W.back, a, 0), ag = field(&W, pop, W.back, a, 1);
            const __m512d bd = field(&W, pop, W.back, b, 0), bg = field(&W, pop, W.back, b, 1);
            const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(ag, pg), _mm512_sub_pd(pd, bd));
            const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(bg, pg), _mm512_sub_pd(pd, ad));
            const __mmask8 go = _mm512_mask_cmp_pd_mask(pop, lhs, rhs, _CMP_GE_OQ);
            m = _mm256_sub_epi32(m, ones_where(go));
            pop = go & mask_of(_mm256_cmpgt_epi32(m, one));
        }
        put_point(&W, enter, W.back, m, pd, pg, pk);
        nb = sel(nb, enter, _mm256_add_epi32(m, one));
        enter &= lt(in, rn);
        enter = _mm512_mask_cmp_pd_mask(enter, _mm512_sub_pd(d, field(&W, enter, W.raw, in, 0)),
                                        near, _CMP_GE_OQ);
    }
    /* samples more than cap behind leave the front */
    __m256i out = load8i(lanes, L->out + j), mid = load8i(lanes, L->mid + j);
    __m256i nf = load8i(lanes, L->nf + j);
    __mmask8 leave = lanes & lt(out, in);
    leave = _mm512_mask_cmp_pd_mask(leave, _mm512_sub_pd(d, field(&W, leave, W.raw, out, 0)), cap,
                                    _CMP_GT_OQ);
    while (leave) {
        const __mmask8 refill = leave & eq(out, mid);
        if (refill) {
            store8i(L->in + j, lanes, in);
            store8i(L->out + j, lanes, out);
            store8i(L->nb + j, lanes, nb);
            store8i(L->nf + j, lanes, nf);
            store8i(L->mid + j, lanes, mid);
            for (int q = 0; q < 8; q++)
                if (refill >> q & 1) {
                    ts_window_hull w = ts_window_lanes_get(L, j + q);
                    ts_window_hull_refill(&w, L->pts + (size_t)(j + q) * L->lane_pts);
                    ts_window_lanes_put(L, j + q, &w);
                }
            nb = load8i(lanes, L->nb + j);
            nf = load8i(lanes, L->nf + j);
            mid = load8i(lanes, L->mid + j);
        }
        /* the oldest sample was the front's last push: undo it */
        const __m256i top = _mm256_sub_epi32(nf, one);
        put_point(&W, leave, W.front, top, field(&W, leave, W.undo, out, 0),
                  field(&W, leave, W.undo, out, 1), field_k(&W, leave, W.undo, out));
        const __m256i ui = _mm256_add_epi32(W.undo_n, out);
        nf = _mm512_castsi512_si256(_mm512_mask_i32gather_epi32(
            _mm512_castsi256_si512(nf), (__mmask16)leave, _mm512_castsi256_si512(ui), W.pi, 4));
        out = _mm256_add_epi32(out, ones_where(leave));
        leave &= lt(out, in);
        leave = _mm512_mask_cmp_pd_mask(leave, _mm512_sub_pd(d, field(&W, leave, W.raw, out, 0)),
                                        cap, _CMP_GT_OQ);
    }
    store8i(L->in + j, lanes, in);
    store8i(L->out + j, lanes, out);
    store8i(L->mid + j, lanes, mid);
    store8i(L->nb + j, lanes, nb);
    store8i(L->nf + j, lanes, nf);
    /* the occluders of the cells below (hi, when asked) and above (lo) */
    const __m256i idx = _mm256_add_epi32(_mm256_set1_epi32(j), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    const __mmask8 want_hi = lanes & ~lt(idx, _mm256_set1_epi32(s->hi_from)) &
                             ~mask_of(_mm256_cmpgt_epi32(idx, _mm256_set1_epi32(s->hi_to)));
    const __m512d hc = load8f(lanes, s->hc + j), hn = load8f(lanes, s->hn + j);
    __m256i k;
    __m256 dd;
    query(&W, _mm512_mask_cmp_pd_mask(want_hi, hc, hc, _CMP_ORD_Q), d, _mm512_sub_pd(hc, cdd), nf,
          nb, L->finger + j, L->finger + L->lanes + j, &k, &dd);
    store8i(occ->hi_k + j, lanes, k);
    _mm512_mask_storeu_ps(occ->hi_dd + j, (__mmask16)lanes, _mm512_castps256_ps512(dd));
    query(&W, _mm512_mask_cmp_pd_mask(lanes, hn, hn, _CMP_ORD_Q), d, _mm512_sub_pd(hn, cdd), nf,
          nb, L->finger + 2 * L->lanes + j, L->finger + 3 * L->lanes + j, &k, &dd);
    store8i(occ->lo_k + j + 1, lanes, k);
    _mm512_mask_storeu_ps(occ->lo_dd + j + 1, (__mmask16)lanes, _mm512_castps256_ps512(dd));
}

int ts_window_lanes_step_vec(const ts_window_lanes *L, const ts_lane_step *s,
                             const ts_lane_occluders *occ)
{
    /* 32-bit offsets: the last line's undo sizes, as ints */
    if (!ts_lane_has_avx512f() || (long long)L->lanes * (long long)L->lane_pts * 6 > INT_MAX)
        return 0;
    for (int j = s->j0; j <= s->j1; j += 8) {
        int left = s->j1 - j + 1;
        step8(L, s, j, left >= 8 ? 0xFF : (__mmask8)((1u << left) - 1), occ);
    }
    return 1;
}

#else

int ts_window_lanes_step_vec(const ts_window_lanes *L, const ts_lane_step *s,
                             const ts_lane_occluders *occ)
{
    (void)L;
    (void)s;
    (void)occ;
    return 0;
}

#endif
