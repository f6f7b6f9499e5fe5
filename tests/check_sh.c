/* Order-4 SH light and visibility (core/sh_*.c): projection and
 * reconstruction of analytic functions, a cap against quadrature, rotation
 * about z against the projection of the rotated function, the triple
 * product against brute-force quadrature, the wedge tables against a
 * direct sum over the sphere, the visibility of flat ground, the key light,
 * and bad input. The visibility and the light of grids are in
 * check_sh_swath_light.c. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sh_internal.h"
#include "terrashade_sh.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

#define N TS_SH_COEFFS
static const double PI = 3.14159265358979323846;

typedef double (*sphere_fn)(const double d[3], const void *user);

/* An environment whose radiance is f (>= 0) on a fine equal-angle grid. */
static void env_of(ts_env *env, sphere_fn f, const void *user)
{
    ts_error err;
    ck_assert_msg(ts_env_sphere_grid(env, 2048, 1024, &err) == TS_OK, "%s", err.message);
    for (size_t t = 0; t < env->count; t++) {
        double d[3] = {env->texels[t].dir[0], env->texels[t].dir[1], env->texels[t].dir[2]};
        float v = (float)f(d, user);
        env->texels[t].rgb[0] = env->texels[t].rgb[1] = env->texels[t].rgb[2] = v;
    }
}

static double reconstruct(const double c[N], const double d[3])
{
    double y[N], s = 0;
    ts_sh_eval(d, y);
    for (int i = 0; i < N; i++)
        s += c[i] * y[i];
    return s;
}

/* A deterministic spread of directions (Fibonacci sphere). */
static void fib_dir(int k, int n, double d[3])
{
    double z = 1 - (2.0 * k + 1) / n, r = sqrt(1 - z * z), phi = k * PI * (3 - sqrt(5.0));
    d[0] = r * cos(phi), d[1] = r * sin(phi), d[2] = z;
}

/* Functions even in z (the projection mirrors the upper hemisphere). */
static double f_const(const double d[3], const void *u)
{
    (void)d, (void)u;
    return 2.5;
}

static double f_lobe(const double d[3], const void *u) /* (1 + a.d) / 2, a horizontal */
{
    (void)u;
    return (1 + 0.6 * d[0] - 0.8 * d[1]) / 2;
}

static double f_single(const double d[3], const void *u) /* 1 + y_i */
{
    double y[N];
    ts_sh_eval(d, y);
    return 1 + y[*(const int *)u];
}

/* Projects f, reconstructs it at 500 directions: max |error|. */
static double roundtrip(sphere_fn f, const void *user, double c[3][N])
{
    ts_env env;
    ts_error err;
    env_of(&env, f, user);
    ck_assert_msg(ts_sh_project_env(&env, c, &err) == TS_OK, "%s", err.message);
    ts_env_free(&env);
    double worst = 0;
    for (int k = 0; k < 500; k++) {
        double d[3];
        fib_dir(k, 500, d);
        worst = fmax(worst, fabs(reconstruct(c[0], d) - f(d, user)));
    }
    return worst;
}

START_TEST(projection_roundtrip)
{
    double c[3][N];
    double e = roundtrip(f_const, NULL, c);
    printf("constant 2.5: max reconstruction error %.2e, c0 %.8f (want %.8f)\n", e, c[0][0],
           2.5 * sqrt(4 * PI));
    ck_assert(e < 1e-5);
    ck_assert(fabs(c[0][0] - 2.5 * sqrt(4 * PI)) < 1e-5);
    e = roundtrip(f_lobe, NULL, c);
    printf("cosine lobe (1 + a.d)/2: max error %.2e\n", e);
    ck_assert(e < 1e-5);
    /* the basis functions even in z */
    static const int singles[] = {3, 4, 6, 8, 9, 11, 13, 15};
    for (int s = 0; s < 8; s++) {
        e = roundtrip(f_single, &singles[s], c);
        double other = 0;
        for (int i = 1; i < N; i++)
            other = fmax(other, fabs(c[0][i] - (i == singles[s])));
        printf("1 + y_%d: max error %.2e, coefficients off by at most %.2e\n", singles[s], e,
               other);
        ck_assert(e < 1e-5 && other < 1e-5);
    }
}
END_TEST

