/* The world beyond the DEM edge (ts_edge_mode): the sea-level surface of
 * the Earth, an open sky, or nodata; docs/algorithms.md derives the first. */
#include <math.h>
#include <stdint.h>

#include "day_cycle.h"
#include "parallel.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)

double ts_edge_horizon(double height_m, double edge_m, const ts_horizon_opts *opts)
{
    double h = height_m, s0 = edge_m;
    double s1 = opts->max_distance > 0 ? opts->max_distance : INFINITY;
    if (isnan(h))
        return NAN;
    if (s0 > s1)
        return -90.0; /* the ray ends on the grid */
    /* drop of the sea level below the cell's tangent plane: c s^2 */
    double c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    /* f(s) = (-h - c s^2) / s has f' = (h - c s^2) / s^2: it rises up to
     * s* = sqrt(h / c) (for h > 0), falls after; for h <= 0 it only falls. */
    double s;
    if (h <= 0)
        s = s0;
    else if (c > 0)
        s = fmin(fmax(sqrt(h / c), s0), s1);
    else
        s = s1; /* flat: -h / s rises toward the horizontal */
    if (isinf(s))
        return 0.0; /* the limit, from below */
    return atan((-h - c * s * s) / s) * RAD2DEG;
}

double ts_edge_distance(const ts_grid *grid, int x, int y, double azimuth)
{
    /* the direction of ts_line_geom_init, in cells per metre */
    double a = azimuth * DEG2RAD;
    double sa = sin(a), ca = cos(a);
    if (fabs(sa) < 1e-12) sa = 0;
    if (fabs(ca) < 1e-12) ca = 0;
    double gx = sa / ts_grid_cell_x(grid, grid->height / 2), gy = -ca / grid->cell_y;
    double px = x + 0.5, py = y + 0.5; /* the cell's centre; the grid is [0, W] x [0, H] */
    double sx = gx > 0 ? (grid->width - px) / gx : gx < 0 ? px / -gx : INFINITY;
    double sy = gy > 0 ? (grid->height - py) / gy : gy < 0 ? py / -gy : INFINITY;
    return fmin(sx, sy);
}

typedef struct {
    const ts_grid *grid;
    const ts_horizon_opts *opts;
    double azimuth;
    float *plane;
} edge_job;

static void edge_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const edge_job *j = ctx;
    const ts_grid *g = j->grid;
    const double reach = j->opts->max_distance > 0 ? j->opts->max_distance : INFINITY;
    for (long y = begin; y < end; y++) {
        float *row = j->plane + (size_t)y * g->width;
        for (int x = 0; x < g->width; x++) {
            if (isnan(row[x]))
                continue; /* nodata stays nodata */
            double s = ts_edge_distance(g, x, (int)y, j->azimuth);
            if (j->opts->edge == TS_EDGE_NODATA) {
                if (s <= reach)
                    row[x] = NAN;
                continue;
            }
            float e = (float)ts_edge_horizon(ts_grid_at(g, x, (int)y), s, j->opts);
            if (e > row[x])
                row[x] = e;
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
    edge_job j = {grid, opts, azimuth, plane};
    return ts_parallel_for(ts_thread_count(opts->threads, grid->height), grid->height,
                           edge_rows, &j, err);
}

ts_status ts_horizon_earth_floor(const ts_grid *grid, const ts_horizon_opts *opts,
                                 float *plane, ts_error *err)
{
    ts_status st = check_plane_args(grid, opts, plane, err);
    if (st != TS_OK || opts->edge != TS_EDGE_HORIZON)
        return st;
    for (int y = 0; y < grid->height; y++)
        for (int x = 0; x < grid->width; x++) {
            float *v = plane + (size_t)y * grid->width + x;
            float f = (float)ts_earth_horizon(ts_grid_at(grid, x, y), opts);
            if (f > *v) /* NaN (nodata) stays NaN */
                *v = f;
        }
    return ts_ok(err);
}
