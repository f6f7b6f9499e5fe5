/*
 * The AVX-512 part of the capped lines' lockstep blocks (capped_lanes.h),
 * called only where ts_cpu_vector_level() is 2. Each gives the bits of the
 * scalar code in capped_lanes.c.
 */
#ifndef TS_CAPPED_LANES512_H
#define TS_CAPPED_LANES512_H

#include <math.h>
#include <stddef.h>

#include "capped_lanes.h"

/* Groups of eight lines that one scan takes together. */
#ifndef TS_CAP_NG
#define TS_CAP_NG 3
#endif

/* The window scan of lines [g, g + 8 * TS_CAP_NG), those below g1, at
 * step k: answers into r->kc, ddc, kn, ddn; only the groups of slots that
 * may change an answer where r->prune. */
void ts_cap_scan512(const ts_cap_lanes *r, int k, int g, int g1);

/* The queries of lines [g0, g1) of step s (r->qd, qc, qn), and after the
 * scan the answers of its lines j0..j1 into occ and their samples into the
 * ring's slots rd, rg and (where r->prune) their groups of both levels,
 * each emptied at its first step. */
void ts_cap_queries512(ts_cap_lanes *r, const ts_lane_step *s, int g0, int g1);
void ts_cap_answers512(ts_cap_lanes *r, const ts_lane_step *s, int g0, int g1,
                       const ts_lane_occluders *occ, double *rd, double *rg);

/* The hull's answers of the hybrid (capped_hybrid.c) where they lie in the
 * window, for lines [g0, g1); need[(g - g0) / 8]: whether group g has a
 * query left to the scan. */
void ts_cap_hull_answers512(ts_cap_lanes *r, int k, int g0, int g1,
                            const ts_lane_occluders *occ, unsigned char *need);

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

#include "simd_clones.h"

/* The ring offsets (slot * stride + line) of the samples `lag` steps
 * before step k of lines j..j + 7, for a gather: the slot is
 * (k mod slots - lag) mod slots, lag in 0..slots - 1. */
TS_AVX512 static inline __attribute__((always_inline)) __m256i
ts_cap_ring_at512(const ts_cap_lanes *r, int k, __m512i lag, int j)
{
    __m512i slot = _mm512_sub_epi64(_mm512_set1_epi64(k % r->slots), lag);
    slot = _mm512_mask_add_epi64(slot, _mm512_cmplt_epi64_mask(slot, _mm512_setzero_si512()),
                                 slot, _mm512_set1_epi64(r->slots));
    const __m256i lane =
        _mm256_add_epi32(_mm256_set1_epi32(j), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    return _mm256_add_epi32(
        _mm256_mullo_epi32(_mm512_cvtepi64_epi32(slot), _mm256_set1_epi32(r->stride)), lane);
}
#endif

/* Empty n groups' entries (no samples: -inf, 0, 0). */
static inline void ts_cap_groups_empty(double *gmax, double *dlo, double *dhi, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        gmax[i] = -INFINITY;
        dlo[i] = dhi[i] = 0.0;
    }
}

#endif
