/* The sun over a day at a site (core/day_cycle.h): dates and offsets,
 * sampling times, hours of sun against the astronomical day length,
 * progress and cancelling, polar night and day, bad sites, per-cell sun
 * positions, the atlas's sampling times. Shadows, grid north, the clear-sky
 * model and the insolation are in check_daycycle_light.c. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "test_daycycle.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"
#include "test_site.h"

/* Apparent elevation at t minus `target`. */
static double elev_at(const ts_sun_sites *s, const ts_day_opts *o, double t)
{
    ts_sun_sample smp;
    ts_error err;
    ck_assert_msg(ts_sun_at_site(s, o, t, &smp, &err) == TS_OK, "%s", err.message);
    return smp.elevation;
}

/* Time within [a, b] where the elevation crosses `target` (bisection). */
static double crossing(const ts_sun_sites *s, const ts_day_opts *o, double a, double b,
                       double target)
{
    double fa = elev_at(s, o, a) - target;
    for (int i = 0; i < 60; i++) {
        double m = 0.5 * (a + b), fm = elev_at(s, o, m) - target;
        if ((fm > 0) == (fa > 0)) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    return 0.5 * (a + b);
}

/* Seconds during [start, start + 86400) with the apparent elevation above
 * `target`: scan every minute, refine each crossing. */
static double time_above(const ts_sun_sites *s, const ts_day_opts *o, double start,
                         double target)
{
    double total = 0, prev_t = start;
    int prev_up = elev_at(s, o, start) > target;
    double since = prev_up ? start : NAN;
    for (int k = 1; k <= 1440; k++) {
        double t = start + 60.0 * k;
        int up = elev_at(s, o, t) > target;
        if (up != prev_up) {
            double c = crossing(s, o, prev_t, t, target);
            if (up)
                since = c;
            else
                total += c - since;
        }
        prev_up = up;
        prev_t = t;
    }
    if (prev_up)
        total += start + 86400.0 - since;
    return total;
}

/* ------------------------------------------------------------ parsing */

START_TEST(test_parse_date_and_offset)
{
    ts_error err;
    int y, m, d, off;
    ck_assert(ts_parse_date("2026-06-21", &y, &m, &d, &err) == TS_OK);
    ck_assert(y == 2026 && m == 6 && d == 21);
    ck_assert(ts_parse_date("2024-02-29", &y, &m, &d, &err) == TS_OK);
    EXPECT_ARG(ts_parse_date("2026-02-29", &y, &m, &d, &err), &err);
    ck_assert(strstr(err.message, "there is no day 29"));
    EXPECT_ARG(ts_parse_date("2026-13-01", &y, &m, &d, &err), &err);
    EXPECT_ARG(ts_parse_date("2026-6-21", &y, &m, &d, &err), &err);
    ck_assert(strstr(err.message, "YYYY-MM-DD"));
    EXPECT_ARG(ts_parse_date("21.06.2026", &y, &m, &d, &err), &err);
    EXPECT_ARG(ts_parse_date("2026-06-21T00:00Z", &y, &m, &d, &err), &err);
    ck_assert(strstr(err.message, "DATETIME"));
    EXPECT_ARG(ts_parse_date("2026-06-21+02:00", &y, &m, &d, &err), &err);
    ck_assert(strstr(err.message, "followed by '+02:00'") && strstr(err.message, "TIMEZONE"));
    EXPECT_ARG(ts_parse_date("", &y, &m, &d, &err), &err);

    ck_assert(ts_parse_utc_offset("+02:00", &off, &err) == TS_OK && off == 120);
    ck_assert(ts_parse_utc_offset("-0530", &off, &err) == TS_OK && off == -330);
    ck_assert(ts_parse_utc_offset("+05", &off, &err) == TS_OK && off == 300);
    ck_assert(ts_parse_utc_offset("Z", &off, &err) == TS_OK && off == 0);
    ck_assert(ts_parse_utc_offset("UTC", &off, &err) == TS_OK && off == 0);
    EXPECT_ARG(ts_parse_utc_offset("Europe/Zurich", &off, &err), &err);
    ck_assert(strstr(err.message, "named time zones"));
    EXPECT_ARG(ts_parse_utc_offset("+24:00", &off, &err), &err);
    EXPECT_ARG(ts_parse_utc_offset("+02:60", &off, &err), &err);
    EXPECT_ARG(ts_parse_utc_offset("2", &off, &err), &err);
    EXPECT_ARG(ts_parse_utc_offset("", &off, &err), &err);

    /* A date and time without an offset (the SPA's parser, used by the
     * driver for DATETIME) is refused. */
    double t;
    EXPECT_ARG(ts_parse_iso8601("2026-06-21T07:30:00", &t, NULL, &err), &err);
    ck_assert(strstr(err.message, "offset"));
}
END_TEST

START_TEST(test_local_day)
{
    /* 2026-06-21 00:00 at +02:00 is 2026-06-20 22:00 UTC */
    double t0 = ts_local_midnight(2026, 6, 21, 120);
    double t;
    ts_error err;
    ck_assert(ts_parse_iso8601("2026-06-20T22:00:00Z", &t, NULL, &err) == TS_OK);
    ck_assert(t0 == t);
    ck_assert(ts_parse_iso8601("2026-06-21T07:30:00+02:00", &t, NULL, &err) == TS_OK);
    ck_assert(ts_local_day_start(t, 120) == t0);
    /* 01:30 local at -05:00 is 06:30 UTC: the local day starts at 05:00 UTC */
    ck_assert(ts_parse_iso8601("2026-01-02T01:30:00-05:00", &t, NULL, &err) == TS_OK);
    ck_assert(ts_local_day_start(t, -300) == ts_local_midnight(2026, 1, 2, -300));

    ck_assert_int_eq(ts_day_step_count(86400, 300), 288);
    ck_assert_int_eq(ts_day_step_count(86400, 7 * 60), 206);
    double mid[206], dur[206];
    ck_assert(ts_day_uniform_times(0, 86400, 420, mid, dur, &err) == TS_OK);
    ck_assert(mid[0] == 210 && dur[0] == 420);
    ck_assert(dur[205] == 86400 - 205 * 420);
    double sum = 0;
    for (int i = 0; i < 206; i++)
        sum += dur[i];
    ck_assert(sum == 86400);
}
END_TEST

/* --------------------------------------------------------- sun hours */

/* Sun hours of a flat plane at sea level under both rules: a step counted
 * while any of the disk is up gives the astronomical day length (upper
 * limb on the horizon, refraction included) within one step; a step
 * weighted by the visible fraction gives the disk fraction above the
 * horizon integrated in 20-second steps, within half a step (which is
 * close to the time the sun's centre is up, unless the sun only grazes
 * the horizon). */
static double flat_sun_hours(const ts_sun_sites *s, double start, double step_min,
                             ts_sun_hours_rule rule)
{
    ts_error err;
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.threads = 1;
    o.sun_hours_rule = rule;
    ts_grid g;
    flat(&g, 16, 30.0, 0.0f);
    float hours[256];
    ck_assert_msg(ts_sun_hours(&g, s, &o, start, 86400, step_min * 60, hours, &err) ==
                      TS_OK, "%s", err.message);
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < 256; i++) {
        lo = fmin(lo, hours[i]);
        hi = fmax(hi, hours[i]);
    }
    ck_assert_msg(hi - lo < 1e-4, "a flat plane: every cell the same");
    ts_grid_free(&g);
    return hi;
}

