/*
 * cm_shadowmap.h - the per-vertex, per-triangle and per-cell formulas of the
 * shadow map (METHOD=shadowmap; core/shadowmap.c, cl/shadowmap.cl).
 *
 * Light space: s runs across the light's azimuth, t up the light's view,
 * depth towards the light (larger = nearer the light). A DEM vertex at
 * metres (X east, Y north, Z up) from the DEM's centre projects to
 *   along = X sin(az) + Y cos(az)          (horizontal, towards the light)
 *   s = X cos(az) - Y sin(az)
 *   t = Z cos(el) - along sin(el)
 *   depth = along cos(el) + Z sin(el)
 * and to texel coordinates u = (s - s0) / ds, v = (t - t0) / dt; texel
 * (a, b) is centred at u = a, v = b. The depth map keeps, per texel, the
 * largest depth of the terrain's triangles over its centre, as an int key
 * that orders like the float (so that OpenCL can keep it with atomic_max),
 * less a slope-scaled offset (glPolygonOffset's factor and units). A cell
 * is lit where its own depth is not below the map's.
 *
 * The frame's parameters travel as one float array, indexed by TS_SMP_*.
 */
#ifndef TS_CM_SHADOWMAP_H
#define TS_CM_SHADOWMAP_H

#include "cm_prelude.h"
#include "cm_fastmath.h"
#include "cm_sun.h"

/* Indices into the frame's parameter array. */
#define TS_SMP_CA 0        /* cos(azimuth) */
#define TS_SMP_SA 1        /* sin(azimuth) */
#define TS_SMP_CE 2        /* cos(elevation) */
#define TS_SMP_SE 3        /* sin(elevation) */
#define TS_SMP_S0 4        /* s of texel column 0, metres */
#define TS_SMP_T0 5        /* t of texel row 0, metres */
#define TS_SMP_INV_DS 6    /* texels per metre along s */
#define TS_SMP_INV_DT 7    /* texels per metre along t */
#define TS_SMP_CX0 8       /* column of the DEM's centre */
#define TS_SMP_CY0 9       /* row of the DEM's centre */
#define TS_SMP_CELL_Y 10   /* north-south cell size, metres */
#define TS_SMP_BIAS 11     /* constant depth offset, metres */
#define TS_SMP_SLOPE_CAP 12 /* largest depth slope used, metres per texel */
#define TS_SMP_KERNEL_U 13 /* fixed PCF width in texels along u; 0 = auto */
#define TS_SMP_KERNEL_V 14 /* and along v */
#define TS_SMP_TAN_R 15    /* tan(light radius): auto's penumbra per metre */
#define TS_SMP_DEPTH_MAX 16 /* largest depth of the map, metres */
#define TS_SMP_SEARCH_CAP 17 /* largest blocker-search half-width, texels
                                (at most TS_SM_TILE: the tiles around) */
#define TS_SMP_INV_R 18    /* 1 / the light's radius in degrees */
#define TS_SMP_COUNT 19

/* Most PCF taps along one axis: wider kernels spread them out. */
#define TS_SM_MAX_TAPS 9
/* Taps of the blocker search of PCF_KERNEL=auto along one axis, at most. */
#define TS_SM_SEARCH_TAPS 7
/* An empty texel: below every depth, so nothing there shadows. */
#define TS_SM_EMPTY (-2147483647 - 1)

/* The map is followed by the largest key of each TS_SM_TILE x TS_SM_TILE
 * tile of it (row-major, ceil(mw / TILE) per row): where the blocker search
 * of PCF_KERNEL=auto may stop looking. OpenCL keeps them while rendering;
 * C computes them after (ts_sm_tile_max), its threads owning map rows. */
#define TS_SM_TILE 16

#ifdef __OPENCL_C_VERSION__
#define TS_SM_KEEP_MAX(p, k) atomic_max((p), (k))
#define TS_SM_KEEP_TILE(map, mw, mh, a, b, k)                                                  \
    atomic_max(&(map)[(long)(mw) * (mh) + (long)((b) / TS_SM_TILE) *                          \
                                            (((mw) + TS_SM_TILE - 1) / TS_SM_TILE) +          \
                      (a) / TS_SM_TILE],                                                       \
               (k))
