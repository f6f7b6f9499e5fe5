/*
 * One sweep line on its own (horizon_sweep.c runs the others in lockstep
 * blocks): the unbounded hull or, with a maximum distance, the sliding
 * window hull of its samples (window_hull.h), the far field of the cells
 * beside it, and the line visitor's samples.
 */
#include <math.h>

#include "sweep_internal.h"

/* The far-field occluder of a point at distance d, height h, among the
 * hull points 0..far (those beyond the near field): walk to farther points
 * while the slope grows (the slopes to an upper convex hull from a point
 * beyond it are unimodal). With a maximum distance, the window's. */
static inline __attribute__((always_inline)) occluder
hull_query(const sweep_ctx *C, sweep_ws *w, int far, double d, float h, int finger[2])
{
    occluder none = {-1, 0.0f};
    double g = h - C->c * d * d;
    if (C->cap > 0) {
        const hull_pt *p = ts_window_hull_query(&w->win, d, g, finger);
        return p ? (occluder){p->k, (float)(d - p->d)} : none;
    }
    return stack_query(w->stack, far, d, g);
}

/* Slope from cell (k, i) at height h to its own ray, dk steps back (at
 * distance dd), where the ray crosses that column; -inf if the ray is off
 * the grid there or touches nodata. */
static inline float ray_slope(const sweep_ctx *C, int k, int i, float h, int dk, float dd)
{
    if (dk <= 0 || dk > k)
        return -INFINITY;
    return cm_ray_slope_at(&C->ray, k, i, h, dk, C->geom->ray_o[dk], C->geom->ray_f[dk], dd,
                           (float)C->c);
}

/* Far field of cell (k, i): its own ray evaluated at and beside the
 * occluders that the hulls of the two neighbouring lines found. Taking the
 * maximum of each line's horizon and interpolating would overestimate (the
 * maximum of a mean is at most the mean of the maxima); sampling the
 * cell's ray where the lines see their occluders does not. */
static float far_field(const sweep_ctx *C, int k, int i, float h, occluder lo, occluder hi,
                       double step)
{
    float best = -INFINITY;
    const occluder cand[2] = {lo, hi};
    for (int c = 0; c < 2; c++) {
        if (cand[c].k < 0 || (c == 1 && cand[1].k == cand[0].k))
            continue;
        int dk = k - cand[c].k;
        for (int e = -FAR_SPREAD; e <= FAR_SPREAD; e++) {
            if (dk + e <= TS_NEAR_STEPS)
                continue;
            /* e = 0 adds exactly +0 to the distance: skip the conversion. */
            float dd = e ? cand[c].dd + (float)(e * step) : cand[c].dd;
            float s = ray_slope(C, k, i, h, dk + e, dd);
            if (e == 0 && s == -INFINITY) /* the ray cannot be sampled there */
                s = cm_ray_lost(&C->ray, k, i, h, dk, TS_NEAR_STEPS, C->cap / step, step,
                                C->c);
            best = s > best ? s : best;
        }
    }
    return best;
}

#ifndef PREFETCH_AHEAD
#define PREFETCH_AHEAD 8
#endif

