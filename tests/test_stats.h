/* Error statistics of a horizon plane against the oracle. */
#ifndef TS_TEST_STATS_H
#define TS_TEST_STATS_H

#include "terrashade.h"

typedef struct {
    long n;           /* cells compared (valid in the DEM) */
    long nodata_bad;  /* cells where NaN-ness of output and DEM differ */
    long minus90_bad; /* cells where exactly one side says -90 */
    double median, p99, max; /* absolute error, degrees */
    long over;        /* cells with an error above 0.5 degrees */
    long edge_n;      /* cells whose error the edge allowance reduced */
    long nodata_n;    /* cells whose error the nodata allowance reduced */
    int axis;         /* the ray runs along a grid axis */
} tstat;

/* Compare `plane` (width*height, row stride = width) with oracle_horizon on
 * every `step`-th cell of every `step`-th row; print one line with `label`
 * and the worst cells, and return the statistics. The -90 cells count in
 * the error like any other (their error is large).
 *
 * The error of a cell is its distance to an interval of oracle answers,
 * normally one value; two allowances widen it, and the cells where they
 * changed the error are counted and printed:
 *  - edge: on a ray that is not along an axis, the sweep's lines sample the
 *    terrain once per step (one cell along the major axis), so by
 *    construction they cannot see the last partial step before the ray
 *    leaves the grid; the oracle cut one step before the edge is allowed;
 *  - nodata: next to nodata, "skipped" can mean renormalising the bilinear
 *    weights over the valid corners (the oracle) or dropping every sample
 *    that touches nodata (strict); both oracles are allowed. */
tstat tstat_vs_oracle(const char *label, const ts_grid *g, const float *plane,
                      double azimuth, const ts_horizon_opts *opts, int step);

/* Assert median <= 0.05 deg, p99 <= 0.5 deg and consistent nodata; on a
 * ray along a grid axis also max <= 0.001 deg: there the sweep's samples
 * are the cell centres, the bilinear surface between them is linear, so
 * the oracle's answer is the sweep's, exactly, nodata included. */
void tstat_check(const tstat *s, const char *label);

#endif
