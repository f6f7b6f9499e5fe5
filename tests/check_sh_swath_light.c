/* Order-4 SH visibility and light of grids (core/sh_visibility.c,
 * core/sh_swath_light.c, core/sh_block512.c): the visibility of hand-set
 * horizon planes against the direct sum, the one-pass swath light on its
 * folded and general paths, a window against the whole grid, the normals
 * made row by row, the AVX-512 block of 16 cells against the cell-by-cell
 * form. The SH algebra itself is in check_sh.c. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sh_block512.h"
#include "sh_internal.h"
#include "terrashade_sh.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

#define N TS_SH_COEFFS

/* The tables, the rotations and the per-cell sums, on a flat grid whose
 * horizons are set by hand, against ts_sh_swath_visibility_flat. */
START_TEST(visibility_planes)
{
    ts_grid g;
    ts_error err;
    tdem_create(&g, 5, 3, 1, 1);
    size_t cells = 15;
    float *plane = tdem_floats(cells);
    ts_sh_swath swaths[2];
    ts_sh_swath_complete(&swaths[0], 8, 10);
    ts_sh_swath_key(&swaths[1], 3, 120, 30, 10);
    for (int s = 0; s < 2; s++) {
        ts_sh_wedges w;
        ts_sh_visibility v;
        ck_assert_msg(ts_sh_wedges_build(&swaths[s], 0, &w, &err) == TS_OK, "%s", err.message);
        ck_assert(ts_sh_visibility_init(&v, &g, &w, &err) == TS_OK);
        for (int k = 0; k < swaths[s].n; k++) {
            for (size_t c = 0; c < cells; c++)
                plane[c] = c == 7 ? NAN : (float)(c * 5.0 - 3); /* cell c: horizon 5c - 3 */
            ck_assert_msg(ts_sh_visibility_add(&v, k, plane, &err) == TS_OK, "%s", err.message);
        }
        ck_assert(ts_sh_visibility_finish(&v, &err) == TS_OK);
        double worst = 0;
        for (size_t c = 0; c < cells; c++) {
            double ref[N];
            if (c == 7) {
                ck_assert(isnan(v.vis[c * N]));
                continue;
            }
            /* the tables' nodes are every 90/255 deg; 5c - 3 needs interpolation */
            ts_sh_swath_visibility_flat(&swaths[s], c * 5.0 - 3, ref);
            for (int i = 0; i < N; i++)
                worst = fmax(worst, fabs(v.vis[c * N + i] - ref[i]));
        }
        printf("%s swath: visibility from the tables within %.2e of the direct sum\n",
               s ? "partial" : "complete", worst);
        ck_assert(worst < (s ? 2e-5 : 2e-4));
        /* the one-pass form gives the same visible share as the stored visibility */
        double l[N] = {0.5, 0.1, 0.3, -0.2, 0.05, 0.1, 0.2, -0.1, 0.1, 0.02, 0.03, 0.04, 0.05,
                       -0.02, 0.01, 0.03};
        float *share = tdem_floats(cells), *stored = tdem_floats(cells);
        const float *planes[8];
        for (int k = 0; k < swaths[s].n; k++)
            planes[k] = plane;
        ck_assert_msg(ts_sh_swath_light(&g, &w, planes, l, NULL, NULL, NULL, 0, NULL, 0.5,
                                        share, &err) == TS_OK, "%s", err.message);
        ck_assert(ts_sh_visible_share(&g, l, v.vis, 0.5, 0, stored, &err) == TS_OK);
        for (size_t c = 0; c < cells; c++)
            ck_assert(c == 7 ? isnan(share[c]) && isnan(stored[c])
                             : fabsf(share[c] - stored[c]) < 1e-6f);
        /* shade with some planes of normals but not all */
        EXPECT_ARG(ts_sh_swath_light(&g, &w, planes, l, plane, NULL, NULL, 1, share, 0, NULL,
                                     &err), &err);
        free(share), free(stored);
        /* a plane out of order is refused */
        EXPECT_ARG(ts_sh_visibility_add(&v, 0, plane, &err), &err);
        ts_sh_visibility_free(&v);
        ts_sh_wedges_free(&w);
    }
    free(plane);
    ts_grid_free(&g);
}
END_TEST

