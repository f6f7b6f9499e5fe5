/* Horizons on terrains whose answer is known in closed form. Curvature is
 * off throughout, so that the answers are exact. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "oracle.h"
#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"
#include "test_stats.h"

static const double DEG = 3.14159265358979323846 / 180.0;
static const double AZ[] = {0, 33.7, 45, 90, 137, 180, 222.2, 300};
#define N_AZ ((int)(sizeof AZ / sizeof AZ[0]))

static ts_horizon_opts flat_earth(int directions)
{
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.curvature = 0;
    o.directions = directions;
    return o;
}

static void sweep(const ts_grid *g, double az, const ts_horizon_opts *o, float *out)
{
    ts_error err;
    ck_assert_msg(ts_horizon_sweep(g, az, o, out, &err) == TS_OK, "az %g: %s", az,
                  err.message);
}

static float *compute(const ts_grid *g, const ts_horizon_opts *o)
{
    float *out = tdem_floats((size_t)g->width * g->height * o->directions);
    ts_error err;
    ck_assert_msg(ts_horizon_compute(g, o, out, &err) == TS_OK, "%s", err.message);
    return out;
}

/* Flat plane at height z0: 0 where something lies beyond the cell (the
 * oracle has a sample), -90 on the edge cells that have nothing beyond.
 * Every differing cell is printed, then the test fails if any. */
static void flat_plane(float z0, double tol)
{
    ts_grid g;
    tdem_create(&g, 60, 40, 10.0, 10.0);
    tdem_fill(&g, z0);
    ts_horizon_opts o = flat_earth(1);
    float *out = tdem_floats(60 * 40);
    long bad = 0;
    for (int a = 0; a < N_AZ; a++) {
        sweep(&g, AZ[a], &o, out);
        for (int y = 0; y < g.height; y++)
            for (int x = 0; x < g.width; x++) {
                double want = oracle_horizon(&g, x, y, AZ[a], &o) == -90.0 ? -90.0 : 0.0;
                double got = out[y * 60 + x];
                int ok = want == -90.0 ? got == -90.0 : fabs(got) <= tol;
                if (!ok && bad++ < 20)
                    printf("flat plane z=%g az %g: cell (%d,%d) got %.9g want %g\n",
                           z0, AZ[a], x, y, got, want);
            }
    }
    printf("flat plane z=%g: %ld cells differ\n", z0, bad);
    ck_assert_msg(bad == 0, "flat plane z=%g: %ld cells differ (listed in the log)",
                  z0, bad);
    free(out);
    ts_grid_free(&g);
}

START_TEST(test_flat_plane_zero) { flat_plane(0.0f, 0.0); }
END_TEST

START_TEST(test_flat_plane_raised)
{
    /* interpolating equal heights in float may round: allow 1e-3 deg */
    flat_plane(523.7f, 1e-3);
}
END_TEST

/* Pillar of height H at the centre of a flat plane, light from `az` at
 * 30 deg: the cells on the far side are shadowed up to H / tan(30 deg). */
static void pillar_grid(ts_grid *g, double H)
{
    tdem_create(g, 121, 121, 10.0, 10.0);
    tdem_fill(g, 0.0f);
    g->z[60 * g->stride + 60] = (float)H;
}

/* Along the shadow ray from the pillar: shadowed[n] for n = 1..N. Returns
 * the shadow length in metres (last shadowed step) after checking that no
 * cell beyond it is shadowed. */
static double shadow_length(const int *shadowed, int N, double step, const char *what,
                            double az)
{
    int last = 0;
    while (last < N && shadowed[last + 1])
        last++;
    for (int n = last + 1; n <= N; n++)
        ck_assert_msg(!shadowed[n], "%s az %g: cell %d steps out shadowed past the "
                      "shadow's end at %d", what, az, n, last);
    return last * step;
}

