/* Brute-force window queries of a lockstep block of capped lines; see
 * capped_lanes.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capped_lanes.h"

void ts_cap_lanes_lags(double near, double cap, double shortest, double longest, int *lag_lo,
                       int *lag_hi)
{
    /* A lag of L steps spans between L * shortest and L * longest metres
     * (up to rounding far below these margins). */
    double lo = ceil(near / longest * (1.0 - 1e-9));
    double hi = floor(cap / shortest * (1.0 + 1e-9));
    *lag_lo = lo < 1.0 ? 1 : (int)lo;
    *lag_hi = hi < (double)*lag_lo ? *lag_lo : hi > 1e8 ? 100000000 : (int)hi;
}

static void *zalloc(size_t n)
{
    void *p = aligned_alloc(64, (n + 63) / 64 * 64);
    if (p)
        memset(p, 0, n);
    return p;
}

int ts_cap_lanes_alloc(ts_cap_lanes *r, int lines, int lag_lo, int lag_hi, double near,
                       double cap, double shortest, int chunked)
{
    *r = (ts_cap_lanes){0};
    r->stride = (lines + 7) / 8 * 8;
    r->slots = lag_hi + 1;
    r->lag_lo = lag_lo;
    r->lag_hi = lag_hi;
    r->near = near;
    r->cap = cap;
    r->shortest = shortest;
    r->chunked = chunked;
    r->nch = chunked ? r->slots / TS_CAP_CHUNK + 2 : 0;
    const size_t ring = (size_t)r->slots * r->stride * sizeof(double);
    const size_t line = (size_t)r->stride * sizeof(double);
    r->d = zalloc(ring);
    r->g = zalloc(ring);
    r->qd = zalloc(line);
    r->qc = zalloc(line);
    r->qn = zalloc(line);
    r->ddc = zalloc(line);
    r->ddn = zalloc(line);
    r->kc = zalloc(line);
    r->kn = zalloc(line);
    int ok = r->d && r->g && r->qd && r->qc && r->qn && r->ddc && r->ddn && r->kc && r->kn;
    if (chunked) {
        r->cmax = zalloc((size_t)r->nch * line);
        r->bnc = zalloc(line);
        r->bnn = zalloc(line);
        r->pkc = zalloc(line);
        r->pkn = zalloc(line);
        ok = ok && r->cmax && r->bnc && r->bnn && r->pkc && r->pkn;
    }
    return ok;
}

void ts_cap_lanes_free(ts_cap_lanes *r)
{
    double *dp[] = {r->d, r->g, r->qd, r->qc, r->qn, r->ddc, r->ddn, r->cmax, r->bnc, r->bnn};
    long long *kp[] = {r->kc, r->kn, r->pkc, r->pkn};
    for (size_t i = 0; i < sizeof dp / sizeof *dp; i++)
        free(dp[i]);
    for (size_t i = 0; i < sizeof kp / sizeof *kp; i++)
        free(kp[i]);
    *r = (ts_cap_lanes){0};
}

void ts_cap_lanes_clear(ts_cap_lanes *r)
{
    const size_t n = (size_t)r->slots * r->stride;
    for (size_t i = 0; i < n; i++) {
        r->d[i] = NAN;
        r->g[i] = -INFINITY;
    }
    for (size_t i = 0; i < (size_t)r->nch * r->stride; i++)
        r->cmax[i] = -INFINITY;
    for (int j = 0; r->chunked && j < r->stride; j++)
        r->pkc[j] = r->pkn[j] = -1;
}

/* Lines [g0, g1) (multiples of 8) at step k: for each query height (NaN:
 * none), the window sample of largest slope (g_p - g) / (d - d_p), the
 * oldest on ties; compared by cross-multiplication (both denominators are
 * positive), from the best so far in (kc, ddc, bnc) and (kn, ddn, bnn)
 * where chunked. Scalar: for CPUs without AVX-512 (and valgrind); the same
 * answers as the vector scans, which skip only what cannot win. */
