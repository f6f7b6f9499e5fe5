/*
 * Pyramid horizons (Snyder & Nowrouzezahrai 2008, sections 4 and 6) from a
 * pyramid of ts_pyramid_build; terrashade.h states the method.
 *
 * For one azimuth every cell's ray has the same direction, so sample j of
 * every cell lies at the same offset (s_j vx, s_j vy) cells from it: along
 * a grid row the samples are a contiguous run of a level row at constant
 * weights, and the blocking angles of a whole row come from a few loops
 * the compiler vectorises. Level j's samples exist for the cells whose ray
 * has not yet left the DEM at distance s_j; these runs shrink from level
 * to level, and a cell that drops out gets its last sample where its ray
 * leaves the DEM (or reaches the maximum distance), read on the DEM, then
 * its horizon.
 *
 * The B-spline of the samples w_0..w_{M-1} in log distance is evaluated at
 * its knots (weights 1/6, 2/3, 1/6) and midpoints (1/48, 23/48, 23/48,
 * 1/48), with linear extrapolation beyond the ends (w_{-1} = 2 w_0 - w_1),
 * so that the end knots are w_0 and w_{M-1} themselves and no value
 * exceeds the largest sample. A sample that touches nodata is no
 * occluder: it repeats the sample before it.
 */
#include <math.h>
#include <stdlib.h>

#include "arg_checks.h"
#include "cellmath/cm_fastmath.h"
#include "parallel.h"
#include "pyramid_hz.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#ifndef CHUNK
#define CHUNK 512 /* columns: the rows of every level a chunk reads stay in L2 */
#endif
#define ROW_BLOCK 32 /* rows whose per-level entries are filled at a time */

/* What sample j of the cells of one row shares: the level rows at the
 * samples' row (the vertical taps), the cells' own row on the level, and
 * the distance in metres. Filled once per row and azimuth, read by every
 * chunk of the row. */
typedef struct {
    const float *t[4]; /* level rows at the samples' row */
    float wt[4];
    int taps;
    const float *r[4]; /* level rows at the cells' own row (weight 0: unused) */
    float wr[4];
    float inv_d, cd; /* 1 / distance, curvature drop over it */
} row_level;

static double step_at(const hz_ctx *C, double row)
{
    int H = C->P->grid->height;
    int r = (int)lround(row);
    return C->step[r < 0 ? 0 : r > H - 1 ? H - 1 : r];
}

/* dst[x] = sum of weights w[t] * rows r[t] at x, for x in [x0, x1]. */
TS_PYR_CLONES
static void combine_rows(const float *const r[4], const float w[4], int taps, int x0, int x1,
                         float *restrict dst)
{
    const float *r0 = r[0];
    const float w0 = w[0];
    if (taps == 1) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            dst[x] = r0[x];
        return;
    }
    const float *r1 = r[1];
    const float w1 = w[1];
    if (taps == 2) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            dst[x] = w0 * r0[x] + w1 * r1[x];
        return;
    }
    const float *r2 = r[2], *r3 = r[3];
    const float w2 = w[2], w3 = w[3];
#pragma GCC ivdep
    for (int x = x0; x <= x1; x++)
        dst[x] = w0 * r0[x] + w1 * r1[x] + w2 * r2[x] + w3 * r3[x];
}

/* The taps of row position `row` (DEM coordinates) on level lev. */
static int level_taps(const ts_pyramid *P, int lev, double row, int idx[4], double w[4])
{
    const ts_pyr_level *L = &P->level[lev];
    return ts_pyr_taps((row + 0.5) / L->spacing - 0.5, L->rows, lev == 0, idx, w);
}

/* spline_push on the state of cell x. */
static inline void spline_step(float *restrict s0, float *restrict s1, float *restrict s2,
                               float *restrict m, int x, float a)
{
    float p0 = s0[x], p1 = s1[x], p2 = s2[x], mm = m[x];
    spline_push(&p0, &p1, &p2, &mm, a);
    m[x] = mm;
    s0[x] = p0;
    s1[x] = p1;
    s2[x] = p2;
}

