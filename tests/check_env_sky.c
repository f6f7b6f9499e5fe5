/* Standard skies: the CIE general sky formula for the 15 types, the
 * traditional overcast sky, the lat-long texel grid, normalisation and bad
 * input. */
#include <check.h>
#include <math.h>
#include <stdlib.h>

#include "terrashade_env.h"
#include "test_run.h"

static const double PI = 3.14159265358979323846;

/* L/Lz at (Z, chi, Zs) in degrees for types 1..15, computed in Python (math
 * module, double) directly from the standard's formula and its parameter
 * table (ISO 15469:2004 / CIE S 011/E:2003, Table 1; also Darula & Kittler
 * 2002), independently of core/env_sky.c. */
static const double POINTS[5][3] = {{45, 20, 40}, {80, 90, 40}, {30, 60, 60}, {60, 10, 50},
                                    {89, 150, 20}};
static const double EXPECTED[15][5] = {
    {0.832584643, 0.358638309, 0.931734462, 0.665157701, 0.334857917},
    {1.106952517, 0.224106534, 0.931734462, 1.174950995, 0.151456789},
    {0.906701722, 0.676574660, 0.961495180, 0.817852749, 0.669226744},
    {1.205493954, 0.422779157, 0.961495180, 1.444675300, 0.302692361},
    {1.000000000, 1.000000000, 1.000000000, 1.000000000, 1.000000000},
    {1.329537515, 0.624881750, 1.000000000, 1.766424705, 0.452301651},
    {1.669123421, 0.512696850, 1.000000000, 2.783187063, 0.348224787},
    {2.002226011, 0.415682013, 1.000000000, 3.982525602, 0.259834032},
    {1.698942352, 1.414877347, 1.111238625, 2.785563103, 1.069144186},
    {2.132880374, 1.160864690, 1.111238625, 4.388946312, 0.823128781},
    {2.558533724, 0.941200577, 1.111238625, 6.280242992, 0.614191977},
    {2.661300126, 1.277517829, 1.128070159, 6.874432733, 0.948815468},
    {2.981768962, 1.023537893, 1.128070159, 8.541000229, 0.589537444},
    {3.078387979, 1.383048311, 1.141737082, 9.206799014, 1.158828169},
    {3.231005728, 0.990838791, 1.141737082, 10.161918381, 0.605927146},
};

START_TEST(test_cie_formula_points)
{
    for (int t = 1; t <= 15; t++)
        for (int p = 0; p < 5; p++) {
            double v = ts_cie_sky_relative(t, POINTS[p][0], POINTS[p][1], POINTS[p][2]);
            ck_assert_msg(fabs(v - EXPECTED[t - 1][p]) <= 1e-8 * EXPECTED[t - 1][p],
                          "type %d at Z=%g chi=%g Zs=%g: %.9f, expected %.9f", t, POINTS[p][0],
                          POINTS[p][1], POINTS[p][2], v, EXPECTED[t - 1][p]);
        }
    /* The zenith is the reference: L/Lz = 1 there (chi = Zs), whatever the sun. */
    for (int t = 1; t <= 15; t++)
        for (double zs = 0; zs <= 90; zs += 15)
            ck_assert(fabs(ts_cie_sky_relative(t, 0, zs, zs) - 1) < 1e-12);
    ck_assert(isnan(ts_cie_sky_relative(0, 10, 10, 10)));
    ck_assert(isnan(ts_cie_sky_relative(16, 10, 10, 10)));
}
END_TEST

/* Published properties: CIE S 011 describes type 5 as the sky of uniform
 * luminance, and type 1 as the overcast sky with the steep 3:1 gradation of
 * the traditional CIE overcast sky (1 + a e^b = 1 + 4 e^-0.7 = 2.986). */
START_TEST(test_cie_published)
{
    for (double z = 0; z <= 90; z += 10)
        for (double chi = 0; chi <= 180; chi += 20)
            ck_assert(fabs(ts_cie_sky_relative(5, z, chi, 35) - 1) < 1e-12);
    double horizon = ts_cie_sky_relative(1, 90, 50, 40);
    ck_assert_msg(fabs(1 / horizon - 3) < 0.015, "type 1 zenith/horizon %g", 1 / horizon);
    /* Type 1 and 3 and 5 have no sun dependence (c = e = 0). */
    for (int t = 1; t <= 5; t += 2)
        ck_assert(fabs(ts_cie_sky_relative(t, 50, 10, 30) -
                       ts_cie_sky_relative(t, 50, 120, 70)) < 1e-12);
}
END_TEST

