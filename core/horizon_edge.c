/* The world beyond the DEM edge (ts_edge_mode): the sea-level surface of
 * the Earth, an open sky, or nodata; docs/algorithms.md derives the first. */
#include <math.h>
#include <stdint.h>

#include "day_cycle.h"
#include "disk_fraction.h"
#include "horizon_edge.h"
#include "parallel.h"
#include "simd_clones.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)

/* The tangent of the elevation of the highest sea-level point over s in
 * [s0, s1] seen from height h, for a drop c s^2 (c = 0: no curvature). */
static inline double edge_tangent(double h, double s0, double s1, double c)
{
    /* f(s) = (-h - c s^2) / s has f' = (h - c s^2) / s^2: it rises up to
     * s* = sqrt(h / c) (for h > 0), falls after; for h <= 0 it only falls. */
    double s;
    if (h <= 0)
        s = s0;
    else if (c > 0)
        s = fmin(fmax(sqrt(h / c), s0), s1);
    else
        s = s1; /* flat: -h / s rises toward the horizontal */
    return isinf(s) ? 0.0 : (-h - c * s * s) / s; /* 0: the limit, from below */
}

double ts_edge_horizon(double height_m, double edge_m, const ts_horizon_opts *opts)
{
    double s1 = opts->max_distance > 0 ? opts->max_distance : INFINITY;
    if (isnan(height_m))
        return NAN;
    if (edge_m > s1)
        return -90.0; /* the ray ends on the grid */
    double c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    return atan(edge_tangent(height_m, edge_m, s1, c)) * RAD2DEG;
}

static ts_edge_ray edge_ray_of(const ts_grid *grid, double azimuth)
{
    double a = azimuth * DEG2RAD;
    double sa = sin(a), ca = cos(a);
    if (fabs(sa) < 1e-12) sa = 0;
    if (fabs(ca) < 1e-12) ca = 0;
    double cx = grid->origin ? grid->origin->ref_cell_x : ts_grid_cell_x(grid, grid->height / 2);
    double gx = sa / cx, gy = -ca / grid->cell_y;
    ts_edge_ray r = {gx != 0 ? 1.0 / fabs(gx) : INFINITY, gy != 0 ? 1.0 / fabs(gy) : INFINITY,
                  gx > 0, gy > 0};
    return r;
}

/* Metres from the centre of cell (x, y) to the grid's outer boundary: the
 * larger DEM's for a window, whose own edges are not the world's. */
static inline double edge_ray_distance(const ts_edge_ray *r, const ts_grid *grid, int x, int y)
{
    const ts_grid_origin *o = grid->origin;
    double px = x + 0.5, py = y + 0.5; /* the grid is [0, W] x [0, H] */
    double W = grid->width, H = grid->height;
    if (o) {
        px += o->x0;
        py += o->y0;
        W = o->full_width;
        H = o->full_height;
    }
    double sx = (r->east ? W - px : px) * r->mx;
    double sy = (r->south ? H - py : py) * r->my;
    return sx < sy ? sx : sy;
}

double ts_edge_distance(const ts_grid *grid, int x, int y, double azimuth)
{
    ts_edge_ray r = edge_ray_of(grid, azimuth);
    return edge_ray_distance(&r, grid, x, y);
}

