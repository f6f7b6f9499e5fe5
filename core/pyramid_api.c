/*
 * Pyramid horizons' entry points (terrashade.h): the arguments checked,
 * each azimuth's context (its direction, step table and what each level's
 * sample shares), then the batch's rows over the threads
 * (ts_pyr_rows_range, core/pyramid_horizon.c).
 */
#include <math.h>
#include <stdlib.h>

#include "arg_checks.h"
#include "parallel.h"
#include "pyramid_hz.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

/* Sample j's shares for the azimuth of C (vx, ko set). */
static void level_az_fill(const hz_ctx *C, level_az *lv)
{
    const ts_pyramid *P = C->P;
    const int W = P->grid->width;
    for (int j = 0; j < P->levels; j++) {
        double s = P->level[j].spacing, ox = s * C->vx;
        double fl = floor(ox), lf = floor(j - C->ko + 1e-9);
        lv[j] = (level_az){s,
                           (int)fl,
                           (float)(ox - fl),
                           C->vx < 0 ? (int)ceil(-ox) : 0,
                           C->vx > 0 ? (int)floor(W - 1 - ox) : W - 1,
                           lf < 0 ? 0 : (int)lf};
    }
}

/* The context of azimuth `azimuth` (checked) into C: its step table and
 * level shares allocated; 0 when out of memory. */
static int az_ctx_init(const ts_pyramid *pyr, double azimuth, const ts_horizon_opts *opts,
                       float *out, int *failed, hz_ctx *C)
{
    const ts_grid *g = pyr->grid;
    const int H = g->height;
    double a = azimuth * DEG2RAD, sa = sin(a), ca = cos(a);
    /* as the sweep: exact axis directions, the direction in cells taken at
     * the central row of a geographic grid */
    if (fabs(sa) < 1e-12) sa = 0;
    if (fabs(ca) < 1e-12) ca = 0;
    double gx = sa / ts_grid_cell_x(g, H / 2), gy = -ca / g->cell_y;
    double major = fabs(gx) > fabs(gy) ? fabs(gx) : fabs(gy);
    *C = (hz_ctx){pyr, gx / major, gy / major, NULL, 0, 0, 0, 0, 0, NULL, out, failed};
    C->step = malloc((size_t)H * sizeof *C->step);
    level_az *lv = malloc((size_t)pyr->levels * sizeof *lv);
    C->lv = lv;
    if (!C->step || !lv)
        return 0;
    for (int y = 0; y < H; y++)
        C->step[y] = hypot(ts_grid_cell_x(g, y) * C->vx, g->cell_y * C->vy);
    C->step_all = C->step[0];
    for (int y = 1; y < H; y++)
        C->step_all = C->step[y] == C->step[0] ? C->step_all : 0;
    C->c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    C->cap = opts->max_distance;
    C->ko = pyr->opts.level_step * pyr->opts.offset;
    C->bspline = pyr->opts.reconstruction == TS_PYRAMID_BSPLINE;
    level_az_fill(C, lv);
    return 1;
}

/* ts_pyramid_horizons, and with sky the sky terms of each plane added
 * span by span (ts_pyramid_horizons_sky; checked). */
