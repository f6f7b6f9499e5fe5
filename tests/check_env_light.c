/* Environment light through Timonen's L_p table: a constant environment
 * gives the uniform-sky terms, a small bright patch shades like the sun,
 * and a brute-force sum over every texel above each cell's horizon agrees;
 * plus exact flat-plane values and bad input. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade_env.h"
#include "test_dem.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

static const double PI = 3.14159265358979323846;

/* A DEM with its normals and horizons at `dirs` azimuths from 0 (no
 * curvature, so that the brute force sees the same terrain). */
typedef struct {
    ts_grid g;
    ts_horizon_opts o;
    size_t n;
    float *nx, *ny, *nz, *hor;
} scene;

static void scene_init(scene *s, int dirs)
{
    ts_error err;
    s->n = (size_t)s->g.width * s->g.height;
    ts_horizon_opts_default(&s->o);
    s->o.curvature = 0;
    s->o.directions = dirs;
    s->nx = tdem_floats(s->n), s->ny = tdem_floats(s->n), s->nz = tdem_floats(s->n);
    s->hor = tdem_floats(s->n * dirs);
    ck_assert_msg(ts_normals(&s->g, s->nx, s->ny, s->nz, &err) == TS_OK, "%s", err.message);
    ck_assert_msg(ts_horizon_compute(&s->g, &s->o, s->hor, &err) == TS_OK, "%s", err.message);
}

static void scene_free(scene *s)
{
    free(s->nx), free(s->ny), free(s->nz), free(s->hor);
    ts_grid_free(&s->g);
}

/* Light of env on the scene with `dirs` of its directions (every
 * (s->o.directions / dirs)-th plane) and the given table steps. */
static void env_light(const scene *s, const ts_env *env, int dirs, int nn, int nh, int ground,
                      float *r, float *g, float *b)
{
    ts_env_table_opts to;
    ts_env_table_opts_default(&to);
    to.directions = dirs;
    to.normal_steps = nn;
    to.horizon_steps = nh;
    to.ground = ground;
    ts_env_table t;
    ts_error err;
    ck_assert_msg(ts_env_table_build(env, &to, &t, &err) == TS_OK, "%s", err.message);
    int stride = s->o.directions / dirs;
    ck_assert(stride * dirs == s->o.directions);
    memset(r, 0, s->n * sizeof *r), memset(g, 0, s->n * sizeof *g), memset(b, 0, s->n * sizeof *b);
    ts_env_light_request req = {&s->g, &t, 0, s->nx, s->ny, s->nz, NULL, r, g, b, 0};
    for (req.k = 0; req.k < dirs; req.k++) {
        req.plane = s->hor + s->n * (size_t)(req.k * stride);
        ck_assert_msg(ts_env_light_accumulate(&req, &err) == TS_OK, "%s", err.message);
    }
    ck_assert(ts_env_light_finish(&s->g, r, g, b, &err) == TS_OK);
    ts_env_table_free(&t);
}

/* A full sphere of constant radiance (r, g, b). */
static void constant_env(ts_env *env, int w, int h, float r, float g, float b)
{
    ts_error err;
    ck_assert(ts_env_sphere_grid(env, w, h, &err) == TS_OK);
    for (size_t i = 0; i < env->count; i++) {
        env->texels[i].rgb[0] = r, env->texels[i].rgb[1] = g, env->texels[i].rgb[2] = b;
    }
}

/* max |a - b| over cells valid in both; NaN-ness must agree. */
static double max_diff(const float *a, const float *b, size_t n, double *mean)
{
    double mx = 0, sum = 0;
    long cnt = 0;
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg(isnan(a[i]) == isnan(b[i]), "cell %zu: %g vs %g", i, a[i], b[i]);
        if (isnan(a[i]))
            continue;
        double d = fabs((double)a[i] - b[i]);
        mx = d > mx ? d : mx;
        sum += d, cnt++;
    }
    if (mean)
        *mean = cnt ? sum / cnt : 0;
    return mx;
}