START_TEST(test_pillar_shadow_length)
{
    const double H = 200.0, elev = 30.0, cell = 10.0;
    const double want = H / tan(elev * DEG); /* 346.4 m */
    const double azs[] = {0, 45, 90, 135, 180, 225, 270, 315};
    ts_grid g;
    pillar_grid(&g, H);
    ts_horizon_opts o = flat_earth(1);
    float *hor = tdem_floats(121 * 121), *vis = tdem_floats(121 * 121);
    for (int a = 0; a < 8; a++) {
        double az = azs[a];
        /* from the pillar away from the light, one cell (or diagonal) a step */
        int dx = -(int)lrint(sin(az * DEG) * 1.2);
        int dy = (int)lrint(cos(az * DEG) * 1.2);
        double step = cell * hypot(dx, dy);
        sweep(&g, az, &o, hor);
        ts_error err;
        ck_assert_msg(ts_shm_compute(&g, az, elev, 0.0, 1, vis, NULL, &err) == TS_OK,
                      "%s", err.message);
        int sh_h[61] = {0}, sh_s[61] = {0};
        for (int n = 1; n <= 60; n++) {
            int x = 60 + n * dx, y = 60 + n * dy;
            sh_h[n] = hor[y * 121 + x] > elev;
            sh_s[n] = vis[y * 121 + x] < 0.5f;
        }
        double lh = shadow_length(sh_h, 60, step, "horizon", az);
        double ls = shadow_length(sh_s, 60, step, "shadow height map", az);
        printf("pillar az %5.1f: shadow length %.1f m (horizon), %.1f m (SHM), "
               "want %.1f m\n", az, lh, ls, want);
        ck_assert_msg(fabs(lh - want) <= step, "horizon shadow az %g: %.1f m, want %.1f",
                      az, lh, want);
        ck_assert_msg(fabs(ls - want) <= step, "SHM shadow az %g: %.1f m, want %.1f",
                      az, ls, want);
    }
    free(hor);
    free(vis);
    ts_grid_free(&g);
}
END_TEST

/* Infinite V-valley along north-south, walls z = tan(beta) |x - x0| cell:
 * from the bottom the horizon is atan(tan(beta) |sin az|), and with the
 * vertical Horn normal there svf = mean of cos^2(horizon) = cos(beta). */
#define V_BETA 30.0
#define V_W 401
#define V_H 801
#define V_X0 200
typedef struct {
    ts_grid g;
    ts_horizon_opts o;
    size_t n;
    float *hor, *nx, *ny, *nz, *svf, *sky, *open;
} valley;

static valley valley_make(void)
{
    valley v;
    tdem_create(&v.g, V_W, V_H, 10.0, 10.0);
    for (int y = 0; y < V_H; y++)
        for (int x = 0; x < V_W; x++)
            v.g.z[y * v.g.stride + x] = (float)(tan(V_BETA * DEG) * abs(x - V_X0) * 10.0);
    v.o = flat_earth(64);
    v.hor = compute(&v.g, &v.o);
    v.n = (size_t)V_W * V_H;
    v.nx = tdem_floats(v.n), v.ny = tdem_floats(v.n), v.nz = tdem_floats(v.n);
    v.svf = tdem_floats(v.n), v.sky = tdem_floats(v.n), v.open = tdem_floats(v.n);
    ts_error err;
    ck_assert_msg(ts_normals(&v.g, v.nx, v.ny, v.nz, &err) == TS_OK, "%s", err.message);
    const ts_sky_request sq = {&v.g, v.nx, v.ny, v.nz, v.hor, &v.o, TS_SVF_RADIATIVE,
                               v.svf, v.sky, v.open};
    ck_assert_msg(ts_sky_terms(&sq, &err) == TS_OK, "%s", err.message);
    return v;
}

static void valley_free(valley *v)
{
    free(v->hor); free(v->nx); free(v->ny); free(v->nz);
    free(v->svf); free(v->sky); free(v->open);
    ts_grid_free(&v->g);
}

static double valley_horizon(double az)
{
    return atan(tan(V_BETA * DEG) * fabs(sin(az * DEG))) / DEG;
}

START_TEST(test_v_valley_svf)
{
    valley v = valley_make();
    double want = cos(V_BETA * DEG);
    for (int y = V_H / 2 - 5; y <= V_H / 2 + 5; y++) {
        size_t i = (size_t)y * V_W + V_X0;
        if (y == V_H / 2)
            printf("V-valley beta %g: svf %.6f sky %.6f (want cos(beta) = %.6f)\n", V_BETA,
                   v.svf[i], v.sky[i], want);
        ck_assert_msg(fabsf(v.nx[i]) < 1e-6f && fabsf(v.ny[i]) < 1e-6f && v.nz[i] > 0.999999f,
                      "valley bottom normal (%g, %g, %g)", v.nx[i], v.ny[i], v.nz[i]);
        ck_assert_msg(fabs(v.svf[i] - want) <= 1e-3, "svf %g, want %g", v.svf[i], want);
        ck_assert_msg(fabs(v.sky[i] - want) <= 1e-3, "sky %g, want %g", v.sky[i], want);
    }
    valley_free(&v);
}
END_TEST

