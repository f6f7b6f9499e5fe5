/* The convex-hull sweep against an O(n^2) brute force along its own sample
 * lines: same samples, so the slopes must agree to float precision. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "capped_lanes.h"
#include "oracle.h"
#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"

static const double DEG = 3.14159265358979323846 / 180.0;
static const double AZ[] = {0, 33.7, 45, 90, 137, 180, 222.2, 300};
#define N_AZ ((int)(sizeof AZ / sizeof AZ[0]))

typedef struct {
    const ts_grid *g;
    double azimuth, c, max_distance;
    long lines, samples, occluded, bad_slope, bad_geometry, bad_height;
    char first[256]; /* the first failure, for the message */
} lines_ctx;

static void record(lines_ctx *u, long *counter, const char *what, int i,
                 double got, double want)
{
    if (u->bad_slope + u->bad_geometry + u->bad_height == 0)
        snprintf(u->first, sizeof u->first,
                 "line %ld sample %d: %s: got %.9g, want %.9g", u->lines, i,
                 what, got, want);
    (*counter)++;
}

/* Brute force horizon slope of sample i over all valid j < i. */
static double brute_slope(const lines_ctx *u, int i, const float *h,
                          const double *d)
{
    double best = -INFINITY;
    for (int j = 0; j < i; j++) {
        double dd = d[i] - d[j];
        if (isnan(h[j]) || (u->max_distance > 0 && dd > u->max_distance))
            continue;
        double s = ((double)h[j] - (double)h[i] - u->c * dd * dd) / dd;
        if (s > best)
            best = s;
    }
    return best;
}

/* A sample on a grid line: its height must be the linear interpolation of
 * its two cells; NaN only if a cell it really uses (weight above 1e-4, the
 * float precision of the position) is nodata. */
static void check_height(lines_ctx *u, int i, float x, float y, float h)
{
    const ts_grid *g = u->g;
    if (!(fabs(x - rint(x)) < 1e-4 || fabs(y - rint(y)) < 1e-4))
        return; /* not on a line: nothing to compare with */
    if (x < -1e-4 || y < -1e-4 || x > g->width - 1 + 1e-4 || y > g->height - 1 + 1e-4)
        return;
    double xc = fmin(fmax(x, 0), g->width - 1), yc = fmin(fmax(y, 0), g->height - 1);
    int x0 = (int)floor(xc), y0 = (int)floor(yc);
    double fx = xc - x0, fy = yc - y0, lo = INFINITY, hi = -INFINITY;
    int used_nodata = 0, any_nodata = 0;
    for (int dy = 0; dy <= 1; dy++)
        for (int dx = 0; dx <= 1; dx++) {
            int xx = x0 + dx < g->width ? x0 + dx : x0;
            int yy = y0 + dy < g->height ? y0 + dy : y0;
            double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
            double c = ts_grid_at(g, xx, yy);
            any_nodata |= isnan(c);
            used_nodata |= isnan(c) && w > 1e-4;
            lo = fmin(lo, c), hi = fmax(hi, c);
        }
    if (isnan(h)) {
        /* on the border itself the position's float rounding decides */
        int border = xc < 1e-4 || yc < 1e-4 || xc > g->width - 1 - 1e-4 ||
                     yc > g->height - 1 - 1e-4;
        if (!used_nodata && !border)
            record(u, &u->bad_height, "sample on valid cells reported as nodata", i, x, y);
        return;
    }
    if (any_nodata)
        return; /* renormalised or not: a policy, see test_stats.h */
    /* x, y come as floats: 1e-5 cell of position is worth that fraction of
     * the height step between the corners */
    double want = oracle_bilinear(g, x, y);
    if (fabs(h - want) > 1e-4 * (1 + fabs(want)) + 2e-5 * (hi - lo))
        record(u, &u->bad_height, "sample height", i, h, want);
}

