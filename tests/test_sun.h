/* Helpers of the sun-position check programs (check_sun, check_sun_geometry):
 * the Unix time of an ISO 8601 text (their tolerance assertion, CK_NEAR, is
 * test_expect.h's). */
#ifndef TS_TEST_SUN_H
#define TS_TEST_SUN_H

#include <check.h>

#include "terrashade_sun.h"
#include "test_expect.h"

static inline double unix_of(const char *iso)
{
    double t;
    ts_error err;
    ck_assert_msg(ts_parse_iso8601(iso, &t, NULL, &err) == TS_OK, "%s: %s", iso,
                  err.message);
    return t;
}

#endif
