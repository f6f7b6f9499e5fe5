/* The AVX-512 window scan of a lockstep block of capped lines
 * (capped_lanes.h), pruned for long windows; see capped_lanes512.h (the
 * step's queries and answers: capped_steps512.c). */
#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#include <math.h>

#include "capped_lanes512.h"
#include "simd_clones.h"

/* groups of eight lines scanned together: independent chains of compares
 * and selects, so that their latencies overlap */
#define NG TS_CAP_NG

/* The accumulators of up to NG groups of eight lines: the queries' distance
 * and heights, the best slope so far (numerator, denominator) and its step,
 * for the cell below (c) and the one above (n). */
typedef struct {
    __m512d d[NG], gc[NG], gn[NG], bnc[NG], bdc[NG], bnn[NG], bdn[NG];
    __m512i bkc[NG], bkn[NG];
} scan512;

/* One slot of the window for group q of eight lines (its distances pd,
 * heights pg, already at the group's lines; step ks): the operations of
 * scan_scalar; the distance test only where `test`. */
TS_AVX512 static inline __attribute__((always_inline)) void
scan512_one(const ts_cap_lanes *r, int q, const double *pd, const double *pg, __m512i ks,
            int test, scan512 *a)
{
    const __m512d dd = _mm512_sub_pd(a->d[q], _mm512_load_pd(pd));
    __mmask8 in = 0xFF;
    if (test) {
        in = _mm512_cmp_pd_mask(dd, _mm512_set1_pd(r->near), _CMP_GE_OQ);
        in = _mm512_mask_cmp_pd_mask(in, dd, _mm512_set1_pd(r->cap), _CMP_LE_OQ);
    }
    const __m512d sg = _mm512_load_pd(pg);
    const __m512d nc = _mm512_sub_pd(sg, a->gc[q]), nn = _mm512_sub_pd(sg, a->gn[q]);
    const __mmask8 wc = _mm512_mask_cmp_pd_mask(in, _mm512_mul_pd(nc, a->bdc[q]),
                                                _mm512_mul_pd(a->bnc[q], dd), _CMP_GT_OQ);
    const __mmask8 wn = _mm512_mask_cmp_pd_mask(in, _mm512_mul_pd(nn, a->bdn[q]),
                                                _mm512_mul_pd(a->bnn[q], dd), _CMP_GT_OQ);
    a->bnc[q] = _mm512_mask_mov_pd(a->bnc[q], wc, nc);
    a->bdc[q] = _mm512_mask_mov_pd(a->bdc[q], wc, dd);
    a->bkc[q] = _mm512_mask_mov_epi64(a->bkc[q], wc, ks);
    a->bnn[q] = _mm512_mask_mov_pd(a->bnn[q], wn, nn);
    a->bdn[q] = _mm512_mask_mov_pd(a->bdn[q], wn, dd);
    a->bkn[q] = _mm512_mask_mov_epi64(a->bkn[q], wn, ks);
}

/* One slot of the window (its distances pd, heights pg, step ks) for ng
 * groups of eight lines. */
TS_AVX512 static inline __attribute__((always_inline)) void
scan512_slot(const ts_cap_lanes *r, int ng, const double *pd, const double *pg, __m512i ks,
             int test, scan512 *a)
{
    for (int q = 0; q < NG; q++) {
        if (q >= ng)
            break;
        scan512_one(r, q, pd + 8 * q, pg + 8 * q, ks, test, a);
    }
}

/* The window's slots of lags lag_from down to lag_to (oldest first), for
 * ng groups of eight lines from line g. */
TS_AVX512 static inline __attribute__((always_inline)) void
scan512_lags(const ts_cap_lanes *r, int k, int g, int ng, int lag_from, int lag_to, scan512 *a)
{
    int slot = (k - lag_from) % r->slots;
    for (int lag = lag_from; lag >= lag_to; lag--) {
        const size_t at = (size_t)slot * r->stride + g;
        slot = slot + 1 == r->slots ? 0 : slot + 1;
        /* within the sure lags, the distance needs no test (a slot without
         * a sample has d NaN, which fails the slope's compare) */
        const int sure = lag >= r->sure_lo && lag <= r->sure_hi;
        scan512_slot(r, ng, r->d + at, r->g + at, _mm512_set1_epi64(k - lag), !sure, a);
    }
}

