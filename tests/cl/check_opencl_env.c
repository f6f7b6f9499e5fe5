/*
 * check_opencl_env: the environment light (envlight) of the OpenCL backend
 * against the C backend, under a CIE sky and sunset.exr, exact and bilinear
 * tables, held to 1e-4 relative; and through the dispatcher.
 *
 * Never skips: without OpenCL support or an OpenCL device the tests fail and
 * say why. Measured maximum differences are printed to the log.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <check.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include "terrashade.h"
#include "terrashade_backend.h"
#include "terrashade_cl.h"
#include "terrashade_env.h"
#include "test_grid.h"
#include "test_run.h"
#include "cl_test_common.h"


/* The two environments of the envlight tests: a CIE sky and a real map. */
static void env_make(ts_env *env, int which)
{
    ts_error e;
    if (which == 0)
        REQUIRE(ts_env_sky(env, TS_SKY_CIE, 7, 120.0, 25.0, 0, 0, &e) == TS_OK);
    else
        REQUIRE(ts_env_load_exr_file(TS_TEST_DATA "/envmaps/sunset.exr", 30.0, 0, env, &e) ==
                TS_OK);
}

static void env_table(ts_env_table *t, const ts_env *env, const scene *sc, int normal_steps)
{
    ts_env_table_opts to;
    ts_error e;
    ts_env_table_opts_default(&to);
    to.directions = sc->o.directions;
    to.start_azimuth = sc->o.start_azimuth;
    to.normal_steps = normal_steps;
    REQUIRE(ts_env_table_build(env, &to, t, &e) == TS_OK);
}

/* Largest |C - OpenCL| relative to the C value, the C value floored at
 * 1e-3 of the image's largest (dark cells: a difference there is absolute
 * at that scale); NaN must match. */
static double env_rel_diff(const float *c, const float *l, size_t n, long *nan_mismatch)
{
    double peak = 0, worst = 0;
    for (size_t i = 0; i < n; i++)
        if (c[i] == c[i] && fabs(c[i]) > peak)
            peak = fabs(c[i]);
    for (size_t i = 0; i < n; i++) {
        if (isnan(c[i]) || isnan(l[i])) {
            *nan_mismatch += isnan(c[i]) != isnan(l[i]);
            continue;
        }
        double d = fabs((double)c[i] - l[i]) / fmax(fabs(c[i]), 1e-3 * peak + 1e-30);
        if (!(d <= worst))
            worst = d;
    }
    return worst;
}

/* Every plane of a scene through the C function and an OpenCL session,
 * then finished; the worst relative difference over the colours. */
static double env_compare(const scene *sc, const ts_env_table *t, float *c, float *l)
{
    ts_error e;
    const size_t n = sc->n;
    memset(c, 0, 3 * n * sizeof *c);
    memset(l, 0, 3 * n * sizeof *l);
    ts_cl_env_light *s;
    const ts_env_light_request first = scene_env(sc, t, 0, l);
    ck_assert_msg(ts_cl_env_light_open(&first, &s, &e) == TS_OK, "%s", e.message);
    for (int k = 0; k < t->directions; k++) {
        const ts_env_light_request qc = scene_env(sc, t, k, c), ql = scene_env(sc, t, k, l);
        ck_assert_int_eq(ts_env_light_accumulate(&qc, &e), TS_OK);
        ck_assert_msg(ts_cl_env_light_add(s, &ql, &e) == TS_OK, "%s", e.message);
    }
    ts_cl_env_light_close(s);
    ck_assert_int_eq(ts_env_light_finish(&sc->g, c, c + n, c + 2 * n, &e), TS_OK);
    ck_assert_int_eq(ts_env_light_finish(&sc->g, l, l + n, l + 2 * n, &e), TS_OK);
    long nan_mismatch = 0;
    double worst = env_rel_diff(c, l, 3 * n, &nan_mismatch);
    ck_assert_int_eq(nan_mismatch, 0);
    return worst;
}

START_TEST(test_env_light)
{
    require_opencl();
    static const char *env_name[2] = {"CIE sky 7", "sunset.exr"};
    double worst_all = 0;
    for (int which = 0; which < 2; which++) {
        ts_env env;
        env_make(&env, which);
        for (int i = 0; i < NSHAPES; i++) {
            const dem_spec *s = &SHAPES[i];
            scene sc;
            scene_make(&sc, s, 8, 10.0);
            float *c = tdem_floats(3 * sc.n), *l = tdem_floats(3 * sc.n);
            static const int steps[2] = {0, 33}; /* exact, bilinear */
            for (int m = 0; m < 2; m++) {
                ts_env_table t;
                env_table(&t, &env, &sc, steps[m]);
                double worst = env_compare(&sc, &t, c, l);
                char sh[64];
                printf("  envlight %-10s %-6s %-30s max |C - OpenCL| / C = %.3g\n",
                       env_name[which], steps[m] ? "bilin" : "exact",
                       shape_name(s, sh, sizeof sh), worst);
                ck_assert_msg(worst <= TOL_ENV_REL, "envlight %s: %g", sh, worst);
                worst_all = fmax(worst_all, worst);
                ts_env_table_free(&t);
            }
            free(c), free(l);
            scene_free(&sc, s);
        }
        ts_env_free(&env);
    }
    printf("  envlight: largest relative difference %.3g\n", worst_all);
}
END_TEST

/* The dispatcher's envlight: OpenCL with a state, one-shot, argument
 * errors as C's, and a forced fallback (TERRASHADE_OPENCL_MAX_ALLOC) that
 * gives C's sums exactly. */
