/*
 * The horizon sweep's state, shared by its two halves: horizon_sweep.c
 * (set-up, the lines in lockstep blocks, the near field and the entry
 * points) and sweep_line.c (a line on its own: capped lines with sliding
 * window hulls, and the line visitor). Internal to core/.
 */
#ifndef TS_SWEEP_INTERNAL_H
#define TS_SWEEP_INTERNAL_H

#include <stddef.h>

#include "capped_lanes.h"
#include "horizon_edge.h"
#include "line_geometry.h"
#include "near_field.h"
#include "parallel.h"
#include "terrashade.h"
#include "window_hull.h"

typedef ts_hull_pt hull_pt;

/* The far-field occluder a hull query found: its step index on the line and
 * its distance from the query point; k < 0 when there is none. */
typedef struct {
    int k;
    float dd;
} occluder;

typedef struct {
    const ts_grid *grid;
    const ts_line_geom *geom;
    double c;           /* curvature coefficient (1-k)/(2R), 0 when off */
    double cap;         /* max distance in metres, 0 = none */
    float *out;         /* slopes, row stride = width */
    ptrdiff_t o_origin, o_u_stride, o_v_stride;
    long b0;            /* first line */
    /* visitor mode (single-threaded) */
    ts_line_visitor visit;
    void *user;
    int *alloc_failed;  /* set by a worker that cannot get its workspace */
    ts_near_plan near;
    double near_skip;   /* hull points closer than this are near field */
    int near_only;      /* the distance ends inside the near field: no lines */
    cm_ray_grid ray;    /* the grid as the geometry sees it, for cm_ray_slope */
    int lags[4];        /* with a maximum distance: the steps back a window spans
                           (ts_cap_lanes_lags) */
    ts_edge_job edge;   /* the world beyond the edge, raised row by row */
    int edge_rows;      /* whether finish_rows raises (not TS_EDGE_OPEN) */
    /* the far-only sweep (sweep_far.c; far_T > 0): a sample joins its
     * line's hull once the line is far_T metres past it, observers stand
     * far_dz above the cells, a line's samples wait in far_slots steps */
    double far_T;
    float far_dz;
    int far_slots;
} sweep_ctx;

typedef struct {
    hull_pt *stack;
    int n;
    hull_pt *raw;       /* with a maximum distance: the line's valid samples */
    int raw_n;
    ts_window_hull win; /* with a maximum distance: the far-field window */
    ts_window_hull vwin; /* and the visitor's (all samples within the distance) */
    int finger[3][2];   /* where the window queries of each kind last ended */
    ts_line_pair lo;    /* occluders of the far side (occluder entries) */
    /* visitor buffers */
    float *vx, *vy, *vh, *vs;
    double *vd;
    /* unbounded sweep: the lines of a block, swept in lockstep */
    hull_pt *lane_stacks; /* line j's hull at lane_stacks + j * (U + 1) */
    int *lane_n, *lane_far; /* its size, its top-most point beyond the near field */
    double *lane_beside;    /* NULL, or TS_BESIDE rows of LANE_ROW: ts_lane_hulls' */
    occluder *carry, *carry_next; /* far-side occluders from the line before */
    /* the block's current step, by line (one entry more than lines) */
    float *lane_f;      /* holds: */
    float *hc, *hn, *hs, *slope; /* samples (lane_passes.h), far-field slopes */
    float *lo_dd, *hi_dd;
    int *lane_i;        /* holds: */
    int *lo_k, *hi_k;   /* far-field occluders; lo_k[j]: from line j - 1 */
    int *lane_k0;       /* each line's first step */
    int *lane_k1;       /* and last on the grid (-1: none) */
    int *lost;          /* the far field's lost flags (ts_lane_lost) */
    double *lane_d;     /* and the distance of its current sample from it */
    ts_cap_lanes capl;  /* capped lines in lockstep: their windows */
    double *far_ring;   /* far-only: the block's samples (d, then g) by step
                           k % far_slots, far_stride lines a slot */
    int far_stride;
    ts_lane_pushes far_push; /* and the hulls' delayed pushes from it */
    int lockstep;       /* lines in lockstep blocks (sweep_block), not one by one */
    int hybrid;         /* capped lines in lockstep keep unbounded hulls too */
} sweep_ws;