/*
 * Pruning. A query (d, g) scans its window oldest first and takes a sample
 * only where its slope compares strictly greater (cross-multiplied, so
 * rounded): the answer is the chain of such takes. A group whose samples
 * all have slopes below T, T well below the slope of a sample L of the
 * window, can be left out without changing the answer: its samples could
 * only be taken while the chain's slope is below theirs, and the chains
 * with and without them can then differ only by samples within rounding
 * of each other (a take of one not taken by the other is at most one
 * rounding of the products above the other's slope), so by at most about
 * 2^-52 of the slopes per sample, and L, above both by the margin, is taken
 * by both and joins them again. The margin, PRUNE_MARGIN of |slope(L)|, is
 * far above that drift for windows of up to 10^5 samples (the pruned scan
 * takes windows of at most PRUNE_TO = 256 lags, capped_lanes.c).
 * L is the steepest of a few samples of the window (prune_threshold).
 *
 * A group's samples p have g_p <= gmax and dlo <= d_p <= dhi, so for a
 * query (d, g) with g >= gmin, (g_p - g) / (d - d_p) < T wherever
 * gmax - gmin < T (d - dsel), dsel = dhi where T >= 0, dlo where T < 0;
 * tested as gmax + T dsel < gmin + T d, each side with one rounding (a
 * fused multiply-add), against a right side lowered by 1e-12 of its terms'
 * size, far above those roundings. The scan's rounded (g_p - g) / (d - d_p)
 * is then below T + 2^-51 |T|, far inside the margin.
 *
 * Ties. Where T is 0 (L level with the higher query point, as on exactly
 * flat ground without curvature, where every sample ties) the margin is
 * 0 and no group passes that test. But where the window's oldest sample,
 * which the scan takes first, is at least as high as both query points,
 * the chain's numerator is >= 0 from there on, so a later sample p with
 * g_p <= g (numerator <= 0; the signs of the subtraction and the products
 * are exact) is never taken: a group whose gmax <= gmin can be left out
 * exactly, and the oldest slot is scanned before the pruned ones
 * (threshold_tests' tie lanes, scan512_pruned).
 */
#define PRUNE_MARGIN 1e-9
/* The newest lags are scanned without a test: their groups seldom prune
 * (4 against 8: ~1 % fewer cycles per scan on this Zen 4 host, 2 the same
 * as 4 within the replay's noise; performance-history.md, session 39). */
#ifndef PRUNE_NEAR
#define PRUNE_NEAR 4
#endif

/* For the eight lines from j: the prune threshold T (-inf: none known;
 * +inf: no query), the lower of the two query heights (+inf: no query),
 * the lines without a query and the tie lines (those whose oldest slot is
 * in the window and at least as high as both query points). T is the
 * steepest (for the higher query point) of four samples of the window,
 * each taken only where the scan's own tests put it in the window: the
 * line's previous answers of both queries, and its newest and oldest
 * slot. */
