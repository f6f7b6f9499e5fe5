/* Sun position (Reda & Andreas SPA) and date/time parsing: the calendar,
 * the Julian day, ISO 8601, the SPA against published values and its
 * input checks. The geometric sanity cases are in check_sun_geometry.c.
 *
 * Reference values: the worked example of the paper (NREL/TP-560-34302,
 * table A5.1: 2003-10-17 12:30:30 at -7 h, Golden, Colorado) and the
 * examples of Meeus, "Astronomical Algorithms" (2nd ed.) whose tables the
 * paper's are taken from. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade_sun.h"
#include "test_expect.h"
#include "test_run.h"
#include "test_sun.h"

/* The paper's example site and time. */
static void paper_input(ts_sun_input *in)
{
    ts_error err;
    ts_sun_input_default(in);
    ck_assert(ts_julian_day(2003, 10, 17, 19, 30, 30, &in->jd, &err) == TS_OK);
    in->latitude = 39.742476;
    in->longitude = -105.1786;
    in->elevation = 1830.14;
    in->pressure = 820.0;
    in->temperature = 11.0;
    in->delta_t = 67.0;
    in->atmos_refraction = 0.5667;
}

/* ------------------------------------------------------------ dates */

START_TEST(test_calendar)
{
    ck_assert_int_eq(ts_days_from_civil(1970, 1, 1), 0);
    ck_assert_int_eq(ts_days_from_civil(1969, 12, 31), -1);
    ck_assert_int_eq(ts_days_from_civil(2000, 3, 1), 11017);
    ck_assert_int_eq(ts_days_from_civil(0, 3, 1), -719468);
    ck_assert_int_eq(ts_days_from_civil(2026, 6, 21), 1782019800LL / 86400);
    /* Consecutive days across month, year and century ends. */
    for (long long y = -401; y <= 2401; y += 1) {
        for (int m = 1; m <= 12; m++) {
            int dim = ts_days_in_month(y, m);
            long long first = ts_days_from_civil(y, m, 1);
            ck_assert(ts_days_from_civil(y, m, dim) == first + dim - 1);
            long long next = m == 12 ? ts_days_from_civil(y + 1, 1, 1)
                                     : ts_days_from_civil(y, m + 1, 1);
            ck_assert(next == first + dim);
        }
    }
    ck_assert(ts_is_leap_year(2000) && ts_is_leap_year(2024));
    ck_assert(!ts_is_leap_year(1900) && !ts_is_leap_year(2023));
    ck_assert_int_eq(ts_days_in_month(2024, 2), 29);
    ck_assert_int_eq(ts_days_in_month(2100, 2), 28);
    ck_assert_int_eq(ts_days_in_month(2024, 13), 0);
}
END_TEST

START_TEST(test_julian_day)
{
    /* Gregorian rows of the paper's table A4.1 (Meeus, ch. 7). */
    static const struct {
        int y, m, d, hh;
        double jd;
    } rows[] = {
        {2000, 1, 1, 12, 2451545.0}, {1999, 1, 1, 0, 2451179.5},
        {1987, 1, 27, 0, 2446822.5}, {1987, 6, 19, 12, 2446966.0},
        {1988, 1, 27, 0, 2447187.5}, {1988, 6, 19, 12, 2447332.0},
        {1900, 1, 1, 0, 2415020.5},  {1600, 1, 1, 0, 2305447.5},
        {1600, 12, 31, 0, 2305812.5},
    };
    ts_error err;
    double jd;
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        ck_assert(ts_julian_day(rows[i].y, rows[i].m, rows[i].d, rows[i].hh, 0, 0.0,
                                &jd, &err) == TS_OK);
        CK_NEAR(jd, rows[i].jd, 1e-9, "Julian day of table A4.1");
    }
    /* The paper's example instant, three ways. */
    ck_assert(ts_julian_day(2003, 10, 17, 19, 30, 30, &jd, &err) == TS_OK);
    CK_NEAR(jd, 2452930.312847, 1e-6, "JD of 2003-10-17 19:30:30 UT");
    CK_NEAR(ts_julian_day_from_unix(1066419030.0), jd, 1e-9, "JD from Unix time");
    CK_NEAR(ts_julian_day_from_unix(unix_of("2003-10-17T12:30:30-07:00")), jd, 1e-9,
            "JD from ISO 8601");
    CK_NEAR(ts_julian_day_from_unix(0.0), 2440587.5, 0.0, "JD of the Unix epoch");
    CK_NEAR(ts_unix_from_julian_day(2451545.0), 946728000.0, 1e-4, "Unix time of J2000");

    EXPECT_ARG(ts_julian_day(2023, 2, 29, 0, 0, 0.0, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 13, 1, 0, 0, 0.0, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 4, 31, 0, 0, 0.0, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 4, 1, 24, 0, 0.0, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 4, 1, 0, 60, 0.0, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 4, 1, 0, 0, 61.0, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 4, 1, 0, 0, NAN, &jd, &err), &err);
    EXPECT_ARG(ts_julian_day(2023, 4, 1, 0, 0, 0.0, NULL, &err), &err);
    ck_assert(ts_julian_day(2023, 4, 1, 0, 0, -1.0, &jd, NULL) == TS_ERR_ARG);
}
END_TEST

