/*
 * check_opencl: the OpenCL backend against the C backend, product by
 * product (horizons, shm, normals, direct, sky, argument checks), on
 * synthetic DEMs (sums of sines plus hashed noise) of odd sizes (1x1, 1xN,
 * Nx1, primes), with nodata holes, geographic row spacing and a padded row
 * stride. The environment light is in check_opencl_env, the dispatcher and
 * the forced failures in check_opencl_dispatch.
 *
 * Never skips: without OpenCL support, or without an OpenCL device (PoCL
 * is installed by setup.sh), the tests fail and say why. Measured maximum
 * differences are printed to the log.
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

/* The build configuration: with OpenCL the backend says so; without it
 * every function answers "not built" and the dispatcher runs C. */
START_TEST(test_build_config)
{
    ts_error e;
#ifdef HAVE_OPENCL
    ck_assert_int_eq(ts_cl_built(), 1);
#else
    ck_assert_int_eq(ts_cl_built(), 0);
#endif
    if (ts_cl_built())
        return;
    ck_assert_int_ne(ts_cl_available(NULL, &e), TS_OK);
    ck_assert_ptr_nonnull(strstr(e.message, "OpenCL support was not built"));
    ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, &SHAPES[4]);
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    ck_assert_int_eq(r.fell_back, 1);
    ck_assert_ptr_nonnull(strstr(r.reason, "OpenCL support was not built"));
}
END_TEST

START_TEST(test_available)
{
    require_opencl();
    ts_cl_info info, list[8];
    ts_error e;
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    printf("  device %d (%d:%d): %s on %s, %s, %s, %d compute units, fp64 %d, "
           "max alloc %llu MiB\n",
           info.index, info.platform_index, info.device_index, info.device, info.platform,
           info.type, info.version, info.compute_units, info.fp64, info.max_alloc >> 20);
    ck_assert(info.device[0] && info.platform[0]);
    int count = 0;
    ck_assert_int_eq(ts_cl_devices(list, 8, &count, &e), TS_OK);
    ck_assert_int_ge(count, 1);
    ck_assert_str_eq(list[info.index].device, info.device);
}
END_TEST

static void horizon_case(const dem_spec *s, int dirs, double start, int curvature,
                         double max_distance)
{
    char name[160], sh[64];
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = dirs;
    o.start_azimuth = start;
    o.curvature = curvature;
    o.max_distance = max_distance;
    o.threads = 2;
    size_t n = (size_t)s->w * s->h * dirs;
    float *c = tdem_floats(n), *cl = tdem_floats(n);
    ck_assert_int_eq(ts_horizon_compute(&g, &o, c, &e), TS_OK);
    snprintf(name, sizeof name, "horizon %s, %d dirs from %g%s%s", shape_name(s, sh, sizeof sh),
             dirs, start, curvature ? ", curvature" : "", max_distance > 0 ? ", capped" : "");
    /* Every test grid is shorter than 1e5 m: a shorter distance caps its
     * lines, and the kernel, without the C sweep's window hull, refuses it. */
    if (max_distance > 0 && max_distance < 1e5) {
        ck_assert_int_eq(ts_cl_horizon_compute(&g, &o, cl, &e), TS_ERR_ARG);
        ck_assert_str_eq(e.message, TS_CL_CAPPED_SWEEP_REASON);
        ck_assert_int_eq(ts_cl_horizon_sweep(&g, start, &o, cl, &e), TS_ERR_ARG);
        ck_assert_str_eq(e.message, TS_CL_CAPPED_SWEEP_REASON);
        /* BACKEND=opencl then runs C: its result bit for bit, and says why. */
        ts_backend_report r;
        ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &g, &o, cl, &r, &e),
                         TS_OK);
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, 1);
        ck_assert_str_eq(r.backend, "c");
        ck_assert_str_eq(r.reason, TS_CL_CAPPED_SWEEP_REASON);
        ck_assert_msg(memcmp(c, cl, n * sizeof *c) == 0, "%s: the fallback differs from C",
                      name);
        printf("  %-58s OpenCL refuses, C ran (bit-identical)\n", name);
    } else {
        ts_status st = ts_cl_horizon_compute(&g, &o, cl, &e);
        ck_assert_msg(st == TS_OK, "ts_cl_horizon_compute: %s", e.message);
        expect_close(name, c, cl, n, TOL_HORIZON);
    }
    free(c);
    free(cl);
    free_dem(&g, s);
}