TS_AVX512 static inline __attribute__((always_inline)) void
prune_threshold(const ts_cap_lanes *r, int k, int lag_hi, int j, const scan512 *a, int q,
                __m512d *thr, __m512d *gmin, __mmask8 *idle, __mmask8 *tie)
{
    const __m512i zero = _mm512_setzero_si512();
    const __m512d near = _mm512_set1_pd(r->near), cap = _mm512_set1_pd(r->cap);
    __m512d cd[4], cg[4];
    __mmask8 cok[4];
    for (int i = 0; i < 2; i++) { /* the previous answers */
        const __m512i kk = _mm512_load_epi64((i ? r->kn : r->kc) + j);
        const __m512i lag = _mm512_sub_epi64(_mm512_set1_epi64(k), kk);
        __mmask8 ok = _mm512_cmpge_epi64_mask(kk, zero);
        ok = _mm512_mask_cmpge_epi64_mask(ok, lag, _mm512_set1_epi64(r->lag_lo));
        ok = _mm512_mask_cmple_epi64_mask(ok, lag, _mm512_set1_epi64(lag_hi));
        const __m256i at = ts_cap_ring_at512(r, k, lag, j);
        cd[i] = _mm512_mask_i32gather_pd(_mm512_set1_pd(NAN), ok, at, r->d, 8);
        cg[i] = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), ok, at, r->g, 8);
        cok[i] = ok;
    }
    for (int i = 2; i < 4; i++) { /* the oldest and the newest slot */
        const size_t at = (size_t)((k - (i == 2 ? lag_hi : r->lag_lo)) % r->slots) * r->stride + j;
        cd[i] = _mm512_load_pd(r->d + at);
        cg[i] = _mm512_load_pd(r->g + at);
        cok[i] = 0xFF;
    }
    /* The threshold of the higher query point only: from it every
     * sample's slope is at most its slope from the lower one, so the
     * steepest candidate's is the lower of the two queries' (up to the
     * compares' rounding: T is the slope of a window sample either way). */
    const __mmask8 hc = _mm512_cmp_pd_mask(a->gc[q], a->gc[q], _CMP_ORD_Q);
    const __mmask8 hn = _mm512_cmp_pd_mask(a->gn[q], a->gn[q], _CMP_ORD_Q);
    const __m512d inf = _mm512_set1_pd(INFINITY);
    const __m512d gc = _mm512_mask_mov_pd(_mm512_set1_pd(-INFINITY), hc, a->gc[q]);
    const __m512d gn = _mm512_mask_mov_pd(_mm512_set1_pd(-INFINITY), hn, a->gn[q]);
    const __m512d ghi = _mm512_max_pd(gc, gn);
    __m512d bn = _mm512_set1_pd(-INFINITY), bd = _mm512_set1_pd(1.0);
    *tie = 0;
    for (int c = 0; c < 4; c++) {
        const __m512d dd = _mm512_sub_pd(a->d[q], cd[c]), n = _mm512_sub_pd(cg[c], ghi);
        __mmask8 ok = _mm512_mask_cmp_pd_mask(cok[c], dd, near, _CMP_GE_OQ);
        ok = _mm512_mask_cmp_pd_mask(ok, dd, cap, _CMP_LE_OQ);
        if (c == 2) /* the oldest slot, in the window, not below the queries */
            *tie = _mm512_mask_cmp_pd_mask(ok, cg[c], ghi, _CMP_GE_OQ);
        ok = _mm512_mask_cmp_pd_mask(ok, _mm512_mul_pd(n, bd), _mm512_mul_pd(bn, dd), _CMP_GT_OQ);
        bn = _mm512_mask_mov_pd(bn, ok, n);
        bd = _mm512_mask_mov_pd(bd, ok, dd);
    }
    /* s = bn / bd (-inf where none) without a division: 1 / bd to 14
     * bits, then two Newton steps (to within ~2^-52 of 1 / bd: s lies
     * within 1e-15 of bn / bd, far inside the margin below) */
    __m512d y = _mm512_rcp14_pd(bd);
    y = _mm512_mul_pd(y, _mm512_fnmadd_pd(bd, y, _mm512_set1_pd(2.0)));
    y = _mm512_mul_pd(y, _mm512_fnmadd_pd(bd, y, _mm512_set1_pd(2.0)));
    const __m512d s = _mm512_mul_pd(bn, y);
    /* s - margin |s|; +inf, and a lower height of +inf, without a query */
    const __mmask8 has = hc | hn;
    *thr = _mm512_mask_mov_pd(inf, has,
                              _mm512_fnmadd_pd(_mm512_abs_pd(s), _mm512_set1_pd(PRUNE_MARGIN), s));
    *gmin = _mm512_min_pd(_mm512_mask_mov_pd(inf, hc, a->gc[q]),
                          _mm512_mask_mov_pd(inf, hn, a->gn[q]));
    *idle = (__mmask8)~has;
}

/* The lines of group q (entry at of level l's groups, at the group of
 * lines) for which the group may hold a sample at least as steep as the
 * threshold: unless gmax + T dsel < gmin + T d (above: rhs) or the line
 * has no query, dsel the group's newest distance where T >= 0, its oldest
 * where T < 0 (neg). */
TS_AVX512 static inline __attribute__((always_inline)) __mmask8
group_may_hold(const ts_cap_lanes *r, int l, size_t at, int q, const __m512d *thr,
               const __m512d *rhs, const __mmask8 *neg, const __mmask8 *idle)
{
    const __m512d dsel =
        _mm512_mask_load_pd(_mm512_load_pd(r->dhi[l] + at), neg[q], r->dlo[l] + at);
    const __m512d lhs = _mm512_fmadd_pd(thr[q], dsel, _mm512_load_pd(r->gmax[l] + at));
    return (__mmask8)~(_mm512_cmp_pd_mask(lhs, rhs[q], _CMP_LT_OQ) | idle[q]);
}

