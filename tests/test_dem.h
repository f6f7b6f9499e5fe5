/* Test DEMs: every deterministic terrain generator of the check programs
 * and the benchmarks, and the reader of the real DEMs of tests/data, in one
 * module. No check framework here, so that bench/ links it too (the check
 * helpers are in test_grid.h). Each generator writes the width x height
 * cells of a grid the caller allocated (not the row padding); same
 * arguments, same heights. */
#ifndef TS_TEST_DEM_H
#define TS_TEST_DEM_H

#include <stddef.h>
#include <stdint.h>

#include "terrashade.h"

/* Deterministic PRNG (splitmix64), so every run sees the same terrain. */
double tdem_uniform(uint64_t *state); /* [0, 1) */

/* Marsaglia's xorshift32 (13, 17, 5): the next value of *state. */
uint32_t tdem_xorshift32(uint32_t *state);

/* Set every cell to z. */
void tdem_fill(ts_grid *g, float z);

/* Fractal terrain: a sum of random plane waves with amplitude ~ 1/f
 * (Brownian-like), heights in about [0, relief] metres. */
void tdem_fractal(ts_grid *g, uint64_t seed, double relief);

/* fBm of hashed bilinear value noise (the benchmarks' terrain): octaves
 * with the wavelength halving from the grid's longer side down to 2 cells
 * and the amplitude scaling by 2^-hurst per octave, heights scaled to
 * [0, relief] metres. */
void tdem_fbm(ts_grid *g, unsigned seed, double hurst, double relief);

/* Smooth sum of a few sines, heights in about [0, relief] metres. */
void tdem_sines(ts_grid *g, double relief);

/* Four sine waves around 300 m (about +-210 m) plus +-6 m of hashed
 * per-cell noise (the C vs OpenCL comparisons). With holes, nodata (NaN)
 * in a 4 x 3 block at (width/3, height/2) and in about 3% of the cells. */
void tdem_sines_hash_noise(ts_grid *g, unsigned seed, int holes);

/* 300 sin(0.21 x) cos(0.17 y) plus noise in [0, 200) m in steps of 0.2 m,
 * one tdem_xorshift32(state) per cell in row order (the far-shadow tests). */
void tdem_sines_rng_noise(ts_grid *g, uint32_t *state);

/* Gaussian hills of random position, width and height up to `relief`. */
void tdem_hills(ts_grid *g, uint64_t seed, int count, double relief);

/* Sharp features for the hull: a rough base plus single-cell spikes,
 * step edges and white noise. */
void tdem_sharp(ts_grid *g, uint64_t seed);

/* Read tests/data/NAME.{hdr,f32} (written by tests/data/make_raw.py) into a
 * new grid with per-row spacing, from $TS_TEST_DATA if set, else the
 * compile-time TS_TEST_DATA. lon and lat, if not NULL, receive the DEM's
 * centre in degrees. Returns 0, or -1 with a sentence in msg and no grid. */
int tdem_read(ts_grid *g, const char *name, double *lon, double *lat, char *msg,
              size_t msg_size);

#endif
