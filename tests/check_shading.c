/* Shading: sun disk, Horn normals, direct sun, sky terms, combination. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

static const double PI = 3.14159265358979323846;
static const double DEG = 3.14159265358979323846 / 180.0;

/* Area fraction of a disk of radius r whose centre is t above a line. */
static double segment_fraction(double t, double r)
{
    double u = t / r;
    if (u >= 1) return 1;
    if (u <= -1) return 0;
    return 1.0 - (acos(u) - u * sqrt(1 - u * u)) / PI;
}

START_TEST(test_sun_disk_fraction)
{
    const double r = TS_SUN_RADIUS_DEG;
    const double horizons[] = {-90, -3.2, 0, 12.5, 89};
    for (int k = 0; k < 5; k++) {
        double h = horizons[k];
        ck_assert(ts_sun_disk_fraction(h + r + 1e-9, h) == 1.0);
        ck_assert(ts_sun_disk_fraction(h + 5, h) == 1.0);
        ck_assert(ts_sun_disk_fraction(h - r - 1e-9, h) == 0.0);
        ck_assert(ts_sun_disk_fraction(h - 5, h) == 0.0);
        ck_assert_msg(fabs(ts_sun_disk_fraction(h, h) - 0.5) < 1e-9, "at h = %g: %g", h,
                      ts_sun_disk_fraction(h, h));
        double prev = -1;
        for (double t = -0.4; t <= 0.4; t += 0.001) {
            double f = ts_sun_disk_fraction(h + t, h);
            ck_assert_msg(f >= prev, "not monotonic at t = %g: %g < %g", t, f, prev);
            ck_assert_msg(fabs(f - segment_fraction(t, r)) <= 1e-3,
                          "t = %g: %g, disk segment area %g", t, f, segment_fraction(t, r));
            prev = f;
        }
    }
    ck_assert(ts_sun_disk_fraction(90, 90) <= 0.5 + 1e-9);
    ck_assert(ts_sun_disk_fraction(10, -90) == 1.0);
}
END_TEST

/* gdaldem's -compute_edges extrapolation of the cell beyond a and b:
 * 2 a - b in float (NaN from NaN). */
static double beyond(double a, double b)
{
    return 2.0f * (float)a - (float)b;
}

/* Horn (as gdaldem hillshade -compute_edges): a..i the 3x3 neighbourhood
 * from the north-west, row by row, built as gdaldem builds its window: on
 * the first and last rows the row beyond extrapolated from the edge's and
 * the next row's, with the columns beyond the edge's own (jmin, jmax); on
 * the other rows the first and last columns' outer column extrapolated;
 * on a grid under 2 x 2, missing neighbours are the centre's; nodata
 * neighbours (or extrapolated from nodata) the centre's. Normal (east,
 * north, up) = normalize(-dz/dx, dz/drow, 1): rows run south, so the
 * northward slope is -dz/drow. */
