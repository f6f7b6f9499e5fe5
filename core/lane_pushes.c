/* The delayed pushes of a lockstep block's hulls (lane_hull.h): each line's
 * oldest waiting sample, once the line is far enough past it; eight lines
 * per AVX-512 vector where the CPU has it, the same doubles and compares
 * per line as the scalar loop, so the same pushes. */
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "lane_hull.h"
#include "simd_clones.h"

int ts_lane_pushes_alloc(ts_lane_pushes *p, int lines)
{
    const size_t n = (size_t)lines + 8;
    p->next = malloc(n * sizeof *p->next);
    p->slot = malloc(n * sizeof *p->slot);
    p->ks = malloc(n * sizeof *p->ks);
    p->pd = malloc(n * sizeof *p->pd);
    p->pg = malloc(n * sizeof *p->pg);
    if (!p->next || !p->slot || !p->ks || !p->pd || !p->pg)
        return 0;
    for (size_t i = 0; i < n; i++) {
        p->next[i] = -1;
        p->slot[i] = 0;
        p->ks[i] = 0;
        p->pd[i] = NAN;
        p->pg[i] = 0.0;
    }
    return 1;
}

void ts_lane_pushes_free(ts_lane_pushes *p)
{
    free(p->next);
    free(p->slot);
    free(p->ks);
    free(p->pd);
    free(p->pg);
    *p = (ts_lane_pushes){0};
}

void ts_lane_pushes_reset(ts_lane_pushes *p, int lines)
{
    for (int j = 0; j < lines; j++)
        p->next[j] = -1;
}

/* Line j's oldest waiting sample from step *q on (at ring slot *slot),
 * skipping steps without one, before step k: moves *q and *slot to it, or
 * to k where there is none. */
static inline void oldest_waiting(const double *d_ring, size_t slot_stride, int slots, int j,
                                  int k, int *q, int *slot)
{
    while (*q < k && isnan(d_ring[(size_t)*slot * slot_stride + j])) {
        ++*q;
        *slot = *slot + 1 == slots ? 0 : *slot + 1;
    }
}

/* Where s's pushes are (every point of the hull is beyond the near field). */
static void pushes_set(const ts_lane_pushes *p, ts_lane_step *s)
{
    s->push_d = p->pd;
    s->push_g = p->pg;
    s->push_ks = p->ks;
    s->near_skip = 0.0;
}

int ts_lane_delayed_pushes_scalar(ts_lane_pushes *p, const double *d_ring, const double *g_ring,
                                  size_t slot_stride, int slots, double behind, ts_lane_step *s)
{
    const int k = s->k;
    int more = 0;
    for (int j = s->j0; j <= s->j1; j++) {
        const double d = s->d[j];
        int q = p->next[j], slot = p->slot[j];
        if (q < 0) /* a line first met now has no sample before: its slots are empty */
            q = k, slot = k % slots;
        oldest_waiting(d_ring, slot_stride, slots, j, k, &q, &slot);
        size_t at = (size_t)slot * slot_stride + j;
        p->pd[j] = NAN;
        if (q < k && d - d_ring[at] >= behind) {
            p->pd[j] = d_ring[at];
            p->pg[j] = g_ring[at];
            p->ks[j] = q;
            ++q;
            slot = slot + 1 == slots ? 0 : slot + 1;
            oldest_waiting(d_ring, slot_stride, slots, j, k, &q, &slot);
            more |= q < k && d - d_ring[(size_t)slot * slot_stride + j] >= behind;
        }
        p->next[j] = q;
        p->slot[j] = slot;
    }
    pushes_set(p, s);
    return more;
}

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

/* The ring as the vector pushes read it (its distances d), and the block's
 * lines j..j + 7. */
typedef struct {
    const double *d;
    size_t stride;
    __m256i stride8, lane; /* the stride in every lane; the lines */
    int j, slots;
} ring8;

/* The doubles of ring (R->d, or the heights beside it) at the lanes' slots where m, else src:
 * one load where those lanes share a slot (a line keeps its neighbours'
 * pace), else a gather. */
TS_AVX512 static inline __m512d ring_read(const ring8 *R, const double *ring, __m256i slot,
                                         __mmask8 m, __m512d src)
{
    const __m256i first = _mm256_set1_epi32(m ? __builtin_ctz(m) : 0);
    const int s0 = _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(slot, first));
    if (_mm256_mask_cmpeq_epi32_mask(m, slot, _mm256_set1_epi32(s0)) == m)
        return _mm512_mask_loadu_pd(src, m, ring + (size_t)s0 * R->stride + R->j);
    const __m256i at = _mm256_add_epi32(_mm256_mullo_epi32(slot, R->stride8), R->lane);
    return _mm512_mask_i32gather_pd(src, m, at, ring, 8);
}