#else
#define TS_SM_KEEP_TILE(map, mw, mh, a, b, k) ((void)(mh))
#define TS_SM_KEEP_MAX(p, k)                                                                   \
    do {                                                                                       \
        if (*(p) < (k))                                                                        \
            *(p) = (k);                                                                        \
    } while (0)
#endif

/* An int that orders as the float f does (f not NaN). */
CM_FN int ts_sm_key(float f)
{
    union {
        float f;
        int i;
    } x;
    x.f = f;
    return x.i < 0 ? x.i ^ 0x7fffffff : x.i;
}

/* The float of a key (not TS_SM_EMPTY). */
CM_FN float ts_sm_unkey(int k)
{
    union {
        float f;
        int i;
    } x;
    x.i = k < 0 ? k ^ 0x7fffffff : k;
    return x.f;
}

/* Texel coordinates (u, v) and depth of the vertex at column col of a row
 * with east-west cell size cell_x, height z (NaN stays NaN). */
CM_FN void ts_sm_project(CM_GLOBAL const float *P, int col, int row, float cell_x, float z,
                         float *u, float *v, float *depth)
{
    float X = ((float)col - P[TS_SMP_CX0]) * cell_x;
    float Y = (P[TS_SMP_CY0] - (float)row) * P[TS_SMP_CELL_Y];
    float along = X * P[TS_SMP_SA] + Y * P[TS_SMP_CA];
    float s = X * P[TS_SMP_CA] - Y * P[TS_SMP_SA];
    float t = z * P[TS_SMP_CE] - along * P[TS_SMP_SE];
    *u = (s - P[TS_SMP_S0]) * P[TS_SMP_INV_DS];
    *v = (t - P[TS_SMP_T0]) * P[TS_SMP_INV_DT];
    *depth = along * P[TS_SMP_CE] + z * P[TS_SMP_SE];
}

