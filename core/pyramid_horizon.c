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
#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include "horizon_edge.h"
#include "pyramid_hz.h"
#include "sky_plane.h"

#ifndef CHUNK
#define CHUNK 1024 /* columns: the rows of every level a chunk reads stay in L2 */
#endif

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

/* The taps of row position `row` (DEM coordinates) on level lev. */
static int level_taps(const ts_pyramid *P, int lev, double row, int idx[4], double w[4])
{
    const ts_pyr_level *L = &P->level[lev];
    return ts_pyr_taps((row + 0.5) / L->spacing - 0.5, L->rows, lev == 0, idx, w);
}

/* The row-level entry of row y for samples at `dist` steps on level lev;
 * the cells' own rows only with `own` (batch_row reads azimuth 0's). The
 * samples' rows and weights are those of `same` where it is given (an
 * azimuth of the batch with the same vy: the same rows and weights). */
static void row_level_fill(const hz_ctx *C, int y, int lev, double dist, int own,
                           const row_level *same, row_level *e)
{
    const ts_pyramid *P = C->P;
    double oy = dist * C->vy;
    int idx[4];
    double wd[4];
    if (same) {
        e->taps = same->taps;
        for (int t = 0; t < 4; t++)
            e->t[t] = same->t[t], e->wt[t] = same->wt[t];
    } else {
        e->taps = level_taps(P, lev, y + oy, idx, wd);
        for (int t = 0; t < 4; t++) {
            e->t[t] = ts_pyr_row(P, lev, idx[t < e->taps ? t : 0]);
            e->wt[t] = (float)wd[t < e->taps ? t : 0];
        }
    }
    /* the cells' own heights on the level: the DEM row itself on level 0 */
    int taps = own ? level_taps(P, lev, y, idx, wd) : 0;
    for (int t = 0; t < 4 && own; t++) {
        e->r[t] = ts_pyr_row(P, lev, idx[t < taps ? t : 0]);
        e->wr[t] = t < taps ? (float)wd[t] : 0.0f;
    }
    double d = dist * step_at(C, y + oy / 2);
    e->inv_d = (float)(1.0 / d);
    e->cd = (float)(C->c * d);
}

/* The columns [*t0, *t1] of the level row that the samples at column
 * offset ix + fx of the cells [x0, x1] read; 0 when none (not reached:
 * the runs keep the samples on the grid). */
static int sample_cols(int W, int ix, float fx, int x0, int x1, int *t0, int *t1)
{
    *t0 = x0 + ix;
    *t1 = x1 + ix + (fx > 0.0f);
    *t1 = *t1 > W - 1 ? W - 1 : *t1;
    return *t0 >= 0 && *t1 >= *t0;
}

/* The samples of the cells [x0, x1] described by e, at column offset
 * ix + fx, against their own heights R on the level, pushed as sample c
 * (the level row at the samples' row: combined into w->T, or shared). */
static void sample_level(const hz_ctx *C, row_ws *w, const row_level *e, const float *R, int ix,
                         float fx, int c, int x0, int x1)
{
    int t0, t1;
    const int W = C->P->grid->width;
    if (!sample_cols(W, ix, fx, x0, x1, &t0, &t1))
        return;
    const float *T = w->Tsh;
    if (t0 < w->t_lo || t1 > w->t_hi) {
        const level_max_row g = {w->m, R, e->wt, e->inv_d, e->cd};
        if (!C->bspline && ts_pyr_level_max_rows(&g, 1, e->t, e->taps, W, t1, ix, fx, x0, x1)) {
            w->t_lo = 1, w->t_hi = 0;
            return; /* the level maximum, its row kept in registers */
        }
        ts_pyr_combine_rows(e->t, e->wt, e->taps, t0, t1, w->T);
        w->T[t1 + 1] = w->T[t1]; /* a weight of fx = 0 there: no NaN from beyond */
        T = w->T;
    }
    w->t_lo = 1, w->t_hi = 0;
    if (!ts_pyr_level_run(w, T, ix, fx, R, e->inv_d, e->cd, C->bspline, c, x0, x1))
        ts_pyr_push_run(w, C->bspline, c, x0, x1, w->A);
}

/* The samples of the cells [x0, x1] of row y at `dist` steps on the DEM
 * (the cells' heights R), pushed as sample c (the last sample of a row
 * whose rays end early). */
