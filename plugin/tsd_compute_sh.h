/*
 * tsd_compute_sh.h - the products' order-4 SH methods (core/terrashade_sh.h):
 * METHOD=sh's key light for shade and shadow, ENV_METHOD=sh for envlight.
 * The horizon sweeps run on the backend; the SH visibility and lighting in
 * C (no OpenCL kernel: with OpenCL they are reported as C, with the reason).
 * No GDAL.
 */
#ifndef TSD_COMPUTE_SH_H
#define TSD_COMPUTE_SH_H

#include "tsd_compute.h"

#ifdef __cplusplus
extern "C" {
#endif

/** shade's direct term with METHOD=sh: the triple product of the key light
 *  (a disk of LIGHT_RADIUS at the run's sun), the visibility of its
 *  partial swath (SWATH_DIRECTIONS sweeps) and the clamped cosine around
 *  the normal, normalised so that open flat ground gets the exact method's
 *  sin(elevation) (ts_sh_key_reference), times the share of the disk above
 *  the horizontal; clamped to 0..1. */
ts_status tsd_sh_key_direct(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                            float *out);

/** shadow with METHOD=sh: the visible share of the key light (light .
 *  visibility, 1 on open flat ground), times the share of the disk above
 *  the horizontal. */
ts_status tsd_sh_key_shadow(const tsd_compute_ctx *c, const ts_grid *g, float *out);

/** envlight with ENV_METHOD=sh: E/pi per colour into r, g, b from the
 *  run's environment, the DIRECTIONS horizon planes as a complete swath. */
ts_status tsd_sh_env_light(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                           float *r, float *gr, float *b);

#ifdef __cplusplus
}
#endif

#endif
