/*
 * Environment light from horizons and Timonen's L_p table (Timonen &
 * Westerholm 2010, eq. 6): one horizon plane at a time, so a caller keeps
 * only one plane in memory, as with ts_sky_accumulate. The per-cell maths
 * is core/cellmath/env_light.h, shared with the OpenCL kernels.
 */
#include <math.h>
#include <string.h>

#include "arg_checks.h"
#include "cellmath/env_light.h"
#include "parallel.h"
#include "simd_clones.h"
#include "status_internal.h"
#include "terrashade_env.h"

#define DEG2RAD (M_PI / 180.0)

typedef struct {
    const ts_grid *g;
    const float *nx, *ny, *nz, *plane, *lp;
    float sa, ca;
    int nn, nh;
    float *r, *gr, *b;
} light_ctx;

/* Cells per block of the exact form's two passes (on the stack). */
#define LIGHT_BLOCK 256

/* Cells i0..i1 (cloned for wider vectors where the CPU has them: the
 * exact form's placing pass vectorises). */
TS_SIMD_CLONES
static void light_cells(const light_ctx *C, size_t i0, size_t i1)
{
    if (C->nn) {
        for (size_t i = i0; i < i1; i++) {
            float r = C->r[i], g = C->gr[i], b = C->b[i];
            cm_env_light_sector(C->nx[i], C->ny[i], C->nz[i], C->plane[i], C->sa, C->ca, C->lp,
                                C->nn, C->nh, &r, &g, &b);
            C->r[i] = r, C->gr[i] = g, C->b[i] = b;
        }
        return;
    }
    const float *restrict nx = C->nx, *restrict ny = C->ny, *restrict nz = C->nz;
    const float *restrict plane = C->plane, *restrict lp = C->lp;
    float *restrict R = C->r, *restrict G = C->gr, *restrict B = C->b;
    const float sa = C->sa, ca = C->ca;
    const int nh = C->nh;
    int node[LIGHT_BLOCK];
    float frac[LIGHT_BLOCK], inplane[LIGHT_BLOCK];
    for (size_t s = i0; s < i1; s += LIGHT_BLOCK) {
        int m = (int)(i1 - s < LIGHT_BLOCK ? i1 - s : LIGHT_BLOCK);
        for (int q = 0; q < m; q++) /* vectorised: no table reads */
            node[q] = cm_env_exact_place(nx[s + q], ny[s + q], nz[s + q], plane[s + q], sa, ca,
                                         nh, &frac[q], &inplane[q]);
        for (int q = 0; q < m; q++) {
            float r = R[s + q], g = G[s + q], b = B[s + q];
            cm_env_exact_add(lp, node[q], frac[q], inplane[q], nz[s + q], &r, &g, &b);
            R[s + q] = r, G[s + q] = g, B[s + q] = b;
        }
    }
}

static void light_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const light_ctx *C = ctx;
    const size_t W = (size_t)C->g->width;
    light_cells(C, (size_t)y0 * W, (size_t)y1 * W);
}

static ts_status check_outputs(const ts_grid *grid, const float *r, const float *g,
                               const float *b, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!r || !g || !b)
        return ts_fail(err, TS_ERR_ARG, "the red, green and blue outputs must not be NULL");
    return TS_OK;
}

static ts_status check_table(const ts_env_table *t, ts_error *err)
{
    if (!t || !t->lp || t->directions < 1 || t->normal_steps == 1 || t->normal_steps < 0 ||
        t->horizon_steps < 2)
        return ts_fail(err, TS_ERR_ARG, "the light table is missing or was not built");
    return TS_OK;
}