static void visit(void *user, int n, const float *x, const float *y,
                  const float *h, const double *d, const float *slope)
{
    lines_ctx *u = user;
    const ts_grid *g = u->g;
    double ex = -sin(u->azimuth * DEG), ey = cos(u->azimuth * DEG); /* east, south */
    for (int i = 0; i < n; i++) {
        /* geometry: moving away from the azimuth, in metres; a sample past
         * the last row or column is allowed only as a skipped one (NaN) */
        if (!(x[i] >= -1e-4 && x[i] <= g->width - 1 + 1e-4 && y[i] >= -1e-4 &&
              y[i] <= g->height - 1 + 1e-4) && !isnan(h[i]))
            record(u, &u->bad_geometry, "valid sample outside the grid", i, x[i], y[i]);
        if (i > 0) {
            double dd = d[i] - d[i - 1];
            double vx = (x[i] - x[i - 1]) * oracle_cell_x(g, 0.5 * (y[i] + y[i - 1]));
            double vy = (y[i] - y[i - 1]) * g->cell_y;
            double len = hypot(vx, vy);
            if (!(dd > 0))
                record(u, &u->bad_geometry, "distance not increasing", i, d[i], d[i - 1]);
            else if (fabs(len - dd) > 1e-3 * dd + 1e-3 * g->cell_y)
                record(u, &u->bad_geometry, "distance step != metres moved", i, dd, len);
            else if (len > 0.5 * g->cell_y && (vx * ex + vy * ey) / len < 0.9999)
                record(u, &u->bad_geometry, "step direction . (-sin az, cos az)", i,
                     (vx * ex + vy * ey) / len, 1.0);
        }
        check_height(u, i, x[i], y[i], h[i]);
        /* the point of the test: hull slope == brute-force slope */
        if (isnan(h[i]))
            continue;
        double want = brute_slope(u, i, h, d);
        double got = slope[i];
        if (want == -INFINITY) {
            if (got != -INFINITY)
                record(u, &u->bad_slope, "slope without occluder", i, got, want);
        } else {
            u->occluded++;
            if (!(fabs(got - want) <= 1e-5 * (1 + fabs(want))))
                record(u, &u->bad_slope, "slope", i, got, want);
        }
    }
    u->lines++;
    u->samples += n;
}

static void check_lines(const char *label, const ts_grid *g, int curvature,
                        double k, double max_distance)
{
    for (int a = 0; a < N_AZ; a++) {
        ts_horizon_opts o;
        ts_horizon_opts_default(&o);
        o.curvature = curvature;
        o.refraction = k;
        o.max_distance = max_distance;
        lines_ctx u = {g, AZ[a], curvature ? (1 - k) / (2 * TS_EARTH_RADIUS) : 0,
                       max_distance, 0, 0, 0, 0, 0, 0, ""};
        ts_error err;
        ck_assert_msg(ts_horizon_sweep_lines(g, AZ[a], &o, visit, &u, &err) == TS_OK,
                      "%s az %g: %s", label, AZ[a], err.message);
        printf("%-36s az %6.1f: %ld lines, %ld samples (%ld occluded); bad slope "
               "%ld, geometry %ld, height %ld\n", label, AZ[a], u.lines,
               u.samples, u.occluded, u.bad_slope, u.bad_geometry, u.bad_height);
        fflush(stdout);
        ck_assert_msg(u.lines > 0 && u.occluded > 0, "%s az %g: no lines", label, AZ[a]);
        ck_assert_msg(u.bad_slope + u.bad_geometry + u.bad_height == 0,
                      "%s az %g: %ld slope, %ld geometry, %ld height errors; first: %s",
                      label, AZ[a], u.bad_slope, u.bad_geometry, u.bad_height,
                      u.first);
    }
}

