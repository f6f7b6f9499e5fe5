/*
 * Exact horizon sweep for one azimuth (Timonen & Westerholm 2010, Alg. 1).
 *
 * Each sweep line keeps the upper convex hull of the samples behind it in a
 * stack; a new sample pops the hull points it hides and its horizon is the
 * slope to the new top, so a line of N samples costs O(N). Heights enter
 * the hull as g = h - c d^2 (d = distance along the line, c = (1-k)/2R):
 * the curvature drop c (d_p - d_q)^2 then becomes a per-query constant
 * -2 c d_p, so the hull stays exact with curvature on.
 *
 * Lines are one cell apart, so every cell lies between two lines in its
 * column (see line_geometry.h). A cell's horizon is the larger of
 *  - the near field: the first cells of the cell's own ray, solved exactly
 *    on the bilinear surface (near_field.h), and
 *  - the far field: the weighted mean (weights = 1 - distance to the line)
 *    of the slopes from the cell's own height to the hull points of the two
 *    neighbouring lines that lie beyond the near field.
 *
 * With a maximum distance, the occluder is the steepest of the line's
 * samples beyond the near field and within the distance: for short windows
 * (capped_lanes.h) the lines run in the same lockstep blocks and each
 * query is a brute-force maximum over the window, vectorised across lines;
 * for long ones, with AVX-512, each line in the blocks also keeps the hull
 * of its samples beyond the near field, whose answer is the window's
 * wherever it lies in the window (capped_lanes.h, the hybrid); else each
 * line keeps the hull of a sliding window of its samples (window_hull.h,
 * one line at a time: sweep_line.c),
 * in amortised O(1) per sample like the unbounded hull. The near field is
 * cut at the distance, and the last part of a step before it is solved
 * exactly on each cell's ray.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "arg_checks.h"
#include "cellmath/cm_fastmath.h"
#include "lane_hull.h"
#include "lane_passes.h"
#include "parallel.h"
#include "simd_clones.h"
#include "status_internal.h"
#include "sweep_cap_tail.h"
#include "sweep_far.h"
#include "sweep_internal.h"

/* A block's per-line arrays on whole cache lines, each row of them too
 * (LANE_ROW entries): the lockstep passes' vector loads and stores of eight
 * or sixteen lines from line 0 then split no line. */
#define LANE_ROW ((LOCKSTEP_LINES + 2 + 15) / 16 * 16)

static void *alloc_lines(size_t bytes)
{
    return aligned_alloc(64, (bytes + 63) / 64 * 64);
}

/* The block's line one row before the grid's first at step k, where it
 * has left the grid across row 0 (lane_k1): its hull holds the terrain it
 * crossed on the grid toward the occluders, so that, between rows -1 and 0
 * (a fraction), it answers row 0's cell for the far side, as the line
 * before every other cell does (without it, row 0 took its far field from
 * one line, up to 13-34 degrees low across oblique cliffs). It takes every
 * such step, so that its distance goes on; -1: none. */
static int row_before(const sweep_ws *w, int k, long i0, int nl)
{
    const long j = -i0 - 1;
    return j >= 0 && j < nl && w->lane_k1[j] >= 0 && k > w->lane_k1[j] ? (int)j : -1;
}

/* Step k of lines j0..j1 of a block (rows i0 + j): each line's distance
 * from its first sample, as ts_line_sample_at advances it. */
static void lane_distances(const sweep_ctx *C, sweep_ws *w, int k, int i0, int j0, int j1)
{
    const ts_line_geom *G = C->geom;
    double *restrict dist = w->lane_d;
    const int *restrict k0 = w->lane_k0;
    if (G->step_row) {
        for (int j = j0; j <= j1; j++) {
            /* (row -1, a line just left the grid: row 0's steps) */
            int row = G->x_major ? (i0 + j < 0 ? 0 : i0 + j) : G->u_start + k * G->u_step;
            if (k > k0[j])
                dist[j] += G->step_row[row];
        }
    } else if (G->anchored) { /* as on the whole DEM */
        ts_lane_distances(k + G->k_anchor, NULL, G->step_m, j0, j1, dist);
    } else {
        ts_lane_distances(k, k0, G->step_m, j0, j1, dist);
    }
}