/* Add sample number c (value a_in[x] for the cells of [x0, x1]) to the
 * spline (or the maximum), as the file's comment says. */
TS_PYR_CLONES
static void push_run(row_ws *w, int bspline, int c, int x0, int x1, const float *restrict a_in)
{
    float *restrict s0 = w->s0, *restrict s1 = w->s1, *restrict s2 = w->s2;
    float *restrict m = w->m;
    if (!bspline) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            m[x] = a_in[x] > m[x] ? a_in[x] : m[x];
        return;
    }
    if (c == 0) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            s2[x] = a_in[x];
        return;
    }
    if (c == 1) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++) {
            float a = a_in[x] == a_in[x] ? a_in[x] : s2[x];
            s0[x] = 2.0f * s2[x] - a; /* w_{-1}: knot 0 is w_0 */
            s1[x] = s2[x];
            s2[x] = a;
            m[x] = s1[x] > m[x] ? s1[x] : m[x];
        }
        return;
    }
#pragma GCC ivdep
    for (int x = x0; x <= x1; x++)
        spline_step(s0, s1, s2, m, x, a_in[x]);
}

/* One level's samples for the cells of [x0, x1]: the level row T at x + ix
 * and x + ix + 1 (weight fx) against the cells' own heights on the level
 * (rows r, weights wr), at d metres (1 / d = inv_d, curvature drop over d
 * = cd). Pushed as sample c in the same pass where the spline allows,
 * else left in w->A for push_run (returns 0 then). */
TS_PYR_CLONES
static int level_run(row_ws *w, const float *restrict T, int ix, float fx,
                     const float *const r[4], const float wr[4], float inv_d, float cd,
                     int bspline, int c, int x0, int x1)
{
    const float *restrict r0 = r[0], *restrict r1 = r[1], *restrict r2 = r[2], *restrict r3 = r[3];
    const float w0 = wr[0], w1 = wr[1], w2 = wr[2], w3 = wr[3];
    float *restrict s0 = w->s0, *restrict s1 = w->s1, *restrict s2 = w->s2;
    float *restrict m = w->m, *restrict A = w->A;
    const float gx = 1.0f - fx;
    const float *restrict Ta = T + ix; /* T[x + ix] defeats the vectoriser */
    if (bspline && c >= 2) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++) {
            float h = gx * Ta[x] + fx * Ta[x + 1];
            float R = w0 * r0[x] + w1 * r1[x] + w2 * r2[x] + w3 * r3[x];
            spline_step(s0, s1, s2, m, x, ts_atan_deg((h - R) * inv_d - cd));
        }
        return 1;
    }
    if (!bspline) { /* the maximum of the tangents; one arctangent at the end */
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++) {
            float h = gx * Ta[x] + fx * Ta[x + 1];
            float R = w0 * r0[x] + w1 * r1[x] + w2 * r2[x] + w3 * r3[x];
            float t = (h - R) * inv_d - cd;
            m[x] = t > m[x] ? t : m[x];
        }
        return 1;
    }
#pragma GCC ivdep
    for (int x = x0; x <= x1; x++) {
        float h = gx * Ta[x] + fx * Ta[x + 1];
        float R = w0 * r0[x] + w1 * r1[x] + w2 * r2[x] + w3 * r3[x];
        A[x] = ts_atan_deg((h - R) * inv_d - cd);
    }
    return 0;
}