/* The one-pass form on a grid large enough for its folded per-slot tables
 * (core/sh_swath_light.c) against the stored visibility, ts_sh_shade and
 * ts_sh_visible_share: horizons varied per cell and sample (below 0, above
 * 90, a NaN), normals varied (one NaN). */
START_TEST(swath_light_folded)
{
    const int W = 400, H = 340; /* 136000 cells: past the folding's threshold */
    const size_t cells = (size_t)W * H;
    ts_grid g;
    ts_error err;
    tdem_create(&g, W, H, 1, 1);
    float *nx = tdem_floats(cells), *ny = tdem_floats(cells), *nz = tdem_floats(cells);
    for (size_t c = 0; c < cells; c++) {
        double a = 0.37 * (double)c, t = 0.6 * fabs(sin(0.011 * (double)c));
        nx[c] = (float)(sin(t) * cos(a)), ny[c] = (float)(sin(t) * sin(a)), nz[c] = (float)cos(t);
    }
    nz[11] = NAN;
    ts_sh_swath swaths[2];
    ts_sh_swath_complete(&swaths[0], 2, 30); /* 2 interior slots, as the key's 3 */
    ts_sh_swath_key(&swaths[1], 3, 315, 35, 4);
    for (int s = 0; s < 2; s++) {
        const int n = swaths[s].n;
        ts_sh_wedges w;
        ts_sh_visibility v;
        float *planes[3];
        ck_assert_msg(ts_sh_wedges_build(&swaths[s], 0, &w, &err) == TS_OK, "%s", err.message);
        ck_assert(ts_sh_visibility_init(&v, &g, &w, &err) == TS_OK);
        for (int k = 0; k < n; k++) {
            planes[k] = tdem_floats(cells);
            for (size_t c = 0; c < cells; c++) /* -10 .. 100 degrees */
                planes[k][c] = (float)(45 + 55 * sin(0.013 * (double)c + 1.7 * k));
            planes[k][5] = k == n - 1 ? NAN : planes[k][5];
            ck_assert(ts_sh_visibility_add(&v, k, planes[k], &err) == TS_OK);
        }
        ck_assert(ts_sh_visibility_finish(&v, &err) == TS_OK);
        double l[N], m[N][N];
        ts_sh_key_light(315, 35, 4, l);
        ts_sh_product_matrix(l, m);
        float *shade = tdem_floats(cells), *share = tdem_floats(cells);
        float *ref_shade = tdem_floats(cells), *ref_share = tdem_floats(cells);
        ck_assert_msg(ts_sh_swath_light(&g, &w, (const float *const *)planes, l, nx, ny, nz, 2,
                                        shade, 3, share, &err) == TS_OK, "%s", err.message);
        ck_assert(ts_sh_shade(&g, m, nx, ny, nz, v.vis, 2, 1, ref_shade, &err) == TS_OK);
        ck_assert(ts_sh_visible_share(&g, l, v.vis, 3, 2, ref_share, &err) == TS_OK);
        double worst = 0;
        for (size_t c = 0; c < cells; c++) {
            ck_assert(isnan(shade[c]) == isnan(ref_shade[c]));
            ck_assert(isnan(share[c]) == isnan(ref_share[c]));
            if (!isnan(shade[c]))
                worst = fmax(worst, fabs(shade[c] - ref_shade[c]));
            if (!isnan(share[c]))
                worst = fmax(worst, fabs(share[c] - ref_share[c]));
        }
        ck_assert(isnan(shade[5]) && isnan(share[5]) && isnan(shade[11]) && !isnan(share[11]));
        printf("%s swath, folded tables: shade and share within %.2e of the stored "
               "visibility's\n", s ? "partial" : "complete", worst);
        ck_assert(worst < 2e-6);
        for (int k = 0; k < n; k++)
            free(planes[k]);
        free(shade), free(share), free(ref_shade), free(ref_share);
        ts_sh_visibility_free(&v);
        ts_sh_wedges_free(&w);
    }
    free(nx), free(ny), free(nz);
    ts_grid_free(&g);
}
END_TEST

/* A key light of SWATH_DIRECTIONS=3: its swath and its SH coefficients. */
static void key_of(double az, double el, double radius, ts_sh_swath *sw, double l[N])
{
    ts_sh_swath_key(sw, 3, az, el, radius);
    ts_sh_key_light(az, el, radius, l);
}