/* Lines bs .. bs + nl - 1 of an unbounded sweep (or a bounded one, in the
 * rings of capped_lanes.h; or the far-only one, C->far_T, sweep_far.c),
 * step by step; the first is only primed (not written) when `prime`.
 * w->carry holds what the line before the block found; on return it holds
 * the block's last line's.
 * Each step samples the lines together (lane_passes.h), pushes and queries
 * each line's hull in the same order as ts_sweep_process_line, then evaluates the
 * far field of the step's cells together: the cell between lines j - 1 and
 * j takes its far-side occluder from line j - 1 and its own from line j. */
static void sweep_block(const sweep_ctx *C, sweep_ws *w, long bs, int nl, int prime)
{
    _Static_assert(FAR_SPREAD == 0, "the lockstep far field samples at the occluders only");
    const ts_line_geom *G = C->geom;
    const occluder none = {-1, 0.0f};
    int kmin = G->U, kmax = -1;
    for (int j = 0; j < nl; j++) {
        int k0, k1;
        w->lane_k1[j] = -1; /* no steps on the grid: none off it either */
        if (!ts_line_k_range(G, bs + j, &k0, &k1))
            continue;
        if (C->cap == 0 || w->hybrid) {
            w->lane_n[j] = 0;
            w->lane_far[j] = -1;
        }
        w->lane_k0[j] = k0;
        w->lane_k1[j] = k1;
        w->lane_d[j] = 0.0;
        kmin = k0 < kmin ? k0 : kmin;
        /* (and the steps where it has left across row 0, row_before) */
        const int kl = ts_line_k_leaving(G, bs + j, k1);
        kmax = kl > kmax ? kl : kmax;
    }
    occluder *next = w->carry_next;
    for (int k = 0; k < G->U; k++)
        next[k] = none;
    if (C->cap > 0)
        ts_cap_lanes_clear(&w->capl);
    if (C->far_T > 0)
        ts_lane_pushes_reset(&w->far_push, nl);
    const ts_lane_occluders occ = {w->lo_k, w->hi_k, w->lo_dd, w->hi_dd};
    const ts_lane_hulls hulls = {w->lane_stacks,  G->U + 1, w->lane_n, w->lane_far,
                                 w->lane_beside, LANE_ROW};
    const ts_lane_lost lost = {&C->ray, C->c, C->cap, C->far_T, w->lost};
    const double c = C->c;
    for (int k = kmin; k <= kmax; k++) {
        /* The lines on the grid at step k: rows i0 + j in [0, V - 1]. */
        const long i0 = bs + G->fl[k];
        const int j0 = i0 < 0 ? (int)-i0 : 0;
        const int j1 = G->V - 1 - i0 < nl - 1 ? (int)(G->V - 1 - i0) : nl - 1;
        const int jq = row_before(w, k, i0, nl);
        if (j0 > j1 && jq < 0) {
            if (C->far_T > 0) /* no samples: its slot is empty */
                ts_far_store(C, w, k, nl, 0, -1);
            if (C->cap > 0) /* no samples: the rings forget this step */
                ts_cap_lanes_step(&w->capl, &(ts_lane_step){.k = k, .j0 = 1, .j1 = 0}, nl, NULL);
            continue;
        }
        /* the lines stepped: those on the grid, and the one before row 0
         * that answers row 0's cell (queries only) */
        const int js = jq >= 0 ? jq : j0;
        if (j0 <= j1)
            ts_lane_sample(G, C->grid->z, k, (int)i0, j0, j1, w->hc, w->hn, w->hs);
        if (jq >= 0) { /* after the sampling, whose vectors may write lane jq */
            w->hc[jq] = w->hs[jq] = NAN;
            w->hn[jq] = G->fr[k] > 0.0f ? C->grid->z[G->origin + (ptrdiff_t)k * G->u_stride]
                                        : NAN; /* on row -1: row 0 is on the next line */
        }
        lane_distances(C, w, k, (int)i0, js, j1);
        /* lo_k[j]: the far-side occluder of line j's cell, found by the
         * line before (none where that line is off the grid). */
        const occluder lo0 = j0 == 0 ? w->carry[k] : none;
        w->lo_k[js] = lo0.k;
        w->lo_dd[js] = lo0.dd;
        /* Every line asks for its own cell's occluder, the one between the
         * last row and the one beyond too: off the grid at this step, it
         * may have been on it toward the occluders (the last row's cells
         * took their far field from one line, degrees low) */
        ts_lane_step step = {k, js, j1, prime, j1, w->lane_d, w->hs, w->hc,
                             w->hn, c, C->near_skip, NULL, NULL, NULL, 0.0};
        if (!G->step_row) /* lane_distances' products (ts_far_store keeps them) */
            step.k_step = G->step_m;
        if (C->far_T > 0) {
            /* far-only: the hulls take the samples far_T behind, one per
             * line and pass (the passes' queries are the same: the last
             * stands) */
            ts_far_store(C, w, k, nl, js, j1);
            for (int more = 1; more;) {
                more = ts_far_pushes(C, w, &step);
                if (!ts_lane_hull_step(&hulls, &step, &occ))
                    ts_lane_hull_step_scalar(&hulls, &step, &occ);
            }
        } else {
            const int hybrid =
                w->hybrid && ts_cap_lanes_hybrid_step(&w->capl, &hulls, &step, nl, &occ);
            if (!hybrid && C->cap > 0)
                ts_cap_lanes_step(&w->capl, &step, nl, &occ);
            else if (!hybrid && !ts_lane_hull_step(&hulls, &step, &occ))
                ts_lane_hull_step_scalar(&hulls, &step, &occ);
        }
        const int jw = prime && j0 == 0 ? 1 : j0;
        float *o = C->out + C->o_origin + (ptrdiff_t)k * C->o_u_stride +
                   (i0 + jw) * C->o_v_stride; /* cell (k, i0 + jw) */
        /* (far-only: every occluder lies beyond the threshold, and so do
         * the lost rays' steps, lost.from) */
        if (jw <= j1)
            ts_lane_far_field(G, C->grid->z, (float)c, C->far_T > 0 ? 0 : TS_NEAR_STEPS, k,
                              (int)i0, jw, j1, w->hc, &occ, &lost, w->slope, o, C->o_v_stride);
        /* the carry, read after the far field: right after the hull step's
         * vector stores to it, the load stalled on store forwarding */
        if (j1 == nl - 1)
            next[k] = (occluder){w->lo_k[nl], w->lo_dd[nl]};
    }
    w->carry_next = w->carry;
    w->carry = next;
}

