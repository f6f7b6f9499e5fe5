/* The shadow map's options and frame: where the DEM lands in the light's
 * orthographic depth map, and the parameters both backends render and read
 * it with (core/cellmath/cm_shadowmap.h). */
#include <math.h>
#include <stdint.h>

#include "cellmath/cm_shadowmap.h"
#include "status_internal.h"
#include "terrashade_shadowmap.h"

_Static_assert(TS_SHADOWMAP_PARAMS == TS_SMP_COUNT, "the frame's parameter count");

#define DEG2RAD (M_PI / 180.0)
/* Most texels of a map, whatever the DEM: the keys' size must fit in memory
 * and in a long index. */
#define MAX_TEXELS ((double)(1ULL << 31))

void ts_shadowmap_opts_default(ts_shadowmap_opts *opts)
{
    opts->scale = 2.0;
    opts->kernel = TS_SHADOWMAP_AUTO;
    opts->light_radius = TS_SUN_RADIUS_DEG;
    opts->threads = 0;
    opts->progress = NULL;
    opts->progress_user = NULL;
}

ts_status ts_shadowmap_opts_validate(const ts_shadowmap_opts *opts, ts_error *err)
{
    if (!opts)
        return ts_fail(err, TS_ERR_ARG, "shadow map options must not be NULL");
    if (!(opts->scale >= TS_SHADOWMAP_SCALE_MIN && opts->scale <= TS_SHADOWMAP_SCALE_MAX))
        return ts_fail(err, TS_ERR_ARG,
                       "the shadow map's scale must be between %g and %g texels per cell, got %g",
                       TS_SHADOWMAP_SCALE_MIN, TS_SHADOWMAP_SCALE_MAX, opts->scale);
    if (!(opts->kernel == TS_SHADOWMAP_AUTO ||
          (opts->kernel > 0 && opts->kernel <= TS_SHADOWMAP_KERNEL_MAX)))
        return ts_fail(err, TS_ERR_ARG,
                       "the PCF kernel must be greater than 0 and at most %g cells, or auto, "
                       "got %g",
                       TS_SHADOWMAP_KERNEL_MAX, opts->kernel);
    if (opts->threads < 0)
        return ts_fail(err, TS_ERR_ARG, "threads must be >= 0, got %d", opts->threads);
    return ts_check_light_radius(opts->light_radius, err);
}

/* Light-space extent of the valid vertices: s, t ranges and the largest
 * depth, by the same float formula the kernels use (P with s0 = t0 = 0 and
 * unit texels). Returns the number of valid vertices. */
static long extent(const ts_grid *g, const float *P, float *smin, float *smax, float *tmin,
                   float *tmax, float *dmax)
{
    long n = 0;
    *smin = *tmin = *dmax = INFINITY;
    *smax = *tmax = -INFINITY;
    *dmax = -INFINITY;
    for (int y = 0; y < g->height; y++) {
        float cx = (float)ts_grid_cell_x(g, y);
        for (int x = 0; x < g->width; x++) {
            float z = ts_grid_at(g, x, y), s, t, d;
            if (isnan(z))
                continue;
            ts_sm_project(P, x, y, cx, z, &s, &t, &d);
            *smin = fminf(*smin, s);
            *smax = fmaxf(*smax, s);
            *tmin = fminf(*tmin, t);
            *tmax = fmaxf(*tmax, t);
            *dmax = fmaxf(*dmax, d);
            n++;
        }
    }
    return n;
}

