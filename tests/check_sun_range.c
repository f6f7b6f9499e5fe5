/* Hours of sun and insolation over date ranges (ts_sun_hours_range,
 * ts_insolation_range in core/day_cycle.h): against the per-step exact day
 * products summed over the days, against the astronomical day lengths of
 * a year on a flat plane, the weighting of sampled days, progress and
 * cancel, and bad arguments. The errors printed per HORIZON_DIRECTIONS are
 * the figures of docs/day-cycle.md. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "test_grid.h"
#include "test_run.h"
#include "test_site.h"

/* A fractal DEM of w x h 30 m cells at 46.5 N 7.4 E, default day options. */
static void fixture(ts_grid *g, int w, int h, uint64_t seed, double relief, test_site *p,
                    ts_day_opts *o)
{
    tdem_create(g, w, h, 30.0, 30.0);
    tdem_fractal(g, seed, relief);
    test_site_init(p, 46.5, 7.4);
    ts_day_opts_default(o);
}

static void range_set(ts_date_range *r, int y0, int m0, int d0, int y1, int m1, int d1,
                      int offset, int interval)
{
    ts_date_range_default(r);
    r->first_year = y0;
    r->first_month = m0;
    r->first_day = d0;
    r->last_year = y1;
    r->last_month = m1;
    r->last_day = d1;
    r->utc_offset_minutes = offset;
    r->day_interval = interval;
}

/* Per-step exact day products summed over the range's days (interval 1). */
static void exact_sum(const ts_grid *g, const test_site *p, const ts_day_opts *o,
                      const ts_date_range *r, int insolation, double *sum)
{
    size_t n = (size_t)g->width * g->height;
    float *day = tdem_floats(n);
    ts_error err;
    long long d0 = ts_days_from_civil(r->first_year, r->first_month, r->first_day);
    long long d1 = ts_days_from_civil(r->last_year, r->last_month, r->last_day);
    memset(sum, 0, n * sizeof *sum);
    for (long long d = d0; d <= d1; d++) {
        double start = (double)d * 86400.0 - r->utc_offset_minutes * 60.0;
        double step = r->step_minutes * 60.0;
        ts_status st = insolation
                           ? ts_insolation(g, &p->s, o, start, 86400, step, day, NULL, NULL, &err)
                           : ts_sun_hours(g, &p->s, o, start, 86400, step, day, &err);
        ck_assert_msg(st == TS_OK, "%s", err.message);
        for (size_t i = 0; i < n; i++)
            sum[i] += day[i];
    }
    free(day);
}

/* Mean and max |range - exact| over valid cells, and the exact mean. */
typedef struct {
    double mean_abs, max_abs, mean_ref;
} range_error;

static range_error compare(const ts_grid *g, const test_site *p, const ts_day_opts *o,
                           const ts_date_range *r, int insolation, const double *ref)
{
    size_t n = (size_t)g->width * g->height;
    float *got = tdem_floats(n);
    ts_error err;
    ts_status st = insolation ? ts_insolation_range(g, &p->s, o, r, got, NULL, NULL, &err)
                              : ts_sun_hours_range(g, &p->s, o, r, got, &err);
    ck_assert_msg(st == TS_OK, "%s", err.message);
    range_error e = {0, 0, 0};
    size_t valid = 0;
    for (size_t i = 0; i < n; i++) {
        if (isnan(ref[i])) {
            ck_assert_msg(isnan(got[i]), "nodata cell %zu got %g", i, got[i]);
            continue;
        }
        double d = fabs(got[i] - ref[i]);
        e.mean_abs += d;
        e.mean_ref += ref[i];
        e.max_abs = d > e.max_abs ? d : e.max_abs;
        valid++;
    }
    e.mean_abs /= valid;
    e.mean_ref /= valid;
    free(got);
    return e;
}

/* Range vs per-step sweeps for several HORIZON_DIRECTIONS; bounds at the
 * default: mean error under mean_tol (relative to the mean), max under
 * max_tol (relative to the mean). */
