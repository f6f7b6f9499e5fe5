/* Helpers of the day-cycle check programs (check_daycycle,
 * check_daycycle_light): a tolerance assertion and a flat test DEM. */
#ifndef TS_TEST_DAYCYCLE_H
#define TS_TEST_DAYCYCLE_H

#include <check.h>
#include <math.h>

#include "test_grid.h"

#define CK_NEAR(got, want, tol, what)                                                 \
    ck_assert_msg(fabs((double)(got) - (double)(want)) <= (tol),                      \
                  "%s: got %.6f, want %.6f +/- %g", what, (double)(got), (double)(want), \
                  (double)(tol))

/* An n x n grid of cells `cell` metres wide, every height z. */
static inline void flat(ts_grid *g, int n, double cell, float z)
{
    tdem_create(g, n, n, cell, cell);
    tdem_fill(g, z);
}

#endif
