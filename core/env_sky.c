/*
 * Standard skies as environments: uniform, the CIE standard overcast sky
 * and the 15 CIE general sky types (ISO 15469:2004 / CIE S 011/E:2003;
 * Darula & Kittler 2002, "CIE general sky standard defining luminance
 * distributions", eSim 2002), with the CIE standard clear sky as type 12.
 *
 * Choices:
 *  - "overcast" is the traditional CIE standard overcast sky (Moon & Spencer
 *    1942, adopted by the CIE in 1955), L = Lz (1 + 2 cos Z) / 3: it is what
 *    daylighting practice (daylight factors) calls the CIE overcast sky, with
 *    its exact published 3:1 gradation and horizontal illuminance 7 pi/9 Lz.
 *    General type 1 is the standard's fit of it (zenith/horizon 2.986), and
 *    is available as cie:1.
 *  - "clear" is type 12, named "CIE standard clear sky, low illuminance
 *    turbidity" in the standard; type 13 (polluted atmosphere) is cie:13.
 *  - Every sky is normalised to a horizontal diffuse irradiance of pi, so a
 *    flat open plane reflects E/pi = 1 under any of them, as under the
 *    uniform sky of radiance 1: the relative distribution is the standard's,
 *    the absolute level is the caller's (SKY_WEIGHT, EXPOSURE).
 *  - Grey (R = G = B); zero below the horizontal (the ground is not a light
 *    source here); the sun's disk is not part of the sky.
 *  - The standard is defined for the sun above the horizon; the formula is
 *    continued as is for a sun below it (dusk), where it stays positive.
 */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "status_internal.h"
#include "terrashade_env.h"

#define DEG2RAD (M_PI / 180.0)

/* Gradation (a, b) and indicatrix (c, d, e) of types 1..15: six gradation
 * groups and six indicatrix groups, combined as in the standard's table. */
static const double CIE_PARAMS[15][5] = {
    {4.0, -0.70, 0, -1.0, 0.00},   /* 1 overcast, steep gradation, azimuthal uniformity */
    {4.0, -0.70, 2, -1.5, 0.15},   /* 2 overcast, steep gradation, slight brightening to the sun */
    {1.1, -0.80, 0, -1.0, 0.00},   /* 3 overcast, moderate gradation, azimuthal uniformity */
    {1.1, -0.80, 2, -1.5, 0.15},   /* 4 overcast, moderate gradation, slight brightening */
    {0.0, -1.00, 0, -1.0, 0.00},   /* 5 sky of uniform luminance */
    {0.0, -1.00, 2, -1.5, 0.15},   /* 6 partly cloudy, no gradation, slight brightening */
    {0.0, -1.00, 5, -2.5, 0.30},   /* 7 partly cloudy, no gradation, brighter circumsolar region */
    {0.0, -1.00, 10, -3.0, 0.45},  /* 8 partly cloudy, no gradation, distinct solar corona */
    {-1.0, -0.55, 2, -1.5, 0.15},  /* 9 partly cloudy, shaded sun */
    {-1.0, -0.55, 5, -2.5, 0.30},  /* 10 partly cloudy, brighter circumsolar region */
    {-1.0, -0.55, 10, -3.0, 0.45}, /* 11 white-blue sky, distinct solar corona */
    {-1.0, -0.32, 10, -3.0, 0.45}, /* 12 CIE standard clear sky, low illuminance turbidity */
    {-1.0, -0.32, 16, -3.0, 0.30}, /* 13 CIE standard clear sky, polluted atmosphere */
    {-1.0, -0.15, 16, -3.0, 0.30}, /* 14 cloudless turbid sky, broad solar corona */
    {-1.0, -0.15, 24, -2.8, 0.15}, /* 15 white-blue turbid sky, broad solar corona */
};

/* phi(Z) from cos Z: 1 + a exp(b / cos Z), and 1 at and below the horizontal. */
static double gradation(const double *p, double cos_z)
{
    return cos_z > 0 ? 1 + p[0] * exp(p[1] / cos_z) : 1.0;
}

/* f(chi), chi in radians. */
static double indicatrix(const double *p, double chi)
{
    double c = cos(chi);
    return 1 + p[2] * (exp(p[3] * chi) - exp(p[3] * M_PI / 2)) + p[4] * c * c;
}

double ts_cie_sky_relative(int type, double zenith_deg, double sun_distance_deg,
                           double sun_zenith_deg)
{
    if (type < 1 || type > 15)
        return NAN;
    const double *p = CIE_PARAMS[type - 1];
    return indicatrix(p, sun_distance_deg * DEG2RAD) * gradation(p, cos(zenith_deg * DEG2RAD)) /
           (indicatrix(p, sun_zenith_deg * DEG2RAD) * gradation(p, 1.0));
}

