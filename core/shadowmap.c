/*
 * Shadow map with percentage-closer filtering, C backend: project the DEM's
 * vertices into light space, render its triangles into the depth map (each
 * thread a band of the map's rows, so no two threads write one texel), take
 * each tile's largest depth, then filter every cell against the map. The
 * formulas are those of the OpenCL kernels (core/cellmath/cm_shadowmap.h),
 * so both render the same map.
 */
#include <math.h>
#include <stdlib.h>

#include "cellmath/cm_shadowmap.h"
#include "parallel.h"
#include "status_internal.h"
#include "terrashade_shadowmap.h"

typedef struct {
    const ts_grid *g;
    const ts_shadowmap_frame *f;
    float *pu, *pv, *pd; /* projected vertices, width*height each */
    int *map;            /* f->width * f->height keys */
    float *out;
} sm_job;

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

/* Render every quad that reaches map rows [begin, end). */
static void render_band(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const sm_job *J = ctx;
    const int W = J->g->width, H = J->g->height, mw = J->f->width;
    for (long i = begin * mw; i < end * mw; i++)
        J->map[i] = TS_SM_EMPTY;
    for (int y = 0; y + 1 < H; y++)
        for (int x = 0; x + 1 < W; x++) {
            long i = (long)y * W + x;
            float a = J->pv[i], b = J->pv[i + 1], c = J->pv[i + W], d = J->pv[i + W + 1];
            float lo = fminf(fminf(a, b), fminf(c, d)), hi = fmaxf(fmaxf(a, b), fmaxf(c, d));
            if (hi < (float)begin - 1.0f || lo > (float)end) /* NaN: in, then skipped */
                continue;
            ts_sm_quad(J->f->params, J->map, mw, J->f->height, (int)begin, (int)end, J->pu,
                       J->pv, J->pd, W, x, y);
        }
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
    const int W = J->g->width, H = J->g->height;
    for (long y = begin; y < end; y++)
        for (int x = 0; x < W; x++)
            J->out[y * W + x] = ts_sm_cell_at(J->f->params, J->map, J->f->width, J->f->height,
                                              J->pu, J->pv, J->pd, W, H, x, (int)y);
}

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
                malloc(ts_shadowmap_keys(&f) * sizeof(int)), visibility};
    if (!J.pu || !J.pv || !J.pd || !J.map)
        st = ts_fail(err, TS_ERR_NOMEM, "out of memory for a %d x %d shadow map", f.width,
                     f.height);
    const int threads = opts->threads;
    if (st == TS_OK)
        st = ts_parallel_for(ts_thread_count(threads, grid->height), grid->height,
                             project_rows, &J, err);
    if (st == TS_OK)
        st = ts_parallel_for(ts_thread_count(threads, f.height), f.height, render_band, &J,
                             err);
    const long th = (f.height + TS_SM_TILE - 1) / TS_SM_TILE;
    if (st == TS_OK)
        st = ts_parallel_for(ts_thread_count(threads, th), th, tile_rows, &J, err);
    if (st == TS_OK)
        st = ts_parallel_for(ts_thread_count(threads, grid->height), grid->height,
                             filter_rows, &J, err);
    free(J.pu);
    free(J.pv);
    free(J.pd);
    free(J.map);
    return st == TS_OK ? ts_ok(err) : st;
}
