/*
 * cm_normals.h - surface normals by Horn's 3x3 method, as gdaldem
 * hillshade, on a grid of float heights (NaN = nodata).
 */
#ifndef TS_CM_NORMALS_H
#define TS_CM_NORMALS_H

#include "cm_prelude.h"

/* Height of cell (x, y) of a W x H grid with row stride `stride`, the
 * centre's where (x, y) is outside the grid or nodata. */
CM_FN float cm_neighbour(const CM_GLOBAL float *z, long stride, int W, int H, int x, int y,
                         float centre)
{
    if (x < 0 || y < 0 || x >= W || y >= H)
        return centre;
    float v = z[(long)y * stride + x];
    return isnan(v) ? centre : v;
}

/* Height of cell (x, y), which lies in the grid (NaN = nodata). */
CM_FN float cm_cell(const CM_GLOBAL float *z, long stride, int x, int y)
{
    return z[(long)y * stride + x];
}

/*
 * Unit normal (east, north, up) of cell (x, y): ew and ns are 8 times the
 * cell's east-west and north-south sizes in metres. NaN where the cell is
 * nodata. At the grid's edge, as gdaldem's -compute_edges (on a grid of at
 * least 2 x 2): the row or column beyond is extrapolated from the two
 * inward, 2 z0 - z1 in float, so that a plane's edge cells have its slope
 * (the centre's height there halved the slope across an edge and cut it to
 * 3/4 along one: session 56's xarray-spatial audit); on the first and last
 * rows the columns beyond are the edge's own (gdaldem's corners, the four
 * cells where a plane's slope along the edge is still halved). A
 * neighbour that is nodata, or extrapolated from nodata, counts as the
 * centre's height, as on a grid of one row or column.
 */
CM_FN void cm_horn_normal(const CM_GLOBAL float *z, long stride, int W, int H, int x, int y,
                          cm_real ew, cm_real ns, float *nx, float *ny, float *nz)
{
    float e = z[(long)y * stride + x];
    if (isnan(e)) {
        *nx = *ny = *nz = NAN;
        return;
    }
    /* w[r][c]: a b c / d e f / g h i, a at the north-west. */
    float w[3][3];
    const int edges = W >= 2 && H >= 2;
    if (edges && (y == 0 || y == H - 1)) {
        const int xs[3] = {x > 0 ? x - 1 : x, x, x < W - 1 ? x + 1 : x};
        const int in = y == 0 ? 1 : H - 2; /* the row inward */
        for (int c = 0; c < 3; c++) {
            const float z0 = cm_cell(z, stride, xs[c], y), z1 = cm_cell(z, stride, xs[c], in);
            w[1][c] = z0;
            w[y == 0 ? 2 : 0][c] = z1;
            w[y == 0 ? 0 : 2][c] = 2.0f * z0 - z1;
        }
    } else if (edges && (x == 0 || x == W - 1)) {
        const int in = x == 0 ? 1 : W - 2; /* the column inward */
        for (int r = 0; r < 3; r++) {
            const float z0 = cm_cell(z, stride, x, y - 1 + r);
            const float z1 = cm_cell(z, stride, in, y - 1 + r);
            w[r][1] = z0;
            w[r][x == 0 ? 0 : 2] = 2.0f * z0 - z1;
            w[r][x == 0 ? 2 : 0] = z1;
        }
    } else {
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                w[r][c] = cm_neighbour(z, stride, W, H, x - 1 + c, y - 1 + r, e);
    }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            w[r][c] = isnan(w[r][c]) ? e : w[r][c];
    cm_real a = w[0][0], b = w[0][1], c = w[0][2], d = w[1][0], f = w[1][2];
    cm_real g = w[2][0], h = w[2][1], i = w[2][2];
    cm_real dzdx = ((c + 2 * f + i) - (a + 2 * d + g)) / ew; /* rise to the east */
    cm_real dzdy = ((g + 2 * h + i) - (a + 2 * b + c)) / ns; /* rise to the south */
    cm_real inv = 1 / sqrt(1 + dzdx * dzdx + dzdy * dzdy);
    *nx = (float)(-dzdx * inv);
    *ny = (float)(dzdy * inv);
    *nz = (float)inv;
}

#endif
