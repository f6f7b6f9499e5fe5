/*
 * fuzz_datetime: the text of DATETIME, DATE and TIMEZONE. The input is one
 * string, read by each parser: ts_parse_iso8601 (as given and after the
 * driver's tsd_datetime_normalise, which turns the basic format of inline
 * options into the extended one), ts_parse_date and ts_parse_utc_offset.
 * Besides the sanitizers, it checks the parsers' promises: a failure says
 * why; an accepted date exists; an offset stays within +/-23:59; an accepted
 * instant is finite and its offset in range; normalising is idempotent and
 * stays within its buffer.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "day_cycle.h"
#include "terrashade_sun.h"
#include "tsd_datetime.h"
#include "tsd_options.h"

static void check_iso(const char *s)
{
    ts_error err;
    double t = NAN;
    int off = 99999;
    memset(&err, 0, sizeof err);
    if (ts_parse_iso8601(s, &t, &off, &err) == TS_OK) {
        fuzz_require(isfinite(t), "an accepted instant is not finite");
        fuzz_require(off >= -(23 * 60 + 59) && off <= 23 * 60 + 59, "offset out of range");
        double jd = ts_julian_day_from_unix(t);
        fuzz_require(fabs(ts_unix_from_julian_day(jd) - t) <= 1e-6 * fabs(t) + 1.0,
                     "Unix time and Julian day do not round-trip");
    } else {
        fuzz_require(err.message[0] != '\0', "ts_parse_iso8601 failed without a message");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *s = fuzz_cstring(data, size);
    if (!s)
        return 0;

    check_iso(s);

    /* The driver's path: basic format to extended, into a small buffer too. */
    char norm[TSD_TEXT_MAX * 2], again[TSD_TEXT_MAX * 2], tiny[8];
    tsd_datetime_normalise(s, norm, sizeof norm);
    fuzz_require(memchr(norm, '\0', sizeof norm) != NULL, "normalised text unterminated");
    tsd_datetime_normalise(norm, again, sizeof again);
    fuzz_require(strcmp(norm, again) == 0, "normalising twice changes the text");
    tsd_datetime_normalise(s, tiny, sizeof tiny);
    fuzz_require(memchr(tiny, '\0', sizeof tiny) != NULL, "normalised text overflows");
    check_iso(norm);

    ts_error err;
    int y = 0, m = 0, d = 0;
    memset(&err, 0, sizeof err);
    if (ts_parse_date(s, &y, &m, &d, &err) == TS_OK) {
        fuzz_require(m >= 1 && m <= 12 && d >= 1 && d <= ts_days_in_month(y, m),
                     "ts_parse_date accepted a day that does not exist");
        double t0 = ts_local_midnight(y, m, d, 0);
        fuzz_require(isfinite(t0), "local midnight is not finite");
    } else {
        fuzz_require(err.message[0] != '\0', "ts_parse_date failed without a message");
    }
    int minutes = 99999;
    memset(&err, 0, sizeof err);
    if (ts_parse_utc_offset(s, &minutes, &err) == TS_OK)
        fuzz_require(minutes >= -(23 * 60 + 59) && minutes <= 23 * 60 + 59,
                     "ts_parse_utc_offset accepted an offset beyond 23:59");
    else
        fuzz_require(err.message[0] != '\0',
                     "ts_parse_utc_offset failed without a message");
    free(s);
    return 0;
}