static void horn(const ts_grid *g, int x, int y, double n[3])
{
    const int W = g->width, H = g->height;
    double e = ts_grid_at(g, x, y), v[3][3];
    if (W >= 2 && H >= 2 && (y == 0 || y == H - 1)) {
        int cols[3] = {x == 0 ? x : x - 1, x, x == W - 1 ? x : x + 1};
        for (int c = 0; c < 3; c++) {
            double edge = ts_grid_at(g, cols[c], y);
            double next = ts_grid_at(g, cols[c], y == 0 ? 1 : H - 2);
            v[1][c] = edge;
            v[0][c] = y == 0 ? beyond(edge, next) : next;
            v[2][c] = y == 0 ? next : beyond(edge, next);
        }
    } else if (W >= 2 && H >= 2 && (x == 0 || x == W - 1)) {
        for (int r = 0; r < 3; r++) {
            double edge = ts_grid_at(g, x, y - 1 + r);
            double next = ts_grid_at(g, x == 0 ? 1 : W - 2, y - 1 + r);
            v[r][1] = edge;
            v[r][0] = x == 0 ? beyond(edge, next) : next;
            v[r][2] = x == 0 ? next : beyond(edge, next);
        }
    } else {
        for (int j = -1; j <= 1; j++)
            for (int i = -1; i <= 1; i++) {
                int xx = x + i, yy = y + j;
                v[j + 1][i + 1] = xx >= 0 && xx < W && yy >= 0 && yy < H
                                      ? ts_grid_at(g, xx, yy) : NAN;
            }
    }
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            v[j][i] = isnan(v[j][i]) ? e : v[j][i];
    double a = v[0][0], b = v[0][1], c = v[0][2], d = v[1][0], f = v[1][2];
    double gg = v[2][0], h = v[2][1], i = v[2][2];
    double dzdx = ((c + 2 * f + i) - (a + 2 * d + gg)) / (8 * ts_grid_cell_x(g, y));
    double dzdrow = ((gg + 2 * h + i) - (a + 2 * b + c)) / (8 * g->cell_y);
    double len = sqrt(dzdx * dzdx + dzdrow * dzdrow + 1);
    n[0] = -dzdx / len;
    n[1] = dzdrow / len;
    n[2] = 1 / len;
}

static void check_normals(const ts_grid *g, const char *label)
{
    size_t n = (size_t)g->width * g->height;
    float *nx = tdem_floats(n), *ny = tdem_floats(n), *nz = tdem_floats(n);
    ts_error err;
    ck_assert_msg(ts_normals(g, nx, ny, nz, &err) == TS_OK, "%s", err.message);
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            size_t k = (size_t)y * g->width + x;
            if (isnan(ts_grid_at(g, x, y))) {
                ck_assert_msg(isnan(nx[k]) && isnan(ny[k]) && isnan(nz[k]),
                              "%s (%d,%d): nodata normal not NaN", label, x, y);
                continue;
            }
            double w[3];
            horn(g, x, y, w);
            ck_assert_msg(fabs(nx[k] - w[0]) < 1e-5 && fabs(ny[k] - w[1]) < 1e-5 &&
                          fabs(nz[k] - w[2]) < 1e-5,
                          "%s (%d,%d): (%g, %g, %g), Horn (%g, %g, %g)", label, x, y,
                          nx[k], ny[k], nz[k], w[0], w[1], w[2]);
        }
    free(nx); free(ny); free(nz);
}

START_TEST(test_normals_horn)
{
    ts_grid g;
    tdem_create(&g, 50, 40, 10.0, 15.0);
    tdem_fractal(&g, 3, 200.0);
    check_normals(&g, "fractal 10x15 m");
    g.z[20 * g.stride + 20] = NAN; /* neighbours use the centre instead */
    g.z[0 * g.stride + 7] = NAN;
    g.z[39 * g.stride + 49] = NAN;
    check_normals(&g, "fractal with nodata");
    ts_grid_free(&g);
    /* small grids, where the edges are most of it: 2 x N, N x 2, 2 x 2,
     * 1 x N, N x 1, with nodata beside an edge */
    const int sizes[][2] = {{2, 7}, {7, 2}, {2, 2}, {3, 3}, {1, 6}, {6, 1}, {5, 4}};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        tdem_create(&g, sizes[k][0], sizes[k][1], 10.0, 15.0);
        tdem_fractal(&g, 7 + k, 80.0);
        check_normals(&g, "small");
        if (g.width * g.height > 3) {
            g.z[g.width > 1 ? 1 : g.stride] = NAN;
            check_normals(&g, "small with nodata");
        }
        ts_grid_free(&g);
    }
}
END_TEST

