/* A lockstep block's hull step, eight lines per AVX-512 vector; see
 * lane_hull.h. */
#include <limits.h>
#include <stddef.h>

#include "lane_hull.h"
#include "simd_clones.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

/* Gathers address a point's fields as doubles (d, g) and ints (k). */
_Static_assert(sizeof(ts_hull_pt) == 3 * sizeof(double) && offsetof(ts_hull_pt, d) == 0 &&
                   offsetof(ts_hull_pt, g) == sizeof(double) &&
                   offsetof(ts_hull_pt, k) == 2 * sizeof(double),
               "ts_hull_pt is laid out as the gathers read it");

typedef struct {
    __m512d d;     /* the lines' distances */
    __m256i first; /* index of each line's first point */
    const double *pd;
    const int *pk;
} group;

/* 3 x: a shift and an add, where vpmulld takes 10 cycles (on the walks'
 * chains: index, gather, compare, index). */
TS_AVX512 static inline __m256i times3(__m256i x)
{
    return _mm256_add_epi32(_mm256_slli_epi32(x, 1), x);
}

/* Field f (0: d, 1: g) of point p of each line, where m. */
TS_AVX512 static inline __m512d field(const group *G, __mmask8 m, __m256i p, int f)
{
    __m256i i = _mm256_add_epi32(times3(_mm256_add_epi32(G->first, p)), _mm256_set1_epi32(f));
    return _mm512_mask_i32gather_pd(_mm512_setzero_pd(), m, i, G->pd, 8);
}

/* Both fields of point p of each line, where m, as two gathers would give
 * them there (the lines outside m read the array's first point, whose
 * values no walk uses: every use is masked): each line's (d, g) pair loaded
 * on its own and the eight transposed, in about half the time of two
 * gathers on the Zen 4 host (session 38). */
TS_AVX512 static inline __attribute__((always_inline)) void
fields(const group *G, __mmask8 m, __m256i p, __m512d *d, __m512d *g)
{
    int at[8] __attribute__((aligned(32)));
    _mm256_store_si256((__m256i *)at,
                       times3(_mm256_maskz_add_epi32(m, G->first, p)));
    const double *pd = G->pd;
    const __m128d a0 = _mm_loadu_pd(pd + at[0]), a1 = _mm_loadu_pd(pd + at[1]);
    const __m128d a2 = _mm_loadu_pd(pd + at[2]), a3 = _mm_loadu_pd(pd + at[3]);
    const __m128d a4 = _mm_loadu_pd(pd + at[4]), a5 = _mm_loadu_pd(pd + at[5]);
    const __m128d a6 = _mm_loadu_pd(pd + at[6]), a7 = _mm_loadu_pd(pd + at[7]);
    /* (d0 g0 d2 g2 d4 g4 d6 g6) and (d1 g1 d3 g3 ...): their low and high
     * halves of each pair of doubles are the lines' d and g */
    const __m512d e = _mm512_insertf64x4(
        _mm512_castpd256_pd512(_mm256_insertf128_pd(_mm256_castpd128_pd256(a0), a2, 1)),
        _mm256_insertf128_pd(_mm256_castpd128_pd256(a4), a6, 1), 1);
    const __m512d o = _mm512_insertf64x4(
        _mm512_castpd256_pd512(_mm256_insertf128_pd(_mm256_castpd128_pd256(a1), a3, 1)),
        _mm256_insertf128_pd(_mm256_castpd128_pd256(a5), a7, 1), 1);
    *d = _mm512_unpacklo_pd(e, o);
    *g = _mm512_unpackhi_pd(e, o);
}

/* Point p of each line of m set to (d, g), as two scatters would, each
 * line's pair stored on its own (the others' into a spare pair). */
