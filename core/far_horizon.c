/*
 * Far-field horizons and far shadows: only terrain at least a threshold
 * distance behind a cell counts (Chajdas et al. 2015). The sweep of
 * horizon_sweep.c, with two differences: a sample joins its line's hull
 * only once the line has moved the threshold past it (so the hull holds
 * exactly the far samples), and there is no near field to solve. As in
 * the whole sweep, a cell between two lines takes its own ray's slope at
 * the occluders the two lines' hulls find (the lines' own slopes, mixed,
 * were up to a degree off on rough terrain at odd azimuths).
 *
 * Where the lines have equal steps (every grid but a geographic one) and
 * the threshold spans more than the near field's steps, the sweep's own
 * lockstep blocks do this work (ts_sweep_far_lanes: each line's hull takes
 * its samples the threshold's steps late, eight lines to a vector), about
 * twice as fast; far_line below, one line at a time, does the rest. The
 * two agree but for float rounding. Both put a line's or a cell's ray's
 * sample within 1e-6 of a cell on the cell (ts_line_geom_snap; the rays
 * were not, and cells whose ray met the grid's last row or column there
 * missed that occluder). See shadow_atlas.h.
 */
#include <math.h>
#include <stdlib.h>

#include "line_geometry.h"
#include "parallel.h"
#include "shadow_atlas.h"
#include "status_internal.h"
#include "sweep_far.h"

typedef struct {
    double d, g;
    int k; /* the sample's step */
} fpt;

/* A query's tangent vertex: its step (-1: none) and its distance from the
 * query, measured along the line that holds it (each line counts its
 * distances from its own first sample). */
typedef struct {
    double D;
    int k;
} fvertex;

typedef struct {
    const ts_grid *grid;
    const ts_line_geom *geom;
    double c;   /* curvature coefficient (1-k)/(2R), 0 when off */
    double T;   /* threshold, metres */
    double dz;  /* observers stand this high above the cells */
    float *out; /* slopes, then degrees; row stride = width */
    ptrdiff_t o_origin, o_u_stride, o_v_stride;
    long b0;
    int *failed;
} far_ctx;

typedef struct {
    fpt *hull, *raw;
    int n, raw_n, pending;
    int tan_c, tan_n; /* the last tangents of the cells' and next cells' queries */
    ts_line_pair lo;   /* far-side tangent vertices (fvertex entries) */
} far_ws;

/* Push onto the upper hull (points arrive by increasing d). */
static inline void hull_push(far_ws *w, fpt p)
{
    fpt *S = w->hull;
    int n = w->n;
    while (n >= 2 && (S[n - 2].g - p.g) * (p.d - S[n - 1].d) >=
                         (S[n - 1].g - p.g) * (p.d - S[n - 2].d))
        n--;
    S[n] = p;
    w->n = n + 1;
}

/* Whether hull vertex j + 1 is at least as steep as vertex j from (d, g)
 * (cross-multiplied: both lie behind d). */
static inline int steeper_next(const fpt *S, int j, double d, double g)
{
    return (S[j + 1].g - g) * (d - S[j].d) >= (S[j].g - g) * (d - S[j + 1].d);
}

/* The vertex of largest slope from (d, g) to the hull, which lies entirely
 * behind d: the slopes to the vertices rise and then fall, so the answer
 * is the first vertex whose next is less steep. It moves little from one
 * sample to the next, so the search walks from the line's last answer
 * *at (kept within the hull): a step or two where a binary search takes
 * log2 of the hull's size. */
static inline int hull_tangent(const far_ws *w, double d, double g, int *at)
{
    const fpt *S = w->hull;
    int j = *at < w->n - 1 ? *at : w->n - 1;
    j = j < 0 ? 0 : j;
    if (j + 1 < w->n && steeper_next(S, j, d, g))
        do
            j++;
        while (j + 1 < w->n && steeper_next(S, j, d, g));
    else
        while (j > 0 && !steeper_next(S, j - 1, d, g))
            j--;
    *at = j;
    return j;
}

/* The tangent vertex of an observer at height h, d along the line. */
static inline fvertex far_vertex(const far_ctx *C, far_ws *w, double d, float h, int *at)
{
    if (w->n == 0)
        return (fvertex){0.0, -1};
    const fpt *v = &w->hull[hull_tangent(w, d, h + C->dz - C->c * d * d, at)];
    return (fvertex){d - v->d, v->k};
}

/* Slope from an observer at height h, d along the line, to the line's own
 * vertex: (h' - h) / D - c D with D = d - d'. */