START_TEST(test_v_valley_horizons)
{
    /* planar walls: every distance ties for the maximum, so an error of the
     * sweep anywhere along the ray shows; the oracle is exact here */
    valley v = valley_make();
    double worst = 0, worst_az = 0, want_open = 0;
    for (int k = 0; k < 64; k++)
        want_open += (90.0 - valley_horizon(ts_horizon_azimuth(&v.o, k))) / 64;
    for (int y = V_H / 2 - 5; y <= V_H / 2 + 5; y++)
        for (int k = 0; k < 64; k++) {
            double az = ts_horizon_azimuth(&v.o, k);
            double err = fabs(v.hor[k * v.n + (size_t)y * V_W + V_X0] - valley_horizon(az));
            if (err > worst)
                worst = err, worst_az = az;
        }
    size_t mid = (size_t)(V_H / 2) * V_W + V_X0;
    printf("V-valley horizons: largest error %.4f deg (az %g; oracle there %.4f, exact "
           "%.4f); openness %.4f (want %.4f)\n", worst, worst_az,
           oracle_horizon(&v.g, V_X0, V_H / 2, worst_az, &v.o), valley_horizon(worst_az),
           v.open[mid], want_open);
    ck_assert_msg(worst <= 0.05, "valley horizon error %.4f deg at az %g", worst, worst_az);
    ck_assert_msg(fabs(v.open[mid] - want_open) <= 0.05, "openness %g, want %g",
                  v.open[mid], want_open);
    valley_free(&v);
}
END_TEST

