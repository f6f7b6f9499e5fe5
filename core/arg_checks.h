/* Argument checks shared by the C and OpenCL backends, so that both accept
 * and refuse exactly the same calls with the same messages. */
#ifndef TS_ARG_CHECKS_H
#define TS_ARG_CHECKS_H

#include "terrashade.h"
#include "terrashade_env.h"

/* Checks of ts_shm_compute's arguments; *azimuth is reduced to [0, 360). */
ts_status ts_check_shm_args(const ts_grid *grid, double *azimuth, double elevation,
                            double penumbra_depth, int threads, const float *vis,
                            const float *shadow_height, ts_error *err);

/* Checks of ts_horizon_sweep's arguments but its output; *azimuth is
 * reduced to [0, 360). */
ts_status ts_check_sweep_args(const ts_grid *grid, double *azimuth,
                              const ts_horizon_opts *opts, ts_error *err);

/* Checks of the backends' sweeps of n azimuths in one call (each as
 * ts_check_sweep_args checks it; into reduced[0..n-1], in [0, 360), where
 * reduced is not NULL), and that n planes of output can be addressed. */
ts_status ts_check_sweeps_args(const ts_grid *grid, const double *azimuths, int n,
                               const ts_horizon_opts *opts, const float *out, double *reduced,
                               ts_error *err);

/* Checks of ts_normals' arguments. */
ts_status ts_check_normals_args(const ts_grid *grid, const float *nx, const float *ny,
                                const float *nz, ts_error *err);

/* Checks of ts_sky_accumulate's grid, normals and number of directions. */
ts_status ts_check_sky_args(const ts_grid *grid, const float *nx, const float *ny,
                            const float *nz, int directions, ts_error *err);

/* Checks of a ts_sky_request (its outputs may be NULL). */
ts_status ts_check_sky_request(const ts_sky_request *req, ts_error *err);

/* Checks of ts_horizon_compute's arguments, including that the
 * directions x width x height output floats can be addressed. */
ts_status ts_check_horizon_compute_args(const ts_grid *grid, const ts_horizon_opts *opts,
                                        const float *out, ts_error *err);

/* What both backends' direct sun derive from a ts_direct_request: the two
 * computed azimuths the sun's lies between (planes k0 and k1, weight w of
 * k1), the unit vector toward the sun (east, north, up) and the radius of
 * its disk. */
typedef struct {
    int k0, k1;
    double w;
    float light[3];
    double radius; /* the light's angular radius, degrees */
} ts_direct_plan;

/* Checks of a ts_direct_request, then its plan. */
ts_status ts_direct_setup(const ts_direct_request *req, ts_direct_plan *plan, ts_error *err);
/* The same without the normals (ts_shade_direct_horn computes them). */
ts_status ts_direct_setup_horn(const ts_direct_request *req, ts_direct_plan *plan,
                               ts_error *err);

/* Checks of a ts_env_light_request (its outputs only for NULL). */
ts_status ts_check_env_light_request(const ts_env_light_request *req, ts_error *err);

/* Floats of one sector of a light table (lp + k * this is sector k). */
size_t ts_env_table_sector_floats(const ts_env_table *table);

/* Sine and cosine (as floats) of sector k's azimuth, as the C loop uses them. */
void ts_env_sector_sincos(const ts_env_table *table, int k, float *sa, float *ca);

#endif
