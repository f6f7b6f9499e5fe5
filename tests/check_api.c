/* Bad arguments: every function answers TS_ERR_ARG with a message, never
 * crashes, never writes outside its output. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

/* The error that EXPECT_ARG checks: the calls below pass it as err. */
static ts_error err_buf;
static ts_error *const err = &err_buf;

/* EXPECT_ARG's call with err = NULL: still the code, still no crash. */
#define EXPECT_ARG_NOERR(call)                                                    \
    do {                                                                          \
        ts_error *err = NULL;                                                     \
        ck_assert_msg((call) == TS_ERR_ARG, "%s with err NULL", #call);           \
    } while (0)

static ts_grid G; /* 20 x 10 fractal, made fresh for each test */
static float *out, *nx, *ny, *nz, *hor;
#define N ((size_t)20 * 10)

static void setup(void)
{
    tdem_create(&G, 20, 10, 10.0, 10.0);
    tdem_fractal(&G, 1, 50.0);
    out = tdem_floats(N), nx = tdem_floats(N), ny = tdem_floats(N), nz = tdem_floats(N);
    hor = tdem_floats(N * 16);
    ts_error e;
    ck_assert(ts_normals(&G, nx, ny, nz, &e) == TS_OK);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    ck_assert(ts_horizon_compute(&G, &o, hor, &e) == TS_OK);
}

static void teardown(void)
{
    free(out); free(nx); free(ny); free(nz); free(hor);
    ts_grid_free(&G);
}

static ts_horizon_opts dflt(void)
{
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    return o;
}

START_TEST(test_defaults_and_names)
{
    ts_horizon_opts o = dflt();
    ck_assert_int_eq(o.directions, 16);
    ck_assert(o.start_azimuth == 0 && o.max_distance == 0 && o.curvature == 1);
    ck_assert(o.refraction == TS_DEFAULT_REFRACTION);
    ts_error e;
    ck_assert(ts_horizon_opts_validate(&o, &e) == TS_OK);
    o.directions = 4;
    o.start_azimuth = 350;
    ck_assert(fabs(ts_horizon_azimuth(&o, 1) - 80.0) < 1e-9);
    ts_status codes[] = {TS_OK,           TS_ERR_ARG,       TS_ERR_NOMEM, TS_ERR_THREAD,
                         TS_ERR_INTERNAL, TS_ERR_CANCELLED, (ts_status)99};
    for (int i = 0; i < 7; i++)
        ck_assert(ts_status_name(codes[i]) != NULL && ts_status_name(codes[i])[0]);
    ck_assert(ts_cpu_count() >= 1);
}
END_TEST

START_TEST(test_grid_args)
{
    ts_grid g;
    EXPECT_ARG(ts_grid_create(NULL, 10, 10, 1, 1, err), err);
    EXPECT_ARG(ts_grid_create(&g, 0, 10, 1, 1, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, -3, 1, 1, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, 10, NAN, 1, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, 10, 1, INFINITY, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, 10, 0, 1, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, 10, 1, -1, err), err);
    /* beyond what the sweeps hold: 1e-320 m cells read NaN everywhere (session 57) */
    EXPECT_ARG(ts_grid_create(&g, 10, 10, 1e-320, 1e-320, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, 10, 1, TS_CELL_MIN_M / 2, err), err);
    EXPECT_ARG(ts_grid_create(&g, 10, 10, TS_CELL_MAX_M * 2, 1, err), err);
    ts_grid edge;
    if (ts_grid_create(&edge, 3, 3, TS_CELL_MIN_M, TS_CELL_MAX_M, err) != TS_OK)
        ck_abort_msg("cells at the bounds refused: %s", err->message);
    ts_grid_free(&edge);
    EXPECT_ARG_NOERR(ts_grid_create(&g, 0, 0, 1, 1, err));
    double rows[10] = {1, 1, 1, 1, NAN, 1, 1, 1, 1, 1};
    EXPECT_ARG(ts_grid_set_row_spacing(&G, NULL, err), err);
    ts_grid copy = G;
    copy.owns_memory = 0;
    EXPECT_ARG(ts_grid_set_row_spacing(&copy, (double[10]){1, 1, 1, 1, 1, 1, 1, 1, 1, 1}, err),
               err);
    EXPECT_ARG(ts_grid_set_row_spacing(&G, rows, err), err);
    rows[4] = -2;
    EXPECT_ARG(ts_grid_set_row_spacing(&G, rows, err), err);
    rows[4] = 1e-40;
    EXPECT_ARG(ts_grid_set_row_spacing(&G, rows, err), err);
    rows[4] = 1.7e-12; /* a geographic row centred on a pole: taken */
    if (ts_grid_set_row_spacing(&G, rows, err) != TS_OK)
        ck_abort_msg("a pole row's cells refused: %s", err->message);
    free(G.cell_x_row); /* (the checks below take G without row spacing) */
    G.cell_x_row = NULL;
    EXPECT_ARG(ts_grid_validate(NULL, err), err);
    ts_grid bad = G;
    bad.z = NULL;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    bad = G, bad.stride = 19;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    bad = G, bad.width = 0;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    bad = G, bad.cell_x = NAN;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    bad = G, bad.cell_y = -INFINITY;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    bad = G, bad.cell_y = 1e-40;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    double nan_rows[10] = {1, 1, 1, 1, 1, 1, 1, 1, 1, NAN};
    bad = G, bad.cell_x_row = nan_rows;
    EXPECT_ARG(ts_grid_validate(&bad, err), err);
    /* a grid that does not validate is refused by every entry point */
    bad = G, bad.cell_x = INFINITY;
    ts_horizon_opts o = dflt();
    EXPECT_ARG(ts_horizon_sweep(&bad, 0, &o, out, err), err);
    EXPECT_ARG(ts_shm_compute(&bad, 0, 30, 0, 1, out, NULL, err), err);
    EXPECT_ARG(ts_normals(&bad, nx, ny, nz, err), err);
}
END_TEST

static void noop_visit(void *u, int n, const float *x, const float *y, const float *h,
                       const double *d, const float *s)
{
    (void)u, (void)n, (void)x, (void)y, (void)h, (void)d, (void)s;
}

START_TEST(test_horizon_args)
{
    ts_horizon_opts o = dflt();
    EXPECT_ARG(ts_horizon_sweep(NULL, 0, &o, out, err), err);
    EXPECT_ARG(ts_horizon_sweep(&G, 0, NULL, out, err), err);
    EXPECT_ARG(ts_horizon_sweep(&G, 0, &o, NULL, err), err);
    EXPECT_ARG(ts_horizon_sweep(&G, NAN, &o, out, err), err);
    EXPECT_ARG(ts_horizon_sweep(&G, INFINITY, &o, out, err), err);
    EXPECT_ARG_NOERR(ts_horizon_sweep(&G, NAN, &o, out, err));
    EXPECT_ARG(ts_horizon_compute(NULL, &o, hor, err), err);
    EXPECT_ARG(ts_horizon_compute(&G, NULL, hor, err), err);
    EXPECT_ARG(ts_horizon_compute(&G, &o, NULL, err), err);
    EXPECT_ARG(ts_horizon_sweep_lines(&G, 0, &o, NULL, NULL, err), err);
    EXPECT_ARG(ts_horizon_sweep_lines(&G, NAN, &o, noop_visit, NULL, err), err);
    EXPECT_ARG(ts_horizon_sweep_lines(NULL, 0, &o, noop_visit, NULL, err), err);

    const struct { const char *field; ts_horizon_opts o; } bad[] = {
        {"direction", {0, 0, 0, 1, 0.13, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"direction", {-5, 0, 0, 1, 0.13, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"refraction", {16, 0, 0, 1, -0.01, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"refraction", {16, 0, 0, 1, 1.01, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"refraction", {16, 0, 0, 1, NAN, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"azimuth", {16, NAN, 0, 1, 0.13, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"distance", {16, 0, -1, 1, 0.13, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
        {"distance", {16, 0, NAN, 1, 0.13, 0, NULL, NULL, TS_EDGE_OPEN, 0}},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const ts_horizon_opts *b = &bad[i].o;
        ts_error e;
        memset(&e, 0, sizeof e);
        ck_assert_msg(ts_horizon_opts_validate(b, &e) == TS_ERR_ARG && e.message[0],
                      "bad opts %zu (%s) accepted", i, bad[i].field);
        printf("opts %zu -> %s\n", i, e.message);
        ck_assert_msg(strstr(e.message, bad[i].field) != NULL,
                      "message \"%s\" does not name %s", e.message, bad[i].field);
        EXPECT_ARG(ts_horizon_compute(&G, b, hor, err), err);
        /* the sweep ignores directions and start_azimuth */
        if (strcmp(bad[i].field, "refraction") == 0 || strcmp(bad[i].field, "distance") == 0)
            EXPECT_ARG(ts_horizon_sweep(&G, 0, b, out, err), err);
    }
}
END_TEST

START_TEST(test_shm_args)
{
    EXPECT_ARG(ts_shm_compute(NULL, 0, 30, 0, 1, out, NULL, err), err);
    EXPECT_ARG(ts_shm_compute(&G, 0, 90.5, 0, 1, out, NULL, err), err);
    EXPECT_ARG(ts_shm_compute(&G, 0, -90.5, 0, 1, out, NULL, err), err);
    EXPECT_ARG(ts_shm_compute(&G, 0, NAN, 0, 1, out, NULL, err), err);
    EXPECT_ARG(ts_shm_compute(&G, NAN, 30, 0, 1, out, NULL, err), err);
    EXPECT_ARG(ts_shm_compute(&G, 0, 30, -1, 1, out, NULL, err), err);
    EXPECT_ARG(ts_shm_compute(&G, 0, 30, NAN, 1, out, NULL, err), err);
    EXPECT_ARG_NOERR(ts_shm_compute(&G, 0, 95, 0, 1, out, NULL, err));
}
END_TEST

START_TEST(test_shading_args)
{
    ts_horizon_opts o = dflt();
    EXPECT_ARG(ts_normals(NULL, nx, ny, nz, err), err);
    EXPECT_ARG(ts_normals(&G, NULL, ny, nz, err), err);
    EXPECT_ARG(ts_normals(&G, nx, ny, NULL, err), err);
    const ts_direct_request d0 = {&G, nx, ny, nz, hor, &o, 0, 30, out, TS_SUN_RADIUS_DEG};
    ts_direct_request d;
    ck_assert(ts_shade_direct(&d0, err) == TS_OK);
    EXPECT_ARG(ts_shade_direct(NULL, err), err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, grid, NULL, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, horizons, NULL, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, nx, NULL, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, opts, NULL, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, out, NULL, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, sun_azimuth, NAN, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, sun_elevation, 95, err);
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, sun_elevation, NAN, err);
    ts_horizon_opts o0 = o;
    o0.directions = 0;
    EXPECT_ARG_FIELD(ts_shade_direct, d, d0, opts, &o0, err);
    const ts_sky_request s0 = {&G, nx, ny, nz, hor, &o, TS_SVF_RADIATIVE, out, NULL, NULL};
    ts_sky_request s;
    ck_assert(ts_sky_terms(&s0, err) == TS_OK);
    EXPECT_ARG(ts_sky_terms(NULL, err), err);
    EXPECT_ARG_FIELD(ts_sky_terms, s, s0, grid, NULL, err);
    EXPECT_ARG_FIELD(ts_sky_terms, s, s0, horizons, NULL, err);
    EXPECT_ARG_FIELD(ts_sky_terms, s, s0, nx, NULL, err);
    EXPECT_ARG_FIELD(ts_sky_terms, s, s0, opts, NULL, err);
    EXPECT_ARG_FIELD(ts_sky_terms, s, s0, opts, &o0, err);
    EXPECT_ARG_FIELD(ts_sky_terms, s, s0, svf_model, (ts_svf_model)2, err);
    EXPECT_ARG(ts_sky_accumulate(&G, nx, ny, nz, hor, 0, 0, out, NULL, NULL, err), err);
    EXPECT_ARG(ts_sky_accumulate(&G, nx, ny, nz, hor, NAN, 16, out, NULL, NULL, err), err);
    EXPECT_ARG(ts_sky_accumulate(&G, nx, ny, nz, NULL, 0, 16, out, NULL, NULL, err), err);
    EXPECT_ARG(ts_sky_finish(&G, 0, out, NULL, NULL, err), err);
    EXPECT_ARG(ts_sky_finish(NULL, 16, out, NULL, NULL, err), err);
    EXPECT_ARG(ts_shade_combine(&G, NULL, out, 0.5, out, err), err);
    EXPECT_ARG(ts_shade_combine(&G, out, NULL, 0.5, out, err), err);
    EXPECT_ARG(ts_shade_combine(&G, out, out, 0.5, NULL, err), err);
    EXPECT_ARG(ts_shade_combine(&G, out, out, NAN, out, err), err);
    EXPECT_ARG(ts_shade_combine(NULL, out, out, 0.5, out, err), err);
}
END_TEST

/* Outputs with a sentinel border: nothing may be written outside them. */
#define GUARD 64
static float *guarded(size_t n)
{
    float *p = tdem_floats(n + 2 * GUARD);
    for (size_t i = 0; i < n + 2 * GUARD; i++)
        p[i] = -12345.0f;
    return p + GUARD;
}

static void check_guard(float *p, size_t n, const char *what)
{
    for (size_t i = 0; i < GUARD; i++)
        ck_assert_msg(p[-1 - (ptrdiff_t)i] == -12345.0f && p[n + i] == -12345.0f,
                      "%s wrote outside its output", what);
    free(p - GUARD);
}

START_TEST(test_no_writes_outside)
{
    /* a grid with stride > width, whose padding must stay untouched too */
    ts_grid g = G;
    float *z = tdem_floats(10 * 27);
    for (int i = 0; i < 10 * 27; i++)
        z[i] = -777.0f;
    for (int y = 0; y < 10; y++)
        memcpy(z + y * 27, G.z + y * 20, 20 * sizeof *z);
    g.z = z, g.stride = 27, g.owns_memory = 0;
    ts_horizon_opts o = dflt();
    o.directions = 5;
    ts_error e;
    float *h = guarded(N * 5), *v = guarded(N), *s = guarded(N);
    float *a = guarded(N), *b = guarded(N), *c = guarded(N), *d = guarded(N);
    ck_assert(ts_horizon_compute(&g, &o, h, &e) == TS_OK);
    ck_assert(ts_shm_compute(&g, 33, 20, 2, 2, v, s, &e) == TS_OK);
    ck_assert(ts_normals(&g, a, b, c, &e) == TS_OK);
    const ts_direct_request dq = {&g, a, b, c, h, &o, 100, 30, d, TS_SUN_RADIUS_DEG};
    ck_assert(ts_shade_direct(&dq, &e) == TS_OK);
    const ts_sky_request sq = {&g, a, b, c, h, &o, TS_SVF_RADIATIVE, v, s, d};
    ck_assert(ts_sky_terms(&sq, &e) == TS_OK);
    for (int y = 0; y < 10; y++)
        for (int x = 20; x < 27; x++)
            ck_assert_msg(z[y * 27 + x] == -777.0f, "grid padding was written");
    check_guard(h, N * 5, "ts_horizon_compute");
    check_guard(v, N, "ts_shm_compute/ts_sky_terms");
    check_guard(s, N, "ts_shm_compute/ts_sky_terms");
    check_guard(a, N, "ts_normals");
    check_guard(b, N, "ts_normals");
    check_guard(c, N, "ts_normals");
    check_guard(d, N, "ts_shade_direct/ts_sky_terms");
    free(z);
}
END_TEST

/* Progress: reported from 0 to 1, never backwards, once per azimuth and
 * at the end; a non-zero answer stops the computation (tprog_log). */

START_TEST(test_progress_and_cancel)
{
    ts_horizon_opts o = dflt();
    o.directions = 8;
    tprog l = {0, -1, 0, -1};
    o.progress = tprog_log;
    o.progress_user = &l;
    ts_error e;
    ck_assert(ts_horizon_compute(&G, &o, hor, &e) == TS_OK);
    ck_assert_int_eq(l.calls, 9);
    ck_assert(l.first == 0.0 && l.last == 1.0);
    /* stop at the third report: cancelled, with a message */
    l = (tprog){0, 3, 0, -1};
    ck_assert(ts_horizon_compute(&G, &o, hor, &e) == TS_ERR_CANCELLED);
    ck_assert_int_eq(l.calls, 3);
    ck_assert(e.code == TS_ERR_CANCELLED && strstr(e.message, "cancelled"));
    printf("cancelled after 3 reports: %s (%s)\n", e.message, ts_status_name(e.code));
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* lines reach the log before a failure exits */
    Suite *s = suite_create("api");
    TCase *tc = tcase_create("errors");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_defaults_and_names);
    tcase_add_test(tc, test_grid_args);
    tcase_add_test(tc, test_horizon_args);
    tcase_add_test(tc, test_shm_args);
    tcase_add_test(tc, test_shading_args);
    tcase_add_test(tc, test_no_writes_outside);
    tcase_add_test(tc, test_progress_and_cancel);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