ts_status ts_shadowmap_frame_make(const ts_grid *grid, double azimuth, double elevation,
                                  const ts_shadowmap_opts *opts, ts_shadowmap_frame *frame,
                                  ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK || (st = ts_shadowmap_opts_validate(opts, err)) != TS_OK)
        return st;
    if (!frame)
        return ts_fail(err, TS_ERR_ARG, "the shadow map's frame must not be NULL");
    if (!isfinite(azimuth))
        return ts_fail(err, TS_ERR_ARG, "light azimuth must be a finite number of degrees, got %g",
                       azimuth);
    if (!(elevation > 0 && elevation <= 90))
        return ts_fail(err, TS_ERR_ARG,
                       "a shadow map needs the light above the horizon: elevation must be "
                       "greater than 0 and at most 90 degrees, got %g (the exact method "
                       "handles a low light)",
                       elevation);
    float *P = frame->params;
    const double az = azimuth * DEG2RAD, el = elevation * DEG2RAD;
    const double cell = fmin(grid->cell_y, ts_grid_cell_x(grid, grid->height / 2));
    P[TS_SMP_CA] = (float)cos(az);
    P[TS_SMP_SA] = (float)sin(az);
    P[TS_SMP_CE] = (float)cos(el);
    P[TS_SMP_SE] = (float)sin(el);
    P[TS_SMP_S0] = P[TS_SMP_T0] = 0.0f;
    P[TS_SMP_INV_DS] = P[TS_SMP_INV_DT] = 1.0f;
    P[TS_SMP_CX0] = (float)(0.5 * (grid->width - 1));
    P[TS_SMP_CY0] = (float)(0.5 * (grid->height - 1));
    P[TS_SMP_CELL_Y] = (float)grid->cell_y;
    float smin, smax, tmin, tmax, dmax;
    if (extent(grid, P, &smin, &smax, &tmin, &tmax, &dmax) == 0)
        smin = smax = tmin = tmax = dmax = 0.0f; /* all nodata: an empty map */
    /* ds: the cell over scale; dt: the cell's ground length seen from the
     * light over scale, coarser only where the relief at a low light would
     * make the map taller than 4 x scale x (width + height) rows. */
    const double ds = cell / opts->scale;
    double dt = cell * sin(el) / opts->scale;
    const double rows_max = 4.0 * opts->scale * (grid->width + grid->height);
    if ((tmax - tmin) / dt > rows_max)
        dt = (tmax - tmin) / rows_max;
    const double w = ceil((smax - smin) / ds) + 3, h = ceil((tmax - tmin) / dt) + 3;
    if (w * h * (1.0 + 1.0 / (TS_SM_TILE * TS_SM_TILE)) > MAX_TEXELS)
        return ts_fail(err, TS_ERR_NOMEM,
                       "the shadow map would have %.0f x %.0f texels; lower SHADOWMAP_SCALE "
                       "(now %g)",
                       w, h, opts->scale);
    frame->width = (int)w;
    frame->height = (int)h;
    P[TS_SMP_S0] = (float)(smin - ds);
    P[TS_SMP_T0] = (float)(tmin - dt);
    P[TS_SMP_INV_DS] = (float)(1.0 / ds);
    P[TS_SMP_INV_DT] = (float)(1.0 / dt);
    /* constant offset: a fraction of a texel and the float depths' rounding */
    P[TS_SMP_BIAS] = (float)(0.02 * ds + 4e-6 * fmax(fabs(dmax), 1.0) +
                             4e-6 * (fabs(smin) + fabs(tmin)));
    /* depth slopes beyond 8 (faces within 7 degrees of edge-on) count as 8 */
    P[TS_SMP_SLOPE_CAP] = (float)(8.0 * fmax(ds, dt));
    P[TS_SMP_KERNEL_U] = (float)(opts->kernel * cell / ds);
    P[TS_SMP_KERNEL_V] = (float)(opts->kernel * cell * sin(el) / dt);
    P[TS_SMP_TAN_R] = (float)tan(opts->light_radius * DEG2RAD);
    P[TS_SMP_DEPTH_MAX] = dmax;
    P[TS_SMP_SEARCH_CAP] = (float)TS_SM_TILE;
    P[TS_SMP_INV_R] = (float)(1.0 / opts->light_radius);
    return ts_ok(err);
}

ts_status ts_shadowmap_prepare(const ts_grid *grid, double azimuth, double elevation,
                               const ts_shadowmap_opts *opts, const float *visibility,
                               ts_shadowmap_frame *frame, ts_error *err)
{
    if (!visibility)
        return ts_fail(err, TS_ERR_ARG, "the visibility output must not be NULL");
    return ts_shadowmap_frame_make(grid, azimuth, elevation, opts, frame, err);
}

size_t ts_shadowmap_keys(const ts_shadowmap_frame *frame)
{
    size_t tw = ((size_t)frame->width + TS_SM_TILE - 1) / TS_SM_TILE;
    size_t th = ((size_t)frame->height + TS_SM_TILE - 1) / TS_SM_TILE;
    return (size_t)frame->width * frame->height + tw * th;
}
