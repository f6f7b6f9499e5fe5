/*
 * Backend dispatcher: run a product on OpenCL or C, fall back to C on any
 * OpenCL failure, and report what ran. See terrashade_backend.h.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "arg_checks.h"
#include "status_internal.h"
#include "terrashade_backend.h"
#include "terrashade_cl.h"

const char *ts_backend_name(ts_backend backend)
{
    switch (backend) {
    case TS_BACKEND_AUTO: return "auto";
    case TS_BACKEND_C: return "c";
    case TS_BACKEND_OPENCL: return "opencl";
    }
    return "unknown";
}

ts_status ts_backend_parse(const char *text, ts_backend *backend, ts_error *err)
{
    if (!text || !backend)
        return ts_fail(err, TS_ERR_ARG, "backend name or result is NULL");
    char buf[16];
    size_t n = 0;
    while (isspace((unsigned char)*text))
        text++;
    while (text[n] && !isspace((unsigned char)text[n]) && n < sizeof buf - 1) {
        buf[n] = text[n];
        n++;
    }
    buf[n] = '\0';
    if (!strcasecmp(buf, "auto") || !buf[0])
        *backend = TS_BACKEND_AUTO;
    else if (!strcasecmp(buf, "c"))
        *backend = TS_BACKEND_C;
    else if (!strcasecmp(buf, "opencl"))
        *backend = TS_BACKEND_OPENCL;
    else
        return ts_fail(err, TS_ERR_ARG, "backend must be auto, c or opencl, got '%.40s'", text);
    return ts_ok(err);
}

/* The backend to run: an explicit argument, else TERRASHADE_BACKEND. */
static ts_status resolve(ts_backend requested, ts_backend *eff, ts_error *err)
{
    if (requested != TS_BACKEND_AUTO && requested != TS_BACKEND_C &&
        requested != TS_BACKEND_OPENCL)
        return ts_fail(err, TS_ERR_ARG, "unknown backend %d", (int)requested);
    *eff = requested;
    if (requested != TS_BACKEND_AUTO)
        return TS_OK;
    const char *env = getenv("TERRASHADE_BACKEND");
    if (!env || !*env)
        return TS_OK;
    ts_error e;
    if (ts_backend_parse(env, eff, &e) != TS_OK)
        return ts_fail(err, TS_ERR_ARG, "TERRASHADE_BACKEND must be auto, c or opencl, got '%.40s'",
                       env);
    return TS_OK;
}

static void report_c(ts_backend_report *r)
{
    r->used = TS_BACKEND_C;
    snprintf(r->backend, sizeof r->backend, "c");
    snprintf(r->device, sizeof r->device, "CPU, %d cores, %s", ts_cpu_count(),
             ts_cpu_vectors_name(ts_cpu_vector_level()));
}

/* Whether to try OpenCL for backend `eff`; fills the report either way. */
static int want_opencl(ts_backend eff, ts_backend_report *r)
{
    memset(r, 0, sizeof *r);
    r->requested = eff;
    report_c(r);
    if (eff == TS_BACKEND_C) {
        snprintf(r->reason, sizeof r->reason, "the C backend was requested");
        return 0;
    }
    ts_cl_info info;
    ts_error e;
    const char *dev = getenv("TERRASHADE_OPENCL_DEVICE");
    int named = dev && *dev;
    /* auto on a CPU device runs C: tell the type from the device list, as
     * making the device compiles the kernels (0.1-0.2 s with PoCL) */
    int choose = eff == TS_BACKEND_AUTO && !named;
    if ((choose && ts_cl_peek(&info, &e) != TS_OK) ||
        ((!choose || strcmp(info.type, "CPU")) && ts_cl_available(&info, &e) != TS_OK)) {
        r->fell_back = 1;
        snprintf(r->reason, sizeof r->reason, "%s", e.message);
        return 0;
    }
    if (choose && !strcmp(info.type, "CPU")) {
        snprintf(r->reason, sizeof r->reason,
                 "auto: the OpenCL device (%.60s) is a CPU, where the C backend is faster; "
                 "TERRASHADE_BACKEND=opencl uses it anyway",
                 info.device);
        return 0;
    }
    r->used = TS_BACKEND_OPENCL;
    snprintf(r->backend, sizeof r->backend, "opencl");
    snprintf(r->device, sizeof r->device, "%.100s (%.80s)", info.device, info.platform);
    return 1;
}