START_TEST(test_sphere_grid)
{
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sphere_grid(&env, 90, 45, &err) == TS_OK);
    ck_assert_uint_eq(env.count, 90 * 45);
    double total = 0;
    for (size_t i = 0; i < env.count; i++) {
        const float *d = env.texels[i].dir;
        ck_assert(fabs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1) < 1e-6);
        total += env.texels[i].solid_angle;
        ck_assert(env.texels[i].rgb[0] == 0);
    }
    ck_assert_msg(fabs(total - 4 * PI) < 1e-5, "solid angles sum to %.8f", total);
    /* Row 0 is at the zenith, column 0 just east of north (azimuth 2 deg). */
    ck_assert(env.texels[0].dir[2] > 0.999f);
    const float *d = env.texels[21 * 90].dir; /* row 21 (4 deg rows): centre at +4 deg */
    ck_assert(fabs(asin(d[2]) * 180 / PI - 4) < 1e-4);
    ck_assert(fabs(atan2(d[0], d[1]) * 180 / PI - 2) < 1e-4);
    ts_env_free(&env);
    ck_assert(env.texels == NULL && env.count == 0);
    ts_env_free(NULL);
}
END_TEST

/* Sum of L cos(Z) omega over the texels: pi for every sky. */
static double horizontal_irradiance(const ts_env *env)
{
    double e = 0;
    for (size_t i = 0; i < env->count; i++) {
        const ts_env_texel *t = &env->texels[i];
        if (t->dir[2] > 0)
            e += t->rgb[0] * t->dir[2] * t->solid_angle;
    }
    return e;
}

START_TEST(test_skies_normalised_grey_and_dark_below)
{
    const ts_sky_kind kinds[] = {TS_SKY_UNIFORM, TS_SKY_OVERCAST, TS_SKY_CLEAR};
    for (int s = 0; s < 18; s++) {
        ts_sky_kind kind = s < 3 ? kinds[s] : TS_SKY_CIE;
        ts_env env;
        ts_error err;
        ck_assert_msg(ts_env_sky(&env, kind, s < 3 ? 0 : s - 2, 135, 30, 256, 128, &err) ==
                          TS_OK, "%s", err.message);
        ck_assert_msg(fabs(horizontal_irradiance(&env) - PI) < 1e-4, "sky %d: %g", s,
                      horizontal_irradiance(&env));
        for (size_t i = 0; i < env.count; i++) {
            const ts_env_texel *t = &env.texels[i];
            ck_assert(t->rgb[0] == t->rgb[1] && t->rgb[1] == t->rgb[2]);
            ck_assert(t->dir[2] > 0 ? t->rgb[0] > 0 : t->rgb[0] == 0);
        }
        ts_env_free(&env);
    }
    /* The formula continued for a sun below the horizon (dusk) stays positive. */
    for (int type = 1; type <= 15; type++) {
        ts_env env;
        ts_error err;
        ck_assert(ts_env_sky(&env, TS_SKY_CIE, type, 250, -12, 128, 64, &err) == TS_OK);
        ck_assert(fabs(horizontal_irradiance(&env) - PI) < 1e-4);
        for (size_t i = 0; i < env.count; i++)
            ck_assert(env.texels[i].dir[2] > 0 ? env.texels[i].rgb[0] > 0
                                               : env.texels[i].rgb[0] == 0);
        ts_env_free(&env);
    }
}
END_TEST

/* The traditional CIE overcast sky (Moon & Spencer 1942): zenith three times
 * as bright as the horizon, and horizontal illuminance 7 pi / 9 Lz, so with
 * the irradiance normalised to pi the zenith radiance is 9/7. */
START_TEST(test_traditional_overcast)
{
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sky(&env, TS_SKY_OVERCAST, 0, 0, 0, 360, 720, &err) == TS_OK);
    /* Row 0 centre at Z = 0.125 deg; row 359 centre at Z = 89.875 deg. */
    double top = env.texels[0].rgb[0], low = env.texels[359 * 360].rgb[0];
    double z_top = 0.125 * PI / 180;
    double lz = top * 3 / (1 + 2 * cos(z_top));
    ck_assert_msg(fabs(lz - 9.0 / 7.0) < 2e-4, "zenith radiance %.6f, expected 9/7", lz);
    /* the first and last rows above the horizontal are 0.125 deg from the ends */
    ck_assert_msg(fabs(top / low - 3) < 0.015, "zenith/horizon %g", top / low);
    ts_env_free(&env);
}
END_TEST

/* A CIE sky's texels follow the formula (ratios between texels) and are
 * symmetric about the sun's azimuth. */
