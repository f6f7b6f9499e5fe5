/* The OpenCL backend of the shadow map and of the wider light's disk
 * against the C backend (tolerances of docs/opencl.md). Never skips:
 * without OpenCL it fails, saying so. */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "terrashade.h"
#include "terrashade_backend.h"
#include "terrashade_cl.h"
#include "terrashade_shadowmap.h"
#include "test_grid.h"
#include "test_run.h"

#define TOL 1e-4 /* visibility, direct light: as SHM in docs/opencl.md */

static void require_opencl(void)
{
    ts_cl_info info;
    ts_error e;
    ck_assert_msg(ts_cl_built(), "OpenCL support was not built");
    ck_assert_msg(ts_cl_available(&info, &e) == TS_OK, "no usable OpenCL device: %s",
                  e.message);
}

/* Largest |a - b| over the cells, NaN only where both are. */
static double max_diff(const float *a, const float *b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg(isnan(a[i]) == isnan(b[i]), "cell %zu: %g vs %g", i, a[i], b[i]);
        if (!isnan(a[i]))
            m = fmax(m, fabs(a[i] - b[i]));
    }
    return m;
}

/* A fractal with a nodata block, rows padded (stride > width). */
static void padded_fractal(ts_grid *g, ts_grid *view)
{
    tdem_create(g, 157, 121, 25, 25);
    tdem_fractal(g, 11, 900);
    *view = *g;
    view->width = 150;
    view->owns_memory = 0;
    for (int y = 40; y < 55; y++)
        for (int x = 60; x < 90; x++)
            g->z[(size_t)y * g->stride + x] = NAN;
}

START_TEST(test_shadowmap_equal)
{
    require_opencl();
    static const struct { double az, el, r, kernel; } RUNS[] = {
        {135, 10, TS_SUN_RADIUS_DEG, TS_SHADOWMAP_AUTO}, {315, 30, TS_SUN_RADIUS_DEG, 0},
        {135, 10, 2, TS_SHADOWMAP_AUTO}, {315, 30, 2, 3}, {20, 60, 5, 0.5}, {250, 4, 1, 0}};
    ts_grid jb, fr, frv;
    tdem_load(&jb, "jacksboro");
    padded_fractal(&fr, &frv);
    const ts_grid *grids[] = {&jb, &frv};
    double worst = 0;
    for (int k = 0; k < 2; k++) {
        const ts_grid *g = grids[k];
        const size_t n = (size_t)g->width * g->height;
        float *c = tdem_floats(n), *cl = tdem_floats(n);
        for (size_t r = 0; r < sizeof RUNS / sizeof *RUNS; r++) {
            ts_shadowmap_opts o;
            ts_shadowmap_opts_default(&o);
            o.light_radius = RUNS[r].r;
            o.kernel = RUNS[r].kernel;
            o.scale = r == 5 ? 3.5 : 2.0;
            ts_error e;
            ck_assert_int_eq(ts_shadowmap_compute(g, RUNS[r].az, RUNS[r].el, &o, c, &e), TS_OK);
            ck_assert_msg(ts_cl_shadowmap_compute(g, RUNS[r].az, RUNS[r].el, &o, cl, &e) == TS_OK,
                          "%s", e.message);
            double d = max_diff(c, cl, n);
            ck_assert_msg(d <= TOL, "grid %d light %g/%g r %g kernel %g: max |C - OpenCL| %g", k,
                          RUNS[r].az, RUNS[r].el, RUNS[r].r, RUNS[r].kernel, d);
            worst = fmax(worst, d);
        }
        free(c);
        free(cl);
    }
    printf("  shadowmap, jacksboro and a padded fractal with nodata: max |C - OpenCL| %.3g\n",
           worst);
    /* the dispatcher runs the same, and says where */
    const size_t n = (size_t)jb.width * jb.height;
    float *a = tdem_floats(n), *b = tdem_floats(n);
    ts_shadowmap_opts o;
    ts_shadowmap_opts_default(&o);
    ts_backend_report rep;
    ts_error e;
    ck_assert_int_eq(ts_backend_shadowmap_compute(TS_BACKEND_C, &jb, 200, 20, &o, a, &rep, &e),
                     TS_OK);
    ck_assert_str_eq(rep.backend, "c");
    ck_assert_int_eq(
        ts_backend_shadowmap_compute(TS_BACKEND_OPENCL, &jb, 200, 20, &o, b, &rep, &e), TS_OK);
    ck_assert_str_eq(rep.backend, "opencl");
    ck_assert(max_diff(a, b, n) <= TOL);
    /* bad input: the same sentence as C, no fallback */
    o.kernel = 100;
    ck_assert_int_eq(ts_cl_shadowmap_compute(&jb, 200, 20, &o, b, &e), TS_ERR_ARG);
    printf("  %s\n", e.message);
    free(a);
    free(b);
    ts_grid_free(&jb);
    ts_grid_free(&fr);
}
END_TEST

/* The direct sun of a wider disk: C and OpenCL, a pillar's penumbra. */
START_TEST(test_direct_disk_equal)
{
    require_opencl();
    ts_grid g;
    tdem_create(&g, 300, 9, 1, 1);
    tdem_fill(&g, 0.0f);
    g.z[4 * g.stride + 20] = 50.0f;
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 1;
    o.curvature = 0;
    o.start_azimuth = 270;
    const size_t n = (size_t)g.width * g.height;
    float *nx = tdem_floats(n), *ny = tdem_floats(n), *nz = tdem_floats(n);
    float *h = tdem_floats(n), *c = tdem_floats(n), *cl = tdem_floats(n);
    ts_error e;
    ck_assert_int_eq(ts_normals(&g, nx, ny, nz, &e), TS_OK);
    ck_assert_int_eq(ts_horizon_sweep(&g, 270, &o, h, &e), TS_OK);
    static const double RADIUS[] = {TS_SUN_RADIUS_DEG, 1, 2, 5, 30};
    double worst = 0;
    for (size_t k = 0; k < sizeof RADIUS / sizeof *RADIUS; k++) {
        ts_direct_request rq = {&g, nx, ny, nz, h, &o, 270, 20, c, RADIUS[k]};
        ck_assert_int_eq(ts_shade_direct(&rq, &e), TS_OK);
        rq.out = cl;
        ck_assert_int_eq(ts_cl_shade_direct(&rq, &e), TS_OK);
        worst = fmax(worst, max_diff(c, cl, n));
        /* the penumbra's start, h / tan(e + r), on both */
        int x0 = 20 + (int)floor(50 / tan((20 + RADIUS[k]) * M_PI / 180)) + 1;
        ck_assert(cl[4 * g.width + x0] > 0.0f && cl[4 * g.width + x0 - 1] == 0.0f);
    }
    ck_assert_msg(worst <= TOL, "direct disk: max |C - OpenCL| %g", worst);
    printf("  direct sun with LIGHT_RADIUS 0.2666..30: max |C - OpenCL| %.3g\n", worst);
    const ts_direct_request wide = {&g, nx, ny, nz, h, &o, 270, 20, cl, 45};
    ck_assert_int_eq(ts_cl_shade_direct(&wide, &e), TS_ERR_ARG);
    free(nx), free(ny), free(nz), free(h), free(c), free(cl);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("opencl_shadowmap");
    TCase *t = tcase_create("equal");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, test_shadowmap_equal);
    tcase_add_test(t, test_direct_disk_equal);
    suite_add_tcase(s, t);
    return test_run_suite(s);
}
