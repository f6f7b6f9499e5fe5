/*
 * The loops of pyramid horizons (core/pyramid_horizon.c) over a run of
 * cells of one grid row: the level rows combined at the samples' row, the
 * samples' blocking angles, the spline (or the maximum) they feed, and the
 * horizons. Branch-free, vectorised, one clone per instruction set.
 */
#include <math.h>

#include "cellmath/cm_fastmath.h"
#include "pyramid_hz.h"

/* The first cell from x0 on whose vector starts a cache line (16
 * floats; the buffers are on lines, ts_pyr_alloc), at most x1 + 1: a run
 * is looped as its head [x0, that - 1] and its body, so that the body's
 * vectors at x do not straddle two lines (the vectoriser does not peel
 * for that by itself). */
static inline int line_start(int x0, int x1)
{
    int a = (x0 + 15) & ~15;
    return a < x1 + 1 ? a : x1 + 1;
}

/* The sums in fused multiply-adds (TS_PYR_FMA_CLONES): fewer operations
 * in the loops that bound the pyramid, and one rounding for each. */
static inline __attribute__((always_inline)) void
combine_span(const float *const r[4], const float w[4], int taps, int x0, int x1,
             float *restrict dst)
{
    const float *r0 = r[0];
    const float w0 = w[0];
    if (taps == 1) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            dst[x] = r0[x];
        return;
    }
    const float *r1 = r[1];
    const float w1 = w[1];
    if (taps == 2) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            dst[x] = fmaf(w1, r1[x], w0 * r0[x]);
        return;
    }
    const float *r2 = r[2], *r3 = r[3];
    const float w2 = w[2], w3 = w[3];
TS_PYR_IVDEP
    for (int x = x0; x <= x1; x++)
        dst[x] = fmaf(w3, r3[x], fmaf(w2, r2[x], fmaf(w1, r1[x], w0 * r0[x])));
}

/* dst[x] = sum of weights w[t] * rows r[t] at x, for x in [x0, x1]. */
TS_PYR_FMA_CLONES
void ts_pyr_combine_rows(const float *const r[4], const float w[4], int taps, int x0, int x1,
                         float *restrict dst)
{
    int a = line_start(x0, x1);
    combine_span(r, w, taps, x0, a - 1, dst);
    combine_span(r, w, taps, a, x1, dst);
}

/* The two plain loops of each row span (core/pyramid_horizon.c), cloned
 * so that they run on the widest vectors. */
TS_SIMD_CLONES
void ts_pyr_clear_max(row_ws *w, int x0, int x1)
{
    float *restrict m = w->m;
    for (int x = x0; x <= x1; x++)
        m[x] = -INFINITY;
}

TS_SIMD_CLONES
int ts_pyr_has_nodata(const float *z, int x0, int x1)
{
    int holes = 0;
    for (int x = x0; x <= x1; x++)
        holes |= z[x] != z[x];
    return holes;
}

/* A cell beside a void has no height of its own on a coarse level (its
 * footprint there is mostly void): it takes its DEM height, so that its
 * samples there still count (each was dropped: beside a 40 x 50 void on
 * jacksboro, 17.5 % of the cell-directions read over 5 degrees low, 13.4 %
 * with this, 11.6 % away from it; samples touching the void stay no
 * occluder, methods.md). */
TS_SIMD_CLONES
void ts_pyr_fill_nodata(float *restrict R, const float *restrict R0, int x0, int x1)
{
    for (int x = x0; x <= x1; x++)
        R[x] = R[x] == R[x] ? R[x] : R0[x];
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
 * spline (or the maximum), as core/pyramid_horizon.c says. */
TS_SIMD_CLONES
void ts_pyr_push_run(row_ws *w, int bspline, int c, int x0, int x1, const float *restrict a_in)
{
    float *restrict s0 = w->s0, *restrict s1 = w->s1, *restrict s2 = w->s2;
    float *restrict m = w->m;
    if (!bspline) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            m[x] = a_in[x] > m[x] ? a_in[x] : m[x];
        return;
    }
    if (c == 0) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            s2[x] = a_in[x];
        return;
    }
    if (c == 1) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++) {
            float a = a_in[x] == a_in[x] ? a_in[x] : s2[x];
            s0[x] = 2.0f * s2[x] - a; /* w_{-1}: knot 0 is w_0 */
            s1[x] = s2[x];
            s2[x] = a;
            m[x] = s1[x] > m[x] ? s1[x] : m[x];
        }
        return;
    }
