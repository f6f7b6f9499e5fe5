/* Vectorised passes of a lockstep block's step; see lane_passes.h. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "cellmath/cm_near_field.h"
#include "lane_hull.h"
#include "lane_passes.h"
#include "simd_clones.h"

/* ts_lane_sample with the lines' cells vs elements apart: a constant 1
 * where they are neighbours in memory, so that the loops vectorise. */
static inline __attribute__((always_inline)) void
sample_run(const float *restrict zk, ptrdiff_t vs, float F, int j0, int j1, int jn,
           float *restrict hc, float *restrict hn, float *restrict hs)
{
    for (int j = j0; j <= j1; j++)
        hc[j] = zk[j * vs];
    if (F == 0.0f) {
        for (int j = j0; j <= j1; j++) {
            hn[j] = (float)NAN;
            hs[j] = hc[j];
        }
        return;
    }
    for (int j = j0; j <= jn; j++) {
        hn[j] = zk[(j + 1) * vs];
        hs[j] = hc[j] + F * (hn[j] - hc[j]);
    }
    for (int j = jn + 1; j <= j1; j++)
        hn[j] = hs[j] = (float)NAN;
}

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

/* sample_run with the lines' cells vs apart, sixteen lines at a time with
 * gathers (gcc's clones load the cells one by one), or plain loads where
 * vs = 1 (gcc's copy of the row's cells is a call to memmove); the same
 * float operations. Offsets j vs in 32 bits. */
TS_AVX512 static void sample_avx512(const float *zk, int vs, float F, int j0, int j1,
                                            int jn, float *hc, float *hn, float *hs)
{
    const __m512i step = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512 nan = _mm512_set1_ps((float)NAN), f = _mm512_set1_ps(F);
    for (int j = j0; j <= j1; j += 16) {
        const __mmask16 lanes = ts_first_lanes16(j1 - j + 1);
        const __m512i at = _mm512_mullo_epi32(_mm512_add_epi32(_mm512_set1_epi32(j), step),
                                              _mm512_set1_epi32(vs));
        /* along rows (vs = 1) the cells are contiguous: plain loads */
        const __m512 c = vs == 1 ? _mm512_mask_loadu_ps(nan, lanes, zk + j)
                                 : _mm512_mask_i32gather_ps(nan, lanes, at, zk, 4);
        _mm512_mask_storeu_ps(hc + j, lanes, c);
        if (F == 0.0f) {
            _mm512_mask_storeu_ps(hn + j, lanes, nan);
            _mm512_mask_storeu_ps(hs + j, lanes, c);
            continue;
        }
        /* the lines with a next cell */
        const __mmask16 next = lanes & ts_first_lanes16(jn - j + 1);
        const __m512i at_n = _mm512_add_epi32(at, _mm512_set1_epi32(vs));
        const __m512 n = vs == 1 ? _mm512_mask_loadu_ps(nan, next, zk + j + 1)
                                 : _mm512_mask_i32gather_ps(nan, next, at_n, zk, 4);
        const __m512 h = _mm512_add_ps(c, _mm512_mul_ps(f, _mm512_sub_ps(n, c)));
        _mm512_mask_storeu_ps(hn + j, lanes, n);
        _mm512_mask_storeu_ps(hs + j, lanes, _mm512_mask_blend_ps(next, nan, h));
    }
}
#define HAVE_SAMPLE_AVX512 1

/* For CPUs with AVX2 and no AVX-512 (most desktops and laptops). */
#define AVX2 __attribute__((target("avx2")))

/* The first n floats at p, the rest 0, and the store of a vector's first
 * n: whole vectors where n >= 8, else through a buffer (ints through the
 * same, as bits). (Not masked loads and stores: QEMU's emulation, which
 * the tests run the AVX2 paths on, reads all eight elements, beyond an
 * array's end.) */
AVX2 static inline __m256 load_first8f(const void *p, int n)
{
    if (n >= 8)
        return _mm256_loadu_ps(p);
    float b[8] = {0};
    if (n > 0)
        memcpy(b, p, (size_t)n * sizeof *b);
    return _mm256_loadu_ps(b);
}

AVX2 static inline void store_first8f(void *p, int n, __m256 v)
{
    if (n >= 8) {
        _mm256_storeu_ps(p, v);
        return;
    }
    float b[8];
    _mm256_storeu_ps(b, v);
    memcpy(p, b, (size_t)n * sizeof *b);
}

