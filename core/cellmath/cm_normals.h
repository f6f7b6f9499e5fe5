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

/*
 * Unit normal (east, north, up) of cell (x, y): ew and ns are 8 times the
 * cell's east-west and north-south sizes in metres. NaN where the cell is
 * nodata; missing neighbours count as the centre's height.
 */
CM_FN void cm_horn_normal(const CM_GLOBAL float *z, long stride, int W, int H, int x, int y,
                          cm_real ew, cm_real ns, float *nx, float *ny, float *nz)
{
    float e = z[(long)y * stride + x];
    if (isnan(e)) {
        *nx = *ny = *nz = NAN;
        return;
    }
    /* a b c / d e f / g h i, a at the north-west. */
    cm_real a = cm_neighbour(z, stride, W, H, x - 1, y - 1, e);
    cm_real b = cm_neighbour(z, stride, W, H, x, y - 1, e);
    cm_real c = cm_neighbour(z, stride, W, H, x + 1, y - 1, e);
    cm_real d = cm_neighbour(z, stride, W, H, x - 1, y, e);
    cm_real f = cm_neighbour(z, stride, W, H, x + 1, y, e);
    cm_real g = cm_neighbour(z, stride, W, H, x - 1, y + 1, e);
    cm_real h = cm_neighbour(z, stride, W, H, x, y + 1, e);
    cm_real i = cm_neighbour(z, stride, W, H, x + 1, y + 1, e);
    cm_real dzdx = ((c + 2 * f + i) - (a + 2 * d + g)) / ew; /* rise to the east */
    cm_real dzdy = ((g + 2 * h + i) - (a + 2 * b + c)) / ns; /* rise to the south */
    cm_real inv = 1 / sqrt(1 + dzdx * dzdx + dzdy * dzdy);
    *nx = (float)(-dzdx * inv);
    *ny = (float)(dzdy * inv);
    *nz = (float)inv;
}

#endif