static void against_exact(const char *what, const ts_grid *g, const test_site *p, int insolation,
                          ts_sun_hours_rule rule, ts_date_range *r, double mean_tol,
                          double max_tol)
{
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.sun_hours_rule = rule;
    const char *label = insolation ? "insolation"
                        : rule == TS_SUN_HOURS_DISK_FRACTION ? "sun hours (fraction)"
                                                             : "sun hours";
    size_t n = (size_t)g->width * g->height;
    double *ref = malloc(n * sizeof *ref);
    ck_assert(ref);
    exact_sum(g, p, &o, r, insolation, ref);
    static const int dirs[] = {32, 64, 128, 360};
    range_error at_default = {-1, -1, -1};
    for (size_t k = 0; k < sizeof dirs / sizeof *dirs; k++) {
        r->horizon_directions = dirs[k];
        range_error e = compare(g, p, &o, r, insolation, ref);
        printf("%s %s, HORIZON_DIRECTIONS %3d: mean |error| %.4f (%.3f%% of the mean %.3f), "
               "max %.4f %s (%.2f%% of the mean)\n",
               what, label, dirs[k], e.mean_abs,
               100 * e.mean_abs / e.mean_ref, e.mean_ref, e.max_abs,
               insolation ? "Wh/m2" : "h", 100 * e.max_abs / e.mean_ref);
        if (dirs[k] == TS_RANGE_HORIZON_DIRECTIONS)
            at_default = e;
    }
    ck_assert_msg(at_default.mean_abs >= 0, "the default direction count was not measured");
    /* The default's horizon error is below the 30-minute step's own
     * sampling error (exact sweeps at 30 against 5 minutes). */
    ts_date_range fine = *r;
    fine.step_minutes = 5;
    double *ref5 = malloc(n * sizeof *ref5);
    ck_assert(ref5);
    exact_sum(g, p, &o, &fine, insolation, ref5);
    double step_err = 0, mean5 = 0;
    size_t valid = 0;
    for (size_t i = 0; i < n; i++)
        if (!isnan(ref5[i])) {
            step_err += fabs(ref[i] - ref5[i]);
            mean5 += ref5[i];
            valid++;
        }
    step_err /= valid;
    mean5 /= valid;
    printf("%s %s: exact sweeps at %g-min steps against 5-min steps: mean |difference| %.4f "
           "(%.3f%% of %.3f)\n", what, label, r->step_minutes, step_err, 100 * step_err / mean5,
           mean5);
    ck_assert_msg(at_default.mean_abs < step_err, "%s: horizon error %g >= step error %g",
                  what, at_default.mean_abs, step_err);
    free(ref5);
    ck_assert_msg(at_default.mean_abs <= mean_tol * at_default.mean_ref,
                  "%s: mean error %g > %g x %g", what, at_default.mean_abs, mean_tol,
                  at_default.mean_ref);
    ck_assert_msg(at_default.max_abs <= max_tol * at_default.mean_ref,
                  "%s: max error %g > %g x %g", what, at_default.max_abs, max_tol,
                  at_default.mean_ref);
    free(ref);
}

START_TEST(test_fractal_against_exact)
{
    ts_grid g;
    tdem_create(&g, 64, 64, 30.0, 30.0);
    tdem_fractal(&g, 7, 400.0);
    test_site p;
    test_site_init(&p, 46.5, 7.4);
    ts_date_range r;
    range_set(&r, 2026, 11, 20, 2026, 11, 22, 60, 1);
    against_exact("fractal 64x64", &g, &p, 0, TS_SUN_HOURS_VISIBLE, &r, 0.006, 0.13);
    against_exact("fractal 64x64", &g, &p, 1, TS_SUN_HOURS_VISIBLE, &r, 0.002, 0.07);
    against_exact("fractal 64x64", &g, &p, 0, TS_SUN_HOURS_DISK_FRACTION, &r, 0.006, 0.11);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_jacksboro_against_exact)
{
    ts_grid full;
    tdem_load(&full, "jacksboro");
    /* a 100 x 80 window of the middle, a view into the full grid */
    int x0 = 150, y0 = 130;
    ts_grid g = full;
    g.width = 100;
    g.height = 80;
    g.z = full.z + (ptrdiff_t)y0 * full.stride + x0;
    g.cell_x_row = full.cell_x_row ? full.cell_x_row + y0 : NULL;
    g.owns_memory = 0;
    test_site p;
    test_site_init(&p, 36.589, -84.245);
    ts_date_range r;
    range_set(&r, 2026, 3, 19, 2026, 3, 21, -300, 1);
    against_exact("jacksboro 100x80", &g, &p, 0, TS_SUN_HOURS_VISIBLE, &r, 0.002, 0.06);
    against_exact("jacksboro 100x80", &g, &p, 1, TS_SUN_HOURS_VISIBLE, &r, 0.0002, 0.02);
    ts_grid_free(&full);
}
END_TEST

/* Apparent elevation of the sun's centre at t. */
static double elev(const test_site *p, const ts_day_opts *o, double t)
{
    ts_sun_sample s;
    ts_error err;
    ck_assert_msg(ts_sun_at_site(&p->s, o, t, &s, &err) == TS_OK, "%s", err.message);
    return s.elevation;
}