/* sample_avx512 eight lines at a time: masks as vectors of all-ones lanes,
 * AVX2's gathers (the clones load the cells one by one: ~30 % less time for
 * the samples of an AVX2 sweep). */
AVX2 static void sample_avx2(const float *zk, int vs, float F, int j0, int j1, int jn,
                             float *hc, float *hn, float *hs)
{
    const __m256i step = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256 nan = _mm256_set1_ps((float)NAN), f = _mm256_set1_ps(F);
    for (int j = j0; j <= j1; j += 8) {
        const int n = j1 - j + 1, nn = jn - j + 1; /* lines, those with a next cell */
        const __m256i lanes = _mm256_cmpgt_epi32(_mm256_set1_epi32(n), step);
        const __m256i at = _mm256_mullo_epi32(_mm256_add_epi32(_mm256_set1_epi32(j), step),
                                              _mm256_set1_epi32(vs));
        const __m256 c = vs == 1 ? load_first8f(zk + j, n)
                                 : _mm256_mask_i32gather_ps(nan, zk, at,
                                                            _mm256_castsi256_ps(lanes), 4);
        store_first8f(hc + j, n, c);
        if (F == 0.0f) {
            store_first8f(hn + j, n, nan);
            store_first8f(hs + j, n, c);
            continue;
        }
        /* NaN for the lines without a next cell */
        const __m256 nm = _mm256_castsi256_ps(
            _mm256_and_si256(lanes, _mm256_cmpgt_epi32(_mm256_set1_epi32(nn), step)));
        const __m256 n1 = _mm256_blendv_ps(
            nan,
            vs == 1 ? load_first8f(zk + j + 1, nn)
                    : _mm256_mask_i32gather_ps(nan, zk, _mm256_add_epi32(at, _mm256_set1_epi32(vs)),
                                               nm, 4),
            nm);
        const __m256 h = _mm256_add_ps(c, _mm256_mul_ps(f, _mm256_sub_ps(n1, c)));
        store_first8f(hn + j, n, n1);
        store_first8f(hs + j, n, _mm256_blendv_ps(nan, h, nm));
    }
}
#else
#define HAVE_SAMPLE_AVX512 0
#endif

TS_SIMD_CLONES
static void sample_any(const float *zk, ptrdiff_t vs, float F, int j0, int j1, int jn, float *hc,
                       float *hn, float *hs)
{
    if (vs == 1)
        sample_run(zk, 1, F, j0, j1, jn, hc, hn, hs);
    else
        sample_run(zk, vs, F, j0, j1, jn, hc, hn, hs);
}

void ts_lane_sample(const ts_line_geom *G, const float *z, int k, int i0, int j0, int j1,
                    float *hc, float *hn, float *hs)
{
    const float F = G->fr[k];
    const ptrdiff_t vs = G->v_stride;
    const float *zk = z + G->origin + (ptrdiff_t)k * G->u_stride + (ptrdiff_t)i0 * vs;
    /* Every line has a next cell but one on the grid's last row. */
    int jn = G->V - 2 - i0 < j1 ? G->V - 2 - i0 : j1;
#if HAVE_SAMPLE_AVX512
    if (vs <= INT_MAX / (j1 + 2) && ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512) {
        sample_avx512(zk, (int)vs, F, j0, j1, jn, hc, hn, hs);
        return;
    }
    if (vs <= INT_MAX / (j1 + 2) && ts_cpu_vector_level() == TS_CPU_VECTORS_AVX2) {
        sample_avx2(zk, (int)vs, F, j0, j1, jn, hc, hn, hs);
        return;
    }
#endif
    sample_any(zk, vs, F, j0, j1, jn, hc, hn, hs);
}

#if defined(__GNUC__) && defined(__x86_64__)
TS_AVX512 static void distances_avx512(int k, const int *k0, double step, int j0, int j1,
                                       double *dist)
{
    const __m512d st = _mm512_set1_pd(step);
    const __m256i kv = _mm256_set1_epi32(k);
    for (int j = j0 / 8 * 8; j <= j1; j += 8) {
        const __m256i n = k0 ? _mm256_sub_epi32(kv, _mm256_loadu_si256((const __m256i *)(k0 + j)))
                             : kv;
        _mm512_storeu_pd(dist + j, _mm512_mul_pd(_mm512_cvtepi32_pd(n), st));
    }
}
#endif

