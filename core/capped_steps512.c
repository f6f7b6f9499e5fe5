/* The AVX-512 work of a lockstep block of capped lines (capped_lanes.h)
 * around the window scan (capped_lanes512.c): the step's queries, its
 * answers and samples, and the hybrid's hull answers; see
 * capped_lanes512.h. */
#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#include <math.h>

#include "capped_lanes512.h"
#include "simd_clones.h"

/* Step k's samples (d, g; lanes has) of lines j.. j + 7 into their groups
 * of both levels (entries at[l]). */
TS_AVX512 static inline __attribute__((always_inline)) void
groups_add(ts_cap_lanes *r, const size_t at[2], int j, __m512d d, __m512d g, __mmask8 has)
{
    for (int l = 0; l < 2; l++) {
        double *gm = r->gmax[l] + at[l] + j, *lo = r->dlo[l] + at[l] + j,
               *hi = r->dhi[l] + at[l] + j;
        const __m512d m = _mm512_load_pd(gm);
        /* lines' distances grow: a group's first sample is its oldest */
        const __mmask8 first =
            _mm512_mask_cmp_pd_mask(has, m, _mm512_set1_pd(-INFINITY), _CMP_EQ_OQ);
        _mm512_store_pd(lo, _mm512_mask_mov_pd(_mm512_load_pd(lo), first, d));
        _mm512_store_pd(hi, _mm512_mask_mov_pd(_mm512_load_pd(hi), has, d));
        _mm512_store_pd(gm, _mm512_mask_max_pd(m, has, m, g));
    }
}

/* ts_cap_lanes_step's work before and after the scan, eight lines per
 * vector (the same operations per line): the queries of lines [g0, g1),
 * then the answers and the step's samples of lines j0..j1. */
TS_AVX512 void ts_cap_queries512(ts_cap_lanes *r, const ts_lane_step *s, int g0, int g1)
{
    const __m512d c = _mm512_set1_pd(s->c), nan = _mm512_set1_pd(NAN);
    for (int j = g0; j < g1; j += 8) {
        const __m512i idx =
            _mm512_add_epi64(_mm512_set1_epi64(j), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7));
        __mmask8 on = _mm512_cmpge_epi64_mask(idx, _mm512_set1_epi64(s->j0));
        on = _mm512_mask_cmple_epi64_mask(on, idx, _mm512_set1_epi64(s->j1));
        __mmask8 hi = _mm512_mask_cmpge_epi64_mask(on, idx, _mm512_set1_epi64(s->hi_from));
        hi = _mm512_mask_cmple_epi64_mask(hi, idx, _mm512_set1_epi64(s->hi_to));
        const __m512d d = _mm512_maskz_loadu_pd(on, s->d + j);
        const __m512d cdd = _mm512_mul_pd(_mm512_mul_pd(c, d), d);
        const __m512d hc = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(hi, s->hc + j));
        const __m512d hn = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(on, s->hn + j));
        _mm512_store_pd(r->qd + j, d);
        _mm512_store_pd(r->qc + j, _mm512_mask_sub_pd(nan, hi, hc, cdd));
        _mm512_store_pd(r->qn + j, _mm512_mask_sub_pd(nan, on, hn, cdd));
    }
}

TS_AVX512 void ts_cap_answers512(ts_cap_lanes *r, const ts_lane_step *s, int g0, int g1,
                                 const ts_lane_occluders *occ, double *rd, double *rg)
{
    const __m512d c = _mm512_set1_pd(s->c), nan = _mm512_set1_pd(NAN);
    /* the pruned scan's groups of the step's samples, each emptied at its
     * first step */
    size_t at[2];
    for (int l = 0; l < 2 && r->prune; l++) {
        const int size = l ? TS_CAP_G1 : TS_CAP_G0;
        at[l] = (size_t)(s->k / size % r->groups[l]) * r->stride;
        if (s->k % size == 0)
            ts_cap_groups_empty(r->gmax[l] + at[l], r->dlo[l] + at[l], r->dhi[l] + at[l],
                                (size_t)r->stride);
    }
    for (int j = g0; j < g1; j += 8) {
        const __m512i idx =
            _mm512_add_epi64(_mm512_set1_epi64(j), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7));
        __mmask8 on = _mm512_cmpge_epi64_mask(idx, _mm512_set1_epi64(s->j0));
        on = _mm512_mask_cmple_epi64_mask(on, idx, _mm512_set1_epi64(s->j1));
        _mm512_mask_cvtepi64_storeu_epi32(occ->hi_k + j, on, _mm512_load_epi64(r->kc + j));
        _mm512_mask_cvtepi64_storeu_epi32(occ->lo_k + j + 1, on, _mm512_load_epi64(r->kn + j));
        /* (256-bit stores: see lane_hull.c's store8i) */
        _mm256_mask_storeu_ps(occ->hi_dd + j, on, _mm512_cvtpd_ps(_mm512_load_pd(r->ddc + j)));
        _mm256_mask_storeu_ps(occ->lo_dd + j + 1, on, _mm512_cvtpd_ps(_mm512_load_pd(r->ddn + j)));
        /* the step's own samples enter the ring after its queries */
        const __m512d d = _mm512_maskz_loadu_pd(on, s->d + j);
        const __m512d hs = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(on, s->hs + j));
        const __mmask8 has = _mm512_cmp_pd_mask(hs, hs, _CMP_ORD_Q);
        const __m512d g = _mm512_sub_pd(hs, _mm512_mul_pd(_mm512_mul_pd(c, d), d));
        _mm512_mask_store_pd(rd + j, on, _mm512_mask_mov_pd(nan, has, d));
        _mm512_mask_store_pd(rg + j, on, g);
        if (r->prune)
            groups_add(r, at, j, d, g, has & on);
    }
}