/* The lanes of m move one step on (q, and slot in the ring). */
TS_AVX512 static inline void step_on(const ring8 *R, __mmask8 m, __m256i *q, __m256i *slot)
{
    const __m256i one = _mm256_set1_epi32(1);
    *q = _mm256_mask_add_epi32(*q, m, *q, one);
    *slot = _mm256_mask_add_epi32(*slot, m, *slot, one);
    *slot = _mm256_mask_mov_epi32(
        *slot, _mm256_mask_cmpeq_epi32_mask(m, *slot, _mm256_set1_epi32(R->slots)),
        _mm256_setzero_si256());
}

/* oldest_waiting for the lanes of wait, whose distance at their slot is
 * *dr: each moves past the slots without a sample, before step k, and *dr
 * is the distance at its new slot where that is before k. */
TS_AVX512 static inline void oldest_waiting8(const ring8 *R, int k, __mmask8 wait, __m256i *q,
                                            __m256i *slot, __m512d *dr)
{
    __mmask8 skip = _mm512_mask_cmp_pd_mask(wait, *dr, *dr, _CMP_UNORD_Q);
    while (skip) {
        step_on(R, skip, q, slot);
        const __mmask8 on = _mm256_mask_cmplt_epi32_mask(skip, *q, _mm256_set1_epi32(k));
        *dr = ring_read(R, R->d, *slot, on, *dr);
        skip = _mm512_mask_cmp_pd_mask(on, *dr, *dr, _CMP_UNORD_Q);
    }
}

/* ts_lane_delayed_pushes_scalar, eight lines a vector. */
TS_AVX512 static int delayed_pushes512(ts_lane_pushes *p, const double *d_ring,
                                      const double *g_ring, size_t slot_stride, int slots,
                                      double behind, const ts_lane_step *s)
{
    const int k = s->k;
    const __m256i kv = _mm256_set1_epi32(k);
    const __m512d nan = _mm512_set1_pd(NAN), far = _mm512_set1_pd(behind);
    ring8 R = {d_ring, slot_stride, _mm256_set1_epi32((int)slot_stride),
               _mm256_setzero_si256(), 0, slots};
    __mmask8 more = 0;
    for (int j = s->j0; j <= s->j1; j += 8) {
        const __mmask8 on = (__mmask8)ts_first_lanes16(s->j1 - j + 1);
        R.j = j;
        R.lane = _mm256_add_epi32(_mm256_set1_epi32(j), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        __m256i q = _mm256_maskz_loadu_epi32(on, p->next + j);
        __m256i slot = _mm256_maskz_loadu_epi32(on, p->slot + j);
        /* a line first met now has no sample before: its slots are empty */
        const __mmask8 fresh = _mm256_mask_cmplt_epi32_mask(on, q, _mm256_setzero_si256());
        q = _mm256_mask_mov_epi32(q, fresh, kv);
        slot = _mm256_mask_mov_epi32(slot, fresh, _mm256_set1_epi32(k % slots));
        const __m512d d = _mm512_maskz_loadu_pd(on, s->d + j);
        __mmask8 wait = _mm256_mask_cmplt_epi32_mask(on, q, kv);
        __m512d dr = ring_read(&R, d_ring, slot, wait, nan);
        oldest_waiting8(&R, k, wait, &q, &slot, &dr);
        wait = _mm256_mask_cmplt_epi32_mask(on, q, kv);
        const __mmask8 ready =
            _mm512_mask_cmp_pd_mask(wait, _mm512_sub_pd(d, dr), far, _CMP_GE_OQ);
        _mm512_mask_storeu_pd(p->pd + j, on, _mm512_mask_mov_pd(nan, ready, dr));
        _mm512_mask_storeu_pd(p->pg + j, ready, ring_read(&R, g_ring, slot, ready, nan));
        _mm256_mask_storeu_epi32(p->ks + j, ready, q);
        /* the next one, where this one was pushed */
        step_on(&R, ready, &q, &slot);
        wait = _mm256_mask_cmplt_epi32_mask(ready, q, kv);
        dr = ring_read(&R, d_ring, slot, wait, nan);
        oldest_waiting8(&R, k, wait, &q, &slot, &dr);
        wait = _mm256_mask_cmplt_epi32_mask(ready, q, kv);
        more |= _mm512_mask_cmp_pd_mask(wait, _mm512_sub_pd(d, dr), far, _CMP_GE_OQ);
        _mm256_mask_storeu_epi32(p->next + j, on, q);
        _mm256_mask_storeu_epi32(p->slot + j, on, slot);
    }
    return more != 0;
}
#endif

int ts_lane_delayed_pushes(ts_lane_pushes *p, const double *d_ring, const double *g_ring,
                           size_t slot_stride, int slots, double behind, ts_lane_step *s)
{
#if defined(__GNUC__) && defined(__x86_64__)
    /* 32-bit ring offsets */
    if (ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512 &&
        (long long)slots * (long long)slot_stride + s->j1 + 8 <= INT_MAX) {
        const int more = delayed_pushes512(p, d_ring, g_ring, slot_stride, slots, behind, s);
        pushes_set(p, s);
        return more;
    }
#endif
    return ts_lane_delayed_pushes_scalar(p, d_ring, g_ring, slot_stride, slots, behind, s);
}