/* A window of a large grid, its origin set (ts_grid_origin: the whole
 * grid's size), takes the path the whole grid takes (the folded tables), so
 * that its cells are the whole's bit for bit; as a grid of its own it takes
 * the general path, within float rounding of them. */
START_TEST(swath_light_window_path)
{
    const int W = 400, H = 340, x0 = 123, y0 = 77, w = 61, h = 45;
    const size_t cells = (size_t)W * H, wcells = (size_t)w * h;
    ts_grid g, win;
    ts_error err;
    tdem_create(&g, W, H, 10, 10);
    tdem_fbm(&g, 11, 0.8, 400);
    tdem_create(&win, w, h, 10, 10);
    float *nx = tdem_floats(cells), *ny = tdem_floats(cells), *nz = tdem_floats(cells);
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    ts_sh_swath sw;
    double l[N];
    key_of(200, 30, 1, &sw, l);
    float *planes[3], *wplanes[3], *wn[3];
    for (int k = 0; k < sw.n; k++) {
        planes[k] = tdem_floats(cells);
        wplanes[k] = tdem_floats(wcells);
        for (size_t c = 0; c < cells; c++)
            planes[k][c] = (float)(30 + 35 * sin(0.017 * (double)c + 0.9 * k));
    }
    for (int k = 0; k < 3; k++)
        wn[k] = tdem_floats(wcells);
    /* the window's heights, horizons and normals: a crop */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const size_t c = (size_t)(y0 + y) * W + x0 + x, cw = (size_t)y * w + x;
            win.z[(size_t)y * win.stride + x] = g.z[(size_t)(y0 + y) * g.stride + x0 + x];
            for (int k = 0; k < sw.n; k++)
                wplanes[k][cw] = planes[k][c];
            wn[0][cw] = nx[c], wn[1][cw] = ny[c], wn[2][cw] = nz[c];
        }
    ts_sh_wedges wt;
    ck_assert(ts_sh_wedges_build(&sw, 2, &wt, &err) == TS_OK);
    const ts_grid_origin whole = {x0, y0, 10, W, H};
    float *shade = tdem_floats(cells), *share = tdem_floats(cells);
    float *wshade = tdem_floats(wcells), *wshare = tdem_floats(wcells);
    ck_assert(ts_sh_swath_light(&g, &wt, (const float *const *)planes, l, nx, ny, nz, 1.3, shade,
                                1.1, share, &err) == TS_OK);
    double worst = 0;
    for (int pass = 0; pass < 2; pass++) {
        win.origin = pass ? &whole : NULL; /* a window of the whole grid, or its own */
        ck_assert(ts_sh_swath_light(&win, &wt, (const float *const *)wplanes, l, wn[0], wn[1],
                                    wn[2], 1.3, wshade, 1.1, wshare, &err) == TS_OK);
        int same = 1;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                const size_t c = (size_t)(y0 + y) * W + x0 + x, cw = (size_t)y * w + x;
                same &= wshade[cw] == shade[c] && wshare[cw] == share[c];
                if (!pass)
                    worst = fmax(worst, fmax(fabs(wshade[cw] - shade[c]),
                                             fabs(wshare[cw] - share[c])));
            }
        if (pass)
            ck_assert_msg(same, "the window with its origin is not the whole's bit for bit");
    }
    printf("a %d x %d window on its own path: within %.2e of the whole grid's cells; with its "
           "origin, equal\n", w, h, worst);
    ck_assert(worst > 0 && worst < 2e-6); /* the general path: another rounding */
    for (int k = 0; k < sw.n; k++)
        free(planes[k]), free(wplanes[k]);
    for (int k = 0; k < 3; k++)
        free(wn[k]);
    free(shade), free(share), free(wshade), free(wshare), free(nx), free(ny), free(nz);
    ts_sh_wedges_free(&wt);
    ts_grid_free(&g);
    ts_grid_free(&win);
}
END_TEST

/* Without planes of normals (all three NULL), ts_sh_swath_light makes each
 * row's from the grid as ts_normals does: bit for bit the same shade and
 * share, on the folded path (a large grid, a key's swath) and the general
 * one (a small grid), with one and two threads, nodata in the DEM. */
/* A W x H fbm grid with a hole at (W / 3, H / 2), its normals, a key
 * light's swath (135 deg, 25 deg, radius 2) and made-up horizon planes. */
