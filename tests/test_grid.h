/* Grids and buffers for the check programs: allocation and the reading of
 * the real DEMs of tests/data (see tests/data/README.md) that fail the
 * running test instead of returning an error. The test DEMs themselves are
 * in test_dem.h, included here. */
#ifndef TS_TEST_GRID_H
#define TS_TEST_GRID_H

#include <stddef.h>

#include "terrashade.h"
#include "test_dem.h"

/* ts_grid_create that aborts the test on failure. */
void tdem_create(ts_grid *g, int width, int height, double cell_x,
                 double cell_y);

/* tdem_read (test_dem.h) that aborts the test on failure. */
void tdem_load(ts_grid *g, const char *name);

/* Allocate n floats (aborts the test on failure); free with free(). */
float *tdem_floats(size_t n);

/* A progress callback's log: tprog_log (a ts_progress_fn, user: a tprog)
 * counts the calls and keeps the first and last fraction, fails the test
 * where a fraction goes back or passes 1, and asks to stop (returns 1) at
 * call stop_at (-1: never). Start it as {0, stop_at, 0, -1}. */
typedef struct {
    int calls, stop_at;
    double last, first;
} tprog;

int tprog_log(double done, void *user);

#endif