START_TEST(test_horizon)
{
    require_opencl();
    for (int i = 0; i < NSHAPES; i++) {
        horizon_case(&SHAPES[i], 8, 0.0, 1, 0);     /* axes and diagonals */
        horizon_case(&SHAPES[i], 7, 10.0, i & 1, 0); /* odd angles */
    }
    /* a search radius of a few cells, and one of many */
    horizon_case(&SHAPES[4], 5, 3.0, 1, 200.0);
    horizon_case(&SHAPES[8], 6, 17.0, 0, 95.0);
    horizon_case(&SHAPES[6], 4, 45.0, 1, 4000.0);
    horizon_case(&SHAPES[5], 6, 7.0, 1, 500.0); /* occluders on both sides of it */
    /* a distance longer than every line caps nothing: OpenCL runs it */
    horizon_case(&SHAPES[6], 5, 3.0, 1, 1e6);
    /* more directions than one batch holds */
    horizon_case(&SHAPES[4], 40, 1.0, 1, 0);
}
END_TEST

/* Small buffers (TERRASHADE_OPENCL_MAX_ALLOC): several batches of azimuths
 * and several launches of hull stacks per batch, same results. */
START_TEST(test_horizon_small_buffers)
{
    require_opencl();
    setenv("TERRASHADE_OPENCL_MAX_ALLOC", "64k", 1);
    horizon_case(&SHAPES[8], 9, 2.0, 1, 0);     /* 64x64: 2 planes a batch */
    horizon_case(&SHAPES[8], 5, 31.0, 1, 300.0); /* with the raw samples */
    horizon_case(&SHAPES[6], 6, 12.0, 1, 0);    /* geographic */
    unsetenv("TERRASHADE_OPENCL_MAX_ALLOC");
}
END_TEST

/* EDGE: every mode gives the same planes in both backends (the clamp runs
 * on the planes read back, before any sum or test), with and without a
 * search radius that the kernel runs (one longer than every line). */
START_TEST(test_horizon_edge)
{
    require_opencl();
    static const ts_edge_mode modes[] = {TS_EDGE_OPEN, TS_EDGE_HORIZON, TS_EDGE_NODATA};
    const int shapes[] = {4, 6, 7}; /* holes, geographic, 500 m cells */
    for (int m = 0; m < 3; m++)
        for (int i = 0; i < 3; i++)
            for (int capped = 0; capped < 2; capped++) {
                const dem_spec *s = &SHAPES[shapes[i]];
                ts_grid g;
                ts_error e;
                char name[96], sh[64];
                make_dem(&g, s);
                ts_horizon_opts o;
                ts_horizon_opts_default(&o);
                o.directions = 7;
                o.start_azimuth = 5.0;
                o.edge = modes[m];
                o.max_distance = capped ? 1e7 : 0.0;
                size_t n = (size_t)s->w * s->h * o.directions;
                float *c = tdem_floats(n), *cl = tdem_floats(n);
                ck_assert_int_eq(ts_horizon_compute(&g, &o, c, &e), TS_OK);
                ck_assert_msg(ts_cl_horizon_compute(&g, &o, cl, &e) == TS_OK, "%s", e.message);
                snprintf(name, sizeof name, "horizon %s, edge mode %d%s",
                         shape_name(s, sh, sizeof sh), (int)modes[m], capped ? ", 1e7 m" : "");
                expect_close(name, c, cl, n, TOL_HORIZON);
                free(c);
                free(cl);
                free_dem(&g, s);
            }
}
END_TEST

