/* A day with the sun on a lattice of sites spread over many degrees of
 * longitude (SUN_POSITION=per_cell on a continent or the globe): the
 * horizon planes kept from one step to the next (ts_day_opts.
 * plane_cache_bytes) change no value and sweep each azimuth once, and the
 * SPA's part that depends on the instant alone, computed once for every
 * site (ts_sun_position_from), changes no bit; the planes a day sweeps are
 * counted as it sweeps them (ts_sun_visibility_planes). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "terrashade_sun.h"
#include "test_dem.h"
#include "test_grid.h"
#include "test_run.h"

enum { W = 48, H = 24, NX = 9, NY = 5 };

/* Sweeps seen by the plane hook. */
static ts_status count_sweeps(void *user, const ts_grid *g, double azimuth,
                              double sun_elevation, float *plane, ts_error *err)
{
    (void)g;
    (void)azimuth;
    (void)sun_elevation;
    (void)plane;
    (void)err;
    ++*(int *)user;
    return TS_OK;
}

/* A rough DEM whose sun sites span 320 degrees of longitude and 60 S to
 * 60 N: at every instant its suns' azimuths span most of the circle. */
typedef struct {
    ts_grid g;
    double lon[NX * NY], lat[NX * NY], north[NX * NY];
    ts_sun_sites s;
    ts_day_opts o;
    int sweeps;
} world;

static void world_init(world *w)
{
    memset(w, 0, sizeof *w);
    tdem_create(&w->g, W, H, 100.0, 100.0);
    tdem_fractal(&w->g, 11, 3000.0);
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++) {
            w->lon[j * NX + i] = -160.0 + 40.0 * i;
            w->lat[j * NX + i] = 60.0 - 30.0 * j;
        }
    w->s = (ts_sun_sites){NX, NY, 0.0, 0.0, (W - 1.0) / (NX - 1), (H - 1.0) / (NY - 1),
                          w->lon, w->lat, w->north};
    ts_day_opts_default(&w->o);
    w->o.plane_hook = count_sweeps;
    w->o.plane_hook_user = &w->sweeps;
}

enum { STEPS = 12 };

/* STEPS instants 2 hours apart over the day of `midnight`, at the steps'
 * middles. */
static void two_hourly(double midnight, double *t)
{
    for (int k = 0; k < STEPS; k++)
        t[k] = midnight + (k + 0.5) * 7200;
}

