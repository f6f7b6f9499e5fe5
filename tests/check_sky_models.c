/* The sky-view factor models (radiative, solid angle) and openness of the
 * sky terms, against their closed forms; one swath of the radiative terms
 * against quadrature. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"

static const double PI_D = 3.14159265358979323846;
static const double DEG = 3.14159265358979323846 / 180.0;

/* Per-direction horizons of the cells, one row per cell: a mix of negative,
 * zero and positive angles (the solid-angle model clamps at 0). */
#define NDIR 8
#define NCELL 4
static const float HOR[NCELL][NDIR] = {
    {-5, -5, -5, -5, -5, -5, -5, -5},
    {0, 10, 20, 30, 40, 30, 20, 10},
    {-20, 35, -1, 60, 2, 0, 15, -80},
    {89, 89, 89, 89, 89, 89, 89, 89},
};

typedef struct {
    ts_grid g;
    float *nx, *ny, *nz, *hor;
    ts_horizon_opts o;
} sky_case;

/* NCELL x 1 grid, flat normals, the horizons above (plane k = direction k). */
static void case_make(sky_case *c)
{
    ts_error e;
    ck_assert(ts_grid_create(&c->g, NCELL, 1, 10, 10, &e) == TS_OK);
    c->nx = tdem_floats(NCELL), c->ny = tdem_floats(NCELL), c->nz = tdem_floats(NCELL);
    c->hor = tdem_floats((size_t)NCELL * NDIR);
    for (int i = 0; i < NCELL; i++) {
        c->nx[i] = c->ny[i] = 0, c->nz[i] = 1;
        for (int k = 0; k < NDIR; k++)
            c->hor[k * NCELL + i] = HOR[i][k];
    }
    ts_horizon_opts_default(&c->o);
    c->o.directions = NDIR;
}

/* The case's sky terms of model `model` into svf and open (may be NULL). */
static ts_status case_sky(const sky_case *c, ts_svf_model model, float *svf, float *open,
                          ts_error *e)
{
    const ts_sky_request req = {&c->g, c->nx, c->ny, c->nz, c->hor, &c->o, model,
                                svf, NULL, open};
    return ts_sky_terms(&req, e);
}

static void case_free(sky_case *c)
{
    free(c->nx), free(c->ny), free(c->nz), free(c->hor);
    ts_grid_free(&c->g);
}

START_TEST(test_solid_angle_closed_form)
{
    sky_case c;
    case_make(&c);
    float svf[NCELL], open[NCELL];
    ts_error e;
    ck_assert_msg(case_sky(&c, TS_SVF_SOLID_ANGLE, svf, open, &e) == TS_OK, "%s", e.message);
    for (int i = 0; i < NCELL; i++) {
        double s = 0, o = 0;
        for (int k = 0; k < NDIR; k++) {
            s += sin(fmax(HOR[i][k], 0) * DEG);
            o += 90.0 - HOR[i][k];
        }
        double want = 1.0 - s / NDIR;
        ck_assert_msg(fabs(svf[i] - want) < 2e-6, "cell %d: svf %.7f, 1 - mean sin %.7f", i,
                      svf[i], want);
        ck_assert_msg(fabs(open[i] - o / NDIR) < 1e-4, "cell %d: openness %.5f, want %.5f", i,
                      open[i], o / NDIR);
    }
    /* an open plane (all horizons below 0) sees the whole sky in both models */
    ck_assert_float_eq(svf[0], 1.0f);
    case_free(&c);
}
END_TEST