START_TEST(test_cie_texels_follow_formula)
{
    const double sun_az = 90, sun_el = 25; /* the sun due east: columns mirror about it */
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sky(&env, TS_SKY_CLEAR, 0, sun_az, sun_el, 360, 180, &err) == TS_OK);
    const ts_env_texel *ref = &env.texels[30 * 360 + 10];
    for (int r = 0; r < 90; r += 7)
        for (int c = 0; c < 360; c += 13) {
            const ts_env_texel *t = &env.texels[r * 360 + c];
            double z = acos(t->dir[2]) * 180 / PI;
            double chi = acos(t->dir[0] * cos(sun_el * PI / 180) +
                              t->dir[2] * sin(sun_el * PI / 180)) * 180 / PI;
            double zr = acos(ref->dir[2]) * 180 / PI;
            double chir = acos(ref->dir[0] * cos(sun_el * PI / 180) +
                               ref->dir[2] * sin(sun_el * PI / 180)) * 180 / PI;
            double want = ts_cie_sky_relative(12, z, chi, 90 - sun_el) /
                          ts_cie_sky_relative(12, zr, chir, 90 - sun_el);
            ck_assert_msg(fabs(t->rgb[0] / ref->rgb[0] - want) < 1e-4 * want,
                          "row %d col %d: %g, expected %g", r, c, t->rgb[0] / ref->rgb[0], want);
            /* mirror about azimuth 90: column c <-> 179 - c */
            ck_assert(fabs(t->rgb[0] - env.texels[r * 360 + (179 - c + 360) % 360].rgb[0]) <=
                      1e-5f * t->rgb[0]);
        }
    ts_env_free(&env);
}
END_TEST

START_TEST(test_sky_parse)
{
    ts_sky_kind kind;
    int type;
    ts_error err;
    ck_assert(ts_sky_parse("Overcast", &kind, &type, &err) == TS_OK && kind == TS_SKY_OVERCAST);
    ck_assert(ts_sky_parse("uniform", &kind, &type, &err) == TS_OK && kind == TS_SKY_UNIFORM);
    ck_assert(ts_sky_parse("clear", &kind, &type, &err) == TS_OK && kind == TS_SKY_CLEAR);
    ck_assert(ts_sky_parse("cie:15", &kind, &type, &err) == TS_OK && kind == TS_SKY_CIE &&
              type == 15);
    /* cieN: the form without ':' that an inline connection string can hold */
    ck_assert(ts_sky_parse("cie9", &kind, &type, &err) == TS_OK && kind == TS_SKY_CIE &&
              type == 9);
    ck_assert(ts_sky_parse("CIE12", &kind, &type, &err) == TS_OK && type == 12);
    /* (strtol took a blank or a sign: 'cie: 9', 'cie:+9', 'cie -3') */
    const char *bad[] = {"cie:0", "cie:16", "cie:", "cie:3x", "sunny", "", "cie", "cie0",
                         "cie16", "cie::3", "cie: 9", "cie:+9", "cie -3", "cie:-1"};
    for (int i = 0; i < (int)(sizeof bad / sizeof bad[0]); i++) {
        ck_assert(ts_sky_parse(bad[i], &kind, &type, &err) == TS_ERR_ARG);
        ck_assert(err.message[0] != 0);
    }
    ck_assert(ts_sky_parse(NULL, &kind, &type, &err) == TS_ERR_ARG);
}
END_TEST

START_TEST(test_sky_bad_input)
{
    ts_env env;
    ts_error err;
    ck_assert(ts_env_sky(&env, TS_SKY_CIE, 0, 0, 30, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_CIE, 16, 0, 30, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_CLEAR, 0, 0, 95, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_CLEAR, 0, NAN, 30, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_CLEAR, 0, 0, NAN, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_UNIFORM, 0, 0, 0, 0, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_UNIFORM, 0, 0, 0, 64, 1, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, TS_SKY_UNIFORM, 0, 0, 0, 1 << 20, 1 << 20, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(&env, (ts_sky_kind)9, 0, 0, 0, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(ts_env_sky(NULL, TS_SKY_UNIFORM, 0, 0, 0, 64, 32, &err) == TS_ERR_ARG);
    ck_assert(env.texels == NULL && env.count == 0);
    ck_assert(ts_env_sky(&env, TS_SKY_UNIFORM, 0, 0, 0, 0, 0, &err) == TS_OK);
    ck_assert_uint_eq(env.count, (size_t)TS_SKY_DEFAULT_WIDTH * TS_SKY_DEFAULT_HEIGHT);
    ts_env_free(&env);
}
END_TEST

static Suite *env_sky_suite(void)
{
    Suite *s = suite_create("env_sky");
    TCase *tc = tcase_create("skies");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_cie_formula_points);
    tcase_add_test(tc, test_cie_published);
    tcase_add_test(tc, test_sphere_grid);
    tcase_add_test(tc, test_skies_normalised_grey_and_dark_below);
    tcase_add_test(tc, test_traditional_overcast);
    tcase_add_test(tc, test_cie_texels_follow_formula);
    tcase_add_test(tc, test_sky_parse);
    tcase_add_test(tc, test_sky_bad_input);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return test_run_suite(env_sky_suite());
}