static void ws_free(sweep_ws *w)
{
    free(w->stack);
    free(w->raw);
    ts_window_hull_free(&w->win);
    ts_window_hull_free(&w->vwin);
    free(w->lo.prev);
    free(w->lo.cur);
    free(w->vx);
    free(w->vy);
    free(w->vh);
    free(w->vs);
    free(w->vd);
    free(w->lane_stacks);
    free(w->lane_n);
    free(w->lane_far);
    free(w->lane_beside);
    free(w->carry);
    free(w->carry_next);
    free(w->lane_f);
    free(w->lane_i);
    free(w->lane_d);
    ts_far_ws_free(w);
    ts_cap_lanes_free(&w->capl);
}

static int ws_init(sweep_ws *w, const sweep_ctx *C)
{
    const int U = C->geom->U, capped = C->cap > 0, need_visit = C->visit != NULL;
    *w = (sweep_ws){0};
    int ok = 1;
    /* the block's hulls' offsets fit the gathers' 32 bits, as
     * ts_lane_hull_step's AVX-512 step asks */
    const int hulls32 = (long long)(LOCKSTEP_LINES + 1) * (U + 1) * 6 <= INT_MAX;
    /* capped lines too where their windows are short enough for the
     * brute force (capped_lanes.h), one by one otherwise */
    w->lockstep = !need_visit && (!capped || ts_cap_lanes_pays(C->lags));
    /* long windows: in lockstep too where the hybrid pays (and hulls32) */
    w->hybrid =
        !need_visit && capped && !w->lockstep && ts_cap_lanes_hybrid_pays(C->lags) && hulls32;
    w->lockstep |= w->hybrid;
    if (capped && !w->lockstep) {
        w->raw = malloc((size_t)(U + 1) * sizeof *w->raw);
        ok = w->raw && ts_window_hull_alloc(&w->win, U) &&
             (!need_visit || ts_window_hull_alloc(&w->vwin, U));
    }
    w->stack = malloc((size_t)(U + 1) * sizeof *w->stack);
    w->lo.prev = malloc((size_t)U * sizeof(occluder));
    w->lo.cur = malloc((size_t)U * sizeof(occluder));
    if (need_visit) {
        w->vx = malloc((size_t)U * sizeof(float));
        w->vy = malloc((size_t)U * sizeof(float));
        w->vh = malloc((size_t)U * sizeof(float));
        w->vs = malloc((size_t)U * sizeof(float));
        w->vd = malloc((size_t)U * sizeof(double));
    }
    if (w->lockstep) {
        /* capped lines keep windows (rings) instead of hulls, the hybrid's
         * both */
        if (capped)
            ok = ts_cap_lanes_alloc(&w->capl, LOCKSTEP_LINES + 1, C->lags, C->near_skip, C->cap);
        if (!capped || w->hybrid) {
            w->lane_n = alloc_lines(LANE_ROW * sizeof *w->lane_n);
            w->lane_far = alloc_lines(LANE_ROW * sizeof *w->lane_far);
            w->lane_stacks =
                malloc((size_t)(LOCKSTEP_LINES + 1) * (U + 1) * sizeof *w->lane_stacks);
            ok = ok && w->lane_n && w->lane_far && w->lane_stacks;
            /* the hulls' most read points beside them, where every step
             * takes AVX-512 (hulls32) */
            if (ok && hulls32 && ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512)
                ok = (w->lane_beside = alloc_lines(TS_BESIDE * LANE_ROW * sizeof(double))) !=
                     NULL;
        }
        w->carry = malloc((size_t)U * sizeof *w->carry);
        w->carry_next = malloc((size_t)U * sizeof *w->carry_next);
        /* a block has up to LOCKSTEP_LINES + 1 lines (with the primed one) */
        const size_t row = LANE_ROW;
        w->lane_f = alloc_lines(6 * row * sizeof *w->lane_f);
        w->lane_i = alloc_lines(5 * row * sizeof *w->lane_i);
        w->lane_d = alloc_lines(row * sizeof *w->lane_d);
        ok = ok && w->carry && w->carry_next && w->lane_f && w->lane_i && w->lane_d;
        if (ok) {
            memset(w->lane_i, 0, 5 * row * sizeof *w->lane_i); /* the lost flags start clear */
            w->hc = w->lane_f;
            w->hn = w->lane_f + row;
            w->hs = w->lane_f + 2 * row;
            w->slope = w->lane_f + 3 * row;
            w->lo_dd = w->lane_f + 4 * row;
            w->hi_dd = w->lane_f + 5 * row;
            w->lo_k = w->lane_i;
            w->hi_k = w->lane_i + row;
            w->lane_k0 = w->lane_i + 2 * row;
            w->lost = w->lane_i + 3 * row;
            w->lane_k1 = w->lane_i + 4 * row;
        }
        ok = ok && (C->far_T == 0 || ts_far_ws_init(w, C));
    }
    return ok && w->stack && w->lo.prev && w->lo.cur &&
           (!need_visit || (w->vx && w->vy && w->vh && w->vs && w->vd));
}

