/*
 * The sweep's vectorised near field against the per-cell one it stands for,
 * cm_near_exact (ts_near_field), on DEMs with speckled nodata: every cell
 * whose near field touches nodata, and every cell of the edges, must get
 * the per-cell answer bit for bit (the vector loops redo the double
 * arithmetic, nodata branch and all); the other interior cells take the
 * float fast path and must agree to float precision.
 */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "line_geometry.h"
#include "near_field.h"
#include "terrashade.h"
#include "test_dem.h"
#include "test_run.h"

static const double AZ[] = {0, 33.7, 45, 90, 137, 180, 222.2, 270, 300, 351.5};
#define N_AZ ((int)(sizeof AZ / sizeof AZ[0]))

/* A W x H fBm DEM of 10 m cells with a fraction `voids` of its cells
 * nodata, scattered, and a 3 x 4 block of them. */
static void speckled_dem(ts_grid *g, int W, int H, double voids, uint32_t seed)
{
    ts_error e;
    ck_assert_int_eq(ts_grid_create(g, W, H, 10.0, 10.0, &e), TS_OK);
    tdem_fbm(g, seed, 0.8, 400.0);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if (tdem_xorshift32(&seed) % 100000 < voids * 100000 ||
                (x >= W / 2 && x < W / 2 + 3 && y >= H / 3 && y < H / 3 + 4))
                g->z[(ptrdiff_t)y * g->stride + x] = NAN;
}

/* Whether a piece of cell x of row y has a nodata corner. */
static int touches_nodata(const ts_near_plan *p, const float *zrow, int x)
{
    for (int n = 0; n < p->npieces; n++)
        for (int j = 0; j < 4; j++)
            if (isnan(zrow[x + p->piece_off[n][j]]))
                return 1;
    return 0;
}

/* ts_near_field of cell x of row y, as the sweep places it. */
static float per_cell(const ts_near_plan *p, const ts_line_geom *G, const ts_grid *g, int y,
                      int x, double step, double c, double cap, int *left)
{
    const int u = G->x_major ? x : y, v = G->x_major ? y : x;
    return ts_near_field(p, G, g->z, (u - G->u_start) * G->u_step, v,
                         g->z[(ptrdiff_t)y * g->stride + x], step, c, cap, left);
}

typedef struct {
    long exact_cells, fast_cells, edge_cells;
    long exact_bad, fast_bad, edge_bad;
    char first[256];
} tally;

static void bad(tally *t, long *count, const char *what, double az, int y, int x, float got,
                float want)
{
    if (t->exact_bad + t->fast_bad + t->edge_bad == 0)
        snprintf(t->first, sizeof t->first, "%s: azimuth %g, row %d, cell %d: %.9g, want %.9g",
                 what, az, y, x, got, want);
    (*count)++;
}

/* Every row of g toward azimuth az: ts_near_row over the interior and
 * ts_near_edges over the rest against per_cell, from a far field of
 * pseudo-random slopes (some above the near field, most below). */