static void load_scene(scene *s, int which, int dirs)
{
    if (which == 0)
        tdem_load(&s->g, "jacksboro");
    else if (which == 1)
        tdem_load(&s->g, "lux_elev");
    else {
        tdem_create(&s->g, 256, 256, 20, 20);
        tdem_fractal(&s->g, 5, 600);
    }
    scene_init(s, dirs);
}

static const char *SCENE_NAMES[] = {"jacksboro", "lux_elev", "fractal 256^2"};

/* Radiance 1 everywhere: with the ground ignored it is the uniform sky of
 * the `sky` product (Timonen eq. 5, horizon raised to 0); with the ground
 * counted, the sky-view factor (the horizon as it is). */
START_TEST(test_constant_env_is_sky_term)
{
    int which = _i;
    scene s;
    load_scene(&s, which, 32);
    float *sky = tdem_floats(s.n), *svf = tdem_floats(s.n);
    float *r = tdem_floats(s.n), *g = tdem_floats(s.n), *b = tdem_floats(s.n);
    ts_error err;
    const ts_sky_request sq = {&s.g, s.nx, s.ny, s.nz, s.hor, &s.o, TS_SVF_RADIATIVE, svf, sky,
                               NULL};
    ck_assert(ts_sky_terms(&sq, &err) == TS_OK);
    /* 360 rows put texel edges on the table's 1-degree horizon nodes; 512
     * rows do not (a row cut by a node counts wholly on one side). */
    const int rows[2] = {360, 512};
    for (int e = 0; e < 2; e++) {
        ts_env env;
        constant_env(&env, 1024, rows[e], 1, 1, 1);
        for (int ground = 0; ground <= 1; ground++) {
            env_light(&s, &env, 32, TS_ENV_DEFAULT_NORMAL_STEPS, TS_ENV_DEFAULT_HORIZON_STEPS,
                      ground, r, g, b);
            double mean, mx = max_diff(r, ground ? svf : sky, s.n, &mean);
            printf("constant env 1024 x %d, %s, 32 directions, ground %d: max |envlight - %s| "
                   "= %.2e, mean %.2e\n", rows[e], SCENE_NAMES[which], ground,
                   ground ? "svf" : "sky", mx, mean);
            ck_assert_msg(mx <= 1e-3, "%s ground %d: max difference %g", SCENE_NAMES[which],
                          ground, mx);
            ck_assert(max_diff(g, r, s.n, NULL) == 0 && max_diff(b, r, s.n, NULL) == 0);
        }
        ts_env_free(&env);
    }
    free(sky), free(svf), free(r), free(g), free(b);
    scene_free(&s);
}
END_TEST

/* Pearson correlation over cells valid in both. */
static double correlation(const float *a, const float *b, size_t n)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    long m = 0;
    for (size_t i = 0; i < n; i++) {
        if (isnan(a[i]) || isnan(b[i]))
            continue;
        sa += a[i], sb += b[i], saa += (double)a[i] * a[i], sbb += (double)b[i] * b[i];
        sab += (double)a[i] * b[i], m++;
    }
    double cov = sab / m - sa / m * sb / m;
    return cov / sqrt((saa / m - sa / m * sa / m) * (sbb / m - sb / m * sb / m));
}

/* A black environment with one small bright patch (radius 0.4 deg) at
 * azimuth az, elevation el shades like the sun there (ts_shade_direct):
 * this pins the orientation of the whole chain. */
