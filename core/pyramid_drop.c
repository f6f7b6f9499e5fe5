/*
 * The last samples of pyramid horizons (core/pyramid_horizon.c): the rays
 * that leave the grid through a side, or end at the row's reach, before a
 * level's sample get one last sample where they end, read bilinearly on
 * the DEM, then their horizons; in branch-free loops the compiler
 * vectorises, once a row.
 */
#include <limits.h>
#include <math.h>

#include "cellmath/cm_fastmath.h"
#include "pyramid_hz.h"

/* Where the ray of cell x leaves the grid's columns, in steps: `side`
 * says how (1, -1: vx = +-1, an x-major azimuth, no division; 2, -2: the
 * sign of another vx; 0: vx = 0, never). */
static inline __attribute__((always_inline)) double side_exit(int side, double lim, double vx,
                                                              int x)
{
    return side == 1    ? lim - x
           : side == -1 ? (double)x
           : side == 2  ? (lim - x) / vx
           : side == -2 ? x / -vx
                        : INFINITY;
}

/* Where the rays of the cells [a, b] end (drop_cells): t steps (at most
 * t_row), at DEM column px and row py, into tpp's three rows. */
static inline __attribute__((always_inline)) void drop_ends(const hz_ctx *C, int side, int y,
                                                            int a, int b, double t_row,
                                                            double *restrict tpp)
{
    const int W = C->P->grid->width;
    const double vx = C->vx, vy = C->vy, lim = W - 1, bot_y = C->P->grid->height - 1;
    for (int x = a; x <= b; x++) {
        double t = side_exit(side, lim, vx, x);
        t = t < t_row ? t : t_row;
        double px = x + t * vx, py = y + t * vy;
        tpp[x] = t;
        tpp[W + x] = px < 0 ? 0 : px > lim ? lim : px;
        tpp[2 * W + x] = py < 0 ? 0 : py > bot_y ? bot_y : py;
    }
}

/* The index of the DEM's sample at row k, column i; `narrow`: it fits an
 * int (which the vectoriser gathers with). */
static inline __attribute__((always_inline)) ptrdiff_t dem_index(int narrow, ptrdiff_t stride,
                                                                 int k, int i)
{
    return narrow ? k * (int)stride + i : k * stride + i;
}

/* How drop_read finds the DEM's corners at a ray's end. */
enum {
    ON_DEM,  /* anywhere: four reads of the DEM */
    ON_SIDE, /* on a side column (vx = +-1): its copy, the neighbour has weight 0 */
    ON_PAIR  /* between the two columns of a side: their copy (pyramid.c) */
};

/* The last samples at the ends tpp of the rays of cells [a, b] (tangents,
 * NaN where a ray ends at its cell), read bilinearly on the DEM, into A;
 * `where`: how the corners are read; `flat`: every row has the same step
 * (C->step_all; a projected grid), no look-up by row. */