static ts_edge_job edge_job_of(const ts_grid *grid, double azimuth, const ts_horizon_opts *o,
                            float *plane, double sun_elevation)
{
    ts_edge_job j = {grid, o, edge_ray_of(grid, azimuth),
                  o->max_distance > 0 ? o->max_distance : INFINITY,
                  o->curvature ? (1.0 - o->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0, plane,
                  sun_elevation, 0};
    /* from a height h >= 0 (with c >= 0) the edge's tangent (-h - c s^2) / s
     * is <= 0: its raise stays at or below 0 deg, moot to the caller */
    j.skip_nonneg = o->nonpositive_moot && o->edge == TS_EDGE_HORIZON && j.c >= 0;
    return j;
}

/* An upper bound of atan(t) in degrees, cheap: atan(t) <= t for t >= 0,
 * atan(t) <= t / (1 + t^2) for t < 0; a horizon at or above it needs no
 * atan. */
static inline double atan_deg_above(double t)
{
    return (t >= 0 ? t : t / (1.0 + t * t)) * RAD2DEG;
}

/* Horizon v of valid cell (x, y) with the world beyond the edge. */
static inline float edge_raise(const ts_edge_job *j, int x, int y, float v)
{
    double s = edge_ray_distance(&j->ray, j->grid, x, y);
    if (j->opts->edge == TS_EDGE_NODATA)
        return s <= j->reach ? NAN : v;
    if (s > j->reach)
        return v;
    /* ts_edge_horizon's tangent; its atan only where it may win (float
     * rounding is monotonic: v >= bound >= atan keeps v) */
    double t = edge_tangent(ts_grid_at(j->grid, x, y), s, j->reach, j->c);
    if (v >= atan_deg_above(t))
        return v;
    float e = (float)(atan(t) * RAD2DEG);
    return e > v ? e : v;
}

/* Whether cell x of a row keeps its horizon v without edge_raise: nodata
 * stays nodata; from a height h >= 0 (c >= 0) the edge's tangent is <= 0,
 * so a horizon at or above 0 deg stays (most cells of rough terrain, toward
 * most azimuths), and every one when skip_nonneg. */
static inline int edge_stays(float v, float z, int skip_nonneg, int above_stays)
{
    return (v != v) | ((z >= 0) & (skip_nonneg | (above_stays & (v >= 0))));
}

/* Cells a chunk of the row spans: rows of rough terrain mostly have a
 * cell needing edge_raise somewhere (a peak looking away), but few, so the
 * scalar loop runs only over the chunks that hold one. */
#define EDGE_CHUNK 64

/* ts_edge_span_row's cells x0 <= x < x1: each chunk first tested
 * branch-free, so that a chunk where no cell needs edge_raise is one
 * vectorised pass, not a scalar loop. */
TS_SIMD_CLONES
static void raise_span(const ts_edge_job *j, int y, float *restrict row, const float *restrict z,
                       int x0, int x1, int skip_nonneg, int above_stays)
{
    for (int c0 = x0; c0 < x1; c0 += EDGE_CHUNK) {
        const int c1 = x1 - c0 < EDGE_CHUNK ? x1 : c0 + EDGE_CHUNK;
        int need = 0;
        for (int x = c0; x < c1; x++)
            need |= !edge_stays(row[x], z[x], skip_nonneg, above_stays);
        if (!need)
            continue;
        for (int x = c0; x < c1; x++)
            if (!edge_stays(row[x], z[x], skip_nonneg, above_stays))
                row[x] = edge_raise(j, x, y, row[x]);
    }
}

void ts_edge_span(const ts_edge_job *j, int y, int x0, int x1)
{
    ts_edge_span_row(j, y, j->plane + (size_t)y * j->grid->width, x0, x1);
}

void ts_edge_span_row(const ts_edge_job *j, int y, float *row, int x0, int x1)
{
    const int above_stays = j->opts->edge == TS_EDGE_HORIZON && j->c >= 0;
    raise_span(j, y, row, j->grid->z + (ptrdiff_t)y * j->grid->stride, x0, x1, j->skip_nonneg,
               above_stays);
}

void ts_edge_row(const ts_edge_job *j, int y)
{
    ts_edge_span(j, y, 0, j->grid->width);
}

static void edge_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    for (long y = begin; y < end; y++)
        ts_edge_row(ctx, (int)y);
}

int ts_edge_rows_init(ts_edge_job *j, const ts_grid *grid, double azimuth,
                      const ts_horizon_opts *opts, float *plane)
{
    *j = edge_job_of(grid, azimuth, opts, plane, 0.0);
    return opts->edge != TS_EDGE_OPEN;
}

/* The Earth's horizon as a floor of horizon v at height h (TS_EDGE_HORIZON). */
static inline float earth_floor(const ts_horizon_opts *o, float h, float v)
{
    if (v >= 0)
        return v; /* the dip is <= 0: no acos */
    float f = (float)ts_earth_horizon(h, o);
    return f > v ? f : v; /* NaN stays NaN */
}

