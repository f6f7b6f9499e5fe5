/*
 * The far-field occluders of a lockstep block of capped sweep lines (the
 * block is sweep_block's in core/horizon_sweep.c) through each line's
 * sliding window hull (window_hull.h), for windows too long for the brute
 * force of capped_lanes.h. Each line does per step what process_line does
 * for it alone: push its sample, slide its window, and query it from the
 * cells below and above, with its own fingers; so a line's answers are
 * process_line's, while the block keeps the vectorised sampling, far field
 * and row-streaming memory of the lockstep blocks.
 */
#ifndef TS_CAPPED_HULLS_H
#define TS_CAPPED_HULLS_H

#include "lane_hull.h"
#include "lane_passes.h"
#include "window_hull.h"

typedef struct {
    int lines;
    ts_window_hull *win; /* line j's window */
    ts_hull_pt *raw;     /* line j's samples: a ring of `ring` at raw + j * ring */
    int *raw_n;          /* samples line j has had */
    int (*finger)[2][2]; /* where line j's hi and lo queries last ended (per hull) */
    int ring;
    double cap;
} ts_cap_hulls;

/* The samples a window of these lags (ts_cap_lanes_lags) on lines of up to
 * U steps holds at most, with its newest ones (for ts_window_hull_alloc). */
int ts_cap_window_span(const int lags[4], int U);

/* Whether windows of these lags (ts_cap_lanes_lags) on lines of up to U
 * steps keep a workspace small enough for the lockstep hulls. */
int ts_cap_hulls_fit(const int lags[4], int U);

/* Windows for up to `lines` lines of up to U steps; 0 if out of memory
 * (ts_cap_hulls_free still applies). */
int ts_cap_hulls_alloc(ts_cap_hulls *r, int lines, const int lags[4], int U, double cap);
void ts_cap_hulls_free(ts_cap_hulls *r);

/* Empty every line's window: a new block starts. */
void ts_cap_hulls_clear(ts_cap_hulls *r);

/* Steps steps[0..n-1] (in order) of lines 0..nl-1, each step of those of
 * its j0..j1 (none when j0 > j1), as ts_cap_lanes_step: each line pushes
 * and slides, then answers the queries of the cells below (hi, for
 * hi_from <= j <= hi_to) and above (lo entry j + 1) into occ[t]. */
void ts_cap_hulls_run(ts_cap_hulls *r, const ts_lane_step *steps, const ts_lane_occluders *occ,
                      int n, int nl);

#endif