CM_FN float ts_sm_clampf(float x, float lo, float hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

/* A triangle set up for rasterising: its corners (texel coordinates, and
 * the first one's depth), depth slopes per texel, offset, the sign of its
 * area, and the texel centres its box holds, clipped to the map and band. */
typedef struct {
    float u0, v0, d0, u1, v1, u2, v2;
    float gu, gv, off, sg;
    int a0, a1, b0, b1;
} ts_sm_tri;

/*
 * Set up one triangle (texel coordinates and depths of its corners) for the
 * map of mw texels a row, rows [vlo, vhi) only (the C backend's band): its
 * depth's slopes and slope-scaled offset bias + min(max |depth slope|, cap),
 * and its box of texel centres. 0 where it is skipped: a NaN corner
 * (nodata) or no area (seen edge-on).
 */
CM_FN int ts_sm_tri_setup(CM_GLOBAL const float *P, int mw, int vlo, int vhi, float u0,
                          float v0, float d0, float u1, float v1, float d1, float u2, float v2,
                          float d2, ts_sm_tri *t)
{
    float area = (u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0);
    if (!(area > 1e-12f || area < -1e-12f)) /* also NaN */
        return 0;
    if (isnan(d0 + d1 + d2))
        return 0;
    float gu = ((d1 - d0) * (v2 - v0) - (d2 - d0) * (v1 - v0)) / area;
    float gv = ((d2 - d0) * (u1 - u0) - (d1 - d0) * (u2 - u0)) / area;
    float slope = CM_FABSF(gu) > CM_FABSF(gv) ? CM_FABSF(gu) : CM_FABSF(gv);
    float cap = P[TS_SMP_SLOPE_CAP];
    t->off = P[TS_SMP_BIAS] + 0.75f * (slope < cap ? slope : cap);
    float umin = u0 < u1 ? (u0 < u2 ? u0 : u2) : (u1 < u2 ? u1 : u2);
    float umax = u0 > u1 ? (u0 > u2 ? u0 : u2) : (u1 > u2 ? u1 : u2);
    float vmin = v0 < v1 ? (v0 < v2 ? v0 : v2) : (v1 < v2 ? v1 : v2);
    float vmax = v0 > v1 ? (v0 > v2 ? v0 : v2) : (v1 > v2 ? v1 : v2);
    int a0 = (int)ceil(umin), a1 = (int)floor(umax);
    int b0 = (int)ceil(vmin), b1 = (int)floor(vmax);
    t->a0 = a0 < 0 ? 0 : a0;
    t->a1 = a1 > mw - 1 ? mw - 1 : a1;
    t->b0 = b0 < vlo ? vlo : b0;
    t->b1 = b1 > vhi - 1 ? vhi - 1 : b1;
    t->sg = area > 0.0f ? 1.0f : -1.0f;
    t->u0 = u0, t->v0 = v0, t->d0 = d0, t->u1 = u1, t->v1 = v1, t->u2 = u2, t->v2 = v2;
    t->gu = gu, t->gv = gv;
    return t->a0 <= t->a1 && t->b0 <= t->b1;
}

/* Whether texel centre (fa, fb) lies inside the triangle or on its edge. */
CM_FN int ts_sm_tri_covers(const ts_sm_tri *t, float fa, float fb)
{
    float e0 = ((t->u1 - t->u0) * (fb - t->v0) - (t->v1 - t->v0) * (fa - t->u0)) * t->sg;
    float e1 = ((t->u2 - t->u1) * (fb - t->v1) - (t->v2 - t->v1) * (fa - t->u1)) * t->sg;
    float e2 = ((t->u0 - t->u2) * (fb - t->v2) - (t->v0 - t->v2) * (fa - t->u2)) * t->sg;
    return !(e0 < 0.0f || e1 < 0.0f || e2 < 0.0f);
}

/* The key the triangle leaves at texel centre (fa, fb). */
CM_FN int ts_sm_tri_key(const ts_sm_tri *t, float fa, float fb)
{
    return ts_sm_key(t->d0 + t->gu * (fa - t->u0) + t->gv * (fb - t->v0) - t->off);
}

/*
 * Render one triangle (texel coordinates and depths of its corners) into
 * the map of mw x mh texels, rows [vlo, vhi) only (the C backend's band).
 * A texel whose centre lies inside the triangle or on its edge keeps the
 * larger of its key and that of the triangle's depth there less the
 * slope-scaled offset (ts_sm_tri_setup).
 */
CM_FN void ts_sm_triangle(CM_GLOBAL const float *P, CM_GLOBAL int *map, int mw, int mh,
                          int vlo, int vhi, float u0, float v0, float d0, float u1, float v1,
                          float d1, float u2, float v2, float d2)
{
    ts_sm_tri t;
    if (!ts_sm_tri_setup(P, mw, vlo, vhi, u0, v0, d0, u1, v1, d1, u2, v2, d2, &t))
        return;
    for (int b = t.b0; b <= t.b1; b++)
        for (int a = t.a0; a <= t.a1; a++) {
            if (!ts_sm_tri_covers(&t, (float)a, (float)b))
                continue;
            int key = ts_sm_tri_key(&t, (float)a, (float)b);
            TS_SM_KEEP_MAX(&map[(long)b * mw + a], key);
            TS_SM_KEEP_TILE(map, mw, mh, a, b, key);
        }
}

/* The largest key of tile (tx, ty) of the map (C: after rendering). */
CM_FN int ts_sm_tile_max(CM_GLOBAL const int *map, int mw, int mh, int tx, int ty)
{
    int top = TS_SM_EMPTY;
    for (int b = ty * TS_SM_TILE; b < (ty + 1) * TS_SM_TILE && b < mh; b++)
        for (int a = tx * TS_SM_TILE; a < (tx + 1) * TS_SM_TILE && a < mw; a++) {
            int k = map[(long)b * mw + a];
            top = k > top ? k : top;
        }
    return top;
}

/* The map's depth at texel (a, b) as a key; off the map: empty (lit). */
CM_FN int ts_sm_fetch(CM_GLOBAL const int *map, int mw, int mh, int a, int b)
{
    return a < 0 || b < 0 || a >= mw || b >= mh ? TS_SM_EMPTY : map[(long)b * mw + a];
}

/* A receiver: its projected centre (fu[0], fv[0], fd[0]) and the projected
 * corners of its own triangles, the fan of the mesh around it (fu[1..6]:
 * its neighbours E, SE, S, W, NW, N; triangle t joins corners t + 1 and
 * t + 2, t = 5 corners 6 and 1; bit t of tri: all three corners valid). */
typedef struct ts_sm_recv_s {
    float fu[7], fv[7], fd[7];
    int tri;
    float box[4]; /* the corners' u and v range, padded: no triangle reaches out of it */
#ifndef __OPENCL_C_VERSION__
    void *memo; /* C: the fan depths its filter has found (core/shadowmap.c), or NULL */
#endif
} ts_sm_recv;

/* The receiver's box (ts_sm_in_box: the fan's quick reject): the range of its
 * seven points, padded by far more than the barycentric test's rounding, so
 * that a texel out of it is out of every triangle by that test too. */
CM_FN void ts_sm_recv_box(ts_sm_recv *r)
{
    float u0 = r->fu[0], u1 = u0, v0 = r->fv[0], v1 = v0;
    for (int k = 1; k < 7; k++) {
        u0 = r->fu[k] < u0 ? r->fu[k] : u0;
        u1 = r->fu[k] > u1 ? r->fu[k] : u1;
        v0 = r->fv[k] < v0 ? r->fv[k] : v0;
        v1 = r->fv[k] > v1 ? r->fv[k] : v1;
    }
    const float pad = 1e-2f;
    r->box[0] = u0 - pad, r->box[1] = u1 + pad, r->box[2] = v0 - pad, r->box[3] = v1 + pad;
}

/* The receiver's fan's triangles that have all three corners and an area
 * (not seen edge-on), in the fan's order: corners p, q as offsets from the
 * receiver (au, av; bu, bv), the determinant, and the depths' offsets. */
typedef struct {
    int nt;
    float au[6], av[6], bu[6], bv[6], det[6], dp[6], dq[6];
} ts_sm_fan;

CM_FN void ts_sm_fan_setup(const ts_sm_recv *r, ts_sm_fan *f)
{
    f->nt = 0;
    for (int t = 0; t < 6; t++) {
        if (!((r->tri >> t) & 1))
            continue;
        int p = t + 1, q = t == 5 ? 1 : t + 2, n = f->nt;
        f->au[n] = r->fu[p] - r->fu[0], f->av[n] = r->fv[p] - r->fv[0];
        f->bu[n] = r->fu[q] - r->fu[0], f->bv[n] = r->fv[q] - r->fv[0];
        f->det[n] = f->au[n] * f->bv[n] - f->bu[n] * f->av[n];
        if (!(f->det[n] > 1e-12f || f->det[n] < -1e-12f)) /* seen edge-on */
            continue;
        f->dp[n] = r->fd[p] - r->fd[0];
        f->dq[n] = r->fd[q] - r->fd[0];
        f->nt++;
    }
}

/* The nearest the light of the fan's triangles that cover texel (x, y),
 * -INFINITY where none does. */
CM_FN float ts_sm_fan_solve(const ts_sm_fan *f, const ts_sm_recv *r, float x, float y)
{
    float best = -INFINITY, px = x - r->fu[0], py = y - r->fv[0];
    for (int n = 0; n < f->nt; n++) {
        float n1 = px * f->bv[n] - f->bu[n] * py, n2 = f->au[n] * py - px * f->av[n];
        /* the signs first: the divisions only where both can be >= 0 */
        if (f->det[n] > 0.0f ? (n1 < 0.0f || n2 < 0.0f) : (n1 > 0.0f || n2 > 0.0f))
            continue;
        float l1 = n1 / f->det[n], l2 = n2 / f->det[n];
        if (!(l1 >= 0.0f && l2 >= 0.0f && l1 + l2 <= 1.0f))
            continue;
        float d = r->fd[0] + l1 * f->dp[n] + l2 * f->dq[n];
        best = d > best ? d : best;
    }
    return best;
}

/* Whether texel (x, y) lies in the receiver's box (out of it, no triangle
 * of its fan covers it). */
CM_FN int ts_sm_in_box(const ts_sm_recv *r, float x, float y)
{
    return x >= r->box[0] && x <= r->box[1] && y >= r->box[2] && y <= r->box[3];
}

/* The depth of the receiver's own surface at texel (x, y): the nearest the
 * light of its fan's triangles that cover the texel, -INFINITY where none
 * does (ts_sm_recv_depth). */
CM_FN float ts_sm_fan_depth(const ts_sm_recv *r, float x, float y)
{
    if (!ts_sm_in_box(r, x, y))
        return -INFINITY;
    ts_sm_fan f;
    ts_sm_fan_setup(r, &f);
    return ts_sm_fan_solve(&f, r, x, y);
}

/* What the taps and the blocker search read the fan's depth with at a
 * texel centre (integer x, y): the C backend's filter remembers each
 * texel's (core/shadowmap.c), the same values. */
#ifndef TS_SM_FAN_DEPTH
#define TS_SM_FAN_DEPTH ts_sm_fan_depth
#endif

/* The receiver's depth at texel (x, y): its own surface where a triangle of
 * its fan covers the texel (the nearest the light of those that do), else
 * its plane (depth slopes gu, gv). A tap compares the map with the
 * receiver's surface, not its plane, where it can: the plane of a concave
 * receiver (a valley floor) runs below its own fan, which then shadowed it
 * through the map (under a light at 90 degrees, which nothing can hide,
 * cells lost up to 0.61 of it). */
CM_FN float ts_sm_recv_depth(const ts_sm_recv *r, float gu, float gv, float x, float y)
{
    float best = TS_SM_FAN_DEPTH(r, x, y);
    return best > -INFINITY ? best : r->fd[0] + gu * (x - r->fu[0]) + gv * (y - r->fv[0]);
}

/* Lit share of one tap at (tu, tv): the comparisons at the four texels
 * around it, weighted bilinearly (the hardware filtering of shadow
 * textures), each against the receiver at that texel (ts_sm_recv_depth). */
CM_FN float ts_sm_tap(CM_GLOBAL const int *map, int mw, int mh, const ts_sm_recv *r, float gu,
                      float gv, float tu, float tv)
{
    float fa = floor(tu), fb = floor(tv);
    float wu = tu - fa, wv = tv - fb;
    int a = (int)fa, b = (int)fb;
    float dark = 0.0f; /* so that all lit is exactly 1 */
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            float d = ts_sm_recv_depth(r, gu, gv, (float)(a + i), (float)(b + j));
            float w = (i ? wu : 1.0f - wu) * (j ? wv : 1.0f - wv);
            dark += ts_sm_fetch(map, mw, mh, a + i, b + j) > ts_sm_key(d) ? w : 0.0f;
        }
    return 1.0f - dark;
}

