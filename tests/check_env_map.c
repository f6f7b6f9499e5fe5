/* Environment maps (core/env_map*.c): solid angles, OpenEXR's direction
 * conventions mapped to the terrain, rotation, lat-long against the cube
 * map made by OpenEXR's exrenvmap, merging into blocks.
 * File variants and bad input: check_env_map_files.c. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade_env.h"
#include "test_env.h"
#include "test_exr_write.h"
#include "test_run.h"

/* ------------------------------------------------------------ solid angles */

/* Constant radiance 1: the solid angles sum to 4 pi and the irradiance on
 * any plane is pi (up to the discretisation of the cosine). */
static void check_constant(const ts_env *e, double cos_tol)
{
    ck_assert_double_eq_tol(tenv_total_solid_angle(e) / (4.0 * M_PI), 1.0, 1e-6);
    static const double normals[3][3] = {{0, 0, 1}, {0, 0, -1}, {0.6, 0, 0.8}};
    for (int k = 0; k < 3; k++) {
        double irr[3];
        tenv_irradiance(e, normals[k], irr);
        ck_assert_double_eq_tol(irr[0] / M_PI, 1.0, cos_tol);
    }
}

START_TEST(test_solid_angles_latlong)
{
    static const int sizes[][2] = {{2, 2}, {3, 2}, {8, 4}, {65, 33}, {512, 256}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        float *rgb = tenv_constant(w * h, 1.0f);
        ts_env e;
        ts_error err;
        ck_assert_int_eq(ts_env_from_latlong(rgb, w, h, 0.0, &e, &err), TS_OK);
        ck_assert_uint_eq(e.count, (size_t)w * h);
        ck_assert_double_eq_tol(tenv_total_solid_angle(&e) / (4.0 * M_PI), 1.0, 1e-6);
        if (w >= 65)
            check_constant(&e, w >= 512 ? 1e-4 : 2e-3);
        ts_env_free(&e);
        ck_assert_ptr_null(e.texels);
        free(rgb);
    }
}
END_TEST

START_TEST(test_solid_angles_cube)
{
    static const int faces[] = {1, 2, 3, 64, 256};
    for (size_t s = 0; s < sizeof faces / sizeof faces[0]; s++) {
        int f = faces[s];
        float *rgb = tenv_constant(6 * f * f, 1.0f);
        ts_env e;
        ts_error err;
        ck_assert_int_eq(ts_env_from_cube(rgb, f, 0.0, &e, &err), TS_OK);
        ck_assert_uint_eq(e.count, (size_t)6 * f * f);
        ck_assert_double_eq_tol(tenv_total_solid_angle(&e) / (4.0 * M_PI), 1.0, 1e-6);
        if (f >= 64)
            check_constant(&e, f >= 256 ? 1e-4 : 1e-3);
        ts_env_free(&e);
        free(rgb);
    }
}
END_TEST

/* ------------------------------------------------------------ conventions */

/* Azimuth (degrees clockwise from north) and elevation of a terrain direction. */
static void az_el(const float d[3], double *az, double *el)
{
    *az = fmod(atan2(d[0], d[1]) * 180.0 / M_PI + 360.0, 360.0);
    *el = asin(d[2]) * 180.0 / M_PI;
}

/* Angle between the two azimuths, in [0, 180]. */
static double az_diff(double a, double b)
{
    double d = fabs(fmod(a - b + 540.0, 360.0) - 180.0);
    return d;
}

/* A 65 x 33 lat-long file (envmap attribute) with one bright pixel (col, row)
 * read with the rotation: the bright texel's azimuth and elevation. */
