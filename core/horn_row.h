/* One row of Horn normals (core/normals.c), for passes that use the
 * normals of a row at once instead of storing planes (ts_shade_direct_horn). */
#ifndef TS_HORN_ROW_H
#define TS_HORN_ROW_H

#include "terrashade.h"

/* The unit normals of row y of `g` into nx, ny, nz (width floats each),
 * bit for bit as ts_normals writes them. */
void ts_horn_row(const ts_grid *g, int y, float *nx, float *ny, float *nz);

#endif