void ts_sweep_process_line(const sweep_ctx *C, sweep_ws *w, long b, int write)
{
    const ts_line_geom *G = C->geom;
    const float *z = C->grid->z;
    const int pk0 = w->lo.prev_k0, pk1 = w->lo.prev_k1;
    int k0, k1;
    if (!ts_line_pair_next(&w->lo, G, b, &k0, &k1))
        return;
    const occluder *prev_lo = w->lo.prev;
    occluder *cur_lo = w->lo.cur;
    w->n = 0;
    w->raw_n = 0;
    ts_window_hull_reset(&w->win);
    ts_window_hull_reset(&w->vwin);
    const double c = C->c;
    double d = 0.0;
    int nv = 0;
    int far = -1; /* top-most hull point beyond the near field */
    for (int k = k0; k <= k1; k++) {
        /* A line crosses a grid row per step: fetch the DEM and the output
         * a few steps ahead, as no hardware prefetcher follows this path. */
        if (k + PREFETCH_AHEAD <= k1) {
            int ka = k + PREFETCH_AHEAD, ia = (int)(b + G->fl[ka]);
            __builtin_prefetch(z + G->origin + (ptrdiff_t)ka * G->u_stride +
                               (ptrdiff_t)ia * G->v_stride);
            if (write)
                __builtin_prefetch(C->out + C->o_origin + (ptrdiff_t)ka * C->o_u_stride +
                                   (ptrdiff_t)ia * C->o_v_stride, 1);
        }
        ts_line_sample ls;
        ts_line_sample_at(G, z, b, k, k0, 0.0f, &d, &ls);
        const int i = ls.i, has_next = ls.has_next;
        const float F = ls.F, hc = ls.hc, hn = ls.hn, hs = ls.hs;

        int pushed = 0;
        float slope = -INFINITY;
        if (C->cap > 0) {
            if (!isnan(hs)) {
                double gs = hs - c * d * d;
                if (w->vs) {
                    ts_window_hull_slide(&w->vwin, w->raw, w->raw_n, d, 0.0, C->cap);
                    const hull_pt *p = ts_window_hull_query(&w->vwin, d, gs, w->finger[2]);
                    if (p)
                        slope = (float)((p->g - gs) / (d - p->d) - 2.0 * c * d);
                }
                w->raw[w->raw_n++] = (hull_pt){d, gs, k};
            }
            ts_window_hull_slide(&w->win, w->raw, w->raw_n, d, C->near_skip, C->cap);
            pushed = 1;
        } else if (!isnan(hs)) {
            double gs = hs - c * d * d;
            const hull_pt *S = w->stack;
            int n = hull_push(w->stack, &w->n, &far, d, gs, k, C->near_skip);
            if (w->vs && n > 0)
                slope = (float)((S[n - 1].g - gs) / (d - S[n - 1].d) - 2.0 * c * d);
            pushed = 1;
        }
        if (!pushed)
            far = far_advance(w->stack, w->n, far, d, C->near_skip);
        occluder none = {-1, 0.0f};
        if (write) {
            float s_out = NAN;
            if (!isnan(hc)) {
                /* (also off the grid, between the last row and the one
                 * beyond: its hull may hold the terrain toward the
                 * occluders, as horizon_sweep.c) */
                occluder hi = hull_query(C, w, far, d, hc, w->finger[0]);
                occluder lo = (F > 0.0f && k >= pk0 && k <= pk1) ? prev_lo[k] : none;
                s_out = far_field(C, k, i, hc, lo, hi, ts_line_cell_step(G, k, i));
            }
            C->out[C->o_origin + (ptrdiff_t)k * C->o_u_stride + (ptrdiff_t)i * C->o_v_stride] =
                s_out;
        }
        cur_lo[k] = (has_next && !isnan(hn)) ? hull_query(C, w, far, d, hn, w->finger[1]) : none;
        if (w->vs) {
            w->vx[nv] = G->x_major ? (float)(G->u_start + k * G->u_step) : (float)i + F;
            w->vy[nv] = G->x_major ? (float)i + F : (float)(G->u_start + k * G->u_step);
            w->vh[nv] = hs;
            w->vd[nv] = d;
            w->vs[nv] = isnan(hs) ? NAN : slope;
            nv++;
        }
    }
    /* A line that leaves the grid across row 0 goes on one row before it,
     * queries only: it answers row 0's cells for the far side, as the
     * lockstep blocks' row_before (horizon_sweep.c) */
    const int kl = ts_line_k_leaving(G, b, k1);
    w->lo.prev_k1 = kl;
    for (int k = k1 + 1; k <= kl; k++) {
        if (G->step_row) /* (row -1: row 0's steps) */
            d += G->step_row[G->x_major ? 0 : G->u_start + k * G->u_step];
        else if (G->anchored)
            d = (double)(k + G->k_anchor) * G->step_m;
        else
            d = (double)(k - k0) * G->step_m;
        if (C->cap > 0)
            ts_window_hull_slide(&w->win, w->raw, w->raw_n, d, C->near_skip, C->cap);
        else
            far = far_advance(w->stack, w->n, far, d, C->near_skip);
        const float hn = G->fr[k] > 0.0f ? z[G->origin + (ptrdiff_t)k * G->u_stride] : NAN;
        cur_lo[k] = !isnan(hn) ? hull_query(C, w, far, d, hn, w->finger[1])
                               : (occluder){-1, 0.0f};
    }
    if (w->vs && nv > 0)
        C->visit(C->user, nv, w->vx, w->vy, w->vh, w->vd, w->vs);
}

