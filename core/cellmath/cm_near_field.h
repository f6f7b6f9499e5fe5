/*
 * cm_near_field.h - the exact near field of a cell's horizon, on the
 * bilinear surface through the cell centres (see core/near_field.h): along
 * a straight ray the surface is quadratic in the distance s inside each
 * cell patch, so the largest slope per patch has a closed form. Distances
 * s are in steps along the sweep's major axis u; the ray from cell (k, i)
 * passes (k - s, i - t s) in (u, v).
 */
#ifndef TS_CM_NEAR_FIELD_H
#define TS_CM_NEAR_FIELD_H

#include "cm_prelude.h"

/* Steps of the ray solved exactly, patch by patch; the sweep's hulls cover
 * what lies beyond. (Whole-step samples between the exact cells and here,
 * as once, miss the surface rising between two steps: up to tens of
 * degrees on rough terrain, and a ray's last stretch at the grid's edge.) */
#define TS_NEAR_STEPS 10
#define TS_NEAR_MAX_PIECES (2 * TS_NEAR_STEPS + 2)
/* Cells at least this far from every edge have their whole near field on
 * the grid. */
#define TS_NEAR_MARGIN (TS_NEAR_STEPS + 2)

/* The grid as a sweep direction sees it: element (u, v) of the direction
 * is z[origin + k u_stride + v v_stride] for step k; t: v per step. */
typedef struct {
    const CM_GLOBAL float *z;
    int V;
    cm_real t;
    long origin, u_stride, v_stride;
} cm_ray_grid;

/* One direction's near-field plan (ts_near_plan_init): piece n of the ray,
 * [sa[n], sb[n]] steps, lies in the patch with corner (k + du[n],
 * i + dv[n]). */
typedef struct {
    int npieces;
    const CM_GLOBAL int *du, *dv;
    const CM_GLOBAL cm_real *sa, *sb;
} cm_near_tables;

/* The bilinear weights at (a, b) of a patch's corners 00, 10, 01, 11, a and
 * b within a hair of 0 or 1 snapped to it. */
CM_FN void cm_edge_weights(cm_real a, cm_real b, cm_real w[4])
{
    const cm_real eps = CM_R(1e-9);
    a = a < eps ? 0 : a > 1 - eps ? 1 : a;
    b = b < eps ? 0 : b > 1 - eps ? 1 : b;
    w[0] = (1 - a) * (1 - b);
    w[1] = a * (1 - b);
    w[2] = (1 - a) * b;
    w[3] = a * b;
}

/* The height of corners h0..h3 under weights w (cm_edge_weights) from the
 * corners that weigh something, summed from 0 in order; NaN if one of those
 * is nodata. A corner that weighs nothing adds +0, which leaves the sum (never
 * -0) as it is: a select, not a branch, so that vector loops take it too
 * (core/near_field.c). */
CM_FN cm_real cm_edge_sum(const cm_real w[4], float h0, float h1, float h2, float h3)
{
    cm_real sum = 0;
    sum += w[0] > 0 ? w[0] * h0 : CM_R(0.0); /* a NaN corner makes the sum NaN */
    sum += w[1] > 0 ? w[1] * h1 : CM_R(0.0);
    sum += w[2] > 0 ? w[2] * h2 : CM_R(0.0);
    sum += w[3] > 0 ? w[3] * h3 : CM_R(0.0);
    return sum;
}

/* Bilinear height at (a, b) of a patch (corners 00, 10, 01, 11) from the
 * corners that weigh something there; NaN if one of those is nodata. */
CM_FN cm_real cm_edge_height(float h0, float h1, float h2, float h3, cm_real a, cm_real b)
{
    cm_real w[4];
    cm_edge_weights(a, b, w);
    return cm_edge_sum(w, h0, h1, h2, h3);
}

/* Slope (with the curvature term -c d) to h(s) = h0 + P + beta s +
 * gamma s^2 at s steps of L metres. */
CM_FN cm_real cm_slope_at(cm_real P, cm_real beta, cm_real gamma, cm_real s, cm_real L,
                          cm_real c)
{
    return (P + beta * s + gamma * s * s) / (s * L) - c * s * L;
}

