/*
 * The passes of one step of a lockstep block of sweep lines (the unbounded
 * sweep's sweep_block, core/horizon_sweep.c) that run over all the block's
 * lines at once: at step k, line bs + j samples between rows (or columns)
 * i0 + j and i0 + j + 1 (i0 = bs + fl[k]), all with the same fraction, so
 * the lines read neighbouring cells; and each written cell's far field is
 * its own ray sampled at the occluders the lines' hulls found, the ray
 * samples being gathers. Only the hull itself stays scalar, line by line.
 * Both passes compute, per line, exactly what the line-by-line code did.
 */
#ifndef TS_LANE_PASSES_H
#define TS_LANE_PASSES_H

#include <stddef.h>

#include "cellmath/cm_near_field.h"
#include "line_geometry.h"

/* Step k's samples of lines j0..j1 (rows i0 + j, all on the grid): the
 * cell below (hc), the one after (hn, NaN where none) and the height on
 * the line (hs, NaN off the grid or at nodata), as ts_line_sample_at. */
void ts_lane_sample(const ts_line_geom *G, const float *z, int k, int i0, int j0, int j1,
                    float *hc, float *hn, float *hs);

/* Step k's distances of lines j0..j1 on steps of one length: dist[j] =
 * (k - k0[j]) x step, one rounding each (k0 NULL: k x step for all). With
 * AVX-512 they are written eight lines a store from line j0 / 8 x 8 up to
 * the vector holding j1, the lines around j0..j1 taking values of no use
 * (dist and k0 must have room up to line j1 / 8 x 8 + 7), so that the
 * passes' loads of the same eight lines read one whole store back, which
 * the CPU forwards (four 16-byte stores, it could not). */
void ts_lane_distances(int k, const int *k0, double step, int j0, int j1, double *dist);

/* Far-field occluders of a step's cells, per line j: their steps (< 0:
 * none) and distances from the cell, from the line below (lo) and the
 * cell's own line (hi). */
typedef struct {
    int *lo_k, *hi_k;
    float *lo_dd, *hi_dd;
} ts_lane_occluders;

/* Where an occluder lies where the cell's own ray cannot be sampled (off
 * the grid or on nodata there; cm_ray_lost samples the ray's steps up to
 * it): the grid as the rays see it, the curvature coefficient and the
 * distance cap (metres, 0 = none) in double, as the near field takes them,
 * the far-only sweep's threshold (metres; 0 = the near field's steps
 * instead: the ray's steps count from the first at least this far), and
 * scratch of j1 + 1 ints, clear between calls. */
typedef struct {
    const cm_ray_grid *ray;
    double c, cap, from;
    int *flags;
} ts_lane_lost;

/* The far-field slope of cells (k, i0 + j), j0 <= j <= j1, at heights
 * hc[j] into out[(j - j0) * ostride]: the larger of the cell's own ray sampled at
 * the two occluders (the second skipped when it is the first's step;
 * either skipped within the near field, at most `near` steps back; at one
 * the ray cannot be sampled at, cm_ray_lost beyond the near field, or
 * beyond lost->from metres in the far-only sweep, whose near is 0), -inf
 * when none counts, NaN where hc is nodata; cf is the curvature
 * coefficient; slope: scratch of j1 + 1 floats. */
void ts_lane_far_field(const ts_line_geom *G, const float *z, float cf, int near, int k, int i0,
                       int j0, int j1, const float *hc, const ts_lane_occluders *occ,
                       const ts_lane_lost *lost, float *slope, float *out, ptrdiff_t ostride);

#endif