/* Lines swept together in one block: at each step they read and write
 * neighbouring cells of one grid row (or column), so memory streams. */
#ifndef LOCKSTEP_LINES
#define LOCKSTEP_LINES 64
#endif

/* Steps on either side of a line's occluder at which the cell's ray is
 * also sampled. */
#ifndef FAR_SPREAD
#define FAR_SPREAD 0
#endif

/* The far-field occluder of a point at distance d and hull height g among
 * the points 0..far (far >= 0) of an unbounded line's hull S, its index:
 * walk to nearer points while the slope grows (the slopes to an upper
 * convex hull from a point beyond it are unimodal). */
static inline int stack_tangent(const hull_pt *S, int far, double d, double g)
{
    int j = far;
    while (j > 0 && (S[j - 1].g - g) * (d - S[j].d) >= (S[j].g - g) * (d - S[j - 1].d))
        j--;
    return j;
}

/* The same as (the occluder's step, its distance); k = -1: none. */
static inline occluder stack_query(const hull_pt *S, int far, double d, double g)
{
    if (far < 0)
        return (occluder){-1, 0.0f};
    const int j = stack_tangent(S, far, d, g);
    return (occluder){S[j].k, (float)(d - S[j].d)};
}

/* Move far (the top-most hull point at least near_skip behind d) up: d
 * only grows, so it moves in O(1) amortised. */
static inline int far_advance(const hull_pt *S, int n, int far, double d, double near_skip)
{
    while (far + 1 < n && d - S[far + 1].d >= near_skip)
        far++;
    return far;
}

/* Push (d, gs, k) onto the unbounded hull S of *n points, popping the points
 * it hides, and keep *far; returns the hull's size before the push (its top
 * is the sample's own occluder on the line). */
static inline int hull_push(hull_pt *S, int *n, int *far, double d, double gs, int k,
                            double near_skip)
{
    int m = *n;
    while (m >= 2 && (S[m - 2].g - gs) * (d - S[m - 1].d) >= (S[m - 1].g - gs) * (d - S[m - 2].d))
        m--;
    /* Pops only take from the top, so far is at most the new top. */
    int f = *far > m - 1 ? m - 1 : *far;
    *far = far_advance(S, m, f, d, near_skip);
    S[m].d = d;
    S[m].g = gs;
    S[m].k = k;
    *n = m + 1;
    return m;
}

/* Line b on its own: pushes its samples into its hull (or sliding window)
 * and writes the far field of its cells when `write` (a line before a
 * thread's first is only primed); with a visitor, hands it the samples. */
void ts_sweep_process_line(const sweep_ctx *C, sweep_ws *w, long b, int write);

/* The sweep's set-up and checks (every entry point's), and its lines of
 * every range [begin, end) a worker takes (a ts_ranges_fn: lines [b0 +
 * begin, b0 + end), the line before each range primed, then each written;
 * one workspace for them all) (horizon_sweep.c). */
ts_status ts_sweep_setup(const ts_grid *grid, double azimuth, const ts_horizon_opts *opts,
                         ts_line_geom *geom, sweep_ctx *C, ts_error *err);
void ts_sweep_ranges(void *ctx, int worker, ts_range_queue *q);

/* The far-only sweep's parts of a lockstep block (sweep_far.c): its
 * workspace; step k's samples of lines j0..j1 into its ring slot (the
 * block's other nl lines none) with the observers raised; a pass of the
 * step's pushes (ts_lane_delayed_pushes). */
int ts_far_ws_init(sweep_ws *w, const sweep_ctx *C);
void ts_far_ws_free(sweep_ws *w);
void ts_far_store(const sweep_ctx *C, sweep_ws *w, int k, int nl, int j0, int j1);
int ts_far_pushes(const sweep_ctx *C, sweep_ws *w, ts_lane_step *step);

#endif
