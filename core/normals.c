/* Surface normals by Horn's 3x3 method, as gdaldem hillshade. */
#include <math.h>

#include "parallel.h"
#include "status_internal.h"

typedef struct {
    const ts_grid *g;
    float *nx, *ny, *nz;
} normals_ctx;

/* Height of a neighbour, the centre's where it is outside or nodata. */
static inline float nb(const ts_grid *g, int x, int y, float centre)
{
    if (x < 0 || y < 0 || x >= g->width || y >= g->height)
        return centre;
    float v = ts_grid_at(g, x, y);
    return isnan(v) ? centre : v;
}

static void normals_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const normals_ctx *C = ctx;
    const ts_grid *g = C->g;
    for (int y = (int)y0; y < (int)y1; y++) {
        double ew = 8.0 * ts_grid_cell_x(g, y), ns = 8.0 * g->cell_y;
        for (int x = 0; x < g->width; x++) {
            size_t o = (size_t)y * g->width + x;
            float e = ts_grid_at(g, x, y);
            if (isnan(e)) {
                C->nx[o] = C->ny[o] = C->nz[o] = NAN;
                continue;
            }
            /* a b c / d e f / g h i, a at the north-west. */
            double a = nb(g, x - 1, y - 1, e), b = nb(g, x, y - 1, e), c = nb(g, x + 1, y - 1, e);
            double d = nb(g, x - 1, y, e), f = nb(g, x + 1, y, e);
            double gg = nb(g, x - 1, y + 1, e), h = nb(g, x, y + 1, e), i = nb(g, x + 1, y + 1, e);
            double dzdx = ((c + 2 * f + i) - (a + 2 * d + gg)) / ew;   /* rise to the east */
            double dzdy = ((gg + 2 * h + i) - (a + 2 * b + c)) / ns;  /* rise to the south */
            double inv = 1.0 / sqrt(1.0 + dzdx * dzdx + dzdy * dzdy);
            C->nx[o] = (float)(-dzdx * inv);
            C->ny[o] = (float)(dzdy * inv);
            C->nz[o] = (float)inv;
        }
    }
}

ts_status ts_normals(const ts_grid *grid, float *nx, float *ny, float *nz, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!nx || !ny || !nz)
        return ts_fail(err, TS_ERR_ARG, "normal output buffers must not be NULL");
    normals_ctx C = {grid, nx, ny, nz};
    return ts_parallel_for(ts_thread_count(0, grid->height), grid->height, normals_rows, &C, err);
}