static void sample_run(const hz_ctx *C, row_ws *w, int y, const float *R, double dist, int c,
                       int x0, int x1)
{
    double ox = dist * C->vx;
    double fl = floor(ox);
    row_level e;
    row_level_fill(C, y, 0, dist, 0, NULL, &e);
    sample_level(C, w, &e, R, (int)fl, (float)(ox - fl), c, x0, x1);
}

/* Where every ray of row y leaves the grid (top or bottom) or ends, in
 * steps. */
static double row_reach(const hz_ctx *C, int y)
{
    const int H = C->P->grid->height;
    double t_row = C->vy > 0 ? (H - 1 - y) / C->vy : C->vy < 0 ? y / -C->vy : INFINITY;
    if (C->cap > 0 && C->cap / C->step[y] < t_row)
        t_row = C->cap / C->step[y];
    return t_row;
}

/* Cells [a, b] drop out before sample j (B-spline: their sample number). */
static void mark_drop(const hz_ctx *C, row_ws *w, int a, int b, int j)
{
    if (C->bspline)
        for (int x = a; x <= b; x++)
            w->jd[x] = j;
}

/* A row's cells [c0, c1) for one azimuth, level by level: the run [pa, pb]
 * of those whose samples lie on the grid so far (empty once every ray has
 * ended), and [fa, fb], those whose rays end at the row's reach t_row. */
typedef struct {
    int pa, pb, fa, fb;
    double t_row;
} row_run;

static void row_start(const hz_ctx *C, row_ws *w, int y, int c0, int c1, row_run *r)
{
    ts_pyr_clear_max(w, c0, c1 - 1);
    *r = (row_run){c0, c1 - 1, c1, c1 - 1, row_reach(C, y)};
}

/* The range of the run that sample j keeps, [*xa, *xb] (empty: none), and
 * whether the sample is read on level j (0: the rays end before it). */
static int row_keeps(const hz_ctx *C, const row_run *r, int j, int *xa, int *xb)
{
    const level_az *L = &C->lv[j];
    *xa = L->xa > r->pa ? L->xa : r->pa;
    *xb = L->xb < r->pb ? L->xb : r->pb;
    return L->s <= r->t_row;
}

/* Sample j of the run of row y (R0: the cells' heights on the DEM): the
 * cells whose rays leave the grid drop out, and where the rays end before
 * the sample, their last one; returns 1 where the sample is instead read
 * on level j for the cells [r->pa, r->pb] (sample_level, the caller's). */
static int row_advance(const hz_ctx *C, row_ws *w, int y, int j, const float *R0, row_run *r)
{
    int pa = r->pa, pb = r->pb, xa, xb;
    if (pa > pb)
        return 0;
    int on_level = row_keeps(C, r, j, &xa, &xb);
    if (xa > xb) {
        mark_drop(C, w, pa, pb, j);
        r->pa = 1, r->pb = 0;
        return 0;
    }
    mark_drop(C, w, pa, xa - 1, j);
    mark_drop(C, w, xb + 1, pb, j);
    pa = r->pa = xa, pb = r->pb = xb;
    if (on_level)
        return 1;
    /* the row's rays end here: one last sample on the DEM */
    float *out = w->out;
    if (r->t_row > 1e-9) {
        sample_run(C, w, y, R0, r->t_row, j, pa, pb);
        ts_pyr_finish_run(w, C->bspline, j + 1, pa, pb, out);
    } else if (j == 0) {
        for (int x = pa; x <= pb; x++)
            out[x] = -90.0f; /* nothing beyond these cells */
    } else {
        ts_pyr_finish_run(w, C->bspline, j, pa, pb, out);
    }
    r->fa = pa, r->fb = pb;
    r->pa = 1, r->pb = 0;
    return 0;
}

/* The horizons of the cells of row y that dropped out, and nodata where
 * the span has any (`holes`). */
static void row_finish(const hz_ctx *C, row_ws *w, int y, int c0, int c1, const row_run *r,
                       int holes)
{
    const ts_grid *g = C->P->grid;
    float *out = w->out;
    if (r->pa <= r->pb) /* not reached: the coarsest spacing spans the grid */
        mark_drop(C, w, r->pa, r->pb, C->P->levels);
    ts_pyr_drop_cells(C, w, y, c0, r->fa - 1, r->t_row, out);
    ts_pyr_drop_cells(C, w, y, r->fb + 1, c1 - 1, r->t_row, out);
    const float *z = g->z + (ptrdiff_t)y * g->stride;
    if (!holes)
        return;
    for (int x = c0; x < c1; x++) {
        float o = out[x]; /* a select, not a branch: the loop vectorises */
        out[x] = z[x] == z[x] ? o : NAN;
    }
}