static void swath_inputs(int W, int H, ts_grid *g, float **nx, float **ny, float **nz,
                         ts_sh_swath *sw, double l[N], float *planes[3])
{
    const size_t cells = (size_t)W * H;
    ts_error err;
    tdem_create(g, W, H, 10, 10);
    tdem_fbm(g, 7, 0.8, 400);
    g->z[(size_t)(H / 2) * g->stride + W / 3] = NAN;
    *nx = tdem_floats(cells), *ny = tdem_floats(cells), *nz = tdem_floats(cells);
    ck_assert(ts_normals(g, *nx, *ny, *nz, &err) == TS_OK);
    key_of(135, 25, 2, sw, l);
    for (int k = 0; k < sw->n; k++) {
        planes[k] = tdem_floats(cells);
        for (size_t c = 0; c < cells; c++)
            planes[k][c] = (float)(20 + 25 * sin(0.029 * (double)c + k));
    }
}

static void swath_inputs_free(ts_grid *g, float *nx, float *ny, float *nz,
                              const ts_sh_swath *sw, float *planes[3])
{
    for (int k = 0; k < sw->n; k++)
        free(planes[k]);
    free(nx), free(ny), free(nz);
    ts_grid_free(g);
}

START_TEST(swath_light_row_normals)
{
    const int sizes[2][2] = {{400, 340}, {37, 23}};
    for (int z = 0; z < 2; z++) {
        const int W = sizes[z][0], H = sizes[z][1];
        const size_t cells = (size_t)W * H;
        ts_grid g;
        ts_error err;
        float *nx, *ny, *nz, *planes[3];
        ts_sh_swath sw;
        double l[N];
        swath_inputs(W, H, &g, &nx, &ny, &nz, &sw, l, planes);
        for (int threads = 1; threads <= 2; threads++) {
            ts_sh_wedges w;
            ck_assert(ts_sh_wedges_build(&sw, threads, &w, &err) == TS_OK);
            float *shade = tdem_floats(cells), *share = tdem_floats(cells);
            float *shade_rows = tdem_floats(cells), *share_rows = tdem_floats(cells);
            ck_assert(ts_sh_swath_light(&g, &w, (const float *const *)planes, l, nx, ny, nz, 1.5,
                                        shade, 1.2, share, &err) == TS_OK);
            ck_assert_msg(ts_sh_swath_light(&g, &w, (const float *const *)planes, l, NULL, NULL,
                                            NULL, 1.5, shade_rows, 1.2, share_rows,
                                            &err) == TS_OK, "%s", err.message);
            ck_assert(memcmp(shade, shade_rows, cells * sizeof(float)) == 0);
            ck_assert(memcmp(share, share_rows, cells * sizeof(float)) == 0);
            size_t nodata = 0;
            for (size_t c = 0; c < cells; c++)
                nodata += isnan(shade[c]);
            ck_assert(nodata > 0 && nodata < 20); /* the hole's neighbours */
            /* one plane of normals without the others */
            EXPECT_ARG(ts_sh_swath_light(&g, &w, (const float *const *)planes, l, nx, NULL, nz,
                                         1, shade, 1, NULL, &err),
                       &err);
            free(shade), free(share), free(shade_rows), free(share_rows);
            ts_sh_wedges_free(&w);
        }
        swath_inputs_free(&g, nx, ny, nz, &sw, planes);
    }
}
END_TEST

/* ts_sh_swath_light_reported: the cells of ts_sh_swath_light bit for bit,
 * about 33 reports from `from` to below `to`, in order, at 1 and 2
 * threads, with the normals' planes and made row by row (the rows in
 * batches between reports); a callback that stops ends it with
 * TS_ERR_CANCELLED and no report after. */
