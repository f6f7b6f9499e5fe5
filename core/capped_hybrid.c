/*
 * Long capped windows in the lockstep blocks (AVX-512): an unbounded hull
 * first, the window's ring only where the hull cannot answer; see
 * capped_lanes.h (ts_cap_lanes_hybrid_step).
 *
 * Each line's hull takes its samples once they leave the near field (from
 * the ring, ts_lane_delayed_pushes: once the line is the near field's
 * distance past them, so on lines of any steps), so it holds every sample
 * beyond the near field, and its query finds the steepest of them. Where
 * that one lies in the window (as the ring tests it: lag <= lag_hi,
 * d - d_p <= cap), it is the window's steepest, the window being a subset
 * of what the hull saw; else the ring's (pruned) scan answers, by group of
 * eight lines. (Pushing samples at once, as the unbounded sweep does, lets
 * a sample still in the near field hide older ones, ~100 steps of them on
 * fractal terrain.)
 */
#include "capped_lanes.h"
#include "capped_lanes512.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <math.h>

/* Steps of one length (k_step > 0: each distance is its step's multiple of
 * k_step, one rounding) make every line's delayed push its sample of step
 * k - lag, lag the least with lag k_step >= near: the one the general
 * pushes (ts_lane_delayed_pushes) find there, one a step, and read in
 * place from the ring (cleared with the block, and its slot of every step
 * rewritten). 0 where near lies within 1e-6 steps of a whole number of
 * steps, where rounding might decide, or the ring is too short: then the
 * general pushes. */
static int uniform_push_lag(const ts_cap_lanes *r, double k_step)
{
    if (!(k_step > 0))
        return 0;
    const double x = r->near / k_step, lag = ceil(x);
    if (!(lag - x >= 1e-6 && x - (lag - 1) >= 1e-6 && lag >= 1 && lag < r->slots))
        return 0;
    return (int)lag;
}

/* The pushes of step k for uniform_push_lag's lag: the ring's slot of step
 * k - lag (NaN distances where a line has no sample there), none before
 * step lag. */
static void ring_pushes(ts_cap_lanes *r, int k, int lag, ts_lane_step *hs)
{
    if (k >= lag) {
        const size_t at = (size_t)((k - lag) % r->slots) * r->stride;
        hs->push_d = r->d + at;
        hs->push_g = r->g + at;
    } else {
        for (int j = hs->j0; j <= hs->j1; j++)
            r->push.pd[j] = NAN;
        hs->push_d = r->push.pd;
        hs->push_g = r->push.pg;
    }
    hs->push_ks = r->push.ks; /* (unread: the hulls' steps follow from k_step) */
    hs->near_skip = 0.0;
}

int ts_cap_lanes_hybrid_step(ts_cap_lanes *r, const ts_lane_hulls *h, ts_lane_step *s, int nl,
                             const ts_lane_occluders *occ)
{
    const int k = s->k, j0 = s->j0, j1 = s->j1;
    if (r->hull_lost || j0 > j1 || r->stride > TS_CAP_MAX_LINES) {
        r->hull_lost = 1;
        return 0;
    }
    /* the ring's samples the near field's distance behind, in as many
     * passes as a line has ready, set in s itself (a copy of s, read back
     * with wider loads right after the caller's stores, stalled on store
     * forwarding) */
    int more, pushed;
    const int lag = uniform_push_lag(r, s->k_step);
    if (lag > 0) {
        ring_pushes(r, k, lag, s);
        pushed = ts_lane_hull_step(h, s, occ);
    } else
        do {
            more = ts_lane_delayed_pushes(&r->push, r->d, r->g, r->stride, r->slots, r->near, s);
            pushed = ts_lane_hull_step(h, s, occ);
        } while (pushed && more);
    if (!pushed) {
        r->hull_lost = 1;
        return 0;
    }
    double *rd, *rg;
    ts_cap_ring_slot(r, k, nl, j0, j1, &rd, &rg); /* (j0..j1: ts_cap_answers512) */
    const int g0 = j0 / 8 * 8, g1 = (j1 + 8) / 8 * 8;
    ts_cap_queries512(r, s, g0, g1);
    /* the hull's answers, where they are the window's; the groups of eight
     * lines where some are not */
    unsigned char scan[TS_CAP_MAX_LINES / 8];
    ts_cap_hull_answers512(r, k, g0, g1, occ, scan);
    /* the ring's scan for the groups that need it, up to TS_CAP_NG at once */
    for (int g = g0; g < g1;) {
        if (!scan[(g - g0) / 8]) {
            g += 8;
            continue;
        }
        int e = g + 8;
        while (e < g1 && e - g < 8 * TS_CAP_NG && scan[(e - g0) / 8])
            e += 8;
        ts_cap_scan512(r, k, g, e);
        g = e;
    }
    ts_cap_answers512(r, s, g0, g1, occ, rd, rg);
    return 1;
}

#else

int ts_cap_lanes_hybrid_step(ts_cap_lanes *r, const ts_lane_hulls *h, ts_lane_step *s, int nl,
                             const ts_lane_occluders *occ)
{
    (void)r;
    (void)h;
    (void)s;
    (void)nl;
    (void)occ;
    return 0;
}

#endif
