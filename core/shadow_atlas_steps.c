/*
 * The step table of a far-shadow atlas, checked on writing and on reading
 * (shadow_atlas.h): the values a map's record may hold, so that a damaged
 * or forged file cannot put the sun below the Earth or a map in the year
 * -292277018574.
 */
#include <math.h>

#include "shadow_atlas.h"
#include "status_internal.h"
#include "terrashade_sun.h"

/* The SPA's range of years, -2000 to 6000, in Unix seconds. */
static double unix_of_year(long long year)
{
    return (double)ts_days_from_civil(year, 1, 1) * 86400.0;
}

/* NaN, or a finite value within [lo, hi]. */
static int unknown_or_within(double v, double lo, double hi)
{
    return isnan(v) || (v >= lo && v <= hi);
}

ts_status ts_atlas_check_steps(const ts_atlas_step *steps, int n, const char *what,
                               ts_error *err)
{
    if (!steps || n < 1)
        return ts_fail(err, TS_ERR_ARG, "%s: no maps", what);
    const double t_min = unix_of_year(-2000), t_max = unix_of_year(6001);
    const int timed = !isnan(steps[0].unix_time);
    for (int k = 0; k < n; k++) {
        const ts_atlas_step *s = &steps[k];
        if (!isnan(s->unix_time) && !(s->unix_time >= t_min && s->unix_time < t_max))
            return ts_fail(err, TS_ERR_ARG,
                           "%s: map %d's time, %.17g Unix seconds, is not an instant "
                           "between the years -2000 and 6000", what, k + 1, s->unix_time);
        const int has_time = !isnan(s->unix_time);
        if (has_time != timed)
            return ts_fail(err, TS_ERR_ARG,
                           "%s: map %d has %s time but map 1 has %s: either every map "
                           "has one or none has", what, k + 1, timed ? "no" : "a",
                           timed ? "one" : "none");
        if (k > 0 && timed && !(s->unix_time > steps[k - 1].unix_time))
            return ts_fail(err, TS_ERR_ARG,
                           "%s: map %d's time (%.3f) is not after map %d's (%.3f): the "
                           "maps of a day follow each other", what, k + 1, s->unix_time,
                           k, steps[k - 1].unix_time);
        if (!unknown_or_within(s->azimuth, 0.0, 360.0) ||
            !unknown_or_within(s->grid_azimuth, 0.0, 360.0))
            return ts_fail(err, TS_ERR_ARG,
                           "%s: map %d's sun azimuth (%g true, %g grid) lies outside 0 "
                           "to 360 degrees", what, k + 1, s->azimuth, s->grid_azimuth);
        if (!unknown_or_within(s->elevation, -90.0, 90.0))
            return ts_fail(err, TS_ERR_ARG,
                           "%s: map %d's sun elevation (%g) lies outside -90 to 90 "
                           "degrees", what, k + 1, s->elevation);
        if (s->utc_offset_minutes < -(23 * 60 + 59) || s->utc_offset_minutes > 23 * 60 + 59)
            return ts_fail(err, TS_ERR_ARG,
                           "%s: map %d's offset from UTC (%d minutes) lies outside "
                           "-23:59 to +23:59", what, k + 1, (int)s->utc_offset_minutes);
    }
    if (timed && !(steps[n - 1].unix_time - steps[0].unix_time < 86400.0))
        return ts_fail(err, TS_ERR_ARG,
                       "%s: its maps span %.6g hours (map 1 to map %d), more than the "
                       "one day an atlas holds", what,
                       (steps[n - 1].unix_time - steps[0].unix_time) / 3600.0, n);
    return ts_ok(err);
}