START_TEST(cap_unit_power)
{
    double d[3] = {0.3, -0.4, sqrt(1 - 0.25)}, c[N];
    for (double r = 0.25; r < 40; r *= 2) {
        ts_sh_cap(d, r, c);
        ck_assert(fabs(c[0] * sqrt(4 * PI) - 1) < 1e-12); /* integral = 1 */
    }
    /* a tiny cap is the delta function: y(d) */
    double y[N];
    ts_sh_eval(d, y);
    ts_sh_cap(d, 1e-4, c);
    for (int i = 0; i < N; i++)
        ck_assert(fabs(c[i] - y[i]) < 1e-8);
}
END_TEST

/* A uniform 30-degree cap of unit power around a tilted direction d,
 * projected by quadrature in the cap's own frame (midpoint in cos of the
 * angle from d, 64 azimuths: exact for band 3), against ts_sh_cap: every
 * band's coefficients, band 3's zonal mean (5c^2 - 1)(1 + c)/8 among them. */
START_TEST(cap_projected)
{
    double d[3] = {0.3, -0.4, sqrt(1 - 0.25)}, c[N], q[N] = {0};
    const double r = 30 * PI / 180, cr = cos(r), power = 1 / (2 * PI * (1 - cr));
    /* e1, e2: a frame around d */
    double e1[3] = {d[2], 0, -d[0]}, l1 = hypot(d[0], d[2]);
    e1[0] /= l1, e1[2] /= l1;
    double e2[3] = {d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2],
                    d[0] * e1[1] - d[1] * e1[0]};
    const int NU = 4000, NP = 64;
    const double du = (1 - cr) / NU, dp = 2 * PI / NP;
    for (int a = 0; a < NU; a++)
        for (int b = 0; b < NP; b++) {
            double u = cr + (a + 0.5) * du, v = sqrt(1 - u * u), p = (b + 0.5) * dp, w[3], y[N];
            for (int k = 0; k < 3; k++)
                w[k] = u * d[k] + v * (cos(p) * e1[k] + sin(p) * e2[k]);
            ts_sh_eval(w, y);
            for (int i = 0; i < N; i++)
                q[i] += power * y[i] * du * dp;
        }
    ts_sh_cap(d, 30, c);
    double worst = 0;
    for (int i = 0; i < N; i++) {
        ck_assert_msg(fabs(c[i] - q[i]) < 1e-7, "coefficient %d: %.9f, quadrature %.9f", i,
                      c[i], q[i]);
        worst = fmax(worst, fabs(c[i] - q[i]));
    }
    printf("30-degree cap: max |coefficient - quadrature| %.2e\n", worst);
}
END_TEST

/* A function with every m up to 3, even in z, and its copy turned by
 * `angle` about z. */
typedef struct {
    double angle;
} turn;

static double f_asym(const double d[3], const void *u)
{
    double a = u ? -((const turn *)u)->angle : 0, ca = cos(a), sa = sin(a);
    double x = ca * d[0] - sa * d[1], y = sa * d[0] + ca * d[1], z = d[2];
    return 2 + 0.3 * x + 0.5 * y + 0.4 * x * y + 0.2 * (x * x - y * y) + 0.3 * z * z +
           0.25 * x * (x * x - 3 * y * y) + 0.15 * y * (3 * x * x - y * y);
}

START_TEST(rotation_about_z)
{
    double c[3][N], cr[3][N], rot[N];
    roundtrip(f_asym, NULL, c);
    for (double angle = -2.5; angle < 3.2; angle += 1.1) {
        turn t = {angle};
        roundtrip(f_asym, &t, cr);
        ts_sh_rotate_z(c[0], angle, rot);
        double worst = 0;
        for (int i = 0; i < N; i++)
            worst = fmax(worst, fabs(rot[i] - cr[0][i]));
        printf("rotation by %+.2f rad: max coefficient difference %.2e\n", angle, worst);
        ck_assert(worst < 1e-5);
    }
}
END_TEST