/* The hull's answers (occ, from ts_lane_hull_step) to the queries of lines
 * [g0, g1) into r->kc, ddc, kn, ddn, where they lie in the window as the
 * scan tests it (lag <= lag_hi, d - d_p <= cap); lines without a query get
 * none (-1, 1.0), those the hull cannot answer keep their last answers.
 * need[(g - g0) / 8]: whether a query of group g is left to the scan. */
TS_AVX512 void ts_cap_hull_answers512(ts_cap_lanes *r, int k, int g0, int g1,
                                      const ts_lane_occluders *occ, unsigned char *need)
{
    const __m512d cap = _mm512_set1_pd(r->cap);
    const __m512i zero = _mm512_setzero_si512(), none = _mm512_set1_epi64(-1);
    for (int j = g0; j < g1; j += 8) {
        const __m512d d = _mm512_load_pd(r->qd + j);
        __mmask8 left = 0;
        for (int q = 0; q < 2; q++) {
            const int *kq = q ? occ->lo_k + j + 1 : occ->hi_k + j;
            const float *fq = q ? occ->lo_dd + j + 1 : occ->hi_dd + j;
            long long *ko = q ? r->kn : r->kc;
            double *ddo = q ? r->ddn : r->ddc;
            const __m512d gq = _mm512_load_pd((q ? r->qn : r->qc) + j);
            const __mmask8 has = _mm512_cmp_pd_mask(gq, gq, _CMP_ORD_Q);
            const __m512i kk = _mm512_cvtepi32_epi64(_mm256_maskz_loadu_epi32(has, kq));
            const __m512i lag = _mm512_sub_epi64(_mm512_set1_epi64(k), kk);
            __mmask8 ok = _mm512_mask_cmpge_epi64_mask(has, kk, zero);
            ok = _mm512_mask_cmple_epi64_mask(ok, lag, _mm512_set1_epi64(r->lag_hi));
            /* A hull point lies at least the near field's distance back; up
             * to sure_hi lags it is surely within the cap too, and its
             * distance is the hull's (the same double, rounded to float
             * there and again by ts_cap_answers512). Beyond, the ring's
             * distance is tested as the scan tests it. */
            __m512d dd = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(ok, fq));
            const __mmask8 unsure =
                _mm512_mask_cmpgt_epi64_mask(ok, lag, _mm512_set1_epi64(r->sure_hi));
            if (unsure) {
                const __m256i at = ts_cap_ring_at512(r, k, lag, j);
                const __m512d dp =
                    _mm512_mask_i32gather_pd(_mm512_set1_pd(NAN), unsure, at, r->d, 8);
                dd = _mm512_mask_sub_pd(dd, unsure, d, dp);
                ok &= ~unsure | _mm512_mask_cmp_pd_mask(unsure, dd, cap, _CMP_LE_OQ);
            }
            const __m512i kb = _mm512_mask_mov_epi64(none, has, _mm512_load_epi64(ko + j));
            const __m512d db =
                _mm512_mask_mov_pd(_mm512_set1_pd(1.0), has, _mm512_load_pd(ddo + j));
            _mm512_store_epi64(ko + j, _mm512_mask_mov_epi64(kb, ok, kk));
            _mm512_store_pd(ddo + j, _mm512_mask_mov_pd(db, ok, dd));
            left |= has & ~ok;
        }
        need[(j - g0) / 8] = left != 0;
    }
}

#endif