START_TEST(test_env_light_dispatch)
{
    require_opencl();
    clear_env();
    const dem_spec *s = &SHAPES[4];
    scene sc;
    scene_make(&sc, s, 8, 0.0);
    ts_env env;
    env_make(&env, 1);
    ts_env_table t;
    env_table(&t, &env, &sc, 0);
    const size_t n = sc.n;
    float *c = tdem_floats(3 * n), *l = tdem_floats(3 * n);
    ts_error e;
    ts_backend_report r;
    memset(c, 0, 3 * n * sizeof *c);
    for (int k = 0; k < 8; k++) {
        const ts_env_light_request qc = scene_env(&sc, &t, k, c);
        ck_assert_int_eq(ts_env_light_accumulate(&qc, &e), TS_OK);
    }
    for (int pass = 0; pass < 3; pass++) {
        /* 0: a state, 1: no state, 2: a state with the allocations capped */
        if (pass == 2)
            setenv("TERRASHADE_OPENCL_MAX_ALLOC", "4k", 1); /* table 46 kB, normals 7.8 kB */
        ts_backend_env_light st = {0};
        memset(l, 0, 3 * n * sizeof *l);
        for (int k = 0; k < 8; k++) {
            const ts_env_light_request ql = scene_env(&sc, &t, k, l);
            ck_assert_msg(ts_backend_env_light_accumulate(TS_BACKEND_OPENCL, pass == 1 ? NULL : &st,
                                                          &ql, &r, &e) == TS_OK,
                          "%s", e.message);
            ck_assert_int_eq(r.used, pass == 2 ? TS_BACKEND_C : TS_BACKEND_OPENCL);
            ck_assert_int_eq(r.fell_back, pass == 2);
        }
        if (pass == 2) {
            ck_assert_int_eq(st.failed, 1);
            ck_assert_ptr_nonnull(strstr(r.reason, "TERRASHADE_OPENCL_MAX_ALLOC"));
            ck_assert(memcmp(c, l, 3 * n * sizeof *c) == 0);
            printf("  envlight fallback: %s\n", r.reason);
        } else {
            long nan_mismatch = 0;
            double d = env_rel_diff(c, l, 3 * n, &nan_mismatch);
            printf("  envlight dispatch %s: max |C - OpenCL| / C = %.3g\n",
                   pass ? "one-shot" : "session", d);
            ck_assert(d <= TOL_ENV_REL && nan_mismatch == 0);
        }
        ts_backend_env_light_release(&st);
        ck_assert_ptr_null(st.cl);
    }
    clear_env();
    /* A fallback in the middle: planes 0..3 on OpenCL; then copies of the
     * normals make the dispatcher reopen its session, which the cap refuses,
     * so planes 4..7 run C from the sums so far (and stay on C). */
    float *nc = tdem_floats(3 * n);
    memcpy(nc, sc.nx, n * sizeof *nc);
    memcpy(nc + n, sc.ny, n * sizeof *nc);
    memcpy(nc + 2 * n, sc.nz, n * sizeof *nc);
    ts_backend_env_light st = {0};
    memset(l, 0, 3 * n * sizeof *l);
    for (int k = 0; k < 8; k++) {
        if (k == 4)
            setenv("TERRASHADE_OPENCL_MAX_ALLOC", "4k", 1);
        ts_env_light_request ql = scene_env(&sc, &t, k, l);
        if (k >= 4)
            ql.nx = nc, ql.ny = nc + n, ql.nz = nc + 2 * n;
        ck_assert_int_eq(ts_backend_env_light_accumulate(TS_BACKEND_OPENCL, &st, &ql, &r, &e),
                         TS_OK);
        ck_assert_int_eq(r.used, k < 4 ? TS_BACKEND_OPENCL : TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, k >= 4);
    }
    ts_backend_env_light_release(&st);
    long mid_nan = 0;
    double mid = env_rel_diff(c, l, 3 * n, &mid_nan);
    printf("  envlight OpenCL then C from plane 4: max |C - mixed| / C = %.3g\n", mid);
    ck_assert(mid <= TOL_ENV_REL && mid_nan == 0);
    free(nc);
    clear_env();
    /* argument errors: the C function's */
    const ts_env_light_request q0 = scene_env(&sc, &t, 0, l);
    ts_env_light_request bad = q0;
    bad.k = 8;
    ck_assert_int_eq(ts_backend_env_light_accumulate(TS_BACKEND_OPENCL, NULL, &bad, &r, &e),
                     TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "outside the light table's 8 directions"));
    bad = q0, bad.ny = NULL;
    ck_assert_int_eq(ts_cl_env_light_accumulate(&bad, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_env_light_accumulate(NULL, &e), TS_ERR_ARG);
    /* a session is for the arrays it was opened with */
    ts_cl_env_light *ss;
    ck_assert_int_eq(ts_cl_env_light_open(&q0, &ss, &e), TS_OK);
    bad = q0, bad.nx = sc.ny;
    ck_assert_int_eq(ts_cl_env_light_add(ss, &bad, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "opened for another"));
    ts_cl_env_light_close(ss);
    ts_env_table_free(&t);
    ts_env_free(&env);
    free(c), free(l);
    scene_free(&sc, s);
}
END_TEST

static Suite *opencl_suite(void)
{
    Suite *s = suite_create("opencl_env");
    TCase *t = tcase_create("backends");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, test_env_light);
    suite_add_tcase(s, t);
    TCase *d = tcase_create("dispatch and failures");
    tcase_set_timeout(d, 600);
    tcase_add_test(d, test_env_light_dispatch);
    suite_add_tcase(s, d);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return test_run_suite_mode(opencl_suite(), CK_VERBOSE);
}