static int same_bits(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

START_TEST(test_sun_position_from)
{
    const double sites[][2] = {{0, 0}, {47.3, 8.5}, {-33.9, 151.2}, {78.2, 15.6},
                               {-77.8, 166.7}, {36.1, -115.2}};
    const double jds[] = {2451545.0, 2461213.25, 2461400.8};
    for (size_t t = 0; t < sizeof jds / sizeof *jds; t++) {
        ts_sun_input in;
        ts_sun_input_default(&in);
        in.jd = jds[t];
        ts_sun_output out, from;
        ts_sun_detail instant, d, df;
        ts_error err;
        ck_assert(ts_sun_position_detail(&in, &out, &instant, &err) == TS_OK);
        for (size_t k = 0; k < sizeof sites / sizeof *sites; k++) {
            in.latitude = sites[k][0];
            in.longitude = sites[k][1];
            ck_assert(ts_sun_position_detail(&in, &out, &d, &err) == TS_OK);
            ck_assert(ts_sun_position_from(&in, &instant, &from, &df, &err) == TS_OK);
            ck_assert_msg(memcmp(&out, &from, sizeof out) == 0 &&
                              memcmp(&d, &df, sizeof d) == 0,
                          "site %zu, jd %.2f: not the same bits", k, jds[t]);
        }
        /* another instant's detail is refused, with a sentence */
        in.jd += 1.0 / 1440;
        ck_assert(ts_sun_position_from(&in, &instant, &from, NULL, &err) == TS_ERR_ARG);
        ck_assert(strstr(err.message, "another instant") != NULL);
        in.jd -= 1.0 / 1440;
        in.delta_t += 1;
        ck_assert(ts_sun_position_from(&in, &instant, &from, NULL, &err) == TS_ERR_ARG);
        ck_assert(ts_sun_position_from(&in, NULL, &from, NULL, &err) == TS_ERR_ARG);
    }
}
END_TEST

/* Hours of sun and insolation: the same bits with every plane kept, with
 * room for a few, and with none; each azimuth swept once a day when the
 * planes fit, where without them every step sweeps the lattice's span. */
START_TEST(test_planes_kept_over_a_day)
{
    world w;
    world_init(&w);
    const size_t n = (size_t)W * H;
    const double start = ts_local_midnight(2026, 3, 20, 0), step = 3600;
    float *kept = malloc(n * sizeof *kept), *some = malloc(n * sizeof *some),
          *none = malloc(n * sizeof *none);
    ts_error err;
    w.sweeps = 0;
    ck_assert(ts_sun_hours(&w.g, &w.s, &w.o, start, 86400, step, kept, &err) == TS_OK);
    const int sweeps_kept = w.sweeps;
    w.o.plane_cache_bytes = 12 * n * sizeof(float);
    w.sweeps = 0;
    ck_assert(ts_sun_hours(&w.g, &w.s, &w.o, start, 86400, step, some, &err) == TS_OK);
    const int sweeps_some = w.sweeps;
    w.o.plane_cache_bytes = 0;
    w.sweeps = 0;
    ck_assert(ts_sun_hours(&w.g, &w.s, &w.o, start, 86400, step, none, &err) == TS_OK);
    const int sweeps_none = w.sweeps;
    printf("day lattice: %d sweeps with the planes kept, %d with room for 12, %d with "
           "none\n", sweeps_kept, sweeps_some, sweeps_none);
    ck_assert(same_bits(kept, none, n) && same_bits(some, none, n));
    ck_assert_int_le(sweeps_kept, 360);
    ck_assert_int_gt(sweeps_none, 10 * sweeps_kept);
    ck_assert_int_lt(sweeps_some, sweeps_none);
    /* physically possible: 0..24 hours, and some of each */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        lo = fmin(lo, kept[i]);
        hi = fmax(hi, kept[i]);
    }
    ck_assert(lo >= 0 && hi <= 24 && hi > lo);

    float *ik = malloc(3 * n * sizeof *ik), *in = malloc(3 * n * sizeof *in);
    w.o.horizon.directions = 8;
    w.o.plane_cache_bytes = TS_DAY_PLANE_CACHE_DEFAULT;
    ck_assert(ts_insolation(&w.g, &w.s, &w.o, start, 86400, step, ik, ik + n, ik + 2 * n,
                            &err) == TS_OK);
    w.o.plane_cache_bytes = 0;
    ck_assert(ts_insolation(&w.g, &w.s, &w.o, start, 86400, step, in, in + n, in + 2 * n,
                            &err) == TS_OK);
    ck_assert(same_bits(ik, in, 3 * n));
    free(ik);
    free(in);
    free(kept);
    free(some);
    free(none);
    ts_grid_free(&w.g);
}
END_TEST

/* The visibility at many instants at once (the daycycle product) equals
 * ts_sun_visibility at each, and sweeps far less. */
