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

#include <math.h>
#include <stddef.h>

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
    int *ray_o;             /* U entries: floor(-t * dk), the v offset of a ray */
    float *ray_f;           /* dk steps back, and its fraction, as cm_ray_slope */
    double step_m;          /* metres per step when cell_x is constant */
    double *step_row;       /* metres per step by grid row, or NULL */
    int anchored;           /* the grid is a window (ts_grid_origin): */
    long k_anchor;          /* sample k is step k + k_anchor of the whole DEM's lines */
} ts_line_geom;

/* Set up the lines for the horizon toward `azimuth` (degrees, any finite
 * value; taken modulo 360). TS_ERR_ARG for a non-finite azimuth. */
ts_status ts_line_geom_init(ts_line_geom *g, const ts_grid *grid, double azimuth,
                            ts_error *err);
void ts_line_geom_free(ts_line_geom *g);

/* The far-only sweep's fractions (core/sweep_far.c): a line's or a
 * ray's fraction within `snap` of a cell (t a rational, or a hair off
 * +/-1, leaves ~1e-16 rather than 0) is put on the cell, so that a line or
 * a cell's ray on the grid's last row or column keeps its sample there. */
void ts_line_geom_snap(ts_line_geom *g, float snap);

/* The shortest and longest metres per step over the grid's `height` rows.
 * No two samples of a line (nor a ray on the grid) are farther apart than
 * longest * U: a maximum distance beyond that caps nothing. */
void ts_line_geom_step_range(const ts_line_geom *g, int height, double *shortest,
                             double *longest);

/* First and last k (inclusive) at which line b's lower row b + fl[k] lies in
 * [0, V-1]; returns 0 if the line misses the grid. */
int ts_line_k_range(const ts_line_geom *g, long b, int *k0, int *k1);

/* The last step k >= k1 at which line b's lower row b + fl[k] is at least
 * -1: where a line that leaves the grid across its first row still
 * answers the far-side queries of row 0's cells (cm_line_k_leaving). */
int ts_line_k_leaving(const ts_line_geom *g, long b, int k1);

/* A sweep's results per step of the line before the current one (the far
 * side of the cells between them) and of the current line. */
typedef struct {
    void *prev, *cur;          /* U entries each, of the sweep's own type */
    int prev_k0, prev_k1;      /* steps of the line before; k0 > k1: none */
} ts_line_pair;

/* Start line b: the current line's results become the previous ones and
 * *k0, *k1 receive its steps; returns 0 when it misses the grid. */
static inline int ts_line_pair_next(ts_line_pair *lp, const ts_line_geom *G, long b,
                                    int *k0, int *k1)
{
    void *t = lp->prev;
    lp->prev = lp->cur;
    lp->cur = t;
    if (!ts_line_k_range(G, b, k0, k1)) {
        lp->prev_k0 = 1;
        lp->prev_k1 = 0;
        return 0;
    }
    lp->prev_k0 = *k0;
    lp->prev_k1 = *k1;
    return 1;
}

/* Element offsets of sample (k, row v) in a width-wide output plane laid
 * out like the grid: origin + k * u_stride + v * v_stride. */
void ts_line_out_strides(const ts_line_geom *g, int width, ptrdiff_t *origin,
                         ptrdiff_t *u_stride, ptrdiff_t *v_stride);

/* Sample k of a line: the cell below it and the one after, and the height
 * on the line between them. */
typedef struct {
    int i;             /* row (or column) b + fl[k] */
    float F;           /* fraction toward i + 1 */
    ptrdiff_t p;       /* element offset of cell (k, i) in the grid */
    int has_next;      /* F > 0 and i + 1 is on the grid */
    int inside;        /* the sample is on the grid (F == 0 or has_next) */
    float hc, hn;      /* heights of cells i and i + 1 (NaN if no next) */
    float hs;          /* height on the line; NaN off the grid or at nodata */
} ts_line_sample;

/* Metres a step of the ray from cell (k, i) (i: the row or column across
 * the lines): its grid row's on a geographic grid, else the grid's. */
static inline double ts_line_cell_step(const ts_line_geom *G, int k, int i)
{
    return G->step_row ? G->step_row[G->x_major ? i : G->u_start + k * G->u_step] : G->step_m;
}

/*
 * Sample k of line b, and the distance d (metres) along the line from its
 * first sample k0 to it: d is advanced from sample k - 1 (pass k0 first,
 * then every k in order). Fractions below `snap` count as 0.
 */
static inline void ts_line_sample_at(const ts_line_geom *G, const float *z, long b, int k,
                                     int k0, float snap, double *d, ts_line_sample *s)
{
    s->i = (int)(b + G->fl[k]);
    s->F = G->fr[k] < snap ? 0.0f : G->fr[k];
    s->p = G->origin + (ptrdiff_t)k * G->u_stride + (ptrdiff_t)s->i * G->v_stride;
    s->has_next = s->F > 0.0f && s->i + 1 < G->V;
    s->hc = z[s->p];
    s->hn = s->has_next ? z[s->p + G->v_stride] : (float)NAN;
    if (G->step_row) {
        if (k > k0) {
            int row = G->x_major ? s->i : G->u_start + k * G->u_step;
            *d += G->step_row[row];
        }
    } else if (G->anchored) {
        *d = (double)(k + G->k_anchor) * G->step_m; /* as on the whole DEM */
    } else {
        *d = (double)(k - k0) * G->step_m;
    }
    s->inside = s->F == 0.0f || s->has_next;
    /* NaN when either cell is nodata: the sample is no occluder. */
    s->hs = !s->inside ? (float)NAN : s->F == 0.0f ? s->hc : s->hc + s->F * (s->hn - s->hc);
}

#endif