void ts_lane_distances(int k, const int *k0, double step, int j0, int j1, double *dist)
{
#if defined(__GNUC__) && defined(__x86_64__)
    if (ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512) {
        distances_avx512(k, k0, step, j0, j1, dist);
        return;
    }
#endif
    for (int j = j0; j <= j1; j++)
        dist[j] = (double)(k0 ? k - k0[j] : k) * step;
}

/* The grid's layout as the direction sees it (passed by pointer: a copy
 * by value, made with wider loads right after its fields' stores, stalled
 * on store forwarding, ~1.4 % of a bounded sweep's samples). */
typedef struct {
    ptrdiff_t origin, u_stride, v_stride;
    int V;
    int near; /* occluders at most this many steps back are left out */
} ray_view;

/* Slope from cell (k, i) at height h to its own ray at the occluder of
 * step kc (< 0: none; else kc < k), dd metres away, as cm_ray_slope_at
 * with the ray's offset and fraction from ray_o and ray_f; -inf where the
 * occluder is none or within the near field, the ray is off the grid or
 * touches nodata. Branch-free, every load from a valid element (masks,
 * not selects, so that gcc gathers), so that the loop over cells
 * vectorises. Element offsets in 32 bits unless `wide` (gathers of 32-bit
 * offsets are the ones gcc vectorises). */
static inline __attribute__((always_inline)) float
ray_at(ray_view R, int wide, const int *restrict ray_o, const float *restrict ray_f,
       const float *restrict z, float cf, int k, int i, float h, int kc, float dd)
{
    const int dk = k - kc;
    int ok = (kc >= 0) & (dk > R.near) & (dd > 0.0f);
    const int dks = dk & -ok;
    const int r0 = i + ray_o[dks];
    const float f = ray_f[dks];
    ok &= (r0 >= 0) & (r0 <= R.V - 1) & ((f <= 0.0f) | (r0 + 1 <= R.V - 1));
    const int two = ok & (f > 0.0f);
    float a, b;
    if (wide) {
        ptrdiff_t ia = (R.origin + (ptrdiff_t)kc * R.u_stride + (ptrdiff_t)r0 * R.v_stride) &
                       -(ptrdiff_t)ok;
        a = z[ia];
        b = z[ia + (R.v_stride & -(ptrdiff_t)two)];
    } else {
        /* unsigned: no overflow where !ok leaves the offset meaningless */
        unsigned ia = ((unsigned)R.origin + (unsigned)kc * (unsigned)R.u_stride +
                       (unsigned)r0 * (unsigned)R.v_stride) & -(unsigned)ok;
        a = z[(int)ia];
        b = z[(int)(ia + ((unsigned)R.v_stride & -(unsigned)two))];
    }
    const float hz = a + f * (b - a);
    const float s = (hz - h) / dd - cf * dd;
    return (ok & (hz == hz)) ? s : -INFINITY;
}

/* ts_lane_far_field's loop, with 32- or 64-bit offsets: every array its
 * own, as restrict parameters of the function that holds the loop (what
 * the vectoriser needs to gather without alias checks). */
#define FAR_LOOP(WIDE)                                                                         \
    for (int j = j0; j <= j1; j++) {                                                           \
        const float h = hc[j];                                                                 \
        const int kl = lo_k[j], kh = hi_k[j] | -(hi_k[j] == kl); /* -1: the same step */      \
        float best = -INFINITY;                                                                \
        const float sl = ray_at(*R, WIDE, ray_o, ray_f, z, cf, k, i0 + j, h, kl, lo_dd[j]);    \
        best = sl > best ? sl : best;                                                          \
        const float sh = ray_at(*R, WIDE, ray_o, ray_f, z, cf, k, i0 + j, h, kh, hi_dd[j]);    \
        best = sh > best ? sh : best;                                                          \
        slope[j] = h != h ? (float)NAN : best;                                                 \
        /* an occluder beyond the near field that the ray cannot be sampled at */             \
        lost[j] = ((sl == -INFINITY) & (kl >= 0) & (k - kl > R->near)) |                       \
                  (((sh == -INFINITY) & (kh >= 0) & (k - kh > R->near)) << 1);                 \
        any |= lost[j];                                                                        \
    }