START_TEST(test_radiative_is_the_default)
{
    sky_case c;
    case_make(&c);
    float a[NCELL], b[NCELL];
    ts_error e;
    /* a request that leaves the model out asks for the radiative svf */
    const ts_sky_request req = {.grid = &c.g, .nx = c.nx, .ny = c.ny, .nz = c.nz,
                                .horizons = c.hor, .opts = &c.o, .svf = a};
    ck_assert(ts_sky_terms(&req, &e) == TS_OK);
    ck_assert(case_sky(&c, TS_SVF_RADIATIVE, b, NULL, &e) == TS_OK);
    ck_assert(memcmp(a, b, sizeof a) == 0);
    /* the radiative svf weighs the sky by cos(zenith): on a flat cell it
     * is 1 - mean sin^2(max(h, 0)) instead of 1 - mean sin(max(h, 0)) */
    for (int i = 0; i < NCELL; i++) {
        double s2 = 0;
        for (int k = 0; k < NDIR; k++)
            s2 += pow(sin(fmax(HOR[i][k], 0) * DEG), 2);
        ck_assert_msg(fabs(a[i] - (1.0 - s2 / NDIR)) < 1e-5, "cell %d: radiative %.6f vs %.6f",
                      i, a[i], 1.0 - s2 / NDIR);
    }
    case_free(&c);
}
END_TEST

START_TEST(test_accumulating_form_and_nodata)
{
    sky_case c;
    case_make(&c);
    c.hor[3 * NCELL + 2] = NAN; /* cell 2, direction 3: nodata */
    float whole[NCELL], acc[NCELL] = {0};
    ts_error e;
    ck_assert(case_sky(&c, TS_SVF_SOLID_ANGLE, whole, NULL, &e) == TS_OK);
    for (int k = 0; k < NDIR; k++)
        ck_assert(ts_sky_accumulate_model(&c.g, c.nx, c.ny, c.nz, c.hor + k * NCELL,
                                          ts_horizon_azimuth(&c.o, k), NDIR,
                                          TS_SVF_SOLID_ANGLE, 1, acc, NULL, NULL, &e) == TS_OK);
    ck_assert(ts_sky_finish(&c.g, NDIR, acc, NULL, NULL, &e) == TS_OK);
    for (int i = 0; i < NCELL; i++)
        ck_assert_msg(memcmp(&acc[i], &whole[i], sizeof(float)) == 0, "cell %d: %g vs %g", i,
                      acc[i], whole[i]);
    ck_assert(isnan(whole[2]));
    ck_assert(!isnan(whole[1]));
    case_free(&c);
}
END_TEST

START_TEST(test_bad_model)
{
    sky_case c;
    case_make(&c);
    float out[NCELL];
    ts_error e;
    ck_assert_int_eq(case_sky(&c, (ts_svf_model)7, out, NULL, &e), TS_ERR_ARG);
    ck_assert_msg(strstr(e.message, "svf model") != NULL, "%s", e.message);
    ck_assert_int_eq(ts_sky_accumulate_model(&c.g, c.nx, c.ny, c.nz, c.hor, 0, NDIR,
                                             (ts_svf_model)-1, 0, out, NULL, NULL, &e),
                     TS_ERR_ARG);
    case_free(&c);
}
END_TEST

/* At the bottom of a conical pit of slope s the horizon is s all around:
 * solid-angle svf 1 - sin s, openness 90 - s; on the negated DEM (a cone
 * peak) the top's horizon is -s: openness 90 + s (negative openness of the
 * pit's negation, as RVT computes it). Four directions, along the grid's
 * axes, where the sweep's lines run through the cells: on other azimuths it
 * interpolates between cells across the kink at the cone's tip. */
START_TEST(test_cone)
{
    const int n = 101, mid = 50;
    const double s = 25.0, cell = 10.0;
    ts_grid g;
    tdem_create(&g, n, n, cell, cell);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++)
            g.z[(size_t)y * g.stride + x] = (float)(hypot(x - mid, y - mid) * cell * tan(s * DEG));
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 4;
    o.curvature = 0;
    o.max_distance = 40 * cell;
    size_t N = (size_t)n * n;
    float *nx = tdem_floats(N), *ny = tdem_floats(N), *nz = tdem_floats(N);
    float *hor = tdem_floats(N * o.directions), *svf = tdem_floats(N), *op = tdem_floats(N);
    ts_error e;
    for (int sign = 1; sign >= -1; sign -= 2) {
        if (sign < 0)
            for (size_t i = 0; i < N; i++)
                g.z[i] = -g.z[i];
        ck_assert(ts_normals(&g, nx, ny, nz, &e) == TS_OK);
        ck_assert(ts_horizon_compute(&g, &o, hor, &e) == TS_OK);
        const ts_sky_request req = {&g, nx, ny, nz, hor, &o, TS_SVF_SOLID_ANGLE, svf, NULL, op};
        ck_assert(ts_sky_terms(&req, &e) == TS_OK);
        size_t c = (size_t)mid * n + mid;
        double want_svf = sign > 0 ? 1.0 - sin(s * DEG) : 1.0;
        double want_op = 90.0 - sign * s;
        printf("cone %s: svf %.4f (want %.4f), openness %.3f (want %.3f)\n",
               sign > 0 ? "pit" : "peak", svf[c], want_svf, op[c], want_op);
        ck_assert_msg(fabs(svf[c] - want_svf) < 1e-4, "svf %g, want %g", svf[c], want_svf);
        ck_assert_msg(fabs(op[c] - want_op) < 1e-3, "openness %g, want %g", op[c], want_op);
    }
    free(nx), free(ny), free(nz), free(hor), free(svf), free(op);
    ts_grid_free(&g);
}
END_TEST

