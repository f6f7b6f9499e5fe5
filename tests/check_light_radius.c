/* LIGHT_RADIUS: the exact method's visible fraction of a wider disk, held
 * against the geometry of a pillar's penumbra on flat ground. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "terrashade.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

#define DEG (M_PI / 180.0)

/*
 * A pillar of height h (one cell) on flat ground, the light in the west at
 * elevation e. A cell at distance d east of it sees the pillar's top at
 * the elevation atan(h / d): the disk of radius r (centre e) is hidden
 * while atan(h / d) >= e + r and wholly visible once atan(h / d) <= e - r.
 * So the umbra ends at d = h / tan(e + r) and the penumbra at
 * d = h / tan(e - r): its width on the ground is
 * h (1 / tan(e - r) - 1 / tan(e + r)).
 */
#define PILLAR_W 640
#define PILLAR_H 5
#define PILLAR_X 20
#define PILLAR_HEIGHT 50.0

/* The pillar's grid, and the options of its one sweep towards the light
 * in the west (no curvature: flat ground). */
static void pillar(ts_grid *g, ts_horizon_opts *o)
{
    tdem_create(g, PILLAR_W, PILLAR_H, 1.0, 1.0);
    tdem_fill(g, 0.0f);
    g->z[(size_t)(PILLAR_H / 2) * g->stride + PILLAR_X] = (float)PILLAR_HEIGHT;
    ts_horizon_opts_default(o);
    o->directions = 1;
    o->curvature = 0;
    o->start_azimuth = 270;
}

/* Start and end (metres east of the pillar) of the penumbra in the
 * visible fractions `lit` of the pillar's row: the first cell with some
 * light, the first with all of it. */
static void penumbra(const float *row, double *start, double *end)
{
    *start = *end = NAN;
    for (int x = PILLAR_X + 1; x < PILLAR_W; x++) {
        if (isnan(*start) && row[x] > 0.0f)
            *start = x - PILLAR_X;
        if (row[x] >= 1.0f) {
            *end = x - PILLAR_X;
            break;
        }
    }
}

START_TEST(test_pillar_penumbra)
{
    static const double ELEV[] = {10, 20, 35}, RADIUS[] = {TS_SUN_RADIUS_DEG, 1, 2, 5};
    ts_grid g;
    ts_horizon_opts o;
    pillar(&g, &o);
    ts_error err;
    float *hor = tdem_floats((size_t)PILLAR_W * PILLAR_H);
    float *lit = tdem_floats((size_t)PILLAR_W * PILLAR_H);
    ck_assert_int_eq(ts_horizon_sweep(&g, 270, &o, hor, &err), TS_OK);
    const float *row = hor + (size_t)(PILLAR_H / 2) * PILLAR_W;
    for (size_t e = 0; e < sizeof ELEV / sizeof *ELEV; e++)
        for (size_t k = 0; k < sizeof RADIUS / sizeof *RADIUS; k++) {
            double el = ELEV[e], r = RADIUS[k];
            float *lr = lit + (size_t)(PILLAR_H / 2) * PILLAR_W;
            for (int x = 0; x < PILLAR_W; x++)
                lr[x] = (float)ts_disk_fraction(el, row[x], r);
            double start, end;
            penumbra(lr, &start, &end);
            double want0 = PILLAR_HEIGHT / tan((el + r) * DEG);
            double want1 = PILLAR_HEIGHT / tan((el - r) * DEG);
            printf("pillar h=%g e=%g r=%g: penumbra %g..%g m, geometry %.2f..%.2f m "
                   "(width %.2f)\n",
                   PILLAR_HEIGHT, el, r, start, end, want0, want1, want1 - want0);
            /* the first lit cell is the first whole metre past the umbra's
             * end, the first fully lit the first at or past the penumbra's */
            ck_assert_msg(start == floor(want0) + 1, "umbra ends at %g, want %g", start,
                          floor(want0) + 1);
            ck_assert_msg(end == ceil(want1), "penumbra ends at %g, want %g", end,
                          ceil(want1));
            /* and in between, the fraction of the disk above atan(h / d) */
            for (int x = (int)start; x < (int)end; x++) {
                double f = ts_disk_fraction(el, atan(PILLAR_HEIGHT / x) / DEG, r);
                ck_assert_msg(fabs(lr[PILLAR_X + x] - f) < 1e-5, "d=%d: %g, want %g", x,
                              lr[PILLAR_X + x], f);
            }
        }
    free(hor);
    free(lit);
    ts_grid_free(&g);
}
END_TEST

/* The sun's radius gives the sun's disk, bit for bit; shade with the wider
 * disk: the same Lambert term, softer shadow. */
START_TEST(test_sun_radius_is_default)
{
    for (double h = -5; h <= 5; h += 0.01)
        ck_assert(ts_disk_fraction(2.0, h, TS_SUN_RADIUS_DEG) == ts_sun_disk_fraction(2.0, h));
    ts_grid g;
    ts_horizon_opts o;
    pillar(&g, &o);
    const size_t n = (size_t)PILLAR_W * PILLAR_H;
    float *nx = tdem_floats(n), *ny = tdem_floats(n), *nz = tdem_floats(n);
    float *hor = tdem_floats(n), *a = tdem_floats(n), *b = tdem_floats(n);
    ts_error err;
    ck_assert_int_eq(ts_normals(&g, nx, ny, nz, &err), TS_OK);
    ck_assert_int_eq(ts_horizon_sweep(&g, 270, &o, hor, &err), TS_OK);
    /* light_radius 0 (unset) is the sun's disk, as TS_SUN_RADIUS_DEG given */
    const ts_direct_request sun = {&g, nx, ny, nz, hor, &o, 270, 20, a, 0.0};
    ts_direct_request disk = sun;
    disk.out = b;
    disk.light_radius = TS_SUN_RADIUS_DEG;
    ck_assert_int_eq(ts_shade_direct(&sun, &err), TS_OK);
    ck_assert_int_eq(ts_shade_direct(&disk, &err), TS_OK);
    for (size_t i = 0; i < n; i++)
        ck_assert(a[i] == b[i] || (isnan(a[i]) && isnan(b[i])));
    disk.light_radius = 2.0;
    ck_assert_int_eq(ts_shade_direct(&disk, &err), TS_OK);
    const size_t r = (size_t)(PILLAR_H / 2) * PILLAR_W + PILLAR_X;
    const double sin20 = sin(20 * DEG);
    for (int d = 100; d < 200; d++) {
        double f = ts_disk_fraction(20, hor[r + d], 2.0);
        ck_assert_msg(fabs(b[r + d] - sin20 * f) < 1e-5, "d=%d: %g, want %g", d, b[r + d],
                      sin20 * f);
    }
    /* the wider disk's penumbra begins nearer the pillar than the sun's */
    ck_assert(b[r + 126] > 0.0f && a[r + 126] == 0.0f);
    static const double BAD_RADIUS[] = {-1.0, 45.0, NAN, INFINITY};
    for (size_t k = 0; k < sizeof BAD_RADIUS / sizeof *BAD_RADIUS; k++) {
        disk.light_radius = BAD_RADIUS[k];
        EXPECT_ARG(ts_shade_direct(&disk, &err), &err);
    }
    ck_assert(isnan(ts_disk_fraction(20, 10, 0)));
    free(nx);
    free(ny);
    free(nz);
    free(hor);
    free(a);
    free(b);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("light_radius");
    TCase *t = tcase_create("disk");
    tcase_add_test(t, test_pillar_penumbra);
    tcase_add_test(t, test_sun_radius_is_default);
    suite_add_tcase(s, t);
    return test_run_suite(s);
}