START_TEST(test_visibility_steps)
{
    world w;
    world_init(&w);
    const size_t n = (size_t)W * H;
    double t[STEPS];
    two_hourly(ts_local_midnight(2026, 12, 21, 0), t);
    float *all = malloc(STEPS * n * sizeof *all), *one = malloc(n * sizeof *one);
    ts_error err;
    w.sweeps = 0;
    ck_assert(ts_sun_visibility_steps(&w.g, &w.s, &w.o, t, STEPS, all, &err) == TS_OK);
    const int sweeps_steps = w.sweeps;
    w.sweeps = 0;
    for (int k = 0; k < STEPS; k++) {
        ck_assert(ts_sun_visibility(&w.g, &w.s, &w.o, t[k], one, NULL, NULL, NULL, &err) ==
                  TS_OK);
        ck_assert_msg(same_bits(all + k * n, one, n), "step %d differs", k);
    }
    printf("day lattice: %d sweeps for %d instants at once, %d one by one\n", sweeps_steps,
           STEPS, w.sweeps);
    ck_assert_int_le(sweeps_steps, 360);
    ck_assert_int_gt(w.sweeps, 2 * sweeps_steps);
    /* bad input: a clear error */
    t[3] = NAN;
    ck_assert(ts_sun_visibility_steps(&w.g, &w.s, &w.o, t, STEPS, all, &err) == TS_ERR_ARG);
    ck_assert(ts_sun_visibility_steps(&w.g, &w.s, &w.o, t, 0, all, &err) == TS_ERR_ARG);
    free(all);
    free(one);
    ts_grid_free(&w.g);
}
END_TEST

/* ts_sun_visibility_planes (the windows' memory estimate): a wide
 * lattice's whole degrees counted once over the day, at most 360 and at
 * least the sweeps the day runs; a narrow one's own sweeps summed over the
 * steps (each step's ts_sun_visibility_sweeps); one site, one a step. */
START_TEST(test_planes_counted)
{
    world w;
    world_init(&w);
    const size_t n = (size_t)W * H;
    double t[STEPS];
    two_hourly(ts_local_midnight(2026, 6, 21, 0), t);
    float *all = malloc(STEPS * n * sizeof *all);
    ts_error err;
    int summed = 0;
    for (int k = 0; k < STEPS; k++)
        summed += ts_sun_visibility_sweeps(&w.s, &w.o, t[k]);
    w.sweeps = 0;
    ck_assert(ts_sun_visibility_steps(&w.g, &w.s, &w.o, t, STEPS, all, &err) == TS_OK);
    const int wide = ts_sun_visibility_planes(&w.s, &w.o, t, STEPS);
    printf("day lattice, wide: %d planes counted, %d swept, %d summed step by step\n", wide,
           w.sweeps, summed);
    ck_assert_int_ge(wide, w.sweeps);
    ck_assert_int_le(wide, 360);
    ck_assert_int_gt(summed, 5 * wide);

    /* a lattice 0.4 degrees wide: its sweeps at its own azimuths */
    for (int i = 0; i < NX * NY; i++) {
        w.lon[i] = -100.2 + 0.4 * (i % NX) / (NX - 1);
        w.lat[i] = 40.0 + 0.4 * (i / NX) / (NY - 1);
    }
    summed = 0;
    for (int k = 0; k < STEPS; k++)
        summed += ts_sun_visibility_sweeps(&w.s, &w.o, t[k]);
    w.sweeps = 0;
    ck_assert(ts_sun_visibility_steps(&w.g, &w.s, &w.o, t, STEPS, all, &err) == TS_OK);
    const int narrow = ts_sun_visibility_planes(&w.s, &w.o, t, STEPS);
    printf("day lattice, narrow: %d planes counted, %d swept\n", narrow, w.sweeps);
    ck_assert_int_eq(narrow, summed);
    ck_assert_int_ge(narrow, w.sweeps);

    ts_sun_sites one = {1, 1, 0.0, 0.0, 1.0, 1.0, w.lon, w.lat, w.north};
    ck_assert_int_eq(ts_sun_visibility_planes(&one, &w.o, t, STEPS), STEPS);
    t[3] = NAN; /* the sun cannot be computed */
    ck_assert_int_eq(ts_sun_visibility_planes(&w.s, &w.o, t, STEPS), -1);
    free(all);
    ts_grid_free(&w.g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("day_lattice");
    TCase *tc = tcase_create("day_lattice");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_sun_position_from);
    tcase_add_test(tc, test_planes_kept_over_a_day);
    tcase_add_test(tc, test_visibility_steps);
    tcase_add_test(tc, test_planes_counted);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
