/*
 * The multi-resolution pyramid of Snyder & Nowrouzezahrai (2008), built for
 * pyramid horizons (pyramid_horizon.c): levels of spacing b^j cells,
 * b = 2^(1/k), each decimated bilinearly from the one before, then
 * reconstructed along x at every DEM column with the cubic B-spline
 * (pyramid_internal.h says how the levels are laid out).
 *
 * Nodata: a decimated sample is the weighted mean of the valid samples
 * under its bilinear footprint, and nodata when less than half of that
 * footprint (carried down as a coverage fraction) is valid, so that holes
 * neither grow nor fill in as the levels coarsen. The B-spline
 * reconstruction renormalises the same way.
 */
#include <math.h>
#include <stdlib.h>

#include "parallel.h"
#include "pyramid_internal.h"
#include "status_internal.h"

#define MAX_LEVEL_STEP 16.0
#define MAX_OFFSET 64.0

void ts_pyramid_opts_default(ts_pyramid_opts *opts)
{
    if (!opts)
        return;
    opts->level_step = 4.0;
    opts->offset = 0.0;
    opts->reconstruction = TS_PYRAMID_BSPLINE;
}

ts_status ts_pyramid_opts_validate(const ts_pyramid_opts *opts, ts_error *err)
{
    if (!opts)
        return ts_fail(err, TS_ERR_ARG, "pyramid options are NULL");
    if (!(opts->level_step >= 1 && opts->level_step <= MAX_LEVEL_STEP))
        return ts_fail(err, TS_ERR_ARG,
                       "pyramid level step k must be between 1 (a power-of-2 pyramid) and "
                       "%g (b = 2^(1/k) levels per halving), got %g",
                       MAX_LEVEL_STEP, opts->level_step);
    if (!(opts->offset >= 0 && opts->offset <= MAX_OFFSET))
        return ts_fail(err, TS_ERR_ARG,
                       "pyramid level offset o must be between 0 and %g (levels of k o finer), "
                       "got %g",
                       MAX_OFFSET, opts->offset);
    if (opts->reconstruction != TS_PYRAMID_BSPLINE &&
        opts->reconstruction != TS_PYRAMID_LEVEL_MAX)
        return ts_fail(err, TS_ERR_ARG,
                       "pyramid reconstruction must be TS_PYRAMID_BSPLINE or "
                       "TS_PYRAMID_LEVEL_MAX, got %d",
                       (int)opts->reconstruction);
    return ts_ok(err);
}

int ts_pyramid_level_count(int width, int height, double level_step)
{
    if (width < 1 || height < 1 || !(level_step >= 1 && level_step <= MAX_LEVEL_STEP))
        return 0;
    int n = width > height ? width : height;
    return (int)ceil(level_step * log2((double)n) - 1e-9) + 1;
}

/* Samples of a level of spacing s along an axis of n DEM cells: enough
 * that the last sample centre reaches the last cell. */
static int level_size(int n, double s)
{
    int m = (int)ceil((n - 0.5) / s + 0.5 - 1e-9);
    return m < 1 ? 1 : m;
}

static double spacing(double level_step, int j)
{
    return exp2(j / level_step);
}

double ts_pyramid_bytes(int width, int height, double level_step)
{
    int levels = ts_pyramid_level_count(width, height, level_step);
    double rows = 0;
    for (int j = 1; j < levels; j++)
        rows += level_size(height, spacing(level_step, j));
    return rows * width * sizeof(float);
}

/* Samples of the largest coarse level (level 1), which sizes the build's
 * four decimation buffers; 1 where there is none. */
static size_t level1_cells(int width, int height, double level_step)
{
    if (ts_pyramid_level_count(width, height, level_step) < 2)
        return 1;
    const double s = spacing(level_step, 1);
    return (size_t)level_size(width, s) * level_size(height, s);
}

double ts_pyramid_build_bytes(int width, int height, double level_step)
{
    /* the four decimation buffers and the two edge-column pairs (2 x height each) */
    return ts_pyramid_bytes(width, height, level_step) +
           (4.0 * level1_cells(width, height, level_step) + 4.0 * height) * sizeof(float);
}