START_TEST(test_normals_plane_edges)
{
    /* A plane's edge cells have its slope, as gdaldem -compute_edges gives
     * them (a missing neighbour as the centre's height halved a slope across
     * the edge, session 56), but for the four corners along the first and
     * last rows, whose columns beyond are the edge's own in gdaldem. */
    ts_grid g;
    const int W = 7, H = 6;
    tdem_create(&g, W, H, 10.0, 20.0);
    const double sx = 0.4, sn = -0.25; /* rise to the east, to the north */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            g.z[y * g.stride + x] = (float)(100 + sx * x * 10.0 + sn * (H - 1 - y) * 20.0);
    float nx[42], ny[42], nz[42];
    ts_error err;
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    const double len = sqrt(1 + sx * sx + sn * sn);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const int k = y * W + x;
            const int corner = (y == 0 || y == H - 1) && (x == 0 || x == W - 1);
            /* a corner: the east-west slope is halved, the north-south kept */
            const double ex = corner ? sx / 2 : sx;
            const double l = corner ? sqrt(1 + ex * ex + sn * sn) : len;
            ck_assert_msg(fabs(nx[k] + ex / l) < 1e-6 && fabs(ny[k] + sn / l) < 1e-6 &&
                              fabs(nz[k] - 1 / l) < 1e-6,
                          "(%d,%d): (%g, %g, %g)", x, y, nx[k], ny[k], nz[k]);
        }
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_normals_signs)
{
    /* rising to the east: normal leans west; rising to the north: south */
    ts_grid g;
    tdem_create(&g, 9, 9, 10.0, 20.0);
    for (int y = 0; y < 9; y++)
        for (int x = 0; x < 9; x++)
            g.z[y * g.stride + x] = (float)(0.5 * x * 10.0);
    float nx[81], ny[81], nz[81];
    ts_error err;
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    ck_assert_msg(fabs(nx[40] + 0.5 / sqrt(1.25)) < 1e-6 && fabs(ny[40]) < 1e-6,
                  "east-rising: (%g, %g, %g)", nx[40], ny[40], nz[40]);
    for (int y = 0; y < 9; y++)
        for (int x = 0; x < 9; x++)
            g.z[y * g.stride + x] = (float)(0.3 * (8 - y) * 20.0);
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    ck_assert_msg(fabs(ny[40] + 0.3 / sqrt(1.09)) < 1e-6 && fabs(nx[40]) < 1e-6,
                  "north-rising: (%g, %g, %g)", nx[40], ny[40], nz[40]);
    ts_grid_free(&g);
}
END_TEST

/* Horizons (curvature off, `dirs` directions from 0) and normals of g. */
typedef struct { size_t n; ts_horizon_opts o; float *hor, *nx, *ny, *nz; } lit;

static lit light_setup_dirs(const ts_grid *g, int dirs)
{
    lit L;
    L.n = (size_t)g->width * g->height;
    ts_horizon_opts_default(&L.o);
    L.o.curvature = 0;
    L.o.directions = dirs;
    L.hor = tdem_floats(L.n * (size_t)dirs);
    L.nx = tdem_floats(L.n), L.ny = tdem_floats(L.n), L.nz = tdem_floats(L.n);
    ts_error err;
    ck_assert_msg(ts_horizon_compute(g, &L.o, L.hor, &err) == TS_OK, "%s", err.message);
    ck_assert_msg(ts_normals(g, L.nx, L.ny, L.nz, &err) == TS_OK, "%s", err.message);
    return L;
}

static lit light_setup(const ts_grid *g) { return light_setup_dirs(g, 16); }

static void light_free(lit *L)
{
    free(L->hor); free(L->nx); free(L->ny); free(L->nz);
}

static void direct(const ts_grid *g, const lit *L, double az, double el, float *out)
{
    ts_error err;
    const ts_direct_request req = {g,  L->nx, L->ny, L->nz, L->hor, &L->o,
                                   az, el,    out,   TS_SUN_RADIUS_DEG};
    ck_assert_msg(ts_shade_direct(&req, &err) == TS_OK, "%s", err.message);
}

/* The radiative sky terms of the lit grid. */
static void sky_terms(const ts_grid *g, const lit *L, float *svf, float *sky, float *op)
{
    ts_error err;
    const ts_sky_request req = {g, L->nx, L->ny, L->nz, L->hor, &L->o, TS_SVF_RADIATIVE,
                                svf, sky, op};
    ck_assert_msg(ts_sky_terms(&req, &err) == TS_OK, "%s", err.message);
}

