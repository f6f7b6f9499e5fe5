/*
 * Far-field horizons and far shadows: only terrain at least a threshold
 * distance behind a cell counts (Chajdas et al. 2015). The sweep of
 * horizon_sweep.c, in its lockstep blocks (sweep_far.c), with two
 * differences: a sample joins its line's hull only once the line has moved
 * the threshold past it (so the hull holds exactly the far samples), and
 * there is no near field to solve. As in the whole sweep, a cell between
 * two lines takes its own ray's slope at the occluders the two lines'
 * hulls find (the lines' own slopes, mixed, were up to a degree off on
 * rough terrain at odd azimuths). See shadow_atlas.h.
 */
#include <math.h>
#include <stdlib.h>

#include "parallel.h"
#include "shadow_atlas.h"
#include "status_internal.h"
#include "sweep_far.h"

typedef struct {
    const ts_grid *grid;
    float *out;
} degrees_ctx;

static void to_degrees(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const degrees_ctx *C = ctx;
    const int W = C->grid->width;
    for (long y = y0; y < y1; y++)
        ts_slopes_to_degrees(C->out + (size_t)y * W, W);
}

/* The far-field sweep: slopes (tangents) into out, or, with `degrees`,
 * elevation angles. */
static ts_status far_sweep(const ts_grid *grid, double azimuth, double threshold_m,
                           double dz, const ts_horizon_opts *opts, int degrees, float *out,
                           ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!opts || !out)
        return ts_fail(err, TS_ERR_ARG, "far-field horizon: options or output are NULL");
    ts_horizon_opts o = *opts;
    if (o.directions < 1)
        o.directions = 1;
    if ((st = ts_horizon_opts_validate(&o, err)) != TS_OK)
        return st;
    if (o.max_distance != 0)
        return ts_fail(err, TS_ERR_ARG, "far-field horizons take no maximum distance "
                       "(got %g m)", o.max_distance);
    if (!(threshold_m > 0) || !isfinite(threshold_m))
        return ts_fail(err, TS_ERR_ARG, "the far-shadow threshold must be a positive "
                       "distance in metres, got %g", threshold_m);
    if ((st = ts_sweep_far_lanes(grid, azimuth, threshold_m, dz, &o, out, err)) != TS_OK)
        return st;
    degrees_ctx C = {grid, out};
    if (degrees)
        st = ts_parallel_for_ranges(ts_thread_count(o.threads, grid->height), grid->height,
                                    TS_ROWS_GRAIN, to_degrees, &C, err);
    return st == TS_OK ? ts_ok(err) : st;
}

ts_status ts_far_horizon(const ts_grid *grid, double azimuth, double threshold_m,
                         const ts_horizon_opts *opts, float *out, ts_error *err)
{
    return far_sweep(grid, azimuth, threshold_m, 0.0, opts, 1, out, err);
}

ts_status ts_far_slope_raised(const ts_grid *grid, double azimuth, double threshold_m,
                              double dz, const ts_horizon_opts *opts, float *out,
                              ts_error *err)
{
    if (!isfinite(dz))
        return ts_fail(err, TS_ERR_ARG, "the observers' height above the cells must be "
                       "finite, got %g", dz);
    return far_sweep(grid, azimuth, threshold_m, dz, opts, 0, out, err);
}

ts_status ts_far_shadow(const ts_grid *grid, double azimuth, double elevation,
                        double threshold_m, const ts_horizon_opts *opts, uint8_t *out,
                        ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "ts_far_shadow: the output is NULL");
    if (!(elevation >= -90.0 && elevation <= 90.0))
        return ts_fail(err, TS_ERR_ARG, "the sun's elevation must be between -90 and "
                       "90 degrees, got %g", elevation);
    size_t cells = (size_t)grid->width * grid->height;
    float *s = malloc(cells * sizeof *s);
    if (!s)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate a far-horizon plane");
    st = far_sweep(grid, azimuth, threshold_m, 0.0, opts, 0, s, err);
    if (st == TS_OK) {
        /* slope > tan(elevation) <=> horizon angle > elevation */
        double t = elevation >= 90.0 ? INFINITY : tan(elevation * (M_PI / 180.0));
        for (size_t i = 0; i < cells; i++)
            out[i] = isnan(s[i]) ? TS_ATLAS_NODATA : (double)s[i] > t ? 1 : 0;
    }
    free(s);
    return st;
}