TS_AVX512 static inline __attribute__((always_inline)) void
set_fields(const group *G, __mmask8 m, __m256i p, __m512d d, __m512d g)
{
    int at[8] __attribute__((aligned(32)));
    _mm256_store_si256((__m256i *)at, times3(_mm256_add_epi32(G->first, p)));
    double spare[2];
    double *pd = (double *)G->pd;
    /* (d0 g0 d2 g2 d4 g4 d6 g6) and (d1 g1 d3 g3 ...) */
    const __m512 e = _mm512_castpd_ps(_mm512_unpacklo_pd(d, g));
    const __m512 o = _mm512_castpd_ps(_mm512_unpackhi_pd(d, g));
#define TS_SET_PAIR(l, v, i)                                                                     \
    _mm_storeu_pd(m >> (l) & 1 ? pd + at[l] : spare,                                             \
                  _mm_castps_pd(_mm512_extractf32x4_ps(v, i)))
    TS_SET_PAIR(0, e, 0);
    TS_SET_PAIR(1, o, 0);
    TS_SET_PAIR(2, e, 1);
    TS_SET_PAIR(3, o, 1);
    TS_SET_PAIR(4, e, 2);
    TS_SET_PAIR(5, o, 2);
    TS_SET_PAIR(6, e, 3);
    TS_SET_PAIR(7, o, 3);
#undef TS_SET_PAIR
}

/* Array a of the hulls' beside (lane_hull.h) at lines jq.., where m. */
TS_AVX512 static inline __m512d beside_load(const ts_lane_hulls *H, int a, int jq, __mmask8 m)
{
    return _mm512_maskz_loadu_pd(m, H->beside + (size_t)a * H->beside_n + jq);
}

TS_AVX512 static inline void beside_store(const ts_lane_hulls *H, int a, int jq, __mmask8 m,
                                         __m512d v)
{
    _mm512_mask_storeu_pd(H->beside + (size_t)a * H->beside_n + jq, m, v);
}

/* Eight lines' floats and ints: 256-bit masked loads and stores (a
 * 512-bit one with half its mask clear still spans, and may split, a
 * 64-byte range) */
TS_AVX512 static inline __m256 load8f(__mmask8 m, const float *p)
{
    return _mm256_maskz_loadu_ps(m, p);
}

TS_AVX512 static inline __m256i load8i(__mmask8 m, const int *p)
{
    return _mm256_maskz_loadu_epi32(m, p);
}

TS_AVX512 static inline void store8i(int *p, __mmask8 m, __m256i v)
{
    _mm256_mask_storeu_epi32(p, m, v);
}

/* The loops below walk several hulls' stacks at once: each pass of a
 * loop issues the gathers of Q independent vectors (lines, or the two
 * queries of the same lines), so that their latencies overlap; Q is a
 * constant where they are inlined. */
#define ALWAYS TS_AVX512 static inline __attribute__((always_inline))
/* vectors of eight lines a step takes at once (4: measured faster than 1,
 * 2 and 8), and at most twice as many walks (two queries per line) */
#define NG 4
#define QMAX (2 * NG)

ALWAYS __mmask8 any_of(int Q, const __mmask8 *active)
{
    __mmask8 any = 0;
    for (int q = 0; q < Q; q++)
        any |= active[q];
    return any;
}

/* One pass of a walk down a hull, for the lines of mask m (from
 * distance d at hull height g): point j - 1 (dm, gm) hides point j (dj,
 * gj) where it pops; there j moves down to it, and the lines stay active
 * while j > 0. Every walk's compare, so that they all round alike. */
ALWAYS void pop_pass(__m512d d, __m512d g, __m512d dm, __m512d gm, __mmask8 m, __m512d *dj,
                     __m512d *gj, __m256i *j, __mmask8 *active)
{
    const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(gm, g), _mm512_sub_pd(d, *dj));
    const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(*gj, g), _mm512_sub_pd(d, dm));
    const __mmask8 pop = _mm512_mask_cmp_pd_mask(m, lhs, rhs, _CMP_GE_OQ);
    *dj = _mm512_mask_mov_pd(*dj, pop, dm);
    *gj = _mm512_mask_mov_pd(*gj, pop, gm);
    *j = _mm256_mask_sub_epi32(*j, pop, *j, _mm256_set1_epi32(1));
    *active = _mm256_mask_cmpgt_epi32_mask(pop, *j, _mm256_setzero_si256());
}

/* The walk of hull_push's pops and of stack_query, for Q vectors of lines
 * (those of active[q], of group G[q]) at hull heights g[q]: j[q] moves
 * down while point j - 1 hides point j (dj, gj: point j's fields) as seen
 * from the lines' samples, and stays at 0 at most. With skip_idle, a pass
 * leaves out the vectors with no line left (no gathers with an empty mask):
 * for the hybrid's queries, whose walks start at the newest point, ~4
 * passes per step where the unbounded sweep's need 0.2. */
