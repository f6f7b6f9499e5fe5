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

/* AVX-512 with its 256-bit forms (every AVX-512 CPU but the Xeon Phi has
 * them; ts_lane_vector_level asks): mask compares and masked adds of the
 * lines' indices, each one instruction on the walks' dependent chains. */
#define AVX512VL __attribute__((target("avx512f,avx512vl")))

/* 3 x: a shift and an add, where vpmulld takes 10 cycles (on the walks'
 * chains: index, gather, compare, index). */
AVX512VL static inline __m256i times3(__m256i x)
{
    return _mm256_add_epi32(_mm256_slli_epi32(x, 1), x);
}

/* Field f (0: d, 1: g) of point p of each line, where m. */
AVX512VL static inline __m512d field(const group *G, __mmask8 m, __m256i p, int f)
{
    __m256i i = _mm256_add_epi32(times3(_mm256_add_epi32(G->first, p)), _mm256_set1_epi32(f));
    return _mm512_mask_i32gather_pd(_mm512_setzero_pd(), m, i, G->pd, 8);
}

AVX512VL static inline __m256 load8f(__mmask8 m, const float *p)
{
    return _mm512_castps512_ps256(_mm512_maskz_loadu_ps((__mmask16)m, p));
}

AVX512VL static inline __m256i load8i(__mmask8 m, const int *p)
{
    return _mm512_castsi512_si256(_mm512_maskz_loadu_epi32((__mmask16)m, p));
}

AVX512VL static inline void store8i(int *p, __mmask8 m, __m256i v)
{
    _mm512_mask_storeu_epi32(p, (__mmask16)m, _mm512_castsi256_si512(v));
}

/* The loops below walk several hulls' stacks at once: each pass of a
 * loop issues the gathers of Q independent vectors (lines, or the two
 * queries of the same lines), so that their latencies overlap; Q is a
 * constant where they are inlined. */
#define ALWAYS AVX512VL static inline __attribute__((always_inline))
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

/* The walk of hull_push's pops and of stack_query, for Q vectors of lines
 * (those of active[q], of group G[q]) at hull heights g[q]: j[q] moves
 * down while point j - 1 hides point j (dj, gj: point j's fields) as seen
 * from the lines' samples, and stays at 0 at most. With skip_idle, a pass
 * leaves out the vectors with no line left (no gathers with an empty mask):
 * for the hybrid's queries, whose walks start at the newest point, ~4
 * passes per step where the unbounded sweep's need 0.2. */
ALWAYS void walk_down(int Q, const group *const *G, const __m512d *g, __mmask8 *active,
                      __m256i *j, __m512d *dj, __m512d *gj, int skip_idle, __m512d (*near)[6])
{
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
    while (any_of(Q, active))
        for (int q = 0; q < Q; q++) {
            if (skip_idle && !active[q])
                continue;
            const __m512d d = G[q]->d;
            __m256i jm = _mm256_sub_epi32(j[q], one);
            __m512d dm = field(G[q], active[q], jm, 0), gm = field(G[q], active[q], jm, 1);
            __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(gm, g[q]), _mm512_sub_pd(d, dj[q]));
            __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(gj[q], g[q]), _mm512_sub_pd(d, dm));
            __mmask8 pop = _mm512_mask_cmp_pd_mask(active[q], lhs, rhs, _CMP_GE_OQ);
            if (near) { /* the points below where it stops and above where it pops */
                const __mmask8 stop = active[q] & (__mmask8)~pop;
                near[q][0] = _mm512_mask_mov_pd(near[q][0], stop, dm);
                near[q][1] = _mm512_mask_mov_pd(near[q][1], stop, gm);
                near[q][4] = _mm512_mask_mov_pd(near[q][4], pop, dj[q]);
                near[q][5] = _mm512_mask_mov_pd(near[q][5], pop, gj[q]);
            }
            dj[q] = _mm512_mask_mov_pd(dj[q], pop, dm);
            gj[q] = _mm512_mask_mov_pd(gj[q], pop, gm);
            j[q] = _mm256_mask_sub_epi32(j[q], pop, j[q], one);
            active[q] = _mm256_mask_cmpgt_epi32_mask(pop, j[q], zero);
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

