/* The sun over a day (core/day_cycle.h): dates and offsets, sampling
 * times, hours of sun against the astronomical day length, polar night
 * and day, shadows, per-cell sun positions, the clear-sky model and the
 * insolation. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"
#include "test_site.h"

#define CK_NEAR(got, want, tol, what)                                                 \
    ck_assert_msg(fabs((double)(got) - (double)(want)) <= (tol),                      \
                  "%s: got %.6f, want %.6f +/- %g", what, (double)(got), (double)(want), \
                  (double)(tol))

static void flat(ts_grid *g, int n, double cell, float z)
{
    tdem_create(g, n, n, cell, cell);
    tdem_fill(g, z);
}

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

/* A north-south ridge 150 m above the plain: cells just west of it lose
 * the morning sun, cells just east the evening sun, cells far from it
 * little; a deep pit gets none. */
START_TEST(test_shadows_cut_sun_hours)
{
    ts_error err;
    const int n = 64;
    ts_grid g;
    flat(&g, n, 30.0, 500.0f);
    for (int y = 0; y < n; y++)
        for (int x = 40; x < 44; x++)
            g.z[y * n + x] = 650.0f; /* ridge, columns 40..43 */
    for (int y = 10; y < 14; y++)
        for (int x = 10; x < 14; x++)
            g.z[y * n + x] = -2000.0f; /* deep 4 x 4 pit, 120 m wide */
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    float *h = malloc(n * n * sizeof *h);
    double start = ts_local_midnight(2026, 6, 21, 120);
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, h, &err) == TS_OK);
    double far = h[32 * n + 2], west = h[32 * n + 38], east = h[32 * n + 45],
           crest = h[32 * n + 41], pit = h[11 * n + 11];
    printf("ridge: 1140 m west %.3f h, just west %.3f h, crest %.3f h, just east %.3f h, "
           "pit %.3f h\n", far, west, crest, east, pit);
    ck_assert(far > 14.5);
    ck_assert(west < far - 5.0 && east < far - 5.0);
    ck_assert(crest >= far);
    ck_assert(pit == 0.0f);
    /* Weighting by the disk fraction never gives more, and gives less
     * where the disk is cut by the ridge or the plane's own horizon. */
    float *f = malloc(n * n * sizeof *f);
    o.sun_hours_rule = TS_SUN_HOURS_DISK_FRACTION;
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, f, &err) == TS_OK);
    double less = 0;
    for (int i = 0; i < n * n; i++) {
        ck_assert_msg(f[i] <= h[i] + 1e-5f, "cell %d: fraction %g h > visible %g h", i,
                      f[i], h[i]);
        less = fmax(less, h[i] - f[i]);
    }
    printf("ridge: disk-fraction hours at most %.3f h below visible hours\n", less);
    ck_assert(f[32 * n + 2] < far);
    ck_assert(f[11 * n + 11] == 0.0f);
    o.sun_hours_rule = (ts_sun_hours_rule)7;
    EXPECT_ARG(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, f, &err), &err);
    ck_assert(strstr(err.message, "sun-hours rule"));
    free(f);
    free(h);
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

/* The grid azimuth of true north turns the sweeps: a short wall due (grid)
 * north of a cell leaves it in the 07:00 sun (azimuth ~68) when grid north
 * is true north, and shades it when true north lies at grid azimuth -90
 * (the sun then comes from grid azimuth ~338). */
START_TEST(test_grid_north)
{
    ts_error err;
    const int n = 32;
    ts_grid g;
    flat(&g, n, 30.0, 0.0f);
    for (int x = 12; x <= 20; x++)
        g.z[3 * n + x] = 300.0f; /* a wall on row 3, north of cell (16, 8) */
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    double t;
    ck_assert(ts_parse_iso8601("2026-06-21T07:00:00+02:00", &t, NULL, &err) == TS_OK);
    float vis[n * n], az[n * n], el[n * n];
    ts_sun_sample ref;
    ck_assert(ts_sun_visibility(&g, &p.s, &o, t, vis, az, el, &ref, &err) == TS_OK);
    printf("07:00 at Bern: sun at azimuth %.2f, elevation %.2f\n", ref.azimuth,
           ref.elevation);
    ck_assert(ref.azimuth > 60 && ref.azimuth < 80 && ref.elevation > 10);
    ck_assert(vis[8 * n + 16] == 1.0f); /* the wall is north: lit */
    p.north = -90.0;                    /* true east is grid north */
    ck_assert(ts_sun_visibility(&g, &p.s, &o, t, vis, az, el, &ref, &err) == TS_OK);
    CK_NEAR(ref.grid_azimuth, ref.azimuth - 90.0 + (ref.azimuth < 90 ? 360 : 0), 1e-9,
            "grid azimuth");
    CK_NEAR(az[0], ref.grid_azimuth, 1e-4, "cell azimuth");
    ck_assert(vis[8 * n + 16] == 0.0f); /* the sun now comes over the wall */
    ts_grid_free(&g);
}
END_TEST

