/* Sweep-line placement for one azimuth; see line_geometry.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cellmath/cm_line.h"
#include "cellmath/cm_near_field.h"
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
    const ts_grid_origin *o = grid->origin;
    double cx = o ? o->ref_cell_x : ts_grid_cell_x(grid, H / 2), cy = grid->cell_y;
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
    g->ray_o = malloc((size_t)g->U * sizeof *g->ray_o);
    g->ray_f = malloc((size_t)g->U * sizeof *g->ray_f);
    if (!g->fl || !g->fr || !g->ray_o || !g->ray_f) {
        ts_line_geom_free(g);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate sweep line tables");
    }
    /* A window's lines are the whole DEM's: its sample k is the whole
     * DEM's step q = k + k_anchor (q counted, as there, from the DEM's
     * first u in the sweep's direction: its last column or row when the
     * sweep runs backwards), at v t * q there; fl[k] counts from
     * floor(t * k_anchor), an integer shift of the window's line
     * intercepts. */
    double f0 = 0;
    if (o) {
        long ou = g->x_major ? o->x0 : o->y0;
        long full_u = g->x_major ? o->full_width : o->full_height;
        long full_start = g->u_step > 0 ? 0 : full_u - 1;
        g->anchored = 1;
        g->k_anchor = (ou + g->u_start - full_start) * (long)g->u_step;
        f0 = floor(g->t * (double)g->k_anchor);
    }
    for (int k = 0; k < g->U; k++) {
        double p = g->t * (double)(k + g->k_anchor);
        double f = floor(p);
        float fr = (float)(p - f);
        /* Rounding can land a hair below 1: fold it onto the next cell;
         * a hair above 0 is on the cell, as the rays' (cm_ray_offset). */
        if (fr >= 1.0f) {
            f += 1;
            fr = 0.0f;
        }
        g->fl[k] = (int)(f - f0);
        g->fr[k] = p - f < CM_CELL_SNAP ? 0.0f : fr;
        /* The far field's ray: as cm_ray_slope takes it. */
        g->ray_o[k] = cm_ray_offset(g->t, k, &g->ray_f[k]);
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
        /* a window's near-field reach is the whole DEM's */
        double cxm = o ? o->ref_cell_x : grid->cell_x_row[H / 2];
        g->step_m = g->x_major ? hypot(cxm, tv * cy) : hypot(tv * cxm, cy);
    }
    return ts_ok(err);
}

void ts_line_geom_free(ts_line_geom *g)
{
    free(g->fl);
    free(g->fr);
    free(g->ray_o);
    free(g->ray_f);
    free(g->step_row);
    memset(g, 0, sizeof *g);
}

void ts_line_geom_snap(ts_line_geom *g, float snap)
{
    for (int k = 0; k < g->U; k++) {
        g->fr[k] = g->fr[k] < snap ? 0.0f : g->fr[k];
        if (g->ray_f[k] < snap) {
            g->ray_f[k] = 0.0f;
        } else if (g->ray_f[k] > 1.0f - snap) {
            g->ray_o[k] += 1;
            g->ray_f[k] = 0.0f;
        }
    }
}

void ts_line_geom_step_range(const ts_line_geom *g, int height, double *shortest,
                             double *longest)
{
    *shortest = *longest = g->step_m;
    if (g->step_row)
        for (int y = 0; y < height; y++) {
            *longest = g->step_row[y] > *longest ? g->step_row[y] : *longest;
            *shortest = g->step_row[y] < *shortest ? g->step_row[y] : *shortest;
        }
}

int ts_line_k_range(const ts_line_geom *g, long b, int *k0, int *k1)
{
    return cm_line_k_range(g->fl, g->U, g->V, g->t >= 0, b, k0, k1);
}

int ts_line_k_leaving(const ts_line_geom *g, long b, int k1)
{
    return cm_line_k_leaving(g->fl, g->U, g->t >= 0, b, k1);
}

void ts_line_out_strides(const ts_line_geom *g, int width, ptrdiff_t *origin,
                         ptrdiff_t *u_stride, ptrdiff_t *v_stride)
{
    ptrdiff_t ou = g->x_major ? 1 : width;
    *v_stride = g->x_major ? width : 1;
    *u_stride = ou * g->u_step;
    *origin = ou * g->u_start;
}
