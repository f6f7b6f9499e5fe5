/* A lockstep block's hull step, four lines per AVX2 vector: lane_hull.c's
 * AVX-512 step for CPUs without AVX-512 (most desktops and laptops), and
 * for hulls past that step's 32-bit offsets, with the same double
 * operations per line in the same order, so the same bits as the scalar
 * hull_push, far_advance and stack_query. AVX2 has no mask registers and
 * no scatters, and its gathers are slow on many of those CPUs: masks are
 * vectors of all-ones lanes, the lines' point indices are 64-bit (so that
 * a mask of doubles is also one of indices, and a pop is an add of its
 * mask), points are loaded and pushes stored lane by lane. */
#include <stddef.h>

#include "lane_hull.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

_Static_assert(sizeof(ts_hull_pt) == 3 * sizeof(double) && offsetof(ts_hull_pt, d) == 0 &&
                   offsetof(ts_hull_pt, g) == sizeof(double) &&
                   offsetof(ts_hull_pt, k) == 2 * sizeof(double),
               "ts_hull_pt is laid out as fields() and the steps' gather read it");

#define AVX2 __attribute__((target("avx2")))
#define ALWAYS AVX2 static inline __attribute__((always_inline))
/* vectors of four lines a step takes at once, and at most twice as many
 * walks (two queries per line) */
#define NG 4
#define QMAX (2 * NG)

typedef struct {
    __m256d d;     /* the lines' distances */
    __m256i first; /* index of each line's first point, 64-bit */
    const double *pd;
    const int *pk;
} group;

ALWAYS __m256d as_pd(__m256i m)
{
    return _mm256_castsi256_pd(m);
}

ALWAYS __m256i as_si(__m256d m)
{
    return _mm256_castpd_si256(m);
}

/* The low halves of four 64-bit lanes: a mask of doubles as one of ints
 * or floats, or small indices as ints. */
