/*
 * Sky terms from horizons: sky-view factor with the surface normal and
 * uniform-sky light (Timonen & Westerholm 2010, eq. 4-5 with c = 1), the
 * solid-angle sky-view factor (Zaksek et al. 2011), and openness. Each
 * azimuth k is a swath of 360/n degrees; inside it the sky is visible from
 * zenith down to theta_k = min(horizon zenith angle, the zenith angle where
 * the tangent plane cuts azimuth k).
 */
#include <math.h>
#include <string.h>

#include "arg_checks.h"
#include "cellmath/cm_sky.h"
#include "parallel.h"
#include "simd_clones.h"
#include "sky_plane.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

void ts_sky_plane_init(ts_sky_plane *p, const float *nx, const float *ny, const float *nz,
                       const float *plane, double azimuth, int directions,
                       ts_svf_model svf_model, float *svf, float *sky, float *open)
{
    *p = (ts_sky_plane){nx, ny, nz, plane,
                        (float)sin(azimuth * DEG2RAD), (float)cos(azimuth * DEG2RAD),
                        (float)(1.0 / directions), (float)(sin(M_PI / directions) / M_PI),
                        svf_model, svf, sky, open};
}

/* One loop per term, each vectorised (cm_sky.h carries NaN explicitly,
 * because the comparisons drop it); AVX-512/AVX2 clones, the same bits.
 * `plane` holds the horizons of cells [i0, i1) from its first float on. */
TS_SIMD_CLONES void ts_sky_plane_add_span(const ts_sky_plane *C, const float *plane, size_t i0,
                                          size_t i1)
{
    const size_t n = i1 - i0;
    const float *restrict nx = C->nx + i0, *restrict ny = C->ny + i0, *restrict nz = C->nz + i0;
    const float *restrict h = plane;
    const float sa = C->sa, ca = C->ca, w1 = C->w1, w2 = C->w2;
    float *restrict acc[2] = {C->svf ? C->svf + i0 : NULL, C->sky ? C->sky + i0 : NULL};
    if (C->svf && C->svf_model == TS_SVF_SOLID_ANGLE) {
        float *restrict svf = acc[0];
        for (size_t i = 0; i < n; i++)
            svf[i] += cm_svf_solid_term(h[i], w1) + (nz[i] - nz[i]);
        acc[0] = NULL;
    }
    for (int term = 0; term < 2; term++) {
        float *restrict out = acc[term];
        if (!out)
            continue;
        for (size_t i = 0; i < n; i++)
            out[i] += cm_sky_term(nx[i], ny[i], nz[i], h[i], sa, ca, w1, w2, term == 1);
    }
    if (C->open) {
        float *restrict open = C->open + i0;
        for (size_t i = 0; i < n; i++)
            open[i] += cm_openness_term(h[i], nz[i]);
    }
}

void ts_sky_plane_add(const ts_sky_plane *C, size_t i0, size_t i1)
{
    ts_sky_plane_add_span(C, C->plane + i0, i0, i1);
}

typedef struct {
    size_t width;
    ts_sky_plane p;
} sky_ctx;

static void sky_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const sky_ctx *C = ctx;
    ts_sky_plane_add(&C->p, (size_t)y0 * C->width, (size_t)y1 * C->width);
}

ts_status ts_sky_accumulate(const ts_grid *grid, const float *nx, const float *ny,
                            const float *nz, const float *plane, double azimuth,
                            int directions, float *svf_acc, float *sky_acc,
                            float *openness_acc, ts_error *err)
{
    return ts_sky_accumulate_model(grid, nx, ny, nz, plane, azimuth, directions,
                                   TS_SVF_RADIATIVE, 0, svf_acc, sky_acc, openness_acc, err);
}

ts_status ts_check_svf_model(ts_svf_model model, ts_error *err)
{
    if (model != TS_SVF_RADIATIVE && model != TS_SVF_SOLID_ANGLE)
        return ts_fail(err, TS_ERR_ARG,
                       "svf model must be TS_SVF_RADIATIVE or TS_SVF_SOLID_ANGLE, got %d",
                       (int)model);
    return ts_ok(err);
}

ts_status ts_sky_accumulate_model(const ts_grid *grid, const float *nx, const float *ny,
                                  const float *nz, const float *plane, double azimuth,
                                  int directions, ts_svf_model svf_model, int threads,
                                  float *svf_acc, float *sky_acc, float *openness_acc,
                                  ts_error *err)
{
    ts_status st = ts_check_svf_model(svf_model, err);
    if (st != TS_OK)
        return st;
    st = ts_check_sky_args(grid, nx, ny, nz, directions, err);
    if (st != TS_OK)
        return st;
    if (!plane)
        return ts_fail(err, TS_ERR_ARG, "horizon plane must not be NULL");
    if (!isfinite(azimuth))
        return ts_fail(err, TS_ERR_ARG, "azimuth must be a finite number of degrees, got %g",
                       azimuth);
    sky_ctx C;
    C.width = (size_t)grid->width;
    ts_sky_plane_init(&C.p, nx, ny, nz, plane, azimuth, directions, svf_model, svf_acc, sky_acc,
                      openness_acc);
    return ts_parallel_for_ranges(ts_thread_count(threads, grid->height), grid->height,
                                  TS_ROWS_GRAIN, sky_rows, &C, err);
}

ts_status ts_sky_finish(const ts_grid *grid, int directions, float *svf_acc, float *sky_acc,
                        float *openness_acc, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (directions < 1)
        return ts_fail(err, TS_ERR_ARG, "directions must be at least 1, got %d", directions);
    size_t n = (size_t)grid->width * grid->height;
    /* Into [0, 1] (cm_sky_clamp: discretisation and rounding leave it). */
    for (size_t i = 0; i < n; i++) {
        if (svf_acc)
            svf_acc[i] = cm_sky_clamp(svf_acc[i]);
        if (sky_acc)
            sky_acc[i] = cm_sky_clamp(sky_acc[i]);
        if (openness_acc)
            openness_acc[i] /= (float)directions;
    }
    return ts_ok(err);
}

ts_status ts_sky_terms(const ts_sky_request *req, ts_error *err)
{
    ts_status st = ts_check_sky_request(req, err);
    if (st != TS_OK)
        return st;
    const ts_grid *grid = req->grid;
    const int n = req->opts->directions;
    size_t cells = (size_t)grid->width * grid->height;
    float *acc[3] = {req->svf, req->sky, req->openness};
    for (int j = 0; j < 3; j++)
        if (acc[j])
            memset(acc[j], 0, cells * sizeof(float));
    for (int k = 0; k < n; k++) {
        st = ts_sky_accumulate_model(grid, req->nx, req->ny, req->nz, req->horizons + cells * k,
                                     ts_horizon_azimuth(req->opts, k), n, req->svf_model,
                                     req->opts->threads, acc[0], acc[1], acc[2], err);
        if (st != TS_OK)
            return st;
    }
    return ts_sky_finish(grid, n, acc[0], acc[1], acc[2], err);
}
