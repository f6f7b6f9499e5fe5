/* A lockstep block's hull step in scalar code, line by line: the
 * reference of the vector steps (lane_hull.c, lane_hull256.c), which do
 * the same double operations per line in the same order; see
 * lane_hull.h. */
#include <math.h>

#include "lane_hull.h"
#include "sweep_internal.h"

/* stack_query, the occluder's step from its distance where s->k_step says
 * so (as lane_hull.c's query: the vector steps leave the points' steps
 * unwritten then). */
static inline occluder lane_query(const ts_lane_step *s, const hull_pt *S, int far, double d,
                                  double g)
{
    if (far < 0 || !(s->k_step > 0))
        return stack_query(S, far, d, g);
    const double dd = d - S[stack_tangent(S, far, d, g)].d;
    /* dd / k_step is >= 0 and within ~1e-12 of an integer: + 0.5 and the
     * truncation round it as nearbyint did, without libm's call (baseline
     * x86-64 has no roundsd) */
    return (occluder){s->k - (int)(dd * (1.0 / s->k_step) + 0.5), (float)dd};
}

void ts_lane_hull_step_scalar(const ts_lane_hulls *h, const ts_lane_step *s,
                              const ts_lane_occluders *occ)
{
    const occluder none = {-1, 0.0f};
    const double c = s->c;
    for (int j = s->j0; j <= s->j1; j++) {
        hull_pt *S = h->pts + (size_t)j * h->stride;
        const double d = s->d[j];
        const float hs = s->hs[j], hc = s->hc[j], hn = s->hn[j];
        if (s->push_d) { /* another step's point; every point is beyond the near field */
            if (!isnan(s->push_d[j]))
                hull_push(S, &h->n[j], &h->far[j], s->push_d[j], s->push_g[j], s->push_ks[j],
                          0.0);
            h->far[j] = h->n[j] - 1;
        } else if (!isnan(hs)) {
            hull_push(S, &h->n[j], &h->far[j], d, hs - c * d * d, s->k, s->near_skip);
        } else {
            h->far[j] = far_advance(S, h->n[j], h->far[j], d, s->near_skip);
        }
        const int far = h->far[j];
        occluder hi = !isnan(hc) && j >= s->hi_from && j <= s->hi_to
                          ? lane_query(s, S, far, d, hc - c * d * d)
                          : none;
        occluder lo = !isnan(hn) ? lane_query(s, S, far, d, hn - c * d * d) : none;
        occ->hi_k[j] = hi.k;
        occ->hi_dd[j] = hi.dd;
        occ->lo_k[j + 1] = lo.k;
        occ->lo_dd[j + 1] = lo.dd;
    }
}