static inline float line_slope(const far_ctx *C, far_ws *w, double d, float h)
{
    if (w->n == 0)
        return -INFINITY;
    double g = h + C->dz - C->c * d * d;
    const fpt *v = &w->hull[hull_tangent(w, d, g, &w->tan_c)];
    return (float)((v->g - g) / (d - v->d) - 2.0 * C->c * d);
}

/* Slope from cell (k, i) at height h to its own ray at the step of vertex
 * v (which lies between the two lines around the ray); -inf where there is
 * none, the ray is off the grid there or touches nodata (cm_ray_slope_at). */
static inline double ray_slope(const far_ctx *C, int k, int i, float h, fvertex v)
{
    const ts_line_geom *G = C->geom;
    int dk = k - v.k;
    double D = v.D;
    if (v.k < 0 || dk <= 0 || !(D > 0))
        return -INFINITY;
    int r0 = i + G->ray_o[dk];
    float f = G->ray_f[dk];
    if (r0 < 0 || r0 > G->V - 1 || (f > 0.0f && r0 + 1 > G->V - 1))
        return -INFINITY;
    const float *zz = C->grid->z + G->origin + (ptrdiff_t)v.k * G->u_stride +
                      (ptrdiff_t)r0 * G->v_stride;
    float a = zz[0], b = f > 0.0f ? zz[G->v_stride] : a;
    float hz = a + f * (b - a);
    if (isnan(hz))
        return -INFINITY;
    return (hz - (h + C->dz)) / D - C->c * D;
}

static void far_line(const far_ctx *C, far_ws *w, long b, int write)
{
    const ts_line_geom *G = C->geom;
    const int pk0 = w->lo.prev_k0, pk1 = w->lo.prev_k1;
    int k0, k1;
    if (!ts_line_pair_next(&w->lo, G, b, &k0, &k1))
        return;
    const fvertex *prev_lo = w->lo.prev;
    fvertex *cur_lo = w->lo.cur;
    w->n = w->raw_n = w->pending = 0;
    w->tan_c = w->tan_n = 0;
    double d = 0.0;
    for (int k = k0; k <= k1; k++) {
        /* (the geometry's fractions are snapped: ts_line_geom_snap) */
        ts_line_sample s;
        ts_line_sample_at(G, C->grid->z, b, k, k0, 0.0f, &d, &s);
        /* Samples at least T behind join the hull, in order. */
        while (w->pending < w->raw_n && d - w->raw[w->pending].d >= C->T)
            hull_push(w, w->raw[w->pending++]);
        if (write) {
            float s_out;
            if (isnan(s.hc)) {
                s_out = NAN;
            } else if (s.F == 0.0f) { /* the cell is on the line */
                s_out = line_slope(C, w, d, s.hc);
            } else {
                fvertex hi = s.inside ? far_vertex(C, w, d, s.hc, &w->tan_c) : (fvertex){0.0, -1};
                fvertex lo = (k >= pk0 && k <= pk1) ? prev_lo[k] : (fvertex){0.0, -1};
                double a = ray_slope(C, k, s.i, s.hc, lo);
                double b = ray_slope(C, k, s.i, s.hc, hi);
                s_out = (float)(a > b ? a : b);
            }
            C->out[C->o_origin + (ptrdiff_t)k * C->o_u_stride +
                   (ptrdiff_t)s.i * C->o_v_stride] = s_out;
        }
        cur_lo[k] = (s.has_next && !isnan(s.hn)) ? far_vertex(C, w, d, s.hn, &w->tan_n)
                                                  : (fvertex){0.0, -1};
        if (!isnan(s.hs))
            w->raw[w->raw_n++] = (fpt){d, s.hs - C->c * d * d, k};
    }
}

static void far_range(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const far_ctx *C = ctx;
    int U = C->geom->U;
    far_ws w = {0};
    w.hull = malloc((size_t)(U + 1) * sizeof *w.hull);
    w.raw = malloc((size_t)(U + 1) * sizeof *w.raw);
    w.lo.prev = malloc((size_t)U * sizeof(fvertex));
    w.lo.cur = malloc((size_t)U * sizeof(fvertex));
    w.lo.prev_k0 = 1;
    w.lo.prev_k1 = 0;
    if (w.hull && w.raw && w.lo.prev && w.lo.cur) {
        if (begin > 0)
            far_line(C, &w, C->b0 + begin - 1, 0);
        for (long b = C->b0 + begin; b < C->b0 + end; b++)
            far_line(C, &w, b, 1);
    } else {
        __atomic_store_n(C->failed, 1, __ATOMIC_RELAXED);
    }
    free(w.hull);
    free(w.raw);
    free(w.lo.prev);
    free(w.lo.cur);
}

