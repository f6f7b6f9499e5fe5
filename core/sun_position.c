/*
 * Solar Position Algorithm (SPA): Reda, I. and Andreas, A., "Solar Position
 * Algorithm for Solar Radiation Applications", NREL/TP-560-34302, 2004
 * (revised 2008). Implemented from the paper's equations (numbers in the
 * comments) and its tables A4.2 (Earth periodic terms, an abridgement of
 * VSOP87 as in Meeus, "Astronomical Algorithms", Appendix III) and A4.3
 * (periodic terms for the nutation, the IAU 1980 theory as in Meeus, table
 * 22.A). NREL's C code is not used.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "status_internal.h"
#include "terrashade_sun.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define RAD (180.0 / PI)

/* Sun's angular radius used with atmos_refraction (paper, A.2). */
#define SPA_SUN_RADIUS 0.26667

#include "sun_spa_terms.h"

typedef struct {
    const term *t;
    size_t n;
} series;

#define SERIES(t) {t, COUNT(t)}

static const series L_SERIES[] = {SERIES(L0), SERIES(L1), SERIES(L2),
                                  SERIES(L3), SERIES(L4), SERIES(L5)};
static const series B_SERIES[] = {SERIES(B0), SERIES(B1)};
static const series R_SERIES[] = {SERIES(R0), SERIES(R1), SERIES(R2),
                                  SERIES(R3), SERIES(R4)};

/* Eq. 9-11: Xi = sum A cos(B + C JME); X = (X0 + X1 JME + X2 JME^2 + ...)
 * / 10^8, in radians for L and B, in AU for R. Smallest terms first. */
static double earth_series(const series *s, size_t count, double jme)
{
    double total = 0.0;
    for (size_t k = count; k-- > 0;) {
        double sum = 0.0;
        for (size_t i = s[k].n; i-- > 0;)
            sum += s[k].t[i].a * cos(s[k].t[i].b + s[k].t[i].c * jme);
        total = total * jme + sum; /* Horner over the powers of JME */
    }
    return total / 1e8;
}

/* ------------------------------------------------------------ helpers */

/* An angle in degrees brought into [0, 360). */
static double limit_degrees(double deg)
{
    double r = fmod(deg, 360.0);
    if (r < 0.0)
        r += 360.0;
    if (r >= 360.0) /* -1e-20 + 360 rounds to 360 */
        r = 0.0;
    return r;
}

/* a + b T + c T^2 + T^3 / d: the nutation arguments' polynomials. */
static double poly3(double a, double b, double c, double d, double t)
{
    return a + t * (b + t * (c + t / d));
}

/* ------------------------------------------------------------ input */

void ts_sun_input_default(ts_sun_input *in)
{
    if (!in)
        return;
    in->jd = NAN;
    in->longitude = 0.0;
    in->latitude = 0.0;
    in->elevation = 0.0;
    in->pressure = 1013.25;
    in->temperature = 15.0;
    in->delta_t = TS_SUN_DEFAULT_DELTA_T;
    in->atmos_refraction = TS_SUN_DEFAULT_ATMOS_REFRACTION;
}

/* Julian day jd as "YYYY-MM-DD hh:mm UTC" (the inverse of
 * ts_days_from_civil, H. Hinnant's civil_from_days). */
static void utc_text(double jd, char *out, size_t n)
{
    if (!(fabs(jd) < 1e11)) { /* beyond any calendar date a long long holds */
        snprintf(out, n, "far outside the years -2000 to 6000");
        return;
    }
    /* to the nearest minute (a day's end, 05:00, read 04:59) */
    const double all = floor((jd - TS_JD_UNIX_EPOCH) * 1440.0 + 0.5);
    const double days = floor(all / 1440.0);
    const int minutes = (int)(all - days * 1440.0);
    long long z = (long long)days + 719468;
    const long long era = (z >= 0 ? z : z - 146096) / 146097;
    const long long doe = z - era * 146097;
    const long long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const long long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    const long long mp = (5 * doy + 2) / 153;
    const int d = (int)(doy - (153 * mp + 2) / 5 + 1), m = (int)(mp < 10 ? mp + 3 : mp - 9);
    snprintf(out, n, "%lld-%02d-%02d %02d:%02d UTC", yoe + era * 400 + (m <= 2), m, d,
             minutes / 60, minutes % 60);
}

