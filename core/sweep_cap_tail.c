/* The exact stretches of a capped (MAX_DISTANCE) sweep that the near field
 * and the lines leave out; see sweep_cap_tail.h. */
#include <math.h>
#include <stdlib.h>

#include "cap_tail_bound.h"
#include "near_field.h"
#include "sweep_cap_tail.h"

/* An upper bound of the slope from cell (k, i) at height h to its ray
 * between whole steps j and j + 1: the highest corner of the patches it
 * crosses there; INFINITY if one is nodata or off the grid (then solve). */
static float between_steps_bound(const ts_line_geom *G, const float *z, int k, int i, float h,
                                 int j, double step, double c)
{
    double va = i - G->t * j, vb = i - G->t * (j + 1);
    double lo = va < vb ? va : vb, hi = va < vb ? vb : va;
    int r0 = (int)floor(lo), r1 = (int)ceil(hi), k0 = k - j - 1;
    if (k0 < 0 || r0 < 0 || r1 > G->V - 1)
        return INFINITY;
    float hmax = -INFINITY;
    const float *p = z + G->origin + (ptrdiff_t)k0 * G->u_stride + (ptrdiff_t)r0 * G->v_stride;
    for (int r = r0; r <= r1; r++, p += G->v_stride) {
        float a = p[0], b = p[G->u_stride];
        if (a != a || b != b)
            return INFINITY;
        hmax = a > hmax ? a : hmax;
        hmax = b > hmax ? b : hmax;
    }
    double dh = (double)hmax - h;
    return (float)(dh / ((dh > 0 ? j : j + 1) * step) - c * j * step);
}

/* Most stretches lie below the horizon found so far: a row-wide bound
 * (cap_tail_bound.h) rules them out before the per-cell bound and solve.
 * The stencils of row y: between whole steps j, sb (at most TS_NEAR_STEPS -
 * TS_NEAR_EXACT of them), then the tail's; bounds[n * W + x] is stencil n's
 * bound at x, NaN where it has none (the cell falls back to the per-cell
 * path), and one more row: scratch, then the largest of the bounds at x.
 * st receives the stencils. Returns how many. */
enum { MAX_STENCILS = TS_NEAR_STEPS - TS_NEAR_EXACT + 1 };

static int row_bounds(const ts_line_geom *G, const float *zrow, int W, int y, double send,
                      int between, double s0, double smax, int tail, double step, double c,
                      ts_cap_stencil st[MAX_STENCILS], float *bounds)
{
    int n = 0;
    for (int j = TS_NEAR_EXACT; between && j < send; j++)
        ts_cap_stencil_init(&st[n++], G, j, j + 1 < send ? j + 1 : send, step, c);
    if (tail)
        ts_cap_stencil_init(&st[n++], G, s0, smax, step, c);
    for (int m = 0; m < n; m++) {
        float *b = bounds + (size_t)m * W;
        int xa, xb;
        ts_cap_stencil_range(&st[m], G, W, y, &xa, &xb);
        for (int x = 0; x < W; x++)
            b[x] = NAN;
        if (xa < xb)
            ts_cap_stencil_row(&st[m], zrow, xa, xb, b, bounds + (size_t)n * W);
    }
    /* the last row: the largest of them, NaN if any is */
    float *top = bounds + (size_t)n * W;
    for (int x = 0; x < W; x++)
        top[x] = -INFINITY;
    for (int m = 0; m < n; m++) {
        const float *b = bounds + (size_t)m * W;
        for (int x = 0; x < W; x++) { /* one select, so that it vectorises */
            float v = b[x], t = top[x];
            top[x] = v > t || v != v ? v : t;
        }
    }
    return n;
}

/* Whether stencil m solves cell x's stretch as ts_ray_exact would: its
 * pieces are the ray's and its bound at x is a number (on the grid, no
 * nodata). */
static inline int fast_exact(const ts_cap_stencil *st, int nst, int m, const float *bound,
                             int x)
{
    return m < nst && st[m].exact && bound[x] == bound[x];
}

/*
 * What the near field and the lines leave out within a maximum distance,
 * solved exactly on each cell's own ray: a capped horizon is often near,
 * often at the distance itself.
 *  - Between the near field's whole steps (TS_NEAR_EXACT..TS_NEAR_STEPS)
 *    the bilinear surface can rise above both steps (not along an axis,
 *    where it is linear there); a step is solved where a bound says it may
 *    raise the horizon.
 *  - The part of a step before the distance ends, where the same bound
 *    says it may.
 */
void ts_cap_tail(const ts_line_geom *G, const ts_grid *grid, double cap, double c, int y,
                 const float *zrow, float *orow, double step)
{
    const float *z = grid->z;
    const int W = grid->width;
    double smax = cap / step, s0 = floor(smax);
    double send = smax < TS_NEAR_STEPS ? smax : TS_NEAR_STEPS;
    int axis = fabs(G->t) <= 1e-12;
    s0 = s0 > TS_NEAR_EXACT ? s0 : TS_NEAR_EXACT;
    int tail = s0 < smax && (axis || smax > TS_NEAR_STEPS);
    float *bounds = malloc((size_t)(MAX_STENCILS + 1) * W * sizeof *bounds);
    ts_cap_stencil st[MAX_STENCILS];
    int nst = bounds ? row_bounds(G, zrow, W, y, send, !axis, s0, smax, tail, step, c, st,
                                  bounds)
                     : 0;
    int jend = TS_NEAR_EXACT; /* the between stretches are j < jend */
    while (!axis && jend < send)
        jend++;
    for (int x = 0; x < W; x++) {
        if (isnan(zrow[x]))
            continue;
        int u = G->x_major ? x : y, i = G->x_major ? y : x;
        int k = (u - G->u_start) * G->u_step;
        float h = zrow[x], best = orow[x];
        if (nst > 0 && bounds[(size_t)nst * W + x] < best)
            continue; /* no stretch can raise it */
        int m = 0; /* the stencil of the stretch at hand */
        for (int j = TS_NEAR_EXACT; j < jend; j++, m++) {
            if (m < nst && bounds[(size_t)m * W + x] < best)
                continue;
            /* the corner bound decides only where the stretch would raise */
            float e;
            if (fast_exact(st, nst, m, bounds + (size_t)m * W, x)) {
                e = ts_cap_stencil_exact(&st[m], zrow, x);
                if (e > best && between_steps_bound(G, z, k, i, h, j, step, c) < best)
                    continue;
            } else {
                if ((m < nst && ts_cap_stencil_off_grid(&st[m], G, k, i)) ||
                    between_steps_bound(G, z, k, i, h, j, step, c) < best)
                    continue;
                e = ts_ray_exact(G, z, k, i, h, j, j + 1 < send ? j + 1 : send, step, c);
            }
            best = e > best ? e : best;
        }
        if (tail && !(m < nst && bounds[(size_t)m * W + x] < best)) {
            float e = -INFINITY;
            if (fast_exact(st, nst, m, bounds + (size_t)m * W, x)) {
                e = ts_cap_stencil_exact(&st[m], zrow, x);
                if (e > best && between_steps_bound(G, z, k, i, h, (int)s0, step, c) < best)
                    e = -INFINITY;
            } else if (!(m < nst && ts_cap_stencil_off_grid(&st[m], G, k, i)) &&
                       between_steps_bound(G, z, k, i, h, (int)s0, step, c) >= best) {
                e = ts_ray_exact(G, z, k, i, h, s0, smax, step, c);
            }
            best = e > best ? e : best;
        }
        orow[x] = best;
    }
    free(bounds);
}
