/*
 * terrashade_sun.h - where the sun is: date and time handling and the Solar
 * Position Algorithm (SPA) of Reda & Andreas, "Solar Position Algorithm for
 * Solar Radiation Applications", NREL/TP-560-34302 (2004, revised 2008).
 *
 * The algorithm is implemented from the paper's equations and tables (its
 * stated uncertainty is +/-0.0003 deg for the years -2000 to 6000); NREL's
 * own C code is not used. Like the rest of libterrashade there is no global
 * state: every function here is re-entrant.
 *
 * Typical use:
 *
 *     ts_sun_input in;
 *     ts_sun_output sun;
 *     double t;
 *     ts_sun_input_default(&in);
 *     if (ts_parse_iso8601("2026-06-21T07:30:00+02:00", &t, NULL, &err))
 *         ... report err.message ...
 *     in.jd = ts_julian_day_from_unix(t);
 *     in.latitude = 46.5; in.longitude = 7.9; in.elevation = 1500;
 *     if (ts_sun_position(&in, &sun, &err)) ... report err.message ...
 *     ... sun.azimuth, sun.elevation (degrees, the conventions of
 *         terrashade.h: azimuth clockwise from north, elevation above the
 *         horizontal) ...
 *
 * Time scales: `jd` is a Julian day in Universal Time. UTC, which clocks and
 * ISO 8601 strings give, is kept within 0.9 s of UT1, so it is used as UT
 * directly (0.9 s moves the sun by at most 0.004 deg). Dynamical time, which
 * the planetary theory needs, is UT + delta_t.
 */
#ifndef TERRASHADE_SUN_H
#define TERRASHADE_SUN_H

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------ date, time */

/** Julian day of the Unix epoch, 1970-01-01T00:00:00Z. */
#define TS_JD_UNIX_EPOCH 2440587.5

/**
 * Days from 1970-01-01 to the given date of the proleptic Gregorian calendar
 * (negative before 1970). Valid for any year within +/-5,000,000; month must
 * be 1..12 and day 1..31 (not checked here: see ts_julian_day).
 */
long long ts_days_from_civil(long long year, int month, int day);

/** Whether `year` is a leap year of the (proleptic) Gregorian calendar. */
int ts_is_leap_year(long long year);

/** Number of days of a month (1..12) of a year; 0 for a bad month. */
int ts_days_in_month(long long year, int month);

/**
 * Julian day (UT) of a UTC date and time of the proleptic Gregorian
 * calendar, e.g. 2003-10-17 19:30:30 -> 2452930.312847. This is the paper's
 * eq. 4 for dates from 1582-10-15 on; earlier dates are read as Gregorian
 * too (as ISO 8601 and Unix time do), not as Julian-calendar dates.
 * Checks the fields: year within +/-1,000,000, month 1..12, day within the
 * month, hour 0..23, minute 0..59, second in [0, 61) (60.x is a leap
 * second, counted as the first second of the next minute).
 */
ts_status ts_julian_day(int year, int month, int day, int hour, int minute,
                        double second, double *jd, ts_error *err);

/**
 * Julian day (UT) of a Unix time: seconds since 1970-01-01T00:00:00Z, leap
 * seconds not counted (POSIX time). jd = TS_JD_UNIX_EPOCH + t / 86400.
 * Non-finite in, non-finite out (ts_sun_position rejects it).
 */
double ts_julian_day_from_unix(double unix_seconds);

/** Unix time of a Julian day (UT); the inverse of ts_julian_day_from_unix. */
double ts_unix_from_julian_day(double jd);

/**
 * Parse an ISO 8601 / RFC 3339 date and time with a UTC offset:
 *
 *     YYYY-MM-DDThh:mm[:ss[.fff...]](Z | +hh:mm | -hh:mm | +hhmm | +hh)
 *
 * e.g. "2026-06-21T07:30:00+02:00", "2026-06-21T05:30:00Z",
 * "2026-06-21T05:30:00.25Z". The separator may be 'T', 't' or one space,
 * 'z' is accepted for 'Z' and ',' for the decimal point. A time without an
 * offset is rejected (its instant is unknown), as are impossible dates
 * (month 13, day 32, February 30 or 29 outside a leap year) and times
 * (hour 24 or more, minute 60 or more, second 61 or more; a leap second,
 * ss = 60, is accepted and counted as the first second of the next minute,
 * as POSIX time does).
 *
 * unix_seconds (required) receives the instant as Unix time (see
 * ts_julian_day_from_unix); offset_minutes (may be NULL) the offset east of
 * UTC in minutes, e.g. 120 for +02:00, 0 for Z.
 */
ts_status ts_parse_iso8601(const char *s, double *unix_seconds,
                           int *offset_minutes, ts_error *err);

/* ------------------------------------------------------------ the sun */

/** Default refraction at sunrise and sunset, degrees (paper, A.2). */
#define TS_SUN_DEFAULT_ATMOS_REFRACTION 0.5667
/** Default TT - UT, seconds: about its value in the 2020s. */
#define TS_SUN_DEFAULT_DELTA_T 69.0