START_TEST(test_iso8601_good)
{
    static const struct {
        const char *s;
        double unix;
        int offset;
    } good[] = {
        {"2026-06-21T07:30:00+02:00", 1782019800.0, 120},
        {"2026-06-21T05:30:00Z", 1782019800.0, 0},
        {"2026-06-21T05:30:00.25Z", 1782019800.25, 0},
        {"2026-06-21T05:30:00,5Z", 1782019800.5, 0},
        {"2026-06-21t05:30z", 1782019800.0, 0},
        {"2026-06-21 01:30:00-0400", 1782019800.0, -240},
        {"2026-06-21T11:00:00+05:30", 1782019800.0, 330},
        {"2026-06-21T10:30:00+05", 1782019800.0, 300},
        {"2026-06-20T23:30:00-06:00", 1782019800.0, -360},
        {"2026-06-21T05:30:00-00:00", 1782019800.0, 0},
        {"1970-01-01T00:00:00Z", 0.0, 0},
        {"1969-12-31T23:59:59.5Z", -0.5, 0},
        {"2016-12-31T23:59:60Z", 1483228800.0, 0}, /* leap second */
        {"2017-01-01T00:59:60+01:00", 1483228800.0, 60}, /* the same, local */
        {"2003-10-17T12:30:30-07:00", 1066419030.0, -420},
        {"2000-01-01T12:00:00Z", 946728000.0, 0},
        {"2024-02-29T12:00:00Z", 1709208000.0, 0},
        {"2000-02-29T00:00:00Z", 951782400.0, 0},
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        double t = -1.0;
        int off = 9999;
        ts_error err;
        ts_status st = ts_parse_iso8601(good[i].s, &t, &off, &err);
        ck_assert_msg(st == TS_OK, "%s: %s", good[i].s, err.message);
        ck_assert_msg(fabs(t - good[i].unix) < 1e-6, "%s: got %.6f, want %.6f", good[i].s,
                      t, good[i].unix);
        ck_assert_msg(off == good[i].offset, "%s: offset %d, want %d", good[i].s, off,
                      good[i].offset);
    }
    /* offset_minutes may be NULL. */
    double t;
    ck_assert(ts_parse_iso8601("2026-06-21T05:30:00Z", &t, NULL, NULL) == TS_OK);
    /* a leap second and a fraction of nines stay within their day: read
     * as the next day's first second, they moved a day product to it */
    ck_assert(ts_parse_iso8601("2016-12-31T23:59:60.5Z", &t, NULL, NULL) == TS_OK);
    ck_assert_msg(t < 1483228800.0, "%.9f", t);
    ck_assert(ts_parse_iso8601("2016-12-31T23:59:60.99999999999999999Z", &t, NULL, NULL) ==
              TS_OK); /* (its nines sum to 61.0: "second 61") */
    ck_assert_msg(t < 1483228800.0, "%.9f", t);
    ck_assert(ts_parse_iso8601("2026-06-21T23:59:59.99999999999999999Z", &t, NULL, NULL) ==
              TS_OK);
    ck_assert_msg(t < 1782086400.0, "%.9f", t);
}
END_TEST

