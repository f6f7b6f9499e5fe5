/* Exact near-field horizon on the bilinear surface; see near_field.h. The
 * per-cell formulas are core/cellmath/cm_near_field.h, shared with the
 * OpenCL kernels; this file holds the plan and the C loops. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "near_field.h"
#include "near_run512.h"
#include "simd_clones.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void ts_near_plan_init(ts_near_plan *p, const ts_line_geom *g)
{
    p->t = g->t;
    /* Break points: whole steps (new column) and v crossing an integer. */
    double br[4 * TS_NEAR_STEPS + 4];
    int nb = 0;
    br[nb++] = 0.0;
    for (int j = 1; j <= TS_NEAR_STEPS; j++)
        br[nb++] = j;
    double at = fabs(g->t);
    if (at > 1e-12)
        for (int m = 1; m / at < TS_NEAR_STEPS - 1e-9 && nb < (int)(sizeof br / sizeof *br); m++)
            br[nb++] = m / at;
    qsort(br, nb, sizeof *br, cmp_double);
    p->npieces = 0;
    for (int j = 0; j + 1 < nb && p->npieces < TS_NEAR_MAX_PIECES; j++) {
        if (br[j + 1] - br[j] < 1e-9)
            continue;
        double mid = 0.5 * (br[j] + br[j + 1]);
        int n = p->npieces++;
        p->piece_sa[n] = br[j];
        p->piece_sb[n] = br[j + 1];
        p->piece_du[n] = (int)floor(-mid);
        p->piece_dv[n] = at > 1e-12 ? (int)floor(-g->t * mid) : 0;
    }
    p->du_min = p->dv_min = p->dv_max = 0;
    for (int n = 0; n < p->npieces; n++) {
        const int dv_top = p->piece_dv[n] + (at > 1e-12); /* the 01 and 11 corners */
        p->du_min = p->piece_du[n] < p->du_min ? p->piece_du[n] : p->du_min;
        p->dv_min = p->piece_dv[n] < p->dv_min ? p->piece_dv[n] : p->dv_min;
        p->dv_max = dv_top > p->dv_max ? dv_top : p->dv_max;
    }
    for (int n = 0; n < p->npieces; n++) {
        ptrdiff_t o = p->piece_du[n] * g->u_stride + p->piece_dv[n] * g->v_stride;
        p->piece_off[n][0] = o;
        p->piece_off[n][1] = o + g->u_stride;
        p->piece_off[n][2] = o + g->v_stride;
        p->piece_off[n][3] = o + g->u_stride + g->v_stride;
    }
}

static cm_ray_grid ray_grid(const ts_line_geom *g, const float *z)
{
    cm_ray_grid r = {z, g->V, g->t, g->origin, g->u_stride, g->v_stride};
    return r;
}

float ts_near_field(const ts_near_plan *p, const ts_line_geom *g, const float *z, int k,
                    int i, float h, double step, double c, double cap, int *left)
{
    cm_ray_grid r = ray_grid(g, z);
    r.t = p->t;
    cm_near_tables q = {p->npieces, p->piece_du, p->piece_dv, p->piece_sa, p->piece_sb};
    return cm_near_exact(&r, &q, k, i, h, step, c, cap, left);
}

float ts_ray_exact(const ts_line_geom *g, const float *z, int k, int i, float h, double s_from,
                   double s_to, double step, double c)
{
    cm_ray_grid r = ray_grid(g, z);
    return cm_ray_exact(&r, k, i, h, s_from, s_to, step, c);
}

/* The inner peaks of one piece at the queued cells qx[0..n) (few: the
 * test finds one at a cell in a few per cent), in scalar code. */
static void near_peaks(const cm_fast_piece *q, const float *const cn[4], const float *zrow,
                       float t, float L, float c, const int *qx, int n, float *restrict best)
{
    for (int e = 0; e < n; e++) {
        const int x = qx[e];
        const float fs = cm_fast_peak(*q, t, cn[0][x], cn[1][x], cn[2][x], cn[3][x], zrow[x], L, c);
        best[x] = fs > best[x] ? fs : best[x];
    }
}