/* Whether two entries read the same level rows (and with `weights`, with
 * the same weights). */
static int same_rows(const row_level *a, const row_level *b, int weights)
{
    if (a->taps != b->taps)
        return 0;
    for (int t = 0; t < a->taps; t++)
        if (a->t[t] != b->t[t] || (weights && a->wt[t] != b->wt[t]))
            return 0;
    return 1;
}

/* Sample j's level row, combined once into Tsh for the azimuths that read
 * the same rows with the same weights (the y-major azimuths of a batch all
 * do: their vy is the same +-1) where the union of the columns they read
 * is no wider than their sum. Only samples with a fraction fx > 0 share:
 * they read no column past their own, so sample_level has no end to pad. */
static void share_level_row(const batch_ctx *B, row_ws *w, const row_level *const *rl,
                            const row_run *run, int j, float *Tsh)
{
    int t0[TS_PYRAMID_BATCH], t1[TS_PYRAMID_BATCH], in[TS_PYRAMID_BATCH];
    int lo = INT_MAX, hi = INT_MIN, sum = 0, members = 0, xa, xb;
    const row_level *e0 = NULL;
    for (int a = 0; a < B->n; a++) {
        const level_az *L = &B->az[a].lv[j];
        in[a] = run[a].pa <= run[a].pb && row_keeps(&B->az[a], &run[a], j, &xa, &xb) &&
                xa <= xb && L->fx > 0.0f &&
                sample_cols(B->az[a].P->grid->width, L->ix, L->fx, xa, xb, &t0[a], &t1[a]) &&
                (!e0 || same_rows(e0, &rl[a][j], 1));
        if (!in[a])
            continue;
        e0 = e0 ? e0 : &rl[a][j];
        lo = t0[a] < lo ? t0[a] : lo;
        hi = t1[a] > hi ? t1[a] : hi;
        sum += t1[a] - t0[a] + 1;
        members++;
    }
    if (members < 2 || hi - lo + 1 > sum)
        return;
    ts_pyr_combine_rows(e0->t, e0->wt, e0->taps, lo, hi, Tsh);
    for (int a = 0; a < B->n; a++)
        if (in[a])
            w[a].Tsh = Tsh, w[a].t_lo = lo, w[a].t_hi = hi;
}

/* A grid row that batch_rows computes: its azimuths' states w (n) and
 * row-level entries rl (n), the cells' heights on the DEM (R0) and on the
 * level being read (R, or R0: Rj), the shared level row (Tsh), the runs. */
typedef struct {
    int y;
    row_ws *w;
    const row_level *rl[TS_PYRAMID_BATCH];
    float *R0, *R, *Tsh;
    const float *Rj;
    row_run run[TS_PYRAMID_BATCH];
} grid_row;

/* Sample j of azimuth a for the two grid rows g at once where their
 * samples read the same level rows at the same cells, each row for its
 * own (the level maximum in registers; not the rows shared with other
 * azimuths): the rows loaded once for both. Returns 0 where not done. */
static int sample_pair(const hz_ctx *C, grid_row g[2], int a, int j)
{
    const row_run *r0 = &g[0].run[a], *r1 = &g[1].run[a];
    const row_level *e0 = &g[0].rl[a][j], *e1 = &g[1].rl[a][j];
    const int W = C->P->grid->width, ix = C->lv[j].ix;
    const float fx = C->lv[j].fx;
    int t0, t1;
    if (C->bspline || r0->pa != r1->pa || r0->pb != r1->pb || !same_rows(e0, e1, 0) ||
        !sample_cols(W, ix, fx, r0->pa, r0->pb, &t0, &t1))
        return 0;
    for (int i = 0; i < 2; i++)
        if (t0 >= g[i].w[a].t_lo && t1 <= g[i].w[a].t_hi)
            return 0;
    const level_max_row m[2] = {{g[0].w[a].m, g[0].Rj, e0->wt, e0->inv_d, e0->cd},
                                {g[1].w[a].m, g[1].Rj, e1->wt, e1->inv_d, e1->cd}};
    if (!ts_pyr_level_max_rows(m, 2, e0->t, e0->taps, W, t1, ix, fx, r0->pa, r0->pb))
        return 0;
    g[0].w[a].t_lo = g[1].w[a].t_lo = 1;
    g[0].w[a].t_hi = g[1].w[a].t_hi = 0;
    return 1;
}

