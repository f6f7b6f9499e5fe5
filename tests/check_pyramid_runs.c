/* The pyramid's loops against each other (core/pyramid_runs.c,
 * core/pyramid_fused.c): the level maximum with the level row kept in
 * registers (ts_pyr_level_max_rows) must give the maxima of the level row
 * combined into T (ts_pyr_combine_rows, T[t1 + 1] = T[t1] as sample_level
 * pads it) then read back by ts_pyr_level_run, bit for bit: every tap
 * count, rows with nodata, runs at any column and offset, the fraction 0
 * at the grid's last column; and with two grid rows reading the same level
 * rows with their own weights, each row's maxima those of the reference.
 * And the pyramid's curvature drop against the closed form. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pyramid_hz.h"
#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"

enum { ROWS = 4, MAXW = 1100 };

/* n floats of heights in [-50, 1450), every `holes`-th NaN (0: none) */
static void fill(float *v, int n, uint64_t *seed, int holes)
{
    for (int i = 0; i < n; i++)
        v[i] = holes && i % holes == 3 ? NAN : (float)(1500.0 * tdem_uniform(seed) - 50.0);
}

/* The maxima m (W + 16 cells, some at -inf: no sample yet) of one grid
 * row's run the reference way: the level row combined into T, padded at
 * t1 + 1 as sample_level does, read back by ts_pyr_level_run. */
static void reference_run(const float *const r[4], const float wt[4], int taps, int ix, float fx,
                          int t1, const float *R, float inv_d, float cd, int x0, int x1,
                          float *m)
{
    row_ws a = {0};
    float *T = ts_pyr_alloc((MAXW + 16) * sizeof *T);
    a.m = m;
    a.A = ts_pyr_alloc((MAXW + 16) * sizeof *a.A);
    ck_assert(T && a.A);
    ts_pyr_combine_rows(r, wt, taps, x0 + ix, t1, T);
    T[t1 + 1] = T[t1];
    ts_pyr_level_run(&a, T, ix, fx, R, inv_d, cd, 0, 1, x0, x1);
    free(T), free(a.A);
}

/* Maxima to start from: some at -inf, the others in [-0.5, 0.5). */
static float *start_max(uint64_t *seed)
{
    float *m = ts_pyr_alloc((MAXW + 16) * sizeof *m);
    ck_assert(m);
    for (int x = 0; x < MAXW + 16; x++)
        m[x] = tdem_uniform(seed) < 0.2 ? -INFINITY : (float)(tdem_uniform(seed) - 0.5);
    return m;
}

static float *copy_max(const float *m)
{
    float *c = ts_pyr_alloc((MAXW + 16) * sizeof *c);
    ck_assert(c);
    memcpy(c, m, (MAXW + 16) * sizeof *c);
    return c;
}

/* One run three ways: the reference for two grid rows reading the same
 * level rows r with their own weights (wt, wt2) and heights (R, R2);
 * ts_pyr_level_max_rows of the first row alone, then of both rows.
 * Returns whether all give the same bits (1 also where the CPU has no
 * AVX-512: nothing to compare; *compared says). */
static int one_run(const float *const r[4], const float wt[4], const float wt2[4], int taps,
                   int W, int ix, float fx, const float *R, const float *R2, int x0, int x1,
                   uint64_t *seed, int *compared)
{
    float *ref = start_max(seed), *ref2 = start_max(seed);
    float *one = copy_max(ref), *pair = copy_max(ref), *pair2 = copy_max(ref2);
    const float inv_d = (float)(1.0 / (40.0 + 900.0 * tdem_uniform(seed)));
    const float cd = (float)(1e-6 * tdem_uniform(seed));
    const float inv_d2 = (float)(1.0 / (40.0 + 900.0 * tdem_uniform(seed)));
    const float cd2 = (float)(1e-6 * tdem_uniform(seed));
    int t1 = x1 + ix + (fx > 0.0f);
    t1 = t1 > W - 1 ? W - 1 : t1;
    reference_run(r, wt, taps, ix, fx, t1, R, inv_d, cd, x0, x1, ref);
    reference_run(r, wt2, taps, ix, fx, t1, R2, inv_d2, cd2, x0, x1, ref2);
    const level_max_row g1 = {one, R, wt, inv_d, cd};
    *compared = ts_pyr_level_max_rows(&g1, 1, r, taps, W, t1, ix, fx, x0, x1);
    const level_max_row g[2] = {{pair, R, wt, inv_d, cd}, {pair2, R2, wt2, inv_d2, cd2}};
    int paired = ts_pyr_level_max_rows(g, 2, r, taps, W, t1, ix, fx, x0, x1);
    ck_assert_int_eq(paired, *compared);
    const size_t bytes = (MAXW + 16) * sizeof *ref;
    int same = !*compared || (!memcmp(ref, one, bytes) && !memcmp(ref, pair, bytes) &&
                              !memcmp(ref2, pair2, bytes));
    free(ref), free(ref2), free(one), free(pair), free(pair2);
    return same;
}