START_TEST(test_sharp_flat_earth)
{
    ts_grid g;
    tdem_create(&g, 120, 90, 10.0, 10.0);
    tdem_sharp(&g, 1);
    check_lines("sharp 120x90 10m, no curvature", &g, 0, 0.13, 0);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_sharp_curved)
{
    /* 100 m cells: at 10 km the curvature drop is ~7 m, well above 1e-5 */
    ts_grid g;
    tdem_create(&g, 120, 90, 100.0, 80.0);
    tdem_sharp(&g, 2);
    check_lines("sharp 120x90 100x80m, k=0.13", &g, 1, TS_DEFAULT_REFRACTION, 0);
    check_lines("sharp 120x90 100x80m, k=0.5", &g, 1, 0.5, 0);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_sharp_max_distance)
{
    /* 303.7 m: not a multiple of the cell, so no sample sits on the cut */
    ts_grid g;
    tdem_create(&g, 120, 90, 10.0, 10.0);
    tdem_sharp(&g, 3);
    check_lines("sharp, max_distance 303.7 m", &g, 0, 0.13, 303.7);
    /* a window of two or three samples: it empties and refills all along */
    check_lines("sharp, max_distance 25.3 m", &g, 0, 0.13, 25.3);
    ts_grid_free(&g);
    tdem_create(&g, 120, 90, 100.0, 100.0);
    tdem_sharp(&g, 4);
    check_lines("sharp 100m, curved, max_distance 2537", &g, 1, 0.13, 2537.0);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_nodata_skipped)
{
    /* NaN blocks: skipped samples, never occluders */
    ts_grid g;
    tdem_create(&g, 100, 80, 10.0, 10.0);
    tdem_sharp(&g, 5);
    for (int y = 20; y < 50; y++)
        for (int x = 30; x < 45; x++)
            g.z[y * g.stride + x] = NAN;
    for (int x = 0; x < 100; x += 7)
        g.z[60 * g.stride + x] = NAN;
    check_lines("sharp with nodata", &g, 0, 0.13, 0);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_jacksboro_rows)
{
    /* per-row spacing; a 160x140 window keeps the O(n^2) brute force fast */
    ts_grid full, g;
    tdem_load(&full, "jacksboro");
    tdem_create(&g, 160, 140, full.cell_x, full.cell_y);
    double cx[140];
    for (int y = 0; y < 140; y++) {
        cx[y] = full.cell_x_row[y + 100];
        for (int x = 0; x < 160; x++)
            g.z[y * g.stride + x] = ts_grid_at(&full, x + 120, y + 100);
    }
    ts_error err;
    ck_assert(ts_grid_set_row_spacing(&g, cx, &err) == TS_OK);
    check_lines("jacksboro window, curved", &g, 1, TS_DEFAULT_REFRACTION, 0);
    ts_grid_free(&g);
    ts_grid_free(&full);
}
END_TEST

/* The capped lines' window scan (capped_lanes.h) on synthetic lines,
 * against its definition: each query scans its window oldest first and
 * takes a sample where its slope compares strictly greater
 * (cross-multiplied). Long windows take the pruned scan (on AVX-512 CPUs),
 * which must give the same steps and distances bit for bit as the unpruned
 * one and as the definition: terraced heights with many exact ties, NaN
 * holes, curvature, lines entering and leaving, steps without lines. */
#define CL_LINES 65
#define CL_STEPS 900

static uint32_t cl_rand(uint32_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 17;
    *s ^= *s << 5;
    return *s;
}

/* line j is on the grid for steps 3j .. 300 + 7j, none for 500..507 */
static int cl_on(int j, int k)
{
    return k >= 3 * j && k <= 300 + 7 * j && !(k >= 500 && k <= 507);
}