/* Level j's heights of the cells of grid row g (the same rows and weights
 * for every azimuth, from azimuth 0's entries) over the runs that read
 * them, into g->R (g->Rj; on the DEM: R0), and the shared level rows. */
static void level_heights(const batch_ctx *B, grid_row *g, int j, int c0, int c1)
{
    int lo = c1, hi = c0 - 1, xa, xb;
    for (int a = 0; a < B->n; a++)
        if (g->run[a].pa <= g->run[a].pb && row_keeps(&B->az[a], &g->run[a], j, &xa, &xb)) {
            lo = xa < lo ? xa : lo;
            hi = xb > hi ? xb : hi;
        }
    g->Rj = g->R0;
    if (lo <= hi && B->az[0].lv[j].lev > 0) {
        ts_pyr_combine_rows(g->rl[0][j].r, g->rl[0][j].wr, 4, lo, hi, g->R);
        ts_pyr_fill_nodata(g->R, g->R0, lo, hi);
        g->Rj = g->R;
    }
    if (B->share)
        share_level_row(B, g->w, g->rl, g->run, j, g->Tsh);
}

/* The cells [c0, c1) of the `rows` (1 or 2) grid rows g for every azimuth
 * of B, level by level: the cells' own heights on a level are computed
 * once per row for all azimuths (level_heights), and two rows whose
 * samples read the same level rows read them once (sample_pair). */
static void batch_rows(const batch_ctx *B, grid_row *g, int rows, int c0, int c1)
{
    const int levels = B->az[0].P->levels;
    for (int i = 0; i < rows; i++) {
        for (int a = 0; a < B->n; a++)
            row_start(&B->az[a], &g[i].w[a], g[i].y, c0, c1, &g[i].run[a]);
        /* 4 taps, weight 0 unused: as the one-azimuth sums */
        ts_pyr_combine_rows(g[i].rl[0][0].r, g[i].rl[0][0].wr, 4, c0, c1 - 1, g[i].R0);
    }
    for (int j = 0; j < levels; j++) {
        for (int i = 0; i < rows; i++)
            level_heights(B, &g[i], j, c0, c1);
        int active = 0;
        for (int a = 0; a < B->n; a++) {
            const hz_ctx *C = &B->az[a];
            int due[2] = {0, 0};
            for (int i = 0; i < rows; i++)
                due[i] = row_advance(C, &g[i].w[a], g[i].y, j, g[i].R0, &g[i].run[a]);
            if (rows == 2 && due[0] && due[1] && sample_pair(C, g, a, j))
                due[0] = due[1] = 0;
            for (int i = 0; i < rows; i++) {
                if (due[i])
                    sample_level(C, &g[i].w[a], &g[i].rl[a][j], g[i].Rj, C->lv[j].ix,
                                 C->lv[j].fx, j, g[i].run[a].pa, g[i].run[a].pb);
                active |= g[i].run[a].pa <= g[i].run[a].pb;
            }
        }
        if (!active)
            break;
    }
    /* whether the span has nodata: looked for once, not per azimuth */
    const ts_grid *grid = B->az[0].P->grid;
    for (int i = 0; i < rows; i++) {
        const float *z = grid->z + (ptrdiff_t)g[i].y * grid->stride;
        int holes = ts_pyr_has_nodata(z, c0, c1 - 1);
        for (int a = 0; a < B->n; a++)
            row_finish(&B->az[a], &g[i].w[a], g[i].y, c0, c1, &g[i].run[a], holes);
    }
}

/* The cells [c0, c1) of row y, just computed for the batch (w: its
 * azimuths' row states, whose out holds the row): the edge, then the sky
 * terms azimuth by azimuth (the order of the planes). */
static void span_done(const batch_ctx *B, const row_ws *w, int y, int c0, int c1)
{
    size_t at = (size_t)y * B->az[0].P->grid->width;
    for (int a = 0; B->edge && a < B->n; a++)
        ts_edge_span_row(&B->edge[a], y, w[a].out, c0, c1);
    for (int a = 0; B->sky && a < B->n; a++)
        ts_sky_plane_add_span(&B->sky[a], w[a].out + c0, at + c0, at + c1);
}