static void scan_scalar(const ts_cap_lanes *r, int k, int g0, int g1)
{
    const int lag_hi = k < r->lag_hi ? k : r->lag_hi; /* no samples before step 0 */
    for (int j = g0; j < g1; j++) {
        const double d = r->qd[j], gq[2] = {r->qc[j], r->qn[j]};
        double bn[2] = {-INFINITY, -INFINITY}, bd[2] = {1.0, 1.0};
        long long bk[2] = {-1, -1};
        if (r->chunked) {
            bn[0] = r->bnc[j], bd[0] = r->ddc[j], bk[0] = r->kc[j];
            bn[1] = r->bnn[j], bd[1] = r->ddn[j], bk[1] = r->kn[j];
        }
        for (int lag = lag_hi; lag >= r->lag_lo; lag--) {
            const size_t at = (size_t)((k - lag) % r->slots) * r->stride + j;
            const double dd = d - r->d[at];
            if (!(dd >= r->near && dd <= r->cap))
                continue;
            for (int q = 0; q < 2; q++) {
                const double n = r->g[at] - gq[q], lhs = n * bd[q], rhs = bn[q] * dd;
                if (lhs > rhs || (lhs == rhs && k - lag < bk[q])) {
                    bn[q] = n;
                    bd[q] = dd;
                    bk[q] = k - lag;
                }
            }
        }
        r->kc[j] = bk[0];
        r->ddc[j] = bd[0];
        r->kn[j] = bk[1];
        r->ddn[j] = bd[1];
    }
}

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

#define AVX512 __attribute__((target("avx512f")))
/* groups of eight lines scanned together: independent chains of compares
 * and selects, so that their latencies overlap */
#define NG 4

/* scan_scalar for up to NG groups from g (those below g1), eight lines
 * per AVX-512 vector: the same operations per line. */
AVX512 static void scan_avx512(const ts_cap_lanes *r, int k, int g, int g1)
{
    const int lag_hi = k < r->lag_hi ? k : r->lag_hi;
    const int ng = (g1 - g) / 8 < NG ? (g1 - g) / 8 : NG;
    const __m512d near = _mm512_set1_pd(r->near), cap = _mm512_set1_pd(r->cap);
    __m512d d[NG], gc[NG], gn[NG], bnc[NG], bdc[NG], bnn[NG], bdn[NG];
    __m512i bkc[NG], bkn[NG];
    for (int q = 0; q < NG; q++) {
        const int o = g + 8 * (q < ng ? q : 0);
        d[q] = _mm512_load_pd(r->qd + o);
        gc[q] = _mm512_load_pd(r->qc + o);
        gn[q] = _mm512_load_pd(r->qn + o);
        bnc[q] = bnn[q] = _mm512_set1_pd(-INFINITY);
        bdc[q] = bdn[q] = _mm512_set1_pd(1.0);
        bkc[q] = bkn[q] = _mm512_set1_epi64(-1);
    }
    int slot = (k - lag_hi) % r->slots;
    for (int lag = lag_hi; lag >= r->lag_lo; lag--) {
        const __m512i ks = _mm512_set1_epi64(k - lag);
        const double *pd = r->d + (size_t)slot * r->stride + g;
        const double *pg = r->g + (size_t)slot * r->stride + g;
        slot = slot + 1 == r->slots ? 0 : slot + 1;
        for (int q = 0; q < NG; q++) {
            if (q >= ng)
                break;
            const __m512d dd = _mm512_sub_pd(d[q], _mm512_load_pd(pd + 8 * q));
            __mmask8 in = _mm512_cmp_pd_mask(dd, near, _CMP_GE_OQ);
            in = _mm512_mask_cmp_pd_mask(in, dd, cap, _CMP_LE_OQ);
            const __m512d sg = _mm512_load_pd(pg + 8 * q);
            const __m512d nc = _mm512_sub_pd(sg, gc[q]), nn = _mm512_sub_pd(sg, gn[q]);
            const __mmask8 wc = _mm512_mask_cmp_pd_mask(in, _mm512_mul_pd(nc, bdc[q]),
                                                        _mm512_mul_pd(bnc[q], dd), _CMP_GT_OQ);
            const __mmask8 wn = _mm512_mask_cmp_pd_mask(in, _mm512_mul_pd(nn, bdn[q]),
                                                        _mm512_mul_pd(bnn[q], dd), _CMP_GT_OQ);
            bnc[q] = _mm512_mask_mov_pd(bnc[q], wc, nc);
            bdc[q] = _mm512_mask_mov_pd(bdc[q], wc, dd);
            bkc[q] = _mm512_mask_mov_epi64(bkc[q], wc, ks);
            bnn[q] = _mm512_mask_mov_pd(bnn[q], wn, nn);
            bdn[q] = _mm512_mask_mov_pd(bdn[q], wn, dd);
            bkn[q] = _mm512_mask_mov_epi64(bkn[q], wn, ks);
        }
    }
    for (int q = 0; q < ng; q++) {
        const int o = g + 8 * q;
        _mm512_store_epi64(r->kc + o, bkc[q]);
        _mm512_store_pd(r->ddc + o, bdc[q]);
        _mm512_store_epi64(r->kn + o, bkn[q]);
        _mm512_store_pd(r->ddn + o, bdn[q]);
    }
}

