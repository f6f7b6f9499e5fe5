/*
 * A cheap upper bound of a capped sweep's exact ray stretches
 * (sweep_cap_tail.c), for a whole grid row at once.
 *
 * Along a cell's ray a stretch [sa, sb] within one step crosses at most two
 * bilinear patches; on each the height is a quadratic in the distance, at
 * most its chord plus, where it is concave (gamma = X t < 0), -gamma
 * len^2 / 4; the slope to a chord is largest at one of its ends. The
 * patches, the ends' weights and the chord terms are the same for every
 * cell of a row (they depend on the direction and the stretch only), so the
 * bound is a fixed stencil that a loop over the row vectorises. It carries
 * a margin far above the rounding of ts_ray_exact, so a stretch whose bound
 * is below the horizon found so far cannot raise it: skipping it leaves the
 * result bit for bit the same. A stretch it lets through is solved from the
 * same stencil (ts_cap_stencil_exact) where its pieces are provably those
 * that ts_ray_exact finds for every cell of the row, with the same
 * operations, so again with the same bits.
 */
#ifndef TS_CAP_TAIL_BOUND_H
#define TS_CAP_TAIL_BOUND_H

#include <math.h>

#include "cellmath/cm_near_field.h"
#include "line_geometry.h"

typedef struct {
    int npieces;              /* 1 or 2; 0: no stencil (the stretch is empty) */
    ptrdiff_t off[2][4];      /* corners 00, 10, 01, 11 of each piece's patch */
    float w[2][2][4];         /* corner weights of each piece's two ends */
    float bulge[2];           /* t len^2 / 4 of each piece */
    float inv[2][2];          /* 1 / (distance in metres) of each piece's ends */
    float drop;               /* c sa step: the curvature term at sa */
    /* for ts_cap_stencil_exact: */
    int exact;                /* the pieces are ts_ray_exact's for every cell */
    double s[2][2];           /* each piece's ends, in steps */
    double a0, b0[2];         /* the cell in each piece's patch */
    double t, step, c;        /* v per step (0 along a grid line), metres per step,
                                 curvature coefficient */
    int jback;                /* steps back of the patches' farther column */
    int vlo, vhi;             /* v offsets of the rows read, from the cell's */
} ts_cap_stencil;

/* The stencil of stretch [sa, sb] (1 <= sa < sb <= floor(sa) + 1) of the
 * rays in direction G, at `step` metres per step, curvature coefficient c
 * (>= 0); no pieces when the stretch is empty. */
void ts_cap_stencil_init(ts_cap_stencil *s, const ts_line_geom *G, double sa, double sb,
                         double step, double c);

/* The cells x of grid row y whose stencil lies on the grid: [*xa, *xb). */
void ts_cap_stencil_range(const ts_cap_stencil *s, const ts_line_geom *G, int width, int y,
                          int *xa, int *xb);

/* bound[x] for xa <= x < xb of the row whose heights start at zrow: an
 * upper bound of the slope to the stretch (NaN where nodata is near);
 * flag: scratch of the same extent. */
void ts_cap_stencil_row(const ts_cap_stencil *s, const float *zrow, int xa, int xb,
                        float *bound, float *flag);

/* The stretch's slope from the cell at x of the row whose heights start at
 * zrow, bit for bit what ts_ray_exact returns (same pieces, same
 * operations), for a cell whose bound ts_cap_stencil_row found finite (on
 * the grid, no nodata) of a stencil with s->exact set. */
static inline float ts_cap_stencil_exact(const ts_cap_stencil *s, const float *zrow, int x)
{
    const double L = s->step, c = s->c, a0 = s->a0, t = s->t;
    const double h = zrow[x];
    double best = -INFINITY;
    for (int p = 0; p < s->npieces; p++) {
        const float *zz = zrow + x;
        double h00 = zz[s->off[p][0]], h10 = zz[s->off[p][1]];
        double h01 = zz[s->off[p][2]], h11 = zz[s->off[p][3]];
        double alpha, beta, gamma;
        cm_patch_poly(h00, h10 - h00, h01 - h00, h11 - h10 - h01 + h00, a0, s->b0[p], t, &alpha,
                      &beta, &gamma);
        double m = cm_piece_max(alpha - h, beta, gamma, s->s[p][0], s->s[p][1], L, c);
        best = m > best ? m : best;
    }
    return (float)best;
}

/* Whether ts_ray_exact finds nothing on the stretch (-inf) for cell (k, i)
 * of a stencil with s->exact set, because the ray leaves the grid in its
 * first piece. */
static inline int ts_cap_stencil_off_grid(const ts_cap_stencil *s, const ts_line_geom *G, int k,
                                          int i)
{
    int r0 = i - (int)s->b0[0];
    return s->exact && (k < s->jback || r0 < 0 || r0 + (s->t != 0) > G->V - 1);
}

#endif
