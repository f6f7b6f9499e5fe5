/* Deterministic fractal DEM for benchmarks: fBm of hashed value noise. */
#ifndef TS_FRACTAL_DEM_H
#define TS_FRACTAL_DEM_H

#include "terrashade.h"

/* Fill grid->z with an fBm surface: octaves of bilinear value noise,
 * wavelength halving and amplitude scaling by 2^-hurst per octave, heights
 * scaled to [0, relief] metres. Same seed, same surface. */
void ts_fractal_fill(ts_grid *grid, unsigned seed, double hurst, double relief);

#endif
