/* Brute-force window queries of a lockstep block of capped lines; see
 * capped_lanes.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capped_lanes.h"
#include "capped_lanes512.h"

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

/* Windows of at least PRUNE_FROM lags take the pruned scan (with AVX-512),
 * up to lags of PRUNE_TO; beyond, the scan alone costs more than the
 * line-by-line window hull, and the hybrid (capped_hybrid.c) less. */
#ifndef PRUNE_TO
#define PRUNE_TO 256
#endif
/* The prune's margin (capped_lanes512.c) holds for windows of up to this
 * many lags. */
#define PRUNE_MAX_LAGS 100000
#ifndef PRUNE_FROM
#define PRUNE_FROM 64
#endif

int ts_cap_lanes_alloc(ts_cap_lanes *r, int lines, const int lags[4], double near, double cap)
{
    *r = (ts_cap_lanes){0};
    r->stride = (lines + 7) / 8 * 8;
    r->lag_lo = lags[0];
    r->lag_hi = lags[1];
    r->sure_lo = lags[2];
    r->sure_hi = lags[3];
    /* a multiple of TS_CAP_G0, so that a level-0 group's slots lie together;
     * more than lag_hi, so that a group is reset only once out of the window */
    r->groups[0] = (r->lag_hi + TS_CAP_G0 - 1) / TS_CAP_G0 + 1;
    r->groups[1] = (r->lag_hi + TS_CAP_G1 - 1) / TS_CAP_G1 + 1;
    r->slots = r->groups[0] * TS_CAP_G0;
    r->near = near;
    r->cap = cap;
    r->prune = ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512 &&
               r->lag_hi - r->lag_lo + 1 >= PRUNE_FROM && r->lag_hi <= PRUNE_MAX_LAGS;
    /* (and a spare slot, never written: the pruned scan's padding) */
    const size_t ring = (size_t)(r->slots + 1) * r->stride * sizeof(double);
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
    int ok = r->d && r->g && r->qd && r->qc && r->qn && r->ddc && r->ddn && r->kc && r->kn &&
             ts_lane_pushes_alloc(&r->push, r->stride);
    for (int l = 0; l < 2 && r->prune; l++) {
        const size_t n = (size_t)r->groups[l] * line;
        r->gmax[l] = zalloc(n);
        r->dlo[l] = zalloc(n);
        r->dhi[l] = zalloc(n);
        ok = ok && r->gmax[l] && r->dlo[l] && r->dhi[l];
    }
    return ok;
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
    ts_lane_pushes_free(&r->push);
    for (int l = 0; l < 2; l++) {
        free(r->gmax[l]);
        free(r->dlo[l]);
        free(r->dhi[l]);
    }
    *r = (ts_cap_lanes){0};
}

void ts_cap_lanes_clear(ts_cap_lanes *r)
{
    const size_t n = (size_t)(r->slots + 1) * r->stride;
    for (size_t i = 0; i < n; i++)
        r->d[i] = NAN;
    for (int j = 0; j < r->stride; j++)
        r->kc[j] = r->kn[j] = -1; /* no previous answers */
    r->hull_lost = 0;
    ts_lane_pushes_reset(&r->push, r->stride);
    for (int l = 0; l < 2 && r->prune; l++)
        ts_cap_groups_empty(r->gmax[l], r->dlo[l], r->dhi[l], (size_t)r->groups[l] * r->stride);
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

#define AVX2 __attribute__((target("avx2")))

/* ts_cap_scan512 for the eight lines from g, four per AVX2 vector (the
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
    /* measured (docs/performance-history.md, "Bounded sweep", sessions 9 and 10):
     * the brute force costs about the line-by-line window at ~96 steps
     * with AVX-512, ~40 with AVX2; pruned, from PRUNE_FROM steps on, at
     * ~200-300 (AVX-512 only) */
    const int span = lags[1] - lags[0] + 1;
    const int level = ts_cpu_vector_level();
    return level == TS_CPU_VECTORS_AVX512
               ? span <= 96 || (span >= PRUNE_FROM && lags[1] <= PRUNE_TO)
           : level == TS_CPU_VECTORS_AVX2 ? span <= 40
                                          : 0;
}

int ts_cap_lanes_hybrid_pays(const int lags[4])
{
    /* measured (docs/performance-history.md, "Bounded sweep: unbounded hull first"):
     * 0.80-0.89x the line-by-line window's CPU time at 300-2000 lags. The
     * ring's pruned scan holds for windows of up to PRUNE_MAX_LAGS. */
    return ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512 &&
           lags[1] - lags[0] + 1 >= PRUNE_FROM && lags[1] <= PRUNE_MAX_LAGS;
}

static void scan_groups(const ts_cap_lanes *r, int k, int g0, int g1)
{
    const int level = ts_cpu_vector_level();
    if (level == TS_CPU_VECTORS_AVX512)
        for (int g = g0; g < g1; g += 8 * TS_CAP_NG)
            ts_cap_scan512(r, k, g, g1);
    else if (level == TS_CPU_VECTORS_AVX2)
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

int ts_cap_lanes_hybrid_pays(const int lags[4])
{
    (void)lags;
    return 0;
}

static void scan_groups(const ts_cap_lanes *r, int k, int g0, int g1)
{
    scan_scalar(r, k, g0, g1);
}
#endif

void ts_cap_ring_slot(ts_cap_lanes *r, int k, int nl, int j0, int j1, double **rd, double **rg)
{
    const size_t at = (size_t)(k % r->slots) * r->stride;
    *rd = r->d + at;
    *rg = r->g + at;
    const int lo = j0 < nl ? j0 : nl, hi = j1 + 1 > 0 ? j1 + 1 : 0;
    for (int j = 0; j < lo; j++)
        (*rd)[j] = NAN;
    for (int j = hi > lo ? hi : lo; j < nl; j++)
        (*rd)[j] = NAN;
}

void ts_cap_lanes_step(ts_cap_lanes *r, const ts_lane_step *s, int nl,
                       const ts_lane_occluders *occ)
{
    const int k = s->k, j0 = s->j0, j1 = s->j1;
    const double c = s->c;
    double *rd, *rg;
    ts_cap_ring_slot(r, k, nl, j0, j1, &rd, &rg); /* (j0..j1 written below) */
    r->hull_lost = 1; /* (a step a hybrid's hulls did not take) */
    if (j0 <= j1) {
        const int g0 = j0 / 8 * 8, g1 = (j1 + 8) / 8 * 8;
#if defined(__GNUC__) && defined(__x86_64__)
        if (ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512) {
            ts_cap_queries512(r, s, g0, g1);
            scan_groups(r, k, g0, g1);
            ts_cap_answers512(r, s, g0, g1, occ, rd, rg);
            return;
        }
#endif
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
            /* the step's own sample enters the ring after its queries (it
             * is no occluder of its own step: lag 0 < lag_lo) */
            const double hs = s->hs[j], d = s->d[j];
            rd[j] = isnan(hs) ? NAN : d;
            rg[j] = hs - c * d * d;
        }
    }
}
