/* Status codes and error messages. */
#include <stdarg.h>
#include <stdio.h>

#include "status_internal.h"

const char *ts_status_name(ts_status code)
{
    switch (code) {
    case TS_OK: return "success";
    case TS_ERR_ARG: return "invalid argument";
    case TS_ERR_NOMEM: return "out of memory";
    case TS_ERR_THREAD: return "cannot start thread";
    case TS_ERR_INTERNAL: return "internal error";
    case TS_ERR_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

ts_status ts_fail(ts_error *err, ts_status code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        err->code = code;
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
    }
    return code;
}

ts_status ts_ok(ts_error *err)
{
    if (err) {
        err->code = TS_OK;
        err->message[0] = '\0';
    }
    return TS_OK;
}

ts_status ts_progress(const ts_horizon_opts *o, double done, ts_error *err)
{
    if (!o || !o->progress)
        return TS_OK;
    if (o->progress(done < 0 ? 0 : done > 1 ? 1 : done, o->progress_user))
        return ts_fail(err, TS_ERR_CANCELLED, "cancelled by the caller");
    return TS_OK;
}
