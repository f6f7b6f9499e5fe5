/*
 * The far-only sweep in the horizon sweep's lockstep blocks (sweep_far.h):
 * core/far_horizon.c's far field, with the whole sweep's vectorised
 * sampling, hulls and far field (horizon_sweep.c's sweep_block).
 *
 * A sample joins its line's hull only once the line is the threshold T
 * past it, so that the hull holds exactly the samples at least T behind
 * (a near sample pushed at once could hide older far ones). Each line's
 * samples wait in a ring of the block's steps; at each step a line pushes
 * its oldest waiting sample once T lies between them
 * (ts_lane_delayed_pushes, lane_hull.h: on lines of any steps, so on
 * geographic grids too). Nearly always one sample a step is ready; where
 * steps shorten and two are, the step takes a second pass (its queries,
 * the same, are asked again). There is no near field, and the blocks' far
 * field takes occluders however few steps back.
 */
#include <math.h>
#include <stdlib.h>

#include "parallel.h"
#include "status_internal.h"
#include "sweep_far.h"
#include "sweep_internal.h"

/* The snap of the lines' and rays' fractions onto cells (ts_line_geom_snap). */
#define FAR_SNAP 1e-6f

int ts_far_ws_init(sweep_ws *w, const sweep_ctx *C)
{
    w->far_stride = LOCKSTEP_LINES + 8; /* a block's, and a vector's loads beyond */
    w->far_ring = malloc((size_t)C->far_slots * 2 * w->far_stride * sizeof *w->far_ring);
    return w->far_ring && ts_lane_pushes_alloc(&w->far_push, w->far_stride);
}

void ts_far_ws_free(sweep_ws *w)
{
    free(w->far_ring);
    ts_lane_pushes_free(&w->far_push);
}

void ts_far_store(const sweep_ctx *C, sweep_ws *w, int k, int nl, int j0, int j1)
{
    double *rd = w->far_ring + (size_t)(k % C->far_slots) * 2 * w->far_stride;
    double *rg = rd + w->far_stride;
    for (int j = 0; j < nl; j++)
        rd[j] = NAN;
    for (int j = j0; j <= j1; j++)
        if (!isnan(w->hs[j])) {
            const double d = w->lane_d[j];
            rd[j] = d;
            rg[j] = w->hs[j] - C->c * d * d;
        }
    if (C->far_dz != 0.0f)
        for (int j = j0; j <= j1; j++) {
            w->hc[j] += C->far_dz;
            w->hn[j] += C->far_dz;
        }
}

int ts_far_pushes(const sweep_ctx *C, sweep_ws *w, ts_lane_step *step)
{
    return ts_lane_delayed_pushes(&w->far_push, w->far_ring, w->far_ring + w->far_stride,
                                  2 * (size_t)w->far_stride, C->far_slots, C->far_T, step);
}

ts_status ts_sweep_far_lanes(const ts_grid *grid, double azimuth, double threshold_m, double dz,
                             const ts_horizon_opts *opts, float *out, ts_error *err)
{
    ts_line_geom geom;
    sweep_ctx C;
    ts_status st = ts_sweep_setup(grid, azimuth, opts, &geom, &C, err);
    if (st != TS_OK)
        return st;
    double shortest, longest;
    ts_line_geom_step_range(&geom, grid->height, &shortest, &longest);
    /* a sample waits at most T / shortest + 1 steps (+2: rounding), and no
     * longer than its line */
    const double wait = ceil(threshold_m / shortest) + 3;
    ts_line_geom_snap(&geom, FAR_SNAP);
    int failed = 0;
    C.far_T = threshold_m;
    C.far_dz = (float)dz;
    C.far_slots = wait < geom.U + 2 ? (int)wait : geom.U + 2;
    C.out = out;
    C.alloc_failed = &failed;
    const long lines = geom.b_hi - geom.b_lo + 1;
    st = ts_parallel_ranges(ts_thread_count(opts->threads, lines), lines, LOCKSTEP_LINES,
                            ts_sweep_ranges, &C, err);
    ts_line_geom_free(&geom);
    if (st == TS_OK && failed)
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the far-field sweep workspace");
    return st;
}