/* cm_piece_max given its ends' slopes fa (at sa) and fb (at sb). */
CM_FN cm_real cm_piece_max_ends(cm_real P, cm_real beta, cm_real gamma, cm_real sa, cm_real sb,
                                cm_real L, cm_real c, cm_real fa, cm_real fb)
{
    cm_real m = fa > fb ? fa : fb;
    cm_real g2 = gamma - c * L * L;
    if (sa > 0 && P < 0 && g2 < 0) {
        cm_real ss = sqrt(P / g2);
        if (ss > sa && ss < sb) {
            cm_real fs = cm_slope_at(P, beta, gamma, ss, L, c);
            m = fs > m ? fs : m;
        }
    }
    return m;
}

/* Largest slope over s in [sa, sb]; at sa = 0 the limit beta / L. */
CM_FN cm_real cm_piece_max(cm_real P, cm_real beta, cm_real gamma, cm_real sa, cm_real sb,
                           cm_real L, cm_real c)
{
    cm_real fb = cm_slope_at(P, beta, gamma, sb, L, c);
    cm_real fa = sa > 0 ? cm_slope_at(P, beta, gamma, sa, L, c) : beta / L;
    return cm_piece_max_ends(P, beta, gamma, sa, sb, L, c, fa, fb);
}

/* h(s) = alpha + beta s + gamma s^2 along the ray in a patch with corner
 * height h00 and A = h10 - h00, B = h01 - h00, X = h11 - h10 - h01 + h00,
 * the cell at local coordinates (a0, b0), t: v per step. */
CM_FN void cm_patch_poly(cm_real h00, cm_real A, cm_real B, cm_real X, cm_real a0, cm_real b0,
                         cm_real t, cm_real *alpha, cm_real *beta, cm_real *gamma)
{
    *alpha = h00 + A * a0 + B * b0 + X * a0 * b0;
    *beta = -(A + B * t + X * (a0 * t + b0));
    *gamma = X * t;
}

/* Largest slope from a cell at height h over the piece [sa, sb] of its ray
 * in the patch with corners hc0..hc3 (00, 10, 01, 11), the cell at local
 * (a0, b0). A patch touching nodata is no terrain, but for its end points
 * on a grid line, whose only corners may be valid; -inf if nothing. */
CM_FN cm_real cm_near_piece(float hc0, float hc1, float hc2, float hc3, cm_real a0, cm_real b0,
                            cm_real t, cm_real sa, cm_real sb, float h, cm_real L, cm_real c)
{
    if (isnan(hc0) || isnan(hc1) || isnan(hc2) || isnan(hc3)) {
        cm_real best = -INFINITY;
        for (int e = 0; e < 2; e++) {
            cm_real se = e ? sb : sa;
            if (se <= 0)
                continue;
            cm_real he = cm_edge_height(hc0, hc1, hc2, hc3, a0 - se, b0 - t * se);
            cm_real sl = (he - h) / (se * L) - c * se * L; /* NaN on nodata */
            best = sl > best ? sl : best;
        }
        return best;
    }
    float A = hc1 - hc0, B = hc2 - hc0, X = hc3 - hc1 - hc2 + hc0;
    cm_real alpha, beta, gamma;
    cm_patch_poly(hc0, A, B, X, a0, b0, t, &alpha, &beta, &gamma);
    return cm_piece_max(alpha - h, beta, gamma, sa, sb, L, c);
}

/* Whether the patch of a piece with corner (k0, r0) leaves the grid of V
 * cells across (its 01 and 11 corners too, unless the ray runs along a
 * grid line: flat_v). */
CM_FN int cm_piece_off_grid(int k0, int r0, int V, int flat_v)
{
    return k0 < 0 || r0 < 0 || r0 > V - 1 || (!flat_v && r0 + 1 > V - 1);
}

/*
 * Exact near field of cell (k, i) at height h: the largest slope over its
 * pieces, within cap metres (0 = none); step:
 * metres per step; -inf if none. *left: the ray leaves the grid inside the
 * near field (what was found up to there is returned).
 */