static double patch_vs_sun(const scene *s, double az, double el)
{
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sphere_grid(&env, 4096, 2048, &err) == TS_OK);
    double c[3] = {cos(el * PI / 180) * sin(az * PI / 180), cos(el * PI / 180) * cos(az * PI / 180),
                   sin(el * PI / 180)};
    int lit = 0;
    for (size_t i = 0; i < env.count; i++) {
        const float *d = env.texels[i].dir;
        if (d[0] * c[0] + d[1] * c[1] + d[2] * c[2] > cos(0.4 * PI / 180)) {
            env.texels[i].rgb[0] = env.texels[i].rgb[1] = env.texels[i].rgb[2] = 1000;
            lit++;
        }
    }
    ck_assert(lit > 10);
    float *r = tdem_floats(s->n), *g = tdem_floats(s->n), *b = tdem_floats(s->n);
    float *sun = tdem_floats(s->n);
    env_light(s, &env, s->o.directions, TS_ENV_DEFAULT_NORMAL_STEPS,
              TS_ENV_DEFAULT_HORIZON_STEPS, 0, r, g, b);
    const ts_direct_request dq = {&s->g, s->nx, s->ny, s->nz, s->hor, &s->o, az, el, sun,
                                  TS_SUN_RADIUS_DEG};
    ck_assert(ts_shade_direct(&dq, &err) == TS_OK);
    long shadowed = 0;
    for (size_t i = 0; i < s->n; i++)
        shadowed += sun[i] == 0;
    double corr = correlation(r, sun, s->n);
    printf("bright patch at azimuth %g, elevation %g, 64 directions: correlation with the "
           "direct sun %.5f (%ld shadowed cells of %zu)\n", az, el, corr, shadowed, s->n);
    ck_assert(shadowed > 0);
    free(r), free(g), free(b), free(sun);
    ts_env_free(&env);
    return corr;
}

START_TEST(test_bright_patch_is_the_sun)
{
    scene s;
    load_scene(&s, 0, 64);
    /* 135 deg is the centre of sector 24 of 64; 140 is off-centre. */
    ck_assert(patch_vs_sun(&s, 135, 12) >= 0.99);
    ck_assert(patch_vs_sun(&s, 140, 12) >= 0.99);
    ck_assert(patch_vs_sun(&s, 300, 25) >= 0.99);
    scene_free(&s);
}
END_TEST

/* Flat open ground: E/pi = L per colour, up to the quadrature of the
 * texels themselves (sum of omega cos Z / pi over the upper texels). */
START_TEST(test_flat_plane)
{
    scene s;
    tdem_create(&s.g, 24, 20, 10, 10);
    tdem_fill(&s.g, 100);
    scene_init(&s, 16);
    float *r = tdem_floats(s.n), *g = tdem_floats(s.n), *b = tdem_floats(s.n);
    ts_env env;
    constant_env(&env, 512, 256, 1.0f, 2.0f, 0.5f);
    double q = 0;
    for (size_t t = 0; t < env.count; t++)
        if (env.texels[t].dir[2] > 0)
            q += env.texels[t].solid_angle * env.texels[t].dir[2] / PI;
    ck_assert(fabs(q - 1) < 1e-4);
    for (int ground = 0; ground <= 1; ground++) {
        env_light(&s, &env, 16, 9, 91, ground, r, g, b);
        for (size_t i = 0; i < s.n; i++)
            ck_assert_msg(fabs(r[i] - q) < 2e-6 && fabs(g[i] - 2 * q) < 4e-6 &&
                          fabs(b[i] - 0.5 * q) < 1e-6, "cell %zu: %.7f %.7f %.7f, texels %.7f",
                          i, r[i], g[i], b[i], q);
    }
    ts_env_free(&env);
    ts_error err;
    for (int kind = TS_SKY_UNIFORM; kind <= TS_SKY_CLEAR; kind++) {
        ck_assert(ts_env_sky(&env, kind, 0, 200, 30, 0, 0, &err) == TS_OK);
        env_light(&s, &env, 16, 17, 181, 0, r, g, b);
        for (size_t i = 0; i < s.n; i++)
            ck_assert_msg(fabs(r[i] - 1) < 2e-6, "sky %d cell %zu: %.7f", kind, i, r[i]);
        ts_env_free(&env);
    }
    free(r), free(g), free(b);
    scene_free(&s);
}
END_TEST

/* The brute-force reference: for every cell, every texel above the cell's
 * horizon at the texel's own azimuth (linear between the 256 swept
 * azimuths) and in front of the surface, L omega (N . w) / pi. */