/* The row-level entry of row y for samples at `dist` steps on level lev. */
static void row_level_fill(const hz_ctx *C, int y, int lev, double dist, row_level *e)
{
    const ts_pyramid *P = C->P;
    double oy = dist * C->vy;
    int idx[4];
    double wd[4];
    e->taps = level_taps(P, lev, y + oy, idx, wd);
    for (int t = 0; t < 4; t++) {
        e->t[t] = ts_pyr_row(P, lev, idx[t < e->taps ? t : 0]);
        e->wt[t] = (float)wd[t < e->taps ? t : 0];
    }
    /* the cells' own heights on the level: the DEM row itself on level 0 */
    int taps = level_taps(P, lev, y, idx, wd);
    for (int t = 0; t < 4; t++) {
        e->r[t] = ts_pyr_row(P, lev, idx[t < taps ? t : 0]);
        e->wr[t] = t < taps ? (float)wd[t] : 0.0f;
    }
    double d = dist * step_at(C, y + oy / 2);
    e->inv_d = (float)(1.0 / d);
    e->cd = (float)(C->c * d);
}

/* The samples of the cells [x0, x1] described by e, at column offset
 * ix + fx, pushed as sample c. */
static void sample_level(const hz_ctx *C, row_ws *w, const row_level *e, int ix, float fx, int c,
                         int x0, int x1)
{
    const int W = C->P->grid->width;
    int t0 = x0 + ix, t1 = x1 + ix + (fx > 0.0f);
    t1 = t1 > W - 1 ? W - 1 : t1;
    if (t0 < 0 || t1 < t0)
        return; /* not reached: the runs keep the samples on the grid */
    combine_rows(e->t, e->wt, e->taps, t0, t1, w->T);
    w->T[t1 + 1] = w->T[t1]; /* a weight of fx = 0 there: no NaN from beyond */
    if (!level_run(w, w->T, ix, fx, e->r, e->wr, e->inv_d, e->cd, C->bspline, c, x0, x1))
        push_run(w, C->bspline, c, x0, x1, w->A);
}

/* The samples of the cells [x0, x1] of row y at `dist` steps on level lev,
 * pushed as sample c (the last sample of a row whose rays end early). */
static void sample_run(const hz_ctx *C, row_ws *w, int y, int lev, double dist, int c, int x0,
                       int x1)
{
    double ox = dist * C->vx;
    double fl = floor(ox);
    row_level e;
    row_level_fill(C, y, lev, dist, &e);
    sample_level(C, w, &e, (int)fl, (float)(ox - fl), c, x0, x1);
}

/* The horizons of cells [x0, x1] after `count` >= 1 samples, into out. */
TS_PYR_CLONES
static void finish_run(row_ws *w, int bspline, int count, int x0, int x1, float *restrict out)
{
    float *restrict s1 = w->s1, *restrict s2 = w->s2, *restrict m = w->m;
    if (!bspline) {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            out[x] = m[x] > -INFINITY ? ts_atan_deg(m[x]) : -90.0f;
        return;
    }
    if (count >= 2) { /* w_M = 2 w_{M-1} - w_{M-2}: knot M-1 is w_{M-1} */
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            w->A[x] = 2.0f * s2[x] - s1[x];
        push_run(w, 1, count, x0, x1, w->A);
    } else {
#pragma GCC ivdep
        for (int x = x0; x <= x1; x++)
            m[x] = s2[x] > m[x] ? s2[x] : m[x];
    }
#pragma GCC ivdep
    /* no spline value where nodata left fewer than three samples: the last */
    for (int x = x0; x <= x1; x++) {
        float r = m[x] > -INFINITY ? m[x] : s2[x];
        out[x] = r == r && r > -INFINITY ? r : -90.0f;
    }
}

/* Cells [a, b] drop out before sample j (B-spline: their sample number). */
static void mark_drop(const hz_ctx *C, row_ws *w, int a, int b, int j)
{
    if (C->bspline)
        for (int x = a; x <= b; x++)
            w->jd[x] = j;
}