/*
 * Lit fraction of the receiver r whose plane's depth slopes by gu, gv
 * metres per texel (receiver-plane bias: each tap compares the map with
 * the receiver at that texel, its fan or its plane, so a wide kernel does
 * not shadow a slope by itself): the mean over nu x nv taps spread over a
 * ku x kv texel box around it.
 */
CM_FN float ts_sm_pcf(CM_GLOBAL const int *map, int mw, int mh, const ts_sm_recv *r, float gu,
                      float gv, float ku, float kv)
{
    const float u = r->fu[0], v = r->fv[0];
    int nu = (int)ceil(ku - 1e-3f), nv = (int)ceil(kv - 1e-3f);
    nu = nu < 1 ? 1 : nu > TS_SM_MAX_TAPS ? TS_SM_MAX_TAPS : nu;
    nv = nv < 1 ? 1 : nv > TS_SM_MAX_TAPS ? TS_SM_MAX_TAPS : nv;
    float lit = 0.0f;
    for (int j = 0; j < nv; j++) {
        float tv = v + (((float)j + 0.5f) / (float)nv - 0.5f) * (nv > 1 ? kv : 0.0f);
        for (int i = 0; i < nu; i++) {
            float tu = u + (((float)i + 0.5f) / (float)nu - 0.5f) * (nu > 1 ? ku : 0.0f);
            lit += ts_sm_tap(map, mw, mh, r, gu, gv, tu, tv);
        }
    }
    return lit / (float)(nu * nv);
}