ts_status ts_check_env_light_request(const ts_env_light_request *req, ts_error *err)
{
    if (!req)
        return ts_fail(err, TS_ERR_ARG, "the environment light request must not be NULL");
    ts_status st = check_outputs(req->grid, req->r, req->g, req->b, err);
    if (st == TS_OK)
        st = check_table(req->table, err);
    if (st != TS_OK)
        return st;
    if (!req->nx || !req->ny || !req->nz || !req->plane)
        return ts_fail(err, TS_ERR_ARG, "normals and the horizon plane must not be NULL");
    if (req->k < 0 || req->k >= req->table->directions)
        return ts_fail(err, TS_ERR_ARG, "sector %d is outside the light table's %d directions",
                       req->k, req->table->directions);
    return TS_OK;
}

size_t ts_env_table_sector_floats(const ts_env_table *table)
{
    size_t rows = table->normal_steps ? (size_t)table->normal_steps : 1;
    return rows * table->horizon_steps * 8;
}

void ts_env_sector_sincos(const ts_env_table *table, int k, float *sa, float *ca)
{
    double az = ts_env_table_azimuth(table, k) * DEG2RAD;
    *sa = (float)sin(az);
    *ca = (float)cos(az);
}

ts_status ts_env_light_accumulate(const ts_env_light_request *req, ts_error *err)
{
    ts_status st = ts_check_env_light_request(req, err);
    if (st != TS_OK)
        return st;
    const ts_env_table *table = req->table;
    float sa, ca;
    ts_env_sector_sincos(table, req->k, &sa, &ca);
    light_ctx C = {req->grid, req->nx, req->ny, req->nz, req->plane,
                   table->lp + ts_env_table_sector_floats(table) * req->k, sa, ca,
                   table->normal_steps, table->horizon_steps, req->r, req->g, req->b};
    const int rows = req->grid->height;
    return ts_parallel_for_ranges(ts_thread_count(req->threads, rows), rows, TS_ROWS_GRAIN,
                                  light_rows, &C, err);
}

ts_status ts_env_light_finish(const ts_grid *grid, float *r, float *g, float *b, ts_error *err)
{
    ts_status st = check_outputs(grid, r, g, b, err);
    if (st != TS_OK)
        return st;
    size_t n = (size_t)grid->width * grid->height;
    float *out[3] = {r, g, b};
    for (int c = 0; c < 3; c++)
        for (size_t i = 0; i < n; i++)
            if (out[c][i] < 0.0f)
                out[c][i] = 0.0f;
    return ts_ok(err);
}

ts_status ts_env_light(const ts_grid *grid, const ts_env_table *table, const float *nx,
                       const float *ny, const float *nz, const float *horizons,
                       const ts_horizon_opts *opts, float *r, float *g, float *b,
                       ts_error *err)
{
    ts_status st = ts_horizon_opts_validate(opts, err);
    if (st == TS_OK)
        st = check_outputs(grid, r, g, b, err);
    if (st == TS_OK)
        st = check_table(table, err);
    if (st != TS_OK)
        return st;
    if (!horizons)
        return ts_fail(err, TS_ERR_ARG, "horizons must not be NULL");
    if (opts->directions != table->directions ||
        fabs(ts_horizon_azimuth(opts, 0) - ts_env_table_azimuth(table, 0)) > 1e-9)
        return ts_fail(err, TS_ERR_ARG, "the horizons (%d directions from %g deg) do not match "
                       "the light table (%d directions from %g deg)", opts->directions,
                       ts_horizon_azimuth(opts, 0), table->directions,
                       ts_env_table_azimuth(table, 0));
    size_t n = (size_t)grid->width * grid->height;
    memset(r, 0, n * sizeof *r);
    memset(g, 0, n * sizeof *g);
    memset(b, 0, n * sizeof *b);
    ts_env_light_request req = {grid, table, 0, nx, ny, nz, NULL, r, g, b, 0};
    for (req.k = 0; req.k < table->directions; req.k++) {
        req.plane = horizons + n * req.k;
        if ((st = ts_env_light_accumulate(&req, err)) != TS_OK)
            return st;
    }
    return ts_env_light_finish(grid, r, g, b, err);
}