ALWAYS void walk_down(int Q, const group *const *G, const __m512d *g, __mmask8 *active,
                      __m256i *j, __m512d *dj, __m512d *gj, int skip_idle)
{
    const __m256i one = _mm256_set1_epi32(1);
    while (any_of(Q, active))
        for (int q = 0; q < Q; q++) {
            if (skip_idle && !active[q])
                continue;
            const __m256i jm = _mm256_sub_epi32(j[q], one);
            __m512d dm, gm;
            fields(G[q], active[q], jm, &dm, &gm);
            pop_pass(G[q]->d, g[q], dm, gm, active[q], &dj[q], &gj[q], &j[q], &active[q]);
        }
}

/* walk_down for the queries' Q vectors in pairs: vectors q and q + 1 (q
 * even) are the same lines, from the same far, and each pass moves every
 * walking lane one point down, so that a lane walking in both stands on the
 * same point in both: one load of each pass's points serves the pair (a
 * lane walking in one only reads its own). The same compares as walk_down. */
ALWAYS void walk_pairs(int Q, const group *const *G, const __m512d *g, __mmask8 *active,
                       __m256i *j, __m512d *dj, __m512d *gj, int skip_idle)
{
    const __m256i one = _mm256_set1_epi32(1);
    while (any_of(Q, active))
        for (int q = 0; q < Q; q += 2) {
            const __mmask8 m = active[q] | active[q + 1];
            if (skip_idle && !m)
                continue;
            const __m256i jm =
                _mm256_sub_epi32(_mm256_mask_blend_epi32(active[q], j[q + 1], j[q]), one);
            __m512d dm, gm;
            fields(G[q], m, jm, &dm, &gm);
            for (int r = q; r < q + 2; r++)
                pop_pass(G[q]->d, g[r], dm, gm, active[r], &dj[r], &gj[r], &j[r], &active[r]);
        }
}

/* far_advance for Q groups: far[q] moves up while its next point (below
 * n[q]) is near_skip behind. */
ALWAYS void advance(int Q, const group *G, const __mmask8 *lanes, __m256i *far,
                    const __m256i *n, __m512d near_skip)
{
    const __m256i one = _mm256_set1_epi32(1);
    __mmask8 active[QMAX];
    for (int q = 0; q < Q; q++)
        active[q] = _mm256_mask_cmpgt_epi32_mask(lanes[q], n[q], _mm256_add_epi32(far[q], one));
    while (any_of(Q, active))
        for (int q = 0; q < Q; q++) {
            __m256i next = _mm256_add_epi32(far[q], one);
            __m512d dn = field(&G[q], active[q], next, 0);
            __mmask8 go = _mm512_mask_cmp_pd_mask(active[q], _mm512_sub_pd(G[q].d, dn),
                                                  near_skip, _CMP_GE_OQ);
            far[q] = _mm256_mask_add_epi32(far[q], go, far[q], one);
            active[q] = _mm256_mask_cmpgt_epi32_mask(go, n[q], _mm256_add_epi32(far[q], one));
        }
}

/* stack_query for Q vectors of lines (those of m[q], of group G[q]) at
 * hull heights g[q]: walk down from far while the slope grows; the
 * occluder's step (-1: none) and distance. Vectors 2p and 2p + 1 are the
 * same lines (the same group and far): they share the gathers of far and
 * of the point below it, which answer 99 % of the queries (walk_down's
 * first pass, the same operations); long_walks: where they do not (the
 * hybrid's hulls, all of whose points lie beyond the near field). */
