/* Argument checks shared by the C and OpenCL backends, so that both accept
 * and refuse exactly the same calls with the same messages. */
#ifndef TS_ARG_CHECKS_H
#define TS_ARG_CHECKS_H

#include "terrashade.h"

/* Checks of ts_shm_compute's arguments. */
ts_status ts_check_shm_args(const ts_grid *grid, double azimuth, double elevation,
                            double penumbra_depth, int threads, const float *vis,
                            const float *shadow_height, ts_error *err);

/* Checks of ts_horizon_compute's arguments, including that the
 * directions x width x height output floats can be addressed. */
ts_status ts_check_horizon_compute_args(const ts_grid *grid, const ts_horizon_opts *opts,
                                        const float *out, ts_error *err);

/* Checks of ts_shade_direct's arguments, and the two computed azimuths the
 * sun's lies between: planes k0 and k1, weight w of k1. */
ts_status ts_direct_setup(const ts_grid *grid, const float *nx, const float *ny,
                          const float *nz, const float *horizons,
                          const ts_horizon_opts *opts, double sun_azimuth,
                          double sun_elevation, const float *out, int *k0, int *k1,
                          double *w, ts_error *err);

#endif