/** Where and when to compute the sun's position. Fill with ts_sun_input_default. */
typedef struct {
    double jd;               /**< Julian day, UT (ts_julian_day, ts_julian_day_from_unix);
                                  years -2000 to 6000 */
    double longitude;        /**< observer, degrees, east positive, [-180, 180] */
    double latitude;         /**< observer, degrees, north positive, [-90, 90] */
    double elevation;        /**< observer, metres above sea level (>= -6500000) */
    double pressure;         /**< mean annual local pressure, hPa = mbar, (0, 5000] */
    double temperature;      /**< mean annual local temperature, deg C, (-273, 6000] */
    double delta_t;          /**< TT - UT, seconds, |delta_t| <= 8000 */
    double atmos_refraction; /**< refraction at sunrise/sunset, degrees, |.| <= 5 */
} ts_sun_input;

/** Where the sun is, seen from the observer (topocentric). */
typedef struct {
    double zenith;    /**< zenith angle, degrees, with atmospheric refraction */
    double azimuth;   /**< degrees clockwise from north, [0, 360): the paper's
                           Phi, eq. 46 (navigators' and gdaldem's convention) */
    double elevation; /**< 90 - zenith, degrees above the horizontal */
} ts_sun_output;

/**
 * Every intermediate value of the algorithm, named after the paper's
 * symbols, in degrees unless said otherwise: for tests and for callers
 * that want the declination, hour angle or distance.
 */
typedef struct {
    double jd, jde;               /**< Julian day (UT) and ephemeris day (TT), eq. 4-5 */
    double jc, jce, jme;          /**< Julian century, ephemeris century and millennium, eq. 6-8 */
    double L;                     /**< Earth heliocentric longitude, eq. 9-12 */
    double B;                     /**< Earth heliocentric latitude */
    double R;                     /**< Earth-Sun distance, astronomical units */
    double theta;                 /**< geocentric longitude Theta, eq. 13 */
    double beta;                  /**< geocentric latitude, eq. 14 */
    double x[5];                  /**< nutation arguments X0..X4, eq. 15-19 */
    double delta_psi;             /**< nutation in longitude, eq. 22 */
    double delta_epsilon;         /**< nutation in obliquity, eq. 23 */
    double epsilon0;              /**< mean obliquity of the ecliptic, arc seconds, eq. 24 */
    double epsilon;               /**< true obliquity of the ecliptic, eq. 25 */
    double delta_tau;             /**< aberration correction, eq. 26 */
    double lambda;                /**< apparent sun longitude, eq. 27 */
    double nu0, nu;               /**< mean and apparent sidereal time at Greenwich, eq. 28-29 */
    double alpha, delta;          /**< geocentric right ascension and declination, eq. 30-31 */
    double H;                     /**< observer local hour angle, eq. 32 */
    double xi;                    /**< equatorial horizontal parallax of the sun, eq. 33 */
    double delta_alpha;           /**< parallax in right ascension, eq. 37 */
    double alpha_prime;           /**< topocentric right ascension, eq. 38 */
    double delta_prime;           /**< topocentric declination, eq. 39 */
    double H_prime;               /**< topocentric local hour angle, eq. 40 */
    double e0;                    /**< topocentric elevation without refraction, eq. 41 */
    double delta_e;               /**< atmospheric refraction correction, eq. 42 */
    double e;                     /**< topocentric elevation, eq. 43 */
    double zenith;                /**< topocentric zenith angle, eq. 44 */
    double gamma;                 /**< astronomers' azimuth (from south, westward), eq. 45 */
    double phi;                   /**< azimuth from north, eastward, eq. 46 */
} ts_sun_detail;

/**
 * Defaults: jd unset (NaN: it must be filled in), longitude, latitude and
 * elevation 0, pressure 1013.25 hPa, temperature 15 C, delta_t
 * TS_SUN_DEFAULT_DELTA_T, atmos_refraction TS_SUN_DEFAULT_ATMOS_REFRACTION.
 */
void ts_sun_input_default(ts_sun_input *in);

/** Check an input; the message names the offending field and its value. */
ts_status ts_sun_input_validate(const ts_sun_input *in, ts_error *err);

/**
 * Topocentric position of the sun's centre (paper, sections 3.1-3.15).
 * Refraction (eq. 42) is applied only while the unrefracted sun is above
 * -(sun radius + atmos_refraction), i.e. while its upper limb can be seen
 * above a level horizon; below that the geometric elevation is returned.
 */
ts_status ts_sun_position(const ts_sun_input *in, ts_sun_output *out,
                          ts_error *err);

/**
 * The refraction (eq. 42) that ts_sun_position adds to the unrefracted
 * elevation e0 (degrees), with its cut-off: 0 below -(sun radius +
 * atmos_refraction), where it jumps (0.6 deg at the defaults), so
 * elevations interpolated between sites are interpolated unrefracted and
 * refracted after. `in` gives pressure, temperature and atmos_refraction.
 */
double ts_sun_refraction(double e0, const ts_sun_input *in);

/** ts_sun_position that also fills `detail` (may be NULL). */
ts_status ts_sun_position_detail(const ts_sun_input *in, ts_sun_output *out,
                                 ts_sun_detail *detail, ts_error *err);

/**
 * ts_sun_position_detail at in's site, its sections 3.1-3.10 (what depends
 * on the instant only: jd and delta_t) taken from `instant`, the detail of
 * a call of ts_sun_position_detail at the same instant: the same results,
 * bit for bit, at the cost of sections 3.11-3.15 alone, to place the sun
 * at many sites of one instant. An `instant` of another jd or delta_t is
 * an error.
 */
ts_status ts_sun_position_from(const ts_sun_input *in, const ts_sun_detail *instant,
                               ts_sun_output *out, ts_sun_detail *detail, ts_error *err);

#ifdef __cplusplus
}
#endif

#endif /* TERRASHADE_SUN_H */
