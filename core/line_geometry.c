/* Sweep-line placement for one azimuth; see line_geometry.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "line_geometry.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

ts_status ts_line_geom_init(ts_line_geom *g, const ts_grid *grid, double azimuth,
                            ts_error *err)
{
    memset(g, 0, sizeof *g);
    if (!isfinite(azimuth))
        return ts_fail(err, TS_ERR_ARG, "azimuth must be a finite number of degrees, got %g",
                       azimuth);
    azimuth = fmod(azimuth, 360.0);
    if (azimuth < 0)
        azimuth += 360.0;
    int W = grid->width, H = grid->height;
    /* Direction toward the azimuth in cells (x east, y south); the line
     * direction is taken at the central row for geographic grids. */
    double cx = ts_grid_cell_x(grid, H / 2), cy = grid->cell_y;
    double a = azimuth * DEG2RAD;
    double s = sin(a), c = cos(a);
    /* Snap tiny components so that 0, 90, 180, 270 give exact axis lines. */
    if (fabs(s) < 1e-12) s = 0;
    if (fabs(c) < 1e-12) c = 0;
    double gx = s / cx, gy = -c / cy;
    /* Sweep (processing) direction is opposite to the azimuth. */
    double wx = -gx, wy = -gy;
    g->x_major = fabs(wx) >= fabs(wy);
    double wu = g->x_major ? wx : wy, wv = g->x_major ? wy : wx;
    g->U = g->x_major ? W : H;
    g->V = g->x_major ? H : W;
    g->t = wv / fabs(wu);
    g->u_step = wu > 0 ? 1 : -1;
    g->u_start = wu > 0 ? 0 : g->U - 1;
    ptrdiff_t su = g->x_major ? 1 : grid->stride;
    g->v_stride = g->x_major ? grid->stride : 1;
    g->u_stride = su * g->u_step;
    g->origin = su * g->u_start;

    g->fl = malloc((size_t)g->U * sizeof *g->fl);
    g->fr = malloc((size_t)g->U * sizeof *g->fr);
    if (!g->fl || !g->fr) {
        ts_line_geom_free(g);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate sweep line tables");
    }
    for (int k = 0; k < g->U; k++) {
        double p = g->t * k;
        double f = floor(p);
        float fr = (float)(p - f);
        /* Rounding can land a hair below 1: fold it onto the next cell. */
        if (fr >= 1.0f) {
            f += 1;
            fr = 0.0f;
        }
        g->fl[k] = (int)f;
        g->fr[k] = fr;
    }
    int flmin = g->fl[0] < g->fl[g->U - 1] ? g->fl[0] : g->fl[g->U - 1];
    int flmax = g->fl[0] < g->fl[g->U - 1] ? g->fl[g->U - 1] : g->fl[0];
    g->b_lo = -(long)flmax;
    g->b_hi = (long)(g->V - 1) - flmin;

    /* Metres per step: one cell along u plus |t| cells along v. */
    double tv = fabs(g->t);
    if (!grid->cell_x_row) {
        g->step_m = g->x_major ? hypot(grid->cell_x, tv * cy) : hypot(tv * grid->cell_x, cy);
    } else {
        g->step_row = malloc((size_t)H * sizeof *g->step_row);
        if (!g->step_row) {
            ts_line_geom_free(g);
            return ts_fail(err, TS_ERR_NOMEM, "cannot allocate sweep step table");
        }
        for (int y = 0; y < H; y++) {
            double cxy = grid->cell_x_row[y];
            g->step_row[y] = g->x_major ? hypot(cxy, tv * cy) : hypot(tv * cxy, cy);
        }
        g->step_m = g->step_row[H / 2];
    }
    return ts_ok(err);
}

void ts_line_geom_free(ts_line_geom *g)
{
    free(g->fl);
    free(g->fr);
    free(g->step_row);
    memset(g, 0, sizeof *g);
}

/* fl is monotone in k (non-decreasing for t >= 0, non-increasing for t < 0),
 * so the k range where lo <= b + fl[k] <= hi is found by binary search. */
static int first_k(const ts_line_geom *g, int ascending, long lim, int want_ge)
{
    /* Smallest k with predicate true, predicate monotone false->true. */
    int lo = 0, hi = g->U; /* answer in [lo, hi], hi = none */
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        long v = g->fl[mid];
        int p = want_ge ? (ascending ? v >= lim : v <= lim) : (ascending ? v > lim : v < lim);
        if (p)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

int ts_line_k_range(const ts_line_geom *g, long b, int *k0, int *k1)
{
    int asc = g->t >= 0;
    /* Rows b + fl[k] in [0, V-1]  <=>  fl[k] in [-b, V-1-b]. */
    long lo = -b, hi = (long)g->V - 1 - b;
    int a, z;
    if (asc) {
        a = first_k(g, 1, lo, 1);      /* first fl >= lo */
        z = first_k(g, 1, hi, 0) - 1;  /* last fl <= hi */
    } else {
        a = first_k(g, 0, hi, 1);      /* first fl <= hi */
        z = first_k(g, 0, lo, 0) - 1;  /* last fl >= lo */
    }
    if (a > z || a >= g->U || z < 0)
        return 0;
    *k0 = a;
    *k1 = z;
    return 1;
}

void ts_line_out_strides(const ts_line_geom *g, int width, ptrdiff_t *origin,
                         ptrdiff_t *u_stride, ptrdiff_t *v_stride)
{
    ptrdiff_t ou = g->x_major ? 1 : width;
    *v_stride = g->x_major ? width : 1;
    *u_stride = ou * g->u_step;
    *origin = ou * g->u_start;
}