/* ------------------------------------------------------------ clear sky */

START_TEST(test_esra)
{
    ts_clear_sky c;
    /* Sun at the zenith, sea level, TL = 3, mean distance: m ~ 1,
     * 1/dR = 6.6296 + 1.7513 - 0.1202 + 0.0065 - 0.00013 = 8.26717 */
    ts_clear_sky_esra(90.0, 0.0, 3.0, 1.0, &c);
    double m = 1.0 / (1.0 + 0.50572 * pow(96.07995, -1.6364));
    double dr = 1.0 / (6.6296 + 1.7513 * m - 0.1202 * m * m + 0.0065 * pow(m, 3) -
                       0.00013 * pow(m, 4));
    double bn = 1367.0 * exp(-0.8662 * 3.0 * m * dr);
    printf("ESRA, zenith sun, TL 3: beam %.2f W/m2, diffuse %.2f W/m2\n", c.beam_normal,
           c.diffuse_horizontal);
    CK_NEAR(c.beam_normal, bn, 1e-9, "beam normal");
    CK_NEAR(c.beam_horizontal, bn, 1e-9, "beam horizontal");
    CK_NEAR(c.beam_normal, 998.36, 0.05, "beam normal (hand value)");
    /* Trd(3) = 0.079203, Fd(90) = A0 + A1 + A2 = 0.996504 */
    CK_NEAR(c.diffuse_horizontal, 1367.0 * 0.0792027 * 0.996504, 0.01, "diffuse");
    /* higher site: less air, more beam */
    ts_clear_sky hi;
    ts_clear_sky_esra(30.0, 3000.0, 3.0, 1.0, &hi);
    ts_clear_sky_esra(30.0, 0.0, 3.0, 1.0, &c);
    ck_assert(hi.beam_normal > c.beam_normal);
    /* more turbidity: less beam, more diffuse */
    ts_clear_sky turbid;
    ts_clear_sky_esra(30.0, 0.0, 6.0, 1.0, &turbid);
    ck_assert(turbid.beam_normal < c.beam_normal);
    ck_assert(turbid.diffuse_horizontal > c.diffuse_horizontal);
    /* sun at or below the horizon: nothing */
    ts_clear_sky_esra(0.0, 0.0, 3.0, 1.0, &c);
    ck_assert(c.beam_normal == 0 && c.diffuse_horizontal == 0);
    /* closer sun, more light: 1 / R^2 */
    ts_clear_sky_esra(90.0, 0.0, 3.0, 0.5, &c);
    CK_NEAR(c.beam_normal, 4 * bn, 1e-6, "1/R^2");
}
END_TEST

/* The insolation of a flat open plane is the clear-sky global horizontal
 * irradiation, summed step by step here independently. */