/* Sunrise-to-sunset of the upper limb over one local day, seconds: scanned
 * every 20 minutes, each crossing refined by bisection. */
static double day_length(const test_site *p, const ts_day_opts *o, double start)
{
    const double target = -TS_SUN_RADIUS_DEG;
    double total = 0, since = NAN, prev = start;
    int up = elev(p, o, start) > target;
    if (up)
        since = start;
    for (int k = 1; k <= 72; k++) {
        double t = start + 1200.0 * k;
        int u = elev(p, o, t) > target;
        if (u != up) {
            double a = prev, b = t;
            for (int i = 0; i < 40; i++) {
                double m = 0.5 * (a + b);
                if ((elev(p, o, m) > target) == up)
                    a = m;
                else
                    b = m;
            }
            double x = 0.5 * (a + b);
            if (up)
                total += x - since;
            else
                since = x;
            up = u;
        }
        prev = t;
    }
    if (up)
        total += start + 86400.0 - since;
    return total;
}

/* A year on an open flat plane: the sun hours are the sum of the day lengths,
 * to within one step per day (half a step at each end); sampled every 14
 * days, the weighted sum of the sampled (middle) days' lengths. */
START_TEST(test_flat_year)
{
    ts_grid g;
    tdem_create(&g, 8, 8, 30.0, 30.0);
    tdem_fill(&g, 0.0f);
    test_site p;
    test_site_init(&p, 46.5, 7.4);
    ts_day_opts o;
    ts_day_opts_default(&o);
    float out[64];
    ts_error err;
    for (int interval = 1; interval <= 14; interval += 13) {
        ts_date_range r;
        range_set(&r, 2026, 1, 1, 2026, 12, 31, 60, interval);
        ck_assert_msg(ts_sun_hours_range(&g, &p.s, &o, &r, out, &err) == TS_OK, "%s",
                      err.message);
        double astro = 0;
        int days = 365;
        for (int b = 0; b < days; b += interval) {
            int w = days - b < interval ? days - b : interval, d = b + (w - 1) / 2;
            double start = (double)(ts_days_from_civil(2026, 1, 1) + d) * 86400.0 - 3600.0;
            astro += w * day_length(&p, &o, start) / 3600.0;
        }
        double got = out[4 * 8 + 4];
        printf("flat plane 46.5 N, 2026, interval %d, 30-min steps: %.3f h of sun, "
               "astronomical %.3f h, difference %+.3f h (%+.2f min a day)\n",
               interval, got, astro, got - astro, (got - astro) * 60.0 / days);
        ck_assert_msg(fabs(got - astro) <= days * 0.5, "year: %g h vs %g h", got, astro);
        /* the errors at dawn and dusk mostly cancel over a year */
        ck_assert_msg(fabs(got - astro) <= days * 0.1, "year: %g h vs %g h", got, astro);
    }
    ts_grid_free(&g);
}
END_TEST

/* 30 days at interval 14: blocks of 14, 14 and 2 days from day 0, 14 and
 * 28, sampled at their middle days 6, 20 and 28. */
START_TEST(test_interval_weights)
{
    ts_grid g;
    test_site p;
    ts_day_opts o;
    fixture(&g, 48, 40, 3, 300.0, &p, &o);
    size_t n = (size_t)g.width * g.height;
    float *got = tdem_floats(n), *day = tdem_floats(n), *got_i = tdem_floats(n);
    double *want = calloc(n, sizeof *want), *want_i = calloc(n, sizeof *want_i);
    ts_error err;
    ts_date_range r;
    range_set(&r, 2026, 4, 10, 2026, 5, 9, 120, 14);
    int days, sampled;
    ck_assert(ts_date_range_check(&r, &days, &sampled, &err) == TS_OK);
    ck_assert_int_eq(days, 30);
    ck_assert_int_eq(sampled, 3);
    ck_assert(ts_sun_hours_range(&g, &p.s, &o, &r, got, &err) == TS_OK);
    ck_assert(ts_insolation_range(&g, &p.s, &o, &r, got_i, NULL, NULL, &err) == TS_OK);
    /* 2026-04-10 + 6, 20, 28 days */
    static const int month[] = {4, 4, 5}, mday[] = {16, 30, 8}, weight[] = {14, 14, 2};
    for (int k = 0; k < 3; k++) {
        ts_date_range one;
        range_set(&one, 2026, month[k], mday[k], 2026, month[k], mday[k], 120, 1);
        ck_assert_msg(ts_sun_hours_range(&g, &p.s, &o, &one, day, &err) == TS_OK, "%s",
                      err.message);
        for (size_t i = 0; i < n; i++)
            want[i] += weight[k] * (double)day[i];
        ck_assert(ts_insolation_range(&g, &p.s, &o, &one, day, NULL, NULL, &err) == TS_OK);
        for (size_t i = 0; i < n; i++)
            want_i[i] += weight[k] * (double)day[i];
    }
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg(fabs(got[i] - want[i]) <= 1e-4 * want[i] + 1e-3,
                      "cell %zu: %g h vs weighted %g h", i, got[i], want[i]);
        ck_assert_msg(fabs(got_i[i] - want_i[i]) <= 1e-4 * want_i[i],
                      "cell %zu: %g Wh/m2 vs weighted %g", i, got_i[i], want_i[i]);
    }
    free(got);
    free(day);
    free(got_i);
    free(want);
    free(want_i);
    ts_grid_free(&g);
}
END_TEST

