/* Sun position (Reda & Andreas SPA), geometric sanity cases: solstice,
 * equinox, polar day and night, sunrise, the refraction near the horizon
 * and over the driver's physical ranges, every output in range over a grid
 * of places and times. The published values are in check_sun.c. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade_sun.h"
#include "test_expect.h"
#include "test_run.h"
#include "test_sun.h"

/* Sun at a UTC time given as ISO 8601 text. */
static ts_sun_output sun_at(const char *iso, double lat, double lon)
{
    ts_sun_input in;
    ts_sun_output out;
    ts_error err;
    double t;
    ts_sun_input_default(&in);
    ck_assert_msg(ts_parse_iso8601(iso, &t, NULL, &err) == TS_OK, "%s", err.message);
    in.jd = ts_julian_day_from_unix(t);
    in.latitude = lat;
    in.longitude = lon;
    ck_assert_msg(ts_sun_position(&in, &out, &err) == TS_OK, "%s", err.message);
    return out;
}

static ts_sun_output sun_unix(double t, double lat, double lon)
{
    ts_sun_input in;
    ts_sun_output out;
    ts_error err;
    ts_sun_input_default(&in);
    in.jd = ts_julian_day_from_unix(t);
    in.latitude = lat;
    in.longitude = lon;
    ck_assert_msg(ts_sun_position(&in, &out, &err) == TS_OK, "%s", err.message);
    return out;
}

/* June solstice 2026 (June 21, 08:24 UTC): at the Tropic of Cancer on the
 * Greenwich meridian the sun passes through the zenith at solar noon,
 * which the equation of time (-1.7 min) puts at about 12:01:45 UTC. */
START_TEST(test_solstice_tropic)
{
    double t0 = unix_of("2026-06-21T11:00:00Z");
    double best = -90.0, best_t = 0.0;
    for (int s = 0; s <= 2 * 3600; s += 10) {
        ts_sun_output o = sun_unix(t0 + s, 23.44, 0.0);
        if (o.elevation > best) {
            best = o.elevation;
            best_t = t0 + s;
        }
    }
    double noon_min = (best_t - unix_of("2026-06-21T12:00:00Z")) / 60.0;
    printf("solstice at 23.44N: max elevation %.4f at 12:00 UTC %+.2f min\n", best, noon_min);
    ck_assert_msg(best > 89.5, "max elevation %.4f", best);
    ck_assert_msg(noon_min > 0.5 && noon_min < 3.5, "solar noon at %+.2f min", noon_min);
    /* Before noon the sun is east of the meridian, after it west. */
    ck_assert(sun_at("2026-06-21T10:00:00Z", 23.44, 0.0).azimuth < 180.0);
    ck_assert(sun_at("2026-06-21T14:00:00Z", 23.44, 0.0).azimuth > 180.0);
    /* Further north the noon sun stands south, further south it stands north. */
    ts_sun_output n = sun_at("2026-06-21T12:02:00Z", 45.0, 0.0);
    ts_sun_output s = sun_at("2026-06-21T12:02:00Z", 0.0, 0.0);
    CK_NEAR(n.azimuth, 180.0, 1.0, "noon azimuth at 45N");
    CK_NEAR(n.elevation, 90.0 - 45.0 + 23.44, 0.1, "noon elevation at 45N");
    ck_assert_msg(s.azimuth < 1.0 || s.azimuth > 359.0, "noon azimuth at the equator %.3f",
                  s.azimuth);
    CK_NEAR(s.elevation, 90.0 - 23.44, 0.1, "noon elevation at the equator");
}
END_TEST

/* March equinox 2026 (March 20, 14:46 UTC): the sun near the zenith at
 * the equator around solar noon. */
START_TEST(test_equinox_equator)
{
    double t0 = unix_of("2026-03-20T11:00:00Z");
    double best = -90.0;
    for (int s = 0; s <= 2 * 3600; s += 10) {
        ts_sun_output o = sun_unix(t0 + s, 0.0, 0.0);
        if (o.elevation > best)
            best = o.elevation;
    }
    /* And at 14:46 UTC, straight over 41.5 W (solar noon there then). */
    ts_sun_output o = sun_at("2026-03-20T14:53:00Z", 0.0, -41.5);
    printf("equinox at the equator: max elevation %.4f; at 41.5W %.4f\n", best, o.elevation);
    ck_assert_msg(best > 89.0, "max elevation %.4f", best);
    ck_assert_msg(o.elevation > 89.0, "elevation %.4f", o.elevation);
}
END_TEST