/* The ng groups of lines from g (bit q: group q) for which group idx of
 * level l may hold such a sample on some line (group_may_hold). */
TS_AVX512 static inline __attribute__((always_inline)) unsigned
groups_needed(const ts_cap_lanes *r, int l, int idx, int g, int ng, const __m512d *thr,
              const __m512d *rhs, const __mmask8 *neg, const __mmask8 *idle)
{
    const size_t at = (size_t)idx * r->stride + g;
    unsigned need = 0;
    for (int q = 0; q < NG; q++) {
        if (q >= ng)
            break;
        need |= (unsigned)(group_may_hold(r, l, at + 8 * q, q, thr, rhs, neg, idle) != 0) << q;
    }
    return need;
}

/* The slots each group of eight lines scans, oldest first: their steps and
 * offsets in the ring (slot * stride). A level-0 group adds at most
 * TS_CAP_G0 to a list; the lists have room for a vector's store beyond. */
#define LIST_MAX 1024
typedef struct {
    int n[NG];
    int step[NG][LIST_MAX + 16], off[NG][LIST_MAX + 16];
} slot_lists;

/* Scan the listed slots, each group of lines its own list, in lockstep (the
 * chains of the groups stay independent, so that their latencies overlap),
 * and empty the lists. A shorter list goes on with the ring's spare slot,
 * which has no samples (d NaN: never taken). */
TS_AVX512 static inline __attribute__((always_inline)) void
scan512_lists(const ts_cap_lanes *r, int g, int ng, slot_lists *L, scan512 *a)
{
    /* the distance test, unless every lag of the window is sure (the spare
     * slot's NaN fails the slope's compare too) */
    const int test = r->lag_lo < r->sure_lo || r->lag_hi > r->sure_hi;
    int n = 0;
    for (int q = 0; q < ng; q++)
        n = L->n[q] > n ? L->n[q] : n;
    /* (selected, not stored: the stores' loops branch on each list's
     * length) */
    const int spare = r->slots * r->stride;
    for (int i = 0; i < n; i++)
        for (int q = 0; q < NG; q++) {
            if (q >= ng)
                break;
            const int in = i < L->n[q];
            const size_t at = (size_t)(in ? L->off[q][i] : spare) + g + 8 * q;
            const long long step = in ? L->step[q][i] : 0;
            scan512_one(r, q, r->d + at, r->g + at, _mm512_set1_epi64(step), test, a);
        }
    for (int q = 0; q < ng; q++)
        L->n[q] = 0;
}

/* Level-0 groups to scan for a group of lines: the group, its entry in
 * the groups' rings, the group of lines; the pairs have room for a
 * vector's store beyond. */
#define PAIRS_MAX 64
typedef struct {
    int n;
    int m0[PAIRS_MAX + 16], idx[PAIRS_MAX + 16], q[PAIRS_MAX + 16];
} group_pairs;

/* Bit i set where byte i of x is not 0. */
static inline unsigned nonzero_bytes(unsigned long long x)
{
    const unsigned long long low7 = 0x7F7F7F7F7F7F7F7FULL;
    const unsigned long long top = (((x & low7) + low7) | x) & 0x8080808080808080ULL;
    return (unsigned)(((top >> 7) * 0x0102040810204080ULL) >> 56);
}

_Static_assert(TS_CAP_G0 <= 8 && TS_CAP_G1 / TS_CAP_G0 <= 8,
               "a group's slots, a level-1 group's level-0 groups as the bytes of one word");

/* Which of the count level-0 groups from entry idx0 on (at most the
 * TS_CAP_G1 / TS_CAP_G0 of a level-1 group) group q of lines from g needs
 * (bit i: the i-th), by group_may_hold. */