static void brute_force(const scene *s, const ts_env *env, float *out[3])
{
    const int D = s->o.directions;
    size_t m = 0;
    int *k0 = malloc(env->count * sizeof *k0);
    float *w = tdem_floats(env->count), *elev = tdem_floats(env->count);
    ck_assert(k0 != NULL);
    for (size_t t = 0; t < env->count; t++) {
        const ts_env_texel *x = &env->texels[t];
        if (x->dir[2] <= 0 || x->rgb[0] + x->rgb[1] + x->rgb[2] == 0)
            continue;
        double az = atan2(x->dir[0], x->dir[1]) * 180 / PI;
        double u = (az < 0 ? az + 360 : az) / (360.0 / D);
        k0[t] = (int)floor(u);
        w[t] = (float)(u - k0[t]);
        k0[t] %= D;
        elev[t] = (float)(asin(x->dir[2]) * 180 / PI);
        m++;
    }
    ck_assert(m > 0);
    for (size_t i = 0; i < s->n; i++) {
        double acc[3] = {0, 0, 0};
        for (size_t t = 0; t < env->count; t++) {
            const ts_env_texel *x = &env->texels[t];
            if (x->dir[2] <= 0 || x->rgb[0] + x->rgb[1] + x->rgb[2] == 0)
                continue;
            double h = (1 - w[t]) * s->hor[s->n * k0[t] + i] +
                       w[t] * s->hor[s->n * ((k0[t] + 1) % D) + i];
            double cosi = s->nx[i] * x->dir[0] + s->ny[i] * x->dir[1] + s->nz[i] * x->dir[2];
            if (elev[t] <= h || cosi <= 0)
                continue;
            for (int c = 0; c < 3; c++)
                acc[c] += x->rgb[c] * x->solid_angle * cosi / PI;
        }
        for (int c = 0; c < 3; c++)
            out[c][i] = (float)acc[c];
    }
    free(k0), free(w), free(elev);
}

/* Mean and max |a - ref| over the three colours. */
static void compare_rgb(const scene *s, float *a[3], float *ref[3], double *mean, double *mx)
{
    double sum = 0, worst = 0;
    for (int c = 0; c < 3; c++) {
        double m, x = max_diff(a[c], ref[c], s->n, &m);
        sum += m / 3;
        worst = x > worst ? x : worst;
    }
    *mean = sum, *mx = worst;
}

START_TEST(test_brute_force_reference)
{
    scene s;
    tdem_create(&s.g, 40, 40, 30, 30);
    tdem_fractal(&s.g, 11, 500);
    scene_init(&s, 256);
    /* A CIE clear sky, tinted by direction so that the colours differ. */
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sky(&env, TS_SKY_CLEAR, 0, 200, 25, 512, 256, &err) == TS_OK);
    for (size_t t = 0; t < env.count; t++) {
        ts_env_texel *x = &env.texels[t];
        x->rgb[0] *= 1 + 0.5f * fmaxf(x->dir[0], 0);
        x->rgb[2] *= 1.3f + 0.3f * x->dir[1];
    }
    float *ref[3], *got[3];
    for (int c = 0; c < 3; c++)
        ref[c] = tdem_floats(s.n), got[c] = tdem_floats(s.n);
    brute_force(&s, &env, ref);
    double mean, mx, mean_at[5], mean64 = 0, max64 = 0;
    const int dirs[5] = {16, 32, 64, 128, 256};
    for (int d = 0; d < 5; d++) {
        env_light(&s, &env, dirs[d], TS_ENV_DEFAULT_NORMAL_STEPS, TS_ENV_DEFAULT_HORIZON_STEPS,
                  0, got[0], got[1], got[2]);
        compare_rgb(&s, got, ref, &mean, &mx);
        printf("brute force, 40^2 fractal, clear sky: %3d directions, table %d x %d: mean "
               "|error| %.5f, max %.5f\n", dirs[d], TS_ENV_DEFAULT_NORMAL_STEPS,
               TS_ENV_DEFAULT_HORIZON_STEPS, mean, mx);
        mean_at[d] = mean;
        if (dirs[d] == 64)
            mean64 = mean, max64 = mx;
    }
    const int nn[6] = {0, 5, 9, 17, 33, 65}, nh[6] = {45, 91, 181, 361, 721, 1441};
    for (int j = 0; j < 6; j++) {
        env_light(&s, &env, 64, nn[j], TS_ENV_DEFAULT_HORIZON_STEPS, 0, got[0], got[1], got[2]);
        compare_rgb(&s, got, ref, &mean, &mx);
        printf("brute force: 64 directions, table %2d x %d: mean |error| %.5f, max %.5f\n",
               nn[j], TS_ENV_DEFAULT_HORIZON_STEPS, mean, mx);
    }
    for (int j = 0; j < 6; j++) {
        env_light(&s, &env, 64, TS_ENV_DEFAULT_NORMAL_STEPS, nh[j], 0, got[0], got[1], got[2]);
        compare_rgb(&s, got, ref, &mean, &mx);
        printf("brute force: 64 directions, table %d x %4d: mean |error| %.5f, max %.5f\n",
               TS_ENV_DEFAULT_NORMAL_STEPS, nh[j], mean, mx);
    }
    /* The light of an open flat plane is 1 here, so these are fractions of it;
     * Timonen's bilinear normal axis at 65 steps must do about as well. */
    ck_assert_msg(mean64 <= 0.0015 && max64 <= 0.03, "64 directions: mean %g max %g", mean64,
                  max64);
    env_light(&s, &env, 64, 65, TS_ENV_DEFAULT_HORIZON_STEPS, 0, got[0], got[1], got[2]);
    compare_rgb(&s, got, ref, &mean, &mx);
    ck_assert_msg(mean <= 0.0015 && mx <= 0.03, "65 normal steps: mean %g max %g", mean, mx);
    ck_assert_msg(mean_at[4] < mean_at[0], "256 directions (%g) no better than 16 (%g)",
                  mean_at[4], mean_at[0]);
    for (int c = 0; c < 3; c++)
        free(ref[c]), free(got[c]);
    ts_env_free(&env);
    scene_free(&s);
}
END_TEST