/* One step of a window scan for a group of eight lines (scan_scalar's
 * loop body): sample slot `slot`, step ks, against the best (n, d, k) of
 * both queries. */
#define SCAN_STEP(slot, ks)                                                                    \
    do {                                                                                       \
        const __m512i kv = _mm512_set1_epi64(ks);                                              \
        const double *pd = r->d + (size_t)(slot) * r->stride + g;                              \
        const __m512d dd = _mm512_sub_pd(d, _mm512_load_pd(pd));                               \
        __mmask8 in = _mm512_cmp_pd_mask(dd, near, _CMP_GE_OQ);                                \
        in = _mm512_mask_cmp_pd_mask(in, dd, cap, _CMP_LE_OQ);                                 \
        const __m512d sg = _mm512_load_pd(r->g + (size_t)(slot) * r->stride + g);              \
        const __m512d nc = _mm512_sub_pd(sg, gc), nn = _mm512_sub_pd(sg, gn);                  \
        const __m512d lc = _mm512_mul_pd(nc, bdc), rc = _mm512_mul_pd(bnc, dd);                \
        const __m512d ln = _mm512_mul_pd(nn, bdn), rn = _mm512_mul_pd(bnn, dd);                \
        const __mmask8 wc = _mm512_mask_cmp_pd_mask(in, lc, rc, _CMP_GT_OQ) |                  \
                            (_mm512_mask_cmp_pd_mask(in, lc, rc, _CMP_EQ_OQ) &                 \
                             _mm512_cmplt_epi64_mask(kv, bkc));                                \
        const __mmask8 wn = _mm512_mask_cmp_pd_mask(in, ln, rn, _CMP_GT_OQ) |                  \
                            (_mm512_mask_cmp_pd_mask(in, ln, rn, _CMP_EQ_OQ) &                 \
                             _mm512_cmplt_epi64_mask(kv, bkn));                                \
        bnc = _mm512_mask_mov_pd(bnc, wc, nc);                                                 \
        bdc = _mm512_mask_mov_pd(bdc, wc, dd);                                                 \
        bkc = _mm512_mask_mov_epi64(bkc, wc, kv);                                              \
        bnn = _mm512_mask_mov_pd(bnn, wn, nn);                                                 \
        bdn = _mm512_mask_mov_pd(bdn, wn, dd);                                                 \
        bkn = _mm512_mask_mov_epi64(bkn, wn, kv);                                              \
    } while (0)

/* Whether any line of the group may find in a chunk whose highest g is
 * gmax (margin added) a sample at least as steep as its best: the slope is
 * at most (gmax - g) / ddlo where positive (ddlo: the chunk's least
 * distance), (gmax - g) / cap otherwise. */