TS_AVX512 static inline __attribute__((always_inline)) unsigned
level0_needed(const ts_cap_lanes *r, int idx0, int count, int g, int q, const __m512d *thr,
              const __m512d *rhs, const __mmask8 *neg, const __mmask8 *idle)
{
    unsigned long long any = 0;
    int idx = idx0;
    for (int i = 0; i < count; i++) {
        const size_t at = (size_t)idx * r->stride + g + 8 * q;
        any |= (unsigned long long)group_may_hold(r, 0, at, q, thr, rhs, neg, idle) << (8 * i);
        idx = idx + 1 == r->groups[0] ? 0 : idx + 1;
    }
    return nonzero_bytes(any);
}

/* Append to group q's list the steps a0..b0 of the level-0 group from step
 * s0 (ring slot slot) whose samples some line of q may take: the group
 * test with the group one sample (gmax = g_p, dsel = d_p), tt and rt the
 * threshold and right side as there. */
TS_AVX512 static inline __attribute__((always_inline)) void
list_samples(const ts_cap_lanes *r, int slot, int s0, int a0, int b0, int g, int q, __m512d tt,
             __m512d rt, __mmask8 idle, slot_lists *L)
{
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 0, 0, 0, 0, 0, 0, 0);
    const unsigned full = (1u << TS_CAP_G0) - 1;
    const unsigned range = (full << (a0 - s0)) & (full >> (s0 + TS_CAP_G0 - 1 - b0));
    const double *pd = r->d + (size_t)slot * r->stride + g + 8 * q;
    const double *pg = r->g + (size_t)slot * r->stride + g + 8 * q;
    __mmask8 m[TS_CAP_G0];
#pragma GCC unroll 8
    for (int i = 0; i < TS_CAP_G0; i++) {
        const __m512d lhs = _mm512_fmadd_pd(tt, _mm512_load_pd(pd + (size_t)i * r->stride),
                                            _mm512_load_pd(pg + (size_t)i * r->stride));
        m[i] = _mm512_mask_cmp_pd_mask((__mmask8)~idle, lhs, rt, _CMP_GE_OQ);
    }
    /* the eight masks as the bytes of one word, then its nonzero bytes */
    const __mmask64 all = _mm512_kunpackd(
        _mm512_kunpackw(_mm512_kunpackb(m[7], m[6]), _mm512_kunpackb(m[5], m[4])),
        _mm512_kunpackw(_mm512_kunpackb(m[3], m[2]), _mm512_kunpackb(m[1], m[0])));
    const unsigned any = _mm_cmpneq_epi8_mask(_mm_cvtsi64_si128((long long)_cvtmask64_u64(all)),
                                              _mm_setzero_si128());
    const __mmask16 take = (__mmask16)(any & range);
    const __m512i steps = _mm512_add_epi32(_mm512_set1_epi32(s0), iota);
    const __m512i offs = _mm512_add_epi32(_mm512_set1_epi32(slot * r->stride),
                                          _mm512_mullo_epi32(iota, _mm512_set1_epi32(r->stride)));
    _mm512_storeu_si512(L->step[q] + L->n[q], _mm512_maskz_compress_epi32(take, steps));
    _mm512_storeu_si512(L->off[q] + L->n[q], _mm512_maskz_compress_epi32(take, offs));
    L->n[q] += __builtin_popcount(take);
}

/* The smallest double above x (x finite; -0 as +0). */
TS_AVX512 static inline __attribute__((always_inline)) __m512d next_up(__m512d x)
{
    const __m512d z = _mm512_add_pd(x, _mm512_setzero_pd()); /* -0 + 0 = +0 */
    const __m512i b = _mm512_castpd_si512(z);
    const __mmask8 negative = _mm512_cmp_pd_mask(z, _mm512_setzero_pd(), _CMP_LT_OQ);
    return _mm512_castsi512_pd(_mm512_mask_sub_epi64(_mm512_add_epi64(b, _mm512_set1_epi64(1)),
                                                     negative, b, _mm512_set1_epi64(1)));
}

/* The tests' terms for threshold T (thr) and lower query height gmin at
 * query distance d: group_may_hold's right side and sign, list_samples'
 * threshold and right side. On the tie lines (prune_threshold) where T is
 * 0, the right side is the next double above gmin, so that the tests
 * leave out exactly the groups and samples with g_p <= gmin (the pruning
 * comment's ties). */
