/* Helpers of the sun-position check programs (check_sun, check_sun_geometry):
 * a tolerance assertion and the Unix time of an ISO 8601 text. */
#ifndef TS_TEST_SUN_H
#define TS_TEST_SUN_H

#include <check.h>
#include <math.h>

#include "terrashade_sun.h"

#define CK_NEAR(got, want, tol, what)                                            \
    ck_assert_msg(fabs((got) - (want)) <= (tol), "%s: got %.10f, want %.10f +/- %g", \
                  what, (double)(got), (double)(want), (double)(tol))

static inline double unix_of(const char *iso)
{
    double t;
    ts_error err;
    ck_assert_msg(ts_parse_iso8601(iso, &t, NULL, &err) == TS_OK, "%s: %s", iso,
                  err.message);
    return t;
}

#endif
