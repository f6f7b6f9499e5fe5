/* Brute-force window queries of a lockstep block of capped lines; see
 * capped_lanes.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capped_lanes.h"

void ts_cap_lanes_lags(double near, double cap, double shortest, double longest, int lags[4])
{
    /* A lag of L steps spans between L * shortest and L * longest metres
     * (up to rounding far below these margins). */
    const double lo = ceil(near / longest * (1.0 - 1e-9));
    const double hi = floor(cap / shortest * (1.0 + 1e-9));
    lags[0] = lo < 1.0 ? 1 : (int)lo;
    lags[1] = hi < (double)lags[0] ? lags[0] : hi > 1e8 ? 100000000 : (int)hi;
    /* the lags surely within: at least near, at most cap metres */
    const double sure_lo = ceil(near / (shortest * (1.0 - 1e-9)));
    const double sure_hi = floor(cap / (longest * (1.0 + 1e-9)));
    lags[2] = sure_lo > 1e8 ? 100000000 : (int)sure_lo;
    lags[3] = sure_hi > 1e8 ? 100000000 : (int)sure_hi;
}

static void *zalloc(size_t n)
{
    void *p = aligned_alloc(64, (n + 63) / 64 * 64);
    if (p)
        memset(p, 0, n);
    return p;
}

int ts_cap_lanes_alloc(ts_cap_lanes *r, int lines, const int lags[4], double near, double cap)
{
    *r = (ts_cap_lanes){0};
    r->stride = (lines + 7) / 8 * 8;
    r->lag_lo = lags[0];
    r->lag_hi = lags[1];
    r->sure_lo = lags[2];
    r->sure_hi = lags[3];
    r->slots = r->lag_hi + 1;
    r->near = near;
    r->cap = cap;
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
    return r->d && r->g && r->qd && r->qc && r->qn && r->ddc && r->ddn && r->kc && r->kn;
}

void ts_cap_lanes_free(ts_cap_lanes *r)
{
    free(r->d);
    free(r->g);
    free(r->qd);
    free(r->qc);
    free(r->qn);
    free(r->ddc);
    free(r->ddn);
    free(r->kc);
    free(r->kn);
    *r = (ts_cap_lanes){0};
}

void ts_cap_lanes_clear(ts_cap_lanes *r)
{
    const size_t n = (size_t)r->slots * r->stride;
    for (size_t i = 0; i < n; i++)
        r->d[i] = NAN;
}

/* Lines [g0, g1) (multiples of 8) at step k: for each query height (NaN:
 * none), the window sample of largest slope (g_p - g) / (d - d_p), the
 * oldest on ties; compared by cross-multiplication (both denominators are
 * positive). Scalar: for CPUs without AVX2. */