/* The answers of Q vectors of queries (those of ok[q]) whose walks ended
 * at points j[q], of distances dj[q]: the occluder's step (-1: none) and
 * distance. */
ALWAYS void answers(int Q, const group *const *G, const __mmask8 *ok, const __m256i *j,
                    const __m512d *dj, __m256i *k_out, __m256 *dd_out)
{
    for (int q = 0; q < Q; q++) {
        /* the step k of point j: ints 6 (first + j) + 4 */
        const __m256i j3 = times3(_mm256_add_epi32(G[q]->first, j[q]));
        __m256i ki = _mm256_add_epi32(_mm256_slli_epi32(j3, 1), _mm256_set1_epi32(4));
        __m512i k = _mm512_mask_i32gather_epi32(_mm512_set1_epi32(-1), (__mmask16)ok[q],
                                                _mm512_castsi256_si512(ki), G[q]->pk, 4);
        k_out[q] = _mm512_castsi512_si256(k);
        dd_out[q] = _mm512_maskz_cvtpd_ps(ok[q], _mm512_sub_pd(G[q]->d, dj[q]));
    }
}

/* stack_query for Q vectors of lines (those of m[q], of group G[q]) at
 * hull heights g[q]: walk down from far while the slope grows; the
 * occluder's step (-1: none) and distance. Vectors 2p and 2p + 1 are the
 * same lines (the same group and far): they share the gathers of far and
 * of the point below it, which answer 99 % of the queries (walk_down's
 * first pass, the same operations). */
ALWAYS void query(int Q, const group *const *G, const __mmask8 *m, const __m256i *far,
                  const __m512d *g, __m256i *k_out, __m256 *dd_out)
{
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
    __mmask8 ok[QMAX], active[QMAX];
    __m256i j[QMAX];
    __m512d dj[QMAX], gj[QMAX];
    for (int q = 0; q < Q; q += 2) {
        const __mmask8 both = _mm256_mask_cmpge_epi32_mask(m[q] | m[q + 1], far[q], zero);
        const __mmask8 below = _mm256_mask_cmpgt_epi32_mask(both, far[q], zero);
        const __m256i fm = _mm256_sub_epi32(far[q], one);
        const __m512d df = field(G[q], both, far[q], 0), gf = field(G[q], both, far[q], 1);
        const __m512d dm = field(G[q], below, fm, 0), gm = field(G[q], below, fm, 1);
        const __m512d d = G[q]->d;
        for (int r = q; r < q + 2; r++) {
            ok[r] = _mm256_mask_cmpge_epi32_mask(m[r], far[r], zero);
            const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(gm, g[r]), _mm512_sub_pd(d, df));
            const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(gf, g[r]), _mm512_sub_pd(d, dm));
            const __mmask8 pop = _mm512_mask_cmp_pd_mask(ok[r] & below, lhs, rhs, _CMP_GE_OQ);
            dj[r] = _mm512_mask_mov_pd(df, pop, dm);
            gj[r] = _mm512_mask_mov_pd(gf, pop, gm);
            j[r] = _mm256_mask_sub_epi32(far[r], pop, far[r], one);
            active[r] = _mm256_mask_cmpgt_epi32_mask(pop, j[r], zero);
        }
    }
    walk_down(Q, G, g, active, j, dj, gj, 0, NULL);
    answers(Q, G, ok, j, dj, k_out, dd_out);
}