/* A geographic grid (0.01 deg cells, rows from 66 N to 62 N: each row its own
 * east-west width) holding a surface that rises 0.08 m per metre east: every
 * row has the east component -0.08 / sqrt(1.0064) of the normal and, lit
 * from due west at 45 deg (N.L does not read the north component, which the
 * converging columns tilt a little), N.L = 1.08 sin 45 / sqrt(1.0064) =
 * 0.761243 (interior cells). */
START_TEST(test_normals_geographic_rows)
{
    const int W = 24, H = 400;
    const double cy = 0.01 * 111320.0, s = 0.08;
    ts_grid g;
    ts_error err;
    double cx[400];
    tdem_create(&g, W, H, cy, cy);
    for (int y = 0; y < H; y++) {
        cx[y] = cy * cos((66.0 - (y + 0.5) * 0.01) * DEG);
        for (int x = 0; x < W; x++)
            g.z[y * g.stride + x] = (float)(s * (x + 0.5) * cx[y]);
    }
    ck_assert(ts_grid_set_row_spacing(&g, cx, &err) == TS_OK);
    lit L = light_setup_dirs(&g, 8);
    float *out = tdem_floats(L.n);
    direct(&g, &L, 270.0, 45.0, out);
    const double len = sqrt(1 + s * s), want = (s + 1) * sin(45 * DEG) / len;
    double worst = 0;
    for (int y = 1; y < H - 1; y++)
        for (int x = 1; x < W - 1; x++) {
            size_t k = (size_t)y * W + x;
            CK_NEAR(L.nx[k], -s / len, 2e-5, "geographic nx");
            CK_NEAR(out[k], want, 5e-5, "geographic N.L, sun west at 45");
            worst = fmax(worst, fabs(out[k] - want));
        }
    printf("geographic rows 66-62 N, plane rising 0.08 east: N.L %.6f (row 1) %.6f "
           "(row %d), want %.6f, max |diff| %.2g\n", out[W + W / 2],
           out[(size_t)(H - 2) * W + W / 2], H - 2, want, worst);
    free(out);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_direct_flat)
{
    ts_grid g;
    tdem_create(&g, 40, 30, 10.0, 10.0);
    tdem_fill(&g, 100.0f);
    lit L = light_setup(&g);
    float *out = tdem_floats(L.n);
    const double els[] = {10, 30, 60, 89.9};
    for (int e = 0; e < 4; e++) {
        direct(&g, &L, 100.0, els[e], out); /* 100: between computed azimuths */
        for (size_t i = 0; i < L.n; i++)
            ck_assert_msg(fabs(out[i] - sin(els[e] * DEG)) < 1e-5,
                          "flat, sun at %g: cell %zu = %g, want %g", els[e], i, out[i],
                          sin(els[e] * DEG));
    }
    direct(&g, &L, 100.0, -5.0, out);
    for (size_t i = 0; i < L.n; i++)
        ck_assert_msg(out[i] == 0.0f, "sun below the horizon: %g", out[i]);
    /* a sun grazing the horizon: half a disk less a little */
    direct(&g, &L, 100.0, 0.1, out);
    size_t mid = 15 * 40 + 20;
    double want = sin(0.1 * DEG) * ts_sun_disk_fraction(0.1, 0.0);
    ck_assert_msg(fabs(out[mid] - want) < 1e-6, "grazing sun: %g, want %g", out[mid], want);
    free(out);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_direct_tilted)
{
    /* plane facing east at slope 20 deg, sun from the east at 30 deg:
     * N.L = sin(50 deg); it is a plane, so nothing is shadowed */
    const double gam = 20.0;
    ts_grid g;
    tdem_create(&g, 40, 30, 10.0, 10.0);
    for (int y = 0; y < 30; y++)
        for (int x = 0; x < 40; x++)
            g.z[y * g.stride + x] = (float)(tan(gam * DEG) * (39 - x) * 10.0);
    lit L = light_setup(&g);
    float *out = tdem_floats(L.n);
    direct(&g, &L, 90.0, 30.0, out);
    for (int y = 1; y < 29; y++)
        for (int x = 1; x < 39; x++)
            ck_assert_msg(fabs(out[y * 40 + x] - sin(50 * DEG)) < 1e-5,
                          "tilted (%d,%d): %g, want %g", x, y, out[y * 40 + x],
                          sin(50 * DEG));
    free(out);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_direct_pillar_shadow)
{
    /* 200 m pillar, sun from the east (a computed azimuth) at 30 deg: the
     * shadow ends at 346 m; the cell at 350 m sees a sliver of the disk */
    ts_grid g;
    tdem_create(&g, 121, 121, 10.0, 10.0);
    tdem_fill(&g, 0.0f);
    g.z[60 * g.stride + 60] = 200.0f;
    lit L = light_setup(&g);
    float *out = tdem_floats(L.n);
    direct(&g, &L, 90.0, 30.0, out);
    for (int n = 2; n <= 60; n++) {
        double v = out[60 * 121 + 60 - n], d = n * 10.0;
        double want = sin(30 * DEG) * ts_sun_disk_fraction(30.0, atan(200.0 / d) / DEG);
        if (n <= 34)
            ck_assert_msg(v == 0.0, "pillar shadow at %g m: %g, want 0", d, v);
        else if (n >= 36)
            ck_assert_msg(fabs(v - 0.5) < 1e-5, "past the shadow at %g m: %g", d, v);
        ck_assert_msg(fabs(v - want) < 2e-3, "at %g m: %g, want %g", d, v, want);
    }
    free(out);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_combine)
{
    ts_grid g;
    tdem_create(&g, 6, 1, 10.0, 10.0);
    float d[6] = {0.2f, 0.9f, NAN, -0.5f, 0.0f, 1.5f};
    const float s[6] = {0.5f, 0.5f, 0.5f, 0.2f, NAN, 0.0f};
    const float want[6] = {0.4f, 1.0f, NAN, 0.0f, NAN, 1.0f};
    float out[6];
    ts_error err;
    ck_assert(ts_shade_combine(&g, d, s, 0.4, out, &err) == TS_OK);
    ck_assert(ts_shade_combine(&g, d, s, 0.4, d, &err) == TS_OK); /* in place */
    for (int i = 0; i < 6; i++) {
        if (isnan(want[i])) {
            ck_assert_msg(isnan(out[i]) && isnan(d[i]), "cell %d: NaN became %g", i, out[i]);
            continue;
        }
        ck_assert_msg(fabsf(out[i] - want[i]) < 1e-6f, "cell %d: %g, want %g", i, out[i],
                      want[i]);
        ck_assert_msg(out[i] == d[i], "cell %d: in place %g != %g", i, d[i], out[i]);
    }
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_sky_flat_and_tilted)
{
    /* open flat plane: svf = sky = 1, openness 90 in the interior; a tilted
     * plane (slope 25 deg): svf = 1 (the terrain is the tangent plane),
     * sky = (1 + cos 25) / 2 (the sky ends at the horizontal). 64
     * directions: with 16, sectors of constant horizon cost ~1e-3 */
    for (int tilted = 0; tilted <= 1; tilted++) {
        const double gam = tilted ? 25.0 : 0.0;
        ts_grid g;
        tdem_create(&g, 40, 30, 10.0, 10.0);
        for (int y = 0; y < 30; y++)
            for (int x = 0; x < 40; x++)
                g.z[y * g.stride + x] = (float)(tan(gam * DEG) * y * 10.0 + 50.0);
        lit L = light_setup_dirs(&g, 64);
        float *svf = tdem_floats(L.n), *sky = tdem_floats(L.n), *op = tdem_floats(L.n);
        sky_terms(&g, &L, svf, sky, op);
        double want_sky = (1 + cos(gam * DEG)) / 2;
        for (int y = 1; y < 29; y++)
            for (int x = 1; x < 39; x++) {
                size_t i = (size_t)y * 40 + x;
                ck_assert_msg(fabs(svf[i] - 1) < (tilted ? 1e-3 : 1e-5), "slope %g (%d,%d): svf %g",
                              gam, x, y, svf[i]);
                ck_assert_msg(fabs(sky[i] - want_sky) < (tilted ? 1e-3 : 1e-5),
                              "slope %g (%d,%d): sky %g, "
                              "want %g", gam, x, y, sky[i], want_sky);
                if (!tilted)
                    ck_assert_msg(fabs(op[i] - 90) < 1e-4, "(%d,%d): openness %g", x, y,
                                  op[i]);
            }
        printf("sky terms, plane of slope %g: svf %.6f sky %.6f (want %.6f) openness %.4f\n",
               gam, svf[15 * 40 + 20], sky[15 * 40 + 20], want_sky, op[15 * 40 + 20]);
        free(svf); free(sky); free(op);
        light_free(&L);
        ts_grid_free(&g);
    }
}
END_TEST

