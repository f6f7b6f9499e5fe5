/* Horizon options and the multi-azimuth driver of the sweep. */
#include <math.h>
#include <stdint.h>

#include "arg_checks.h"
#include "status_internal.h"

void ts_horizon_opts_default(ts_horizon_opts *opts)
{
    if (!opts)
        return;
    opts->directions = 16;
    opts->start_azimuth = 0.0;
    opts->max_distance = 0.0;
    opts->curvature = 1;
    opts->refraction = TS_DEFAULT_REFRACTION;
    opts->threads = 0;
    opts->progress = NULL;
    opts->progress_user = NULL;
    opts->edge = TS_EDGE_OPEN;
    opts->nonpositive_moot = 0;
}

ts_status ts_horizon_opts_validate(const ts_horizon_opts *opts, ts_error *err)
{
    if (!opts)
        return ts_fail(err, TS_ERR_ARG, "horizon options are NULL");
    if (opts->directions < 1 || opts->directions > 65536)
        return ts_fail(err, TS_ERR_ARG, "directions must be between 1 and 65536, got %d",
                       opts->directions);
    if (!isfinite(opts->start_azimuth))
        return ts_fail(err, TS_ERR_ARG, "start azimuth must be a finite number of degrees, got %g",
                       opts->start_azimuth);
    if (!(opts->max_distance >= 0) || isinf(opts->max_distance))
        return ts_fail(err, TS_ERR_ARG,
                       "max distance must be 0 (unbounded) or a positive number of metres, got %g",
                       opts->max_distance);
    if (!(opts->refraction >= 0 && opts->refraction <= 1))
        return ts_fail(err, TS_ERR_ARG, "refraction coefficient must be between 0 and 1, got %g",
                       opts->refraction);
    if (opts->edge != TS_EDGE_OPEN && opts->edge != TS_EDGE_HORIZON &&
        opts->edge != TS_EDGE_NODATA)
        return ts_fail(err, TS_ERR_ARG, "the edge mode must be open, horizon or nodata, got %d",
                       (int)opts->edge);
    if (opts->threads < 0)
        return ts_fail(err, TS_ERR_ARG, "threads must be 0 (all cores) or more, got %d",
                       opts->threads);
    return ts_ok(err);
}

double ts_horizon_azimuth(const ts_horizon_opts *opts, int k)
{
    double a = fmod(opts->start_azimuth + 360.0 * k / opts->directions, 360.0);
    return a < 0 ? a + 360.0 : a;
}

ts_status ts_horizon_compute(const ts_grid *grid, const ts_horizon_opts *opts, float *out,
                             ts_error *err)
{
    ts_status st = ts_check_horizon_compute_args(grid, opts, out, err);
    if (st != TS_OK)
        return st;
    size_t plane = (size_t)grid->width * (size_t)grid->height;
    for (int k = 0; k < opts->directions; k++) {
        if ((st = ts_progress(opts, (double)k / opts->directions, err)) != TS_OK)
            return st;
        st = ts_horizon_sweep(grid, ts_horizon_azimuth(opts, k), opts, out + plane * k, err);
        if (st != TS_OK)
            return st;
    }
    if ((st = ts_progress(opts, 1.0, err)) != TS_OK)
        return st;
    return ts_ok(err);
}