ALWAYS void query(int Q, const group *const *G, const __mmask8 *m, const __m256i *far,
                  const __m512d *g, int long_walks, int k_now, double k_step, __m256i *k_out,
                  __m256 *dd_out, const __m512d (*at_far)[4])
{
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
    __mmask8 ok[QMAX], active[QMAX];
    __m256i j[QMAX];
    __m512d dj[QMAX], gj[QMAX];
    for (int q = 0; q < Q; q += 2) {
        const __mmask8 both = _mm256_mask_cmpge_epi32_mask(m[q] | m[q + 1], far[q], zero);
        const __mmask8 below = _mm256_mask_cmpgt_epi32_mask(both, far[q], zero);
        const __m256i fm = _mm256_sub_epi32(far[q], one);
        /* (at_far: far's point and the one under it, known: the top two) */
        __m512d df, gf, dm, gm;
        if (at_far) {
            df = at_far[q / 2][0], gf = at_far[q / 2][1];
            dm = at_far[q / 2][2], gm = at_far[q / 2][3];
        } else {
            fields(G[q], both, far[q], &df, &gf);
            fields(G[q], below, fm, &dm, &gm);
        }
        const __m512d d = G[q]->d;
        for (int r = q; r < q + 2; r++) {
            ok[r] = _mm256_mask_cmpge_epi32_mask(m[r], far[r], zero);
            dj[r] = df, gj[r] = gf, j[r] = far[r];
            pop_pass(d, g[r], dm, gm, ok[r] & below, &dj[r], &gj[r], &j[r], &active[r]);
        }
    }
    walk_pairs(Q, G, g, active, j, dj, gj, long_walks);
    for (int q = 0; q < Q; q++) {
        const __m512d dd = _mm512_sub_pd(G[q]->d, dj[q]);
        if (k_step > 0) {
            /* the step k of point j from its distance: k_now - dd / k_step,
             * rounded to the nearest (dd / k_step lies within ~1e-12 of an
             * integer) */
            const __m256i lag = _mm512_cvt_roundpd_epi32(
                _mm512_mul_pd(dd, _mm512_set1_pd(1.0 / k_step)),
                _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
            k_out[q] = _mm256_mask_sub_epi32(_mm256_set1_epi32(-1), ok[q],
                                             _mm256_set1_epi32(k_now), lag);
        } else {
            /* the step k of point j: ints 6 (first + j) + 4 */
            const __m256i j3 = times3(_mm256_add_epi32(G[q]->first, j[q]));
            __m256i ki = _mm256_add_epi32(_mm256_slli_epi32(j3, 1), _mm256_set1_epi32(4));
            __m512i k = _mm512_mask_i32gather_epi32(_mm512_set1_epi32(-1), (__mmask16)ok[q],
                                                    _mm512_castsi256_si512(ki), G[q]->pk, 4);
            k_out[q] = _mm512_castsi512_si256(k);
        }
        dd_out[q] = _mm512_maskz_cvtpd_ps(ok[q], dd);
    }
}

/* walk_down's first pass for the pushes, from the top two points kept
 * beside the stacks (the same operations): (d1, g1) the top. */
ALWAYS void first_pop_beside(const ts_lane_hulls *H, int j, const group *const *GP,
                             const __m512d *gs, __mmask8 *active, __m256i *top, __m512d *d1,
                             __m512d *g1)
{
    for (int q = 0; q < NG; q++) {
        const int jq = j + 8 * q;
        const __m512d dm = beside_load(H, TS_BESIDE_SD, jq, active[q]);
        const __m512d gm = beside_load(H, TS_BESIDE_SG, jq, active[q]);
        pop_pass(GP[q]->d, gs[q], dm, gm, active[q], &d1[q], &g1[q], &top[q], &active[q]);
    }
}

/* Groups of eight lines from j on, NG of them at once, those of lanes[q]
 * in group q (a group with none is left alone). With the points beside
 * (H->beside), the pushes' first compares come from there, and in the
 * hybrid (far at the top) the queries' first points too. */
TS_AVX512 static void hull_groups(const ts_lane_hulls *H, const ts_lane_step *s, int j,
                                  const __mmask8 *lanes, const ts_lane_occluders *occ)
{
    const __m512d c = _mm512_set1_pd(s->c), near_skip = _mm512_set1_pd(s->near_skip);
    const __m256i one = _mm256_set1_epi32(1);
    const int bes = H->beside != NULL;
    group G[NG], P[NG]; /* the lines at their queries' and their pushes' distances */
    const group *GP[NG];
    __m256i idx[NG], m[NG], top[NG], far[NG];
    __m512d cdd[NG], gs[NG], d1[NG], g1[NG];
    __m512d at_far[NG][4]; /* the hybrid's with bes: far's point and the one under it */
    __mmask8 push[NG], active[NG];
    for (int q = 0; q < NG; q++) {
        const int jq = j + 8 * q;
        idx[q] = _mm256_add_epi32(_mm256_set1_epi32(jq), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        G[q].d = _mm512_maskz_loadu_pd(lanes[q], s->d + jq);
        G[q].first = _mm256_mullo_epi32(idx[q], _mm256_set1_epi32(H->stride));
        G[q].pd = (const double *)H->pts;
        G[q].pk = (const int *)H->pts;
        cdd[q] = _mm512_mul_pd(_mm512_mul_pd(c, G[q].d), G[q].d);
        /* hull_push: pop the points the sample hides (from its own
         * distance where it pushes another point's) */
        GP[q] = &G[q];
        if (s->push_d) {
            /* (field by field: a copy of the whole struct read back the
             * stores just made to G[q] with one wider load, which stalls on
             * store forwarding: ~7 % of this function's samples) */
            P[q].first = G[q].first;
            P[q].pd = G[q].pd;
            P[q].pk = G[q].pk;
            GP[q] = &P[q];
            P[q].d = _mm512_maskz_loadu_pd(lanes[q], s->push_d + jq);
            push[q] = _mm512_mask_cmp_pd_mask(lanes[q], P[q].d, P[q].d, _CMP_ORD_Q);
            gs[q] = _mm512_maskz_loadu_pd(push[q], s->push_g + jq);
        } else {
            const __m512d hs = _mm512_cvtps_pd(load8f(lanes[q], s->hs + jq));
            push[q] = _mm512_mask_cmp_pd_mask(lanes[q], hs, hs, _CMP_ORD_Q);
            gs[q] = _mm512_sub_pd(hs, cdd[q]);
        }
        m[q] = load8i(lanes[q], H->n + jq);
        /* the top point is m - 1; the walk leaves the new top */
        top[q] = _mm256_sub_epi32(m[q], one);
        active[q] = _mm256_mask_cmpgt_epi32_mask(push[q], top[q], _mm256_setzero_si256());
        if (bes) { /* (a line with one point keeps it as the new top too) */
            const __mmask8 some =
                _mm256_mask_cmpge_epi32_mask(push[q], top[q], _mm256_setzero_si256());
            d1[q] = beside_load(H, TS_BESIDE_TD, jq, some);
            g1[q] = beside_load(H, TS_BESIDE_TG, jq, some);
        } else {
            fields(&G[q], active[q], top[q], &d1[q], &g1[q]);
        }
    }
    if (bes)
        first_pop_beside(H, j, GP, gs, active, top, d1, g1);
    walk_down(NG, GP, gs, active, top, d1, g1, 0);
    /* Pops only take from the top, so far is at most the new top; lines
     * with nothing to push keep m = n, where far already is. */
    for (int q = 0; q < NG; q++) {
        m[q] = _mm256_add_epi32(top[q], one);
        far[q] = _mm256_min_epi32(load8i(lanes[q], H->far + j + 8 * q), top[q]);
    }
    if (s->push_d) /* every point is beyond the near field, the new one too */
        for (int q = 0; q < NG; q++)
            far[q] = _mm256_mask_add_epi32(top[q], push[q], top[q], one);
    else
        advance(NG, G, lanes, far, m, near_skip);
    const group *QG[2 * NG];
    __mmask8 qm[2 * NG];
    __m256i qfar[2 * NG], k[2 * NG];
    __m512d qg[2 * NG];
    __m256 dd[2 * NG];
    for (int q = 0; q < NG; q++) {
        const int jq = j + 8 * q;
        /* the push itself */
        set_fields(&G[q], push[q], m[q], GP[q]->d, gs[q]);
        if (!(s->k_step > 0)) { /* else a point's step is never read back */
            const __m256i at = times3(_mm256_add_epi32(G[q].first, m[q]));
            const __m256i kat = _mm256_add_epi32(_mm256_add_epi32(at, at), _mm256_set1_epi32(4));
            const __m512i kp = s->push_d
                                   ? _mm512_castsi256_si512(load8i(push[q], s->push_ks + jq))
                                   : _mm512_set1_epi32(s->k);
            _mm512_mask_i32scatter_epi32((int *)H->pts, (__mmask16)push[q],
                                         _mm512_castsi256_si512(kat), kp, 4);
        }
        if (bes) {
            if (s->push_d) {
                /* far is the top: the queries' first points are the new
                 * top and the one it went on, or the kept two (the lines
                 * without a push) */
                const __mmask8 keep = lanes[q] & (__mmask8)~push[q];
                const __m512d kept[4] = {beside_load(H, TS_BESIDE_TD, jq, keep),
                                         beside_load(H, TS_BESIDE_TG, jq, keep),
                                         beside_load(H, TS_BESIDE_SD, jq, keep),
                                         beside_load(H, TS_BESIDE_SG, jq, keep)};
                at_far[q][0] = _mm512_mask_blend_pd(push[q], kept[0], P[q].d);
                at_far[q][1] = _mm512_mask_blend_pd(push[q], kept[1], gs[q]);
                at_far[q][2] = _mm512_mask_blend_pd(push[q], kept[2], d1[q]);
                at_far[q][3] = _mm512_mask_blend_pd(push[q], kept[3], g1[q]);
            }
            /* the new top, and the one it went on (none: garbage, never read) */
            beside_store(H, TS_BESIDE_SD, jq, push[q], d1[q]);
            beside_store(H, TS_BESIDE_SG, jq, push[q], g1[q]);
            beside_store(H, TS_BESIDE_TD, jq, push[q], GP[q]->d);
            beside_store(H, TS_BESIDE_TG, jq, push[q], gs[q]);
        }
        store8i(H->n + jq, lanes[q], _mm256_mask_add_epi32(m[q], push[q], m[q], one));
        store8i(H->far + jq, lanes[q], far[q]);
        /* the occluders of the cells below (hi, when asked) and above (lo) */
        const __m512d hc = _mm512_cvtps_pd(load8f(lanes[q], s->hc + jq));
        const __m512d hn = _mm512_cvtps_pd(load8f(lanes[q], s->hn + jq));
        const __mmask8 want_hi = _mm256_mask_cmple_epi32_mask(
            _mm256_mask_cmpge_epi32_mask(lanes[q], idx[q], _mm256_set1_epi32(s->hi_from)), idx[q],
            _mm256_set1_epi32(s->hi_to));
        QG[2 * q] = QG[2 * q + 1] = &G[q];
        qfar[2 * q] = qfar[2 * q + 1] = far[q];
        qm[2 * q] = _mm512_mask_cmp_pd_mask(want_hi, hc, hc, _CMP_ORD_Q);
        qg[2 * q] = _mm512_sub_pd(hc, cdd[q]);
        qm[2 * q + 1] = _mm512_mask_cmp_pd_mask(lanes[q], hn, hn, _CMP_ORD_Q);
        qg[2 * q + 1] = _mm512_sub_pd(hn, cdd[q]);
    }
    query(2 * NG, QG, qm, qfar, qg, s->push_d != NULL, s->k, s->k_step, k, dd,
          bes && s->push_d ? (const __m512d(*)[4])at_far : NULL);
    for (int q = 0; q < NG; q++) {
        const int jq = j + 8 * q;
        store8i(occ->hi_k + jq, lanes[q], k[2 * q]);
        _mm256_mask_storeu_ps(occ->hi_dd + jq, lanes[q], dd[2 * q]);
        store8i(occ->lo_k + jq + 1, lanes[q], k[2 * q + 1]);
        _mm256_mask_storeu_ps(occ->lo_dd + jq + 1, lanes[q], dd[2 * q + 1]);
    }
}

int ts_lane_hull_step(const ts_lane_hulls *h, const ts_lane_step *s, const ts_lane_occluders *occ)
{
    const int level = ts_cpu_vector_level();
    /* 32-bit offsets: the last line's points, as ints (AVX2's are 64-bit) */
    if (level != TS_CPU_VECTORS_AVX512 || (long long)(s->j1 + 1) * h->stride * 6 > INT_MAX)
        return level >= TS_CPU_VECTORS_AVX2 && ts_lane_hull_step_avx2(h, s, occ);
    for (int j = s->j0; j <= s->j1; j += 8 * NG) {
        __mmask8 lanes[NG];
        for (int q = 0; q < NG; q++) {
            int left = s->j1 - (j + 8 * q) + 1;
            lanes[q] = left >= 8 ? 0xFF : left <= 0 ? 0 : (__mmask8)((1u << left) - 1);
        }
        hull_groups(h, s, j, lanes, occ);
    }
    return 1;
}

#else

int ts_lane_hull_step(const ts_lane_hulls *h, const ts_lane_step *s, const ts_lane_occluders *occ)
{
    (void)h;
    (void)s;
    (void)occ;
    return 0;
}

#endif