static void day_length_case(double lat, double lon, const char *date, int offset,
                            double step_min)
{
    int y, m, d;
    ts_error err;
    ck_assert(ts_parse_date(date, &y, &m, &d, &err) == TS_OK);
    double start = ts_local_midnight(y, m, d, offset);
    test_site p;
    test_site_init(&p, lat, lon);
    ts_day_opts o;
    ts_day_opts_default(&o);
    double astro = time_above(&p.s, &o, start, -TS_SUN_RADIUS_DEG) / 3600.0;
    double centre = time_above(&p.s, &o, start, 0.0) / 3600.0;
    double disk = 0;
    for (double t = start + 10.0; t < start + 86400.0; t += 20.0)
        disk += ts_sun_disk_fraction(elev_at(&p.s, &o, t), 0.0) * 20.0 / 3600.0;
    double vis = flat_sun_hours(&p.s, start, step_min, TS_SUN_HOURS_VISIBLE);
    double frac = flat_sun_hours(&p.s, start, step_min, TS_SUN_HOURS_DISK_FRACTION);
    printf("day length %s at %5.1f, %6.1f, step %.0f min: visible %.4f h vs "
           "astronomical day %.4f h (%+.1f min); disk fraction %.4f h vs its integral "
           "%.4f h (%+.2f min), centre up %.4f h\n",
           date, lat, lon, step_min, vis, astro, (vis - astro) * 60, frac, disk,
           (frac - disk) * 60, centre);
    CK_NEAR(vis, astro, step_min / 60.0, "sun hours vs astronomical day length");
    CK_NEAR(frac, disk, 0.5 * step_min / 60.0, "disk-fraction hours vs their integral");
}

