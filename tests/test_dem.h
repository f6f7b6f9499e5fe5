/* Test DEMs: deterministic synthetic terrains and the raw real DEMs of
 * tests/data (see tests/data/README.md). */
#ifndef TS_TEST_DEM_H
#define TS_TEST_DEM_H

#include <stdint.h>

#include "terrashade.h"

/* Deterministic PRNG (splitmix64), so every run sees the same terrain. */
double tdem_uniform(uint64_t *state); /* [0, 1) */

/* ts_grid_create that aborts the test on failure. */
void tdem_create(ts_grid *g, int width, int height, double cell_x,
                 double cell_y);

/* Set every cell to z. */
void tdem_fill(ts_grid *g, float z);

/* Fractal terrain: a sum of random plane waves with amplitude ~ 1/f
 * (Brownian-like), heights in about [0, relief] metres. */
void tdem_fractal(ts_grid *g, uint64_t seed, double relief);

/* Smooth sum of a few sines, heights in about [0, relief] metres. */
void tdem_sines(ts_grid *g, double relief);

/* Gaussian hills of random position, width and height up to `relief`. */
void tdem_hills(ts_grid *g, uint64_t seed, int count, double relief);

/* Sharp features for the hull: a rough base plus single-cell spikes,
 * step edges and white noise. */
void tdem_sharp(ts_grid *g, uint64_t seed);

/* Load tests/data/NAME.{hdr,f32} into a new grid with per-row spacing.
 * The data directory is $TS_TEST_DATA if set, else the compile-time
 * TS_TEST_DATA. Aborts the test on failure. */
void tdem_load(ts_grid *g, const char *name);

/* Allocate n floats (aborts the test on failure); free with free(). */
float *tdem_floats(size_t n);

#endif
