/*
 * Shadow map with percentage-closer filtering, C backend: project the DEM's
 * vertices into light space, render its triangles into the depth map (each
 * thread a band of the map's rows, so no two threads write one texel), take
 * each tile's largest depth, then filter every cell against the map. The
 * formulas are those of the OpenCL kernels (core/cellmath/cm_shadowmap.h),
 * so both render the same map. The filter remembers each receiver's fan
 * depth per texel: its blocker search and its taps read the same texels
 * around the receiver two to three times over, six triangle tests each.
 */
#include <math.h>
#include <stdlib.h>

/* The filter reads each receiver's fan depths through its memo (below). */
struct ts_sm_recv_s;
static float sm_fan_depth(const struct ts_sm_recv_s *r, float x, float y);
#define TS_SM_FAN_DEPTH sm_fan_depth

#include "cellmath/cm_shadowmap.h"
#include "parallel.h"
#include "shadowmap_raster.h"
#include "status_internal.h"
#include "terrashade_shadowmap.h"

typedef struct {
    const ts_grid *g;
    const ts_shadowmap_frame *f;
    float *pu, *pv, *pd; /* projected vertices, width*height each */
    int *map;            /* f->width * f->height keys */
    float *out;
    float *seg_lo, *seg_hi; /* ts_sm_seg_bounds of every mesh row (NULL: none) */
} sm_job;

/* Most texels of a receiver's box that its memo keeps (a box is the fan's
 * extent: a few texels across, up to a few hundred tall under a low light;
 * a taller one is read without the memo). */
#define SM_MEMO_MAX 4096

/* One thread's memo of the current receiver's fan depths, and its fan's
 * triangles set up once (ts_sm_fan_depth sets them up at every call). */
typedef struct {
    unsigned *stamp; /* SM_MEMO_MAX: gen where depth[] holds this receiver's */
    float *depth;
    unsigned gen;
    int a0, b0, na, nb; /* the box's texel centres: columns a0.., rows b0.. */
    ts_sm_fan fan;
} sm_memo;

/* Start the memo on receiver r (r->memo = m). */
static void sm_memo_start(sm_memo *m, ts_sm_recv *r)
{
    r->memo = m;
    if (++m->gen == 0) { /* wrapped: every stamp is stale */
        for (int k = 0; k < SM_MEMO_MAX; k++)
            m->stamp[k] = 0;
        m->gen = 1;
    }
    ts_sm_fan_setup(r, &m->fan);
    double a0 = ceil(r->box[0]), a1 = floor(r->box[1]);
    double b0 = ceil(r->box[2]), b1 = floor(r->box[3]);
    double na = a1 - a0 + 1, nb = b1 - b0 + 1;
    m->na = m->nb = 0;
    if (na > 0 && nb > 0 && na * nb <= SM_MEMO_MAX) {
        m->a0 = (int)a0, m->b0 = (int)b0;
        m->na = (int)na, m->nb = (int)nb;
    }
}

/* ts_sm_fan_depth through the receiver's memo (its own where it has none). */
static float sm_fan_depth(const ts_sm_recv *r, float x, float y)
{
    sm_memo *m = r->memo;
    if (!m)
        return ts_sm_fan_depth(r, x, y);
    if (!ts_sm_in_box(r, x, y))
        return -INFINITY;
    const int a = (int)x - m->a0, b = (int)y - m->b0;
    if (a < 0 || b < 0 || a >= m->na || b >= m->nb || (float)(int)x != x || (float)(int)y != y)
        return ts_sm_fan_solve(&m->fan, r, x, y); /* no memo for this box, or not a texel centre */
    const int k = b * m->na + a;
    if (m->stamp[k] != m->gen) {
        m->depth[k] = ts_sm_fan_solve(&m->fan, r, x, y);
        m->stamp[k] = m->gen;
    }
    return m->depth[k];
}

static void project_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const sm_job *J = ctx;
    const ts_grid *g = J->g;
    for (long y = begin; y < end; y++) {
        float cx = (float)ts_grid_cell_x(g, (int)y);
        for (int x = 0; x < g->width; x++) {
            long i = y * g->width + x;
            ts_sm_project(J->f->params, x, (int)y, cx, ts_grid_at(g, x, (int)y), &J->pu[i],
                          &J->pv[i], &J->pd[i]);
        }
    }
}

/* The segments' bounds of mesh rows [begin, end). */
static void seg_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const sm_job *J = ctx;
    ts_sm_seg_bounds(J->pv, J->g->width, (int)begin, (int)end, J->seg_lo, J->seg_hi);
}

/* Render every quad that reaches map rows [begin, end). */
static void render_band(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const sm_job *J = ctx;
    const int mw = J->f->width;
    for (long i = begin * mw; i < end * mw; i++)
        J->map[i] = TS_SM_EMPTY;
    ts_sm_render_band_segs(J->f->params, J->map, mw, (int)begin, (int)end, J->pu, J->pv, J->pd,
                           J->g->width, J->g->height, J->seg_lo, J->seg_hi);
}