/* Lines [b0 + begin, b0 + end) in workspace w (ws_init's), as a fresh
 * workspace would take them: nothing carried from lines w took before (the
 * line before begin is primed instead); the carries are set here, not by
 * ws_init. */
static void sweep_lines(const sweep_ctx *C, sweep_ws *w, long begin, long end)
{
    const occluder none = {-1, 0.0f};
    if (w->lockstep) {
        for (int k = 0; k < C->geom->U; k++)
            w->carry[k] = none;
        long b = C->b0 + begin, bend = C->b0 + end;
        for (int prime = begin > 0; b < bend; prime = 0) {
            int nl = bend - b < LOCKSTEP_LINES ? (int)(bend - b) : LOCKSTEP_LINES;
            sweep_block(C, w, b - prime, nl + prime, prime);
            b += nl;
        }
        return;
    }
    w->lo.prev_k0 = 1;
    w->lo.prev_k1 = 0;
    if (begin > 0)
        ts_sweep_process_line(C, w, C->b0 + begin - 1, 0);
    for (long b = C->b0 + begin; b < C->b0 + end; b++)
        ts_sweep_process_line(C, w, b, 1);
}

void ts_sweep_ranges(void *ctx, int worker, ts_range_queue *q)
{
    (void)worker;
    const sweep_ctx *C = ctx;
    sweep_ws w;
    long begin, end;
    if (ws_init(&w, C))
        while (ts_range_next(q, &begin, &end))
            sweep_lines(C, &w, begin, end);
    else
        __atomic_store_n(C->alloc_failed, 1, __ATOMIC_RELAXED);
    ws_free(&w);
}