static inline __attribute__((always_inline)) void drop_read(const hz_ctx *C, int narrow,
                                                            int where, int flat, int y, int a,
                                                            int b, const double *restrict tpp,
                                                            float *restrict A)
{
    /* on a column: the pyramid's copy of that side of the DEM, read down
     * (the outer column of the pair: 0 on the left, W - 1 on the right) */
    const float *restrict pair = C->P->pair[C->vx > 0], *restrict col = pair + (C->vx > 0);
    const ts_grid *g = C->P->grid;
    const int W = g->width, H = g->height, pair0 = C->vx > 0 ? W - 2 : 0;
    const float *restrict z = g->z, *restrict zrow = g->z + (ptrdiff_t)y * g->stride;
    const double *restrict step = C->step;
    const ptrdiff_t stride = g->stride;
    const double vy = C->vy, c = C->c, step_all = C->step_all;
    for (int x = a; x <= b; x++) {
        double t = tpp[x], px = tpp[W + x], py = tpp[2 * W + x];
        int i = (int)px, k = (int)py;
        float fx = (float)(px - i), fy = (float)(py - k);
        int i1 = i + 1 < W ? i + 1 : i, k1 = k + 1 < H ? k + 1 : k;
        float z00, z01, z10, z11;
        if (where == ON_SIDE) {
            z00 = z01 = col[2 * k];
            z10 = z11 = col[2 * k1];
        } else if (where == ON_PAIR) { /* i is pair0 or (right side) W - 1 = i1 */
            z00 = pair[2 * k + (i - pair0)], z01 = pair[2 * k + 1];
            z10 = pair[2 * k1 + (i - pair0)], z11 = pair[2 * k1 + 1];
        } else {
            z00 = z[dem_index(narrow, stride, k, i)], z01 = z[dem_index(narrow, stride, k, i1)];
            z10 = z[dem_index(narrow, stride, k1, i)], z11 = z[dem_index(narrow, stride, k1, i1)];
        }
        /* a corner of weight 0 does not count: no NaN from it (computed,
         * then selected: a conditional float operation is control flow
         * that keeps the loop scalar) */
        float top_i = z00 + fx * (z01 - z00), bot_i = z10 + fx * (z11 - z10);
        float top = fx > 0 ? top_i : z00;
        float bot = fx > 0 ? bot_i : z10;
        float h_i = top + fy * (bot - top);
        float h = fy > 0 ? h_i : top;
        double d;
        if (flat) {
            d = t * step_all;
        } else {
            int row = (int)(y + t * vy / 2 + 0.5);
            row = row < 0 ? 0 : row;
            row = row > H - 1 ? H - 1 : row;
            d = t * step[row];
        }
        float tan_w = (float)((h - zrow[x]) / d - c * d);
        A[x] = tan_w;
    }
    /* apart: a select in the loop above becomes a branch around tan_w */
    for (int x = a; x <= b; x++)
        A[x] = tpp[x] > 1e-9 ? A[x] : NAN;
}

/* The cells of [a, b] whose ends px lie between the columns of the side
 * that rays of direction vx leave through, [W - 2, W - 1] (vx > 0) or
 * [0, 1) (vx < 0: column 1 itself would need column 2): those that leave
 * through the side, a suffix (vx > 0) or a prefix of the run; the rest
 * end at the row's reach (t_row) within the grid. Returns the first cell
 * after the prefix (vx < 0) or the last before the suffix (vx > 0). */
static inline int pair_part(const double *restrict px, int a, int b, double vx, double lim)
{
    if (vx < 0) {
        while (a <= b && px[a] < 1)
            a++;
        return a;
    }
    while (b >= a && px[b] >= lim - 1)
        b--;
    return b;
}

/* drop_read for the cells of [a, b] (none when a > b), its constant
 * arguments dispatched. */
static inline __attribute__((always_inline)) void read_ends(const hz_ctx *C, int where, int y,
                                                            int a, int b,
                                                            const double *restrict tpp,
                                                            float *restrict A)
{
    const ts_grid *g = C->P->grid;
    int flat = C->step_all > 0;
    if (a > b)
        return;
    if ((double)g->stride * g->height > INT_MAX)
        drop_read(C, 0, ON_DEM, 0, y, a, b, tpp, A);
    else if (where == ON_SIDE)
        flat ? drop_read(C, 1, ON_SIDE, 1, y, a, b, tpp, A)
             : drop_read(C, 1, ON_SIDE, 0, y, a, b, tpp, A);
    else if (where == ON_PAIR)
        flat ? drop_read(C, 1, ON_PAIR, 1, y, a, b, tpp, A)
             : drop_read(C, 1, ON_PAIR, 0, y, a, b, tpp, A);
    else
        flat ? drop_read(C, 1, ON_DEM, 1, y, a, b, tpp, A)
             : drop_read(C, 1, ON_DEM, 0, y, a, b, tpp, A);
}

/* The last sample A[x] of each cell of [a, b], its sample number jd[x]
 * (B-spline only), then its horizon into out: push_run and finish_run for
 * one cell, with the sample number per cell (selects, not branches). */