#define FAR_PARAMS                                                                             \
    const ray_view *R, const int *restrict ray_o, const float *restrict ray_f,                 \
        const float *restrict z, float cf, int k, int i0, int j0, int j1,                      \
        const float *restrict hc, const int *restrict lo_k, const float *restrict lo_dd,       \
        const int *restrict hi_k, const float *restrict hi_dd, float *restrict slope,            \
        int *restrict lost

TS_SIMD_CLONES
static int far_run32(FAR_PARAMS)
{
    int any = 0;
    FAR_LOOP(0)
    return any;
}

TS_SIMD_CLONES
static int far_run64(FAR_PARAMS)
{
    int any = 0;
    FAR_LOOP(1)
    return any;
}

#if defined(__GNUC__) && defined(__x86_64__)
/* ray_at (32-bit offsets) for 16 cells i at once, where lanes: the same
 * float operations, the loads as gathers (gcc's far_run32 emulates them
 * with scalar loads, three instructions an element). */
TS_AVX512 static inline __m512 ray16(const ray_view *R, const int *ray_o, const float *ray_f,
                                  const float *z, __m512 cf, __m512i k, __m512i i, __m512 h,
                                  __m512i kc, __m512 dd, __mmask16 lanes, __mmask16 *lost)
{
    const __m512i zero = _mm512_setzero_si512(), last = _mm512_set1_epi32(R->V - 1);
    const __m512 fzero = _mm512_setzero_ps();
    const __m512i dk = _mm512_sub_epi32(k, kc);
    __mmask16 ok = lanes & _mm512_cmpge_epi32_mask(kc, zero) &
                   _mm512_cmpgt_epi32_mask(dk, _mm512_set1_epi32(R->near)) &
                   _mm512_cmp_ps_mask(dd, fzero, _CMP_GT_OQ);
    const __mmask16 counts = ok; /* an occluder beyond the near field */
    const __m512i dks = _mm512_maskz_mov_epi32(ok, dk); /* 0 where not ok: a valid entry */
    const __m512i r0 = _mm512_add_epi32(i, _mm512_i32gather_epi32(dks, ray_o, 4));
    const __m512 f = _mm512_i32gather_ps(dks, ray_f, 4);
    ok &= _mm512_cmpge_epi32_mask(r0, zero) & _mm512_cmple_epi32_mask(r0, last) &
          (_mm512_cmp_ps_mask(f, fzero, _CMP_LE_OQ) |
           _mm512_cmple_epi32_mask(_mm512_add_epi32(r0, _mm512_set1_epi32(1)), last));
    const __mmask16 two = ok & _mm512_cmp_ps_mask(f, fzero, _CMP_GT_OQ);
    const __m512i vs = _mm512_set1_epi32((int)(unsigned)R->v_stride);
    const __m512i ia = _mm512_add_epi32(
        _mm512_add_epi32(_mm512_set1_epi32((int)(unsigned)R->origin),
                         _mm512_mullo_epi32(kc, _mm512_set1_epi32((int)(unsigned)R->u_stride))),
        _mm512_mullo_epi32(r0, vs));
    const __m512 a = _mm512_mask_i32gather_ps(fzero, ok, ia, z, 4);
    const __m512 b = _mm512_mask_i32gather_ps(a, two, _mm512_add_epi32(ia, vs), z, 4);
    const __m512 hz = _mm512_add_ps(a, _mm512_mul_ps(f, _mm512_sub_ps(b, a)));
    const __m512 s = _mm512_sub_ps(_mm512_div_ps(_mm512_sub_ps(hz, h), dd), _mm512_mul_ps(cf, dd));
    ok &= _mm512_cmp_ps_mask(hz, hz, _CMP_ORD_Q);
    *lost = counts & ~ok; /* where the ray cannot be sampled */
    return _mm512_mask_blend_ps(ok, _mm512_set1_ps(-INFINITY), s);
}

/* far_run32 (FAR_LOOP's cells) sixteen at once, cell j's slope to
 * slope[(j - j0) * ostride] (straight into the output), its lost flags
 * (FAR_LOOP's) where any is set; whether any is. */