/* Random coefficients. */
static void random_sh(unsigned *seed, double c[N])
{
    for (int i = 0; i < N; i++) {
        *seed = *seed * 1103515245u + 12345u;
        c[i] = ((*seed >> 8) & 0xffff) / 65535.0 - 0.5;
    }
}

START_TEST(triple_product_brute_force)
{
    unsigned seed = 7;
    double l[N], v[N], h[N], m[N][N];
    for (int trial = 0; trial < 2; trial++) {
        random_sh(&seed, l), random_sh(&seed, v), random_sh(&seed, h);
        ts_sh_product_matrix(l, m);
        double fast = ts_sh_triple(m, v, h), brute = 0;
        /* midpoint rule on a fine equal-area grid in z */
        const int NZ = 1200, NP = 2400;
        for (int a = 0; a < NZ; a++)
            for (int b = 0; b < NP; b++) {
                double z = -1 + (a + 0.5) * 2 / NZ, r = sqrt(1 - z * z);
                double phi = (b + 0.5) * 2 * PI / NP, d[3] = {r * cos(phi), r * sin(phi), z};
                brute += reconstruct(l, d) * reconstruct(v, d) * reconstruct(h, d);
            }
        brute *= 4 * PI / ((double)NZ * NP);
        printf("triple product %+.8f, brute force %+.8f\n", fast, brute);
        ck_assert(fabs(fast - brute) < 1e-5);
    }
    /* the clamped cosine dotted with a light is the light's band-limited
     * irradiance: a constant radiance 1 gives pi */
    double one[N] = {sqrt(4 * PI)}, n[3] = {0.6, 0, 0.8}, hc[N], s = 0;
    ts_sh_clamped_cosine(n, hc);
    for (int i = 0; i < N; i++)
        s += one[i] * hc[i];
    ck_assert(fabs(s - PI) < 1e-5);
}
END_TEST

/* The wedge of ts_sh_wedge_project, summed texel by texel. */
static void wedge_brute(double extent, double wa, double wb, double out[N])
{
    ts_env env;
    ts_error err;
    memset(out, 0, sizeof(double) * N);
    ck_assert(ts_env_sphere_grid(&env, 4096, 2048, &err) == TS_OK);
    for (size_t t = 0; t < env.count; t++) {
        double d[3] = {env.texels[t].dir[0], env.texels[t].dir[1], env.texels[t].dir[2]};
        double phi = atan2(d[1], d[0]) * 180 / PI, el = asin(d[2]) * 180 / PI;
        if (phi < 0)
            phi += 360;
        if (phi > extent || el <= wa + (wb - wa) * phi / extent)
            continue;
        double y[N];
        ts_sh_eval(d, y);
        for (int i = 0; i < N; i++)
            out[i] += y[i] * env.texels[t].solid_angle;
    }
    ts_env_free(&env);
}

START_TEST(wedges_brute_force)
{
    static const double cases[][3] = {{22.5, 10, 40}, {11.25, 0, 0}, {90, 70, 5}, {3, 45, 45}};
    for (int c = 0; c < 4; c++) {
        double q[N], b[N], worst = 0;
        ts_sh_wedge_project(cases[c][0], cases[c][1], cases[c][2], q);
        wedge_brute(cases[c][0], cases[c][1], cases[c][2], b);
        for (int i = 0; i < N; i++)
            worst = fmax(worst, fabs(q[i] - b[i]));
        printf("wedge %g deg, horizons %g -> %g: max difference %.2e (grid of 0.09 deg)\n",
               cases[c][0], cases[c][1], cases[c][2], worst);
        ck_assert(worst < 2e-3 * cases[c][0] / 22.5 + 1e-4);
    }
    /* a complete swath of flat horizons at 0 is the upper hemisphere:
     * coefficients of y_0 = sqrt(pi), y_2 (z) = sqrt(3 pi) / 2, y_6 = 0 */
    ts_sh_swath s;
    double v[N];
    ts_sh_swath_complete(&s, 16, 0);
    ts_sh_swath_visibility_flat(&s, 0, v);
    ck_assert(fabs(v[0] - sqrt(PI)) < 1e-9 && fabs(v[2] - sqrt(3 * PI) / 2) < 1e-9);
    ck_assert(fabs(v[6]) < 1e-9 && fabs(v[1]) < 1e-9 && fabs(v[3]) < 1e-9);
}
END_TEST

