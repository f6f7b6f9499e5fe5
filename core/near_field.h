/*
 * Near field of the horizon: the first few cells of a cell's own ray,
 * evaluated exactly on the bilinear surface through the cell centres.
 *
 * Close occluders are where the sweep's line interpolation would cost most
 * (a lateral offset of a fraction of a cell, at a distance of one cell, is
 * degrees). Along a straight ray the bilinear surface is quadratic in the
 * distance s inside each cell patch, so the maximum of (h(s) - h0) / s per
 * patch has a closed form.
 */
#ifndef TS_NEAR_FIELD_H
#define TS_NEAR_FIELD_H

#include "cellmath/cm_near_field.h"
#include "line_geometry.h"

/* Piece n of the ray, [piece_sa[n], piece_sb[n]] steps, lies in the patch
 * with corner (k + piece_du[n], i + piece_dv[n]). */
typedef struct {
    double t;                              /* v per step, as the geometry */
    int npieces;
    int piece_du[TS_NEAR_MAX_PIECES], piece_dv[TS_NEAR_MAX_PIECES];
    double piece_sa[TS_NEAR_MAX_PIECES], piece_sb[TS_NEAR_MAX_PIECES];
    /* Element offsets from the cell, for the vectorised interior pass:
     * corners 00, 10, 01, 11 of each piece. */
    ptrdiff_t piece_off[TS_NEAR_MAX_PIECES][4];
    /* The pieces' extent from the cell: every piece's patch is on the
     * grid where k + du_min >= 0 and dv_min <= -i, i + dv_max <= V - 1. */
    int du_min, dv_min, dv_max;
} ts_near_plan;

/* The pieces for the geometry's direction. */
void ts_near_plan_init(ts_near_plan *p, const ts_line_geom *g);

/* Largest horizon slope (with curvature term -c d) from cell (k, i) at
 * height h over the near field, step = metres per step, cap = the maximum
 * distance in metres (0 = none); -inf if none. *left is set when the ray
 * leaves the grid inside the near field. */
float ts_near_field(const ts_near_plan *p, const ts_line_geom *g, const float *z, int k,
                    int i, float h, double step, double c, double cap, int *left);

/* Largest horizon slope from cell (k, i) at height h over its ray between
 * s_from and s_to steps (exclusive, inclusive) on the exact bilinear
 * surface, patch by patch: the brute force the near field is a table-driven
 * case of. -inf if nothing there. */
float ts_ray_exact(const ts_line_geom *g, const float *z, int k, int i, float h, double s_from,
                   double s_to, double step, double c);

/*
 * Near field of the interior cells x0 <= x < x1 of one grid row (their
 * pieces all on the grid), all with the same metres per step. zrow points
 * at the row's first height; out[x] receives max(out[x], near field) (the
 * far field is already there). Cells whose near field touches nodata or
 * an infinity are redone with ts_near_field's double arithmetic,
 * vectorised over runs of them; the same bits as ts_near_field.
 * scratch: TS_NEAR_ROW_SCRATCH(x1) floats.
 */
#define TS_NEAR_ROW_SCRATCH(x1) (7 * (size_t)(x1) + 160)
void ts_near_row(const ts_near_plan *p, const float *zrow, int x0, int x1, double step,
                 double c, float *out, float *scratch);

/*
 * Near field of the cells of row y outside [xa, xb) (the interior that
 * ts_near_row does), cap as ts_near_field: out[x] = the near field where
 * the ray leaves the grid inside it, else max(out[x], near field). Cells
 * take the vectorised form of ts_near_field's double arithmetic in runs:
 * of cells whose pieces all lie on the grid, and of at least 8 cells whose
 * rays leave the grid at the same piece (the pieces before it); the others
 * take ts_near_field itself; the same bits either way. scratch: 3 W floats
 * (TS_NEAR_ROW_SCRATCH(W) is more).
 */
void ts_near_edges(const ts_near_plan *p, const ts_line_geom *g, const float *z,
                   const float *zrow, int y, int xa, int xb, int W, double step, double c,
                   double cap, float *out, float *scratch);

#endif