/* The cells [c0, c1) of row y; rl: the row's entry for every level. */
static void horizon_row(const hz_ctx *C, row_ws *w, int y, int c0, int c1, const row_level *rl)
{
    const ts_pyramid *P = C->P;
    const ts_grid *g = P->grid;
    const int W = g->width, H = g->height;
    float *out = C->out + (size_t)y * W;
    for (int x = c0; x < c1; x++)
        w->m[x] = -INFINITY;
    /* where every ray of the row leaves the grid (top or bottom) or ends */
    double t_row = C->vy > 0 ? (H - 1 - y) / C->vy : C->vy < 0 ? y / -C->vy : INFINITY;
    if (C->cap > 0 && C->cap / C->step[y] < t_row)
        t_row = C->cap / C->step[y];
    int pa = c0, pb = c1 - 1, j = 0;
    int fa = c1, fb = c1 - 1; /* the cells whose rays end at t_row: the others drop */
    for (; j < P->levels && pa <= pb; j++) {
        const level_az *L = &C->lv[j];
        int xa = L->xa > pa ? L->xa : pa;
        int xb = L->xb < pb ? L->xb : pb;
        if (xa > xb) {
            mark_drop(C, w, pa, pb, j);
            pa = 1, pb = 0;
            break;
        }
        mark_drop(C, w, pa, xa - 1, j);
        mark_drop(C, w, xb + 1, pb, j);
        pa = xa, pb = xb;
        if (L->s <= t_row) {
            sample_level(C, w, &rl[j], L->ix, L->fx, j, pa, pb);
        } else { /* the row's rays end here: one last sample on the DEM */
            if (t_row > 1e-9) {
                sample_run(C, w, y, 0, t_row, j, pa, pb);
                finish_run(w, C->bspline, j + 1, pa, pb, out);
            } else if (j == 0) {
                for (int x = pa; x <= pb; x++)
                    out[x] = -90.0f; /* nothing beyond these cells */
            } else {
                finish_run(w, C->bspline, j, pa, pb, out);
            }
            fa = pa, fb = pb;
            pa = 1, pb = 0;
        }
    }
    if (pa <= pb) /* not reached: the coarsest spacing spans the grid */
        mark_drop(C, w, pa, pb, j);
    ts_pyr_drop_cells(C, w, y, c0, fa - 1, t_row, out);
    ts_pyr_drop_cells(C, w, y, fb + 1, c1 - 1, t_row, out);
    const float *z = g->z + (ptrdiff_t)y * g->stride;
    for (int x = c0; x < c1; x++)
        if (z[x] != z[x])
            out[x] = NAN;
}

static void rows_range(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const hz_ctx *C = ctx;
    const int W = C->P->grid->width, levels = C->P->levels;
    /* s0, s1, s2, m: W each; T and the samples: W + 1 each */
    float *buf = malloc((size_t)(6 * W + 2) * sizeof *buf);
    double *tpp = malloc((size_t)3 * W * sizeof *tpp);
    int *jd = malloc((size_t)W * sizeof *jd);
    row_level *rl = malloc((size_t)ROW_BLOCK * levels * sizeof *rl);
    if (!buf || !tpp || !jd || !rl) {
        free(buf);
        free(tpp);
        free(jd);
        free(rl);
        __atomic_store_n(C->alloc_failed, 1, __ATOMIC_RELAXED);
        return;
    }
    row_ws w = {buf, buf + W, buf + 2 * W, buf + 3 * W, buf + 4 * W, buf + 5 * W + 1, tpp, jd};
    for (long yb = y0; yb < y1; yb += ROW_BLOCK) {
        long ye = yb + ROW_BLOCK < y1 ? yb + ROW_BLOCK : y1;
        for (long y = yb; y < ye; y++)
            for (int j = 0; j < levels; j++)
                row_level_fill(C, (int)y, C->lv[j].lev, C->lv[j].s,
                               &rl[(size_t)(y - yb) * levels + j]);
        /* a chunk of columns down the rows, then the next: the level rows
         * that the cells of a chunk read stay in the cache from row to row */
        for (int c0 = 0; c0 < W; c0 += CHUNK)
            for (long y = yb; y < ye; y++)
                horizon_row(C, &w, (int)y, c0, c0 + CHUNK < W ? c0 + CHUNK : W,
                            &rl[(size_t)(y - yb) * levels]);
    }
    free(rl);
    free(jd);
    free(tpp);
    free(buf);
}