START_TEST(swath_light_reported)
{
    const int W = 300, H = 211;
    const size_t cells = (size_t)W * H;
    ts_grid g;
    ts_error err;
    float *nx, *ny, *nz, *planes[3];
    ts_sh_swath sw;
    double l[N];
    swath_inputs(W, H, &g, &nx, &ny, &nz, &sw, l, planes);
    for (int threads = 1; threads <= 2; threads++)
        for (int rows = 0; rows < 2; rows++) {
            ts_sh_wedges w;
            ck_assert(ts_sh_wedges_build(&sw, threads, &w, &err) == TS_OK);
            float *shade = tdem_floats(cells), *got = tdem_floats(cells);
            const float *n[3] = {rows ? NULL : nx, rows ? NULL : ny, rows ? NULL : nz};
            ck_assert(ts_sh_swath_light(&g, &w, (const float *const *)planes, l, n[0], n[1],
                                        n[2], 1.5, shade, 0, NULL, &err) == TS_OK);
            ts_horizon_opts h;
            ts_horizon_opts_default(&h);
            tprog r = {0, -1, 0, -1};
            h.progress = tprog_log;
            h.progress_user = &r;
            ck_assert_msg(ts_sh_swath_light_reported(&g, &w, (const float *const *)planes, l,
                                                     n[0], n[1], n[2], 1.5, got, 0, NULL, &h,
                                                     0.75, 1.0, &err) == TS_OK,
                          "%s", err.message);
            ck_assert(memcmp(shade, got, cells * sizeof(float)) == 0);
            ck_assert_int_eq(r.calls, 33); /* before the tables, and before each batch */
            ck_assert(r.first == 0.75 && r.last < 1.0 && r.last > 0.99);
            tprog stop = {0, 5, 0, -1};
            h.progress_user = &stop;
            ck_assert(ts_sh_swath_light_reported(&g, &w, (const float *const *)planes, l, n[0],
                                                 n[1], n[2], 1.5, got, 0, NULL, &h, 0.75, 1.0,
                                                 &err) == TS_ERR_CANCELLED);
            ck_assert_int_eq(stop.calls, 5);
            free(shade), free(got);
            ts_sh_wedges_free(&w);
        }
    swath_inputs_free(&g, nx, ny, nz, &sw, planes);
}
END_TEST

/* The AVX-512 block of 16 cells (core/sh_block512.c) against the cell-by-cell
 * form it replaces (TS_SH_BASIS, ts_sh_sum16, the clamp), bit for bit:
 * coefficients and normals varied, results of both signs, a NaN normal, a
 * NaN coefficient, skipped cells left as they were. Where the CPU has no
 * AVX-512 the block does nothing and says so (returns 0). */
START_TEST(block_shade_avx512)
{
    float acc[16][N] __attribute__((aligned(64)));
    float nx[16], ny[16], nz[16], out[16], want[16];
    int done = 0;
    for (int round = 0; round < 200; round++) {
        for (int j = 0; j < 16; j++) {
            double a = 0.91 * (round * 16 + j), t = 1.4 * fabs(sin(0.37 * (round * 16 + j)));
            nx[j] = (float)(sin(t) * cos(a)), ny[j] = (float)(sin(t) * sin(a));
            nz[j] = (float)cos(t);
            for (int k = 0; k < N; k++)
                acc[j][k] = (float)(sin(1.3 * k + 0.7 * j + 0.11 * round) * (k ? 0.6 : 1.1));
        }
        if (round == 3)
            nz[5] = NAN, acc[9][4] = NAN;
        const unsigned skip = round % 4 == 1 ? 0x8421u : 0;
        const float scale = 1.7f;
        for (int j = 0; j < 16; j++) {
            float yn[N], p[N];
            TS_SH_BASIS(float, nx[j], ny[j], nz[j], yn);
            for (int k = 0; k < N; k++)
                p[k] = acc[j][k] * yn[k];
            float t = ts_sh_sum16(p) * scale;
            want[j] = skip >> j & 1 ? -7.0f : t == t ? (t < 0 ? 0 : t) : NAN;
            out[j] = -7.0f;
        }
        if (!ts_sh_block_shade512((const float(*)[N])acc, nx, ny, nz, scale, skip, out))
            break;
        done++;
        ck_assert(memcmp(out, want, sizeof out) == 0);
        if (round == 3)
            ck_assert(isnan(out[5]) && isnan(out[9]));
    }
    printf("AVX-512 block shade: %s\n", done ? "200 blocks bit for bit the cell-by-cell form"
                                              : "no AVX-512 here: the cell-by-cell form runs");
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("sh_swath_light");
    TCase *tc = tcase_create("swath_light");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, visibility_planes);
    tcase_add_test(tc, swath_light_folded);
    tcase_add_test(tc, swath_light_window_path);
    tcase_add_test(tc, swath_light_row_normals);
    tcase_add_test(tc, swath_light_reported);
    tcase_add_test(tc, block_shade_avx512);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IONBF, 0); /* the numbers even of a failing test */
    return test_run_suite_mode(suite(), CK_VERBOSE);
}