/* The pieces over a run of cells, one piece at a time: plain float
 * arithmetic in loops the compiler vectorises (cm_fast_piece's slopes;
 * prev: the slopes at the previous piece's end). The cells whose inner
 * peak the test finds are queued (qx) and their peaks solved after the
 * loop, so that the loop does not compute a square root and two divisions
 * at every cell for the few that need them (the AVX-512 run does the same;
 * the maximum does not depend on the order). Cells with a corner that is
 * nodata or infinite are flagged and redone in scalar code. */
TS_SIMD_CLONES
static void near_run(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                     float L, float c, float *restrict best, float *restrict flag,
                     float *restrict prev, unsigned char *restrict peak, int *restrict qx)
{
    for (int x = x0; x < x1; x++) {
        best[x] = -INFINITY;
        flag[x] = 0.0f;
    }
    const float t = (float)p->t;
    const int flat_v = fabs(p->t) <= 1e-12;
    for (int n = 0; n < p->npieces; n++) {
        const float *restrict c00 = zrow + p->piece_off[n][0];
        const float *restrict c10 = zrow + p->piece_off[n][1];
        const float *restrict c01 = zrow + p->piece_off[n][2];
        const float *restrict c11 = zrow + p->piece_off[n][3];
        const cm_fast_piece q = cm_fast_piece_init(p->piece_du[n], p->piece_dv[n], flat_v,
                                                   p->piece_sa[n], p->piece_sb[n], p->t, L, c);
        const float *cn[4] = {c00, c10, c01, c11};
        const float *restrict n0 = cn[q.e0], *restrict n1 = cn[q.e1];
        /* the ray's start (no inner peak) in a loop of its own: one loop
         * with the start's term and the peak test under if (q.has_sa)
         * vectorises badly, an AVX2 CPU's sweep 1.6x slower (cpu_levels.sh) */
        if (!q.has_sa) {
            for (int x = x0; x < x1; x++) {
                const float X = cm_fast_twist(c00[x], c10[x], c01[x], c11[x]);
                const float f = cm_fast_cross(q, n0[x], n1[x], zrow[x]);
                const float s0 = cm_fast_start(q, t, c00[x], c10[x], c01[x], c11[x]);
                const float m = s0 > f ? s0 : f;
                best[x] = m > best[x] ? m : best[x];
                prev[x] = f;
                flag[x] += X - X == 0.0f ? 0.0f : 1.0f;
            }
            continue;
        }
        for (int x = x0; x < x1; x++) {
            const float X = cm_fast_twist(c00[x], c10[x], c01[x], c11[x]);
            const float f = cm_fast_cross(q, n0[x], n1[x], zrow[x]);
            peak[x] = (unsigned char)cm_fast_peak_test(q, t, X, prev[x], f);
            best[x] = f > best[x] ? f : best[x];
            prev[x] = f;
            flag[x] += X - X == 0.0f ? 0.0f : 1.0f;
        }
        int nq = 0;
        for (int x = x0; x < x1; x++) { /* branch-free: qx has room for every cell */
            qx[nq] = x;
            nq += peak[x];
        }
        near_peaks(&q, cn, zrow, t, L, c, qx, nq, best);
    }
}

/* Piece n's slope at cells e0 <= e < e1 (corners c00[e] .. c11[e], height
 * hz[e]), folded into best[e]: what cm_near_piece gives, with the same
 * double operations, in a loop the compiler vectorises. voids = 0: for
 * corners without nodata, the cells with a nodata corner (where
 * cm_near_piece takes its other branch) counted in flag[e]; voids = 1:
 * both branches, each cell's own selected, where a ray crosses nodata
 * (speckled voids flag most cells of a row, and the scalar near field made
 * such a DEM's sweep 7x dearer). An end's slope (he - h) / (s L) - c s L
 * has the form of the polynomial's at s, so the one division takes either
 * numerator. */
