/* Brute-force ray-marching horizon oracle: slow, simple, independent of the
 * core's sweeps, so that the sweeps can be held against it. */
#ifndef TS_ORACLE_H
#define TS_ORACLE_H

#include "terrashade.h"

/* Bilinear height at grid position (x, y) in [0, w-1] x [0, h-1]; the
 * weights are renormalised over the valid (non-NaN) corners; NaN if all
 * four corners are nodata. */
double oracle_bilinear(const ts_grid *g, double x, double y);

/* The same; with `strict`, NaN as soon as a corner of positive weight is
 * nodata (the other reasonable reading of "nodata is skipped"). */
double oracle_bilinear_ex(const ts_grid *g, double x, double y, int strict);

/* East-west cell size at fractional row y: linear between rows. */
double oracle_cell_x(const ts_grid *g, double y);

/* Horizon angle in degrees from the centre of cell (x, y) towards `azimuth`
 * (degrees clockwise from north): march in steps of at most a quarter of
 * the smallest cell size (finer near the cell, and stopping on every row
 * and column line crossed), direction recomputed in metres at every step,
 * until
 * the ray leaves the grid or passes opts->max_distance (0 = unbounded).
 * Uses opts->curvature, refraction and max_distance only. NaN if the cell
 * is nodata, -90 if no valid sample lies along the ray. */
double oracle_horizon(const ts_grid *g, int x, int y, double azimuth,
                      const ts_horizon_opts *opts);

/* The same, with the strict nodata rule of oracle_bilinear_ex if `strict`,
 * also giving the distance (metres) of the highest sample and the distance
 * at which the ray left the grid (INFINITY if it did not: nodata cell, or
 * stopped by max_distance). */
double oracle_horizon_ex(const ts_grid *g, int x, int y, double azimuth,
                         const ts_horizon_opts *opts, int strict,
                         double *d_best, double *d_edge);

#endif