AVX512 static inline __mmask8 chunk_may(__m512d gmax, __m512d gq, __m512d bn, __m512d bd,
                                        __m512d ddlo, __m512d cap)
{
    const __m512d num = _mm512_sub_pd(gmax, gq);
    const __mmask8 pos = _mm512_cmp_pd_mask(num, _mm512_setzero_pd(), _CMP_GE_OQ);
    const __m512d den = _mm512_mask_mov_pd(cap, pos, ddlo);
    return _mm512_cmp_pd_mask(_mm512_mul_pd(num, bd), _mm512_mul_pd(bn, den), _CMP_GE_OQ);
}

/* scan_scalar for the eight lines from g of a chunked window: chunk by
 * chunk, oldest first, each complete chunk skipped where chunk_may says
 * no line can gain from it. */
AVX512 static void scan_chunks_avx512(const ts_cap_lanes *r, int k, int g)
{
    const int lag_hi = k < r->lag_hi ? k : r->lag_hi, C = TS_CAP_CHUNK;
    const __m512d near = _mm512_set1_pd(r->near), cap = _mm512_set1_pd(r->cap);
    const __m512d d = _mm512_load_pd(r->qd + g);
    const __m512d gc = _mm512_load_pd(r->qc + g), gn = _mm512_load_pd(r->qn + g);
    __m512d bnc = _mm512_load_pd(r->bnc + g), bdc = _mm512_load_pd(r->ddc + g);
    __m512d bnn = _mm512_load_pd(r->bnn + g), bdn = _mm512_load_pd(r->ddn + g);
    __m512i bkc = _mm512_load_epi64(r->kc + g), bkn = _mm512_load_epi64(r->kn + g);
    const int s_lo = k - lag_hi, s_hi = k - r->lag_lo; /* the window's steps */
    for (int c = s_lo / C; c <= s_hi / C; c++) {
        const int a = c * C > s_lo ? c * C : s_lo, b = c * C + C - 1 < s_hi ? c * C + C - 1 : s_hi;
        if (c * C + C - 1 < k) { /* complete: its maximum is known */
            const double lo = (k - b) * r->shortest * (1.0 - 1e-9);
            const __m512d ddlo = _mm512_set1_pd(lo > r->near ? lo : r->near);
            __m512d gmax = _mm512_load_pd(r->cmax + (size_t)(c % r->nch) * r->stride + g);
            /* far above the rounding of the products compared */
            gmax = _mm512_add_pd(gmax, _mm512_add_pd(_mm512_set1_pd(1e-6),
                                                      _mm512_mul_pd(_mm512_abs_pd(gmax),
                                                                    _mm512_set1_pd(1e-9))));
            if (!(chunk_may(gmax, gc, bnc, bdc, ddlo, cap) | chunk_may(gmax, gn, bnn, bdn, ddlo, cap)))
                continue;
        }
        for (int st = a; st <= b; st++)
            SCAN_STEP(st % r->slots, st);
    }
    _mm512_store_epi64(r->kc + g, bkc);
    _mm512_store_pd(r->ddc + g, bdc);
    _mm512_store_epi64(r->kn + g, bkn);
    _mm512_store_pd(r->ddn + g, bdn);
}

static void scan_groups(const ts_cap_lanes *r, int k, int g0, int g1)
{
    if (!ts_lane_have_avx512()) {
        scan_scalar(r, k, g0, g1);
        return;
    }
    if (r->chunked)
        for (int g = g0; g < g1; g += 8)
            scan_chunks_avx512(r, k, g);
    else
        for (int g = g0; g < g1; g += 8 * NG)
            scan_avx512(r, k, g, g1);
}
#else
static void scan_groups(const ts_cap_lanes *r, int k, int g0, int g1)
{
    scan_scalar(r, k, g0, g1);
}
#endif

