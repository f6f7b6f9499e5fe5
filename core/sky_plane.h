/* One horizon plane's sky terms added to the accumulators over a range of
 * cells (core/sky.c): ts_sky_accumulate_model over whole rows, and the
 * pyramid (core/pyramid_horizon.c) over each row span right after it has
 * written it (to its plane, or to a row of scratch where only the sums are
 * wanted), so that the span's horizons, normals and sums are still in the
 * cache. The same loops either way: the sums have the same bits. */
#ifndef TS_SKY_PLANE_H
#define TS_SKY_PLANE_H

#include <stddef.h>

#include "terrashade.h"

typedef struct {
    const float *nx, *ny, *nz, *plane;
    float sa, ca; /* sin, cos of the azimuth */
    float w1, w2; /* 1/n and sin(pi/n)/pi */
    ts_svf_model svf_model;
    float *svf, *sky, *open; /* NULL: not summed */
} ts_sky_plane;

/* The terms of `plane` at `azimuth` (degrees), one of `directions`, into
 * the accumulators of model svf_model (any may be NULL). */
void ts_sky_plane_init(ts_sky_plane *p, const float *nx, const float *ny, const float *nz,
                       const float *plane, double azimuth, int directions,
                       ts_svf_model svf_model, float *svf, float *sky, float *open);

/* The terms of cells [i0, i1) (indices into the planes) added. */
void ts_sky_plane_add(const ts_sky_plane *p, size_t i0, size_t i1);

/* The same with the horizons of those cells read from `plane` (its first
 * float: cell i0's) instead of p's plane, which may then be NULL: the
 * same operations on the same values, so the same bits. */
void ts_sky_plane_add_span(const ts_sky_plane *p, const float *plane, size_t i0, size_t i1);

#endif