START_TEST(test_flat_plane_day_length)
{
    day_length_case(46.5, 7.9, "2026-06-21", 120, 5);    /* Bern, summer */
    day_length_case(46.5, 7.9, "2026-12-21", 60, 5);     /* Bern, winter */
    day_length_case(0.0, -78.5, "2026-03-20", -300, 5);  /* Quito, equinox */
    day_length_case(-33.9, 18.4, "2026-06-21", 120, 5);  /* Cape Town, winter */
    day_length_case(36.6, -84.2, "2026-06-21", -240, 5); /* jacksboro, summer */
    day_length_case(46.5, 7.9, "2026-06-21", 120, 1);    /* one-minute steps */
    day_length_case(64.1, -21.9, "2026-06-01", 0, 5);    /* Reykjavik, long day */
    day_length_case(64.1, -21.9, "2026-12-21", 0, 5);    /* Reykjavik, short day */
    day_length_case(69.6, 18.9, "2026-01-15", 60, 5);    /* Tromso, first days of sun */
    day_length_case(69.6, 18.9, "2026-05-15", 120, 15);  /* Tromso, near midnight sun */
    day_length_case(-77.8, 166.7, "2026-02-20", 780, 5); /* McMurdo, autumn */
}
END_TEST

/* The day products report their steps and stop when asked. */
static int count_progress(double done, void *user)
{
    int *n = user;
    ck_assert(done >= 0.0 && done <= 1.0);
    return ++*n == 50; /* stop at the 50th report */
}

