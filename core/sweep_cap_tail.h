/*
 * What the near field and the lines of a horizon sweep leave out within a
 * maximum distance, solved exactly on each cell's own ray (a capped horizon
 * is often near, often at the distance itself).
 */
#ifndef TS_SWEEP_CAP_TAIL_H
#define TS_SWEEP_CAP_TAIL_H

#include "line_geometry.h"

/* Raise orow[x] (slopes, row y of the grid, metres per step `step`) to the
 * exact horizon over the stretches of each cell's ray within `cap` metres
 * that the near field and the lines do not cover; c: curvature coefficient.
 * Cells whose zrow[x] is nodata are left alone. */
void ts_cap_tail(const ts_line_geom *G, const ts_grid *grid, double cap, double c, int y,
                 const float *zrow, float *orow, double step);

#endif