/* After an OpenCL attempt: success, or note the fallback. */
static int cl_done(ts_status st, const ts_error *e, ts_backend_report *r)
{
    if (st == TS_OK || st == TS_ERR_CANCELLED)
        return st == TS_OK;
    r->fell_back = 1;
    snprintf(r->reason, sizeof r->reason, "%s", e->message);
    report_c(r);
    return 0;
}

ts_status ts_backend_choose(ts_backend requested, ts_backend_report *report, ts_error *err)
{
    ts_backend eff;
    ts_backend_report tmp;
    ts_backend_report *r = report ? report : &tmp;
    ts_status st = resolve(requested, &eff, err);
    if (st != TS_OK)
        return st;
    want_opencl(eff, r);
    return ts_ok(err);
}

/* The common shape of every product: resolve, try OpenCL, else C. */
#define DISPATCH(CL_CALL, C_CALL)                                                             \
    do {                                                                                       \
        ts_backend eff;                                                                        \
        ts_backend_report tmp;                                                                 \
        ts_backend_report *r = report ? report : &tmp;                                        \
        ts_status st = resolve(backend, &eff, err);                                            \
        if (st != TS_OK)                                                                       \
            return st;                                                                         \
        if (want_opencl(eff, r)) {                                                             \
            ts_error e = {TS_OK, ""};                                                          \
            ts_error *cl_err = &e;                                                             \
            st = CL_CALL;                                                                      \
            if (cl_done(st, cl_err, r))                                                        \
                return ts_ok(err);                                                             \
            if (st == TS_ERR_CANCELLED) /* the caller stopped: no fallback */                  \
                return ts_fail(err, st, "%s", e.message);                                      \
        }                                                                                      \
        return C_CALL;                                                                         \
    } while (0)

ts_status ts_backend_horizon_sweep(ts_backend backend, const ts_grid *grid, double azimuth,
                                   const ts_horizon_opts *opts, float *out,
                                   ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_horizon_sweep(grid, azimuth, opts, out, cl_err),
             ts_horizon_sweep(grid, azimuth, opts, out, err));
}

/* The C side of ts_backend_horizon_sweeps: one sweep after the other. */
static ts_status c_horizon_sweeps(const ts_grid *grid, const double *azimuths, int n,
                                  const ts_horizon_opts *opts, float *out, ts_error *err)
{
    ts_status st = ts_check_sweeps_args(grid, azimuths, n, opts, out, NULL, err);
    const size_t cells = st == TS_OK ? (size_t)grid->width * grid->height : 0;
    for (int a = 0; st == TS_OK && a < n; a++)
        st = ts_horizon_sweep(grid, azimuths[a], opts, out + (size_t)a * cells, err);
    return st;
}

ts_status ts_backend_horizon_sweeps(ts_backend backend, const ts_grid *grid,
                                    const double *azimuths, int n, const ts_horizon_opts *opts,
                                    float *out, ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_horizon_sweeps(grid, azimuths, n, opts, out, cl_err),
             c_horizon_sweeps(grid, azimuths, n, opts, out, err));
}

ts_status ts_backend_horizon_compute(ts_backend backend, const ts_grid *grid,
                                     const ts_horizon_opts *opts, float *out,
                                     ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_horizon_compute(grid, opts, out, cl_err),
             ts_horizon_compute(grid, opts, out, err));
}

ts_status ts_backend_shm_compute(ts_backend backend, const ts_grid *grid, double azimuth,
                                 double elevation, double penumbra_depth, int threads,
                                 float *visibility, float *shadow_height,
                                 ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_shm_compute(grid, azimuth, elevation, penumbra_depth, threads, visibility,
                               shadow_height, cl_err),
             ts_shm_compute(grid, azimuth, elevation, penumbra_depth, threads, visibility,
                            shadow_height, err));
}