static inline __attribute__((always_inline)) void
exact_piece(const ts_near_plan *p, int n, const float *restrict c00, const float *restrict c10,
            const float *restrict c01, const float *restrict c11, const float *restrict hz,
            int e0, int e1, double smax, double L, double c, int voids, double *restrict best,
            float *restrict flag)
{
    const int flat_v = fabs(p->t) <= 1e-12; /* along a grid line: 01, 11 weigh nothing */
    const double t = flat_v ? 0 : p->t;
    const double a0 = -p->piece_du[n], b0 = flat_v ? 0 : -p->piece_dv[n];
    const double sa = p->piece_sa[n], sb = p->piece_sb[n] < smax ? p->piece_sb[n] : smax;
    const int has_sa = sa > 0;
    /* a nodata patch's ends on grid lines (cm_edge_height's weights) */
    double wa[4], wb[4];
    cm_edge_weights(a0 - sa, b0 - t * sa, wa);
    cm_edge_weights(a0 - sb, b0 - t * sb, wb);
    const double ca = c * sa * L, cb = c * sb * L, la = sa * L, lb = sb * L;
    for (int e = e0; e < e1; e++) {
        const float h0 = c00[e], h1 = c10[e], h2 = c01[e], h3 = c11[e];
        const float A = h1 - h0, B = h2 - h0, X = h3 - h1 - h2 + h0;
        const int nodata = (h0 != h0) | (h1 != h1) | (h2 != h2) | (h3 != h3);
        double alpha, beta, gamma;
        cm_patch_poly(h0, A, B, X, a0, b0, t, &alpha, &beta, &gamma);
        const double P = alpha - hz[e];
        double m;
        if (!voids) {
            m = cm_piece_max(P, beta, gamma, sa, sb, L, c);
            flag[e] += nodata ? 1.0f : 0.0f;
        } else {
            /* cm_edge_height's sums */
            const double ea = cm_edge_sum(wa, h0, h1, h2, h3);
            const double eb = cm_edge_sum(wb, h0, h1, h2, h3);
            const double na = nodata ? ea - hz[e] : P + beta * sa + gamma * sa * sa;
            const double nb = nodata ? eb - hz[e] : P + beta * sb + gamma * sb * sb;
            const double fa = has_sa ? na / la - ca : beta / L, fb = nb / lb - cb;
            /* cm_near_piece's nodata branch: the valid ends' largest */
            double me = has_sa && fa > -INFINITY ? fa : -INFINITY;
            me = fb > me ? fb : me;
            m = nodata ? me : cm_piece_max_ends(P, beta, gamma, sa, sb, L, c, fa, fb);
        }
        best[e] = m > best[e] ? m : best[e];
    }
}

/* Piece n's corners 00, 10, 01, 11 from a cell, as element offsets (a
 * ray along a grid line: 01 and 11 are 00 and 10, which alone weigh). */
static void piece_corners(const ts_near_plan *p, int n, ptrdiff_t off[4])
{
    const int flat_v = fabs(p->t) <= 1e-12;
    for (int j = 0; j < 4; j++)
        off[j] = p->piece_off[n][flat_v ? j & 1 : j];
}

/* cm_near_exact over cells x0 <= x < x1 of a row whose pieces before
 * n_end are on the grid: those pieces before smax steps (with sb cut
 * there), each by exact_piece (voids as there; flag[x] is left 0 with
 * voids). best: doubles. */
static inline __attribute__((always_inline)) void
exact_cells(const ts_near_plan *p, const float *restrict zrow, int x0, int x1, int n_end,
            double smax, double L, double c, int voids, double *restrict best,
            float *restrict flag)
{
    for (int x = x0; x < x1; x++) {
        best[x] = -INFINITY;
        flag[x] = 0.0f;
    }
    for (int n = 0; n < n_end && p->piece_sa[n] < smax; n++) {
        ptrdiff_t o[4];
        piece_corners(p, n, o);
        exact_piece(p, n, zrow + o[0], zrow + o[1], zrow + o[2], zrow + o[3], zrow, x0, x1, smax,
                    L, c, voids, best, flag);
    }
}

TS_SIMD_CLONES
static void exact_run(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                      int n_end, double smax, double L, double c, double *restrict best,
                      float *restrict flag)
{
    exact_cells(p, zrow, x0, x1, n_end, smax, L, c, 0, best, flag);
}

TS_SIMD_CLONES
static void exact_run_voids(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                            int n_end, double smax, double L, double c, double *restrict best,
                            float *restrict flag)
{
    exact_cells(p, zrow, x0, x1, n_end, smax, L, c, 1, best, flag);
}

/* Cells of a list that exact_list_voids takes at a time. */
#define LIST_CHUNK 128
/* Where more than this share of a row's cells is listed, exact_run_voids
 * takes the whole row (its unlisted cells' answers dropped) rather than
 * gather the listed ones: svf of a 1024^2 DEM took 7 % less time so at 10 %
 * voids (nearly every cell listed), and 1.5x more at 1 %. */