START_TEST(test_horizon_sweep)
{
    require_opencl();
    const dem_spec *s = &SHAPES[5];
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    size_t n = (size_t)s->w * s->h;
    float *c = tdem_floats(n), *cl = tdem_floats(n);
    const double az[] = {0, 360, 33.3, -45, 90, 180.0001, 270, 1e-7, 719.5};
    for (size_t k = 0; k < sizeof az / sizeof *az; k++) {
        ck_assert_int_eq(ts_horizon_sweep(&g, az[k], &o, c, &e), TS_OK);
        ck_assert_msg(ts_cl_horizon_sweep(&g, az[k], &o, cl, &e) == TS_OK, "%s", e.message);
        char name[96];
        snprintf(name, sizeof name, "horizon sweep at %g", az[k]);
        expect_close(name, c, cl, n, TOL_HORIZON);
    }
    /* every azimuth in one call: each plane what its own call gives, bit for
     * bit, on both backends (the driver's batches, tsd_compute_stream) */
    const int na = (int)(sizeof az / sizeof *az);
    float *all = tdem_floats(n * na);
    for (int b = 0; b < 2; b++) {
        ts_backend_report rep;
        ck_assert_msg(ts_backend_horizon_sweeps(b ? TS_BACKEND_OPENCL : TS_BACKEND_C, &g, az, na,
                                                &o, all, &rep, &e) == TS_OK,
                      "%s", e.message);
        ck_assert_int_eq(rep.used, b ? TS_BACKEND_OPENCL : TS_BACKEND_C);
        for (int k = 0; k < na; k++) {
            ck_assert_int_eq(b ? ts_cl_horizon_sweep(&g, az[k], &o, cl, &e)
                               : ts_horizon_sweep(&g, az[k], &o, cl, &e),
                             TS_OK);
            ck_assert_msg(!memcmp(all + (size_t)k * n, cl, n * sizeof *cl),
                          "%s: azimuth %g swept with the others differs from its own sweep",
                          b ? "opencl" : "c", az[k]);
        }
    }
    /* a bad list: nothing, NULL, an azimuth that is no number */
    const double bad[] = {10, NAN};
    ck_assert_int_eq(ts_cl_horizon_sweeps(&g, az, 0, &o, all, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "at least one entry, got 0"));
    ck_assert_int_eq(ts_cl_horizon_sweeps(&g, NULL, 1, &o, all, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_horizon_sweeps(&g, bad, 2, &o, all, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_backend_horizon_sweeps(TS_BACKEND_C, &g, bad, 2, &o, all, NULL, &e),
                     TS_ERR_ARG);
    ck_assert_int_eq(ts_backend_horizon_sweeps(TS_BACKEND_C, &g, az, -1, &o, all, NULL, &e),
                     TS_ERR_ARG);
    free(all);
    free(c);
    free(cl);
    free_dem(&g, s);
}
END_TEST

START_TEST(test_shm)
{
    require_opencl();
    const double az[] = {0, 90, 180, 270, 45, 135, 225, 315, 30.5, 200.7, 359.9, 63.4349};
    const double el[][2] = {{5, 0}, {30, 20}, {90, 0}, {-10, 5}, {2, 50}};
    double worst_v = 0, worst_s = 0;
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        ts_grid g;
        ts_error e;
        make_dem(&g, s);
        size_t n = (size_t)s->w * s->h;
        float *vc = tdem_floats(n), *vl = tdem_floats(n);
        float *sc = tdem_floats(n), *sl = tdem_floats(n);
        for (size_t a = 0; a < sizeof az / sizeof *az; a++)
            for (size_t k = 0; k < sizeof el / sizeof *el; k++) {
                if ((a + k + (size_t)i) % 2 && s->w * s->h > 100)
                    continue; /* half the combinations on the bigger grids */
                ck_assert_int_eq(ts_shm_compute(&g, az[a], el[k][0], el[k][1], 2, vc, sc, &e),
                                 TS_OK);
                ts_status st = ts_cl_shm_compute(&g, az[a], el[k][0], el[k][1], 0, vl, sl, &e);
                ck_assert_msg(st == TS_OK, "ts_cl_shm_compute: %s", e.message);
                diff dv = compare(vc, vl, n), ds = compare(sc, sl, n);
                char sh[64];
                ck_assert_msg(dv.nan_mismatch == 0 && ds.nan_mismatch == 0,
                              "shm %s az %g el %g: nodata differs", shape_name(s, sh, sizeof sh),
                              az[a], el[k][0]);
                ck_assert_msg(dv.max <= TOL && ds.max <= TOL,
                              "shm %s az %g el %g depth %g: visibility %g, height %g",
                              shape_name(s, sh, sizeof sh), az[a], el[k][0], el[k][1], dv.max,
                              ds.max);
                worst_v = fmax(worst_v, dv.max);
                worst_s = fmax(worst_s, ds.max);
            }
        /* one output at a time */
        ck_assert_int_eq(ts_shm_compute(&g, 123.0, 12.0, 0, 0, vc, NULL, &e), TS_OK);
        ck_assert_int_eq(ts_cl_shm_compute(&g, 123.0, 12.0, 0, 0, vl, NULL, &e), TS_OK);
        expect_close("shm visibility only", vc, vl, n, TOL);
        ck_assert_int_eq(ts_shm_compute(&g, 300.0, 8.0, 0, 0, NULL, sc, &e), TS_OK);
        ck_assert_int_eq(ts_cl_shm_compute(&g, 300.0, 8.0, 0, 0, NULL, sl, &e), TS_OK);
        expect_close("shm shadow height only", sc, sl, n, TOL);
        free(vc), free(vl), free(sc), free(sl);
        free_dem(&g, s);
    }
    printf("  shm, all shapes and lights: max |C - OpenCL| visibility %.3g, shadow height %.3g m\n",
           worst_v, worst_s);
}
END_TEST

/* A grid wider than one work-group band, so that the halo tiles matter. */
START_TEST(test_shm_wide)
{
    require_opencl();
    const dem_spec s = {331, 293, 20, 1, 0, 0, 11};
    ts_grid g;
    ts_error e;
    make_dem(&g, &s);
    size_t n = (size_t)s.w * s.h;
    float *vc = tdem_floats(n), *vl = tdem_floats(n);
    float *sc = tdem_floats(n), *sl = tdem_floats(n);
    const double az[] = {10, 100, 190, 280, 45, 315, 0, 90};
    for (size_t a = 0; a < sizeof az / sizeof *az; a++) {
        ck_assert_int_eq(ts_shm_compute(&g, az[a], 7.0, 3.0, 0, vc, sc, &e), TS_OK);
        ck_assert_msg(ts_cl_shm_compute(&g, az[a], 7.0, 3.0, 0, vl, sl, &e) == TS_OK, "%s",
                      e.message);
        char name[96];
        snprintf(name, sizeof name, "shm 331x293 az %g visibility", az[a]);
        expect_close(name, vc, vl, n, TOL);
        snprintf(name, sizeof name, "shm 331x293 az %g shadow height (m)", az[a]);
        expect_close(name, sc, sl, n, TOL);
    }
    free(vc), free(vl), free(sc), free(sl);
    free_dem(&g, &s);
}
END_TEST

START_TEST(test_normals)
{
    require_opencl();
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        ts_grid g;
        ts_error e;
        make_dem(&g, s);
        size_t n = (size_t)s->w * s->h;
        float *c[3] = {tdem_floats(n), tdem_floats(n), tdem_floats(n)};
        float *l[3] = {tdem_floats(n), tdem_floats(n), tdem_floats(n)};
        ck_assert_int_eq(ts_normals(&g, c[0], c[1], c[2], &e), TS_OK);
        ck_assert_msg(ts_cl_normals(&g, l[0], l[1], l[2], &e) == TS_OK, "%s", e.message);
        for (int k = 0; k < 3; k++) {
            char name[192], sh[64];
            snprintf(name, sizeof name, "normals %s, n%c", shape_name(s, sh, sizeof sh), "xyz"[k]);
            expect_close(name, c[k], l[k], n, TOL);
            free(c[k]);
            free(l[k]);
        }
        free_dem(&g, s);
    }
}
END_TEST