TS_AVX512 static int far_run32_avx512(FAR_PARAMS, int ostride)
{
    __mmask16 any = 0;
    const __m512 cfv = _mm512_set1_ps(cf);
    const __m512i kv = _mm512_set1_epi32(k), step = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8,
                                                                     9, 10, 11, 12, 13, 14, 15);
    for (int j = j0; j <= j1; j += 16) {
        const __mmask16 lanes = ts_first_lanes16(j1 - j + 1);
        const __m512 h = _mm512_maskz_loadu_ps(lanes, hc + j);
        const __m512i i = _mm512_add_epi32(_mm512_set1_epi32(i0 + j), step);
        const __m512i kl = _mm512_maskz_loadu_epi32(lanes, lo_k + j);
        const __m512i khi = _mm512_maskz_loadu_epi32(lanes, hi_k + j);
        const __m512i kh = _mm512_mask_mov_epi32(khi, _mm512_cmpeq_epi32_mask(khi, kl),
                                                 _mm512_set1_epi32(-1)); /* the same step */
        __m512 best = _mm512_set1_ps(-INFINITY);
        __mmask16 lost_l, lost_h;
        best = _mm512_max_ps(ray16(R, ray_o, ray_f, z, cfv, kv, i, h, kl,
                                   _mm512_maskz_loadu_ps(lanes, lo_dd + j), lanes, &lost_l),
                             best);
        best = _mm512_max_ps(ray16(R, ray_o, ray_f, z, cfv, kv, i, h, kh,
                                   _mm512_maskz_loadu_ps(lanes, hi_dd + j), lanes, &lost_h),
                             best);
        if (lost_l | lost_h) { /* rare: at the DEM's edges and nodata */
            const __m512i flags = _mm512_or_si512(_mm512_maskz_set1_epi32(lost_l, 1),
                                                  _mm512_maskz_set1_epi32(lost_h, 2));
            _mm512_mask_storeu_epi32(lost + j, lanes, flags);
            any |= lost_l | lost_h;
        }
        const __m512 out = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(h, h, _CMP_UNORD_Q), best,
                                                _mm512_set1_ps((float)NAN));
        if (ostride == 1)
            _mm512_mask_storeu_ps(slope + (j - j0), lanes, out);
        else
            _mm512_mask_i32scatter_ps(
                slope, lanes,
                _mm512_mullo_epi32(_mm512_add_epi32(_mm512_set1_epi32(j - j0), step),
                                   _mm512_set1_epi32(ostride)),
                out, 4);
    }
    return any != 0;
}
#define HAVE_FAR_AVX512 1
#else
#define HAVE_FAR_AVX512 0
#endif

#if defined(__GNUC__) && defined(__x86_64__)
/* far_run32 eight cells at once for CPUs with AVX2 and no AVX-512 (most
 * desktops and laptops), whose far_run32 clone gcc leaves scalar: ray16's
 * float operations in the same order (no FMA: the same bits), masks as
 * vectors of all-ones lanes, the loads as AVX2 gathers. */