#define LIST_MOST 0.8

/* exact_run_voids over the listed cells qx[0..nq) of an interior row (no
 * cap), best[e] for cell qx[e]: each piece's corners gathered into rows of
 * their own, LIST_CHUNK cells at a time, for the vector loop. */
TS_SIMD_CLONES
static void exact_list_voids(const ts_near_plan *p, const float *restrict zrow,
                             const int *restrict qx, int nq, double L, double c,
                             double *restrict best)
{
    float cn[4][LIST_CHUNK], hz[LIST_CHUNK], flag[LIST_CHUNK];
    for (int e0 = 0; e0 < nq; e0 += LIST_CHUNK) {
        const int ne = nq - e0 < LIST_CHUNK ? nq - e0 : LIST_CHUNK;
        const int *restrict x = qx + e0;
        double *restrict b = best + e0;
        for (int e = 0; e < ne; e++) {
            hz[e] = zrow[x[e]];
            b[e] = -INFINITY;
        }
        for (int n = 0; n < p->npieces; n++) {
            ptrdiff_t o[4];
            piece_corners(p, n, o);
            for (int j = 0; j < 4; j++)
                for (int e = 0; e < ne; e++)
                    cn[j][e] = zrow[x[e] + o[j]];
            exact_piece(p, n, cn[0], cn[1], cn[2], cn[3], hz, 0, ne, INFINITY, L, c, 1, b,
                        flag);
        }
    }
}

/* out[x] = max(best[x], out[x]) over the cells with a height and no flag,
 * branch-free; returns whether any cell is flagged. */
TS_SIMD_CLONES
static int near_merge(const float *restrict zrow, const float *restrict best,
                      const float *restrict flag, int x0, int x1, float *restrict out)
{
    int flagged = 0;
    for (int x = x0; x < x1; x++) {
        const float o = out[x], b = best[x] + 0.0f; /* +0 for -0, which the fold may give */
        const int take = (zrow[x] == zrow[x]) & (flag[x] == 0.0f) & (b > o);
        out[x] = take ? b : o;
        flagged |= flag[x] != 0.0f;
    }
    return flagged;
}

void ts_near_row(const ts_near_plan *p, const float *zrow, int x0, int x1, double step,
                 double c, float *out, float *scratch)
{
    /* best in zrow's phase on 64-byte lines (ts_near_run_avx512's aligned
     * vectors) */
    const size_t phase = (((uintptr_t)zrow - (uintptr_t)scratch) / sizeof(float)) & 15;
    float *best = scratch + phase, *flag = best + x1, *queue = flag + x1;
    if (!ts_near_run_avx512(p, zrow, x0, x1, (float)step, (float)c, best, flag, queue))
        /* prev, the queued cells and their tests in the queue's room
         * (TS_NEAR_ROW_SCRATCH: 5 x1 floats and more) */
        near_run(p, zrow, x0, x1, (float)step, (float)c, best, flag, queue,
                 (unsigned char *)(queue + 2 * (size_t)x1), (int *)(queue + x1));
    if (!near_merge(zrow, best, flag, x0, x1, out))
        return;
    /* cells whose near field touches nodata: ts_near_field's arithmetic,
     * vectorised over the list of them, in the queue's room
     * (TS_NEAR_ROW_SCRATCH leaves 5 x1 floats there): a double, a flag and
     * an int a cell */
    double *exact = (double *)(scratch + ((phase + 2 * (size_t)x1 + 1) & ~(size_t)1));
    float *unused = (float *)(exact + x1);
    int *qx = (int *)(unused + x1), nq = 0;
    for (int x = x0; x < x1; x++) {
        qx[nq] = x;
        nq += flag[x] != 0.0f && zrow[x] == zrow[x];
    }
    if (nq > LIST_MOST * (x1 - x0)) { /* most of the row: no gathers */
        exact_run_voids(p, zrow, x0, x1, p->npieces, INFINITY, step, c, exact, unused);
        for (int e = 0; e < nq; e++)
            exact[e] = exact[qx[e]];
    } else {
        exact_list_voids(p, zrow, qx, nq, step, c, exact);
    }
    for (int e = 0; e < nq; e++) {
        const int x = qx[e];
        const float nf = (float)exact[e];
        out[x] = nf > out[x] ? nf : out[x];
    }
}