/* ramp: 0 terraces, 1 a steady climb, 2 level plateaus */
static void check_capped_scan(double near, double cap, double c, double jitter, uint32_t seed,
                              int ramp)
{
    static float hs[CL_STEPS][CL_LINES + 1], hc[CL_STEPS][CL_LINES + 1], hn[CL_STEPS][CL_LINES + 1];
    static double d[CL_STEPS][CL_LINES + 1];
    const double step = 10.0;
    for (int k = 0; k < CL_STEPS; k++)
        for (int j = 0; j < CL_LINES; j++) {
            /* terraces of 2.5 m (exact ties), spikes, holes; steps of
             * 10 m, or of 10 m +- jitter (per-row spacing) */
            const double x = k - 3 * j;
            float h = (float)(2.5 * floor((x * 0.37 + 40.0 * sin(x * 0.013 + j)) / 2.5));
            /* or a steady climb with centimetres of noise: every sample
             * behind nearly as steep as the next, so that the pruned scan's
             * lists grow long and its threshold rises within a scan */
            if (ramp == 1)
                h = (float)(x * 0.37 + 0.01 * (cl_rand(&seed) % 8));
            /* or long level plateaus (flat ground without curvature, where
             * every sample of a window ties with the query points: the
             * pruned scan's tie lines), a step of 5 m every 150 */
            if (ramp == 2)
                h = (float)(5.0 * floor((x + 40.0 * j) / 150.0));
            if (cl_rand(&seed) % 61 == 0)
                h += (float)(cl_rand(&seed) % 300);
            if ((k / 37 + j) % 11 == 0)
                h = NAN;
            hs[k][j] = h;
            hc[k][j] = cl_rand(&seed) % 17 == 0 ? NAN : h - (float)(cl_rand(&seed) % 5) * 2.5f;
            hn[k][j] = h + (float)(cl_rand(&seed) % 3) * 2.5f;
            if (ramp == 2 && cl_rand(&seed) % 5 != 0) /* mostly level with the ground */
                hc[k][j] = hn[k][j] = h;
            d[k][j] = k == 3 * j ? 0.0 : (k > 0 ? d[k - 1][j] : 0.0) +
                                         step * (1.0 + jitter * sin(k * 0.7));
        }
    int lags[4];
    ts_cap_lanes_lags(near, cap, step * (1.0 - jitter), step * (1.0 + jitter), lags);
    ts_cap_lanes pruned, full;
    ck_assert(ts_cap_lanes_alloc(&pruned, CL_LINES, lags, near, cap));
    ck_assert(ts_cap_lanes_alloc(&full, CL_LINES, lags, near, cap));
    full.prune = 0;
    ts_cap_lanes_clear(&pruned);
    ts_cap_lanes_clear(&full);
    int ok_k[4][CL_LINES + 1], hi_k[4][CL_LINES + 1];
    float ok_dd[4][CL_LINES + 1], hi_dd[4][CL_LINES + 1];
    long queries = 0, ties = 0, bad = 0, hull_steps[2] = {0}, hyb_ties = 0;
    /* long windows (AVX-512): the hybrid, unbounded hulls first; where the
     * steps are of one length, twice: with the general delayed pushes
     * (k_step 0) and as the sweep runs it, the pushes read in place from
     * the ring and the hulls' steps from their distances (k_step = step:
     * each d here is (k - 3j) x 10, exact) */
    const int hybrid = ts_cap_lanes_hybrid_pays(lags) && !ts_cap_lanes_pays(lags);
    const int hybrids = hybrid ? (jitter == 0.0 ? 2 : 1) : 0;
    ts_cap_lanes hyb[2] = {{0}, {0}};
    static ts_hull_pt pts[2][CL_LINES * (CL_STEPS + 1)];
    int hn_n[2][CL_LINES + 1] = {{0}}, hn_far[2][CL_LINES + 1];
    const ts_lane_hulls hulls[2] = {{pts[0], CL_STEPS + 1, hn_n[0], hn_far[0], NULL, 0},
                                    {pts[1], CL_STEPS + 1, hn_n[1], hn_far[1], NULL, 0}};
    for (int j = 0; j <= CL_LINES; j++)
        hn_far[0][j] = hn_far[1][j] = -1;
    for (int u = 0; u < hybrids; u++) {
        ck_assert(ts_cap_lanes_alloc(&hyb[u], CL_LINES, lags, near, cap));
        ts_cap_lanes_clear(&hyb[u]);
    }
    for (int k = 0; k < CL_STEPS; k++) {
        int j0 = CL_LINES, j1 = -1;
        for (int j = 0; j < CL_LINES; j++)
            if (cl_on(j, k)) {
                j0 = j < j0 ? j : j0;
                j1 = j;
            }
        double dk[CL_LINES + 1];
        for (int j = 0; j <= CL_LINES; j++)
            dk[j] = d[k][j];
        const int hi_from = j0 + (k % 3 == 0), hi_to = j1 - (k % 5 == 0);
        const ts_lane_step st = {k, j0 <= j1 ? j0 : 1, j0 <= j1 ? j1 : 0, hi_from, hi_to,
                                 dk, hs[k], hc[k], hn[k], c, near, NULL, NULL, NULL, 0.0};
        for (int v = 0; v < 2; v++) {
            const ts_lane_occluders occ = {ok_k[v], hi_k[v], ok_dd[v], hi_dd[v]};
            ts_cap_lanes_step(v ? &full : &pruned, &st, CL_LINES, &occ);
        }
        for (int u = 0; u < hybrids; u++) {
            const ts_lane_occluders occ = {ok_k[2 + u], hi_k[2 + u], ok_dd[2 + u], hi_dd[2 + u]};
            ts_lane_step su = st;
            su.k_step = u ? step : 0.0;
            if (!ts_cap_lanes_hybrid_step(&hyb[u], &hulls[u], &su, CL_LINES, &occ))
                ts_cap_lanes_step(&hyb[u], &su, CL_LINES, &occ);
            hull_steps[u] += !hyb[u].hull_lost;
        }
        for (int j = j0; j <= j1; j++)
            for (int q = 0; q < 2; q++) {
                if (q == 0 && (j < hi_from || j > hi_to))
                    continue;
                /* the definition */
                const double gq = (double)(q ? hn[k][j] : hc[k][j]) - c * d[k][j] * d[k][j];
                double bn = -INFINITY, bd = 1.0;
                long bk = -1, nbest = 0;
                for (int lag = (k < lags[1] ? k : lags[1]); lag >= lags[0]; lag--) {
                    const int kp = k - lag;
                    if (!cl_on(j, kp) || isnan(hs[kp][j]))
                        continue;
                    const double dd = d[k][j] - d[kp][j];
                    if (!(dd >= near && dd <= cap))
                        continue;
                    const double n = (double)hs[kp][j] - c * d[kp][j] * d[kp][j] - gq;
                    if (n * bd > bn * dd) {
                        bn = n, bd = dd, bk = kp, nbest = 1;
                    } else if (n * bd == bn * dd) {
                        nbest++;
                    }
                }
                if (isnan(gq))
                    bk = -1, bd = 1.0;
                queries++;
                ties += nbest > 1;
                const int jo = q ? j + 1 : j;
                for (int u = 0; u < hybrids; u++) {
                    /* the steepest slope; another equally steep sample's
                     * step (the hull's tie rule) counts as a tie */
                    const int gk = q ? ok_k[2 + u][jo] : hi_k[2 + u][jo];
                    const float gdd = q ? ok_dd[2 + u][jo] : hi_dd[2 + u][jo];
                    int good = gk == bk && gdd == (float)bd;
                    if (!good && gk >= 0 && bk >= 0 && cl_on(j, gk) && !isnan(hs[gk][j])) {
                        const double dd = d[k][j] - d[gk][j];
                        const double n = (double)hs[gk][j] - c * d[gk][j] * d[gk][j] - gq;
                        good = dd >= near && dd <= cap && gdd == (float)dd && n * bd == bn * dd;
                        hyb_ties += good;
                    }
                    if (!good && bad++ == 0)
                        printf("step %d line %d query %d (hybrid, k_step %s): step %d dd "
                               "%.9g, want %ld %.9g\n",
                               k, j, q, u ? "> 0" : "0", gk, gdd, bk, bd);
                }
                for (int v = 0; v < 2; v++) {
                    const int gk = q ? ok_k[v][jo] : hi_k[v][jo];
                    const float gdd = q ? ok_dd[v][jo] : hi_dd[v][jo];
                    if (gk != bk || gdd != (float)bd) {
                        if (bad++ == 0)
                            printf("step %d line %d query %d (%s): step %d dd %.9g, "
                                   "want %ld %.9g\n",
                                   k, j, q, v ? "unpruned" : "pruned", gk, gdd, bk, bd);
                    }
                }
            }
    }
    printf("capped scan, lags %d..%d, %s, c %g, jitter %g: %ld queries, %ld with tied "
           "steepest, %ld wrong\n", lags[0], lags[1], pruned.prune ? "pruned" : "not pruned",
           c, jitter, queries, ties, bad);
    for (int u = 0; u < hybrids; u++)
        printf("  hybrid (k_step %s): hulls on %ld of %d steps\n", u ? "> 0" : "0",
               hull_steps[u], CL_STEPS);
    if (hybrid)
        printf("  hybrid: %ld answers another tied sample\n", hyb_ties);
    ts_cap_lanes_free(&pruned);
    ts_cap_lanes_free(&full);
    ts_cap_lanes_free(&hyb[0]);
    ts_cap_lanes_free(&hyb[1]);
    ck_assert_msg(queries > 10000 && bad == 0, "%ld of %ld capped queries wrong", bad, queries);
    ck_assert(!hybrid || hull_steps[0] > 400);
    ck_assert(hybrids < 2 || hull_steps[1] > 400);
}