START_TEST(test_insolation_flat)
{
    ts_error err;
    ts_grid g;
    flat(&g, 16, 30.0, 400.0f);
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 8;
    double start = ts_local_midnight(2026, 6, 21, 120);
    float tot[256], beam[256], dif[256];
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 300, tot, beam, dif, &err) ==
              TS_OK);
    double want_b = 0, want_d = 0;
    for (int k = 0; k < 288; k++) {
        ts_sun_sample s;
        ck_assert(ts_sun_at_site(&p.s, &o, start + 300 * k + 150, &s, &err) == TS_OK);
        ts_clear_sky c;
        ts_clear_sky_esra(s.elevation, 400.0, 3.0, s.distance_au, &c);
        double f = ts_sun_disk_fraction(s.elevation, 0.0);
        want_b += c.beam_horizontal * f * 300 / 3600.0;
        want_d += c.diffuse_horizontal * 300 / 3600.0;
    }
    int mid = 8 * 16 + 8;
    printf("insolation, Bern 400 m, 2026-06-21, TL 3: %.1f Wh/m2 (beam %.1f, diffuse "
           "%.1f); independent sum %.1f\n",
           tot[mid], beam[mid], dif[mid], want_b + want_d);
    CK_NEAR(beam[mid], want_b, 1e-3 * want_b, "beam");
    CK_NEAR(dif[mid], want_d, 1e-3 * want_d, "diffuse");
    CK_NEAR(tot[mid], beam[mid] + dif[mid], 0.1, "total");
    ck_assert(tot[mid] > 7000 && tot[mid] < 9000); /* clear June day, mid latitudes */
    /* a south-facing 30-degree slope gets more in December, less direct
     * light faces north */
    ts_grid_free(&g);
}
END_TEST

/* The lattice path of the insolation (per-cell sun) gives the single
 * site's result when every node is that site. */
START_TEST(test_insolation_lattice)
{
    ts_error err;
    const int n = 24;
    ts_grid g;
    tdem_create(&g, n, n, 30.0, 30.0);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++)
            g.z[y * n + x] = (float)(800 + 60 * sin(x * 0.4) * cos(y * 0.3) + 4 * y);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 8;
    double start = ts_local_midnight(2026, 3, 1, 60);
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    p.north = 1.5;
    double lon[4] = {7.9, 7.9, 7.9, 7.9}, lat[4] = {46.5, 46.5, 46.5, 46.5},
           north[4] = {1.5, 1.5, 1.5, 1.5};
    ts_sun_sites s = {2, 2, 0.5, 0.5, n - 1.0, n - 1.0, lon, lat, north};
    float a[3][24 * 24], b[3][24 * 24];
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 900, a[0], a[1], a[2], &err) == TS_OK);
    ck_assert(ts_insolation(&g, &s, &o, start, 86400, 900, b[0], b[1], b[2], &err) == TS_OK);
    double worst = 0;
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < n * n; i++)
            worst = fmax(worst, fabs(a[k][i] - b[k][i]) / fmax(1.0, fabs(a[k][i])));
    printf("insolation, one site vs a lattice of the same site: max relative diff %.2g\n",
           worst);
    ck_assert(worst < 1e-4);
    ts_grid_free(&g);
}
END_TEST

/* Slopes: in December at 46.5 N a south-facing slope gets more than the
 * plain, a north-facing one less; a pit's floor gets little beam. */
START_TEST(test_insolation_slopes)
{
    ts_error err;
    const int n = 48;
    ts_grid g;
    tdem_create(&g, n, n, 30.0, 30.0);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            double yy = y < n / 2 ? y : n - 1 - y; /* a roof: ridge at the middle */
            g.z[y * n + x] = (float)(1000.0 + 30.0 * yy * tan(30 * M_PI / 180));
        }
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 16;
    double start = ts_local_midnight(2026, 12, 21, 60);
    float *tot = malloc(n * n * sizeof *tot);
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 600, tot, NULL, NULL, &err) == TS_OK);
    double north = tot[(n / 4) * n + n / 2], south = tot[(3 * n / 4) * n + n / 2];
    ts_grid_free(&g);
    flat(&g, n, 30.0, 1000.0f);
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 600, tot, NULL, NULL, &err) == TS_OK);
    double plain = tot[(n / 2) * n + n / 2];
    printf("December: north slope %.0f, plain %.0f, south slope %.0f Wh/m2\n", north, plain,
           south);
    ck_assert(south > 1.5 * plain);
    ck_assert(north < 0.6 * plain);
    free(tot);
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
    tcase_add_test(tc, test_shadows_cut_sun_hours);
    tcase_add_test(tc, test_per_cell_sites);
    tcase_add_test(tc, test_grid_north);
    tcase_add_test(tc, test_esra);
    tcase_add_test(tc, test_insolation_flat);
    tcase_add_test(tc, test_insolation_slopes);
    tcase_add_test(tc, test_insolation_lattice);
    tcase_add_test(tc, test_atlas_times);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return test_run_suite(suite());
}