START_TEST(test_level_max_rows_identical)
{
    uint64_t seed = 12345;
    float *rows = ts_pyr_alloc(ROWS * MAXW * sizeof *rows);
    float *R = ts_pyr_alloc((MAXW + 16) * sizeof *R);
    float *R2 = ts_pyr_alloc((MAXW + 16) * sizeof *R2);
    ck_assert(rows && R && R2);
    static const int widths[] = {1, 17, 100, 1024, 1093};
    int runs = 0, compared = 0, differ = 0;
    char first[160] = "";
    for (int wi = 0; wi < 5; wi++) {
        const int W = widths[wi];
        for (int k = 0; k < 200; k++) {
            int holes = k % 3 == 0 ? 0 : 5 + k % 17;
            fill(rows, ROWS * W, &seed, holes);
            fill(R, W, &seed, k % 4 == 1 ? 7 : 0);
            fill(R2, W, &seed, k % 4 == 2 ? 9 : 0);
            const int taps = k % 3 == 0 ? 1 : k % 3 == 1 ? 2 : 4;
            const float *r[4] = {rows, rows + W, rows + 2 * W, rows + 3 * W};
            float wt[4], wt2[4];
            for (int t = 0; t < 4; t++)
                wt[t] = (float)tdem_uniform(&seed), wt2[t] = (float)tdem_uniform(&seed);
            /* the offset ix + fx of a sample on the grid for cells [x0, x1]
             * of the row: x + ix + fx in [0, W - 1] (the runs keep such cells) */
            int ix = (int)((2.0 * tdem_uniform(&seed) - 1.0) * W);
            float fx = k % 5 == 0 ? 0.0f : (float)tdem_uniform(&seed);
            int lo = ix < 0 ? -ix : 0, hi = W - 1 - ix - (fx > 0.0f);
            hi = hi > W - 1 ? W - 1 : hi;
            if (lo > hi)
                continue;
            int x0 = lo + (int)(tdem_uniform(&seed) * (hi - lo + 1));
            int x1 = k % 7 == 0 ? hi : x0 + (int)(tdem_uniform(&seed) * (hi - x0 + 1));
            int c;
            runs++;
            if (!one_run(r, wt, wt2, taps, W, ix, fx, R, R2, x0, x1, &seed, &c) && !differ++)
                snprintf(first, sizeof first, "W %d taps %d ix %d fx %g cells [%d, %d]", W,
                         taps, ix, fx, x0, x1);
            compared += c;
        }
    }
    printf("level max, row in registers (one grid row, and two sharing the level rows) against "
           "combine + level run: %d runs, %d compared "
           "(0: no AVX-512 here), %d differ\n",
           runs, compared, differ);
    ck_assert_msg(!differ, "%d runs differ, the first: %s", differ, first);
    ck_assert_int_gt(runs, 800);
    free(rows), free(R), free(R2);
}
END_TEST

/* A 400 m wall (the grid's west column) over a sea-level plain, 30 m cells,
 * seen from 9 to 21 km east with curvature on (k = 0.13): the horizon is
 * atan((400 - (1 - k) d^2 / 2R) / d), the wall read where the ray leaves the
 * grid; (1 + k) would miss it by 0.01 deg at 9 km, 0.02 at 20 km. */
START_TEST(test_curvature_wall)
{
    const int W = 700, H = 8;
    ts_grid g;
    ts_error err;
    tdem_create(&g, W, H, 30.0, 30.0);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            g.z[y * g.stride + x] = x == 0 ? 400.0f : 0.0f;
    ts_pyramid_opts p;
    ts_pyramid_opts_default(&p);
    ts_pyramid *pyr;
    ck_assert_msg(ts_pyramid_build(&g, &p, 0, &pyr, &err) == TS_OK, "%s", err.message);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.edge = TS_EDGE_OPEN;
    ck_assert(o.curvature && o.refraction == 0.13);
    float *out = malloc((size_t)W * H * sizeof *out);
    ck_assert(out);
    ck_assert_msg(ts_pyramid_horizon(pyr, 270.0, &o, out, &err) == TS_OK, "%s", err.message);
    const double c = (1 - 0.13) / (2 * TS_EARTH_RADIUS);
    double worst = 0;
    for (int x = 300; x < W; x++) {
        double d = 30.0 * x, want = atan((400 - c * d * d) / d) * 180 / M_PI;
        ck_assert_msg(fabs(out[4 * W + x] - want) < 2e-3, "wall %.2f km away: %.5f, want %.5f",
                      d / 1000, out[4 * W + x], want);
        worst = fmax(worst, fabs(out[4 * W + x] - want));
    }
    printf("pyramid, curvature on, 400 m wall 9-21 km away: max |horizon - closed form| %.2g "
           "deg (%.5f at 20.97 km)\n", worst, out[4 * W + W - 1]);
    free(out);
    ts_pyramid_free(pyr);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("pyramid_runs");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_level_max_rows_identical);
    tcase_add_test(tc, test_curvature_wall);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