/* ts_near_field's answer for cell x of row y, and whether the ray left. */
static float near_cell(const ts_near_plan *p, const ts_line_geom *g, const float *z,
                       const float *zrow, int y, int x, double step, double c, double cap,
                       int *left)
{
    int u = g->x_major ? x : y, v = g->x_major ? y : x;
    return ts_near_field(p, g, z, (u - g->u_start) * g->u_step, v, zrow[x], step, c, cap, left);
}

/* Whether every piece of cell x of row y is on the grid. */
static int near_on_grid(const ts_near_plan *p, const ts_line_geom *g, int y, int x)
{
    int u = g->x_major ? x : y, i = g->x_major ? y : x, k = (u - g->u_start) * g->u_step;
    return k + p->du_min >= 0 && i + p->dv_min >= 0 && i + p->dv_max <= g->V - 1;
}

/* The first piece of cell x of row y whose patch is off the grid, as
 * cm_near_exact tests them (npieces: none). */
static int near_first_off(const ts_near_plan *p, const ts_line_geom *g, int y, int x)
{
    int u = g->x_major ? x : y, i = g->x_major ? y : x, k = (u - g->u_start) * g->u_step;
    const int V = g->V, flat_v = fabs(p->t) <= 1e-12;
    for (int n = 0; n < p->npieces; n++)
        if (cm_piece_off_grid(k + p->piece_du[n], i + p->piece_dv[n], V, flat_v))
            return n;
    return p->npieces;
}

/* Cells whose rays leave the grid at the same piece (along an edge the
 * ray heads for) take exact_run from this many on; fewer, ts_near_field. */
#define OFF_RUN_MIN 8

void ts_near_edges(const ts_near_plan *p, const ts_line_geom *g, const float *z,
                   const float *zrow, int y, int xa, int xb, int W, double step, double c,
                   double cap, float *out, float *scratch)
{
    double *best = (double *)scratch;
    float *flag = scratch + 2 * (size_t)W;
    const double smax = cap > 0 ? cap / step : INFINITY; /* as cm_near_exact */
    int nsmax = 0; /* the first piece cm_near_exact stops at for the cap */
    while (nsmax < p->npieces && p->piece_sa[nsmax] < smax)
        nsmax++;
    for (int x = 0; x < W;) {
        if (x == xa) {
            x = xb;
            continue;
        }
        /* the run of cells from x whose pieces are all on the grid, or
         * else whose rays leave it at the same piece n_end, together;
         * cm_near_exact returns what it found before that piece, and says
         * the ray left where the cap did not stop it first */
        const int end = x < xa ? xa : W;
        int x1 = x, n_end = p->npieces, left_all = 0;
        while (x1 < end && near_on_grid(p, g, y, x1))
            x1++;
        if (x1 == x) {
            n_end = near_first_off(p, g, y, x);
            x1 = x + 1;
            while (x1 < end && !near_on_grid(p, g, y, x1) && near_first_off(p, g, y, x1) == n_end)
                x1++;
            left_all = n_end < p->npieces && n_end <= nsmax;
            if (x1 - x < OFF_RUN_MIN) {
                for (; x < x1; x++) /* ts_near_field tells where the ray left */
                    if (!isnan(zrow[x])) {
                        int left;
                        float nf = near_cell(p, g, z, zrow, y, x, step, c, cap, &left);
                        out[x] = left ? nf : fmaxf(nf, out[x]);
                    }
                continue;
            }
        }
        exact_run(p, zrow, x, x1, n_end, smax, step, c, best, flag);
        int flagged = 0;
        for (int xf = x; xf < x1; xf++)
            flagged |= flag[xf] != 0.0f;
        if (flagged) /* a nodata corner: the run again, both branches */
            exact_run_voids(p, zrow, x, x1, n_end, smax, step, c, best, flag);
        for (; x < x1; x++) {
            if (isnan(zrow[x]))
                continue;
            const int left = left_all; /* near_cell's too: 0 on the grid */
            const float nf = (float)best[x];
            out[x] = left ? nf : fmaxf(nf, out[x]);
        }
    }
}