/* A level before reconstruction: its samples (rows `stride` floats apart)
 * and their valid fraction (NULL: all valid, as the DEM's). */
typedef struct {
    int w, h;
    double s;
    float *z, *cov;
    ptrdiff_t stride;
} coarse;

typedef struct {
    const coarse *src;
    coarse *dst;
    /* each column's taps on src (ts_pyr_taps, linear): their number, 4
     * columns and 4 weights; the same for every row, so found once */
    const int *nx, *cx;
    const double *cw;
} decimate_ctx;

/* Rows [r0, r1) of dst from src by bilinear decimation. */
static void decimate_rows(void *ctx, int worker, long r0, long r1)
{
    (void)worker;
    const decimate_ctx *C = ctx;
    const coarse *S = C->src;
    coarse *D = C->dst;
    const double ratio = D->s / S->s;
    for (long r = r0; r < r1; r++) {
        int ry[4];
        double wy[4];
        int ny = ts_pyr_taps((r + 0.5) * ratio - 0.5, S->h, 1, ry, wy);
        for (int i = 0; i < D->w; i++) {
            const int nx = C->nx[i], *rx = C->cx + 4 * (size_t)i;
            const double *wx = C->cw + 4 * (size_t)i;
            double sum = 0, wsum = 0, cov = 0;
            for (int a = 0; a < ny; a++)
                for (int b = 0; b < nx; b++) {
                    double w = wy[a] * wx[b];
                    size_t k = (size_t)ry[a] * S->stride + rx[b];
                    float z = S->z[k];
                    if (z != z)
                        continue;
                    sum += w * z;
                    wsum += w;
                    cov += w * (S->cov ? S->cov[(size_t)ry[a] * S->w + rx[b]] : 1.0);
                }
            size_t o = (size_t)r * D->w + i;
            D->cov[o] = (float)cov;
            D->z[o] = cov >= 0.5 && wsum > 0 ? (float)(sum / wsum) : NAN;
        }
    }
}

typedef struct {
    const coarse *lv;
    float *hu;
    int width;
    const int *idx;       /* width x 4 column taps */
    const double *w;      /* width x 4 weights */
} recon_ctx;

/* Rows [r0, r1) of a level reconstructed at every DEM column. */
static void reconstruct_rows(void *ctx, int worker, long r0, long r1)
{
    (void)worker;
    const recon_ctx *C = ctx;
    for (long r = r0; r < r1; r++) {
        const float *src = C->lv->z + (size_t)r * C->lv->w;
        float *dst = C->hu + (size_t)r * C->width;
        for (int x = 0; x < C->width; x++) {
            const int *ix = C->idx + 4 * (size_t)x;
            const double *w = C->w + 4 * (size_t)x;
            double sum = 0, wsum = 0;
            for (int t = 0; t < 4; t++) {
                float z = src[ix[t]];
                if (z == z)
                    sum += w[t] * z, wsum += w[t];
            }
            dst[x] = wsum >= 0.5 ? (float)(sum / wsum) : NAN;
        }
    }
}

void ts_pyramid_free(ts_pyramid *pyr)
{
    if (!pyr)
        return;
    for (int j = 0; pyr->level && j < pyr->levels; j++)
        free(pyr->level[j].hu);
    free(pyr->level);
    free(pyr->pair[0]);
    free(pyr->pair[1]);
    free(pyr);
}

/* Level j's reconstruction from its samples; 0 when out of memory. */
static int reconstruct(ts_pyramid *P, const coarse *lv, int j, int threads, ts_error *err)
{
    const int W = P->grid->width;
    int *idx = malloc((size_t)W * 4 * sizeof *idx);
    double *w = malloc((size_t)W * 4 * sizeof *w);
    /* on cache lines: the run loops read whole vectors of a row */
    P->level[j].hu = ts_pyr_alloc((size_t)lv->h * W * sizeof(float));
    if (!idx || !w || !P->level[j].hu) {
        free(idx);
        free(w);
        return 0;
    }
    for (int x = 0; x < W; x++)
        ts_pyr_taps((x + 0.5) / lv->s - 0.5, lv->w, 0, idx + 4 * (size_t)x, w + 4 * (size_t)x);
    recon_ctx rc = {lv, P->level[j].hu, W, idx, w};
    ts_parallel_for_ranges(ts_thread_count(threads, lv->h), lv->h, TS_ROWS_GRAIN, reconstruct_rows,
                           &rc, err);
    free(idx);
    free(w);
    return 1;
}

