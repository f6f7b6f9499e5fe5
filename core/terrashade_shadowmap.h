/*
 * terrashade_shadowmap.h - shadow mapping with percentage-closer filtering
 * (the shadow-mapping article in docs/algorithms.md; METHOD=shadowmap).
 *
 * An approximation of the exact visible fraction of the light's disk
 * (ts_disk_fraction over the horizon at the light's azimuth), built for
 * speed: the DEM's triangles are rendered into an orthographic depth map
 * seen from the light, SHADOWMAP_SCALE texels per DEM cell, with a
 * slope-scaled depth offset; each cell is then compared with the map
 * through a percentage-closer filter, either of a fixed width or (auto)
 * as wide as the penumbra that the light's disk casts from the occluders'
 * distance read in the map. Flat Earth: no curvature, no distance bound.
 * docs/methods.md measures it against the exact method.
 */
#ifndef TERRASHADE_SHADOWMAP_H
#define TERRASHADE_SHADOWMAP_H

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/** PCF width that follows the occluder's distance (PCF_KERNEL=auto). */
#define TS_SHADOWMAP_AUTO 0.0
/** Range of the depth map's texels per DEM cell. */
#define TS_SHADOWMAP_SCALE_MIN 0.25
#define TS_SHADOWMAP_SCALE_MAX 8.0
/** Widest fixed PCF kernel, DEM cells. */
#define TS_SHADOWMAP_KERNEL_MAX 64.0
/** Number of floats of a frame's parameters (core/cellmath/cm_shadowmap.h). */
#define TS_SHADOWMAP_PARAMS 19

/** Options of the shadow map. Fill with ts_shadowmap_opts_default. */
typedef struct {
    double scale;        /**< texels per DEM cell along each axis, 0.25..8 */
    double kernel;       /**< PCF width in DEM cells, 0 < k <= 64, or
                              TS_SHADOWMAP_AUTO */
    double light_radius; /**< the light's angular radius, degrees, 0 < r < 45
                              (what auto's kernel follows) */
    int threads;         /**< worker threads; 0 = number of cores */
    ts_progress_fn progress; /**< the C backend reports 0..1 in the map's
                                  rows and the cells' (and stops with
                                  TS_ERR_CANCELLED where it asks); NULL: none */
    void *progress_user;     /**< passed to progress */
} ts_shadowmap_opts;

/** Defaults: scale 2, auto kernel, the sun's radius, all cores, no
 * progress. */
void ts_shadowmap_opts_default(ts_shadowmap_opts *opts);

/** Check the options; the message names the offending field. */
ts_status ts_shadowmap_opts_validate(const ts_shadowmap_opts *opts, ts_error *err);

/**
 * Where the DEM lands in the light's depth map: its size in texels and the
 * parameters of the per-cell formulas (TS_SMP_* of cm_shadowmap.h). Both
 * backends make it with ts_shadowmap_frame_make, so that they render and
 * read the same map.
 */
typedef struct {
    int width, height; /**< texels */
    float params[TS_SHADOWMAP_PARAMS];
} ts_shadowmap_frame;

/** Number of int keys of the frame's map: its texels, then the largest key
 * of each 16 x 16 tile (TS_SM_TILE of cm_shadowmap.h). */
size_t ts_shadowmap_keys(const ts_shadowmap_frame *frame);

/**
 * The frame for a light at `azimuth` (degrees from north) and `elevation`
 * (degrees, 0 < e <= 90: a shadow map needs the light above the horizon).
 * Fails with TS_ERR_NOMEM when the map would not fit in memory.
 */
ts_status ts_shadowmap_frame_make(const ts_grid *grid, double azimuth, double elevation,
                                  const ts_shadowmap_opts *opts, ts_shadowmap_frame *frame,
                                  ts_error *err);

/** ts_shadowmap_frame_make, and a check of the output: what both backends
 * of ts_shadowmap_compute start with. */
ts_status ts_shadowmap_prepare(const ts_grid *grid, double azimuth, double elevation,
                               const ts_shadowmap_opts *opts, const float *visibility,
                               ts_shadowmap_frame *frame, ts_error *err);

/**
 * Lit fraction (0..1) of every cell under a light at `azimuth`,
 * `elevation` by the shadow map: `visibility` width*height (row stride =
 * width), NaN for nodata. A nodata cell casts no shadow. The type of every
 * backend's shadow map (terrashade_cl.h).
 */
typedef ts_status ts_shadowmap_compute_fn(const ts_grid *grid, double azimuth,
                                          double elevation, const ts_shadowmap_opts *opts,
                                          float *visibility, ts_error *err);
/** The shadow map on the C backend. */
ts_shadowmap_compute_fn ts_shadowmap_compute;

#ifdef __cplusplus
}
#endif

#endif