/* ray16 for the eight cells of lanes (all-ones lanes). */
AVX2 static inline __attribute__((always_inline)) __m256
ray8(const ray_view *R, const int *ray_o, const float *ray_f, const float *z, __m256 cf,
     __m256i k, __m256i i, __m256 h, __m256i kc, __m256 dd, __m256i lanes, __m256i *lost)
{
    const __m256i none = _mm256_set1_epi32(-1), vm1 = _mm256_set1_epi32(R->V - 1);
    const __m256 fzero = _mm256_setzero_ps();
    const __m256i dk = _mm256_sub_epi32(k, kc);
    __m256i ok = _mm256_and_si256(lanes, _mm256_cmpgt_epi32(kc, none));
    ok = _mm256_and_si256(ok, _mm256_cmpgt_epi32(dk, _mm256_set1_epi32(R->near)));
    ok = _mm256_and_si256(ok, _mm256_castps_si256(_mm256_cmp_ps(dd, fzero, _CMP_GT_OQ)));
    const __m256i counts = ok; /* an occluder beyond the near field */
    const __m256i dks = _mm256_and_si256(ok, dk); /* 0 where not ok: a valid entry */
    const __m256i r0 = _mm256_add_epi32(i, _mm256_i32gather_epi32(ray_o, dks, 4));
    const __m256 f = _mm256_i32gather_ps(ray_f, dks, 4);
    /* 0 <= r0 <= V - 1, and r0 + 1 <= V - 1 where f > 0 */
    const __m256i in = _mm256_andnot_si256(_mm256_cmpgt_epi32(r0, vm1),
                                           _mm256_cmpgt_epi32(r0, none));
    const __m256i fle = _mm256_castps_si256(_mm256_cmp_ps(f, fzero, _CMP_LE_OQ));
    ok = _mm256_and_si256(_mm256_and_si256(ok, in),
                          _mm256_or_si256(fle, _mm256_cmpgt_epi32(vm1, r0)));
    const __m256i two =
        _mm256_and_si256(ok, _mm256_castps_si256(_mm256_cmp_ps(f, fzero, _CMP_GT_OQ)));
    const __m256i vs = _mm256_set1_epi32((int)(unsigned)R->v_stride);
    const __m256i ia = _mm256_add_epi32(
        _mm256_add_epi32(_mm256_set1_epi32((int)(unsigned)R->origin),
                         _mm256_mullo_epi32(kc, _mm256_set1_epi32((int)(unsigned)R->u_stride))),
        _mm256_mullo_epi32(r0, vs));
    const __m256 a = _mm256_mask_i32gather_ps(fzero, z, ia, _mm256_castsi256_ps(ok), 4);
    const __m256 b =
        _mm256_mask_i32gather_ps(a, z, _mm256_add_epi32(ia, vs), _mm256_castsi256_ps(two), 4);
    const __m256 hz = _mm256_add_ps(a, _mm256_mul_ps(f, _mm256_sub_ps(b, a)));
    const __m256 s = _mm256_sub_ps(_mm256_div_ps(_mm256_sub_ps(hz, h), dd), _mm256_mul_ps(cf, dd));
    ok = _mm256_and_si256(ok, _mm256_castps_si256(_mm256_cmp_ps(hz, hz, _CMP_ORD_Q)));
    *lost = _mm256_andnot_si256(ok, counts); /* where the ray cannot be sampled */
    return _mm256_blendv_ps(_mm256_set1_ps(-INFINITY), s, _mm256_castsi256_ps(ok));
}

/* far_run32_avx512 in eight-cell vectors: cell j's slope to
 * out[j - j0] (ostride 1) or to slope[j] (the caller copies it out), its
 * lost flags where any is set; whether any is. */
AVX2 static int far_run32_avx2(FAR_PARAMS, float *restrict out)
{
    int any = 0;
    const __m256 cfv = _mm256_set1_ps(cf);
    const __m256i kv = _mm256_set1_epi32(k), step = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for (int j = j0; j <= j1; j += 8) {
        const int n = j1 - j + 1;
        const __m256i lanes = _mm256_cmpgt_epi32(_mm256_set1_epi32(n), step);
        const __m256 h = load_first8f(hc + j, n);
        const __m256i i = _mm256_add_epi32(_mm256_set1_epi32(i0 + j), step);
        const __m256i kl = _mm256_castps_si256(load_first8f(lo_k + j, n));
        const __m256i khi = _mm256_castps_si256(load_first8f(hi_k + j, n));
        const __m256i kh = _mm256_or_si256(khi, _mm256_cmpeq_epi32(khi, kl)); /* the same step */
        __m256 best = _mm256_set1_ps(-INFINITY);
        __m256i lost_l, lost_h;
        best = _mm256_max_ps(ray8(R, ray_o, ray_f, z, cfv, kv, i, h, kl,
                                  load_first8f(lo_dd + j, n), lanes, &lost_l),
                             best);
        best = _mm256_max_ps(ray8(R, ray_o, ray_f, z, cfv, kv, i, h, kh,
                                  load_first8f(hi_dd + j, n), lanes, &lost_h),
                             best);
        if (!_mm256_testz_si256(_mm256_or_si256(lost_l, lost_h), lanes)) {
            /* rare: at the DEM's edges and nodata */
            const __m256i flags = _mm256_or_si256(_mm256_and_si256(lost_l, _mm256_set1_epi32(1)),
                                                  _mm256_and_si256(lost_h, _mm256_set1_epi32(2)));
            store_first8f(lost + j, n, _mm256_castsi256_ps(flags));
            any = 1;
        }
        const __m256 nan = _mm256_cmp_ps(h, h, _CMP_UNORD_Q);
        const __m256 o = _mm256_blendv_ps(best, _mm256_set1_ps((float)NAN), nan);
        store_first8f(out ? out + (j - j0) : slope + j, n, o);
    }
    return any;
}
#define HAVE_FAR_AVX2 1
#else
#define HAVE_FAR_AVX2 0
#endif