TS_AVX512 static inline __attribute__((always_inline)) void
threshold_tests(__m512d thr, __m512d gmin, __m512d d, __mmask8 tie, __m512d *rhs, __mmask8 *neg,
                __m512d *tt, __m512d *rt)
{
    *neg = _mm512_cmp_pd_mask(thr, _mm512_setzero_pd(), _CMP_LT_OQ);
    const __m512d td = _mm512_mul_pd(thr, d);
    const __m512d size = _mm512_add_pd(_mm512_abs_pd(gmin), _mm512_abs_pd(td));
    *rhs = _mm512_fnmadd_pd(size, _mm512_set1_pd(1e-12), _mm512_fmadd_pd(thr, d, gmin));
    /* (gmin is finite on a tie line: it has a query) */
    const __mmask8 level = _mm512_mask_cmp_pd_mask(tie, thr, _mm512_setzero_pd(), _CMP_EQ_OQ);
    *rhs = _mm512_mask_mov_pd(*rhs, level, next_up(gmin));
    /* sample by sample: T = -inf (no threshold) as T = 0 against -inf, so
     * that every sample passes (a distance of 0 would give NaN), and a slot
     * without a sample (d NaN) fails */
    const __mmask8 none = _mm512_cmp_pd_mask(thr, _mm512_set1_pd(-INFINITY), _CMP_EQ_OQ);
    *tt = _mm512_mask_mov_pd(thr, none, _mm512_setzero_pd());
    *rt = _mm512_mask_mov_pd(*rhs, none, _mm512_set1_pd(-INFINITY));
}

/* The threshold raised, where the scan so far has taken a steeper sample
 * than the one it came from: the steeper, from the higher query point, of
 * the two queries' answers so far, less the margin (prune_threshold's).
 * Those answers are samples of the window that the scan has taken, so
 * the pruning argument holds with either as L. A query's answer is at
 * height g + bn, its slope from the higher point ghi (bn + (g - ghi)) / bd
 * to within ~2^-51 (|bn| + |g - ghi|) / bd, which is taken off too: T
 * stays below L's slope where the difference cancels. */
TS_AVX512 static inline __attribute__((always_inline)) __m512d
raised_threshold(const scan512 *a, int q, __m512d thr)
{
    const __mmask8 hc = _mm512_cmp_pd_mask(a->gc[q], a->gc[q], _CMP_ORD_Q);
    const __mmask8 hn = _mm512_cmp_pd_mask(a->gn[q], a->gn[q], _CMP_ORD_Q);
    const __m512d ninf = _mm512_set1_pd(-INFINITY), slack = _mm512_set1_pd(1e-14);
    const __m512d ghi = _mm512_max_pd(_mm512_mask_mov_pd(ninf, hc, a->gc[q]),
                                      _mm512_mask_mov_pd(ninf, hn, a->gn[q]));
    __m512d s = ninf;
    for (int x = 0; x < 2; x++) {
        const __m512d g = x ? a->gn[q] : a->gc[q], bn = x ? a->bnn[q] : a->bnc[q];
        const __m512d bd = x ? a->bdn[q] : a->bdc[q], up = _mm512_sub_pd(g, ghi);
        /* -inf where no answer yet (bn = -inf), NaN where no query */
        const __m512d sx = _mm512_div_pd(
            _mm512_fnmadd_pd(_mm512_add_pd(_mm512_abs_pd(bn), _mm512_abs_pd(up)), slack,
                             _mm512_add_pd(bn, up)),
            bd);
        s = _mm512_max_pd(s, _mm512_mask_mov_pd(ninf, x ? hn : hc, sx));
    }
    const __m512d t = _mm512_fnmadd_pd(_mm512_abs_pd(s), _mm512_set1_pd(PRUNE_MARGIN), s);
    /* NaN (no answer yet: -inf less its margin) fails the compare */
    return _mm512_mask_mov_pd(thr, _mm512_cmp_pd_mask(t, thr, _CMP_GT_OQ), t);
}

_Static_assert(PAIRS_MAX * TS_CAP_G0 <= LIST_MAX && NG * (TS_CAP_G1 / TS_CAP_G0) <= PAIRS_MAX,
               "the lists of the pairs listed at once fit, and a level-1 group's pairs");

/* The samples of the pairs P that a line may take, appended to the lists
 * (list_samples); P emptied. */