/* Slopes to degrees over a row, in AVX-512/AVX2 clones (branch-free; the
 * same float operations at any width). */
TS_SIMD_CLONES
static void degrees_row(float *restrict o, int n)
{
    for (int x = 0; x < n; x++)
        o[x] = ts_atan_deg(o[x]);
}

void ts_slopes_to_degrees(float *o, int n)
{
    degrees_row(o, n);
}

/* Rows [y0, y1): add each cell's near field to the far-field slope the
 * lines left in out, then turn slopes into degrees. */
static void finish_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const sweep_ctx *C = ctx;
    const ts_grid *grid = C->grid;
    const ts_line_geom *G = C->geom;
    const int W = grid->width, H = grid->height, m = TS_NEAR_MARGIN;
    float *scratch = malloc(TS_NEAR_ROW_SCRATCH(W) * sizeof *scratch); /* and ts_near_edges' */
    for (long y = y0; y < y1; y++) {
        const float *zrow = grid->z + y * grid->stride;
        float *orow = C->out + y * W;
        double step = G->step_row ? G->step_row[y] : G->step_m;
        if (C->near_only) /* no lines wrote the far field */
            for (int x = 0; x < W; x++)
                orow[x] = isnan(zrow[x]) ? NAN : -INFINITY;
        /* The vectorised pass has no distance cap: it serves a distance
         * that ends beyond the near field, where the cap changes nothing. */
        int uncut = C->cap == 0 || C->cap / step >= TS_NEAR_STEPS;
        int interior = scratch && uncut && y >= m && y < H - m && W > 2 * m;
        int xa = interior ? m : W, xb = interior ? W - m : W;
        if (interior)
            ts_near_row(&C->near, zrow, xa, xb, step, C->c, orow, scratch);
        if (scratch)
            ts_near_edges(&C->near, G, grid->z, zrow, (int)y, xa, xb, W, step, C->c, C->cap,
                          orow, scratch);
        if (C->cap > 0)
            ts_cap_tail(C->geom, grid, C->cap, C->c, (int)y, zrow, orow, step);
        degrees_row(orow, W);
        if (C->edge_rows) /* while the row is at hand */
            ts_edge_row(&C->edge, (int)y);
    }
    if (!scratch)
        __atomic_store_n(C->alloc_failed, 1, __ATOMIC_RELAXED);
    free(scratch);
}