void ts_pyr_rows_range(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const batch_ctx *B = ctx;
    const int n = B->n, W = B->az[0].P->grid->width, levels = B->az[0].P->levels;
    /* per grid row of a pair and azimuth s0, s1, s2, m, T and the samples
     * (T and the samples W + 1), each on a cache line as the level rows
     * (ts_pyr_alloc): the runs' vectors then lie within a line where a run
     * starts on one */
    const size_t P = ((size_t)W + 1 + 15) / 16 * 16;
    float *buf = ts_pyr_alloc((size_t)2 * n * 6 * P * sizeof *buf);
    float *own = ts_pyr_alloc(2 * 3 * P * sizeof *own);
    double *tpp = ts_pyr_alloc(3 * P * sizeof *tpp);
    int *jd = ts_pyr_alloc((size_t)2 * n * P * sizeof *jd);
    row_level *rl = malloc((size_t)n * TS_PYR_ROW_BLOCK * levels * sizeof *rl);
    /* without planes (only the sky sums wanted), each grid row of a pair
     * and azimuth is written to a row of scratch, summed, then reused */
    const int planes = B->az[0].out != NULL;
    float *scratch = planes ? NULL : ts_pyr_alloc((size_t)2 * n * P * sizeof *scratch);
    row_ws w[2][TS_PYRAMID_BATCH];
    if (!buf || !own || !tpp || !jd || !rl || (!planes && !scratch)) {
        free(buf);
        free(own);
        free(tpp);
        free(jd);
        free(rl);
        free(scratch);
        __atomic_store_n(B->az[0].alloc_failed, 1, __ATOMIC_RELAXED);
        return;
    }
    for (int i = 0; i < 2; i++)
        for (int a = 0; a < n; a++) {
            float *f = buf + ((size_t)i * n + a) * 6 * P;
            w[i][a] = (row_ws){f, f + P, f + 2 * P, f + 3 * P, f + 4 * P, f + 5 * P, tpp,
                               jd + ((size_t)i * n + a) * P, NULL, 1, 0, NULL};
        }
    for (long yb = y0; yb < y1; yb += TS_PYR_ROW_BLOCK) {
        long ye = yb + TS_PYR_ROW_BLOCK < y1 ? yb + TS_PYR_ROW_BLOCK : y1;
        for (int a = 0; a < n; a++) {
            /* an earlier azimuth with the same vy reads the same level rows */
            const int b = B->same_vy[a];
            for (long y = yb; y < ye; y++)
                for (int j = 0; j < levels; j++) {
                    const level_az *L = &B->az[a].lv[j], *Lb = &B->az[b].lv[j];
                    size_t at = (size_t)(y - yb) * levels + j;
                    const row_level *same = b < a && Lb->lev == L->lev && Lb->s == L->s
                                                ? &rl[(size_t)b * TS_PYR_ROW_BLOCK * levels + at]
                                                : NULL;
                    row_level_fill(&B->az[a], (int)y, L->lev, L->s, a == 0, same,
                                   &rl[(size_t)a * TS_PYR_ROW_BLOCK * levels + at]);
                }
        }
        /* a chunk of columns down the rows, two rows at a time, then the
         * next chunk: the level rows that the cells of a chunk read stay in
         * the cache from row to row */
        for (int c0 = 0; c0 < W; c0 += CHUNK) {
            int c1 = c0 + CHUNK < W ? c0 + CHUNK : W;
            for (long y = yb; y < ye; y += 2) {
                const int rows = y + 1 < ye ? 2 : 1;
                grid_row g[2];
                for (int i = 0; i < rows; i++) {
                    float *o = own + (size_t)i * 3 * P;
                    g[i].y = (int)y + i;
                    g[i].w = w[i];
                    g[i].R0 = o, g[i].R = o + P, g[i].Tsh = o + 2 * P;
                    for (int a = 0; a < n; a++) {
                        w[i][a].out = planes ? B->az[a].out + (size_t)(y + i) * W
                                             : scratch + ((size_t)i * n + a) * P;
                        g[i].rl[a] = &rl[((size_t)a * TS_PYR_ROW_BLOCK + (y + i - yb)) * levels];
                    }
                }
                batch_rows(B, g, rows, c0, c1);
                for (int i = 0; i < rows; i++)
                    span_done(B, w[i], (int)y + i, c0, c1);
            }
        }
    }
    free(scratch);
    free(rl);
    free(jd);
    free(tpp);
    free(own);
    free(buf);
}