TS_PYR_IVDEP
    for (int x = x0; x <= x1; x++)
        spline_step(s0, s1, s2, m, x, a_in[x]);
}

/* One level's samples for the cells of [x0, x1]: the level row T at x + ix
 * and x + ix + 1 (weight fx) against the cells' own heights on the level
 * R, at d metres (1 / d = inv_d, curvature drop over d
 * = cd). Pushed as sample c in the same pass where the spline allows,
 * else left in w->A for push_run (returns 0 then). */
static inline __attribute__((always_inline)) int
level_span(row_ws *w, const float *restrict T, int ix, float fx, const float *restrict R,
           float inv_d, float cd, int bspline, int c, int x0, int x1)
{
    float *restrict s0 = w->s0, *restrict s1 = w->s1, *restrict s2 = w->s2;
    float *restrict m = w->m, *restrict A = w->A;
    const float gx = 1.0f - fx;
    const float *restrict Ta = T + ix; /* T[x + ix] defeats the vectoriser */
    if (bspline && c >= 2) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++) {
            float h = fmaf(fx, Ta[x + 1], gx * Ta[x]);
            spline_step(s0, s1, s2, m, x, ts_atan_deg(fmaf(h - R[x], inv_d, -cd)));
        }
        return 1;
    }
    if (!bspline) { /* the maximum of the tangents; one arctangent at the end */
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++) {
            float h = fmaf(fx, Ta[x + 1], gx * Ta[x]);
            float t = fmaf(h - R[x], inv_d, -cd);
            m[x] = t > m[x] ? t : m[x];
        }
        return 1;
    }
TS_PYR_IVDEP
    for (int x = x0; x <= x1; x++) {
        float h = fmaf(fx, Ta[x + 1], gx * Ta[x]);
        A[x] = ts_atan_deg(fmaf(h - R[x], inv_d, -cd));
    }
    return 0;
}

TS_PYR_FMA_CLONES
int ts_pyr_level_run(row_ws *w, const float *restrict T, int ix, float fx,
                     const float *restrict R, float inv_d, float cd, int bspline, int c, int x0,
                     int x1)
{
    int a = line_start(x0, x1);
    level_span(w, T, ix, fx, R, inv_d, cd, bspline, c, x0, a - 1);
    return level_span(w, T, ix, fx, R, inv_d, cd, bspline, c, a, x1);
}

/* The horizons of cells [x0, x1] after `count` >= 1 samples, into out. */
TS_SIMD_CLONES
void ts_pyr_finish_run(row_ws *w, int bspline, int count, int x0, int x1, float *restrict out)
{
    float *restrict s1 = w->s1, *restrict s2 = w->s2, *restrict m = w->m;
    if (!bspline) {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            out[x] = m[x] > -INFINITY ? ts_atan_deg(m[x]) : -90.0f;
        return;
    }
    if (count >= 2) { /* w_M = 2 w_{M-1} - w_{M-2}: knot M-1 is w_{M-1} */
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            w->A[x] = 2.0f * s2[x] - s1[x];
        ts_pyr_push_run(w, 1, count, x0, x1, w->A);
    } else {
TS_PYR_IVDEP
        for (int x = x0; x <= x1; x++)
            m[x] = s2[x] > m[x] ? s2[x] : m[x];
    }
TS_PYR_IVDEP
    /* no spline value where nodata left fewer than three samples: the last */
    for (int x = x0; x <= x1; x++) {
        float r = m[x] > -INFINITY ? m[x] : s2[x];
        out[x] = r == r && r > -INFINITY ? r : -90.0f;
    }
}