CM_FN float cm_near_exact(const cm_ray_grid *r, const cm_near_tables *q, int k, int i, float h,
                          cm_real step, cm_real c, cm_real cap, int *left)
{
    const cm_real smax = cap > 0 ? cap / step : (cm_real)INFINITY; /* in steps */
    const int V = r->V, flat_v = fabs(r->t) <= CM_R(1e-12); /* flat: along a grid line */
    const cm_real t = flat_v ? 0 : r->t;
    cm_real best = -INFINITY;
    *left = 0;
    for (int n = 0; n < q->npieces; n++) {
        int k0 = k + q->du[n], r0 = i + q->dv[n];
        if (cm_piece_off_grid(k0, r0, V, flat_v)) {
            *left = 1;
            return (float)best;
        }
        if (q->sa[n] >= smax)
            break;
        const CM_GLOBAL float *zz = r->z + r->origin + (long)k0 * r->u_stride +
                                    (long)r0 * r->v_stride;
        /* along a grid line (t = 0) the 01 and 11 corners weigh nothing */
        int use_r1 = !flat_v && r0 + 1 <= V - 1;
        float hc0 = zz[0], hc1 = zz[r->u_stride];
        float hc2 = use_r1 ? zz[r->v_stride] : hc0;
        float hc3 = use_r1 ? zz[r->u_stride + r->v_stride] : hc1;
        cm_real sb = q->sb[n] < smax ? q->sb[n] : smax;
        cm_real m = cm_near_piece(hc0, hc1, hc2, hc3, -q->du[n], flat_v ? 0 : -q->dv[n], t,
                                  q->sa[n], sb, h, step, c);
        best = m > best ? m : best;
    }
    return (float)best;
}

/* Largest slope from cell (k, i) at height h over its ray between s_from
 * and s_to steps (exclusive, inclusive), patch by patch until the ray
 * leaves the grid: the brute force the near field is a table-driven case
 * of. -inf if nothing there. */
CM_FN float cm_ray_exact(const cm_ray_grid *r, int k, int i, float h, cm_real s_from,
                         cm_real s_to, cm_real step, cm_real c)
{
    const cm_real t = r->t, at = fabs(t);
    const int use_r1 = at > CM_R(1e-12);
    cm_real best = -INFINITY;
    cm_real s = s_from;
    while (s < s_to - CM_R(1e-12)) {
        /* next break point: a whole step, or v crossing an integer */
        cm_real nxt = floor(s + CM_R(1e-9)) + 1;
        if (use_r1) {
            cm_real v = i - t * s;
            cm_real vb = t > 0 ? ceil(v - CM_R(1e-9)) - 1 : floor(v + CM_R(1e-9)) + 1;
            cm_real sv = (i - vb) / t;
            if (sv > s + CM_R(1e-9) && sv < nxt)
                nxt = sv;
        }
        cm_real se = nxt < s_to ? nxt : s_to, mid = CM_R(0.5) * (s + se);
        int k0 = (int)floor(k - mid), r0 = use_r1 ? (int)floor(i - t * mid) : i;
        if (k0 < 0 || r0 < 0 || r0 > r->V - 1 || (use_r1 && r0 + 1 > r->V - 1))
            break; /* the ray leaves the grid */
        const CM_GLOBAL float *zz = r->z + r->origin + (long)k0 * r->u_stride +
                                    (long)r0 * r->v_stride;
        cm_real h00 = zz[0], h10 = zz[r->u_stride];
        cm_real h01 = use_r1 ? (cm_real)zz[r->v_stride] : h00;
        cm_real h11 = use_r1 ? (cm_real)zz[r->u_stride + r->v_stride] : h10;
        if (!isnan(h00 + h10 + h01 + h11)) {
            cm_real a0 = k - k0, b0 = use_r1 ? (cm_real)(i - r0) : 0, tt = use_r1 ? t : 0;
            cm_real alpha, beta, gamma;
            cm_patch_poly(h00, h10 - h00, h01 - h00, h11 - h10 - h01 + h00, a0, b0, tt, &alpha,
                          &beta, &gamma);
            cm_real m = cm_piece_max(alpha - h, beta, gamma, s > 0 ? s : CM_R(1e-9), se, step, c);
            best = m > best ? m : best;
        } else {
            /* nodata patch: only its valid end points on grid lines */
            for (int e = 0; e < 2; e++) {
                cm_real end = e ? se : s;
                if (end <= 0)
                    continue;
                cm_real he = cm_edge_height((float)h00, (float)h10, (float)h01, (float)h11,
                                            (k - end) - k0, use_r1 ? (i - t * end) - r0 : 0);
                cm_real sl = (he - h) / (end * step) - c * end * step; /* NaN on nodata */
                best = sl > best ? sl : best;
            }
        }
        s = se;
    }
    return (float)best;
}

