/* Brute-force ray-marching horizon oracle. Deliberately naive: no hulls, no
 * precomputed lines, every step recomputed from the definitions. */
#include "oracle.h"

#include <math.h>

static const double DEG = 3.14159265358979323846 / 180.0;

static double at(const ts_grid *g, int x, int y)
{
    return g->z[(ptrdiff_t)y * g->stride + x];
}

double oracle_bilinear(const ts_grid *g, double x, double y)
{
    return oracle_bilinear_ex(g, x, y, 0);
}

double oracle_bilinear_ex(const ts_grid *g, double x, double y, int strict)
{
    int x0 = (int)floor(x), y0 = (int)floor(y);
    int x1 = x0 + 1 < g->width ? x0 + 1 : x0;
    int y1 = y0 + 1 < g->height ? y0 + 1 : y0;
    double fx = x - x0, fy = y - y0;
    double v[4] = {at(g, x0, y0), at(g, x1, y0), at(g, x0, y1), at(g, x1, y1)};
    double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    double sum = 0, wsum = 0;
    for (int i = 0; i < 4; i++) {
        if (w[i] <= 0)
            continue;
        if (isnan(v[i])) {
            if (strict)
                return NAN;
            continue;
        }
        sum += w[i] * v[i];
        wsum += w[i];
    }
    if (wsum > 0)
        return sum / wsum;
    /* exactly on a valid corner whose neighbours are all nodata */
    for (int i = 0; i < 4; i++)
        if (!isnan(v[i]) && w[i] == 1.0)
            return v[i];
    return NAN;
}

double oracle_cell_x(const ts_grid *g, double y)
{
    if (!g->cell_x_row)
        return g->cell_x;
    if (y <= 0)
        return g->cell_x_row[0];
    if (y >= g->height - 1)
        return g->cell_x_row[g->height - 1];
    int y0 = (int)floor(y);
    double f = y - y0;
    return (1 - f) * g->cell_x_row[y0] + f * g->cell_x_row[y0 + 1];
}

double oracle_horizon(const ts_grid *g, int x, int y, double azimuth,
                      const ts_horizon_opts *opts)
{
    double d_best, d_edge;
    return oracle_horizon_ex(g, x, y, azimuth, opts, 0, &d_best, &d_edge);
}

double oracle_horizon_ex(const ts_grid *g, int x, int y, double azimuth,
                         const ts_horizon_opts *opts, int strict,
                         double *d_best, double *d_edge)
{
    double h0 = at(g, x, y);
    *d_best = *d_edge = INFINITY;
    if (isnan(h0))
        return NAN;

    double min_cell = g->cell_y;
    for (int r = 0; r < g->height; r++)
        if (oracle_cell_x(g, r) < min_cell)
            min_cell = oracle_cell_x(g, r);
    /* Steps of at most a quarter cell, and much finer near the start: the
     * horizon of the bilinear surface is a supremum that, on ground rising
     * ahead, is only reached as the distance goes to 0 (the slope of the
     * first patch), so the steps grow geometrically from 1e-4 cell. */
    double s_max = 0.25 * min_cell, s = 1e-4 * min_cell;
    double sa = sin(azimuth * DEG), ca = cos(azimuth * DEG);
    /* cos(90 deg) is 6e-17, not 0: snap, or a ray along the first row
     * would drift off the grid at once */
    if (fabs(sa) < 1e-12) sa = 0;
    if (fabs(ca) < 1e-12) ca = 0;
    double c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS)
                               : 0.0;

    double px = x, py = y, d = 0, best = -INFINITY;
    for (;;) {
        /* grid units per metre, then shorten the step to land exactly on
         * the next row or column line: the kinks of the bilinear surface,
         * where the maxima of piecewise-linear terrain lie */
        double ux = sa / oracle_cell_x(g, py), uy = -ca / g->cell_y;
        double tx = ux > 0   ? (floor(px) + 1 - px) / ux
                    : ux < 0 ? (ceil(px) - 1 - px) / ux
                             : INFINITY;
        double ty = uy > 0   ? (floor(py) + 1 - py) / uy
                    : uy < 0 ? (ceil(py) - 1 - py) / uy
                             : INFINITY;
        double step = fmin(s, fmin(tx, ty));
        /* and on max_distance itself, where a capped horizon often lies */
        double to_cap = opts->max_distance > 0 ? opts->max_distance - d : INFINITY;
        if (to_cap > 0 && to_cap < step)
            step = to_cap;
        px = step == tx ? rint(px + step * ux) : px + step * ux;
        py = step == ty ? rint(py + step * uy) : py + step * uy;
        d += step;
        s = fmin(s_max, d / 16); /* d grows by 1/16 a step up to s_max */
        if (px < 0 || px > g->width - 1 || py < 0 || py > g->height - 1) {
            *d_edge = d;
            break;
        }
        /* a sample exactly at max_distance counts (d carries rounding) */
        if (opts->max_distance > 0 && d > opts->max_distance * (1 + 1e-9))
            break;
        double hs = oracle_bilinear_ex(g, px, py, strict);
        if (isnan(hs))
            continue; /* nodata is skipped, not an occluder */
        double slope = (hs - h0 - c * d * d) / d;
        if (slope > best) {
            best = slope;
            *d_best = d;
        }
    }
    return best == -INFINITY ? -90.0 : atan(best) / DEG;
}
