/* Surface normals by Horn's 3x3 method, as gdaldem hillshade
 * (core/cellmath/cm_normals.h). */
#include <math.h>

#include "arg_checks.h"
#include "cellmath/cm_normals.h"
#include "parallel.h"
#include "status_internal.h"

typedef struct {
    const ts_grid *g;
    float *nx, *ny, *nz;
} normals_ctx;

static void normals_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const normals_ctx *C = ctx;
    const ts_grid *g = C->g;
    for (int y = (int)y0; y < (int)y1; y++) {
        double ew = 8.0 * ts_grid_cell_x(g, y), ns = 8.0 * g->cell_y;
        for (int x = 0; x < g->width; x++) {
            size_t o = (size_t)y * g->width + x;
            cm_horn_normal(g->z, g->stride, g->width, g->height, x, y, ew, ns, &C->nx[o],
                           &C->ny[o], &C->nz[o]);
        }
    }
}

ts_status ts_normals(const ts_grid *grid, float *nx, float *ny, float *nz, ts_error *err)
{
    ts_status st = ts_check_normals_args(grid, nx, ny, nz, err);
    if (st != TS_OK)
        return st;
    normals_ctx C = {grid, nx, ny, nz};
    return ts_parallel_for(ts_thread_count(0, grid->height), grid->height, normals_rows, &C, err);
}