/* Far field: the slope from cell (k, i) at height h to its own ray dk
 * steps back, at distance dd metres, interpolated between the two cells
 * around it (rows i + o and i + o + 1, fraction f); cf: the curvature
 * coefficient; -inf off the grid or on nodata. */
CM_FN float cm_ray_slope_at(const cm_ray_grid *r, int k, int i, float h, int dk, int o, float f,
                            float dd, float cf)
{
    int kk = k - dk;
    if (dk <= 0 || kk < 0 || dd <= 0.0f)
        return -INFINITY;
    int r0 = i + o;
    if (r0 < 0 || r0 > r->V - 1 || (f > 0.0f && r0 + 1 > r->V - 1))
        return -INFINITY;
    const CM_GLOBAL float *zz = r->z + r->origin + (long)kk * r->u_stride + (long)r0 * r->v_stride;
    float a = zz[0], b = f > 0.0f ? zz[r->v_stride] : a;
    float hz = a + f * (b - a);
    if (isnan(hz))
        return -INFINITY;
    return (hz - h) / dd - cf * dd;
}

/* A fraction of a cell this close to 0 or 1 is on the cell: t a hair off
 * +-1 (225 and 315 degrees on square cells: 1 - 2e-16) leaves ~1e-16, not
 * 0, and a nodata neighbour given that weight made the sample nodata (the
 * far field lost a ray along a nodata block's edge: -90 where the oracle
 * saw -1.6 degrees, 3 degrees too low beside it). */
#define CM_CELL_SNAP CM_R(1e-9)

/* The v offset of a ray dk steps back, -t dk: the whole cells (returned)
 * and the fraction beyond, in *f. */
CM_FN int cm_ray_offset(cm_real t, int dk, float *f)
{
    const cm_real pv = -t * dk;
    cm_real o = floor(pv), fr = pv - o;
    if (fr > 1 - CM_CELL_SNAP) {
        o += 1;
        fr = 0;
    }
    *f = fr < CM_CELL_SNAP ? 0.0f : (float)fr;
    return (int)o;
}

/* cm_ray_slope_at with the ray's offset dk steps back computed here
 * (cm_ray_offset). */
CM_FN float cm_ray_slope(const cm_ray_grid *r, int k, int i, float h, int dk, float dd, float cf)
{
    float f;
    const int o = cm_ray_offset(r->t, dk, &f);
    return cm_ray_slope_at(r, k, i, h, dk, o, f, dd, cf);
}

/* Steps of a cell's own ray sampled where a line's occluder lies where the
 * ray itself cannot be sampled (cm_ray_lost). */
#ifndef TS_LOST_STEPS
#define TS_LOST_STEPS 8
#endif

/*
 * A line's occluder dk steps back at which the cell's own ray is off the
 * grid or on nodata, while the line, up to a cell aside, is still on the
 * data: the far field sampled only there lost that terrain (up to tens of
 * degrees near a DEM's edge or a nodata hole). Instead: the ray sampled
 * (cm_ray_slope, step metres a step, c the curvature coefficient) at the
 * TS_LOST_STEPS whole steps up to that occluder, or up to where the ray
 * leaves the grid before it, and solved exactly over the part of a step it
 * has left there (cm_ray_exact), and, where the ray is on the grid there
 * but on nodata, at the TS_LOST_STEPS whole steps beyond it (a hole's far
 * side, where the lines found their terrain: a cell looking across a
 * nodata block saw nothing, -90, where the terrain stood 16-25 deg up);
 * beyond `near` steps (the part of a step from `piece_from` at least) and
 * within s_cap steps (0 = none); -inf if none counts. A few steps, not the
 * whole ray, so that a DEM whose edge holds every line's occluder costs a
 * few steps a cell. (cm_ray_lost: the part of a step from the near field's
 * last, near; the far-only sweep's from its first far step, near + 1, so
 * that nothing nearer than its threshold counts.)
 */
