/* Direct sun with the visible fraction of the sun's disk, and the final mix. */
#include <math.h>

#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

double ts_sun_disk_fraction(double sun_elevation, double horizon)
{
    if (isnan(sun_elevation) || isnan(horizon))
        return NAN;
    double u = (sun_elevation - horizon) / TS_SUN_RADIUS_DEG;
    if (u >= 1.0)
        return 1.0;
    if (u <= -1.0)
        return 0.0;
    /* Area of the disk above a horizontal chord at height -u radii. */
    return 0.5 + (u * sqrt(1.0 - u * u) + asin(u)) / M_PI;
}

ts_status ts_shade_direct(const ts_grid *grid, const float *nx, const float *ny,
                          const float *nz, const float *horizons,
                          const ts_horizon_opts *opts, double sun_azimuth,
                          double sun_elevation, float *out, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if ((st = ts_horizon_opts_validate(opts, err)) != TS_OK)
        return st;
    if (!nx || !ny || !nz || !horizons || !out)
        return ts_fail(err, TS_ERR_ARG, "normals, horizons and output must not be NULL");
    if (!isfinite(sun_azimuth))
        return ts_fail(err, TS_ERR_ARG, "sun azimuth must be a finite number of degrees, got %g",
                       sun_azimuth);
    if (!(sun_elevation >= -90 && sun_elevation <= 90))
        return ts_fail(err, TS_ERR_ARG, "sun elevation must be between -90 and 90, got %g",
                       sun_elevation);
    int n = opts->directions;
    double step = 360.0 / n;
    double p = fmod(sun_azimuth - opts->start_azimuth, 360.0);
    if (p < 0)
        p += 360.0;
    p /= step;
    int k0 = (int)floor(p);
    double w = p - k0;
    if (k0 >= n) {
        k0 = 0;
        w = 0;
    }
    int k1 = (k0 + 1) % n;
    if (n == 1 && w * step > 1e-9 && (1 - w) * step > 1e-9)
        return ts_fail(err, TS_ERR_ARG,
                       "the horizons were computed for azimuth %g only, not for the sun's azimuth %g",
                       opts->start_azimuth, sun_azimuth);
    if (n == 1)
        w = 0;
    size_t plane = (size_t)grid->width * grid->height;
    const float *h0 = horizons + plane * k0, *h1 = horizons + plane * k1;
    double az = sun_azimuth * DEG2RAD, el = sun_elevation * DEG2RAD;
    float lx = (float)(sin(az) * cos(el)), ly = (float)(cos(az) * cos(el)), lz = (float)sin(el);
    for (size_t i = 0; i < plane; i++) {
        float hz = (float)((1.0 - w) * h0[i] + w * h1[i]);
        float ndotl = nx[i] * lx + ny[i] * ly + nz[i] * lz;
        if (isnan(hz) || isnan(ndotl)) {
            out[i] = NAN;
            continue;
        }
        out[i] = ndotl > 0 ? ndotl * (float)ts_sun_disk_fraction(sun_elevation, hz) : 0.0f;
    }
    return ts_ok(err);
}

ts_status ts_shade_combine(const ts_grid *grid, const float *direct, const float *sky,
                           double sky_weight, float *out, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!direct || !sky || !out)
        return ts_fail(err, TS_ERR_ARG, "direct, sky and output must not be NULL");
    if (!(sky_weight >= 0) || isinf(sky_weight))
        return ts_fail(err, TS_ERR_ARG, "sky weight must be a finite number >= 0, got %g",
                       sky_weight);
    size_t plane = (size_t)grid->width * grid->height;
    float wgt = (float)sky_weight;
    for (size_t i = 0; i < plane; i++) {
        float v = direct[i] + wgt * sky[i];
        out[i] = v > 1.0f ? 1.0f : v < 0.0f ? 0.0f : v; /* NaN passes through */
    }
    return ts_ok(err);
}