/* Open flat ground under a constant sky: E/pi = 1 exactly in the
 * continuous case; state what order 4 gives. */
START_TEST(flat_ground_constant_sky)
{
    double l[N] = {sqrt(4 * PI)}, m[N][N], v[N], h[N], up[3] = {0, 0, 1};
    ts_sh_swath s;
    ts_sh_swath_complete(&s, 32, 0);
    ts_sh_swath_visibility_flat(&s, 0, v);
    ts_sh_product_matrix(l, m);
    ts_sh_clamped_cosine(up, h);
    double e = ts_sh_triple(m, v, h) / PI;
    printf("open flat ground, constant sky 1: SH gives %.6f (truncation %.2f %%)\n", e,
           100 * (e - 1));
    ck_assert(fabs(e - 1) < 0.05);
}
END_TEST

START_TEST(key_light_reference)
{
    /* the swath of a small disk is narrow and centred on its azimuth */
    ts_sh_swath s;
    ts_sh_swath_key(&s, 3, 315, 45, 0.2666);
    ck_assert(!s.complete && fabs(s.span - 2 * 0.2666 / cos(PI / 4)) < 1e-3);
    ck_assert(fabs(ts_sh_swath_azimuth(&s, 1) - 315) < 1e-9);
    ts_sh_swath_key(&s, 3, 10, 80, 15); /* holds the zenith */
    ck_assert(s.complete);
    ck_assert(ts_sh_disk_above(10, 1) == 1 && ts_sh_disk_above(-10, 1) == 0);
    ck_assert(fabs(ts_sh_disk_above(0, 1) - 0.5) < 1e-12);
}
END_TEST

START_TEST(bad_input)
{
    ts_error err;
    ts_sh_wedges w;
    ts_sh_swath s = {0};
    EXPECT_ARG(ts_sh_wedges_build(&s, 0, &w, &err), &err);
    EXPECT_ARG(ts_sh_project_env(NULL, NULL, &err), &err);
    ts_env empty = {0};
    double c[3][N];
    EXPECT_ARG(ts_sh_project_env(&empty, c, &err), &err);
    /* a radiance near FLT_MAX lit every cell as inf through the float light */
    ts_env_texel huge = {.dir = {0, 0, 1}, .rgb = {1e38f, 1e38f, 1e38f}, .solid_angle = 1};
    ts_env big = {1, &huge};
    EXPECT_ARG(ts_sh_project_env(&big, c, &err), &err);
    ck_assert_msg(strstr(err.message, "ENV_METHOD=table") != NULL, "%s", err.message);
    ts_grid g;
    tdem_create(&g, 4, 4, 1, 1);
    ts_sh_visibility v;
    EXPECT_ARG(ts_sh_visibility_init(&v, &g, NULL, &err), &err);
    EXPECT_ARG(ts_sh_visible_share(&g, NULL, NULL, 1, 0, NULL, &err), &err);
    ts_grid_free(&g);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("sh");
    TCase *tc = tcase_create("sh");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, projection_roundtrip);
    tcase_add_test(tc, cap_unit_power);
    tcase_add_test(tc, cap_projected);
    tcase_add_test(tc, rotation_about_z);
    tcase_add_test(tc, triple_product_brute_force);
    tcase_add_test(tc, wedges_brute_force);
    tcase_add_test(tc, flat_ground_constant_sky);
    tcase_add_test(tc, key_light_reference);
    tcase_add_test(tc, bad_input);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IONBF, 0); /* the numbers even of a failing test */
    return test_run_suite_mode(suite(), CK_VERBOSE);
}