ts_status ts_pyramid_build(const ts_grid *grid, const ts_pyramid_opts *opts, int threads,
                           ts_pyramid **out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "pyramid output pointer is NULL");
    *out = NULL;
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK || (st = ts_pyramid_opts_validate(opts, err)) != TS_OK)
        return st;
    if (threads < 0)
        return ts_fail(err, TS_ERR_ARG, "threads must be 0 (all cores) or more, got %d",
                       threads);
    ts_pyramid *P = calloc(1, sizeof *P);
    if (!P)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid");
    P->grid = grid;
    P->opts = *opts;
    P->levels = ts_pyramid_level_count(grid->width, grid->height, opts->level_step);
    P->level = calloc((size_t)P->levels, sizeof *P->level);
    if (!P->level) {
        ts_pyramid_free(P);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid");
    }
    /* level 0 is the DEM, decimated from where it lies; the coarse levels
     * alternate between two buffers sized for level 1 (the largest), so
     * that their pages are faulted in once, not once a level */
    const int W = grid->width, H = grid->height;
    coarse prev = {W, H, 1.0, grid->z, NULL, grid->stride};
    P->level[0] = (ts_pyr_level){1.0, H, NULL};
    size_t most = level1_cells(W, H, opts->level_step);
    float *buf[2][2] = {{malloc(most * sizeof(float)), malloc(most * sizeof(float))},
                        {malloc(most * sizeof(float)), malloc(most * sizeof(float))}};
    P->pair[0] = malloc((size_t)2 * H * sizeof(float));
    P->pair[1] = malloc((size_t)2 * H * sizeof(float));
    int ok = buf[0][0] && buf[0][1] && buf[1][0] && buf[1][1] && P->pair[0] && P->pair[1];
    for (int y = 0; ok && y < H; y++) {
        const float *z = grid->z + (ptrdiff_t)y * grid->stride;
        P->pair[0][2 * y] = z[0];
        P->pair[0][2 * y + 1] = z[W > 1];
        P->pair[1][2 * y] = z[W > 1 ? W - 2 : 0];
        P->pair[1][2 * y + 1] = z[W - 1];
    }
    /* the column taps of the largest coarse level */
    const size_t most_w = P->levels > 1 ? (size_t)level_size(W, spacing(opts->level_step, 1)) : 1;
    int *nx = malloc(most_w * sizeof *nx), *cx = malloc(4 * most_w * sizeof *cx);
    double *cw = malloc(4 * most_w * sizeof *cw);
    ok = ok && nx && cx && cw;
    for (int j = 1; ok && j < P->levels; j++) {
        double s = spacing(opts->level_step, j);
        coarse cur = {level_size(W, s), level_size(H, s), s, buf[j % 2][0], buf[j % 2][1], 0};
        cur.stride = cur.w;
        const double ratio = cur.s / prev.s;
        for (int i = 0; i < cur.w; i++)
            nx[i] = ts_pyr_taps((i + 0.5) * ratio - 0.5, prev.w, 1, cx + 4 * (size_t)i,
                                cw + 4 * (size_t)i);
        decimate_ctx dc = {&prev, &cur, nx, cx, cw};
        ts_parallel_for_ranges(ts_thread_count(threads, cur.h), cur.h, TS_ROWS_GRAIN,
                               decimate_rows, &dc, err);
        P->level[j] = (ts_pyr_level){s, cur.h, NULL};
        ok = reconstruct(P, &cur, j, threads, err);
        prev = cur;
    }
    for (int i = 0; i < 4; i++)
        free(buf[i / 2][i % 2]);
    free(nx);
    free(cx);
    free(cw);
    if (!ok) {
        ts_pyramid_free(P);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid's levels (%.0f MiB)",
                       ts_pyramid_bytes(W, H, opts->level_step) / 1048576.0);
    }
    *out = P;
    return ts_ok(err);
}