/* The chunked scan's start: each query's best so far is the line's
 * previous answer (the same query kind at the step before) where that
 * sample is still in the window. */
static void start_from_previous(ts_cap_lanes *r, int k, int g0, int g1)
{
    const double *q[2] = {r->qc, r->qn};
    long long *pk[2] = {r->pkc, r->pkn}, *bk[2] = {r->kc, r->kn};
    double *bn[2] = {r->bnc, r->bnn}, *bd[2] = {r->ddc, r->ddn};
    for (int i = 0; i < 2; i++)
        for (int j = g0; j < g1; j++) {
            const long long p = pk[i][j];
            bn[i][j] = -INFINITY;
            bd[i][j] = 1.0;
            bk[i][j] = -1;
            if (p < 0 || k - p > r->lag_hi || k - p < r->lag_lo || isnan(q[i][j]))
                continue;
            const size_t at = (size_t)(p % r->slots) * r->stride + j;
            const double dd = r->qd[j] - r->d[at];
            if (dd >= r->near && dd <= r->cap) {
                bn[i][j] = r->g[at] - q[i][j];
                bd[i][j] = dd;
                bk[i][j] = p;
            }
        }
}

/* Chunk k / TS_CAP_CHUNK is complete at step k: keep each line's highest
 * g in it. */
static void close_chunk(ts_cap_lanes *r, int k)
{
    const int C = TS_CAP_CHUNK, c = k / C;
    double *restrict m = r->cmax + (size_t)(c % r->nch) * r->stride;
    for (int j = 0; j < r->stride; j++)
        m[j] = -INFINITY;
    for (int st = c * C; st <= k; st++) {
        const double *restrict g = r->g + (size_t)(st % r->slots) * r->stride;
        for (int j = 0; j < r->stride; j++)
            m[j] = g[j] > m[j] ? g[j] : m[j];
    }
}

void ts_cap_lanes_step(ts_cap_lanes *r, const ts_lane_step *s, int nl,
                       const ts_lane_occluders *occ)
{
    const int k = s->k, j0 = s->j0, j1 = s->j1;
    const double c = s->c;
    double *rd = r->d + (size_t)(k % r->slots) * r->stride;
    double *rg = r->g + (size_t)(k % r->slots) * r->stride;
    for (int j = 0; j < nl; j++) {
        rd[j] = NAN;
        rg[j] = -INFINITY;
    }
    if (j0 <= j1) {
        const int g0 = j0 / 8 * 8, g1 = (j1 + 8) / 8 * 8;
        for (int j = g0; j < g1; j++) {
            const int on = j >= j0 && j <= j1;
            const double d = on ? s->d[j] : 0.0;
            const double cdd = c * d * d;
            const int hi = on && j >= s->hi_from && j <= s->hi_to;
            r->qd[j] = d;
            /* as hull_query and ts_lane_hull_step: g = h - c d^2 */
            r->qc[j] = hi ? (double)s->hc[j] - cdd : NAN;
            r->qn[j] = on ? (double)s->hn[j] - cdd : NAN;
        }
        if (r->chunked)
            start_from_previous(r, k, g0, g1);
        scan_groups(r, k, g0, g1);
        for (int j = j0; j <= j1; j++) {
            occ->hi_k[j] = (int)r->kc[j];
            occ->hi_dd[j] = (float)r->ddc[j];
            occ->lo_k[j + 1] = (int)r->kn[j];
            occ->lo_dd[j + 1] = (float)r->ddn[j];
            if (r->chunked) {
                r->pkc[j] = r->kc[j];
                r->pkn[j] = r->kn[j];
            }
            /* the step's own sample enters the ring after its queries (it
             * is no occluder of its own step: lag 0 < lag_lo) */
            const double hs = s->hs[j], d = s->d[j];
            if (!isnan(hs)) {
                rd[j] = d;
                rg[j] = hs - c * d * d;
            }
        }
    }
    if (r->chunked && (k + 1) % TS_CAP_CHUNK == 0)
        close_chunk(r, k);
}