/*
 * PCF over the light's disk as it falls on the map, an ellipse of radii
 * ru x rv texels: rows of taps across it, each row weighted by its chord
 * (so that a straight edge across the light's view darkens the receiver
 * by the disk's area above it, as the exact method's disk does).
 */
CM_FN float ts_sm_pcf_disk(CM_GLOBAL const int *map, int mw, int mh, const ts_sm_recv *r,
                           float gu, float gv, float ru, float rv)
{
    const float u = r->fu[0], v = r->fv[0];
    int nv = (int)ceil(2.0f * rv - 1e-3f);
    nv = nv < 1 ? 1 : nv > TS_SM_MAX_TAPS ? TS_SM_MAX_TAPS : nv;
    float lit = 0.0f, weight = 0.0f;
    for (int j = 0; j < nv; j++) {
        float y = nv > 1 ? ((float)j + 0.5f) / (float)nv * 2.0f - 1.0f : 0.0f;
        float chord = CM_SQRTF(1.0f - y * y);
        int nu = (int)ceil(2.0f * chord * ru - 1e-3f);
        nu = nu < 1 ? 1 : nu > TS_SM_MAX_TAPS ? TS_SM_MAX_TAPS : nu;
        float row = 0.0f;
        for (int i = 0; i < nu; i++) {
            float x = nu > 1 ? (((float)i + 0.5f) / (float)nu * 2.0f - 1.0f) * chord : 0.0f;
            row += ts_sm_tap(map, mw, mh, r, gu, gv, u + x * ru, v + y * rv);
        }
        lit += chord * row / (float)nu;
        weight += chord;
    }
    return lit / weight;
}