static void scan_scalar(const ts_cap_lanes *r, int k, int g0, int g1)
{
    const int lag_hi = k < r->lag_hi ? k : r->lag_hi; /* no samples before step 0 */
    for (int j = g0; j < g1; j++) {
        const double d = r->qd[j], gq[2] = {r->qc[j], r->qn[j]};
        double bn[2] = {-INFINITY, -INFINITY}, bd[2] = {1.0, 1.0};
        long long bk[2] = {-1, -1};
        for (int lag = lag_hi; lag >= r->lag_lo; lag--) {
            const size_t at = (size_t)((k - lag) % r->slots) * r->stride + j;
            const double dd = d - r->d[at];
            if (!(dd >= r->near && dd <= r->cap))
                continue;
            for (int q = 0; q < 2; q++) {
                const double n = r->g[at] - gq[q];
                if (n * bd[q] > bn[q] * dd) {
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
#define NG 3

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
        /* within the sure lags, the distance needs no test (a slot without
         * a sample has d NaN, which fails the slope's compare) */
        const int sure = lag >= r->sure_lo && lag <= r->sure_hi;
        for (int q = 0; q < NG; q++) {
            if (q >= ng)
                break;
            const __m512d dd = _mm512_sub_pd(d[q], _mm512_load_pd(pd + 8 * q));
            __mmask8 in = 0xFF;
            if (!sure) {
                in = _mm512_cmp_pd_mask(dd, near, _CMP_GE_OQ);
                in = _mm512_mask_cmp_pd_mask(in, dd, cap, _CMP_LE_OQ);
            }
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

#define AVX2 __attribute__((target("avx2")))

/* scan_avx512 for the eight lines from g, four per AVX2 vector (the
 * compares give lane masks as vectors, the selects are blends): the same
 * operations per line. */
AVX2 static void scan_avx2(const ts_cap_lanes *r, int k, int g)
{
    const int lag_hi = k < r->lag_hi ? k : r->lag_hi;
    const __m256d near = _mm256_set1_pd(r->near), cap = _mm256_set1_pd(r->cap);
    __m256d d[2], gc[2], gn[2], bnc[2], bdc[2], bnn[2], bdn[2], bkc[2], bkn[2];
    for (int q = 0; q < 2; q++) {
        d[q] = _mm256_load_pd(r->qd + g + 4 * q);
        gc[q] = _mm256_load_pd(r->qc + g + 4 * q);
        gn[q] = _mm256_load_pd(r->qn + g + 4 * q);
        bnc[q] = bnn[q] = _mm256_set1_pd(-INFINITY);
        bdc[q] = bdn[q] = _mm256_set1_pd(1.0);
        /* the steps, as 64-bit integers carried in double vectors */
        bkc[q] = bkn[q] = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    }
    int slot = (k - lag_hi) % r->slots;
    for (int lag = lag_hi; lag >= r->lag_lo; lag--) {
        const __m256d ks = _mm256_castsi256_pd(_mm256_set1_epi64x(k - lag));
        const double *pd = r->d + (size_t)slot * r->stride + g;
        const double *pg = r->g + (size_t)slot * r->stride + g;
        slot = slot + 1 == r->slots ? 0 : slot + 1;
        const int sure = lag >= r->sure_lo && lag <= r->sure_hi;
        for (int q = 0; q < 2; q++) {
            const __m256d dd = _mm256_sub_pd(d[q], _mm256_load_pd(pd + 4 * q));
            __m256d in = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
            if (!sure)
                in = _mm256_and_pd(_mm256_cmp_pd(dd, near, _CMP_GE_OQ),
                                   _mm256_cmp_pd(dd, cap, _CMP_LE_OQ));
            const __m256d sg = _mm256_load_pd(pg + 4 * q);
            const __m256d nc = _mm256_sub_pd(sg, gc[q]), nn = _mm256_sub_pd(sg, gn[q]);
            const __m256d wc = _mm256_and_pd(in, _mm256_cmp_pd(_mm256_mul_pd(nc, bdc[q]),
                                                               _mm256_mul_pd(bnc[q], dd),
                                                               _CMP_GT_OQ));
            const __m256d wn = _mm256_and_pd(in, _mm256_cmp_pd(_mm256_mul_pd(nn, bdn[q]),
                                                               _mm256_mul_pd(bnn[q], dd),
                                                               _CMP_GT_OQ));
            bnc[q] = _mm256_blendv_pd(bnc[q], nc, wc);
            bdc[q] = _mm256_blendv_pd(bdc[q], dd, wc);
            bkc[q] = _mm256_blendv_pd(bkc[q], ks, wc);
            bnn[q] = _mm256_blendv_pd(bnn[q], nn, wn);
            bdn[q] = _mm256_blendv_pd(bdn[q], dd, wn);
            bkn[q] = _mm256_blendv_pd(bkn[q], ks, wn);
        }
    }
    for (int q = 0; q < 2; q++) {
        const int o = g + 4 * q;
        _mm256_store_si256((__m256i *)(r->kc + o), _mm256_castpd_si256(bkc[q]));
        _mm256_store_pd(r->ddc + o, bdc[q]);
        _mm256_store_si256((__m256i *)(r->kn + o), _mm256_castpd_si256(bkn[q]));
        _mm256_store_pd(r->ddn + o, bdn[q]);
    }
}

int ts_cap_lanes_pays(const int lags[4])
{
    /* measured (docs/performance.md, "Bounded sweep, session 9"): the
     * brute force costs about the line-by-line window at ~96 steps with
     * AVX-512, ~40 with AVX2 */
    const int span = lags[1] - lags[0] + 1;
    const int level = ts_lane_vector_level();
    return level == 2 ? span <= 96 : level == 1 ? span <= 40 : 0;
}

static void scan_groups(const ts_cap_lanes *r, int k, int g0, int g1)
{
    const int level = ts_lane_vector_level();
    if (level == 2)
        for (int g = g0; g < g1; g += 8 * NG)
            scan_avx512(r, k, g, g1);
    else if (level == 1)
        for (int g = g0; g < g1; g += 8)
            scan_avx2(r, k, g);
    else
        scan_scalar(r, k, g0, g1);
}
#else
int ts_cap_lanes_pays(const int lags[4])
{
    (void)lags;
    return 0;
}

static void scan_groups(const ts_cap_lanes *r, int k, int g0, int g1)
{
    scan_scalar(r, k, g0, g1);
}
#endif

void ts_cap_lanes_step(ts_cap_lanes *r, const ts_lane_step *s, int nl,
                       const ts_lane_occluders *occ)
{
    const int k = s->k, j0 = s->j0, j1 = s->j1;
    const double c = s->c;
    double *rd = r->d + (size_t)(k % r->slots) * r->stride;
    double *rg = r->g + (size_t)(k % r->slots) * r->stride;
    for (int j = 0; j < nl; j++)
        rd[j] = NAN;
    if (j0 > j1)
        return;
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
    scan_groups(r, k, g0, g1);
    for (int j = j0; j <= j1; j++) {
        occ->hi_k[j] = (int)r->kc[j];
        occ->hi_dd[j] = (float)r->ddc[j];
        occ->lo_k[j + 1] = (int)r->kn[j];
        occ->lo_dd[j + 1] = (float)r->ddn[j];
        /* the step's own sample enters the ring after its queries (it is
         * no occluder of its own step: lag 0 < lag_lo) */
        const double hs = s->hs[j], d = s->d[j];
        rd[j] = isnan(hs) ? NAN : d;
        rg[j] = hs - c * d * d;
    }
}