ALWAYS __m128i narrow(__m256i x)
{
    return _mm256_castsi256_si128(
        _mm256_permutevar8x32_epi32(x, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
}

ALWAYS __m256i times3(__m256i x)
{
    return _mm256_add_epi64(_mm256_slli_epi64(x, 1), x);
}

/* Both fields of point p of each line, where m (elsewhere the first
 * line's first point): four 16-byte loads and a transpose, which take
 * no longer here than two gathers and do not depend on the CPU's gathers
 * (microcoded on AMD before Zen 4, slowed by Intel's GDS mitigation). */
ALWAYS void fields(const group *G, __m256d m, __m256i p, __m256d *d, __m256d *g)
{
    const __m256i i = _mm256_and_si256(times3(_mm256_add_epi64(G->first, p)), as_si(m));
    const __m128i i01 = _mm256_castsi256_si128(i), i23 = _mm256_extracti128_si256(i, 1);
    const double *pd = G->pd;
    const __m128d a0 = _mm_loadu_pd(pd + _mm_cvtsi128_si64(i01));
    const __m128d a1 = _mm_loadu_pd(pd + _mm_extract_epi64(i01, 1));
    const __m128d a2 = _mm_loadu_pd(pd + _mm_cvtsi128_si64(i23));
    const __m128d a3 = _mm_loadu_pd(pd + _mm_extract_epi64(i23, 1));
    const __m256d lo = _mm256_insertf128_pd(_mm256_castpd128_pd256(a0), a2, 1);
    const __m256d hi = _mm256_insertf128_pd(_mm256_castpd128_pd256(a1), a3, 1);
    *d = _mm256_unpacklo_pd(lo, hi);
    *g = _mm256_unpackhi_pd(lo, hi);
}

ALWAYS __m256d ordered(__m256d lanes, __m256d x)
{
    return _mm256_and_pd(lanes, _mm256_cmp_pd(x, x, _CMP_ORD_Q));
}

ALWAYS __m256d gt64(__m256d lanes, __m256i a, __m256i b)
{
    return _mm256_and_pd(lanes, as_pd(_mm256_cmpgt_epi64(a, b)));
}

ALWAYS int any_of(int Q, const __m256d *active)
{
    int any = 0;
    for (int q = 0; q < Q; q++)
        any |= _mm256_movemask_pd(active[q]);
    return any;
}

/* lane_hull.c's walk_down: j[q] moves down while point j - 1 hides point
 * j as seen from the lines' samples, and stays at 0 at most; a pop adds
 * its all-ones mask (-1) to j. */
ALWAYS void walk_down(int Q, const group *const *G, const __m256d *g, __m256d *active,
                      __m256i *j, __m256d *dj, __m256d *gj, int skip_idle)
{
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi64x(1);
    while (any_of(Q, active))
        for (int q = 0; q < Q; q++) {
            if (skip_idle && !_mm256_movemask_pd(active[q]))
                continue;
            const __m256d d = G[q]->d;
            __m256i jm = _mm256_sub_epi64(j[q], one);
            __m256d dm, gm;
            fields(G[q], active[q], jm, &dm, &gm);
            __m256d lhs = _mm256_mul_pd(_mm256_sub_pd(gm, g[q]), _mm256_sub_pd(d, dj[q]));
            __m256d rhs = _mm256_mul_pd(_mm256_sub_pd(gj[q], g[q]), _mm256_sub_pd(d, dm));
            __m256d pop = _mm256_and_pd(active[q], _mm256_cmp_pd(lhs, rhs, _CMP_GE_OQ));
            dj[q] = _mm256_blendv_pd(dj[q], dm, pop);
            gj[q] = _mm256_blendv_pd(gj[q], gm, pop);
            j[q] = _mm256_add_epi64(j[q], as_si(pop));
            active[q] = gt64(pop, j[q], zero);
        }
}

/* lane_hull.c's advance: far[q] moves up while its next point (below
 * n[q]) is near_skip behind. */
ALWAYS void advance(int Q, const group *G, const __m256d *lanes, __m256i *far, const __m256i *n,
                    __m256d near_skip)
{
    const __m256i one = _mm256_set1_epi64x(1);
    __m256d active[QMAX];
    for (int q = 0; q < Q; q++)
        active[q] = gt64(lanes[q], n[q], _mm256_add_epi64(far[q], one));
    while (any_of(Q, active))
        for (int q = 0; q < Q; q++) {
            __m256i next = _mm256_add_epi64(far[q], one);
            __m256d dn, gn;
            fields(&G[q], active[q], next, &dn, &gn);
            __m256d go = _mm256_and_pd(
                active[q], _mm256_cmp_pd(_mm256_sub_pd(G[q].d, dn), near_skip, _CMP_GE_OQ));
            far[q] = _mm256_sub_epi64(far[q], as_si(go));
            active[q] = gt64(go, n[q], _mm256_add_epi64(far[q], one));
        }
}

/* lane_hull.c's query: vectors 2p and 2p + 1 are the same lines and share
 * the loads of far and of the point below it. */
ALWAYS void query(int Q, const group *const *G, const __m256d *m, const __m256i *far,
                  const __m256d *g, int long_walks, int k_now, double k_step, __m128i *k_out,
                  __m128 *dd_out)
{
    const __m256i zero = _mm256_setzero_si256(), none = _mm256_set1_epi64x(-1);
    const __m256i one = _mm256_set1_epi64x(1);
    __m256d ok[QMAX], active[QMAX], dj[QMAX], gj[QMAX];
    __m256i j[QMAX];
    for (int q = 0; q < Q; q += 2) {
        const __m256d both = gt64(_mm256_or_pd(m[q], m[q + 1]), far[q], none);
        const __m256d below = gt64(both, far[q], zero);
        const __m256i fm = _mm256_sub_epi64(far[q], one);
        __m256d df, gf, dm, gm;
        fields(G[q], both, far[q], &df, &gf);
        fields(G[q], below, fm, &dm, &gm);
        const __m256d d = G[q]->d;
        for (int r = q; r < q + 2; r++) {
            ok[r] = gt64(m[r], far[r], none);
            const __m256d lhs = _mm256_mul_pd(_mm256_sub_pd(gm, g[r]), _mm256_sub_pd(d, df));
            const __m256d rhs = _mm256_mul_pd(_mm256_sub_pd(gf, g[r]), _mm256_sub_pd(d, dm));
            const __m256d pop = _mm256_and_pd(_mm256_and_pd(ok[r], below),
                                              _mm256_cmp_pd(lhs, rhs, _CMP_GE_OQ));
            dj[r] = _mm256_blendv_pd(df, dm, pop);
            gj[r] = _mm256_blendv_pd(gf, gm, pop);
            j[r] = _mm256_add_epi64(far[r], as_si(pop));
            active[r] = gt64(pop, j[r], zero);
        }
    }
    walk_down(Q, G, g, active, j, dj, gj, long_walks);
    for (int q = 0; q < Q; q++) {
        const __m256d dd = _mm256_sub_pd(G[q]->d, dj[q]);
        const __m128i ok32 = narrow(as_si(ok[q]));
        if (k_step > 0) {
            /* k_now - dd / k_step rounded to the nearest (the default
             * rounding mode), as lane_hull.c */
            const __m128i lag = _mm256_cvtpd_epi32(_mm256_mul_pd(dd, _mm256_set1_pd(1.0 / k_step)));
            k_out[q] = _mm_blendv_epi8(_mm_set1_epi32(-1),
                                       _mm_sub_epi32(_mm_set1_epi32(k_now), lag), ok32);
        } else {
            /* the step k of point j: ints 6 (first + j) + 4 */
            const __m256i j3 = times3(_mm256_add_epi64(G[q]->first, j[q]));
            const __m256i ki = _mm256_add_epi64(_mm256_slli_epi64(j3, 1), _mm256_set1_epi64x(4));
            k_out[q] = _mm256_mask_i64gather_epi32(_mm_set1_epi32(-1), G[q]->pk, ki, ok32, 4);
        }
        dd_out[q] = _mm_and_ps(_mm256_cvtpd_ps(dd), _mm_castsi128_ps(ok32));
    }
}

/* Groups of four lines from j on, NG of them at once, those of lanes[q]
 * (all-ones lanes; lanes32: the same as ints) in group q. */
AVX2 static void hull_groups(const ts_lane_hulls *H, const ts_lane_step *s, int j,
                             const __m256d *lanes, const __m128i *lanes32,
                             const ts_lane_occluders *occ)
{
    const __m256d c = _mm256_set1_pd(s->c), near_skip = _mm256_set1_pd(s->near_skip);
    const __m256i one = _mm256_set1_epi64x(1);
    const __m128i iota = _mm_setr_epi32(0, 1, 2, 3);
    const long long stride = H->stride;
    const __m256i strides = _mm256_setr_epi64x(0, stride, 2 * stride, 3 * stride);
    group G[NG], P[NG]; /* the lines at their queries' and their pushes' distances */
    const group *GP[NG];
    __m256i m[NG], top[NG], far[NG];
    __m256d cdd[NG], gs[NG], d1[NG], g1[NG], push[NG], active[NG];
    for (int q = 0; q < NG; q++) {
        const int jq = j + 4 * q;
        const __m256i lm = as_si(lanes[q]);
        G[q].d = _mm256_maskload_pd(s->d + jq, lm);
        G[q].first = _mm256_add_epi64(_mm256_set1_epi64x((long long)jq * H->stride), strides);
        G[q].pd = (const double *)H->pts;
        G[q].pk = (const int *)H->pts;
        cdd[q] = _mm256_mul_pd(_mm256_mul_pd(c, G[q].d), G[q].d);
        GP[q] = &G[q];
        if (s->push_d) {
            P[q] = G[q];
            GP[q] = &P[q];
            P[q].d = _mm256_maskload_pd(s->push_d + jq, lm);
            push[q] = ordered(lanes[q], P[q].d);
            gs[q] = _mm256_maskload_pd(s->push_g + jq, as_si(push[q]));
        } else {
            const __m256d hs = _mm256_cvtps_pd(_mm_maskload_ps(s->hs + jq, lanes32[q]));
            push[q] = ordered(lanes[q], hs);
            gs[q] = _mm256_sub_pd(hs, cdd[q]);
        }
        m[q] = _mm256_cvtepi32_epi64(_mm_maskload_epi32(H->n + jq, lanes32[q]));
        /* the top point is m - 1; the walk leaves the new top */
        top[q] = _mm256_sub_epi64(m[q], one);
        active[q] = gt64(push[q], top[q], _mm256_setzero_si256());
        fields(&G[q], active[q], top[q], &d1[q], &g1[q]);
    }
    walk_down(NG, GP, gs, active, top, d1, g1, 0);
    for (int q = 0; q < NG; q++) {
        m[q] = _mm256_add_epi64(top[q], one);
        const __m256i f =
            _mm256_cvtepi32_epi64(_mm_maskload_epi32(H->far + j + 4 * q, lanes32[q]));
        far[q] = _mm256_blendv_epi8(f, top[q], _mm256_cmpgt_epi64(f, top[q]));
    }
    if (s->push_d) /* every point is beyond the near field, the new one too */
        for (int q = 0; q < NG; q++)
            far[q] = _mm256_sub_epi64(top[q], as_si(push[q]));
    else
        advance(NG, G, lanes, far, m, near_skip);
    const group *QG[2 * NG];
    __m256d qm[2 * NG], qg[2 * NG];
    __m256i qfar[2 * NG];
    __m128i k[2 * NG];
    __m128 dd[2 * NG];
    for (int q = 0; q < NG; q++) {
        const int jq = j + 4 * q;
        /* the push itself, lane by lane */
        const int pushing = _mm256_movemask_pd(push[q]);
        if (pushing) {
            long long at[4];
            double pd[4], pg[4];
            _mm256_storeu_si256((__m256i *)at, m[q]);
            _mm256_storeu_pd(pd, GP[q]->d);
            _mm256_storeu_pd(pg, gs[q]);
            for (int l = 0; l < 4; l++)
                if (pushing >> l & 1) {
                    ts_hull_pt *p = H->pts + (size_t)(jq + l) * H->stride + at[l];
                    p->d = pd[l];
                    p->g = pg[l];
                    /* else a point's step is never read back */
                    if (!(s->k_step > 0))
                        p->k = s->push_d ? s->push_ks[jq + l] : s->k;
                }
        }
        _mm_maskstore_epi32(H->n + jq, lanes32[q], narrow(_mm256_sub_epi64(m[q], as_si(push[q]))));
        _mm_maskstore_epi32(H->far + jq, lanes32[q], narrow(far[q]));
        /* the occluders of the cells below (hi, when asked) and above (lo) */
        const __m256d hc = _mm256_cvtps_pd(_mm_maskload_ps(s->hc + jq, lanes32[q]));
        const __m256d hn = _mm256_cvtps_pd(_mm_maskload_ps(s->hn + jq, lanes32[q]));
        const __m128i idx = _mm_add_epi32(_mm_set1_epi32(jq), iota);
        const __m128i hi32 =
            _mm_andnot_si128(_mm_or_si128(_mm_cmplt_epi32(idx, _mm_set1_epi32(s->hi_from)),
                                          _mm_cmpgt_epi32(idx, _mm_set1_epi32(s->hi_to))),
                             lanes32[q]);
        const __m256d want_hi = as_pd(_mm256_cvtepi32_epi64(hi32));
        QG[2 * q] = QG[2 * q + 1] = &G[q];
        qfar[2 * q] = qfar[2 * q + 1] = far[q];
        qm[2 * q] = ordered(want_hi, hc);
        qg[2 * q] = _mm256_sub_pd(hc, cdd[q]);
        qm[2 * q + 1] = ordered(lanes[q], hn);
        qg[2 * q + 1] = _mm256_sub_pd(hn, cdd[q]);
    }
    query(2 * NG, QG, qm, qfar, qg, s->push_d != NULL, s->k, s->k_step, k, dd);
    for (int q = 0; q < NG; q++) {
        const int jq = j + 4 * q;
        _mm_maskstore_epi32(occ->hi_k + jq, lanes32[q], k[2 * q]);
        _mm_maskstore_ps(occ->hi_dd + jq, lanes32[q], dd[2 * q]);
        _mm_maskstore_epi32(occ->lo_k + jq + 1, lanes32[q], k[2 * q + 1]);
        _mm_maskstore_ps(occ->lo_dd + jq + 1, lanes32[q], dd[2 * q + 1]);
    }
}

AVX2 static void hull_step(const ts_lane_hulls *h, const ts_lane_step *s,
                           const ts_lane_occluders *occ)
{
    const __m128i iota = _mm_setr_epi32(0, 1, 2, 3);
    for (int j = s->j0; j <= s->j1; j += 4 * NG) {
        __m256d lanes[NG];
        __m128i lanes32[NG];
        for (int q = 0; q < NG; q++) {
            /* the lines left from j + 4 q on, at most four */
            lanes32[q] = _mm_cmpgt_epi32(_mm_set1_epi32(s->j1 - (j + 4 * q) + 1), iota);
            lanes[q] = as_pd(_mm256_cvtepi32_epi64(lanes32[q]));
        }
        hull_groups(h, s, j, lanes, lanes32, occ);
    }
}

int ts_lane_hull_step_avx2(const ts_lane_hulls *h, const ts_lane_step *s,
                           const ts_lane_occluders *occ)
{
    hull_step(h, s, occ);
    return 1;
}

#else

int ts_lane_hull_step_avx2(const ts_lane_hulls *h, const ts_lane_step *s,
                           const ts_lane_occluders *occ)
{
    (void)h;
    (void)s;
    (void)occ;
    return 0;
}

#endif