static ts_status horizons_run(const ts_pyramid *pyr, int count, const double *azimuths,
                              const ts_horizon_opts *opts, const ts_pyramid_sky *sky,
                              float *const *out, ts_error *err)
{
    if (!pyr)
        return ts_fail(err, TS_ERR_ARG, "pyramid is NULL");
    if (count < 1 || count > TS_PYRAMID_BATCH)
        return ts_fail(err, TS_ERR_ARG, "azimuths at once must be 1 to %d, got %d",
                       TS_PYRAMID_BATCH, count);
    if (!azimuths)
        return ts_fail(err, TS_ERR_ARG, "azimuths are NULL");
    const ts_grid *g = pyr->grid;
    double az[TS_PYRAMID_BATCH];
    ts_status st;
    /* out NULL: no planes, only the sky sums (ts_pyramid_horizons_sky) */
    for (int k = 0; k < count; k++) {
        if ((!out && !sky) || (out && !out[k]))
            return ts_fail(err, TS_ERR_ARG, "output buffer is NULL");
        az[k] = azimuths[k];
        if ((st = ts_check_sweep_args(g, &az[k], opts, err)) != TS_OK)
            return st;
    }
    /* the edge as ts_horizon_edge_apply after the rows would, and the sky
     * terms at the caller's azimuths, as ts_sky_accumulate_model of each
     * plane in turn: each cell on its own, the same values */
    ts_edge_job edge[TS_PYRAMID_BATCH];
    ts_sky_plane terms[TS_PYRAMID_BATCH];
    int edged = 0;
    for (int k = 0; k < count; k++) {
        edged = ts_edge_rows_init(&edge[k], g, az[k], opts, out ? out[k] : NULL);
        if (sky)
            ts_sky_plane_init(&terms[k], sky->nx, sky->ny, sky->nz, out ? out[k] : NULL,
                              azimuths[k], sky->directions, sky->svf_model, sky->svf, sky->sky,
                              sky->openness);
    }
    hz_ctx C[TS_PYRAMID_BATCH];
    int failed = 0, ok = 1, k = 0;
    for (; ok && k < count; k++)
        ok = az_ctx_init(pyr, az[k], opts, out ? out[k] : NULL, &failed, &C[k]);
    if (ok) {
        batch_ctx B = {count, C, {0}, 0, edged ? edge : NULL, sky ? terms : NULL};
        for (int a = 0; a < count; a++) {
            int b = 0;
            while (b < a && C[b].vy != C[a].vy)
                b++;
            B.same_vy[a] = b;
            B.share |= b < a;
        }
        st = ts_parallel_for_ranges(ts_thread_count(opts->threads, g->height), g->height,
                                    TS_PYR_ROW_BLOCK, ts_pyr_rows_range, &B, err);
    }
    for (int i = 0; i < k; i++) {
        free(C[i].step);
        free((level_az *)C[i].lv);
    }
    if (!ok)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid's step tables");
    if (st != TS_OK)
        return st;
    if (failed)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid's row workspace");
    return ts_ok(err);
}

ts_status ts_pyramid_horizons(const ts_pyramid *pyr, int count, const double *azimuths,
                              const ts_horizon_opts *opts, float *const *out, ts_error *err)
{
    return horizons_run(pyr, count, azimuths, opts, NULL, out, err);
}

ts_status ts_pyramid_horizons_sky(const ts_pyramid *pyr, int count, const double *azimuths,
                                  const ts_horizon_opts *opts, const ts_pyramid_sky *sky,
                                  float *const *out, ts_error *err)
{
    if (!pyr || !sky)
        return ts_fail(err, TS_ERR_ARG, pyr ? "sky terms are NULL" : "pyramid is NULL");
    /* the azimuths are checked with the rest in horizons_run, before the
     * sky terms read them */
    ts_status st = ts_check_svf_model(sky->svf_model, err);
    if (st == TS_OK)
        st = ts_check_sky_args(pyr->grid, sky->nx, sky->ny, sky->nz, sky->directions, err);
    return st == TS_OK ? horizons_run(pyr, count, azimuths, opts, sky, out, err) : st;
}

ts_status ts_pyramid_horizon(const ts_pyramid *pyr, double azimuth, const ts_horizon_opts *opts,
                             float *out, ts_error *err)
{
    return ts_pyramid_horizons(pyr, 1, &azimuth, opts, &out, err);
}

ts_status ts_pyramid_horizon_compute(const ts_grid *grid, const ts_pyramid_opts *popts,
                                     const ts_horizon_opts *opts, float *out, ts_error *err)
{
    ts_status st = ts_check_horizon_compute_args(grid, opts, out, err);
    if (st != TS_OK)
        return st;
    ts_pyramid *pyr;
    if ((st = ts_pyramid_build(grid, popts, opts->threads, &pyr, err)) != TS_OK)
        return st;
    size_t plane = (size_t)grid->width * (size_t)grid->height;
    for (int k = 0; st == TS_OK && k < opts->directions; k += TS_PYRAMID_BATCH) {
        int n = opts->directions - k < TS_PYRAMID_BATCH ? opts->directions - k : TS_PYRAMID_BATCH;
        double az[TS_PYRAMID_BATCH];
        float *planes[TS_PYRAMID_BATCH];
        for (int i = 0; i < n; i++) {
            az[i] = ts_horizon_azimuth(opts, k + i);
            planes[i] = out + plane * (k + i);
        }
        if ((st = ts_progress(opts, (double)k / opts->directions, err)) == TS_OK)
            st = ts_pyramid_horizons(pyr, n, az, opts, planes, err);
    }
    ts_pyramid_free(pyr);
    if (st == TS_OK)
        st = ts_progress(opts, 1.0, err);
    return st == TS_OK ? ts_ok(err) : st;
}