/*
 * PCF_KERNEL=auto (percentage-closer soft shadows): search the map around
 * the receiver, over the width of the penumbra the farthest occluder could
 * cast, for blockers: texels nearer the light than the receiver (its fan
 * or its plane, ts_sm_recv_depth) by D, no farther than D tan(r) across
 * (so that they hide part of the light's disk). Their mean D sets the
 * kernel to the penumbra of the disk there, a disk of radius D tan(r) in
 * light space. No blocker: fully lit.
 */
CM_FN float ts_sm_pcf_auto(CM_GLOBAL const float *P, CM_GLOBAL const int *map, int mw, int mh,
                           const ts_sm_recv *r, float gu, float gv)
{
    const float u = r->fu[0], v = r->fv[0], depth = r->fd[0];
    float tr = P[TS_SMP_TAN_R], cap = P[TS_SMP_SEARCH_CAP];
    float ds = 1.0f / P[TS_SMP_INV_DS], dt = 1.0f / P[TS_SMP_INV_DT];
    /* the nearest the light anything within the search's reach can be */
    int tw = (mw + TS_SM_TILE - 1) / TS_SM_TILE, th = (mh + TS_SM_TILE - 1) / TS_SM_TILE;
    int tx = (int)floor(u + 0.5f) / TS_SM_TILE, ty = (int)floor(v + 0.5f) / TS_SM_TILE;
    int top = TS_SM_EMPTY;
    for (int j = ty - 1; j <= ty + 1; j++)
        for (int i = tx - 1; i <= tx + 1; i++)
            if (i >= 0 && j >= 0 && i < tw && j < th) {
                int k = map[(long)mw * mh + (long)j * tw + i];
                top = k > top ? k : top;
            }
    if (top <= ts_sm_key(depth)) /* nothing near is nearer the light */
        return ts_sm_tap(map, mw, mh, r, gu, gv, u, v);
    float reach = (ts_sm_unkey(top) - depth) * tr; /* metres */
    float hu = ts_sm_clampf(reach * P[TS_SMP_INV_DS], 0.0f, cap);
    float hv = ts_sm_clampf(reach * P[TS_SMP_INV_DT], 0.0f, cap);
    int nu = 2 * (int)ceil(hu) + 1, nv = 2 * (int)ceil(hv) + 1;
    nu = nu > TS_SM_SEARCH_TAPS ? TS_SM_SEARCH_TAPS : nu;
    nv = nv > TS_SM_SEARCH_TAPS ? TS_SM_SEARCH_TAPS : nv;
    float sum = 0.0f;
    int blockers = 0, last_b = 0;
    /* taps less than a texel apart round to the same texel: a repeated row
     * of taps, or a tap repeating the one before it, adds nothing to the
     * least D or to whether there is a blocker, and is skipped */
    for (int j = 0; j < nv; j++) {
        float tv = v + (nv > 1 ? ((float)j / (float)(nv - 1) * 2.0f - 1.0f) * hv : 0.0f);
        int b = (int)floor(tv + 0.5f), last_a = 0;
        if (j > 0 && b == last_b)
            continue;
        last_b = b;
        for (int i = 0; i < nu; i++) {
            float tu = u + (nu > 1 ? ((float)i / (float)(nu - 1) * 2.0f - 1.0f) * hu : 0.0f);
            int a = (int)floor(tu + 0.5f);
            if (i > 0 && a == last_a)
                continue;
            last_a = a;
            float d = ts_sm_recv_depth(r, gu, gv, (float)a, (float)b);
            int k = ts_sm_fetch(map, mw, mh, a, b);
            if (!(k > ts_sm_key(d)))
                continue;
            /* a blocker only where it can hide part of the disk: within
             * its height above the receiver times tan(r) */
            float D = ts_sm_unkey(k) - d;
            float du = CM_FABSF((float)a - u) - 0.5f, dv = CM_FABSF((float)b - v) - 0.5f;
            du = du > 0.0f ? du * ds : 0.0f; /* from the texel's nearest point */
            dv = dv > 0.0f ? dv * dt : 0.0f;
            if (du * du + dv * dv <= D * D * tr * tr) {
                sum = blockers == 0 || D < sum ? D : sum;
                blockers++;
            }
        }
    }
    if (blockers == 0) /* a hard shadow's edge at most */
        return ts_sm_tap(map, mw, mh, r, gu, gv, u, v);
    float rad = sum * tr; /* the disk's radius there, metres */
    return ts_sm_pcf_disk(map, mw, mh, r, 0.0f, 0.0f, rad * P[TS_SMP_INV_DS],
                          rad * P[TS_SMP_INV_DT]);
}