static void bright_texel(int col, int row, double rotation, double *az, double *el)
{
    enum { W = 65, H = 33 };
    float *rgb = tenv_constant(W * H, 0.0f);
    for (int c = 0; c < 3; c++)
        rgb[((size_t)row * W + col) * 3 + c] = 100.0f;
    static const char *const ch[] = {"R", "G", "B"};
    texr_spec s = {.width = W, .height = H, .channels = ch, .nchannels = 3,
                   .type = EXR_PIXEL_FLOAT, .compression = EXR_COMPRESSION_ZIP,
                   .envmap = EXR_ENVMAP_LATLONG};
    const char *path = tenv_tmp("bright.exr");
    ck_assert_int_eq(texr_write(path, &s, rgb), 0);
    ts_env e;
    ts_error err;
    ck_assert_msg(ts_env_load_exr_file(path, rotation, 0, &e, &err) == TS_OK, "%s", err.message);
    size_t best = tenv_brightest(&e);
    az_el(e.texels[best].dir, az, el);
    ts_env_free(&e);
    free(rgb);
}

/* OpenEXR's LatLongMap: the centre column looks along +Z (north on the
 * terrain), the left quarter column along +X (west), the right one along
 * -X (east), the top row up; rotation turns clockwise seen from above. */
START_TEST(test_latlong_orientation)
{
    static const struct {
        int col, row;
        double rotation, az, el;
    } cases[] = {
        {32, 16, 0, 0, 0},     {16, 16, 0, 270, 0},  {48, 16, 0, 90, 0},
        {0, 16, 0, 180, 0},    {32, 8, 0, 0, 45},    {16, 24, 0, 270, -45},
        {32, 16, 90, 90, 0},   {16, 16, 90, 0, 0},   {48, 16, 90, 180, 0},
        {32, 16, -90, 270, 0}, {32, 16, 450, 90, 0}, {8, 4, 30, 225 + 30, 67.5},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double az, el;
        bright_texel(cases[k].col, cases[k].row, cases[k].rotation, &az, &el);
        printf("lat-long pixel (%2d, %2d), rotation %4.0f: azimuth %6.2f, elevation %6.2f\n",
               cases[k].col, cases[k].row, cases[k].rotation, az, el);
        ck_assert_double_le(az_diff(az, cases[k].az), 1e-3);
        ck_assert_double_eq_tol(el, cases[k].el, 1e-3);
    }
    double az, el;
    bright_texel(32, 0, 0, &az, &el);
    ck_assert_double_eq_tol(el, 90.0, 1e-3);
}
END_TEST

/* The reader's cube directions against OpenEXR's forward mapping
 * (CubeMap::faceAndPixelPosition and ::pixelPosition, coded in test_env.c):
 * a direction lights the pixel OpenEXR assigns it, and the reader gives
 * that pixel's direction back. Terrain: +Z north, +X west, +Y up. */
START_TEST(test_cube_orientation)
{
    enum { F = 33 };
    unsigned seed = 7;
    for (int k = 0; k < 200; k++) {
        double m[3];
        tenv_random_direction(&seed, m);
        if (k < 6) { /* the face centres first */
            m[0] = m[1] = m[2] = 0.0;
            m[k / 2] = (k & 1) ? -1.0 : 1.0;
        }
        int x, y;
        tenv_cube_pixel_of(m, F, &x, &y);
        float *rgb = tenv_constant(6 * F * F, 0.0f);
        rgb[((size_t)y * F + x) * 3] = 1.0f;
        ts_env e;
        ts_error err;
        ck_assert_int_eq(ts_env_from_cube(rgb, F, 0.0, &e, &err), TS_OK);
        const float *d = e.texels[tenv_brightest(&e)].dir;
        double len = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        double east = -m[0] / len, north = m[2] / len, up = m[1] / len;
        double cosang = d[0] * east + d[1] * north + d[2] * up;
        /* within a texel: half the diagonal of 2/(F-1) on the face, at most */
        ck_assert_msg(cosang > cos(1.5 / (F - 1)), "direction %d: cos %f", k, cosang);
        if (k < 6)
            ck_assert_double_eq_tol(cosang, 1.0, 1e-6);
        ts_env_free(&e);
        free(rgb);
    }
}
END_TEST