CM_FN float cm_ray_lost_from(const cm_ray_grid *r, int k, int i, float h, int dk, int near,
                             int piece_from, cm_real s_cap, cm_real step, cm_real c)
{
    /* where the ray ends: the grid's start along u (k steps back), where
     * v = i - t s leaves [0, V - 1], or the cap */
    cm_real end = (cm_real)k;
    if (fabs(r->t) > CM_R(1e-12)) {
        cm_real sv = r->t > 0 ? i / r->t : (i - (r->V - 1)) / r->t;
        end = sv < end ? sv : end;
    }
    if (s_cap > 0 && s_cap < end)
        end = s_cap;
    const cm_real last = dk < k ? dk : k;
    const cm_real exit = dk < end ? (cm_real)dk : end;
    const int hi = (int)floor(exit), lo = hi - TS_LOST_STEPS > near ? hi - TS_LOST_STEPS : near;
    float best = -INFINITY;
    for (int s = hi; s > lo; s--) {
        float v = cm_ray_slope(r, k, i, h, s, (float)(s * step), (float)c);
        best = v > best ? v : best;
    }
    if (exit > hi && exit < last) { /* the ray leaves the grid (or the cap) within a step */
        cm_real from = hi > piece_from ? (cm_real)hi : (cm_real)piece_from;
        float v = exit > from ? cm_ray_exact(r, k, i, h, from, exit, step, c) : -INFINITY;
        best = v > best ? v : best;
    }
    /* On the grid at the occluder but on nodata: the hole's far side, where
     * the line found its terrain, lies beyond it (empty where the ray has
     * left the grid or the cap before dk) */
    const cm_real beyond = (cm_real)(dk + TS_LOST_STEPS);
    const int far_end = (int)floor(beyond < end ? beyond : end);
    for (int s = dk + 1; s <= far_end; s++) {
        float v = cm_ray_slope(r, k, i, h, s, (float)(s * step), (float)c);
        best = v > best ? v : best;
    }
    return best;
}

CM_FN float cm_ray_lost(const cm_ray_grid *r, int k, int i, float h, int dk, int near,
                        cm_real s_cap, cm_real step, cm_real c)
{
    return cm_ray_lost_from(r, k, i, h, dk, near, near, s_cap, step, c);
}

/*
 * The float fast path for interior cells whose near field has no nodata.
 * A cell's largest slope over its ray's pieces is the largest of
 *  - the slope at each piece's end (where the ray crosses a grid line, so
 *    the height there is read off that edge's two nodes: cm_fast_cross),
 *  - the ray's start (the surface's own slope there: cm_fast_start), and
 *  - a piece's inner peak, where the slope along it rises and then falls
 *    (cm_fast_peak_test; then cm_fast_peak).
 * Per piece, the constants depend only on the direction (cm_fast_piece).
 * Every backend takes the same float operations and folds the maximum,
 * which does not depend on the order, then adds +0 (a -0 becomes +0), so
 * that the bits agree. A corner with nodata or an infinity makes the
 * twist (cm_fast_twist) not finite: the caller then flags the cell and
 * redoes it with cm_near_exact.
 */
typedef struct {
    float a0, b0;      /* the cell in the piece's patch */
    float sa, sb;      /* the piece's ends, in steps */
    float inv_b, cb;   /* 1 / (sb L) and the curvature term at sb */
    float cLL, invL;
    int e0, e1;        /* the end's edge: corners (0: 00, 1: 10, 2: 01, 3: 11) */
    float frac;        /* where along it, from e0 */
    float ka, kbn;     /* the inner-peak test's factors (cm_fast_peak_test) */
    int has_sa;        /* the piece starts beyond the cell: it may have a peak */
} cm_fast_piece;