ts_status ts_backend_normals(ts_backend backend, const ts_grid *grid, int threads, float *nx,
                             float *ny, float *nz, ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_normals(grid, nx, ny, nz, cl_err),
             ts_normals_threads(grid, threads, nx, ny, nz, err));
}

ts_status ts_backend_shade_direct(ts_backend backend, const ts_direct_request *req,
                                  ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_shade_direct(req, cl_err), ts_shade_direct(req, err));
}

/* The normals on the device into planes, then the direct sun from them. */
static ts_status cl_shade_direct_horn(const ts_direct_request *req, ts_error *err)
{
    if (!req || !req->grid)
        return ts_fail(err, TS_ERR_ARG, "the direct sun request and its grid must be set");
    size_t cells = (size_t)req->grid->width * req->grid->height;
    float *n = malloc(3 * cells * sizeof *n);
    if (!n)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the planes of normals");
    ts_direct_request r = *req;
    r.nx = n;
    r.ny = n + cells;
    r.nz = n + 2 * cells;
    ts_status st = ts_cl_normals(req->grid, n, n + cells, n + 2 * cells, err);
    if (st == TS_OK)
        st = ts_cl_shade_direct(&r, err);
    free(n);
    return st;
}

ts_status ts_backend_shade_direct_horn(ts_backend backend, const ts_direct_request *req,
                                       ts_backend_report *report, ts_error *err)
{
    DISPATCH(cl_shade_direct_horn(req, cl_err), ts_shade_direct_horn(req, err));
}

ts_status ts_backend_shadowmap_compute(ts_backend backend, const ts_grid *grid, double azimuth,
                                       double elevation, const ts_shadowmap_opts *opts,
                                       float *visibility, ts_backend_report *report,
                                       ts_error *err)
{
    DISPATCH(ts_cl_shadowmap_compute(grid, azimuth, elevation, opts, visibility, cl_err),
             ts_shadowmap_compute(grid, azimuth, elevation, opts, visibility, err));
}

ts_status ts_backend_sky_terms(ts_backend backend, const ts_sky_request *req,
                               ts_backend_report *report, ts_error *err)
{
    DISPATCH(ts_cl_sky_terms(req, cl_err), ts_sky_terms(req, err));
}

/* One plane on OpenCL, through the session of `state` (opened on the first
 * plane, reopened for other arrays) or, without a state, in one call. */
static ts_status env_light_cl(ts_backend_env_light *state, const ts_env_light_request *req,
                              ts_error *err)
{
    if (!state)
        return ts_cl_env_light_accumulate(req, err);
    if (state->failed) /* not again for every plane */
        return ts_fail(err, TS_ERR_INTERNAL, "%s", state->reason);
    if (state->cl && !ts_cl_env_light_matches(state->cl, req))
        ts_backend_env_light_release(state);
    ts_status st = TS_OK;
    if (!state->cl)
        st = ts_cl_env_light_open(req, &state->cl, err);
    if (st == TS_OK)
        st = ts_cl_env_light_add(state->cl, req, err);
    if (st != TS_OK && st != TS_ERR_ARG) {
        ts_cl_env_light_close(state->cl);
        state->cl = NULL;
        state->failed = 1;
        snprintf(state->reason, sizeof state->reason, "%s",
                 err ? err->message : ts_status_name(st));
    }
    return st;
}

ts_status ts_backend_env_light_accumulate(ts_backend backend, ts_backend_env_light *state,
                                          const ts_env_light_request *req,
                                          ts_backend_report *report, ts_error *err)
{
    DISPATCH(env_light_cl(state, req, cl_err), ts_env_light_accumulate(req, err));
}

void ts_backend_env_light_release(ts_backend_env_light *state)
{
    if (!state)
        return;
    ts_cl_env_light_close(state->cl);
    memset(state, 0, sizeof *state);
}