TS_AVX512 static inline __attribute__((always_inline)) void
list_pairs(const ts_cap_lanes *r, int s_lo, int s_hi, int g, const __m512d *tt, const __m512d *rt,
           const __mmask8 *idle, group_pairs *P, slot_lists *L)
{
    for (int p = 0; p < P->n; p++) {
        const int q = P->q[p], s0 = P->m0[p] * TS_CAP_G0;
        const int a0 = s0 > s_lo ? s0 : s_lo,
                  b0 = s0 + TS_CAP_G0 - 1 < s_hi ? s0 + TS_CAP_G0 - 1 : s_hi;
        list_samples(r, P->idx[p] * TS_CAP_G0, s0, a0, b0, g, q, tt[q], rt[q], idle[q], L);
    }
    P->n = 0;
}

/* The pruned scan of steps s_lo..s_hi for the ng groups of lines from g.
 * Each group of lines lists the slots it must scan: those of the level-0
 * groups that the level-1 and level-0 bounds leave (the newest PRUNE_NEAR
 * steps untested), and of these the samples that the same bound, taken
 * sample by sample (a group of one: gmax = g_p, dsel = d_p), leaves. */
TS_AVX512 static inline __attribute__((always_inline)) void
scan512_pruned(const ts_cap_lanes *r, int k, int lag_hi, int g, int ng, scan512 *a)
{
    __m512d thr[NG], rhs[NG], tt[NG], rt[NG], gmin[NG];
    __mmask8 idle[NG], neg[NG], tie[NG];
    for (int q = 0; q < ng; q++) {
        prune_threshold(r, k, lag_hi, g + 8 * q, a, q, &thr[q], &gmin[q], &idle[q], &tie[q]);
        threshold_tests(thr[q], gmin[q], a->d[q], tie[q], &rhs[q], &neg[q], &tt[q], &rt[q]);
    }
    /* Where a tie line's threshold is level, the oldest slot first, whatever
     * the tests say (its pruning rests on it), then the pruned ones after
     * it. (A tie line's threshold is never below 0, its oldest sample's
     * slope being a candidate: it is level from the start or never.) */
    __mmask8 level = 0;
    for (int q = 0; q < ng; q++)
        level |= _mm512_mask_cmp_pd_mask(tie[q], thr[q], _mm512_setzero_pd(), _CMP_EQ_OQ);
    int first_lag = lag_hi;
    if (level) {
        scan512_lags(r, k, g, ng, lag_hi, lag_hi, a);
        if (--first_lag < r->lag_lo)
            return;
    }
    slot_lists L;
    for (int q = 0; q < NG; q++)
        L.n[q] = 0;
    const unsigned all = (1u << ng) - 1;
    const int s_lo = k - first_lag, s_hi = k - r->lag_lo, s_near = s_hi - PRUNE_NEAR + 1;
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 0, 0, 0, 0, 0, 0, 0);
    /* the level-0 groups each group of lines needs, (group, its entry,
     * lines) in step order; the groups' entries kept in step (no division
     * per group) */
    group_pairs P;
    /* (the pairs' count in a register: the lists' stores may alias P.n in
     * the compiler's view, which then reloaded it after each) */
    int pn = 0;
    int idx1 = s_lo / TS_CAP_G1 % r->groups[1], idx0 = s_lo / TS_CAP_G0 % r->groups[0];
    const int last1 = s_hi / TS_CAP_G1;
    for (int m1 = s_lo / TS_CAP_G1; m1 <= last1; m1++) {
        const int a1 = m1 * TS_CAP_G1 > s_lo ? m1 * TS_CAP_G1 : s_lo;
        const int b1 =
            m1 * TS_CAP_G1 + TS_CAP_G1 - 1 < s_hi ? m1 * TS_CAP_G1 + TS_CAP_G1 - 1 : s_hi;
        const unsigned need1 =
            b1 >= s_near ? all : groups_needed(r, 1, idx1, g, ng, thr, rhs, neg, idle);
        idx1 = idx1 + 1 == r->groups[1] ? 0 : idx1 + 1;
        /* its level-0 groups f0 .. f0 + count - 1, those from the first
         * with a step from s_near on untested */
        const int f0 = a1 / TS_CAP_G0, count = b1 / TS_CAP_G0 - f0 + 1;
        if (need1) {
            const int nb = s_near - TS_CAP_G0 + 1 - f0 * TS_CAP_G0;
            const int first_near = nb <= 0 ? 0 : (nb + TS_CAP_G0 - 1) / TS_CAP_G0;
            const unsigned near = first_near >= count ? 0 : 0xFFu << first_near;
            const __m512i m0s = _mm512_add_epi32(_mm512_set1_epi32(f0), iota);
            __m512i idxs = _mm512_add_epi32(_mm512_set1_epi32(idx0), iota);
            idxs = _mm512_mask_sub_epi32(
                idxs, _mm512_cmpge_epi32_mask(idxs, _mm512_set1_epi32(r->groups[0])), idxs,
                _mm512_set1_epi32(r->groups[0]));
            for (int q = 0; q < NG; q++) {
                if (q >= ng)
                    break;
                if (!(need1 >> q & 1))
                    continue;
                const __mmask16 need0 =
                    (__mmask16)((level0_needed(r, idx0, count, g, q, thr, rhs, neg, idle) | near) &
                                ((1u << count) - 1));
                _mm512_storeu_si512(P.m0 + pn, _mm512_maskz_compress_epi32(need0, m0s));
                _mm512_storeu_si512(P.idx + pn, _mm512_maskz_compress_epi32(need0, idxs));
                _mm512_storeu_si512(P.q + pn,
                                    _mm512_maskz_compress_epi32(need0, _mm512_set1_epi32(q)));
                pn += __builtin_popcount(need0);
            }
        }
        idx0 = idx0 + count < r->groups[0] ? idx0 + count : idx0 + count - r->groups[0];
        /* The pairs are listed and scanned once, after all the tests, but
         * where the next level-1 group's could overflow them (long windows):
         * then their answers raise the threshold for the newer groups. */
        if (pn > PAIRS_MAX - NG * (TS_CAP_G1 / TS_CAP_G0) && m1 < last1) {
            P.n = pn;
            list_pairs(r, s_lo, s_hi, g, tt, rt, idle, &P, &L);
            pn = 0;
            scan512_lists(r, g, ng, &L, a);
            for (int q = 0; q < ng; q++) {
                thr[q] = raised_threshold(a, q, thr[q]);
                threshold_tests(thr[q], gmin[q], a->d[q], tie[q], &rhs[q], &neg[q], &tt[q],
                                &rt[q]);
            }
        }
    }
    P.n = pn;
    list_pairs(r, s_lo, s_hi, g, tt, rt, idle, &P, &L);
    scan512_lists(r, g, ng, &L, a); /* all, or those since the early scan */
}

