/* The DEM grid: allocation and validation. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "status_internal.h"

/* A cell size the sweeps can take (TS_CELL_MIN_M .. TS_CELL_MAX_M metres;
 * NaN fails it). */
static int cell_ok(double m)
{
    return m >= TS_CELL_MIN_M && m <= TS_CELL_MAX_M;
}

ts_status ts_grid_create(ts_grid *grid, int width, int height, double cell_x,
                         double cell_y, ts_error *err)
{
    if (!grid)
        return ts_fail(err, TS_ERR_ARG, "grid is NULL");
    memset(grid, 0, sizeof *grid);
    if (width < 1 || height < 1 || width > TS_MAX_SIDE || height > TS_MAX_SIDE)
        return ts_fail(err, TS_ERR_ARG,
                       "grid size must be between 1 and %d cells per side, got %d x %d",
                       TS_MAX_SIDE, width, height);
    if (!cell_ok(cell_x) || !cell_ok(cell_y))
        return ts_fail(err, TS_ERR_ARG, "cell size must be %g to %g m, got %g x %g",
                       TS_CELL_MIN_M, TS_CELL_MAX_M, cell_x, cell_y);
    size_t n = (size_t)width * (size_t)height;
    if (n > SIZE_MAX / sizeof(float))
        return ts_fail(err, TS_ERR_NOMEM, "grid of %d x %d cells is too large",
                       width, height);
    grid->z = calloc(n, sizeof(float));
    if (!grid->z)
        return ts_fail(err, TS_ERR_NOMEM,
                       "cannot allocate a grid of %d x %d cells (%zu MiB)", width,
                       height, n * sizeof(float) >> 20);
    grid->width = width;
    grid->height = height;
    grid->stride = width;
    grid->cell_x = cell_x;
    grid->cell_y = cell_y;
    grid->owns_memory = 1;
    return ts_ok(err);
}

ts_status ts_grid_set_row_spacing(ts_grid *grid, const double *cell_x_row,
                                  ts_error *err)
{
    if (!grid || !cell_x_row)
        return ts_fail(err, TS_ERR_ARG, "grid or row spacing is NULL");
    if (!grid->owns_memory)
        return ts_fail(err, TS_ERR_ARG,
                       "row spacing can only be set on a grid made by ts_grid_create");
    for (int y = 0; y < grid->height; y++)
        if (!cell_ok(cell_x_row[y]))
            return ts_fail(err, TS_ERR_ARG,
                           "east-west cell size of row %d must be %g to %g m, got %g", y,
                           TS_CELL_MIN_M, TS_CELL_MAX_M, cell_x_row[y]);
    double *copy = malloc((size_t)grid->height * sizeof *copy);
    if (!copy)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate row spacing");
    memcpy(copy, cell_x_row, (size_t)grid->height * sizeof *copy);
    free(grid->cell_x_row);
    grid->cell_x_row = copy;
    return ts_ok(err);
}

void ts_grid_free(ts_grid *grid)
{
    if (!grid)
        return;
    if (grid->owns_memory) {
        free(grid->z);
        free(grid->cell_x_row);
    }
    memset(grid, 0, sizeof *grid);
}

ts_status ts_grid_validate(const ts_grid *grid, ts_error *err)
{
    if (!grid)
        return ts_fail(err, TS_ERR_ARG, "grid is NULL");
    if (!grid->z)
        return ts_fail(err, TS_ERR_ARG, "grid has no height data");
    if (grid->width < 1 || grid->height < 1 || grid->width > TS_MAX_SIDE ||
        grid->height > TS_MAX_SIDE)
        return ts_fail(err, TS_ERR_ARG,
                       "grid size must be between 1 and %d cells per side, got %d x %d",
                       TS_MAX_SIDE, grid->width, grid->height);
    if (grid->stride < grid->width)
        return ts_fail(err, TS_ERR_ARG, "grid stride %td is smaller than its width %d",
                       grid->stride, grid->width);
    if (!cell_ok(grid->cell_x) || !cell_ok(grid->cell_y))
        return ts_fail(err, TS_ERR_ARG, "cell size must be %g to %g m, got %g x %g",
                       TS_CELL_MIN_M, TS_CELL_MAX_M, grid->cell_x, grid->cell_y);
    if (grid->cell_x_row)
        for (int y = 0; y < grid->height; y++)
            if (!cell_ok(grid->cell_x_row[y]))
                return ts_fail(err, TS_ERR_ARG,
                               "east-west cell size of row %d must be %g to %g m, got %g", y,
                               TS_CELL_MIN_M, TS_CELL_MAX_M, grid->cell_x_row[y]);
    return ts_ok(err);
}