static void to_degrees(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const far_ctx *C = ctx;
    const int W = C->grid->width;
    for (long y = y0; y < y1; y++)
        ts_slopes_to_degrees(C->out + (size_t)y * W, W);
}

/* The far-field sweep: slopes (tangents) into out, or, with `degrees`,
 * elevation angles. */
static ts_status far_sweep(const ts_grid *grid, double azimuth, double threshold_m,
                           double dz, const ts_horizon_opts *opts, int degrees, float *out,
                           ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!opts || !out)
        return ts_fail(err, TS_ERR_ARG, "far-field horizon: options or output are NULL");
    ts_horizon_opts o = *opts;
    if (o.directions < 1)
        o.directions = 1;
    if ((st = ts_horizon_opts_validate(&o, err)) != TS_OK)
        return st;
    if (o.max_distance != 0)
        return ts_fail(err, TS_ERR_ARG, "far-field horizons take no maximum distance "
                       "(got %g m)", o.max_distance);
    if (!(threshold_m > 0) || !isfinite(threshold_m))
        return ts_fail(err, TS_ERR_ARG, "the far-shadow threshold must be a positive "
                       "distance in metres, got %g", threshold_m);
    far_ctx C = {0};
    C.grid = grid;
    C.out = out;
    if (ts_sweep_far_lanes(grid, azimuth, threshold_m, dz, &o, out, &st, err)) {
        if (st == TS_OK && degrees)
            st = ts_parallel_for(ts_thread_count(o.threads, grid->height), grid->height,
                                 to_degrees, &C, err);
        return st == TS_OK ? ts_ok(err) : st;
    }
    ts_line_geom geom;
    if ((st = ts_line_geom_init(&geom, grid, azimuth, err)) != TS_OK)
        return st;
    ts_line_geom_snap(&geom, TS_FAR_SNAP);
    int failed = 0;
    C.geom = &geom;
    C.c = o.curvature ? (1.0 - o.refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    C.T = threshold_m;
    C.dz = dz;
    ts_line_out_strides(&geom, grid->width, &C.o_origin, &C.o_u_stride, &C.o_v_stride);
    C.b0 = geom.b_lo;
    C.failed = &failed;
    long lines = geom.b_hi - geom.b_lo + 1;
    st = ts_parallel_for(ts_thread_count(o.threads, lines), lines, far_range, &C, err);
    if (st == TS_OK && !failed && degrees)
        st = ts_parallel_for(ts_thread_count(o.threads, grid->height), grid->height,
                             to_degrees, &C, err);
    ts_line_geom_free(&geom);
    if (st != TS_OK)
        return st;
    if (failed)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the far-field sweep workspace");
    return ts_ok(err);
}

ts_status ts_far_horizon(const ts_grid *grid, double azimuth, double threshold_m,
                         const ts_horizon_opts *opts, float *out, ts_error *err)
{
    return far_sweep(grid, azimuth, threshold_m, 0.0, opts, 1, out, err);
}

ts_status ts_far_slope_raised(const ts_grid *grid, double azimuth, double threshold_m,
                              double dz, const ts_horizon_opts *opts, float *out,
                              ts_error *err)
{
    if (!isfinite(dz))
        return ts_fail(err, TS_ERR_ARG, "the observers' height above the cells must be "
                       "finite, got %g", dz);
    return far_sweep(grid, azimuth, threshold_m, dz, opts, 0, out, err);
}

ts_status ts_far_shadow(const ts_grid *grid, double azimuth, double elevation,
                        double threshold_m, const ts_horizon_opts *opts, uint8_t *out,
                        ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "ts_far_shadow: the output is NULL");
    if (!(elevation >= -90.0 && elevation <= 90.0))
        return ts_fail(err, TS_ERR_ARG, "the sun's elevation must be between -90 and "
                       "90 degrees, got %g", elevation);
    size_t cells = (size_t)grid->width * grid->height;
    float *s = malloc(cells * sizeof *s);
    if (!s)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate a far-horizon plane");
    st = far_sweep(grid, azimuth, threshold_m, 0.0, opts, 0, s, err);
    if (st == TS_OK) {
        /* slope > tan(elevation) <=> horizon angle > elevation */
        double t = elevation >= 90.0 ? INFINITY : tan(elevation * (M_PI / 180.0));
        for (size_t i = 0; i < cells; i++)
            out[i] = isnan(s[i]) ? TS_ATLAS_NODATA : (double)s[i] > t ? 1 : 0;
    }
    free(s);
    return st;
}

