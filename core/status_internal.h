/* Internal helpers for filling a ts_error. */
#ifndef TS_STATUS_INTERNAL_H
#define TS_STATUS_INTERNAL_H

#include "terrashade.h"

/* Set err (if not NULL) to code and a printf-formatted message; returns code. */
ts_status ts_fail(ts_error *err, ts_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Mark err as success; returns TS_OK. */
ts_status ts_ok(ts_error *err);

/* Report `done` (0..1) through the options' progress callback, if any;
 * TS_ERR_CANCELLED (err filled) when it asks to stop, else TS_OK. */
ts_status ts_progress(const ts_horizon_opts *o, double done, ts_error *err);

#endif