/* ENV_ROTATION 90 equals the lat-long map with its columns rolled by a
 * quarter turn (w-1 = 64 columns of spacing: 16). */
START_TEST(test_rotation_is_a_roll)
{
    enum { W = 65, H = 33, Q = 16 };
    float *img = tenv_random_image(W, H, 11), *rolled = tenv_constant(W * H, 0.0f);
    for (int j = 0; j < H; j++) {
        for (int c = 0; c < 3; c++) /* first and last columns: the same meridian */
            img[((size_t)j * W + W - 1) * 3 + c] = img[(size_t)j * W * 3 + c];
        for (int i = 0; i < W; i++)
            for (int c = 0; c < 3; c++)
                rolled[((size_t)j * W + i) * 3 + c] =
                    img[((size_t)j * W + (i - Q + W - 1) % (W - 1)) * 3 + c];
    }
    ts_env a, b;
    ts_error err;
    ck_assert_int_eq(ts_env_from_latlong(img, W, H, 90.0, &a, &err), TS_OK);
    ck_assert_int_eq(ts_env_from_latlong(rolled, W, H, 0.0, &b, &err), TS_OK);
    unsigned seed = 3;
    for (int k = 0; k < 100; k++) {
        double n[3], ea[3], eb[3];
        tenv_random_direction(&seed, n);
        tenv_irradiance(&a, n, ea);
        tenv_irradiance(&b, n, eb);
        for (int c = 0; c < 3; c++)
            ck_assert_double_eq_tol(ea[c], eb[c], 1e-5 * eb[c] + 1e-9);
    }
    ts_env_free(&a);
    ts_env_free(&b);
    free(img);
    free(rolled);
}
END_TEST

/* -------------------------------------------------- the real map, two ways */

START_TEST(test_latlong_vs_cube)
{
    ts_env ll, cube;
    ts_error err;
    ck_assert_msg(ts_env_load_exr_file(TS_TEST_DATA "/envmaps/sunset.exr", 0.0, 0, &ll, &err) ==
                  TS_OK, "%s", err.message);
    ck_assert_msg(ts_env_load_exr_file(TS_TEST_DATA "/envmaps/sunset_cube128.exr", 0.0, 0, &cube,
                                       &err) == TS_OK, "%s", err.message);
    ck_assert_uint_eq(ll.count, 1024 * 512);
    ck_assert_uint_eq(cube.count, 6 * 128 * 128);
    ck_assert_double_eq_tol(tenv_total_solid_angle(&ll) / (4 * M_PI), 1.0, 1e-6);
    ck_assert_double_eq_tol(tenv_total_solid_angle(&cube) / (4 * M_PI), 1.0, 1e-6);

    /* the horizontal plane, then planes tilted 30 and 60 degrees every 45 */
    double worst = 0.0;
    for (int tilt = 0; tilt <= 60; tilt += 30)
        for (int az = 0; az < (tilt ? 360 : 1); az += 45) {
            double t = tilt * M_PI / 180, a = az * M_PI / 180;
            double n[3] = {sin(t) * sin(a), sin(t) * cos(a), cos(t)}, el[3], ec[3];
            tenv_irradiance(&ll, n, el);
            tenv_irradiance(&cube, n, ec);
            for (int c = 0; c < 3; c++) {
                double rel = fabs(ec[c] / el[c] - 1.0);
                worst = fmax(worst, rel);
                ck_assert_msg(rel <= 0.01, "tilt %d azimuth %d colour %d: %g vs %g", tilt, az,
                              c, el[c], ec[c]);
            }
        }
    /* the median over directions all around */
    enum { N = 400 };
    double rel[N];
    for (int k = 0; k < N; k++) {
        double n[3], el[3], ec[3];
        tenv_fibonacci_direction(k, N, n);
        tenv_irradiance(&ll, n, el);
        tenv_irradiance(&cube, n, ec);
        rel[k] = fabs((ec[0] + ec[1] + ec[2]) / (el[0] + el[1] + el[2]) - 1.0);
    }
    double median = tenv_median(rel, N);
    printf("sunset lat-long vs exrenvmap cube 128: planes worst %.2e, median over %d "
           "directions %.2e\n", worst, N, median);
    ck_assert_double_le(median, 0.01);
    ts_env_free(&ll);
    ts_env_free(&cube);
}
END_TEST