START_TEST(test_capped_scan_pruned)
{
    const double curved = (1 - TS_DEFAULT_REFRACTION) / (2 * TS_EARTH_RADIUS);
    check_capped_scan(25.0, 2000.0, 0.0, 0.0, 1, 0);    /* 3..200 lags: pruned */
    check_capped_scan(25.0, 2000.0, curved, 0.0, 2, 0);
    check_capped_scan(25.0, 2555.0, 0.0, 0.01, 3, 0);   /* per-row steps, up to 258 lags */
    check_capped_scan(80.0, 1200.0, curved, 0.01, 4, 0);
    check_capped_scan(25.0, 500.0, 0.0, 0.0, 5, 0);     /* 50 lags: the whole window */
    /* 3..500 and 9..3000 lags: the hybrid too (with AVX-512) */
    check_capped_scan(25.0, 5000.0, 0.0, 0.0, 6, 0);
    check_capped_scan(25.0, 5000.0, curved, 0.0, 7, 0);
    check_capped_scan(85.0, 30000.0, curved, 0.0, 8, 0);
    /* steps of 9-11 m, windows of 10..333 and 10..555 lags (pruned) */
    check_capped_scan(105.0, 3000.0, 0.0, 0.1, 9, 0);
    check_capped_scan(105.0, 5000.0, curved, 0.1, 10, 0);
    /* long lists: the steady climb, a pruned window and hybrid ones */
    check_capped_scan(25.0, 2000.0, 0.0, 0.0, 11, 1);
    check_capped_scan(25.0, 5000.0, curved, 0.0, 12, 1);
    check_capped_scan(105.0, 5000.0, 0.0, 0.1, 13, 1);
    /* level plateaus: windows of ties, pruned and hybrid */
    check_capped_scan(25.0, 2000.0, 0.0, 0.0, 14, 2);
    check_capped_scan(25.0, 1000.0, 0.0, 0.0, 15, 2);
    check_capped_scan(25.0, 5000.0, 0.0, 0.0, 16, 2);
    check_capped_scan(105.0, 3000.0, 0.0, 0.1, 17, 2);
}
END_TEST

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* lines reach the log before a failure exits */
    Suite *s = suite_create("sweep_lines");
    TCase *tc = tcase_create("hull_vs_brute_force");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_sharp_flat_earth);
    tcase_add_test(tc, test_sharp_curved);
    tcase_add_test(tc, test_sharp_max_distance);
    tcase_add_test(tc, test_nodata_skipped);
    tcase_add_test(tc, test_jacksboro_rows);
    tcase_add_test(tc, test_capped_scan_pruned);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