START_TEST(test_cone_apex)
{
    /* z = 1000 - s r: from the apex every direction looks down the flank,
     * horizon -atan(s) (negative: never clamped at 0) */
    const double s = 0.5, cell = 10.0;
    ts_grid g;
    tdem_create(&g, 201, 201, cell, cell);
    for (int y = 0; y < 201; y++)
        for (int x = 0; x < 201; x++)
            g.z[y * g.stride + x] = (float)(1000.0 - s * hypot(x - 100, y - 100) * cell);
    ts_horizon_opts o = flat_earth(16);
    o.start_azimuth = 7.5;
    float *hor = compute(&g, &o);
    size_t n = 201 * 201, apex = 100 * 201 + 100;
    double want = -atan(s) / DEG, worst = 0, worst_az = 0;
    for (int k = 0; k < 16; k++) {
        double got = hor[k * n + apex];
        printf("cone apex az %6.2f: %.4f (oracle %.4f, analytic %.4f)\n",
               ts_horizon_azimuth(&o, k), got,
               oracle_horizon(&g, 100, 100, ts_horizon_azimuth(&o, k), &o), want);
        if (fabs(got - want) > worst)
            worst = fabs(got - want), worst_az = ts_horizon_azimuth(&o, k);
    }
    /* as in the valley, every distance ties for the maximum */
    ck_assert_msg(worst <= 0.05, "cone apex az %g: error %.4f deg", worst_az, worst);
    /* the sky around a vertical normal is all visible: svf = sky = 1 */
    float *nx = tdem_floats(n), *ny = tdem_floats(n), *nz = tdem_floats(n);
    float *svf = tdem_floats(n), *open = tdem_floats(n);
    ts_error err;
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    const ts_sky_request sq = {&g, nx, ny, nz, hor, &o, TS_SVF_RADIATIVE, svf, NULL, open};
    ck_assert(ts_sky_terms(&sq, &err) == TS_OK);
    printf("cone apex: horizon %.4f (want %.4f), svf %.6f, openness %.4f (want %.4f)\n",
           hor[apex], want, svf[apex], open[apex], 90 - want);
    ck_assert_msg(fabs(svf[apex] - 1.0) <= 1e-4, "apex svf %g", svf[apex]);
    ck_assert_msg(fabs(open[apex] - (90.0 - want)) <= 0.05, "apex openness %g", open[apex]);
    free(hor); free(nx); free(ny); free(nz); free(svf); free(open);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_crater_centre)
{
    /* paraboloid bowl z = D (r/R)^2 up to a 3-cell flat rim at height D,
     * falling outside: from the centre the rim is seen at atan(D / R) */
    const double D = 200.0, R = 100.0, cell = 10.0;
    ts_grid g;
    tdem_create(&g, 241, 241, cell, cell);
    for (int y = 0; y < 241; y++)
        for (int x = 0; x < 241; x++) {
            double r = hypot(x - 120, y - 120), z;
            if (r <= R) z = D * (r / R) * (r / R);
            else if (r <= R + 3) z = D;
            else z = D - 0.4 * (r - R - 3) * cell;
            g.z[y * g.stride + x] = (float)z;
        }
    ts_horizon_opts o = flat_earth(16);
    o.start_azimuth = 3.0;
    float *hor = compute(&g, &o);
    size_t n = 241 * 241, c = 120 * 241 + 120;
    double want = atan(D / (R * cell)) / DEG;
    /* the rim between samples up to sqrt(2) cells apart reads at most that
     * much further away: atan(D/R) - atan(D/(R + sqrt 2)) = 0.16 deg */
    double lo = atan(D / ((R + sqrt(2.0)) * cell)) / DEG - 0.01;
    for (int k = 0; k < 16; k++) {
        double az = ts_horizon_azimuth(&o, k), got = hor[k * n + c];
        double orc = oracle_horizon(&g, 120, 120, az, &o);
        printf("crater az %6.2f: %.4f (oracle %.4f, analytic %.4f)\n", az, got, orc, want);
        ck_assert_msg(got >= lo && got <= want + 0.01,
                      "crater az %g: %g not in [%g, %g]", az, got, lo, want + 0.01);
    }
    free(hor);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_azimuth_0_is_360)
{
    ts_grid g;
    tdem_create(&g, 90, 70, 10.0, 12.0);
    tdem_fractal(&g, 9, 200.0);
    ts_horizon_opts o = flat_earth(1);
    o.curvature = 1;
    size_t n = 90 * 70;
    float *a = tdem_floats(n), *b = tdem_floats(n);
    sweep(&g, 0.0, &o, a);
    sweep(&g, 360.0, &o, b);
    ck_assert_msg(memcmp(a, b, n * sizeof *a) == 0, "horizon: az 0 != az 360");
    ts_error err;
    ck_assert(ts_shm_compute(&g, 0.0, 25.0, 3.0, 1, a, NULL, &err) == TS_OK);
    ck_assert(ts_shm_compute(&g, 360.0, 25.0, 3.0, 1, b, NULL, &err) == TS_OK);
    ck_assert_msg(memcmp(a, b, n * sizeof *a) == 0, "shadow map: az 0 != az 360");
    free(a);
    free(b);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_nodata_hole_wall)
{
    /* flat 0 plane, a nodata block in front of a 50 m wall: looking east,
     * the cells west of the hole see the wall through it, not the hole */
    ts_grid g;
    tdem_create(&g, 120, 100, 10.0, 10.0);
    tdem_fill(&g, 0.0f);
    for (int y = 0; y < 100; y++) {
        g.z[y * g.stride + 100] = 50.0f;
        for (int x = 50; x < 70; x++)
            if (y >= 20 && y < 80)
                g.z[y * g.stride + x] = NAN;
    }
    ts_horizon_opts o = flat_earth(1);
    float *out = tdem_floats(120 * 100);
    sweep(&g, 90.0, &o, out);
    for (int y = 0; y < 100; y++)
        for (int x = 0; x < 120; x++) {
            float v = out[y * 120 + x];
            int hole = isnan(ts_grid_at(&g, x, y));
            ck_assert_msg(hole == !!isnan(v), "cell (%d,%d): %g, hole %d", x, y, v, hole);
            if (x < 50 && y >= 20 && y < 80) {
                double want = atan(50.0 / ((100 - x) * 10.0)) / DEG;
                ck_assert_msg(fabs(v - want) <= 0.01, "behind hole (%d,%d): %g, want %g",
                              x, y, v, want);
            }
        }
    free(out);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_nodata_hole_fractal)
{
    /* holes of several shapes in rough terrain, against the oracle */
    ts_grid g;
    tdem_create(&g, 160, 120, 10.0, 10.0);
    tdem_fractal(&g, 21, 250.0);
    for (int y = 0; y < 120; y++)
        for (int x = 0; x < 160; x++)
            if (hypot(x - 70, y - 60) < 15 || (x > 120 && x < 125) || (y == 30 && x % 3 == 0))
                g.z[y * g.stride + x] = NAN;
    ts_horizon_opts o = flat_earth(1);
    o.curvature = 1;
    float *out = tdem_floats(160 * 120);
    tstat s[N_AZ];
    for (int a = 0; a < N_AZ; a++) {
        sweep(&g, AZ[a], &o, out);
        s[a] = tstat_vs_oracle("fractal with nodata holes", &g, out, AZ[a], &o, 1);
    }
    for (int a = 0; a < N_AZ; a++)
        tstat_check(&s[a], "fractal with nodata holes");
    free(out);
    ts_grid_free(&g);
}
END_TEST

