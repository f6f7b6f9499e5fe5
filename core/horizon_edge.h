/* The world beyond the DEM edge applied row by row, for a sweep that
 * raises each row of its horizon plane as it finishes it
 * (ts_horizon_edge_apply does every row after the fact; the same values). */
#ifndef TS_HORIZON_EDGE_H
#define TS_HORIZON_EDGE_H

#include "terrashade.h"

/* The ray toward an azimuth in cells per metre (the direction of
 * ts_line_geom_init: the central row's cell size, the larger DEM's for a
 * window), as the metres per cell
 * it advances along x and y (infinite along an axis it does not cross). */
typedef struct {
    double mx, my; /* metres per cell along x, y; INFINITY = parallel */
    int east, south; /* 1: toward +x, +y */
} ts_edge_ray;

/* What the rows of one plane need (ts_horizon_edge_apply, ts_horizon_edge_sun). */
typedef struct {
    const ts_grid *grid;
    const ts_horizon_opts *opts;
    ts_edge_ray ray;
    double reach;         /* max_distance, or INFINITY */
    double c;             /* drop per square metre: (1 - k) / 2R, or 0 */
    float *plane;         /* the horizons, or the sun's visibility */
    double sun_elevation; /* ts_horizon_edge_sun */
    int skip_nonneg;      /* nonpositive_moot: cells of height >= 0 left as they are */
} ts_edge_job;

/* The job of ts_horizon_edge_apply's rows for the plane of one azimuth;
 * returns 0 where the edge mode leaves every horizon as it is. */
int ts_edge_rows_init(ts_edge_job *j, const ts_grid *grid, double azimuth,
                      const ts_horizon_opts *opts, float *plane);

/* Row y of the job's plane, in degrees, with the world beyond the edge. */
void ts_edge_row(const ts_edge_job *j, int y);

/* The cells [x0, x1) of row y alone, as ts_edge_row does them (each cell
 * on its own: a row done span by span has the same values). */
void ts_edge_span(const ts_edge_job *j, int y, int x0, int x1);

/* The same with row y's horizons in `row` (its cell x at row[x]) instead
 * of the job's plane, which may then be NULL. */
void ts_edge_span_row(const ts_edge_job *j, int y, float *row, int x0, int x1);

#endif
