/*
 * Lights in SH: an environment's texels and a circular key light (both
 * mirrored below the horizontal, terrashade_sh.h says why), and the swaths
 * of azimuths the visibility is sampled on (Snyder & Nowrouzezahrai 2008,
 * section 4: a complete swath for an environment, a partial one for a key
 * light).
 */
#include <math.h>
#include <string.h>

#include "sh_internal.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)

/* Largest SH light coefficient taken: far above any real sky, far below
 * FLT_MAX once multiplied by the transfer's coefficients. */
#define TS_SH_MAX_COEFF 1e36

ts_status ts_sh_project_env(const ts_env *env, double out[3][TS_SH_COEFFS], ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "the SH light must not be NULL");
    memset(out, 0, sizeof(double) * 3 * TS_SH_COEFFS);
    if (!env || !env->count || !env->texels)
        return ts_fail(err, TS_ERR_ARG, "the environment is empty");
    for (size_t t = 0; t < env->count; t++) {
        const ts_env_texel *x = &env->texels[t];
        if (!(x->dir[2] > 0) || !(x->rgb[0] + x->rgb[1] + x->rgb[2] > 0))
            continue;
        double d[3] = {x->dir[0], x->dir[1], x->dir[2]}, m[3] = {d[0], d[1], -d[2]};
        double y[TS_SH_COEFFS], ym[TS_SH_COEFFS];
        ts_sh_eval(d, y);
        ts_sh_eval(m, ym);
        for (int c = 0; c < 3; c++) {
            double w = (double)x->rgb[c] * x->solid_angle;
            for (int i = 0; i < TS_SH_COEFFS; i++)
                out[c][i] += w * (y[i] + ym[i]);
        }
    }
    /* the SH light runs in float: a map near FLT_MAX (a radiance of 1e38)
     * lit every cell as inf; the sun's disk is some 2e7 W/m2/sr */
    for (int c = 0; c < 3; c++)
        for (int i = 0; i < TS_SH_COEFFS; i++)
            if (!(fabs(out[c][i]) <= TS_SH_MAX_COEFF))
                return ts_fail(err, TS_ERR_ARG,
                               "the environment's light is too large for the spherical "
                               "harmonics' single precision (coefficient %g; at most %g): "
                               "scale the map down or use ENV_METHOD=table",
                               fabs(out[c][i]), TS_SH_MAX_COEFF);
    return ts_ok(err);
}

/* Unit vector of azimuth (degrees from north, clockwise) and elevation. */
static void direction(double azimuth, double elevation, double d[3])
{
    double a = azimuth * DEG2RAD, e = elevation * DEG2RAD;
    d[0] = sin(a) * cos(e);
    d[1] = cos(a) * cos(e);
    d[2] = sin(e);
}

void ts_sh_key_light(double azimuth, double elevation, double radius_deg,
                     double out[TS_SH_COEFFS])
{
    double d[3], cap[TS_SH_COEFFS], mirror[TS_SH_COEFFS];
    direction(azimuth, elevation, d);
    ts_sh_cap(d, radius_deg, cap);
    d[2] = -d[2];
    ts_sh_cap(d, radius_deg, mirror);
    for (int i = 0; i < TS_SH_COEFFS; i++)
        out[i] = cap[i] + mirror[i];
}

double ts_sh_disk_above(double elevation, double radius_deg)
{
    double t = elevation / radius_deg; /* the chord's distance from the centre, in radii */
    if (t >= 1)
        return 1;
    if (t <= -1)
        return 0;
    return 1 - (acos(t) - t * sqrt(1 - t * t)) / M_PI;
}

static double wrap360(double a)
{
    a = fmod(a, 360.0);
    return a < 0 ? a + 360.0 : a;
}

void ts_sh_swath_complete(ts_sh_swath *s, int n, double first)
{
    memset(s, 0, sizeof *s);
    s->complete = 1;
    s->n = n;
    s->span = 360;
    s->step = 360.0 / n;
    s->start = s->first = wrap360(first);
}

void ts_sh_swath_key(ts_sh_swath *s, int n, double azimuth, double elevation,
                     double radius_deg)
{
    if (elevation + radius_deg >= 90 || elevation - radius_deg <= -90) {
        ts_sh_swath_complete(s, n, azimuth); /* the disk holds a pole */
        return;
    }
    double half = asin(sin(radius_deg * DEG2RAD) / cos(elevation * DEG2RAD)) * RAD2DEG;
    memset(s, 0, sizeof *s);
    s->n = n;
    s->span = 2 * half;
    s->step = s->span / n;
    s->start = wrap360(azimuth - half);
    s->first = wrap360(s->start + s->step / 2);
}

double ts_sh_swath_azimuth(const ts_sh_swath *s, int k)
{
    return wrap360(s->first + k * s->step);
}