START_TEST(test_iso8601_bad)
{
    static const char *bad[] = {
        "2026-13-01T00:00:00Z",      /* month 13 */
        "2026-00-10T00:00:00Z",      /* month 0 */
        "2026-01-32T00:00:00Z",      /* day 32 */
        "2026-01-00T00:00:00Z",      /* day 0 */
        "2026-02-30T00:00:00Z",      /* February 30 */
        "2023-02-29T00:00:00Z",      /* not a leap year */
        "1900-02-29T00:00:00Z",      /* century, not a leap year */
        "2026-04-31T00:00:00Z",      /* April has 30 days */
        "2026-06-21T25:00:00Z",      /* hour 25 */
        "2026-06-21T24:00:00Z",      /* hour 24 */
        "2026-06-21T12:60:00Z",      /* minute 60 */
        "2026-06-21T12:00:61Z",      /* second 61 */
        "2026-06-21T12:00:60Z",      /* a leap second only ends a UTC day */
        "2016-12-31T23:59:60+01:00", /* 22:59:60 UTC */
        "garbage",
        "",
        "2026-06-21",                /* no time */
        "2026-6-21T12:00:00Z",       /* one-digit month */
        "2026-06-21X12:00:00Z",
        "2026-06-21T12:00:00+2",     /* one-digit offset */
        "2026-06-21T12:00:00+25:00", /* offset out of range */
        "2026-06-21T12:00:00+02:60",
        "2026-06-21T12:00:00Z trailing",
        "2026-06-21T12:00:00ZZ",
        "2026-06-21T12:00:00.Z",     /* no digits after the point */
        "2026-06-21T12Z",            /* no minutes */
        "2026-06-21T12:00:0Z",
        " 2026-06-21T12:00:00Z",
        "2026-06-21T12:00:00 +02:00",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        double t = 12345.0;
        int off = 777;
        ts_error err;
        memset(&err, 0, sizeof err);
        ts_status st = ts_parse_iso8601(bad[i], &t, &off, &err);
        ck_assert_msg(st == TS_ERR_ARG, "'%s' accepted", bad[i]);
        ck_assert_msg(err.code == TS_ERR_ARG && err.message[0], "'%s': no message", bad[i]);
        ck_assert_msg(t == 12345.0 && off == 777, "'%s': outputs written on error", bad[i]);
        printf("%-32s -> %s\n", bad[i], err.message);
    }

    /* A missing offset is named as such. */
    ts_error err;
    double t;
    EXPECT_ARG(ts_parse_iso8601("2026-06-21T07:30:00", &t, NULL, &err), &err);
    ck_assert_msg(strstr(err.message, "offset") && strstr(err.message, "Z"),
                  "message does not ask for an offset or Z: %s", err.message);
    EXPECT_ARG(ts_parse_iso8601("2026-06-21T07:30", &t, NULL, &err), &err);
    ck_assert(strstr(err.message, "offset") != NULL);
    /* The bad field is named. */
    EXPECT_ARG(ts_parse_iso8601("2026-13-01T00:00:00Z", &t, NULL, &err), &err);
    ck_assert(strstr(err.message, "month 13") != NULL);
    EXPECT_ARG(ts_parse_iso8601("2026-02-30T00:00:00Z", &t, NULL, &err), &err);
    ck_assert(strstr(err.message, "day 30") != NULL);
    EXPECT_ARG(ts_parse_iso8601("2026-06-21T25:00:00Z", &t, NULL, &err), &err);
    ck_assert(strstr(err.message, "hour 25") != NULL);

    EXPECT_ARG(ts_parse_iso8601(NULL, &t, NULL, &err), &err);
    EXPECT_ARG(ts_parse_iso8601("2026-06-21T05:30:00Z", NULL, NULL, &err), &err);
    ck_assert(ts_parse_iso8601("2026-02-30T00:00:00Z", &t, NULL, NULL) == TS_ERR_ARG);
}
END_TEST

/* ------------------------------------------------------------ the SPA */

