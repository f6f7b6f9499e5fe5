/* What the backend dispatcher ran for a product; see tsd_backend.h. */
#include "tsd_backend.h"

#include "terrashade_cl.h"

#include "tsd_text.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ts_backend tsd_backend_to_ts(tsd_backend b)
{
    return b == TSD_BACKEND_OPENCL ? TS_BACKEND_OPENCL
           : b == TSD_BACKEND_C    ? TS_BACKEND_C
                                   : TS_BACKEND_AUTO;
}

/* The first reason; the first failure wins over a choice (auto on a CPU). */
static void take_reason(tsd_backend_summary *s, const char *reason, int fell_back)
{
    if (reason[0] && (!s->reason[0] || (fell_back && !s->fell_back)))
        snprintf(s->reason, sizeof s->reason, "%s", reason);
    s->fell_back |= fell_back;
}

void tsd_backend_summary_add(tsd_backend_summary *s, const ts_backend_report *r)
{
    if (!s->calls)
        s->requested = r->requested;
    s->calls++;
    if (r->used == TS_BACKEND_OPENCL) {
        s->opencl_calls++;
        snprintf(s->device_opencl, sizeof s->device_opencl, "%s", r->device);
        return;
    }
    s->c_calls++;
    snprintf(s->device_c, sizeof s->device_c, "%s", r->device);
    take_reason(s, r->requested != TS_BACKEND_C ? r->reason : "", r->fell_back);
}

void tsd_backend_summary_merge(tsd_backend_summary *s, const tsd_backend_summary *add)
{
    if (!add->calls)
        return;
    if (!s->calls)
        s->requested = add->requested;
    s->calls += add->calls;
    s->opencl_calls += add->opencl_calls;
    s->c_calls += add->c_calls;
    if (add->device_opencl[0])
        snprintf(s->device_opencl, sizeof s->device_opencl, "%s", add->device_opencl);
    if (add->device_c[0])
        snprintf(s->device_c, sizeof s->device_c, "%s", add->device_c);
    take_reason(s, add->reason, add->fell_back);
}

void tsd_backend_note_c(tsd_backend_summary *s, ts_backend requested, const char *why)
{
    ts_backend_report r;
    ts_error err;
    if (!s || ts_backend_choose(TS_BACKEND_C, &r, &err) != TS_OK)
        return;
    r.requested = requested;
    snprintf(r.reason, sizeof r.reason, "%s", why);
    tsd_backend_summary_add(s, &r);
}

const char *tsd_backend_c_step(const tsd_options *o, int *all)
{
    const char *p = tsd_options_product_name(o);
    const int horizon = !strcmp(p, "horizon"), shadow = !strcmp(p, "shadow");
    *all = 0;
    if (o->horizon_method == TSD_HORIZON_PYRAMID) {
        *all = horizon;
        return TSD_PYRAMID_C_REASON;
    }
    if (o->max_distance > 0 && o->method == TSD_METHOD_EXACT) {
        *all = horizon || shadow;
        return TS_CL_CAPPED_SWEEP_REASON;
    }
    if (o->sun_position == TSD_SUN_PER_CELL) {
        *all = shadow;
        return TSD_PER_CELL_C_REASON;
    }
    return NULL;
}

int tsd_backend_predict(const tsd_options *o, tsd_backend_summary *s, char *msg,
                        size_t n)
{
    ts_backend_report r;
    ts_error err;
    memset(s, 0, sizeof *s);
    const ts_backend requested = tsd_backend_to_ts(o->backend);
    if (ts_backend_choose(requested, &r, &err) != TS_OK) /* (a bad TERRASHADE_BACKEND) */
        return (tsd_fail_core(msg, n, NULL, &err), -1);
    int all;
    const char *why = tsd_backend_c_step(o, &all);
    if (!all)
        tsd_backend_summary_add(s, &r);
    if (why) /* (after the choice: its failure's reason would come first) */
        tsd_backend_note_c(s, r.requested, why);
    return 0;
}

int tsd_backend_check_env(const tsd_options *o, int uses_backend, char *msg, size_t n)
{
    const char *env = getenv("TERRASHADE_BACKEND");
    ts_backend b;
    ts_error err;
    int cap;
    if (ts_cpu_vectors_parse(getenv("TERRASHADE_SIMD"), &cap, &err) != TS_OK)
        return (tsd_fail_core(msg, n, NULL, &err), -1);
    if (uses_backend && tsd_backend_batch(msg, n) < 0)
        return -1;
    if (!uses_backend || o->backend != TSD_BACKEND_AUTO || !env || !*env ||
        ts_backend_parse(env, &b, &err) == TS_OK)
        return 0;
    return (tsd_fail(msg, n, TS_ERR_ARG,
                     "TERRASHADE_BACKEND must be auto, c or opencl, got '%.40s'", env),
            -1);
}

int tsd_backend_batch(char *msg, size_t n)
{
    const char *env = getenv("TERRASHADE_OPENCL_BATCH");
    if (!env || !*env)
        return 0;
    char *end;
    long v = strtol(env, &end, 10);
    if (end == env || *end || v < 1 || v > TSD_OPENCL_BATCH_MAX)
        return (tsd_fail(msg, n, TS_ERR_ARG,
                         "TERRASHADE_OPENCL_BATCH must be an integer from 1 to %d, got '%.40s'",
                         TSD_OPENCL_BATCH_MAX, env),
                -1);
    return (int)v;
}

void tsd_backend_summary_text(const tsd_backend_summary *s, char *backend, size_t bn,
                              char *device, size_t dn)
{
    if (s->opencl_calls && s->c_calls) {
        snprintf(backend, bn, "mixed");
        snprintf(device, dn, "opencl: %s; c: %s", s->device_opencl, s->device_c);
    } else if (s->opencl_calls) {
        snprintf(backend, bn, "opencl");
        snprintf(device, dn, "%s", s->device_opencl);
    } else {
        snprintf(backend, bn, "c");
        snprintf(device, dn, "%s", s->device_c);
    }
}