START_TEST(test_direct)
{
    require_opencl();
    const double sun[][2] = {{123.4, 25}, {0, 0.1}, {359.99, 3}, {270, 60}, {45, -0.1}, {200, 90}};
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        scene sc;
        scene_make(&sc, s, 8, 5.0);
        float *c = tdem_floats(sc.n), *l = tdem_floats(sc.n);
        ts_error e;
        for (size_t k = 0; k < sizeof sun / sizeof *sun; k++) {
            const ts_direct_request qc = scene_direct(&sc, sun[k][0], sun[k][1], c);
            const ts_direct_request ql = scene_direct(&sc, sun[k][0], sun[k][1], l);
            ck_assert_int_eq(ts_shade_direct(&qc, &e), TS_OK);
            ck_assert_msg(ts_cl_shade_direct(&ql, &e) == TS_OK, "%s", e.message);
            char name[192], sh[64];
            snprintf(name, sizeof name, "direct %s, sun %g/%g", shape_name(s, sh, sizeof sh),
                     sun[k][0], sun[k][1]);
            expect_close(name, c, l, sc.n, TOL);
        }
        /* one direction, the sun on it */
        sc.o.directions = 1;
        const ts_direct_request qc = scene_direct(&sc, 5.0, 20, c),
                                ql = scene_direct(&sc, 5.0, 20, l);
        ck_assert_int_eq(ts_shade_direct(&qc, &e), TS_OK);
        ck_assert_int_eq(ts_cl_shade_direct(&ql, &e), TS_OK);
        expect_close("direct, one direction", c, l, sc.n, TOL);
        sc.o.directions = 8;
        free(c), free(l);
        scene_free(&sc, s);
    }
}
END_TEST