/* The paper's worked example, every intermediate value it lists. */
START_TEST(test_paper_example)
{
    ts_sun_input in;
    ts_sun_output out;
    ts_sun_detail d;
    ts_error err;
    paper_input(&in);
    ck_assert_msg(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK, "%s", err.message);

    printf("paper example: JD %.6f L %.10f B %.10f R %.10f\n"
           "  dpsi %.8f deps %.8f eps %.6f lambda %.10f\n"
           "  alpha %.6f delta %.6f H %.6f alpha' %.6f delta' %.6f H' %.6f\n"
           "  e0 %.6f e %.6f zenith %.6f gamma %.6f azimuth %.6f\n",
           d.jd, d.L, d.B, d.R, d.delta_psi, d.delta_epsilon, d.epsilon, d.lambda,
           d.alpha, d.delta, d.H, d.alpha_prime, d.delta_prime, d.H_prime, d.e0, d.e,
           out.zenith, d.gamma, out.azimuth);

    CK_NEAR(d.jd, 2452930.312847, 1e-6, "JD");
    CK_NEAR(d.L, 24.0182616917, 1e-10, "L");
    CK_NEAR(d.B, -0.0001011219, 1e-10, "B");
    CK_NEAR(d.R, 0.9965422974, 1e-10, "R");
    CK_NEAR(d.theta, 204.0182616917, 1e-10, "Theta");
    CK_NEAR(d.beta, 0.0001011219, 1e-10, "beta");
    CK_NEAR(d.x[0], 17185.861179, 1e-6, "X0");
    CK_NEAR(d.x[1], 1722.893218, 1e-6, "X1");
    CK_NEAR(d.x[2], 18234.075703, 1e-6, "X2");
    CK_NEAR(d.x[3], 18420.071012, 1e-6, "X3");
    CK_NEAR(d.x[4], 51.686951, 1e-6, "X4");
    CK_NEAR(d.delta_psi, -0.00399840, 1e-8, "delta psi");
    CK_NEAR(d.delta_epsilon, 0.00166657, 1e-8, "delta epsilon");
    CK_NEAR(d.epsilon, 23.440465, 1e-6, "epsilon");
    CK_NEAR(d.delta_tau, -0.005711, 1e-6, "delta tau");
    CK_NEAR(d.lambda, 204.0085519281, 1e-10, "lambda");
    CK_NEAR(d.alpha, 202.22741, 1e-5, "alpha");
    CK_NEAR(d.delta, -9.31434, 1e-5, "delta");
    CK_NEAR(d.H, 11.105902, 1e-6, "H");
    /* H' as remembered from the table (11.10629) is 2e-5 deg off
     * H - delta_alpha = 11.10627, which alpha' (matching to 1e-5) implies:
     * checked loosely here, exactly against eq. 40 below. */
    CK_NEAR(d.H_prime, 11.10629, 3e-5, "H'");
    CK_NEAR(d.H_prime, d.H - d.delta_alpha, 1e-12, "H' (eq. 40)");
    CK_NEAR(d.alpha_prime, 202.22704, 1e-5, "alpha'");
    CK_NEAR(d.delta_prime, -9.316179, 1e-6, "delta'");
    CK_NEAR(d.e0, 39.872046, 1e-6, "e0");
    CK_NEAR(d.e, 39.888378, 1e-6, "e");
    CK_NEAR(d.gamma, 14.340241, 1e-6, "Gamma");
    /* The paper's results, to the required 0.0001 deg. */
    CK_NEAR(out.zenith, 50.11162, 1e-4, "topocentric zenith angle");
    CK_NEAR(out.azimuth, 194.34024, 1e-4, "topocentric azimuth");
    CK_NEAR(out.elevation, 90.0 - out.zenith, 1e-12, "elevation");
    CK_NEAR(d.phi, out.azimuth, 0.0, "Phi");

    /* ts_sun_position gives the same, and a NULL err is fine. */
    ts_sun_output out2;
    ck_assert(ts_sun_position(&in, &out2, NULL) == TS_OK);
    ck_assert(out2.zenith == out.zenith && out2.azimuth == out.azimuth);
}
END_TEST

/* Meeus, Astronomical Algorithms (2nd ed.), whose abridged VSOP87 and IAU
 * 1980 nutation tables are the paper's tables A4.2 and A4.3. */
START_TEST(test_meeus_examples)
{
    ts_sun_input in;
    ts_sun_output out;
    ts_sun_detail d;
    ts_error err;
    paper_input(&in);
    in.delta_t = 0.0; /* the examples give dynamical time */

    /* Example 25.b: 1992 Oct 13.0 TD, L, B, R from Appendix III. */
    in.jd = 2448908.5;
    ck_assert(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK);
    CK_NEAR(d.L, 19.907372, 1e-6, "Meeus 25.b L");
    CK_NEAR(d.B, -0.000179, 1e-6, "Meeus 25.b B");
    CK_NEAR(d.R, 0.99760775, 1e-8, "Meeus 25.b R");

    /* Examples 22.a and 12.a: 1987 April 10, 0h. */
    in.jd = 2446895.5;
    ck_assert(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK);
    CK_NEAR(d.delta_psi * 3600.0, -3.788, 1e-3, "Meeus 22.a delta psi (arcsec)");
    CK_NEAR(d.delta_epsilon * 3600.0, 9.443, 1e-3, "Meeus 22.a delta epsilon (arcsec)");
    CK_NEAR(d.epsilon0, 23.0 * 3600 + 26.0 * 60 + 27.407, 1e-3, "Meeus 22.a epsilon0");
    CK_NEAR(d.epsilon, 23.0 + 26.0 / 60 + 36.850 / 3600, 1e-6, "Meeus 22.a epsilon");
    CK_NEAR(d.nu0, (13.0 + 10.0 / 60 + 46.3668 / 3600) * 15.0, 1e-6,
            "Meeus 12.a mean sidereal time");
    CK_NEAR(d.nu, (13.0 + 10.0 / 60 + 46.1351 / 3600) * 15.0, 1e-6,
            "Meeus 12.a apparent sidereal time");
}
END_TEST

