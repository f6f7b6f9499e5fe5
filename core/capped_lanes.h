/*
 * The far-field occluders of a lockstep block of capped sweep lines (a
 * horizon with a maximum distance; the block is sweep_block's in
 * core/horizon_sweep.c), found by brute force over each line's window.
 *
 * A line's window at distance d holds its samples p with
 * near <= d - d_p <= cap, as the sliding window hull (window_hull.h) does;
 * the occluder of a query point (d, g) is the sample of largest slope
 * (g_p - g) / (d - d_p) among them. Each line keeps its recent samples in a
 * ring indexed by step (slot k mod slots), laid out slot by slot with the
 * block's lines side by side, so that one slot of eight lines is one
 * vector: a query compares every slot of the window's lags by
 * cross-multiplication (no division), eight lines at a time, no gathers.
 * Among equally steep samples the oldest (smallest step) wins, whatever
 * the block's first step, so a line's answers do not depend on where a
 * block or a tile begins. Long windows (with AVX-512) skip the groups of
 * slots, and then the samples, whose bounds show they cannot change the
 * answer (capped_lanes512.c), with the same bits.
 */
#ifndef TS_CAPPED_LANES_H
#define TS_CAPPED_LANES_H

#include "lane_hull.h"
#include "lane_passes.h"

typedef struct {
    double *d, *g;      /* slot s of line j at [s * stride + j]; d NaN: no sample */
    int stride;         /* lines per slot, a multiple of 8 */
    int slots;          /* lag_hi + 1 */
    int lag_lo, lag_hi; /* the lags (steps back) a window sample may have */
    int sure_lo, sure_hi; /* and those that are surely in the window */
    double near, cap;
    /* Pruning (AVX-512, long windows): per aligned group of TS_CAP_G0 steps
     * (level 0, whose slots lie together in the ring) and of TS_CAP_G1 steps
     * (level 1), per line, the largest g of its samples and the distances
     * of its oldest and newest; -inf, 0, 0 when it has none. Group m of
     * level l sits at [(m % groups[l]) * stride + j]. */
    int prune;
    int groups[2];
    double *gmax[2], *dlo[2], *dhi[2];
    /* per line, padded to stride: the step's distance and query heights,
     * and the answers (steps, -1: none; distances) */
    double *qd, *qc, *qn, *ddc, *ddn;
    long long *kc, *kn;
    /* ts_cap_lanes_hybrid_step's hulls miss samples (a step without lines
     * pushed none): the block's other steps take the scan alone */
    int hull_lost;
    /* the hybrid's delayed pushes from the ring (those near behind) */
    ts_lane_pushes push;
} ts_cap_lanes;

/* Level 0 and level 1 groups of the pruned scan, in steps. */
#ifndef TS_CAP_G0
#define TS_CAP_G0 8
#endif
#ifndef TS_CAP_G1
#define TS_CAP_G1 64
#endif

/* The lags (steps back) of a window from near to cap metres behind, on
 * lines whose steps are shortest..longest metres long: lags[0..1], those
 * a sample of the window may have; lags[2..3], those that are surely in
 * it (none where lags[2] > lags[3]). */
void ts_cap_lanes_lags(double near, double cap, double shortest, double longest, int lags[4]);

/* Whether the brute force (pruned for long windows) is the cheaper way to
 * answer windows of these lags on this CPU (else the line-by-line sliding
 * window hull is). The answers differ only between exactly equally steep
 * samples. */
int ts_cap_lanes_pays(const int lags[4]);

/* Rings for up to `lines` lines and the window of lags (as
 * ts_cap_lanes_lags gives them); 0 if out of memory (ts_cap_lanes_free
 * still applies). */
int ts_cap_lanes_alloc(ts_cap_lanes *r, int lines, const int lags[4], double near, double cap);
void ts_cap_lanes_free(ts_cap_lanes *r);

/* Forget every sample: a new block starts. */
void ts_cap_lanes_clear(ts_cap_lanes *r);

/* Step s->k of lines 0..nl-1, those of s->j0..s->j1 on the grid (none when
 * j0 > j1): record their samples and, for those, answer the queries of
 * the cells below (hi, for hi_from <= j <= hi_to) and above (lo entry
 * j + 1), as ts_lane_hull_step does for unbounded lines. */
void ts_cap_lanes_step(ts_cap_lanes *r, const ts_lane_step *s, int nl,
                       const ts_lane_occluders *occ);

/* Step k's slot of the ring (rd, rg) for the step's samples, emptied
 * (d NaN: no sample) for the lines of 0..nl-1 outside j0..j1 (all where
 * j0 > j1): the caller writes every line of j0..j1. */
void ts_cap_ring_slot(ts_cap_lanes *r, int k, int nl, int j0, int j1, double **rd, double **rg);

/* Lines a block may have for ts_cap_lanes_hybrid_step. */
#define TS_CAP_MAX_LINES 256

/* Whether the hybrid (ts_cap_lanes_hybrid_step) is the cheaper way to
 * answer windows of these lags on this CPU than the line-by-line window
 * hull (only where ts_cap_lanes_pays is not). */
int ts_cap_lanes_hybrid_pays(const int lags[4]);

/* ts_cap_lanes_step for long windows (AVX-512), with each line's hull h
 * (ts_lane_hull_step's, emptied with the block) of its samples beyond the
 * near field: where the hull's steepest sample lies in the window, it is
 * the window's; the ring's scan answers the rest, by group of eight lines
 * (capped_hybrid.c). The hulls take the ring's samples themselves, each
 * once its line is the near field's distance past it (r->push: every
 * sample beyond the near field, none within). The answers differ from
 * ts_cap_lanes_step's only between equally steep samples (up to
 * rounding). Sets s's pushes (push_d, push_g, push_ks; near_skip 0) for
 * the hulls. Returns 0, having answered nothing, where the CPU has no
 * AVX-512, the block too many lines, or the hulls missed a step
 * (hull_lost): the caller then runs ts_cap_lanes_step (which reads none
 * of those fields). */
int ts_cap_lanes_hybrid_step(ts_cap_lanes *r, const ts_lane_hulls *h, ts_lane_step *s, int nl,
                             const ts_lane_occluders *occ);

#endif