START_TEST(test_sky_rough)
{
    /* rough terrain with nodata: openness is the mean of 90 - horizon,
     * sky <= svf (the sky raises the horizon to 0), all in range, and the
     * accumulating form gives the same as ts_sky_terms */
    ts_grid g;
    tdem_create(&g, 90, 70, 10.0, 10.0);
    tdem_fractal(&g, 17, 250.0);
    for (int x = 30; x < 40; x++)
        g.z[35 * g.stride + x] = NAN;
    lit L = light_setup(&g);
    size_t n = L.n;
    float *svf = tdem_floats(n), *sky = tdem_floats(n), *op = tdem_floats(n);
    float *as = calloc(n, 4), *ak = calloc(n, 4), *ao = calloc(n, 4);
    ck_assert(as && ak && ao);
    ts_error err;
    sky_terms(&g, &L, svf, sky, op);
    for (int k = 0; k < 16; k++)
        ck_assert_msg(ts_sky_accumulate(&g, L.nx, L.ny, L.nz, L.hor + k * n,
                                        ts_horizon_azimuth(&L.o, k), 16, as, ak, ao,
                                        &err) == TS_OK, "%s", err.message);
    ck_assert(ts_sky_finish(&g, 16, as, ak, ao, &err) == TS_OK);
    for (size_t i = 0; i < n; i++) {
        if (isnan(g.z[i])) {
            ck_assert_msg(isnan(svf[i]) && isnan(sky[i]) && isnan(op[i]) && isnan(as[i]),
                          "nodata cell %zu not NaN", i);
            continue;
        }
        double mean = 0;
        for (int k = 0; k < 16; k++)
            mean += 90.0 - L.hor[k * n + i];
        mean /= 16;
        ck_assert_msg(fabs(op[i] - mean) < 1e-3, "cell %zu: openness %g, want %g", i,
                      op[i], mean);
        ck_assert_msg(svf[i] >= 0 && svf[i] <= 1 + 1e-6 && sky[i] >= 0 &&
                      sky[i] <= svf[i] + 1e-6, "cell %zu: svf %g sky %g", i, svf[i], sky[i]);
        ck_assert_msg(fabsf(as[i] - svf[i]) < 1e-5f && fabsf(ak[i] - sky[i]) < 1e-5f &&
                      fabsf(ao[i] - op[i]) < 1e-4f, "cell %zu: accumulated (%g %g %g) vs "
                      "(%g %g %g)", i, as[i], ak[i], ao[i], svf[i], sky[i], op[i]);
    }
    free(svf); free(sky); free(op); free(as); free(ak); free(ao);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

/* Normals made row by row on the way (ts_shade_direct_horn): the same bits
 * as the planes of ts_normals then ts_shade_direct, nodata included. */
START_TEST(test_direct_horn_same_bits)
{
    ts_grid g;
    tdem_create(&g, 61, 47, 10.0, 12.0);
    tdem_fractal(&g, 5, 300.0);
    g.z[20 * g.stride + 30] = NAN;
    g.z[0 * g.stride + 3] = NAN;
    g.z[46 * g.stride + 60] = NAN;
    lit L = light_setup(&g);
    float *a = tdem_floats(L.n), *b = tdem_floats(L.n);
    const double sun[][2] = {{100, 20}, {315, 45}, {22.5, 3}, {200, 0.1}, {90, -2}};
    for (int k = 0; k < 5; k++) {
        direct(&g, &L, sun[k][0], sun[k][1], a);
        ts_error err;
        const ts_direct_request req = {&g, NULL, NULL, NULL, L.hor, &L.o,
                                       sun[k][0], sun[k][1], b, TS_SUN_RADIUS_DEG};
        ck_assert_msg(ts_shade_direct_horn(&req, &err) == TS_OK, "%s", err.message);
        ck_assert_msg(memcmp(a, b, L.n * sizeof *a) == 0, "sun %g/%g: other bits",
                      sun[k][0], sun[k][1]);
    }
    free(a);
    free(b);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

/* The direct sun in place (req->out is the one horizon plane, as the
 * driver's shade takes it): the same bits as into another plane; refused
 * with several horizon planes. */
START_TEST(test_direct_horn_in_place)
{
    ts_grid g;
    tdem_create(&g, 53, 41, 10.0, 12.0);
    tdem_fractal(&g, 7, 300.0);
    g.z[17 * g.stride + 9] = NAN;
    const size_t n = (size_t)g.width * g.height;
    float *hz = tdem_floats(n), *a = tdem_floats(n);
    const double sun[][2] = {{100, 20}, {315, 45}, {200, 0.1}, {90, -2}};
    ts_error err;
    for (int k = 0; k < 4; k++) {
        ts_horizon_opts o;
        ts_horizon_opts_default(&o);
        o.directions = 1;
        o.start_azimuth = sun[k][0];
        ck_assert_msg(ts_horizon_compute(&g, &o, hz, &err) == TS_OK, "%s", err.message);
        ts_direct_request req = {&g, NULL, NULL, NULL, hz, &o, sun[k][0], sun[k][1], a, 0.0};
        ck_assert_msg(ts_shade_direct_horn(&req, &err) == TS_OK, "%s", err.message);
        req.out = hz;
        ck_assert_msg(ts_shade_direct_horn(&req, &err) == TS_OK, "%s", err.message);
        ck_assert_msg(memcmp(a, hz, n * sizeof *a) == 0, "sun %g/%g: other bits in place",
                      sun[k][0], sun[k][1]);
    }
    lit L = light_setup(&g);
    const ts_direct_request req = {&g, NULL, NULL, NULL, L.hor, &L.o, 100, 20, L.hor, 0.0};
    ck_assert(ts_shade_direct_horn(&req, &err) == TS_ERR_ARG);
    ck_assert_msg(strstr(err.message, "in place") != NULL, "%s", err.message);
    free(hz);
    free(a);
    light_free(&L);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* lines reach the log before a failure exits */
    Suite *s = suite_create("shading");
    TCase *tc = tcase_create("shading");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_sun_disk_fraction);
    tcase_add_test(tc, test_normals_horn);
    tcase_add_test(tc, test_normals_plane_edges);
    tcase_add_test(tc, test_normals_signs);
    tcase_add_test(tc, test_normals_geographic_rows);
    tcase_add_test(tc, test_direct_flat);
    tcase_add_test(tc, test_direct_tilted);
    tcase_add_test(tc, test_direct_horn_same_bits);
    tcase_add_test(tc, test_direct_horn_in_place);
    tcase_add_test(tc, test_direct_pillar_shadow);
    tcase_add_test(tc, test_combine);
    tcase_add_test(tc, test_sky_flat_and_tilted);
    tcase_add_test(tc, test_sky_rough);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