START_TEST(test_nodata_and_streaming)
{
    scene s;
    tdem_create(&s.g, 30, 20, 10, 10);
    tdem_fractal(&s.g, 3, 80);
    s.g.z[5 * s.g.stride + 7] = NAN;
    scene_init(&s, 8);
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sky(&env, TS_SKY_OVERCAST, 0, 0, 0, 256, 128, &err) == TS_OK);
    ts_env_table_opts to;
    ts_env_table_opts_default(&to);
    to.directions = 8;
    ts_env_table t;
    ck_assert(ts_env_table_build(&env, &to, &t, &err) == TS_OK);
    float *r = tdem_floats(s.n), *g = tdem_floats(s.n), *b = tdem_floats(s.n);
    float *r2 = tdem_floats(s.n), *g2 = tdem_floats(s.n), *b2 = tdem_floats(s.n);
    ck_assert_msg(ts_env_light(&s.g, &t, s.nx, s.ny, s.nz, s.hor, &s.o, r, g, b, &err) == TS_OK,
                  "%s", err.message);
    ck_assert(isnan(r[5 * 30 + 7]) && isnan(g[5 * 30 + 7]) && isnan(b[5 * 30 + 7]));
    for (size_t i = 0; i < s.n; i++)
        ck_assert(i == 5 * 30 + 7 || (r[i] > 0 && r[i] < 1.01f));
    env_light(&s, &env, 8, TS_ENV_DEFAULT_NORMAL_STEPS, TS_ENV_DEFAULT_HORIZON_STEPS, 0, r2,
              g2, b2);
    ck_assert(max_diff(r, r2, s.n, NULL) == 0);
    /* the horizons must be the table's sectors */
    s.o.start_azimuth = 10;
    ck_assert(ts_env_light(&s.g, &t, s.nx, s.ny, s.nz, s.hor, &s.o, r, g, b, &err) ==
              TS_ERR_ARG);
    s.o.start_azimuth = 0;
    s.o.directions = 4;
    ck_assert(ts_env_light(&s.g, &t, s.nx, s.ny, s.nz, s.hor, &s.o, r, g, b, &err) ==
              TS_ERR_ARG);
    const ts_env_light_request q0 = {&s.g, &t, 0, s.nx, s.ny, s.nz, s.hor, r, g, b, 1};
    ts_env_light_request q;
    ck_assert(ts_env_light_accumulate(&q0, &err) == TS_OK);
    EXPECT_ARG(ts_env_light_accumulate(NULL, &err), &err);
    EXPECT_ARG_FIELD(ts_env_light_accumulate, q, q0, k, 8, &err);
    EXPECT_ARG_FIELD(ts_env_light_accumulate, q, q0, k, -1, &err);
    EXPECT_ARG_FIELD(ts_env_light_accumulate, q, q0, plane, NULL, &err);
    EXPECT_ARG_FIELD(ts_env_light_accumulate, q, q0, g, NULL, &err);
    EXPECT_ARG_FIELD(ts_env_light_accumulate, q, q0, grid, NULL, &err);
    EXPECT_ARG_FIELD(ts_env_light_accumulate, q, q0, table, NULL, &err);
    ts_env_table_free(&t);
    EXPECT_ARG(ts_env_light_accumulate(&q0, &err), &err);
    ts_env_table_free(NULL);
    free(r), free(g), free(b), free(r2), free(g2), free(b2);
    ts_env_free(&env);
    scene_free(&s);
}
END_TEST