ts_status ts_sweep_setup(const ts_grid *grid, double azimuth, const ts_horizon_opts *opts,
                         ts_line_geom *geom, sweep_ctx *C, ts_error *err)
{
    ts_status st = ts_check_sweep_args(grid, &azimuth, opts, err);
    if (st != TS_OK)
        return st;
    if ((st = ts_line_geom_init(geom, grid, azimuth, err)) != TS_OK)
        return st;
    *C = (sweep_ctx){0};
    C->grid = grid;
    C->geom = geom;
    C->ray = (cm_ray_grid){grid->z, geom->V, geom->t, geom->origin, geom->u_stride,
                           geom->v_stride};
    C->c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    ts_line_out_strides(geom, grid->width, &C->o_origin, &C->o_u_stride, &C->o_v_stride);
    C->b0 = geom->b_lo;
    ts_near_plan_init(&C->near, geom);
    C->near_skip = (TS_NEAR_STEPS + 0.5) * geom->step_m;
    /* A distance no two samples of a line (nor a ray on the grid) are
     * apart is no distance: the unbounded sweep, bit for bit. */
    double longest, shortest;
    ts_line_geom_step_range(geom, grid->height, &shortest, &longest);
    C->cap = opts->max_distance > longest * geom->U ? 0.0 : opts->max_distance;
    /* Within the near field of every row, the near field is all there is. */
    C->near_only = C->cap > 0 && C->cap <= TS_NEAR_STEPS * shortest;
    if (C->cap > 0)
        ts_cap_lanes_lags(C->near_skip, C->cap, shortest, longest, C->lags);
    return TS_OK;
}

ts_status ts_horizon_sweep(const ts_grid *grid, double azimuth,
                           const ts_horizon_opts *opts, float *out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "output buffer is NULL");
    /* the options as ts_horizon_edge_apply takes them (every direction) */
    ts_status st = opts ? ts_horizon_opts_validate(opts, err) : TS_OK;
    if (st != TS_OK)
        return st;
    ts_line_geom geom;
    sweep_ctx C;
    if ((st = ts_sweep_setup(grid, azimuth, opts, &geom, &C, err)) != TS_OK)
        return st;
    int failed = 0;
    C.out = out;
    C.alloc_failed = &failed;
    C.edge_rows = ts_edge_rows_init(&C.edge, grid, azimuth, opts, out);
    long lines = geom.b_hi - geom.b_lo + 1;
    /* Ranges taken as the threads get to them (a core slowed by another
     * process, or rougher terrain, takes fewer); each range re-primes one
     * line, so they are whole lockstep blocks. */
    if (!C.near_only)
        st = ts_parallel_ranges(ts_thread_count(opts->threads, lines), lines, LOCKSTEP_LINES,
                                ts_sweep_ranges, &C, err);
    if (st == TS_OK && !failed)
        st = ts_parallel_for_ranges(ts_thread_count(opts->threads, grid->height), grid->height,
                                    TS_ROWS_GRAIN, finish_rows, &C, err);
    ts_line_geom_free(&geom);
    if (st != TS_OK)
        return st;
    if (failed)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate sweep workspace");
    /* the world beyond the edge was raised row by row (finish_rows),
     * before anyone reads the horizons */
    return ts_ok(err);
}

ts_status ts_horizon_sweep_lines(const ts_grid *grid, double azimuth,
                                 const ts_horizon_opts *opts, ts_line_visitor visit,
                                 void *user, ts_error *err)
{
    if (!visit)
        return ts_fail(err, TS_ERR_ARG, "line visitor is NULL");
    ts_line_geom geom;
    sweep_ctx C;
    ts_status st = ts_sweep_setup(grid, azimuth, opts, &geom, &C, err);
    if (st != TS_OK)
        return st;
    size_t n = (size_t)grid->width * grid->height;
    float *scratch = malloc(n * sizeof *scratch);
    if (!scratch) {
        ts_line_geom_free(&geom);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate sweep scratch");
    }
    int failed = 0;
    C.out = scratch;
    C.visit = visit;
    C.user = user;
    C.alloc_failed = &failed;
    sweep_ws w; /* one thread: the visitor sees the lines in order */
    if (ws_init(&w, &C))
        sweep_lines(&C, &w, 0, geom.b_hi - geom.b_lo + 1);
    else
        failed = 1;
    ws_free(&w);
    free(scratch);
    ts_line_geom_free(&geom);
    if (failed)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate sweep workspace");
    return ts_ok(err);
}