/* Whether point s of each line (below its top: s + 1 is a point) may start
 * the walk of a query at (d, g) as well as the top: where the walk's own
 * rounded test of s + 1 pops it (point s at least as steep as s + 1) by
 * the margin below, the walk from the top pops every point above s too,
 * bit for bit. Why: exactly, the test of point i (against i - 1) is
 * (d_i - d_{i-1}) (g - T_i(d)), T_i the line through points i - 1 and i,
 * and T_i(d) - T_{s+1}(d) = sum over s < l < i of (e_{l+1} - e_l) (d - d_l),
 * e_l the slope of the hull's edge into point l. The hull is concave up to
 * rounding: point l stayed when l + 1 was pushed, so (rounded test,
 * 3-rounding products) e_{l+1} - e_l < 6 gamma3 G / step, G >= |g| of the
 * hull's points (gabs), step the shortest edge; with at most `span` points
 * and (d - d_l) / step <= span, T_i(d) <= T_{s+1}(d) + 6 gamma3 G span^2.
 * Point i's rounded test pops where its exact value exceeds
 * 2 gamma3 (G + |g|) (d - d_0), so where g - T_{s+1}(d) > 8 gamma3 (G + |g|)
 * span^2 (gamma3 ~ 3 u, u = 2^-53); the test below asks its rounded
 * lhs - rhs, (d_{s+1} - d_s) (g - T_{s+1}(d)), for more than that with
 * 2^-48 = 32 u (and 2^-50 = 8 u of its own terms' rounding), covering the
 * margin's own roundings. span2u: 2^-48 span^2. */
ALWAYS __mmask8 start_below_top(__mmask8 m, __m512d d, __m512d g, __m512d ds, __m512d gs,
                                __m512d d1, __m512d g1, __m512d gabs, __m512d span2u)
{
    const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(gs, g), _mm512_sub_pd(d, d1));
    const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(g1, g), _mm512_sub_pd(d, ds));
    const __m512d span = _mm512_mul_pd(_mm512_mul_pd(_mm512_sub_pd(d1, ds), span2u),
                                       _mm512_add_pd(gabs, _mm512_abs_pd(g)));
    const __m512d own = _mm512_mul_pd(_mm512_set1_pd(0x1p-50),
                                      _mm512_add_pd(_mm512_abs_pd(lhs), _mm512_abs_pd(rhs)));
    return _mm512_mask_cmp_pd_mask(m, _mm512_sub_pd(lhs, rhs), _mm512_add_pd(span, own),
                                   _CMP_GT_OQ);
}

/* query for the hybrid's hulls (all of whose points lie beyond the near
 * field, so that a walk from the top is long): each line's walks start at
 * start (its previous answer; -1: none) where start_below_top allows, at
 * the top t else. around[p]: the fields of points start - 1, start and
 * start + 1 of group p's lines as the previous step's walks left them (the
 * points up to the top after this step's pops are unchanged; start + 1,
 * where this step pushed it (fresh), is the push's fd, fg), so that the
 * walks from start gather nothing until they pop. near[q]: the same three
 * points around where query q's walk ends, for the next step. */