START_TEST(test_input_errors)
{
    ts_sun_input in, good;
    ts_sun_output out;
    ts_error err;
    paper_input(&good);

    /* jd left unset by ts_sun_input_default */
    ts_sun_input_default(&in);
    EXPECT_ARG(ts_sun_position(&in, &out, &err), &err);

#define BAD_FIELD(field, value)                                  \
    do {                                                         \
        in = good;                                               \
        in.field = (value);                                      \
        EXPECT_ARG(ts_sun_position(&in, &out, &err), &err);      \
        ck_assert(ts_sun_position(&in, &out, NULL) == TS_ERR_ARG); \
    } while (0)

    BAD_FIELD(latitude, 90.5);
    BAD_FIELD(latitude, -91.0);
    BAD_FIELD(latitude, NAN);
    BAD_FIELD(longitude, 180.01);
    BAD_FIELD(longitude, -200.0);
    BAD_FIELD(longitude, INFINITY);
    BAD_FIELD(elevation, NAN);
    BAD_FIELD(elevation, -7e6);
    BAD_FIELD(pressure, 0.0);
    BAD_FIELD(pressure, -1013.0);
    BAD_FIELD(pressure, 6000.0);
    BAD_FIELD(pressure, NAN);
    BAD_FIELD(temperature, -300.0);
    BAD_FIELD(temperature, INFINITY);
    BAD_FIELD(delta_t, 8001.0);
    BAD_FIELD(delta_t, -9000.0);
    BAD_FIELD(delta_t, NAN);
    BAD_FIELD(atmos_refraction, 6.0);
    BAD_FIELD(atmos_refraction, NAN);
    BAD_FIELD(jd, NAN);
    BAD_FIELD(jd, 1e9);  /* far beyond the year 6000 */
    BAD_FIELD(jd, -1e6); /* before the year -2000 */
#undef BAD_FIELD

    /* The message names the field and the value. */
    in = good;
    in.latitude = 95.0;
    EXPECT_ARG(ts_sun_position(&in, &out, &err), &err);
    ck_assert(strstr(err.message, "atitude") && strstr(err.message, "95"));
    in = good;
    in.delta_t = 9000.0;
    EXPECT_ARG(ts_sun_position(&in, &out, &err), &err);
    ck_assert(strstr(err.message, "delta_t") && strstr(err.message, "9000"));

    EXPECT_ARG(ts_sun_position(NULL, &out, &err), &err);
    EXPECT_ARG(ts_sun_position(&good, NULL, &err), &err);
    EXPECT_ARG(ts_sun_input_validate(NULL, &err), &err);
    ck_assert(ts_sun_input_validate(&good, &err) == TS_OK && err.code == TS_OK);

    /* Limits themselves are valid. */
    in = good;
    in.latitude = 90.0;
    in.longitude = -180.0;
    ck_assert(ts_sun_position(&in, &out, &err) == TS_OK);
    in.latitude = -90.0;
    in.longitude = 180.0;
    ck_assert(ts_sun_position(&in, &out, &err) == TS_OK);
    ts_sun_input_default(NULL); /* no crash */
}
END_TEST

int main(void)
{
    Suite *s = suite_create("sun");
    TCase *dates = tcase_create("dates");
    tcase_add_test(dates, test_calendar);
    tcase_add_test(dates, test_julian_day);
    tcase_add_test(dates, test_iso8601_good);
    tcase_add_test(dates, test_iso8601_bad);
    suite_add_tcase(s, dates);
    TCase *spa = tcase_create("spa");
    tcase_set_timeout(spa, 60);
    tcase_add_test(spa, test_paper_example);
    tcase_add_test(spa, test_meeus_examples);
    tcase_add_test(spa, test_input_errors);
    suite_add_tcase(s, spa);
    return test_run_suite(s);
}
