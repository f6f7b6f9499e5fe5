/*
 * Geometry of the parallel sweep lines for one azimuth.
 *
 * The lines step one cell at a time along the major axis u (the grid axis
 * closer to the sweep direction) and advance t cells along the minor axis v
 * per step; neighbouring lines are one cell apart along v. Sample k of the
 * line with intercept b lies at u = u_start + k * u_step, v = b + t * k, so
 * every line shares the integer part fl[k] and fraction fr[k] of t * k:
 * its sample k sits between rows (or columns) b + fl[k] and b + fl[k] + 1.
 * Lines run from the side the azimuth points to, so that the occluders of a
 * sample are the samples before it.
 */
#ifndef TS_LINE_GEOMETRY_H
#define TS_LINE_GEOMETRY_H

#include "terrashade.h"

typedef struct {
    int x_major;            /* 1: u = x (column), v = y (row); 0: u = y, v = x */
    int U, V;               /* grid extent along u and v */
    ptrdiff_t u_stride;     /* element offset of one step along u (signed) */
    ptrdiff_t v_stride;     /* element offset of +1 along v */
    ptrdiff_t origin;       /* element offset of (u_start, v = 0) */
    int u_start, u_step;    /* u of sample k = u_start + k * u_step */
    double t;               /* v advance per step, |t| <= 1 */
    long b_lo, b_hi;        /* intercepts of the lines that touch the grid */
    int *fl;                /* U entries: floor(t * k) */
    float *fr;              /* U entries: t * k - floor(t * k), in [0, 1) */
    double step_m;          /* metres per step when cell_x is constant */
    double *step_row;       /* metres per step by grid row, or NULL */
} ts_line_geom;

/* Set up the lines for the horizon toward `azimuth` (degrees). */
ts_status ts_line_geom_init(ts_line_geom *g, const ts_grid *grid, double azimuth,
                            ts_error *err);
void ts_line_geom_free(ts_line_geom *g);

/* First and last k (inclusive) at which line b's lower row b + fl[k] lies in
 * [0, V-1]; returns 0 if the line misses the grid. */
int ts_line_k_range(const ts_line_geom *g, long b, int *k0, int *k1);

#endif