CM_FN cm_fast_piece cm_fast_piece_init(int du, int dv, int flat_v, cm_real sa, cm_real sb,
                                       cm_real t, float L, float c)
{
    cm_fast_piece q;
    q.a0 = (float)-du;
    q.b0 = flat_v ? 0.0f : (float)-dv;
    q.sa = (float)sa;
    q.sb = (float)sb;
    q.inv_b = 1.0f / (q.sb * L);
    q.cb = c * q.sb * L;
    q.cLL = c * L * L;
    q.invL = 1.0f / L;
    q.has_sa = q.sa > 0;
    /* The end in the patch's (a, b): on its edge a = 0 (a new step) or on
     * b = 0 or 1 (a new row); the nearer node first, so that an end on a
     * corner reads that corner exactly. */
    const cm_real ae = -sb - du, be = flat_v ? 0 : -t * sb - dv;
    cm_real f;
    if (fabs(ae) < CM_R(1e-9)) {
        q.e0 = 0;
        q.e1 = 2;
        f = be;
    } else {
        q.e0 = be < CM_R(0.5) ? 0 : 2;
        q.e1 = q.e0 + 1;
        f = ae;
    }
    if (f > CM_R(0.5)) {
        const int e = q.e0;
        q.e0 = q.e1;
        q.e1 = e;
        f = CM_R(1.0) - f;
    }
    q.frac = f > CM_R(0.0) ? (float)f : 0.0f;
    /* With D = (slope at sa) - (slope at sb) and g2 = gamma - c L^2, the
     * slope P / s + beta + gamma s - c L^2 s (over L) peaks inside the piece,
     * at s^2 = P / g2 in (sa^2, sb^2), exactly where g2 < 0 and
     * g2 (sb - sa)^2 / (sa L) < D < -g2 (sb - sa)^2 / (sb L). */
    const cm_real d2 = (sb - sa) * (sb - sa);
    q.ka = q.has_sa ? (float)(d2 / (sa * L)) : 0.0f;
    q.kbn = q.has_sa ? (float)(-d2 / (sb * L)) : 0.0f;
    return q;
}

/* The patch's twist c11 - c10 - c01 + c00: not finite where a corner is
 * nodata or infinite. */
CM_FN float cm_fast_twist(float c00, float c10, float c01, float c11)
{
    return c11 - c10 - c01 + c00;
}

/* The slope at the piece's end from a cell at height h, n0 and n1 its
 * edge's nodes (corners e0, e1). */
CM_FN float cm_fast_cross(cm_fast_piece q, float n0, float n1, float h)
{
    /* the height above the cell's: n0 - h first, exact for nearby heights */
    return ((n0 - h) + (n1 - n0) * q.frac) * q.inv_b - q.cb;
}

/* The ray's start (piece 0, sa = 0): the limit of the slope, the surface's
 * own slope along the ray. */
CM_FN float cm_fast_start(cm_fast_piece q, float t, float c00, float c10, float c01, float c11)
{
    const float A = c10 - c00, B = c01 - c00, X = cm_fast_twist(c00, c10, c01, c11);
    const float beta = -(A + B * t + X * (q.a0 * t + q.b0));
    return beta * q.invL;
}

/* Whether the piece (has_sa) peaks inside: X its twist, fa and fb the
 * slopes at its ends. */
CM_FN int cm_fast_peak_test(cm_fast_piece q, float t, float X, float fa, float fb)
{
    const float g2 = X * t - q.cLL, D = fa - fb;
    return (g2 < 0.0f) & (D > g2 * q.ka) & (D < g2 * q.kbn);
}

/* The slope at the piece's inner peak (cm_fast_peak_test), its distance
 * held inside the piece. */
CM_FN float cm_fast_peak(cm_fast_piece q, float t, float c00, float c10, float c01, float c11,
                         float h, float L, float c)
{
    const float A = c10 - c00, B = c01 - c00, X = cm_fast_twist(c00, c10, c01, c11);
    const float alpha = c00 + A * q.a0 + B * q.b0 + X * q.a0 * q.b0;
    const float beta = -(A + B * t + X * (q.a0 * t + q.b0));
    const float gamma = X * t, P = alpha - h, g2 = gamma - q.cLL;
    const float r = P / g2;
    float ss = CM_SQRTF(r > 0.0f ? r : 0.0f);
    ss = ss > q.sa ? ss : q.sa;
    ss = ss < q.sb ? ss : q.sb;
    return (P / ss + beta + gamma * ss) * q.invL - c * ss * L;
}

#endif