START_TEST(test_sky)
{
    require_opencl();
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        scene sc;
        scene_make(&sc, s, 16, 0.0);
        float *c[3], *l[3];
        for (int k = 0; k < 3; k++)
            c[k] = tdem_floats(sc.n), l[k] = tdem_floats(sc.n);
        ts_error e;
        const ts_svf_model rad = TS_SVF_RADIATIVE, solid = TS_SVF_SOLID_ANGLE;
        ts_sky_request qc = scene_sky(&sc, rad, c[0], c[1], c[2]);
        ts_sky_request ql = scene_sky(&sc, rad, l[0], l[1], l[2]);
        ck_assert_int_eq(ts_sky_terms(&qc, &e), TS_OK);
        ck_assert_msg(ts_cl_sky_terms(&ql, &e) == TS_OK, "%s", e.message);
        static const char *what[3] = {"svf", "sky", "openness (deg)"};
        for (int k = 0; k < 3; k++) {
            char name[192], sh[64];
            snprintf(name, sizeof name, "%s %s", what[k], shape_name(s, sh, sizeof sh));
            expect_close(name, c[k], l[k], sc.n, TOL);
        }
        /* outputs one at a time */
        ql = scene_sky(&sc, rad, NULL, l[1], NULL);
        ck_assert_int_eq(ts_cl_sky_terms(&ql, &e), TS_OK);
        expect_close("sky alone", c[1], l[1], sc.n, TOL);
        /* the solid-angle svf (Zaksek et al. 2011), with and without the others */
        qc = scene_sky(&sc, solid, c[0], NULL, NULL);
        ck_assert_int_eq(ts_sky_terms(&qc, &e), TS_OK);
        ql = scene_sky(&sc, solid, l[0], l[1], l[2]);
        ck_assert_msg(ts_cl_sky_terms(&ql, &e) == TS_OK, "%s", e.message);
        char name[192], sh[64];
        snprintf(name, sizeof name, "svf solid_angle %s", shape_name(s, sh, sizeof sh));
        expect_close(name, c[0], l[0], sc.n, TOL);
        expect_close("sky beside svf solid_angle", c[1], l[1], sc.n, TOL);
        ql = scene_sky(&sc, solid, l[0], NULL, NULL);
        ck_assert_int_eq(ts_cl_sky_terms(&ql, &e), TS_OK);
        expect_close("svf solid_angle alone", c[0], l[0], sc.n, TOL);
        ql = scene_sky(&sc, (ts_svf_model)5, l[0], NULL, NULL);
        ck_assert_int_eq(ts_cl_sky_terms(&ql, &e), TS_ERR_ARG);
        for (int k = 0; k < 3; k++)
            free(c[k]), free(l[k]);
        scene_free(&sc, s);
    }
}
END_TEST

START_TEST(test_arguments)
{
    require_opencl();
    const dem_spec *s = &SHAPES[4];
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    size_t n = (size_t)s->w * s->h;
    float *a = tdem_floats(n), *b = tdem_floats(n), *c = tdem_floats(n);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    ck_assert_int_eq(ts_cl_shm_compute(&g, 10, 95, 0, 0, a, NULL, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "between -90 and 90, got 95"));
    ck_assert_int_eq(ts_cl_shm_compute(&g, NAN, 5, 0, 0, a, NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_shm_compute(&g, 10, 5, 0, 0, NULL, NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_horizon_sweep(&g, INFINITY, &o, a, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_horizon_sweep(&g, 0, NULL, a, &e), TS_ERR_ARG);
    o.directions = 0;
    ck_assert_int_eq(ts_cl_horizon_compute(&g, &o, a, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_normals(&g, a, b, NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_normals(NULL, a, b, c, &e), TS_ERR_ARG);
    o.directions = 1;
    const ts_direct_request dq = {&g, a, b, c, a, &o, 100, 20, b, TS_SUN_RADIUS_DEG};
    ck_assert_int_eq(ts_cl_shade_direct(&dq, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "computed for azimuth 0 only"));
    const ts_sky_request sq = {&g, a, b, c, NULL, &o, TS_SVF_RADIATIVE, a, NULL, NULL};
    ck_assert_int_eq(ts_cl_sky_terms(&sq, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_sky_terms(NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_shade_direct(NULL, &e), TS_ERR_ARG);
    free(a), free(b), free(c);
    free_dem(&g, s);
}
END_TEST

/* ------------------------------------------------------ environment light */
static Suite *opencl_suite(void)
{
    Suite *s = suite_create("opencl");
    TCase *t = tcase_create("backends");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, test_build_config);
    tcase_add_test(t, test_available);
    tcase_add_test(t, test_horizon);
    tcase_add_test(t, test_horizon_small_buffers);
    tcase_add_test(t, test_horizon_sweep);
    tcase_add_test(t, test_horizon_edge);
    tcase_add_test(t, test_shm);
    tcase_add_test(t, test_shm_wide);
    tcase_add_test(t, test_normals);
    tcase_add_test(t, test_direct);
    tcase_add_test(t, test_sky);
    tcase_add_test(t, test_arguments);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return test_run_suite_mode(opencl_suite(), CK_VERBOSE);
}
