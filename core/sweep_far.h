/*
 * What core/far_horizon.c takes from the horizon sweep (horizon_sweep.c):
 * the far-only sweep in its lockstep blocks and its slopes to degrees.
 * Internal to core/.
 */
#ifndef TS_SWEEP_FAR_H
#define TS_SWEEP_FAR_H

#include "terrashade.h"

/* The far field of core/far_horizon.c in the sweep's lockstep blocks: the
 * slope (tangent, curvature included) from each cell, raised by dz, to the
 * steepest terrain at least threshold_m behind it along azimuth, into out
 * (NaN at nodata, -inf where none). The arguments are the caller's to
 * check (far_horizon.c). */
ts_status ts_sweep_far_lanes(const ts_grid *grid, double azimuth, double threshold_m, double dz,
                             const ts_horizon_opts *opts, float *out, ts_error *err);

/* Slopes (tangents) to elevation angles in degrees, in place, as the
 * sweep's own (ts_atan_deg, within 3e-6 degrees; -inf to -90, NaN kept). */
void ts_slopes_to_degrees(float *o, int n);

#endif