ALWAYS void query_from(int Q, const group *const *G, const __mmask8 *m, const __m256i *start,
                       const __m256i *top, const __mmask8 *fresh, const __m512d *fd,
                       const __m512d *fg, const __m512d *gabs, __m512d span2u,
                       const __m512d (*around)[6], const __m512d *g, __m256i *k_out,
                       __m256 *dd_out, __m256i *j_out, __m512d (*near)[6])
{
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
    __mmask8 ok[QMAX], active[QMAX];
    __m512d dj[QMAX], gj[QMAX];
    for (int q = 0; q < Q; q += 2) {
        const int p = q / 2;
        const __m256i s = start[p], t = top[p];
        const __mmask8 both = _mm256_mask_cmpge_epi32_mask(m[q] | m[q + 1], t, zero);
        const __mmask8 valid = _mm256_mask_cmpge_epi32_mask(both, s, zero);
        const __mmask8 below = _mm256_mask_cmplt_epi32_mask(valid, s, t);
        const __mmask8 has_m = _mm256_mask_cmpgt_epi32_mask(valid, s, zero);
        const __mmask8 new1 = _mm256_mask_cmpeq_epi32_mask(fresh[p], _mm256_add_epi32(s, one), t);
        const __m512d d = G[q]->d;
        const __m512d dm = around[p][0], gm = around[p][1];
        const __m512d ds = around[p][2], gs = around[p][3];
        const __m512d d1 = _mm512_mask_mov_pd(around[p][4], new1, fd[p]);
        const __m512d g1 = _mm512_mask_mov_pd(around[p][5], new1, fg[p]);
        __mmask8 at_s[2], from_top = 0;
        for (int r = 0; r < 2; r++) {
            ok[q + r] = _mm256_mask_cmpge_epi32_mask(m[q + r], t, zero);
            at_s[r] = ok[q + r] & ((valid & (__mmask8)~below) |
                                   start_below_top(below, d, g[q + r], ds, gs, d1, g1, gabs[p],
                                                   span2u));
            from_top |= ok[q + r] & (__mmask8)~at_s[r];
        }
        /* the top's fields: the push's, else gathered (rare) */
        const __mmask8 old_top = from_top & (__mmask8)~fresh[p];
        __m512d dt = fd[p], gt = fg[p];
        if (old_top) {
            dt = _mm512_mask_mov_pd(dt, old_top, field(G[q], old_top, t, 0));
            gt = _mm512_mask_mov_pd(gt, old_top, field(G[q], old_top, t, 1));
        }
        for (int r = 0; r < 2; r++) {
            const int w = q + r;
            /* from start: the walk's first test here (walk_down's
             * operations); from the top: walk_down's passes */
            const __mmask8 fb = ok[w] & (__mmask8)~at_s[r];
            const __m512d lhs = _mm512_mul_pd(_mm512_sub_pd(gm, g[w]), _mm512_sub_pd(d, ds));
            const __m512d rhs = _mm512_mul_pd(_mm512_sub_pd(gs, g[w]), _mm512_sub_pd(d, dm));
            const __mmask8 pop = _mm512_mask_cmp_pd_mask(at_s[r] & has_m, lhs, rhs, _CMP_GE_OQ);
            j_out[w] = _mm256_mask_mov_epi32(_mm256_mask_sub_epi32(s, pop, s, one), fb, t);
            dj[w] = _mm512_mask_mov_pd(_mm512_mask_mov_pd(ds, pop, dm), fb, dt);
            gj[w] = _mm512_mask_mov_pd(_mm512_mask_mov_pd(gs, pop, gm), fb, gt);
            near[w][0] = dm;
            near[w][1] = gm;
            near[w][4] = _mm512_mask_mov_pd(d1, pop, ds);
            near[w][5] = _mm512_mask_mov_pd(g1, pop, gs);
            active[w] = _mm256_mask_cmpgt_epi32_mask(pop | fb, j_out[w], zero);
        }
    }
    walk_down(Q, G, g, active, j_out, dj, gj, 1, near);
    for (int q = 0; q < Q; q++) {
        near[q][2] = dj[q];
        near[q][3] = gj[q];
    }
    answers(Q, G, ok, j_out, dj, k_out, dd_out);
}

/* Groups of eight lines from j on, NG of them at once, those of lanes[q]
 * in group q (a group with none is left alone). hybrid (a constant where
 * inlined): s->push_d's pushes and query_from's walks. */