/*
 * Lit fraction of the receiver r (its neighbours east, west, north and
 * south, the cell itself where one is missing, give its plane's depth
 * slope). NaN for nodata.
 */
CM_FN float ts_sm_cell(CM_GLOBAL const float *P, CM_GLOBAL const int *map, int mw, int mh,
                       const ts_sm_recv *r)
{
    if (isnan(r->fd[0]))
        return r->fd[0];
    /* the plane through the two central differences, E - W and S - N, in
     * (u, v, depth) */
    float au = r->fu[1] - r->fu[4], av = r->fv[1] - r->fv[4], ad = r->fd[1] - r->fd[4];
    float bu = r->fu[3] - r->fu[6], bv = r->fv[3] - r->fv[6], bd = r->fd[3] - r->fd[6];
    float nu = av * bd - ad * bv, nv = ad * bu - au * bd, nd = au * bv - av * bu;
    float cap = P[TS_SMP_SLOPE_CAP], gu = 0.0f, gv = 0.0f;
    /* nd > 0: the surface faces the light (flat ground under a light above
     * the horizon gives nd > 0; nd changes sign only edge-on). A surface
     * facing away is compared at its own depth: its plane's steep slope
     * would lift it past its occluder. */
    if (nd > 1e-12f) {
        gu = ts_sm_clampf(-nu / nd, -cap, cap);
        gv = ts_sm_clampf(-nv / nd, -cap, cap);
    }
    float ku = P[TS_SMP_KERNEL_U];
    if (ku > 0.0f)
        return ts_sm_pcf(map, mw, mh, r, gu, gv, ku, P[TS_SMP_KERNEL_V]);
    return ts_sm_pcf_auto(P, map, mw, mh, r, gu, gv);
}

/* Render the two triangles of the quad whose north-west corner is vertex
 * (x, y) (x < W - 1, y < H - 1) of the projected vertices pu, pv, pd
 * (W per row). */
CM_FN void ts_sm_quad(CM_GLOBAL const float *P, CM_GLOBAL int *map, int mw, int mh, int vlo,
                      int vhi,
                      CM_GLOBAL const float *pu, CM_GLOBAL const float *pv,
                      CM_GLOBAL const float *pd, int W, int x, int y)
{
    long i00 = (long)y * W + x, i10 = i00 + 1, i01 = i00 + W, i11 = i01 + 1;
    ts_sm_triangle(P, map, mw, mh, vlo, vhi, pu[i00], pv[i00], pd[i00], pu[i10], pv[i10],
                   pd[i10], pu[i11], pv[i11], pd[i11]);
    ts_sm_triangle(P, map, mw, mh, vlo, vhi, pu[i00], pv[i00], pd[i00], pu[i11], pv[i11],
                   pd[i11], pu[i01], pv[i01], pd[i01]);
}

/* Index of the neighbour (x, y), or i itself off the grid or at nodata. */
CM_FN long ts_sm_neighbour(CM_GLOBAL const float *pd, int W, int H, long i, int x, int y)
{
    if (x < 0 || y < 0 || x >= W || y >= H)
        return i;
    long j = (long)y * W + x;
    return isnan(pd[j]) ? i : j;
}

