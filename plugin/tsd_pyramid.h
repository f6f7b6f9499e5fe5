/*
 * tsd_pyramid.h - HORIZON_METHOD=pyramid in the driver: the checks of its
 * options, the memory of its pyramid, and the horizon planes of the
 * products read from the pyramid (core ts_pyramid_*) instead of the
 * sweep. The pyramid runs on the C backend: BACKEND=opencl falls back to
 * C for it, saying why. No GDAL.
 */
#ifndef TSD_PYRAMID_H
#define TSD_PYRAMID_H

#include "tsd_compute.h"
#include "tsd_options.h"

#ifdef __cplusplus
extern "C" {
#endif

/** HORIZON_METHOD, PYRAMID_LEVEL_STEP and PYRAMID_OFFSET against the
 * product and each other: 0, or -1 with a sentence in msg. */
int tsd_options_check_pyramid(const tsd_options *o, char *msg, size_t msg_size);

/** Bytes of the pyramid of a width x height DEM under options o, and of the
 * `planes` horizon planes its run holds at once, less the one the
 * product's count already has for the sweep (so -1 plane where it holds
 * none); 0 with HORIZON_METHOD=exact. */
double tsd_pyramid_bytes(const tsd_options *o, int width, int height, int planes);

/** tsd_compute_stream with pyramid horizons: the DIRECTIONS planes, one
 * at a time, to `add`, for the products that integrate the sky over the
 * directions (svf, sky, openness, envlight, shade's sky term): read as the
 * maximum over the levels (S&N section 6, their environment light), as
 * accurate there as the B-spline and twice as fast (docs/methods.md). */
ts_status tsd_pyramid_stream(const tsd_compute_ctx *c, const ts_grid *g, tsd_plane_fn add,
                             void *user);

/** tsd_pyramid_stream for the sky products (svf of either model, sky,
 * openness): each plane's terms added to sky's accumulators as the rows
 * are done (ts_pyramid_horizons_sky), the same sums as tsd_pyramid_stream
 * to ts_sky_accumulate_model, bit for bit. */
ts_status tsd_pyramid_sky(const tsd_compute_ctx *c, const ts_grid *g, const ts_pyramid_sky *sky);

/** The DIRECTIONS planes of PRODUCT=horizon into out: the B-spline in log
 * distance and its maximum (S&N eq. 4-5). */
ts_status tsd_pyramid_planes(const tsd_compute_ctx *c, const ts_grid *g, float *out);

/** The B-spline horizons (as tsd_pyramid_planes) at `count` given azimuths
 * (degrees), into planes[0 .. count - 1]: METHOD=sh's key light. */
ts_status tsd_pyramid_planes_at(const tsd_compute_ctx *c, const ts_grid *g, int count,
                                const double *azimuths, float **planes);

#ifdef __cplusplus
}
#endif

#endif