START_TEST(test_day_progress_and_cancel)
{
    ts_error err;
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 4;
    int calls = 0;
    o.horizon.progress = count_progress;
    o.horizon.progress_user = &calls;
    ts_grid g;
    flat(&g, 8, 30.0, 0.0f);
    float out[64];
    double start = ts_local_midnight(2026, 6, 21, 120);
    /* 60-minute steps: 24 steps + the end, under the 50 that cancel */
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 3600, out, &err) == TS_OK);
    ck_assert_int_eq(calls, 25);
    calls = 0;
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 3600, out, NULL, NULL, &err) ==
              TS_OK);
    ck_assert_int_eq(calls, 4 + 24 + 1);
    calls = 0;
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, out, &err) == TS_ERR_CANCELLED);
    ck_assert_int_eq(calls, 50);
    calls = 0;
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 300, out, NULL, NULL, &err) ==
              TS_ERR_CANCELLED);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_polar_night_and_day)
{
    ts_error err;
    test_site p;
    test_site_init(&p, 78.2, 15.6); /* Longyearbyen */
    ts_day_opts o;
    ts_day_opts_default(&o);
    ts_grid g;
    flat(&g, 8, 30.0, 10.0f);
    float hours[64];
    double night = ts_local_midnight(2026, 12, 21, 60);
    ck_assert(ts_sun_hours(&g, &p.s, &o, night, 86400, 300, hours, &err) == TS_OK);
    for (int i = 0; i < 64; i++)
        ck_assert_msg(hours[i] == 0.0f, "polar night: %g h of sun", hours[i]);
    double day = ts_local_midnight(2026, 6, 21, 120);
    ck_assert(ts_sun_hours(&g, &p.s, &o, day, 86400, 300, hours, &err) == TS_OK);
    for (int i = 0; i < 64; i++)
        CK_NEAR(hours[i], 24.0, 1e-4, "midnight sun");
    printf("Longyearbyen: 0 h of sun on 2026-12-21, %.3f h on 2026-06-21\n", hours[0]);
    /* the atlas samples nothing in the polar night */
    double times[16];
    int n = -1;
    ck_assert(ts_day_atlas_times(&p.s, &o, night, 86400, 16, times, &n, &err) == TS_OK);
    ck_assert_int_eq(n, 0);
    /* and the whole day in the polar day */
    ck_assert(ts_day_atlas_times(&p.s, &o, day, 86400, 16, times, &n, &err) == TS_OK);
    ck_assert_int_eq(n, 16);
    /* insolation of the polar night is 0, of the polar day positive */
    float ins[64];
    ck_assert(ts_insolation(&g, &p.s, &o, night, 86400, 300, ins, NULL, NULL, &err) ==
              TS_OK);
    ck_assert(ins[0] == 0.0f);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_bad_sites)
{
    ts_error err;
    test_site p;
    test_site_init(&p, 91.0, 0.0);
    ts_day_opts o;
    ts_day_opts_default(&o);
    ts_grid g;
    flat(&g, 4, 30.0, 0.0f);
    float out[16];
    EXPECT_ARG(ts_sun_hours(&g, &p.s, &o, 0, 86400, 300, out, &err), &err);
    ck_assert(strstr(err.message, "latitude 91 is beyond +/-90"));
    test_site_init(&p, -90.5, 0.0);
    EXPECT_ARG(ts_sun_visibility(&g, &p.s, &o, 0, out, NULL, NULL, NULL, &err), &err);
    test_site_init(&p, 45.0, 200.0);
    EXPECT_ARG(ts_sun_visibility(&g, &p.s, &o, 0, out, NULL, NULL, NULL, &err), &err);
    test_site_init(&p, NAN, 0.0);
    EXPECT_ARG(ts_sun_visibility(&g, &p.s, &o, 0, out, NULL, NULL, NULL, &err), &err);
    test_site_init(&p, 45.0, 0.0);
    EXPECT_ARG(ts_sun_hours(&g, &p.s, &o, 0, 86400, 0, out, &err), &err);
    o.linke_turbidity = 0.5;
    EXPECT_ARG(ts_insolation(&g, &p.s, &o, 0, 86400, 300, out, NULL, NULL, &err), &err);
    ts_day_opts_default(&o);
    /* the SPA's own range of years */
    EXPECT_ARG(ts_sun_hours(&g, &p.s, &o, -1e12, 86400, 300, out, &err), &err);
    ts_grid_free(&g);
}
END_TEST
/* Sites on a lattice: the same site everywhere gives the centre's result
 * bit for bit; latitudes 40..56 N across the grid give each row its own
 * day length. */
START_TEST(test_per_cell_sites)
{
    ts_error err;
    const int n = 32;
    ts_grid g;
    flat(&g, n, 30.0, 0.0f);
    ts_day_opts o;
    ts_day_opts_default(&o);
    double start = ts_local_midnight(2026, 6, 21, 0);
    test_site p;
    test_site_init(&p, 48.0, 0.0);
    float *a = malloc(n * n * sizeof *a), *b = malloc(n * n * sizeof *b);
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 600, a, &err) == TS_OK);
    double lon[9], lat[9], north[9];
    for (int i = 0; i < 9; i++) {
        lon[i] = 0.0;
        lat[i] = 48.0;
        north[i] = 0.0;
    }
    ts_sun_sites s = {3, 3, 0.5, 0.5, (n - 1) / 2.0, (n - 1) / 2.0, lon, lat, north};
    ck_assert(ts_sun_hours(&g, &s, &o, start, 86400, 600, b, &err) == TS_OK);
    ck_assert(memcmp(a, b, n * n * sizeof *a) == 0);
    /* now a 16-degree north-south extent, and longitudes 0..4 E */
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            lat[j * 3 + i] = 56.0 - 8.0 * j;
            lon[j * 3 + i] = 2.0 * i;
        }
    ck_assert(ts_sun_hours(&g, &s, &o, start, 86400, 300, b, &err) == TS_OK);
    for (int y = 0; y < n; y += n - 1) {
        double la = 56.0 - 16.0 * (y + 0.5 - 0.5) / (n - 1);
        test_site q;
        test_site_init(&q, la, 2.0);
        double want = time_above(&q.s, &o, start, 0.0) / 3600.0;
        printf("per cell: row %d (lat %.2f): %.3f h, centre above the horizon %.3f h\n", y,
               la, b[y * n + n / 2], want);
        CK_NEAR(b[y * n + n / 2], want, 5.0 / 60.0, "per-cell day length");
    }
    ck_assert(b[0] > b[(n - 1) * n] + 1.0); /* 56 N has a longer day than 40 N */
    free(a);
    free(b);
    ts_grid_free(&g);
}
END_TEST