ALWAYS void hull_groups_of(const ts_lane_hulls *H, const ts_lane_step *s, int j,
                           const __mmask8 *lanes, const ts_lane_occluders *occ, int hybrid)
{
    const __m512d c = _mm512_set1_pd(s->c), near_skip = _mm512_set1_pd(s->near_skip);
    const __m256i one = _mm256_set1_epi32(1);
    group G[NG], P[NG]; /* the lines at their queries' and their pushes' distances */
    const group *GP[NG];
    __m256i idx[NG], m[NG], top[NG], far[NG];
    __m512d cdd[NG], gs[NG], d1[NG], g1[NG], gabs[NG], GP_d[NG];
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
        if (hybrid) {
            P[q] = G[q];
            GP[q] = &P[q];
            P[q].d = _mm512_maskz_loadu_pd(lanes[q], s->push_d + jq);
            push[q] = _mm512_mask_cmp_pd_mask(lanes[q], P[q].d, P[q].d, _CMP_ORD_Q);
            gs[q] = _mm512_maskz_loadu_pd(push[q], s->push_g + jq);
            GP_d[q] = P[q].d;
            gabs[q] = _mm512_maskz_loadu_pd(lanes[q], s->gabs + jq);
            gabs[q] = _mm512_mask_max_pd(gabs[q], push[q], gabs[q], _mm512_abs_pd(gs[q]));
            _mm512_mask_storeu_pd(s->gabs + jq, lanes[q], gabs[q]);
        } else {
            const __m512d hs = _mm512_cvtps_pd(load8f(lanes[q], s->hs + jq));
            push[q] = _mm512_mask_cmp_pd_mask(lanes[q], hs, hs, _CMP_ORD_Q);
            gs[q] = _mm512_sub_pd(hs, cdd[q]);
        }
        m[q] = load8i(lanes[q], H->n + jq);
        /* the top point is m - 1; the walk leaves the new top */
        top[q] = _mm256_sub_epi32(m[q], one);
        active[q] = _mm256_mask_cmpgt_epi32_mask(push[q], top[q], _mm256_setzero_si256());
        d1[q] = field(&G[q], active[q], top[q], 0);
        g1[q] = field(&G[q], active[q], top[q], 1);
    }
    walk_down(NG, GP, gs, active, top, d1, g1, 0, NULL);
    /* Pops only take from the top, so far is at most the new top; lines
     * with nothing to push keep m = n, where far already is. */
    for (int q = 0; q < NG; q++) {
        m[q] = _mm256_add_epi32(top[q], one);
        far[q] = _mm256_min_epi32(load8i(lanes[q], H->far + j + 8 * q), top[q]);
    }
    __m256i start[NG];
    __m512d around[NG][6];
    if (hybrid) /* every point is beyond the near field, the new one too;
                 * the walks start at the previous answer (far: -1, none)
                 * where it is still on the hull (at most the top after
                 * the pops), its points around it as that step left them */
        for (int q = 0; q < NG; q++) {
            const __m256i at = load8i(lanes[q], H->far + j + 8 * q);
            far[q] = _mm256_mask_add_epi32(top[q], push[q], top[q], one);
            start[q] = _mm256_mask_mov_epi32(_mm256_set1_epi32(-1),
                                             _mm256_cmple_epi32_mask(at, top[q]), at);
            for (int f = 0; f < 6; f++)
                around[q][f] = _mm512_maskz_loadu_pd(
                    lanes[q], s->around + (size_t)f * s->around_stride + j + 8 * q);
        }
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
        const __m256i at = times3(_mm256_add_epi32(G[q].first, m[q]));
        _mm512_mask_i32scatter_pd((double *)H->pts, push[q], at, GP[q]->d, 8);
        _mm512_mask_i32scatter_pd((double *)H->pts, push[q], _mm256_add_epi32(at, one), gs[q], 8);
        const __m256i kat = _mm256_add_epi32(_mm256_add_epi32(at, at), _mm256_set1_epi32(4));
        _mm512_mask_i32scatter_epi32((int *)H->pts, (__mmask16)push[q],
                                     _mm512_castsi256_si512(kat),
                                     _mm512_set1_epi32(hybrid ? s->push_k : s->k), 4);
        store8i(H->n + jq, lanes[q], _mm256_mask_add_epi32(m[q], push[q], m[q], one));
        if (!hybrid)
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
    if (hybrid) {
        __m256i at[2 * NG];
        __m512d near[2 * NG][6];
        query_from(2 * NG, QG, qm, start, far, push, GP_d, gs, gabs,
                   _mm512_set1_pd(0x1p-48 * s->span * s->span), (const __m512d(*)[6])around, qg,
                   k, dd, at, near);
        /* the next step's start: the higher of the lines' two answers,
         * with its points around; none where neither asked */
        for (int q = 0; q < NG; q++) {
            const __mmask8 on = _mm256_cmpge_epi32_mask(far[q], _mm256_setzero_si256());
            const __mmask8 hi = qm[2 * q] & on, lo = qm[2 * q + 1] & on;
            const __mmask8 use_lo = lo & ((__mmask8)~hi | _mm256_cmpgt_epi32_mask(at[2 * q + 1],
                                                                                   at[2 * q]));
            const __mmask8 use_hi = hi & (__mmask8)~use_lo;
            __m256i next = _mm256_mask_mov_epi32(_mm256_set1_epi32(-1), use_hi, at[2 * q]);
            next = _mm256_mask_mov_epi32(next, use_lo, at[2 * q + 1]);
            store8i(H->far + j + 8 * q, lanes[q], next);
            for (int f = 0; f < 6; f++)
                _mm512_mask_storeu_pd(
                    s->around + (size_t)f * s->around_stride + j + 8 * q, lanes[q],
                    _mm512_mask_mov_pd(near[2 * q][f], use_lo, near[2 * q + 1][f]));
        }
    } else
        query(2 * NG, QG, qm, qfar, qg, k, dd);
    for (int q = 0; q < NG; q++) {
        const int jq = j + 8 * q;
        store8i(occ->hi_k + jq, lanes[q], k[2 * q]);
        _mm512_mask_storeu_ps(occ->hi_dd + jq, (__mmask16)lanes[q],
                              _mm512_castps256_ps512(dd[2 * q]));
        store8i(occ->lo_k + jq + 1, lanes[q], k[2 * q + 1]);
        _mm512_mask_storeu_ps(occ->lo_dd + jq + 1, (__mmask16)lanes[q],
                              _mm512_castps256_ps512(dd[2 * q + 1]));
    }
}