/* The sky term's start_azimuth turns its azimuths only: a start below 0
 * or at 360 names the azimuths of its turn into [0, 360) (the planes the
 * stream shares had a negative phase at -5.625 and the sky summed none:
 * diffuse 0, session 58's review), and a start a hair off a plane is
 * swept on its own (359.9999999999 was read from plane 0). */
START_TEST(test_sky_start_azimuth_turns)
{
    ts_grid g;
    test_site p;
    ts_day_opts o;
    fixture(&g, 48, 40, 3, 300.0, &p, &o);
    o.horizon.directions = 16;
    size_t n = (size_t)g.width * g.height;
    float *want = tdem_floats(n), *got = tdem_floats(n), *dummy = tdem_floats(n);
    ts_error err;
    ts_date_range r;
    range_set(&r, 2026, 6, 1, 2026, 6, 2, 60, 1);
    static const double pairs[][2] = {{354.375, -5.625}, {354.375, -365.625}, {0, 360},
                                      {11.25, 371.25}};
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) {
        o.horizon.start_azimuth = pairs[k][0];
        ck_assert(ts_insolation_range(&g, &p.s, &o, &r, dummy, NULL, want, &err) == TS_OK);
        o.horizon.start_azimuth = pairs[k][1];
        ck_assert(ts_insolation_range(&g, &p.s, &o, &r, dummy, NULL, got, &err) == TS_OK);
        double mean = 0;
        for (size_t i = 0; i < n; i++) {
            mean += want[i] / n;
            ck_assert_msg(fabs(got[i] - want[i]) <= 1e-4 * want[i], "start %g vs %g, cell %zu: "
                          "diffuse %g vs %g", pairs[k][1], pairs[k][0], i, got[i], want[i]);
        }
        ck_assert_msg(mean > 100, "diffuse %g Wh/m2", mean);
    }
    /* a hair off plane 0: the sweeps at 359.9999999999 + k * 22.5, as one
     * sky sweep per azimuth gives them (HORIZON_DIRECTIONS 60: none shared) */
    o.horizon.start_azimuth = 359.9999999999;
    ck_assert(ts_insolation_range(&g, &p.s, &o, &r, dummy, NULL, got, &err) == TS_OK);
    r.horizon_directions = 60;
    ck_assert(ts_insolation_range(&g, &p.s, &o, &r, dummy, NULL, want, &err) == TS_OK);
    for (size_t i = 0; i < n; i++)
        ck_assert_msg(fabs(got[i] - want[i]) <= 1e-5 * want[i], "cell %zu: diffuse %g vs %g", i,
                      got[i], want[i]);
    free(want);
    free(got);
    free(dummy);
    ts_grid_free(&g);
}
END_TEST

typedef struct {
    int calls, stop_at;
    double last;
    int monotone;
} progress_log;

static int on_progress(double done, void *user)
{
    progress_log *l = user;
    if (done < l->last)
        l->monotone = 0;
    l->last = done;
    return ++l->calls == l->stop_at;
}