/* Cells j0..j1 whose lost flags are set (FAR_LOOP's), clearing them: each
 * flagged occluder's slope by cm_ray_lost raises the cell's far field at
 * out[(j - j0) * ostride], from the ray's steps beyond the near field's
 * `near`, or, in the far-only sweep, beyond lost->from metres (its
 * threshold: without them, a cell whose ray left the DEM before the lines'
 * occluders lost that terrain, up to 8 deg near the DEM's edges). */
static void far_lost(const ts_line_geom *G, int near, int k, int i0, int j0, int j1,
                     const float *hc, const ts_lane_occluders *occ, const ts_lane_lost *lost,
                     float *out, ptrdiff_t ostride)
{
    for (int j = j0; j <= j1; j++) {
        const int f = lost->flags[j];
        lost->flags[j] = 0; /* the AVX-512 pass writes only vectors with a flag */
        if (!f || hc[j] != hc[j])
            continue;
        const int i = i0 + j;
        const double step = ts_line_cell_step(G, k, i);
        /* far-only: the steps from the first at least lost->from away, s0,
         * and no part of a step before it */
        const int s0 = lost->from > 0 ? (int)ceil(lost->from / step) : near + 1;
        const int piece_from = lost->from > 0 ? s0 : near;
        float *o = out + (j - j0) * ostride;
        for (int e = 0; e < 2; e++) {
            if (!(f >> e & 1))
                continue;
            const int kc = e ? occ->hi_k[j] : occ->lo_k[j];
            const float s = cm_ray_lost_from(lost->ray, k, i, hc[j], k - kc, s0 - 1, piece_from,
                                             lost->cap / step, step, lost->c);
            *o = s > *o ? s : *o;
        }
    }
}

void ts_lane_far_field(const ts_line_geom *G, const float *z, float cf, int near, int k, int i0,
                       int j0, int j1, const float *hc, const ts_lane_occluders *occ,
                       const ts_lane_lost *lost, float *slope, float *out, ptrdiff_t ostride)
{
    const ray_view R = {G->origin, G->u_stride, G->v_stride, G->V, near};
    /* Every element the ray reads lies within U x V cells of the grid. */
    const ptrdiff_t span = (ptrdiff_t)(G->U - 1) * (G->u_stride < 0 ? -G->u_stride : G->u_stride) +
                           (ptrdiff_t)(G->V - 1) * G->v_stride + 1;
    int any;
#if HAVE_FAR_AVX512
    const ptrdiff_t omax = INT_MAX / (j1 + 16); /* the scatter's offsets in 32 bits */
    if (span <= INT_MAX && ostride <= omax && ostride >= -omax &&
        ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512) {
        any = far_run32_avx512(&R, G->ray_o, G->ray_f, z, cf, k, i0, j0, j1, hc, occ->lo_k,
                               occ->lo_dd, occ->hi_k, occ->hi_dd, out, lost->flags,
                               (int)ostride);
        if (any)
            far_lost(G, near, k, i0, j0, j1, hc, occ, lost, out, ostride);
        return;
    }
#endif
    int direct = 0; /* the slopes written straight into out */
#if HAVE_FAR_AVX2
    if (span <= INT_MAX && ts_cpu_vector_level() == TS_CPU_VECTORS_AVX2) {
        direct = ostride == 1;
        any = far_run32_avx2(&R, G->ray_o, G->ray_f, z, cf, k, i0, j0, j1, hc, occ->lo_k,
                             occ->lo_dd, occ->hi_k, occ->hi_dd, slope, lost->flags,
                             direct ? out : NULL);
    } else
#endif
        any = (span > INT_MAX ? far_run64 : far_run32)(&R, G->ray_o, G->ray_f, z, cf, k, i0,
                                                       j0, j1, hc, occ->lo_k, occ->lo_dd,
                                                       occ->hi_k, occ->hi_dd, slope, lost->flags);
    if (!direct)
        for (int j = j0; j <= j1; j++)
            out[(j - j0) * ostride] = slope[j];
    if (any)
        far_lost(G, near, k, i0, j0, j1, hc, occ, lost, out, ostride);
}