static void check_rows(const ts_grid *g, double az, double c, double cap, tally *t)
{
    ts_error e;
    ts_line_geom G;
    ck_assert_int_eq(ts_line_geom_init(&G, g, az, &e), TS_OK);
    ts_near_plan p;
    ts_near_plan_init(&p, &G);
    const int W = g->width, H = g->height, m = TS_NEAR_MARGIN;
    float *scratch = malloc(TS_NEAR_ROW_SCRATCH(W) * sizeof *scratch);
    float *got = malloc(W * sizeof *got), *far = malloc(W * sizeof *far);
    ck_assert_ptr_nonnull(scratch);
    ck_assert_ptr_nonnull(got);
    ck_assert_ptr_nonnull(far);
    uint32_t seed = 77;
    for (int y = 0; y < H; y++) {
        const float *zrow = g->z + (ptrdiff_t)y * g->stride;
        const double step = G.step_row ? G.step_row[y] : G.step_m;
        for (int x = 0; x < W; x++)
            far[x] = (float)((tdem_xorshift32(&seed) % 2000) / 1000.0 - 1.5);
        memcpy(got, far, W * sizeof *got);
        const int interior = cap == 0 && y >= m && y < H - m && W > 2 * m;
        const int xa = interior ? m : W, xb = interior ? W - m : W;
        if (interior)
            ts_near_row(&p, zrow, xa, xb, step, c, got, scratch);
        ts_near_edges(&p, &G, g->z, zrow, y, xa, xb, W, step, c, cap, got, scratch);
        for (int x = 0; x < W; x++) {
            if (isnan(zrow[x]))
                continue;
            int left;
            const float nf = per_cell(&p, &G, g, y, x, step, c, cap, &left);
            const float want = left && !(x >= xa && x < xb) ? nf : fmaxf(nf, far[x]);
            if (x < xa || x >= xb) {
                t->edge_cells++;
                if (memcmp(&got[x], &want, sizeof want))
                    bad(t, &t->edge_bad, "edge cell not bit-identical", az, y, x, got[x], want);
            } else if (touches_nodata(&p, zrow, x)) {
                t->exact_cells++;
                if (memcmp(&got[x], &want, sizeof want))
                    bad(t, &t->exact_bad, "cell beside nodata not bit-identical", az, y, x,
                        got[x], want);
            } else {
                t->fast_cells++;
                if (!(fabsf(got[x] - want) <= 1e-4f * fmaxf(1.0f, fabsf(want))))
                    bad(t, &t->fast_bad, "fast path off", az, y, x, got[x], want);
            }
        }
    }
    free(scratch);
    free(got);
    free(far);
    ts_line_geom_free(&G);
}

static void check_dem(const char *name, const ts_grid *g, double cap)
{
    tally t = {0};
    const double c = 1.0 / (2.0 * TS_EARTH_RADIUS) * 0.87; /* curvature and refraction */
    for (int a = 0; a < N_AZ; a++) {
        check_rows(g, AZ[a], a & 1 ? c : 0.0, cap, &t);
    }
    printf("  %-40s cap %5g m: %ld cells beside nodata, %ld fast, %ld edge cells checked\n",
           name, cap, t.exact_cells, t.fast_cells, t.edge_cells);
    ck_assert_msg(t.exact_bad + t.fast_bad + t.edge_bad == 0,
                  "%s: %ld beside nodata, %ld fast, %ld edge cells differ; first: %s", name,
                  t.exact_bad, t.fast_bad, t.edge_bad, t.first);
    ck_assert_msg(cap > 0 || t.exact_cells > 0, "%s: no cell beside nodata was checked", name);
}

START_TEST(test_speckled_voids)
{
    /* 131 wide: rows of fewer listed cells than a chunk of the gathered
     * list; 420 wide at 3 %: several chunks a row */
    const double voids[] = {0.01, 0.1, 0.5, 0.03};
    const int widths[] = {131, 131, 131, 420};
    for (int i = 0; i < 4; i++) {
        ts_grid g;
        speckled_dem(&g, widths[i], 97, voids[i], 11 + i);
        char name[64];
        snprintf(name, sizeof name, "%d x 97, %g %% voids", widths[i], voids[i] * 100);
        check_dem(name, &g, 0.0);
        ts_grid_free(&g);
    }
}
END_TEST

/* A distance cap inside the near field (the sweep then runs every cell
 * through ts_near_edges), and geographic rows. */
START_TEST(test_capped_and_geographic)
{
    ts_grid g;
    ts_error e;
    speckled_dem(&g, 90, 120, 0.08, 5);
    check_dem("90 x 120, 8 % voids", &g, 35.0);
    check_dem("90 x 120, 8 % voids", &g, 73.0);
    double cx[120];
    for (int y = 0; y < 120; y++)
        cx[y] = 10.0 * cos((60.0 - y * 0.01) * 3.14159265358979323846 / 180.0);
    ck_assert_int_eq(ts_grid_set_row_spacing(&g, cx, &e), TS_OK);
    check_dem("90 x 120, 8 % voids, geographic", &g, 0.0);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("near_field");
    TCase *tc = tcase_create("voids");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_speckled_voids);
    tcase_add_test(tc, test_capped_and_geographic);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