/* Every product on a w x h grid: no error, values in range. */
static void tiny_grid(int w, int h)
{
    ts_grid g;
    tdem_create(&g, w, h, 10.0, 10.0);
    uint64_t seed = 77;
    for (int i = 0; i < w * h; i++)
        g.z[i] = (float)(100.0 * tdem_uniform(&seed));
    ts_horizon_opts o = flat_earth(8);
    size_t n = (size_t)w * h;
    float *hor = compute(&g, &o);
    float *nx = tdem_floats(n), *ny = tdem_floats(n), *nz = tdem_floats(n);
    float *svf = tdem_floats(n), *sky = tdem_floats(n), *open = tdem_floats(n);
    float *vis = tdem_floats(n), *sh = tdem_floats(n), *dir = tdem_floats(n);
    ts_error err;
    ck_assert_msg(ts_normals(&g, nx, ny, nz, &err) == TS_OK, "%dx%d: %s", w, h, err.message);
    const ts_sky_request sq = {&g, nx, ny, nz, hor, &o, TS_SVF_RADIATIVE, svf, sky, open};
    ck_assert_msg(ts_sky_terms(&sq, &err) == TS_OK, "%dx%d: %s", w, h, err.message);
    ck_assert_msg(ts_shm_compute(&g, 123.0, 20.0, 2.0, 0, vis, sh, &err) == TS_OK,
                  "%dx%d: %s", w, h, err.message);
    const ts_direct_request dq = {&g, nx, ny, nz, hor, &o, 200.0, 35.0, dir, TS_SUN_RADIUS_DEG};
    ck_assert_msg(ts_shade_direct(&dq, &err) == TS_OK, "%dx%d: %s", w, h, err.message);
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 8; k++) {
            float v = hor[k * n + i];
            ck_assert_msg(v >= -90.0f && v <= 90.0f, "%dx%d horizon %g", w, h, v);
            if (w == 1 && h == 1)
                ck_assert_msg(v == -90.0f, "1x1 horizon %g, want -90", v);
        }
        ck_assert_msg(isfinite(nx[i]) && isfinite(ny[i]) && nz[i] > 0, "%dx%d normal", w, h);
        ck_assert_msg(svf[i] >= 0 && svf[i] <= 1.0001f, "%dx%d svf %g", w, h, svf[i]);
        ck_assert_msg(sky[i] >= 0 && sky[i] <= 1.0001f, "%dx%d sky %g", w, h, sky[i]);
        ck_assert_msg(open[i] >= 0 && open[i] <= 180, "%dx%d openness %g", w, h, open[i]);
        ck_assert_msg(vis[i] >= 0 && vis[i] <= 1, "%dx%d visibility %g", w, h, vis[i]);
        ck_assert_msg(dir[i] >= 0 && dir[i] <= 1, "%dx%d direct %g", w, h, dir[i]);
    }
    if (w == 1 && h == 1)
        ck_assert_msg(fabsf(svf[0] - 1.0f) < 1e-5f && fabsf(open[0] - 180.0f) < 1e-4f,
                      "1x1: svf %g openness %g", svf[0], open[0]);
    free(hor); free(nx); free(ny); free(nz); free(svf); free(sky); free(open);
    free(vis); free(sh); free(dir);
    ts_grid_free(&g);
}

START_TEST(test_tiny_grids)
{
    tiny_grid(1, 1);
    tiny_grid(1, 9);
    tiny_grid(9, 1);
    tiny_grid(2, 2);
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* lines reach the log before a failure exits */
    Suite *s = suite_create("analytic");
    TCase *tc = tcase_create("closed_form");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_flat_plane_zero);
    tcase_add_test(tc, test_flat_plane_raised);
    tcase_add_test(tc, test_pillar_shadow_length);
    tcase_add_test(tc, test_v_valley_svf);
    tcase_add_test(tc, test_v_valley_horizons);
    tcase_add_test(tc, test_cone_apex);
    tcase_add_test(tc, test_crater_centre);
    tcase_add_test(tc, test_azimuth_0_is_360);
    tcase_add_test(tc, test_nodata_hole_wall);
    tcase_add_test(tc, test_nodata_hole_fractal);
    tcase_add_test(tc, test_tiny_grids);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