ts_status ts_sun_input_validate(const ts_sun_input *in, ts_error *err)
{
    if (!in)
        return ts_fail(err, TS_ERR_ARG, "The sun position input must not be NULL.");
    struct {
        const char *name;
        double v;
    } fields[] = {
        {"longitude", in->longitude},     {"latitude", in->latitude},
        {"elevation", in->elevation},     {"pressure", in->pressure},
        {"temperature", in->temperature}, {"delta_t", in->delta_t},
        {"atmos_refraction", in->atmos_refraction},
    };
    if (!isfinite(in->jd))
        return ts_fail(err, TS_ERR_ARG,
                       "The date and time of the sun position are not set (Julian "
                       "day %g): set jd, e.g. with ts_julian_day.",
                       in->jd);
    for (size_t i = 0; i < COUNT(fields); i++)
        if (!isfinite(fields[i].v))
            return ts_fail(err, TS_ERR_ARG, "The sun position's %s must be a finite "
                           "number, got %g.", fields[i].name, fields[i].v);
    /* The paper's range of validity: years -2000 to 6000. */
    double jd_min = (double)ts_days_from_civil(-2000, 1, 1) + TS_JD_UNIX_EPOCH;
    double jd_max = (double)ts_days_from_civil(6001, 1, 1) + TS_JD_UNIX_EPOCH;
    if (in->jd < jd_min || in->jd >= jd_max) {
        /* the instant in UTC: a local day of 6000-12-31 west of Greenwich
         * ends in 6001, which a Julian day alone did not show */
        char when[64];
        utc_text(in->jd, when, sizeof when);
        return ts_fail(err, TS_ERR_ARG,
                       "The instant %s (Julian day %.6f) must lie between the years -2000 "
                       "and 6000 (UTC), where the solar position algorithm is valid.",
                       when, in->jd);
    }
    if (in->longitude < -180.0 || in->longitude > 180.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Longitude must be between -180 and 180 degrees (east "
                       "positive), got %g.", in->longitude);
    if (in->latitude < -90.0 || in->latitude > 90.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Latitude must be between -90 and 90 degrees, got %g.",
                       in->latitude);
    if (in->elevation < -6500000.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Elevation must be at least -6500000 m (the centre of the "
                       "Earth), got %g m.", in->elevation);
    if (!(in->pressure > 0.0 && in->pressure <= 5000.0))
        return ts_fail(err, TS_ERR_ARG,
                       "Pressure must be greater than 0 and at most 5000 hPa (mbar), "
                       "got %g.", in->pressure);
    if (!(in->temperature > -273.0 && in->temperature <= 6000.0))
        return ts_fail(err, TS_ERR_ARG,
                       "Temperature must be above -273 and at most 6000 degrees "
                       "Celsius, got %g.", in->temperature);
    if (fabs(in->delta_t) > 8000.0)
        return ts_fail(err, TS_ERR_ARG,
                       "delta_t (TT - UT) must be between -8000 and 8000 seconds, "
                       "got %g (it is about 69 s in the 2020s).", in->delta_t);
    if (fabs(in->atmos_refraction) > 5.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Atmospheric refraction at sunrise and sunset must be between "
                       "-5 and 5 degrees, got %g (the usual value is 0.5667).",
                       in->atmos_refraction);
    return ts_ok(err);
}

/* ------------------------------------------------------------ the SPA */

double ts_sun_refraction(double e0, const ts_sun_input *in)
{
    double de = 0.0;
    if (e0 >= -(SPA_SUN_RADIUS + in->atmos_refraction))
        de = in->pressure / 1010.0 * 283.0 / (273.0 + in->temperature) * 1.02 /
             (60.0 * tan((e0 + 10.3 / (e0 + 5.11)) * DEG)); /* eq. 42 */
    return isfinite(de) ? de : 0.0; /* e0 = -5.11 exactly, reachable with a large
                                     * atmos_refraction */
}

/* Sections 3.1-3.10: what depends on the instant only (jd, delta_t). */
static void sun_instant(const ts_sun_input *in, ts_sun_detail *dp)
{
    ts_sun_detail d;

    /* 3.1 Time scales. */
    d.jd = in->jd;
    d.jde = d.jd + in->delta_t / 86400.0;          /* eq. 5 */
    d.jc = (d.jd - 2451545.0) / 36525.0;           /* eq. 6 */
    d.jce = (d.jde - 2451545.0) / 36525.0;         /* eq. 7 */
    d.jme = d.jce / 10.0;                          /* eq. 8 */

    /* 3.2 Earth heliocentric longitude, latitude and radius vector. */
    d.L = limit_degrees(earth_series(L_SERIES, COUNT(L_SERIES), d.jme) * RAD); /* eq. 9-12 */
    d.B = earth_series(B_SERIES, COUNT(B_SERIES), d.jme) * RAD;
    d.R = earth_series(R_SERIES, COUNT(R_SERIES), d.jme);

    /* 3.3 Geocentric longitude and latitude. */
    d.theta = limit_degrees(d.L + 180.0);          /* eq. 13 */
    d.beta = -d.B;                                 /* eq. 14 */

    /* 3.4 Nutation in longitude and obliquity. */
    double t = d.jce;
    d.x[0] = poly3(297.85036, 445267.111480, -0.0019142, 189474.0, t);  /* eq. 15 */
    d.x[1] = poly3(357.52772, 35999.050340, -0.0001603, -300000.0, t);  /* eq. 16 */
    d.x[2] = poly3(134.96298, 477198.867398, 0.0086972, 56250.0, t);    /* eq. 17 */
    d.x[3] = poly3(93.27191, 483202.017538, -0.0036825, 327270.0, t);   /* eq. 18 */
    d.x[4] = poly3(125.04452, -1934.136261, 0.0020708, 450000.0, t);    /* eq. 19 */
    double sum_psi = 0.0, sum_eps = 0.0;
    for (size_t i = COUNT(NUTATION); i-- > 0;) {
        const nutation_term *n = &NUTATION[i];
        double arg = 0.0;
        for (int j = 0; j < 5; j++)
            arg += d.x[j] * n->y[j];
        arg *= DEG;
        sum_psi += (n->a + n->b * t) * sin(arg);   /* eq. 20 */
        sum_eps += (n->c + n->d * t) * cos(arg);   /* eq. 21 */
    }
    d.delta_psi = sum_psi / 36000000.0;            /* eq. 22 */
    d.delta_epsilon = sum_eps / 36000000.0;        /* eq. 23 */

    /* 3.5 True obliquity of the ecliptic. */
    double u = d.jme / 10.0;
    static const double eps_poly[] = {84381.448, -4680.93, -1.55, 1999.25, -51.38,
                                      -249.67,   -39.05,   7.12,  27.87,   5.79,
                                      2.45};
    double e0 = 0.0;
    for (size_t k = COUNT(eps_poly); k-- > 0;)
        e0 = e0 * u + eps_poly[k];                 /* eq. 24, arc seconds */
    d.epsilon0 = e0;
    d.epsilon = e0 / 3600.0 + d.delta_epsilon;     /* eq. 25 */

    /* 3.6-3.7 Aberration and apparent sun longitude. */
    d.delta_tau = -20.4898 / (3600.0 * d.R);       /* eq. 26 */
    d.lambda = d.theta + d.delta_psi + d.delta_tau; /* eq. 27 */

    /* 3.8 Apparent sidereal time at Greenwich. */
    d.nu0 = limit_degrees(280.46061837 + 360.98564736629 * (d.jd - 2451545.0) +
                          d.jc * d.jc * (0.000387933 - d.jc / 38710000.0)); /* eq. 28 */
    d.nu = d.nu0 + d.delta_psi * cos(d.epsilon * DEG); /* eq. 29 */

    /* 3.9-3.10 Geocentric right ascension and declination. */
    double lam = d.lambda * DEG, eps = d.epsilon * DEG, bet = d.beta * DEG;
    d.alpha = limit_degrees(
        atan2(sin(lam) * cos(eps) - tan(bet) * sin(eps), cos(lam)) * RAD); /* eq. 30 */
    d.delta = asin(sin(bet) * cos(eps) + cos(bet) * sin(eps) * sin(lam)) * RAD; /* eq. 31 */
    *dp = d;
}

/* Sections 3.11-3.15: the site's, from d's sections 3.1-3.10. */
static ts_status sun_at_site(const ts_sun_input *in, ts_sun_detail *dp, ts_sun_output *out,
                             ts_error *err)
{
    ts_sun_detail d = *dp;

    /* 3.11 Observer local hour angle. */
    d.H = limit_degrees(d.nu + in->longitude - d.alpha); /* eq. 32 */

    /* 3.12 Topocentric right ascension and declination (parallax). */
    d.xi = 8.794 / (3600.0 * d.R);                 /* eq. 33 */
    double phi = in->latitude * DEG;
    double uu = atan(0.99664719 * tan(phi));       /* eq. 34 */
    double x = cos(uu) + in->elevation / 6378140.0 * cos(phi);           /* eq. 35 */
    double y = 0.99664719 * sin(uu) + in->elevation / 6378140.0 * sin(phi); /* eq. 36 */
    double xi = d.xi * DEG, h = d.H * DEG, dec = d.delta * DEG;
    double denom = cos(dec) - x * sin(xi) * cos(h);
    double dalpha = atan2(-x * sin(xi) * sin(h), denom); /* eq. 37 */
    d.delta_alpha = dalpha * RAD;
    d.alpha_prime = d.alpha + d.delta_alpha;       /* eq. 38 */
    double dec_p = atan2((sin(dec) - y * sin(xi)) * cos(dalpha), denom); /* eq. 39 */
    d.delta_prime = dec_p * RAD;

    /* 3.13 Topocentric local hour angle. */
    d.H_prime = d.H - d.delta_alpha;               /* eq. 40 */
    double hp = d.H_prime * DEG;

    /* 3.14 Topocentric zenith angle. */
    double s_e0 = sin(phi) * sin(dec_p) + cos(phi) * cos(dec_p) * cos(hp);
    if (s_e0 > 1.0)
        s_e0 = 1.0;
    if (s_e0 < -1.0)
        s_e0 = -1.0;
    d.e0 = asin(s_e0) * RAD;                       /* eq. 41 */
    d.delta_e = ts_sun_refraction(d.e0, in);
    d.e = d.e0 + d.delta_e;                        /* eq. 43 */
    /* eq. 42 holds for the air at the Earth's surface; far outside it (a
     * temperature near -273 C, a large atmos_refraction) its tangent can
     * blow up: no sun leaves [-90, 90] */
    if (!(d.e >= -90.0 && d.e <= 90.0))
        return ts_fail(err, TS_ERR_ARG,
                       "The refracted sun elevation would be %g degrees, outside -90 "
                       "to 90: the refraction model does not hold for pressure %g hPa, "
                       "temperature %g degrees Celsius and atmos_refraction %g (it "
                       "holds for the air at the Earth's surface, about 300 to 1100 "
                       "hPa and -90 to 60 degrees Celsius).",
                       d.e, in->pressure, in->temperature, in->atmos_refraction);
    d.zenith = 90.0 - d.e;                         /* eq. 44 */

    /* 3.15 Topocentric azimuth. */
    d.gamma = limit_degrees(
        atan2(sin(hp), cos(hp) * sin(phi) - tan(dec_p) * cos(phi)) * RAD); /* eq. 45 */
    d.phi = limit_degrees(d.gamma + 180.0);        /* eq. 46 */

    out->zenith = d.zenith;
    out->azimuth = d.phi;
    out->elevation = d.e;
    *dp = d;
    return ts_ok(err);
}

ts_status ts_sun_position_detail(const ts_sun_input *in, ts_sun_output *out,
                                 ts_sun_detail *detail, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "The sun position output must not be NULL.");
    ts_status st = ts_sun_input_validate(in, err);
    if (st != TS_OK)
        return st;
    ts_sun_detail d;
    sun_instant(in, &d);
    if ((st = sun_at_site(in, &d, out, err)) == TS_OK && detail)
        *detail = d;
    return st;
}

ts_status ts_sun_position_from(const ts_sun_input *in, const ts_sun_detail *instant,
                               ts_sun_output *out, ts_sun_detail *detail, ts_error *err)
{
    if (!out || !instant)
        return ts_fail(err, TS_ERR_ARG, "The sun position output and the instant's detail "
                       "must not be NULL.");
    ts_status st = ts_sun_input_validate(in, err);
    if (st != TS_OK)
        return st;
    if (instant->jd != in->jd || instant->jde != in->jd + in->delta_t / 86400.0)
        return ts_fail(err, TS_ERR_ARG, "The instant's detail is of another instant "
                       "(jd %.9f, jde %.9f) than the input's (jd %.9f, delta_t %g s).",
                       instant->jd, instant->jde, in->jd, in->delta_t);
    ts_sun_detail d = *instant;
    if ((st = sun_at_site(in, &d, out, err)) == TS_OK && detail)
        *detail = d;
    return st;
}

ts_status ts_sun_position(const ts_sun_input *in, ts_sun_output *out,
                          ts_error *err)
{
    return ts_sun_position_detail(in, out, NULL, err);
}