START_TEST(test_polar_day_night)
{
    /* 80 N, June 21: the sun never sets, lowest at local midnight. */
    ts_sun_output mid = sun_at("2026-06-21T00:00:00Z", 80.0, 0.0);
    printf("80N June 21 00:00 UTC: elevation %.3f azimuth %.3f\n", mid.elevation, mid.azimuth);
    ck_assert_msg(mid.elevation > 0.0, "midnight sun below the horizon: %.3f", mid.elevation);
    CK_NEAR(mid.elevation, 23.44 - 10.0, 0.5, "midnight sun elevation");
    ck_assert_msg(mid.azimuth < 2.0 || mid.azimuth > 358.0, "midnight sun azimuth %.3f",
                  mid.azimuth);
    /* 80 N, December 21: polar night, the sun below the horizon at noon. */
    ts_sun_output noon = sun_at("2026-12-21T12:00:00Z", 80.0, 0.0);
    printf("80N Dec 21 12:00 UTC: elevation %.3f azimuth %.3f\n", noon.elevation, noon.azimuth);
    ck_assert_msg(noon.elevation < 0.0, "sun above the horizon in polar night: %.3f",
                  noon.elevation);
    CK_NEAR(noon.elevation, 10.0 - 23.44, 0.5, "polar night noon elevation");
    /* The whole day. */
    double day = unix_of("2026-06-21T00:00:00Z"), night = unix_of("2026-12-21T00:00:00Z");
    for (int s = 0; s < 86400; s += 600) {
        ck_assert(sun_unix(day + s, 80.0, 0.0).elevation > 0.0);
        ck_assert(sun_unix(night + s, 80.0, 0.0).elevation < 0.0);
        ck_assert(sun_unix(day + s, -80.0, 0.0).elevation < 0.0); /* austral winter */
    }
}
END_TEST

/* At the equator on the equinox the sun rises due east and sets due west. */
START_TEST(test_equinox_sunrise)
{
    double lo = unix_of("2026-03-20T05:00:00Z"), hi = unix_of("2026-03-20T07:00:00Z");
    ck_assert(sun_unix(lo, 0.0, 0.0).elevation < 0.0);
    ck_assert(sun_unix(hi, 0.0, 0.0).elevation > 0.0);
    for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        if (sun_unix(mid, 0.0, 0.0).elevation < 0.0)
            lo = mid;
        else
            hi = mid;
    }
    ts_sun_output rise = sun_unix(hi, 0.0, 0.0);
    printf("equinox sunrise at 0N 0E: %.1f min after 06:00 UTC, azimuth %.4f\n",
           (hi - unix_of("2026-03-20T06:00:00Z")) / 60.0, rise.azimuth);
    CK_NEAR(rise.azimuth, 90.0, 1.0, "sunrise azimuth");
    ts_sun_output set = sun_at("2026-03-20T18:07:00Z", 0.0, 0.0);
    CK_NEAR(set.azimuth, 270.0, 1.0, "sunset azimuth");
}
END_TEST

/* Refraction: about half a degree at the horizon, nothing far below it,
 * none with a vacuum-thin atmosphere. */
START_TEST(test_refraction)
{
    ts_sun_input in;
    ts_sun_output out;
    ts_sun_detail d;
    ts_error err;
    ts_sun_input_default(&in);
    double t0 = unix_of("2026-03-20T06:00:00Z");
    for (int s = -3600; s <= 3600; s += 60) {
        in.jd = ts_julian_day_from_unix(t0 + s);
        ck_assert(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK);
        ck_assert(isfinite(out.zenith) && isfinite(out.azimuth));
        ck_assert(out.azimuth >= 0.0 && out.azimuth < 360.0);
        if (d.e0 < -(0.26667 + 0.5667))
            ck_assert(d.delta_e == 0.0);
        else
            ck_assert(d.delta_e > 0.0 && d.delta_e < 0.75);
        if (fabs(d.e0) < 0.01)
            CK_NEAR(d.delta_e, 0.48, 0.05, "refraction at the horizon");
    }
    in.pressure = 1e-6;
    in.jd = ts_julian_day_from_unix(t0);
    ck_assert(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK);
    ck_assert(d.delta_e < 1e-8);
}
END_TEST