START_TEST(test_table_bad_input)
{
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sky(&env, TS_SKY_UNIFORM, 0, 0, 0, 64, 32, &err) == TS_OK);
    ts_env_table_opts o;
    ts_env_table t;
    ts_env_table_opts_default(&o);
    ck_assert(ts_env_table_build(NULL, &o, &t, &err) == TS_ERR_ARG);
    ck_assert(ts_env_table_build(&env, NULL, &t, &err) == TS_ERR_ARG);
    ck_assert(ts_env_table_build(&env, &o, NULL, &err) == TS_ERR_ARG);
    /* even steps: no node at 0 degrees, where flat ground has its normal and
     * horizon */
    const int bad[][4] = {{0, 17, 181, 0}, {16, 1, 181, 0}, {16, 17, 1, 0},
                          {16, 17, 181, 2}, {65536, 16384, 16384, 0}, {16, 2, 181, 0},
                          {16, 16, 181, 0}, {16, 0, 2, 0}, {16, 0, 180, 0}};
    for (int i = 0; i < 9; i++) {
        o.directions = bad[i][0], o.normal_steps = bad[i][1], o.horizon_steps = bad[i][2];
        o.ground = bad[i][3];
        ck_assert_msg(ts_env_table_build(&env, &o, &t, &err) == TS_ERR_ARG, "case %d", i);
        ck_assert(err.message[0] && t.lp == NULL);
    }
    ts_env_table_opts_default(&o);
    o.start_azimuth = INFINITY;
    ck_assert(ts_env_table_build(&env, &o, &t, &err) == TS_ERR_ARG);
    ts_env_table_opts_default(&o);
    const float bad_rgb[] = {-1.0f, NAN, INFINITY};
    for (int i = 0; i < 3; i++) {
        env.texels[100].rgb[1] = bad_rgb[i];
        ck_assert(ts_env_table_build(&env, &o, &t, &err) == TS_ERR_ARG);
        ck_assert_msg(strstr(err.message, "texel 100") != NULL, "%s", err.message);
    }
    env.texels[100].rgb[1] = 1;
    env.texels[7].dir[2] = 3;
    ck_assert(ts_env_table_build(&env, &o, &t, &err) == TS_ERR_ARG);
    ts_env_free(&env);
    /* An empty environment is black, not an error. */
    ck_assert(ts_env_table_build(&env, &o, &t, &err) == TS_OK);
    for (size_t i = 0; i < (size_t)o.directions * o.normal_steps * o.horizon_steps * 8; i++)
        ck_assert(t.lp[i] == 0);
    ts_env_table_free(&t);
}
END_TEST

static Suite *env_light_suite(void)
{
    Suite *s = suite_create("env_light");
    TCase *tc = tcase_create("light");
    tcase_set_timeout(tc, 300);
    tcase_add_loop_test(tc, test_constant_env_is_sky_term, 0, 3);
    tcase_add_test(tc, test_bright_patch_is_the_sun);
    tcase_add_test(tc, test_flat_plane);
    tcase_add_test(tc, test_brute_force_reference);
    tcase_add_test(tc, test_nodata_and_streaming);
    tcase_add_test(tc, test_table_bad_input);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return test_run_suite(env_light_suite());
}