TS_SIMD_CLONES
static void finish_last(row_ws *w, int bspline, int a, int b, const float *restrict A,
                        float *restrict out)
{
    const float *restrict s0 = w->s0, *restrict s1 = w->s1, *restrict s2 = w->s2;
    const float *restrict m = w->m;
    const int *restrict jd = w->jd;
    if (!bspline) {
TS_PYR_IVDEP
        for (int x = a; x <= b; x++) {
            float mm = A[x] > m[x] ? A[x] : m[x];
            out[x] = mm > -INFINITY ? ts_atan_deg(mm) : -90.0f;
        }
        return;
    }
TS_PYR_IVDEP
    for (int x = a; x <= b; x++) {
        int c = jd[x];
        float v = A[x], p2 = s2[x], mm = m[x];
        /* c = 0: the one sample is the spline */
        float m0 = v > mm ? v : mm;
        /* c = 1: w_{-1} = 2 w_0 - w_1, knot 0 is w_0 */
        float v1 = v == v ? v : p2;
        float q0 = 2.0f * p2 - v1, q1 = p2, q2 = v1;
        float m1 = q1 > mm ? q1 : mm;
        /* c >= 2 */
        float r0 = s0[x], r1 = s1[x], r2 = p2, m2 = mm;
        spline_push(&r0, &r1, &r2, &m2, v);
        /* then w_M = 2 w_{M-1} - w_{M-2}: knot M-1 is w_{M-1} */
        float e0 = c == 1 ? q0 : r0, e1 = c == 1 ? q1 : r1, e2 = c == 1 ? q2 : r2;
        float em = c == 1 ? m1 : m2;
        spline_push(&e0, &e1, &e2, &em, 2.0f * e2 - e1);
        float fm = c == 0 ? m0 : em, last = c == 0 ? v : e2;
        /* no spline value where nodata left fewer than three samples: the last */
        float r = fm > -INFINITY ? fm : last;
        out[x] = r == r && r > -INFINITY ? r : -90.0f;
    }
}

TS_SIMD_CLONES
void ts_pyr_drop_cells(const hz_ctx *C, row_ws *w, int y, int a, int b, double t_row,
                       float *out)
{
    if (a > b)
        return;
    const ts_grid *g = C->P->grid;
    const double vx = C->vx;
    float *restrict A = w->A;
    double *restrict tpp = w->tpp;
    /* constant arguments: one branch-free loop each, vectorised */
    if (vx == 1.0)
        drop_ends(C, 1, y, a, b, t_row, tpp);
    else if (vx == -1.0)
        drop_ends(C, -1, y, a, b, t_row, tpp);
    else if (vx > 0)
        drop_ends(C, 2, y, a, b, t_row, tpp);
    else if (vx < 0)
        drop_ends(C, -2, y, a, b, t_row, tpp);
    else
        drop_ends(C, 0, y, a, b, t_row, tpp);
    /* x-major rays that all end on their side (not earlier, at t_row) end
     * on a whole column: x + (lim - x) or x - x, exactly; other rays that
     * leave through a side end between the two columns of its pair */
    const double lim = g->width - 1;
    if ((vx == 1.0 && lim - a <= t_row) || (vx == -1.0 && b <= t_row)) {
        read_ends(C, ON_SIDE, y, a, b, tpp, A);
    } else if (vx != 0 && g->width >= 2) {
        int s = pair_part(tpp + g->width, a, b, vx, lim);
        read_ends(C, vx < 0 ? ON_PAIR : ON_DEM, y, a, vx < 0 ? s - 1 : s, tpp, A);
        read_ends(C, vx < 0 ? ON_DEM : ON_PAIR, y, vx < 0 ? s : s + 1, b, tpp, A);
    } else {
        read_ends(C, ON_DEM, y, a, b, tpp, A);
    }
    if (C->bspline) {
TS_PYR_IVDEP
        for (int x = a; x <= b; x++)
            A[x] = ts_atan_deg(A[x]); /* atan(NaN) is NaN */
    }
    finish_last(w, C->bspline, a, b, A, out);
}