/* The refraction over the physical ranges of the driver (300..1100 hPa,
 * -90..60 C): at most about a degree, and the elevation stays in
 * [-90, 90]; outside them (near absolute zero) the core refuses with a
 * sentence instead of returning an elevation of thousands of degrees. */
START_TEST(test_refraction_bounds)
{
    ts_sun_input in;
    ts_sun_output out;
    ts_sun_detail d;
    ts_error err;
    ts_sun_input_default(&in);
    double sunrise = unix_of("2026-03-20T06:00:00Z"), noon = unix_of("2026-03-20T12:00:00Z");
    const double pressures[] = {300.0, 1013.25, 1100.0}, temps[] = {-90.0, 15.0, 60.0};
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 3; k++)
            for (int s = -1800; s <= 1800; s += 30) {
                in.pressure = pressures[p];
                in.temperature = temps[k];
                in.latitude = 0.0;
                in.longitude = 0.0;
                in.jd = ts_julian_day_from_unix(sunrise + s);
                ck_assert_msg(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK, "%s",
                              err.message);
                ck_assert(out.elevation >= -90.0 && out.elevation <= 90.0);
                ck_assert_msg(d.delta_e >= 0.0 && d.delta_e < 1.1, "refraction %g at %g hPa, %g C",
                              d.delta_e, in.pressure, in.temperature);
                /* near the zenith (noon at the equator, equinox): a few thousandths */
                in.jd = ts_julian_day_from_unix(noon + s / 10.0);
                in.longitude = -0.1;
                ck_assert(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK);
                ck_assert(out.elevation >= -90.0 && out.elevation <= 90.0);
                ck_assert(out.elevation > 85.0 && fabs(d.delta_e) < 0.01);
            }
    /* TEMPERATURE=-272.999: the formula would give a sun thousands of
     * degrees high */
    ts_sun_input_default(&in);
    in.temperature = -272.999;
    in.jd = ts_julian_day_from_unix(sunrise + 600); /* the sun 1 degree up */
    EXPECT_ARG(ts_sun_position(&in, &out, &err), &err);
    ck_assert_msg(strstr(err.message, "outside -90 to 90") &&
                      strstr(err.message, "refraction model does not hold"),
                  "%s", err.message);
    /* a large atmos_refraction reaches the pole of eq. 42 (e0 = -5.11):
     * either a sun in range or the same refusal, never anything else */
    ts_sun_input_default(&in);
    in.atmos_refraction = 5.0;
    for (int s = 0; s <= 3600; s += 5) {
        in.jd = ts_julian_day_from_unix(sunrise - s);
        ts_status st = ts_sun_position(&in, &out, &err);
        ck_assert(st == TS_OK || st == TS_ERR_ARG);
        if (st == TS_OK)
            ck_assert(out.elevation >= -90.0 && out.elevation <= 90.0);
    }
}
END_TEST

/* Every azimuth and zenith in range over a coarse grid of places and times. */
START_TEST(test_ranges)
{
    double t0 = unix_of("2026-01-01T00:00:00Z");
    for (int day = 0; day < 365; day += 17)
        for (int h = 0; h < 24; h += 5)
            for (int lat = -90; lat <= 90; lat += 15)
                for (int lon = -180; lon <= 180; lon += 45) {
                    ts_sun_output o = sun_unix(t0 + day * 86400.0 + h * 3600.0, lat, lon);
                    ck_assert(o.azimuth >= 0.0 && o.azimuth < 360.0);
                    ck_assert(o.zenith >= 0.0 && o.zenith <= 180.0);
                    ck_assert(fabs(o.elevation + o.zenith - 90.0) < 1e-9);
                }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("sun_geometry");
    TCase *geometry = tcase_create("geometry");
    tcase_set_timeout(geometry, 60);
    tcase_add_test(geometry, test_solstice_tropic);
    tcase_add_test(geometry, test_equinox_equator);
    tcase_add_test(geometry, test_polar_day_night);
    tcase_add_test(geometry, test_equinox_sunrise);
    tcase_add_test(geometry, test_refraction);
    tcase_add_test(geometry, test_refraction_bounds);
    tcase_add_test(geometry, test_ranges);
    suite_add_tcase(s, geometry);
    return test_run_suite(s);
}