static void sun_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const ts_edge_job *j = ctx;
    /* From a height >= 0 (c >= 0) the edge's raise stays <= 0 deg
     * (edge_tangent's t <= 0) and so does the Earth's floor: where the sun
     * clears 0 deg, such a cell keeps vis (the fraction 1), without the
     * edge's atan nor the floor's acos (most cells, by day). */
    const int clears0 = j->opts->edge == TS_EDGE_HORIZON && j->c >= 0 &&
                        ts_sun_disk_clears(j->sun_elevation, 0.0);
    for (long y = begin; y < end; y++) {
        float *vis = j->plane + (size_t)y * j->grid->width;
        for (int x = 0; x < j->grid->width; x++) {
            if (isnan(vis[x]) || (clears0 && ts_grid_at(j->grid, x, (int)y) >= 0))
                continue;
            float h = edge_raise(j, x, (int)y, -90.0f);
            /* the Earth's floor raises h to at most max(h, 0): where the sun
             * clears that, the fraction is 1 whatever the floor (u only
             * grows as h falls), so no acos */
            if (h == h && ts_sun_disk_clears(j->sun_elevation, h > 0 ? h : 0.0f))
                continue;
            if (j->opts->edge == TS_EDGE_HORIZON)
                h = earth_floor(j->opts, ts_grid_at(j->grid, x, (int)y), h);
            vis[x] = isnan(h) ? NAN : vis[x] * (float)ts_sun_disk_fraction_inl(j->sun_elevation, h);
        }
    }
}

static ts_status check_plane_args(const ts_grid *grid, const ts_horizon_opts *opts,
                                  const float *plane, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!plane)
        return ts_fail(err, TS_ERR_ARG, "the horizon plane is NULL");
    return ts_horizon_opts_validate(opts, err);
}

ts_status ts_horizon_edge_apply(const ts_grid *grid, double azimuth,
                                const ts_horizon_opts *opts, float *plane, ts_error *err)
{
    ts_status st = check_plane_args(grid, opts, plane, err);
    if (st != TS_OK)
        return st;
    if (!isfinite(azimuth))
        return ts_fail(err, TS_ERR_ARG, "azimuth must be a finite number of degrees, got %g",
                       azimuth);
    if (opts->edge == TS_EDGE_OPEN)
        return ts_ok(err);
    ts_edge_job j = edge_job_of(grid, azimuth, opts, plane, 0.0);
    return ts_parallel_for_ranges(ts_thread_count(opts->threads, grid->height), grid->height,
                                  TS_ROWS_GRAIN, edge_rows, &j, err);
}

ts_status ts_horizon_edge_sun(const ts_grid *grid, double azimuth, double elevation,
                              const ts_horizon_opts *opts, float *vis, ts_error *err)
{
    ts_status st = check_plane_args(grid, opts, vis, err);
    if (st != TS_OK)
        return st;
    if (!isfinite(azimuth) || !(elevation >= -90.0 && elevation <= 90.0))
        return ts_fail(err, TS_ERR_ARG, "the sun must be at a finite azimuth and an elevation "
                       "within -90..90 degrees, got %g and %g", azimuth, elevation);
    if (opts->edge == TS_EDGE_OPEN)
        return ts_ok(err);
    ts_edge_job j = edge_job_of(grid, azimuth, opts, vis, elevation);
    return ts_parallel_for_ranges(ts_thread_count(opts->threads, grid->height), grid->height,
                                  TS_ROWS_GRAIN, sun_rows, &j, err);
}

ts_status ts_horizon_earth_floor(const ts_grid *grid, const ts_horizon_opts *opts,
                                 float *plane, ts_error *err)
{
    ts_status st = check_plane_args(grid, opts, plane, err);
    /* the dip is <= 0 deg: moot where nonpositive_moot says so */
    if (st != TS_OK || opts->edge != TS_EDGE_HORIZON || opts->nonpositive_moot)
        return st;
    for (int y = 0; y < grid->height; y++)
        for (int x = 0; x < grid->width; x++) {
            float *v = plane + (size_t)y * grid->width + x;
            *v = earth_floor(opts, ts_grid_at(grid, x, y), *v);
        }
    return ts_ok(err);
}