AVX512VL static void hull_groups(const ts_lane_hulls *H, const ts_lane_step *s, int j,
                                  const __mmask8 *lanes, const ts_lane_occluders *occ)
{
    hull_groups_of(H, s, j, lanes, occ, 0);
}

AVX512VL static void hull_groups_hybrid(const ts_lane_hulls *H, const ts_lane_step *s, int j,
                                         const __mmask8 *lanes, const ts_lane_occluders *occ)
{
    hull_groups_of(H, s, j, lanes, occ, 1);
}

int ts_lane_vector_level(void)
{
    static int known = -1; /* the CPU's answer, once asked */
    int level = __atomic_load_n(&known, __ATOMIC_RELAXED);
    if (level < 0) {
        __builtin_cpu_init();
        level = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? 2
                : __builtin_cpu_supports("avx2")                                        ? 1
                                                                                        : 0;
        __atomic_store_n(&known, level, __ATOMIC_RELAXED);
    }
    return level;
}

int ts_lane_hull_step(const ts_lane_hulls *h, const ts_lane_step *s, const ts_lane_occluders *occ)
{
    /* 32-bit offsets: the last line's points, as ints */
    if (ts_lane_vector_level() != 2 || (long long)(s->j1 + 1) * h->stride * 6 > INT_MAX)
        return 0;
    for (int j = s->j0; j <= s->j1; j += 8 * NG) {
        __mmask8 lanes[NG];
        for (int q = 0; q < NG; q++) {
            int left = s->j1 - (j + 8 * q) + 1;
            lanes[q] = left >= 8 ? 0xFF : left <= 0 ? 0 : (__mmask8)((1u << left) - 1);
        }
        if (s->push_d)
            hull_groups_hybrid(h, s, j, lanes, occ);
        else
            hull_groups(h, s, j, lanes, occ);
    }
    return 1;
}

#else

int ts_lane_vector_level(void)
{
    return 0;
}

int ts_lane_hull_step(const ts_lane_hulls *h, const ts_lane_step *s, const ts_lane_occluders *occ)
{
    (void)h;
    (void)s;
    (void)occ;
    return 0;
}

#endif
