/* What the day products let a caller change (core/day_cycle.h): the plane
 * hook after each horizon sweep (the driver's windows raise the planes to
 * their far field there) and the heights a date range's transmittance
 * tables span. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "test_dem.h"
#include "test_grid.h"
#include "test_run.h"
#include "test_site.h"

/* What the hook saw, and what it does to the planes. */
typedef struct {
    int sun_calls, other_calls;
    double last_elevation;
    float raise_to; /* every cell raised to at least this; -INFINITY: none */
    int fail;       /* 1: fail at the first call */
} hook_log;

static ts_status hook(void *user, const ts_grid *g, double azimuth, double sun_elevation,
                      float *plane, ts_error *err)
{
    hook_log *h = user;
    ck_assert(azimuth >= 0.0 && azimuth < 360.0);
    if (h->fail) {
        err->code = TS_ERR_ARG;
        snprintf(err->message, sizeof err->message, "the hook says no");
        return TS_ERR_ARG;
    }
    if (isnan(sun_elevation)) {
        h->other_calls++;
    } else {
        h->sun_calls++;
        h->last_elevation = sun_elevation;
    }
    for (size_t i = 0; i < (size_t)g->width * g->height; i++)
        plane[i] = plane[i] > h->raise_to ? plane[i] : h->raise_to;
    return TS_OK;
}

/* Steps of `step_s` over the local day from `start` whose sun's upper limb
 * is above the flat horizon of a plane at sea level. */
static int steps_with_sun(const test_site *p, const ts_day_opts *o, double start, double step_s)
{
    int n = 0;
    for (double t = start + step_s / 2; t < start + 86400; t += step_s) {
        ts_sun_sample s;
        ts_error err;
        ck_assert(ts_sun_at_site(&p->s, o, t, &s, &err) == TS_OK);
        n += s.elevation + TS_SUN_RADIUS_DEG > 0.0;
    }
    return n;
}

/* One call per sweep: the sun's, with its elevation, once per step with the
 * sun up; the sky term's without one. Raising every plane to 90 degrees
 * takes every hour of sun and every watt away. */
START_TEST(test_plane_hook_day)
{
    ts_error err;
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 4;
    ts_grid g;
    tdem_create(&g, 12, 10, 30.0, 30.0);
    tdem_fill(&g, 0.0f);
    float hours[120], hooked[120], tot[120];
    const double start = ts_local_midnight(2026, 6, 21, 120), step = 1800;
    const int up = steps_with_sun(&p, &o, start, step);
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, step, hours, &err) == TS_OK);

    hook_log h = {0, 0, NAN, -INFINITY, 0};
    o.plane_hook = hook;
    o.plane_hook_user = &h;
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, step, hooked, &err) == TS_OK);
    printf("sun hours, June 21 at 46.5 N, 30-minute steps: %d steps with the sun up, "
           "%d sun sweeps hooked, %d others; %.2f h\n",
           up, h.sun_calls, h.other_calls, hooked[0]);
    ck_assert_int_eq(h.sun_calls, up);
    ck_assert_int_eq(h.other_calls, 0);
    ck_assert(h.last_elevation > -1.0 && h.last_elevation < 10.0); /* the evening's */
    ck_assert(memcmp(hours, hooked, sizeof hours) == 0); /* a hook that changes nothing */

    h = (hook_log){0, 0, NAN, -INFINITY, 0};
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, step, tot, NULL, NULL, &err) ==
              TS_OK);
    ck_assert_int_eq(h.sun_calls, up);
    ck_assert_int_eq(h.other_calls, 4);
    ck_assert(tot[0] > 5000.0f);

    h = (hook_log){0, 0, NAN, 90.0f, 0};
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, step, hooked, &err) == TS_OK);
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, step, tot, NULL, NULL, &err) ==
              TS_OK);
    for (int i = 0; i < 120; i++) {
        ck_assert(hooked[i] == 0.0f);
        ck_assert_msg(fabsf(tot[i]) < 1e-3f, "insolation under a wall: %g", tot[i]);
    }

    h = (hook_log){0, 0, NAN, -INFINITY, 1};
    ck_assert_int_eq(ts_sun_hours(&g, &p.s, &o, start, 86400, step, hooked, &err),
                     TS_ERR_ARG);
    ck_assert_str_eq(err.message, "the hook says no");
    float vis[120];
    ck_assert_int_eq(ts_sun_visibility(&g, &p.s, &o, start + 43200, vis, NULL, NULL, NULL,
                                       &err),
                     TS_ERR_ARG);
    ts_grid_free(&g);
}
END_TEST

static void range_set(ts_date_range *r)
{
    ts_date_range_default(r);
    r->first_year = r->last_year = 2026;
    r->first_month = 3;
    r->last_month = 5;
    r->first_day = r->last_day = 1;
    r->utc_offset_minutes = 60;
    r->day_interval = 30;
    r->horizon_directions = 16;
}

/* A date range's planes are hooked without a sun elevation (each serves
 * many sun positions); the tables over given heights move insolation by
 * interpolation error only, and bad heights are refused. */
START_TEST(test_range_hook_and_tables)
{
    ts_error err;
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 8;
    ts_grid g;
    tdem_create(&g, 24, 20, 30.0, 30.0);
    tdem_fractal(&g, 7, 300.0);
    ts_date_range r;
    range_set(&r);
    float own[480], given[480], hours[480];
    ck_assert(ts_insolation_range(&g, &p.s, &o, &r, own, NULL, NULL, &err) == TS_OK);

    hook_log h = {0, 0, NAN, -INFINITY, 0};
    o.plane_hook = hook;
    o.plane_hook_user = &h;
    ck_assert(ts_sun_hours_range(&g, &p.s, &o, &r, hours, &err) == TS_OK);
    ck_assert_int_eq(h.sun_calls, 0);
    ck_assert(h.other_calls >= 2 && h.other_calls <= 16);

    o.table_heights_given = 1;
    o.table_height_min = -500.0;
    o.table_height_max = 9000.0;
    ck_assert(ts_insolation_range(&g, &p.s, &o, &r, given, NULL, NULL, &err) == TS_OK);
    double worst = 0;
    for (int i = 0; i < 480; i++)
        worst = fmax(worst, fabs(given[i] - own[i]) / own[i]);
    printf("insolation over a range, tables over -500..9000 m against the grid's own "
           "heights: %.2e at most, relative\n", worst);
    ck_assert(worst > 0.0 && worst < 1e-4);

    o.table_height_min = 100.0;
    o.table_height_max = 50.0;
    ck_assert_int_eq(ts_insolation_range(&g, &p.s, &o, &r, given, NULL, NULL, &err),
                     TS_ERR_ARG);
    ck_assert_msg(strstr(err.message, "heights") != NULL, "%s", err.message);
    o.table_height_min = NAN;
    ck_assert_int_eq(ts_sun_hours_range(&g, &p.s, &o, &r, hours, &err), TS_ERR_ARG);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IONBF, 0); /* the figures survive a failed test */
    Suite *s = suite_create("day_hooks");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_plane_hook_day);
    tcase_add_test(tc, test_range_hook_and_tables);
    suite_add_tcase(s, tc);
    return test_run_suite_mode(s, CK_VERBOSE);
}