/* The tiles' largest keys, after the map: tile rows [begin, end). */
static void tile_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const sm_job *J = ctx;
    const int mw = J->f->width, mh = J->f->height, tw = (mw + TS_SM_TILE - 1) / TS_SM_TILE;
    int *tiles = J->map + (long)mw * mh;
    for (long ty = begin; ty < end; ty++)
        for (int tx = 0; tx < tw; tx++)
            tiles[ty * tw + tx] = ts_sm_tile_max(J->map, mw, mh, tx, (int)ty);
}

static void filter_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const sm_job *J = ctx;
    const ts_shadowmap_frame *f = J->f;
    const int W = J->g->width, H = J->g->height;
    sm_memo m = {.stamp = calloc(SM_MEMO_MAX, sizeof(unsigned)),
                 .depth = malloc(SM_MEMO_MAX * sizeof(float))};
    sm_memo *use = m.stamp && m.depth ? &m : NULL; /* no memory: ts_sm_fan_depth */
    for (long y = begin; y < end; y++)
        for (int x = 0; x < W; x++) {
            ts_sm_recv r;
            float near = ts_sm_recv_make(f->params, J->pu, J->pv, J->pd, W, H, x, (int)y, &r);
            if (near > 0.0f) { /* as ts_sm_cell_at */
                if (use)
                    sm_memo_start(use, &r);
                float lit = ts_sm_cell(f->params, J->map, f->width, f->height, &r);
                near = near < lit ? near : lit;
            }
            J->out[y * W + x] = near;
        }
    free(m.stamp);
    free(m.depth);
}

/* The map's rows and the cells' rows in SM_BATCHES batches between
 * reports, where the caller wants them (at a 0.5 degree sun rendering and
 * filtering took 3.7 s of a 1024^2 DEM, 18 s of a 2048^2 one). */
#define SM_BATCHES 16

ts_status ts_shadowmap_compute(const ts_grid *grid, double azimuth, double elevation,
                               const ts_shadowmap_opts *opts, float *visibility, ts_error *err)
{
    ts_shadowmap_frame f;
    ts_status st = ts_shadowmap_prepare(grid, azimuth, elevation, opts, visibility, &f, err);
    if (st != TS_OK)
        return st;
    const size_t cells = (size_t)grid->width * grid->height;
    sm_job J = {grid, &f, malloc(cells * sizeof(float)), malloc(cells * sizeof(float)),
                malloc(cells * sizeof(float)),
                malloc(ts_shadowmap_keys(&f) * sizeof(int)), visibility, NULL, NULL};
    /* a few floats a row: without them (no memory) each band scans every quad */
    const size_t nseg = grid->height > 1 && grid->width > 1
                            ? (size_t)(grid->height - 1) * TS_SM_SEGS(grid->width)
                            : 0;
    if (nseg) {
        J.seg_lo = malloc(nseg * sizeof(float));
        J.seg_hi = malloc(nseg * sizeof(float));
        if (!J.seg_lo || !J.seg_hi) {
            free(J.seg_lo);
            free(J.seg_hi);
            J.seg_lo = J.seg_hi = NULL;
        }
    }
    if (!J.pu || !J.pv || !J.pd || !J.map)
        st = ts_fail(err, TS_ERR_NOMEM, "out of memory for a %d x %d shadow map", f.width,
                     f.height);
    const int threads = opts->threads;
    ts_horizon_opts report; /* (what ts_parallel_reported reports through) */
    ts_horizon_opts_default(&report);
    report.progress = opts->progress;
    report.progress_user = opts->progress_user;
    if (st == TS_OK)
        st = ts_parallel_for(ts_thread_count(threads, grid->height), grid->height,
                             project_rows, &J, err);
    if (st == TS_OK && J.seg_lo)
        st = ts_parallel_for(ts_thread_count(threads, grid->height - 1), grid->height - 1,
                             seg_rows, &J, err);
    /* (the bar: rendering a little more than half, the filter the rest, as
     * measured at a low sun) */
    /* each band of the map scans every quad of the DEM: no more bands than
     * cores (THREADS=64 on two made the render 10x dearer, the same bits) */
    const int cores = ts_cpu_count();
    if (st == TS_OK)
        st = ts_parallel_reported(ts_thread_count(threads > 0 && threads < cores ? threads
                                                                                : cores,
                                                  f.height),
                                  f.height, 0, render_band, &J, &report, 0.0, 0.55, SM_BATCHES,
                                  err);
    const long th = (f.height + TS_SM_TILE - 1) / TS_SM_TILE;
    if (st == TS_OK)
        st = ts_parallel_for(ts_thread_count(threads, th), th, tile_rows, &J, err);
    if (st == TS_OK)
        st = ts_parallel_reported(ts_thread_count(threads, grid->height), grid->height, 0,
                                  filter_rows, &J, &report, 0.55, 1.0, SM_BATCHES, err);
    free(J.pu);
    free(J.pv);
    free(J.pd);
    free(J.map);
    free(J.seg_lo);
    free(J.seg_hi);
    return st == TS_OK ? ts_ok(err) : st;
}