START_TEST(test_progress_and_cancel)
{
    ts_grid g;
    test_site p;
    ts_day_opts o;
    fixture(&g, 32, 32, 5, 200.0, &p, &o);
    progress_log log = {0, -1, 0.0, 1};
    o.horizon.progress = on_progress;
    o.horizon.progress_user = &log;
    float out[32 * 32];
    ts_error err;
    ts_date_range r;
    range_set(&r, 2026, 6, 1, 2026, 6, 30, 0, 14);
    ck_assert(ts_insolation_range(&g, &p.s, &o, &r, out, NULL, NULL, &err) == TS_OK);
    ck_assert_msg(log.calls > 10 && log.monotone && log.last == 1.0,
                  "%d progress reports, last %g", log.calls, log.last);
    log = (progress_log){0, 5, 0.0, 1};
    ck_assert_int_eq(ts_sun_hours_range(&g, &p.s, &o, &r, out, &err), TS_ERR_CANCELLED);
    ck_assert_int_eq(log.calls, 5);
    ts_grid_free(&g);
}
END_TEST

static void expect_bad(const ts_grid *g, const ts_sun_sites *s, const ts_date_range *r,
                       const char *words)
{
    ts_day_opts o;
    ts_day_opts_default(&o);
    float out[16 * 16];
    ts_error err;
    memset(&err, 0, sizeof err);
    ck_assert_int_eq(ts_sun_hours_range(g, s, &o, r, out, &err), TS_ERR_ARG);
    ck_assert_msg(strstr(err.message, words), "message '%s' lacks '%s'", err.message, words);
    ck_assert_int_eq(ts_insolation_range(g, s, &o, r, out, NULL, NULL, &err), TS_ERR_ARG);
    ck_assert_msg(strstr(err.message, words), "message '%s' lacks '%s'", err.message, words);
}

START_TEST(test_bad_arguments)
{
    ts_grid g;
    tdem_create(&g, 16, 16, 30.0, 30.0);
    tdem_fill(&g, 100.0f);
    test_site p;
    test_site_init(&p, 46.5, 7.4);
    ts_date_range r;
    range_set(&r, 2026, 6, 10, 2026, 6, 9, 0, 1);
    expect_bad(&g, &p.s, &r, "is before its first");
    range_set(&r, 2026, 2, 29, 2026, 3, 9, 0, 1);
    expect_bad(&g, &p.s, &r, "is not a date");
    range_set(&r, 2026, 6, 1, 2026, 6, 9, 0, 0);
    expect_bad(&g, &p.s, &r, "DAY_INTERVAL must be between 1 and 366");
    range_set(&r, 2026, 6, 1, 2026, 6, 9, 0, 1);
    r.horizon_directions = 3;
    expect_bad(&g, &p.s, &r, "HORIZON_DIRECTIONS must be between 4 and 3600");
    r.horizon_directions = 100000;
    expect_bad(&g, &p.s, &r, "HORIZON_DIRECTIONS must be between 4 and 3600");
    r.horizon_directions = 64;
    r.step_minutes = 0.5;
    expect_bad(&g, &p.s, &r, "STEP_MINUTES must be between 1 and 1440");
    r.step_minutes = 2000;
    expect_bad(&g, &p.s, &r, "STEP_MINUTES must be between 1 and 1440");
    r.step_minutes = NAN;
    expect_bad(&g, &p.s, &r, "STEP_MINUTES must be between 1 and 1440");
    range_set(&r, 1900, 1, 1, 2026, 1, 1, 0, 1);
    expect_bad(&g, &p.s, &r, "at most 36600 days");
    /* per-cell sun is refused with a sentence */
    double lon[4] = {7, 7.1, 7, 7.1}, lat[4] = {46, 46, 46.1, 46.1};
    ts_sun_sites lattice = {2, 2, 0.5, 0.5, 15, 15, lon, lat, NULL};
    range_set(&r, 2026, 6, 1, 2026, 6, 9, 0, 1);
    expect_bad(&g, &lattice, &r, "not supported over a date range");
    ts_error err;
    ts_day_opts o;
    ts_day_opts_default(&o);
    ck_assert_int_eq(ts_sun_hours_range(&g, &p.s, &o, &r, NULL, &err), TS_ERR_ARG);
    ck_assert_int_eq(ts_sun_hours_range(&g, &p.s, &o, NULL, (float[256]){0}, &err),
                     TS_ERR_ARG);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IONBF, 0); /* the figures survive a failed test */
    Suite *s = suite_create("sun_range");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_fractal_against_exact);
    tcase_add_test(tc, test_jacksboro_against_exact);
    tcase_add_test(tc, test_flat_year);
    tcase_add_test(tc, test_interval_weights);
    tcase_add_test(tc, test_sky_start_azimuth_turns);
    tcase_add_test(tc, test_progress_and_cancel);
    tcase_add_test(tc, test_bad_arguments);
    suite_add_tcase(s, tc);
    return test_run_suite_mode(s, CK_VERBOSE);
}
