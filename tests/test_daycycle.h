/* Helpers of the day-cycle check programs (check_daycycle,
 * check_daycycle_light): a flat test DEM (their tolerance assertion,
 * CK_NEAR, is test_expect.h's). */
#ifndef TS_TEST_DAYCYCLE_H
#define TS_TEST_DAYCYCLE_H

#include <check.h>

#include "test_expect.h"
#include "test_grid.h"

/* An n x n grid of cells `cell` metres wide, every height z. */
static inline void flat(ts_grid *g, int n, double cell, float z)
{
    tdem_create(g, n, n, cell, cell);
    tdem_fill(g, z);
}

#endif