/* (1/pi) of the integral of n.w sin(theta) over the swath of azimuths
 * [a0, a1] (degrees from north) from the zenith down to theta1 (Timonen &
 * Westerholm 2010, eq. 4, c = 1): midpoint rule, w = (east, north, up). */
static double swath_quadrature(const double n[3], double a0, double a1, double theta1)
{
    const int NA = 256, NT = 2000;
    double s = 0, da = (a1 - a0) * DEG / NA, dt = theta1 / NT;
    for (int i = 0; i < NA; i++) {
        double az = a0 * DEG + (i + 0.5) * da;
        for (int j = 0; j < NT; j++) {
            double t = (j + 0.5) * dt, st = sin(t);
            s += (n[0] * st * sin(az) + n[1] * st * cos(az) + n[2] * cos(t)) * st;
        }
    }
    return s * da * dt / PI_D;
}

/* One swath of 4 (azimuth 90, so [45, 135]) at two cells tilted 30 deg,
 * towards azimuth 110 (horizon 20) and away, towards 290 (horizon 40): the
 * horizon bounds the sky above the tangent plane across the whole swath,
 * so the radiative svf and sky terms are eq. 4 over the swath exactly
 * (with the swath weight sin(pi/n)/pi of the normal's tilt). */
START_TEST(test_swath_quadrature)
{
    ts_grid g;
    ts_error e;
    ck_assert(ts_grid_create(&g, 2, 1, 10, 10, &e) == TS_OK);
    const double tilt = 30 * DEG, face[2] = {110 * DEG, 290 * DEG};
    float nx[2], ny[2], nz[2], hor[2] = {20, 40}, svf[2] = {0}, sky[2] = {0};
    for (int i = 0; i < 2; i++) {
        nx[i] = (float)(sin(tilt) * sin(face[i]));
        ny[i] = (float)(sin(tilt) * cos(face[i]));
        nz[i] = (float)cos(tilt);
    }
    ck_assert(ts_sky_accumulate(&g, nx, ny, nz, hor, 90.0, 4, svf, sky, NULL, &e) == TS_OK);
    for (int i = 0; i < 2; i++) {
        double n[3] = {nx[i], ny[i], nz[i]};
        double want = swath_quadrature(n, 45, 135, (90 - hor[i]) * DEG);
        printf("swath [45, 135], normal tilted 30 towards %.0f, horizon %.0f: svf term %.6f, "
               "sky term %.6f, quadrature %.6f\n", face[i] / DEG, hor[i], svf[i], sky[i], want);
        ck_assert_msg(fabs(svf[i] - want) < 1e-5, "svf term %.7f, want %.7f", svf[i], want);
        ck_assert_msg(fabs(sky[i] - want) < 1e-5, "sky term %.7f, want %.7f", sky[i], want);
    }
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("sky_models");
    TCase *tc = tcase_create("sky_models");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_solid_angle_closed_form);
    tcase_add_test(tc, test_radiative_is_the_default);
    tcase_add_test(tc, test_accumulating_form_and_nodata);
    tcase_add_test(tc, test_bad_model);
    tcase_add_test(tc, test_cone);
    tcase_add_test(tc, test_swath_quadrature);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
