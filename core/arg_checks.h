/* Argument checks shared by the C and OpenCL backends, so that both accept
 * and refuse exactly the same calls with the same messages. */
#ifndef TS_ARG_CHECKS_H
#define TS_ARG_CHECKS_H

#include "terrashade.h"

/* Checks of ts_shm_compute's arguments; *azimuth is reduced to [0, 360). */
ts_status ts_check_shm_args(const ts_grid *grid, double *azimuth, double elevation,
                            double penumbra_depth, int threads, const float *vis,
                            const float *shadow_height, ts_error *err);

/* Checks of ts_horizon_sweep's arguments but its output; *azimuth is
 * reduced to [0, 360). */
ts_status ts_check_sweep_args(const ts_grid *grid, double *azimuth,
                              const ts_horizon_opts *opts, ts_error *err);

/* Checks of ts_normals' arguments. */
ts_status ts_check_normals_args(const ts_grid *grid, const float *nx, const float *ny,
                                const float *nz, ts_error *err);

/* Checks of ts_sky_accumulate's grid, normals and number of directions. */
ts_status ts_check_sky_args(const ts_grid *grid, const float *nx, const float *ny,
                            const float *nz, int directions, ts_error *err);

/* Checks of ts_sky_terms' arguments but its outputs. */
ts_status ts_check_sky_terms_args(const ts_grid *grid, const float *nx, const float *ny,
                                  const float *nz, const float *horizons,
                                  const ts_horizon_opts *opts, ts_error *err);

/* Checks of ts_horizon_compute's arguments, including that the
 * directions x width x height output floats can be addressed. */
ts_status ts_check_horizon_compute_args(const ts_grid *grid, const ts_horizon_opts *opts,
                                        const float *out, ts_error *err);

/* Checks of ts_shade_direct's arguments, the two computed azimuths the
 * sun's lies between (planes k0 and k1, weight w of k1) and the unit vector
 * toward the sun (east, north, up) in light[]. */
ts_status ts_direct_setup(const ts_grid *grid, const float *nx, const float *ny,
                          const float *nz, const float *horizons,
                          const ts_horizon_opts *opts, double sun_azimuth,
                          double sun_elevation, const float *out, int *k0, int *k1,
                          double *w, float light[3], ts_error *err);

#endif