/* Merging into blocks keeps the solid angle and the energy, and the light
 * on planes within 1 %. */
START_TEST(test_block_merging)
{
    ts_env full, small, cube;
    ts_error err;
    const char *ll = TS_TEST_DATA "/envmaps/sunset.exr";
    ck_assert_int_eq(ts_env_load_exr_file(ll, 0.0, 0, &full, &err), TS_OK);
    ck_assert_int_eq(ts_env_load_exr_file(ll, 0.0, 20000, &small, &err), TS_OK);
    ck_assert_int_eq(ts_env_load_exr_file(TS_TEST_DATA "/envmaps/sunset_cube128.exr", 0.0, 6000,
                                          &cube, &err), TS_OK);
    printf("blocks: %zu lat-long texels -> %zu, cube -> %zu\n", full.count, small.count,
           cube.count);
    ck_assert_uint_le(small.count, 20000);
    ck_assert_uint_ge(small.count, 10000);
    ck_assert_uint_le(cube.count, 6000);
    ck_assert_uint_ge(cube.count, 3000);
    ck_assert_double_eq_tol(tenv_total_solid_angle(&small) / (4 * M_PI), 1.0, 1e-6);
    ck_assert_double_eq_tol(tenv_total_solid_angle(&cube) / (4 * M_PI), 1.0, 1e-6);
    double pf[3], ps[3];
    tenv_power(&full, pf);
    tenv_power(&small, ps);
    for (int c = 0; c < 3; c++)
        ck_assert_double_eq_tol(ps[c] / pf[c], 1.0, 1e-5);
    double worst_ll = 0.0, worst_cube = 0.0;
    for (int k = 0; k < 50; k++) {
        double n[3], ef[3], es[3], ec[3];
        tenv_fibonacci_direction(k, 50, n);
        tenv_irradiance(&full, n, ef);
        tenv_irradiance(&small, n, es);
        tenv_irradiance(&cube, n, ec);
        for (int c = 0; c < 3; c++) {
            ck_assert_double_eq_tol(es[c] / ef[c], 1.0, 0.01);
            ck_assert_double_eq_tol(ec[c] / ef[c], 1.0, 0.01);
            worst_ll = fmax(worst_ll, fabs(es[c] / ef[c] - 1.0));
            worst_cube = fmax(worst_cube, fabs(ec[c] / ef[c] - 1.0));
        }
    }
    printf("blocks against the full lat-long map, 50 planes: lat-long worst %.2e, cube worst "
           "%.2e\n", worst_ll, worst_cube);
    ts_env_free(&full);
    ts_env_free(&small);
    ts_env_free(&cube);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("env_map");
    TCase *geo = tcase_create("geometry");
    tcase_add_test(geo, test_solid_angles_latlong);
    tcase_add_test(geo, test_solid_angles_cube);
    tcase_add_test(geo, test_latlong_orientation);
    tcase_add_test(geo, test_cube_orientation);
    tcase_add_test(geo, test_rotation_is_a_roll);
    suite_add_tcase(s, geo);
    TCase *real = tcase_create("real map");
    tcase_set_timeout(real, 60);
    tcase_add_test(real, test_latlong_vs_cube);
    tcase_add_test(real, test_block_merging);
    suite_add_tcase(s, real);
    tenv_tmp_begin();
    int rc = test_run_suite(s);
    tenv_tmp_end();
    return rc;
}