/* ------------------------------------------------------------- times */

START_TEST(test_atlas_times)
{
    ts_error err;
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    double start = ts_local_midnight(2026, 6, 21, 120);
    double t[64];
    int n;
    ck_assert(ts_day_atlas_times(&p.s, &o, start, 86400, 64, t, &n, &err) == TS_OK);
    ck_assert_int_eq(n, 64);
    double rise = crossing(&p.s, &o, start + 3 * 3600, start + 8 * 3600, -TS_SUN_RADIUS_DEG);
    double set = crossing(&p.s, &o, start + 18 * 3600, start + 23 * 3600, -TS_SUN_RADIUS_DEG);
    for (int i = 0; i < 64; i++) {
        ck_assert(t[i] > rise - 60 && t[i] < set + 60);
        if (i)
            ck_assert(t[i] > t[i - 1]);
    }
    double first = t[1] - t[0], middle = t[32] - t[31];
    printf("atlas times: %d maps from %.1f to %.1f h local, gap %.1f min at dawn, %.1f min "
           "at noon\n", n, (t[0] - start) / 3600, (t[63] - start) / 3600, first / 60,
           middle / 60);
    ck_assert(first < 0.5 * middle);
}
END_TEST

/* Every atlas instant has the sun's upper limb up, also the first and last
 * of many maps: the minute of sunrise counts from sunrise on. Before, an
 * instant interpolated across that minute could fall while the sun was
 * 0.9 deg down (36 N, 21 June: map 1 of the default 158 at -0.86 deg). */
START_TEST(test_atlas_times_sun_up)
{
    ts_error err;
    static const double sites[][3] = {{36.3, -84.2, -300}, {46.5, 7.9, 120}, {66.0, 25.0, 120}};
    static const int dates[][2] = {{6, 21}, {12, 21}, {3, 20}};
    static double t[1024];
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++)
            for (int n = 158; n <= 1024; n += 866) {
                test_site p;
                test_site_init(&p, sites[k][0], sites[k][1]);
                ts_day_opts o;
                ts_day_opts_default(&o);
                double start = ts_local_midnight(2026, dates[d][0], dates[d][1],
                                                 (int)sites[k][2]);
                int got;
                ck_assert(ts_day_atlas_times(&p.s, &o, start, 86400, n, t, &got, &err) ==
                          TS_OK);
                ck_assert_int_eq(got, n);
                double low = 90;
                for (int i = 0; i < n; i++)
                    low = fmin(low, elev_at(&p.s, &o, t[i]));
                printf("atlas at %.1f N, %02d-%02d, %4d maps: lowest sun %.4f deg\n",
                       sites[k][0], dates[d][0], dates[d][1], n, low);
                ck_assert(low > -TS_SUN_RADIUS_DEG);
            }
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("daycycle");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_parse_date_and_offset);
    tcase_add_test(tc, test_local_day);
    tcase_add_test(tc, test_flat_plane_day_length);
    tcase_add_test(tc, test_day_progress_and_cancel);
    tcase_add_test(tc, test_polar_night_and_day);
    tcase_add_test(tc, test_bad_sites);
    tcase_add_test(tc, test_per_cell_sites);
    tcase_add_test(tc, test_atlas_times);
    tcase_add_test(tc, test_atlas_times_sun_up);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return test_run_suite(suite());
}