/* scan_scalar for up to NG groups from g (those below g1), eight lines
 * per AVX-512 vector: the same operations per line; with r->prune, only
 * the slots that may change the answer. */

TS_AVX512 void ts_cap_scan512(const ts_cap_lanes *r, int k, int g, int g1)
{
    const int lag_hi = k < r->lag_hi ? k : r->lag_hi;
    const int ng = (g1 - g) / 8 < NG ? (g1 - g) / 8 : NG;
    scan512 a;
    for (int q = 0; q < NG; q++) {
        const int o = g + 8 * (q < ng ? q : 0);
        a.d[q] = _mm512_load_pd(r->qd + o);
        a.gc[q] = _mm512_load_pd(r->qc + o);
        a.gn[q] = _mm512_load_pd(r->qn + o);
        a.bnc[q] = a.bnn[q] = _mm512_set1_pd(-INFINITY);
        a.bdc[q] = a.bdn[q] = _mm512_set1_pd(1.0);
        a.bkc[q] = a.bkn[q] = _mm512_set1_epi64(-1);
    }
    if (!r->prune || lag_hi < r->lag_lo)
        scan512_lags(r, k, g, ng, lag_hi, r->lag_lo, &a);
    else
        scan512_pruned(r, k, lag_hi, g, ng, &a);
    for (int q = 0; q < ng; q++) {
        const int o = g + 8 * q;
        _mm512_store_epi64(r->kc + o, a.bkc[q]);
        _mm512_store_pd(r->ddc + o, a.bdc[q]);
        _mm512_store_epi64(r->kn + o, a.bkn[q]);
        _mm512_store_pd(r->ddn + o, a.bdn[q]);
    }
}

#endif