/*
 * The receiver's own slope towards the light (the self-shadow that a depth
 * map cannot resolve below one texel, and the DEM's edge, beyond which the
 * map holds no face): on the ring of the 8 neighbours (ring[k]: their
 * indices, clockwise, the cell itself where one is missing), the point F
 * with the receiver's u lies on the light's side; the terrain there rises
 * h - e above the light's direction, tan(h - e) = dt (v_F - v) / (d_F - d)
 * (light space turns elevation angles by e), and hides the part of the
 * disk below it, as the exact method's first sample does.
 */
CM_FN float ts_sm_near(CM_GLOBAL const float *P, CM_GLOBAL const float *pu,
                       CM_GLOBAL const float *pv, CM_GLOBAL const float *pd, long i,
                       const long *ring)
{
    const float dt = 1.0f / P[TS_SMP_INV_DT], u = pu[i], v = pv[i], d = pd[i];
    float lit = 1.0f;
    for (int k = 0; k < 8; k++) {
        long a = ring[k], b = ring[(k + 1) & 7];
        float ea = pu[a] - u, eb = pu[b] - u;
        if (a == i || b == i || !(ea * eb <= 0.0f) || ea == eb)
            continue;
        float l = ea / (ea - eb);
        float dv = (pv[a] + l * (pv[b] - pv[a]) - v) * dt;
        float dd = pd[a] + l * (pd[b] - pd[a]) - d;
        if (!(dd * P[TS_SMP_CE] - dv * P[TS_SMP_SE] > 0.0f) || !(dd > 0.0f))
            continue; /* the side away from the light, or a drop beyond 90 - e */
        float rise = ts_atanf(dv / dd) * 57.2957795f; /* h - e, degrees */
        float f = ts_disk_fraction_u(-rise * P[TS_SMP_INV_R]);
        lit = f < lit ? f : lit;
    }
    return lit;
}

/* The receiver at cell (x, y) of the projected vertices pu, pv, pd, into r,
 * and its near field's lit share (ts_sm_near), which is what the cell gets
 * where that is not above 0: NaN for nodata, 0 in its own shadow (r then
 * unset). */
CM_FN float ts_sm_recv_make(CM_GLOBAL const float *P, CM_GLOBAL const float *pu,
                            CM_GLOBAL const float *pv, CM_GLOBAL const float *pd, int W, int H,
                            int x, int y, ts_sm_recv *r)
{
    long i = (long)y * W + x;
    long ring[8];
    const int rx[8] = {0, 1, 1, 1, 0, -1, -1, -1}, ry[8] = {-1, -1, 0, 1, 1, 1, 0, -1};
    for (int k = 0; k < 8; k++)
        ring[k] = ts_sm_neighbour(pd, W, H, i, x + rx[k], y + ry[k]);
    r->fu[0] = pu[i];
    r->fv[0] = pv[i];
    r->fd[0] = pd[i];
    r->tri = 0;
    if (isnan(pd[i]))
        return pd[i];
    float near = ts_sm_near(P, pu, pv, pd, i, ring);
    if (!(near > 0.0f)) /* in its own shadow: the map cannot add light */
        return 0.0f;
    /* the fan: E, SE, S, W, NW, N (the mesh's diagonals run NW-SE) */
    const int fan[6] = {2, 3, 4, 6, 7, 0};
    for (int k = 0; k < 6; k++) {
        long j = ring[fan[k]];
        r->fu[k + 1] = pu[j];
        r->fv[k + 1] = pv[j];
        r->fd[k + 1] = pd[j];
        r->tri |= (j != i && ring[fan[(k + 1) % 6]] != i) << k;
    }
    ts_sm_recv_box(r);
#ifndef __OPENCL_C_VERSION__
    r->memo = 0;
#endif
    return near;
}

/* ts_sm_cell for cell (x, y) of the projected vertices pu, pv, pd. */
CM_FN float ts_sm_cell_at(CM_GLOBAL const float *P, CM_GLOBAL const int *map, int mw, int mh,
                          CM_GLOBAL const float *pu, CM_GLOBAL const float *pv,
                          CM_GLOBAL const float *pd, int W, int H, int x, int y)
{
    ts_sm_recv r;
    float near = ts_sm_recv_make(P, pu, pv, pd, W, H, x, y, &r);
    if (!(near > 0.0f))
        return near;
    float lit = ts_sm_cell(P, map, mw, mh, &r);
    return near < lit ? near : lit;
}

#endif
