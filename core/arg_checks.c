/* Argument checks shared by the C and OpenCL backends (arg_checks.h). */
#include <math.h>
#include <stdint.h>

#include "arg_checks.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

/* A finite azimuth in degrees, reduced to [0, 360). */
static void reduce_azimuth(double *azimuth)
{
    *azimuth = fmod(*azimuth, 360.0);
    if (*azimuth < 0)
        *azimuth += 360.0;
}

ts_status ts_check_shm_args(const ts_grid *grid, double *azimuth, double elevation,
                            double penumbra_depth, int threads, const float *vis,
                            const float *shadow_height, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!isfinite(*azimuth))
        return ts_fail(err, TS_ERR_ARG, "sun azimuth must be a finite number of degrees, got %g",
                       *azimuth);
    if (!(elevation >= -90 && elevation <= 90))
        return ts_fail(err, TS_ERR_ARG, "sun elevation must be between -90 and 90, got %g",
                       elevation);
    if (!(penumbra_depth >= 0) || isinf(penumbra_depth))
        return ts_fail(err, TS_ERR_ARG,
                       "penumbra depth must be 0 (hard shadows) or a positive number of "
                       "metres, got %g", penumbra_depth);
    if (threads < 0)
        return ts_fail(err, TS_ERR_ARG, "threads must be 0 (all cores) or more, got %d", threads);
    if (!vis && !shadow_height)
        return ts_fail(err, TS_ERR_ARG, "both outputs are NULL");
    reduce_azimuth(azimuth);
    return TS_OK;
}

ts_status ts_check_sweep_args(const ts_grid *grid, double *azimuth,
                              const ts_horizon_opts *opts, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!opts)
        return ts_fail(err, TS_ERR_ARG, "horizon options are NULL");
    ts_horizon_opts o = *opts; /* one azimuth: the number of directions is not used */
    o.directions = o.directions < 1 ? 1 : o.directions;
    if ((st = ts_horizon_opts_validate(&o, err)) != TS_OK)
        return st;
    if (!isfinite(*azimuth))
        return ts_fail(err, TS_ERR_ARG, "azimuth must be a finite number of degrees, got %g",
                       *azimuth);
    reduce_azimuth(azimuth);
    return TS_OK;
}

ts_status ts_check_sweeps_args(const ts_grid *grid, const double *azimuths, int n,
                               const ts_horizon_opts *opts, const float *out, double *reduced,
                               ts_error *err)
{
    if (!out || !azimuths)
        return ts_fail(err, TS_ERR_ARG, "output buffer or azimuth list is NULL");
    if (n < 1)
        return ts_fail(err, TS_ERR_ARG, "the azimuth list must have at least one entry, got %d",
                       n);
    ts_status st = TS_OK;
    for (int a = 0; st == TS_OK && a < n; a++) {
        double az = azimuths[a];
        st = ts_check_sweep_args(grid, &az, opts, err);
        if (reduced)
            reduced[a] = az;
    }
    if (st == TS_OK && (double)n * grid->width * grid->height > (double)(SIZE_MAX / sizeof *out))
        return ts_fail(err, TS_ERR_ARG, "%d planes of %d x %d floats cannot be addressed", n,
                       grid->width, grid->height);
    return st;
}

ts_status ts_check_normals_args(const ts_grid *grid, const float *nx, const float *ny,
                                const float *nz, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!nx || !ny || !nz)
        return ts_fail(err, TS_ERR_ARG, "normal output buffers must not be NULL");
    return TS_OK;
}

ts_status ts_check_sky_args(const ts_grid *grid, const float *nx, const float *ny,
                            const float *nz, int directions, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!nx || !ny || !nz)
        return ts_fail(err, TS_ERR_ARG, "normals must not be NULL");
    if (directions < 1)
        return ts_fail(err, TS_ERR_ARG, "directions must be at least 1, got %d", directions);
    return TS_OK;
}