ts_status ts_sky_parse(const char *name, ts_sky_kind *kind, int *cie_type, ts_error *err)
{
    if (!name || !kind || !cie_type)
        return ts_fail(err, TS_ERR_ARG, "sky name and results must not be NULL");
    static const struct { const char *name; ts_sky_kind kind; } NAMED[] = {
        {"uniform", TS_SKY_UNIFORM}, {"overcast", TS_SKY_OVERCAST}, {"clear", TS_SKY_CLEAR}};
    *cie_type = 0;
    for (size_t i = 0; i < sizeof NAMED / sizeof NAMED[0]; i++)
        if (!strcasecmp(name, NAMED[i].name)) {
            *kind = NAMED[i].kind;
            return ts_ok(err);
        }
    if (!strncasecmp(name, "cie", 3)) {
        /* cie:N, or cieN where a ':' cannot go (an inline connection string) */
        const char *num = name + 3 + (name[3] == ':');
        char *end;
        /* digits only: strtol took 'cie: 9' and 'cie:+9' too */
        long n = *num >= '0' && *num <= '9' ? strtol(num, &end, 10) : 0;
        if (n && *end == '\0' && n >= 1 && n <= 15) {
            *kind = TS_SKY_CIE;
            *cie_type = (int)n;
            return ts_ok(err);
        }
    }
    return ts_fail(err, TS_ERR_ARG, "SKY must be uniform, overcast, clear or cie:N with N "
                   "from 1 to 15, got '%s'", name);
}

int ts_sky_follows_sun(ts_sky_kind kind, int cie_type)
{
    if (kind == TS_SKY_CLEAR)
        return 1;
    if (kind != TS_SKY_CIE || cie_type < 1 || cie_type > 15)
        return 0;
    const double *p = CIE_PARAMS[cie_type - 1];
    return p[2] != 0 || p[4] != 0; /* an indicatrix that is not 1 */
}

/* Relative radiance of one sky direction (unit vector d, z up). */
typedef struct {
    ts_sky_kind kind;
    const double *p;   /* CIE parameters, NULL for uniform and overcast */
    double sun[3];     /* unit vector to the sun */
} sky_model;

static double sky_radiance(const sky_model *m, const float *d)
{
    double cz = d[2];
    if (cz <= 0)
        return 0; /* below the horizontal: the ground is no light */
    if (m->kind == TS_SKY_UNIFORM)
        return 1;
    if (m->kind == TS_SKY_OVERCAST)
        return (1 + 2 * cz) / 3;
    double dot = d[0] * m->sun[0] + d[1] * m->sun[1] + d[2] * m->sun[2];
    double chi = acos(dot > 1 ? 1 : dot < -1 ? -1 : dot);
    return indicatrix(m->p, chi) * gradation(m->p, cz);
}

ts_status ts_env_sky(ts_env *env, ts_sky_kind kind, int cie_type, double sun_azimuth,
                     double sun_elevation, int width, int height, ts_error *err)
{
    if (!env)
        return ts_fail(err, TS_ERR_ARG, "the environment must not be NULL");
    env->count = 0;
    env->texels = NULL;
    if (kind < TS_SKY_UNIFORM || kind > TS_SKY_CIE)
        return ts_fail(err, TS_ERR_ARG, "unknown sky kind %d", (int)kind);
    if (kind == TS_SKY_CIE && (cie_type < 1 || cie_type > 15))
        return ts_fail(err, TS_ERR_ARG, "the CIE general sky type must be from 1 to 15, got %d",
                       cie_type);
    if (!isfinite(sun_azimuth))
        return ts_fail(err, TS_ERR_ARG, "SUN_AZIMUTH must be a finite number of degrees, got %g",
                       sun_azimuth);
    if (!(sun_elevation >= -90 && sun_elevation <= 90))
        return ts_fail(err, TS_ERR_ARG, "SUN_ELEVATION must be between -90 and 90, got %g",
                       sun_elevation);
    if (width == 0 && height == 0) {
        width = TS_SKY_DEFAULT_WIDTH;
        height = TS_SKY_DEFAULT_HEIGHT;
    }
    ts_status st = ts_env_sphere_grid(env, width, height, err);
    if (st != TS_OK)
        return st;
    sky_model m = {kind, NULL, {0, 0, 0}};
    if (kind == TS_SKY_CLEAR || kind == TS_SKY_CIE) {
        m.kind = TS_SKY_CIE;
        m.p = CIE_PARAMS[(kind == TS_SKY_CLEAR ? 12 : cie_type) - 1];
        double az = sun_azimuth * DEG2RAD, el = sun_elevation * DEG2RAD;
        m.sun[0] = cos(el) * sin(az);
        m.sun[1] = cos(el) * cos(az);
        m.sun[2] = sin(el);
    }
    /* Horizontal irradiance of the relative sky over these very texels, so
     * that the normalisation is exact on the grid the table integrates. */
    double irradiance = 0;
    for (size_t i = 0; i < env->count; i++) {
        ts_env_texel *t = &env->texels[i];
        double L = sky_radiance(&m, t->dir);
        t->rgb[0] = (float)L;
        irradiance += L * t->dir[2] * t->solid_angle;
    }
    if (!(irradiance > 0)) {
        ts_env_free(env);
        return ts_fail(err, TS_ERR_ARG, "a %d x %d grid has no texel above the horizontal; "
                       "use at least 2 rows", width, height);
    }
    const double scale = M_PI / irradiance;
    for (size_t i = 0; i < env->count; i++) {
        ts_env_texel *t = &env->texels[i];
        t->rgb[0] = t->rgb[1] = t->rgb[2] = (float)(t->rgb[0] * scale);
    }
    return ts_ok(err);
}