/* Sample j's shares for the azimuth of C (vx, ko set). */
static void level_az_fill(const hz_ctx *C, level_az *lv)
{
    const ts_pyramid *P = C->P;
    const int W = P->grid->width;
    for (int j = 0; j < P->levels; j++) {
        double s = P->level[j].spacing, ox = s * C->vx;
        double fl = floor(ox), lf = floor(j - C->ko + 1e-9);
        lv[j] = (level_az){s,
                           (int)fl,
                           (float)(ox - fl),
                           C->vx < 0 ? (int)ceil(-ox) : 0,
                           C->vx > 0 ? (int)floor(W - 1 - ox) : W - 1,
                           lf < 0 ? 0 : (int)lf};
    }
}

ts_status ts_pyramid_horizon(const ts_pyramid *pyr, double azimuth, const ts_horizon_opts *opts,
                             float *out, ts_error *err)
{
    if (!pyr)
        return ts_fail(err, TS_ERR_ARG, "pyramid is NULL");
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "output buffer is NULL");
    const ts_grid *g = pyr->grid;
    ts_status st = ts_check_sweep_args(g, &azimuth, opts, err);
    if (st != TS_OK)
        return st;
    const int H = g->height;
    double a = azimuth * DEG2RAD, sa = sin(a), ca = cos(a);
    /* as the sweep: exact axis directions, the direction in cells taken at
     * the central row of a geographic grid */
    if (fabs(sa) < 1e-12) sa = 0;
    if (fabs(ca) < 1e-12) ca = 0;
    double gx = sa / ts_grid_cell_x(g, H / 2), gy = -ca / g->cell_y;
    double major = fabs(gx) > fabs(gy) ? fabs(gx) : fabs(gy);
    hz_ctx C = {pyr, gx / major, gy / major, NULL, 0, 0, 0, 0, NULL, NULL, NULL};
    C.step = malloc((size_t)H * sizeof *C.step);
    level_az *lv = malloc((size_t)pyr->levels * sizeof *lv);
    if (!C.step || !lv) {
        free(C.step);
        free(lv);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid's step table");
    }
    for (int y = 0; y < H; y++)
        C.step[y] = hypot(ts_grid_cell_x(g, y) * C.vx, g->cell_y * C.vy);
    C.c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    C.cap = opts->max_distance;
    C.ko = pyr->opts.level_step * pyr->opts.offset;
    C.bspline = pyr->opts.reconstruction == TS_PYRAMID_BSPLINE;
    level_az_fill(&C, lv);
    C.lv = lv;
    C.out = out;
    int failed = 0;
    C.alloc_failed = &failed;
    st = ts_parallel_for(ts_thread_count(opts->threads, H), H, rows_range, &C, err);
    free(C.step);
    free(lv);
    if (st != TS_OK)
        return st;
    if (failed)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the pyramid's row workspace");
    /* what lies beyond the DEM's edge, as after the exact sweep */
    return ts_horizon_edge_apply(g, azimuth, opts, out, err);
}

ts_status ts_pyramid_horizon_compute(const ts_grid *grid, const ts_pyramid_opts *popts,
                                     const ts_horizon_opts *opts, float *out, ts_error *err)
{
    ts_status st = ts_check_horizon_compute_args(grid, opts, out, err);
    if (st != TS_OK)
        return st;
    ts_pyramid *pyr;
    if ((st = ts_pyramid_build(grid, popts, opts->threads, &pyr, err)) != TS_OK)
        return st;
    size_t plane = (size_t)grid->width * (size_t)grid->height;
    for (int k = 0; st == TS_OK && k < opts->directions; k++) {
        if ((st = ts_progress(opts, (double)k / opts->directions, err)) == TS_OK)
            st = ts_pyramid_horizon(pyr, ts_horizon_azimuth(opts, k), opts, out + plane * k, err);
    }
    ts_pyramid_free(pyr);
    if (st == TS_OK)
        st = ts_progress(opts, 1.0, err);
    return st == TS_OK ? ts_ok(err) : st;
}
