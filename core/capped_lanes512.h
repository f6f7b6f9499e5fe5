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

/* Empty n groups' entries (no samples: -inf, 0, 0). */
static inline void ts_cap_groups_empty(double *gmax, double *dlo, double *dhi, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        gmax[i] = -INFINITY;
        dlo[i] = dhi[i] = 0.0;
    }
}

#endif
