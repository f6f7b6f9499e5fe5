/* Surface normals by Horn's 3x3 method, as gdaldem hillshade
 * (core/cellmath/cm_normals.h). */
#include <math.h>

#include "arg_checks.h"
#include "cellmath/cm_normals.h"
#include "horn_row.h"
#include "parallel.h"
#include "simd_clones.h"
#include "status_internal.h"

typedef struct {
    const ts_grid *g;
    float *nx, *ny, *nz;
} normals_ctx;

/* The neighbour as cm_neighbour has it inside the grid. */
static inline float horn_nb(float v, float centre)
{
    return isnan(v) ? centre : v;
}

/* cm_horn_normal of cells x0..x1-1 of a row whose 3x3 neighbourhoods lie
 * inside the grid (rows up, mid, dn): the same operations in the same order
 * without the bounds checks, so it vectorises and gives the same bits. */
TS_SIMD_CLONES
static void horn_interior(const float *restrict up, const float *restrict mid,
                          const float *restrict dn, int x0, int x1, double ew, double ns,
                          float *restrict nx, float *restrict ny, float *restrict nz)
{
    for (int x = x0; x < x1; x++) {
        float e = mid[x];
        double a = horn_nb(up[x - 1], e), b = horn_nb(up[x], e), c = horn_nb(up[x + 1], e);
        double d = horn_nb(mid[x - 1], e), f = horn_nb(mid[x + 1], e);
        double g = horn_nb(dn[x - 1], e), h = horn_nb(dn[x], e), i = horn_nb(dn[x + 1], e);
        double dzdx = ((c + 2 * f + i) - (a + 2 * d + g)) / ew;
        double dzdy = ((g + 2 * h + i) - (a + 2 * b + c)) / ns;
        double inv = 1 / sqrt(1 + dzdx * dzdx + dzdy * dzdy);
        int nodata = isnan(e);
        nx[x] = nodata ? NAN : (float)(-dzdx * inv);
        ny[x] = nodata ? NAN : (float)(dzdy * inv);
        nz[x] = nodata ? NAN : (float)inv;
    }
}

void ts_horn_row(const ts_grid *g, int y, float *nx, float *ny, float *nz)
{
    const int W = g->width, H = g->height;
    double ew = 8.0 * ts_grid_cell_x(g, y), ns = 8.0 * g->cell_y;
    int inner = y > 0 && y < H - 1 && W > 2;
    for (int x = 0; x < W; x++) {
        if (inner && x == 1) {
            const float *mid = g->z + (ptrdiff_t)y * g->stride;
            horn_interior(mid - g->stride, mid, mid + g->stride, 1, W - 1, ew, ns, nx, ny, nz);
            x = W - 2;
            continue;
        }
        cm_horn_normal(g->z, g->stride, W, H, x, y, ew, ns, &nx[x], &ny[x], &nz[x]);
    }
}

static void normals_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const normals_ctx *C = ctx;
    for (int y = (int)y0; y < (int)y1; y++) {
        size_t o = (size_t)y * C->g->width;
        ts_horn_row(C->g, y, C->nx + o, C->ny + o, C->nz + o);
    }
}

ts_status ts_normals_threads(const ts_grid *grid, int threads, float *nx, float *ny, float *nz,
                             ts_error *err)
{
    ts_status st = ts_check_normals_args(grid, nx, ny, nz, err);
    if (st != TS_OK)
        return st;
    normals_ctx C = {grid, nx, ny, nz};
    return ts_parallel_for_ranges(ts_thread_count(threads, grid->height), grid->height,
                                  TS_ROWS_GRAIN, normals_rows, &C, err);
}

ts_status ts_normals(const ts_grid *grid, float *nx, float *ny, float *nz, ts_error *err)
{
    return ts_normals_threads(grid, 0, nx, ny, nz, err);
}