ts_status ts_check_sky_request(const ts_sky_request *req, ts_error *err)
{
    if (!req)
        return ts_fail(err, TS_ERR_ARG, "the sky terms request must not be NULL");
    ts_status st = ts_horizon_opts_validate(req->opts, err);
    if (st != TS_OK)
        return st;
    st = ts_check_sky_args(req->grid, req->nx, req->ny, req->nz, req->opts->directions, err);
    if (st != TS_OK)
        return st;
    if (!req->horizons)
        return ts_fail(err, TS_ERR_ARG, "horizons must not be NULL");
    return ts_check_svf_model(req->svf_model, err);
}

ts_status ts_direct_setup(const ts_direct_request *req, ts_direct_plan *plan, ts_error *err)
{
    if (req && (!req->nx || !req->ny || !req->nz))
        return ts_fail(err, TS_ERR_ARG, "normals, horizons and output must not be NULL");
    return ts_direct_setup_horn(req, plan, err);
}

ts_status ts_direct_setup_horn(const ts_direct_request *req, ts_direct_plan *plan,
                               ts_error *err)
{
    if (!req)
        return ts_fail(err, TS_ERR_ARG, "the direct sun request must not be NULL");
    ts_status st = ts_grid_validate(req->grid, err);
    if (st != TS_OK)
        return st;
    const ts_horizon_opts *opts = req->opts;
    if ((st = ts_horizon_opts_validate(opts, err)) != TS_OK)
        return st;
    if (!req->horizons || !req->out)
        return ts_fail(err, TS_ERR_ARG, "horizons and output must not be NULL");
    const double sun_azimuth = req->sun_azimuth, sun_elevation = req->sun_elevation;
    if (!isfinite(sun_azimuth))
        return ts_fail(err, TS_ERR_ARG, "sun azimuth must be a finite number of degrees, got %g",
                       sun_azimuth);
    if (!(sun_elevation >= -90 && sun_elevation <= 90))
        return ts_fail(err, TS_ERR_ARG, "sun elevation must be between -90 and 90, got %g",
                       sun_elevation);
    plan->radius = req->light_radius == 0 ? TS_SUN_RADIUS_DEG : req->light_radius;
    if ((st = ts_check_light_radius(plan->radius, err)) != TS_OK)
        return st;
    int n = opts->directions;
    double step = 360.0 / n;
    double p = fmod(sun_azimuth - opts->start_azimuth, 360.0);
    if (p < 0)
        p += 360.0;
    p /= step;
    plan->k0 = (int)floor(p);
    plan->w = p - plan->k0;
    if (plan->k0 >= n) {
        plan->k0 = 0;
        plan->w = 0;
    }
    plan->k1 = (plan->k0 + 1) % n;
    if (n == 1 && plan->w * step > 1e-9 && (1 - plan->w) * step > 1e-9)
        return ts_fail(err, TS_ERR_ARG,
                       "the horizons were computed for azimuth %g only, not for the sun's "
                       "azimuth %g", opts->start_azimuth, sun_azimuth);
    if (n == 1)
        plan->w = 0;
    double az = sun_azimuth * DEG2RAD, el = sun_elevation * DEG2RAD;
    plan->light[0] = (float)(sin(az) * cos(el));
    plan->light[1] = (float)(cos(az) * cos(el));
    plan->light[2] = (float)sin(el);
    return TS_OK;
}

ts_status ts_check_horizon_compute_args(const ts_grid *grid, const ts_horizon_opts *opts,
                                        const float *out, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if ((st = ts_horizon_opts_validate(opts, err)) != TS_OK)
        return st;
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "output buffer is NULL");
    size_t plane = (size_t)grid->width * (size_t)grid->height;
    if (plane > SIZE_MAX / sizeof(float) / (size_t)opts->directions)
        return ts_fail(err, TS_ERR_NOMEM, "%d horizon planes of %d x %d cells are too large",
                       opts->directions, grid->width, grid->height);
    return ts_ok(err);
}
