/*
 * terrashade_backend.h - run a product on the C or the OpenCL backend.
 *
 * Each ts_backend_* function computes the same product as the C function of
 * terrashade.h and takes the same arguments, plus the backend wanted and a
 * report of what ran:
 *
 *  - TS_BACKEND_C runs the C core.
 *  - TS_BACKEND_OPENCL runs the OpenCL backend (terrashade_cl.h); if it fails
 *    for any reason (not built, no platform, no device, a bad
 *    TERRASHADE_OPENCL_DEVICE, build failure, device memory, kernel error),
 *    the C core runs instead and the report says so and why.
 *  - TS_BACKEND_AUTO reads the environment variable TERRASHADE_BACKEND
 *    (auto, c or opencl; unset or empty = auto). Auto runs OpenCL when the
 *    selected device is a GPU or an accelerator, or when
 *    TERRASHADE_OPENCL_DEVICE names a device explicitly; a CPU OpenCL device
 *    picked by default (PoCL) is not used, because the C core is faster on
 *    the same cores (docs/opencl.md). Failures fall back to C as above.
 *
 * An explicit TS_BACKEND_C or TS_BACKEND_OPENCL argument wins over the
 * environment. The results of the two backends agree within the tolerances
 * of docs/opencl.md. Errors of the arguments are reported as the C function
 * reports them; a bad TERRASHADE_BACKEND value is a TS_ERR_ARG error.
 */
#ifndef TERRASHADE_BACKEND_H
#define TERRASHADE_BACKEND_H

#include "terrashade.h"
#include "terrashade_shadowmap.h"
#include "terrashade_env.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_BACKEND_AUTO = 0,
    TS_BACKEND_C,
    TS_BACKEND_OPENCL
} ts_backend;

/** What ran. */
typedef struct {
    ts_backend requested; /**< after TERRASHADE_BACKEND: AUTO, C or OPENCL */
    ts_backend used;      /**< TS_BACKEND_C or TS_BACKEND_OPENCL */
    char backend[16];     /**< "c" or "opencl" */
    char device[192];     /**< e.g. "pthread-skylake (Portable Computing Language)"
                               or "CPU, 8 cores, AVX-512" */
    int fell_back;        /**< 1: OpenCL was tried and failed, C ran */
    char reason[256];     /**< why OpenCL did not run (fell back, or not chosen) */
} ts_backend_report;

/** "auto", "c" or "opencl". */
const char *ts_backend_name(ts_backend backend);

/** Parse "auto", "c", "opencl" (any case; also "cl", "cpu"... are refused). */
ts_status ts_backend_parse(const char *text, ts_backend *backend, ts_error *err);

/**
 * Decide without computing: which backend a product would run on now.
 * Probes (and on first use builds) the OpenCL device. `report` is filled as
 * a product would fill it; fell_back is set when OpenCL was wanted but is
 * not usable.
 */
ts_status ts_backend_choose(ts_backend requested, ts_backend_report *report,
                            ts_error *err);

ts_status ts_backend_horizon_sweep(ts_backend backend, const ts_grid *grid,
                                   double azimuth, const ts_horizon_opts *opts,
                                   float *out, ts_backend_report *report,
                                   ts_error *err);

/**
 * The sweeps of n azimuths in one call, into n planes of width*height
 * (ts_cl_horizon_sweeps: the DEM uploaded once for all of them); on C,
 * ts_horizon_sweep for each in turn. Plane a is what
 * ts_backend_horizon_sweep gives for azimuth a on the same backend.
 */
ts_status ts_backend_horizon_sweeps(ts_backend backend, const ts_grid *grid,
                                    const double *azimuths, int n, const ts_horizon_opts *opts,
                                    float *out, ts_backend_report *report, ts_error *err);

ts_status ts_backend_horizon_compute(ts_backend backend, const ts_grid *grid,
                                     const ts_horizon_opts *opts, float *out,
                                     ts_backend_report *report, ts_error *err);

ts_status ts_backend_shm_compute(ts_backend backend, const ts_grid *grid,
                                 double azimuth, double elevation,
                                 double penumbra_depth, int threads,
                                 float *visibility, float *shadow_height,
                                 ts_backend_report *report, ts_error *err);

ts_status ts_backend_normals(ts_backend backend, const ts_grid *grid, int threads, float *nx,
                             float *ny, float *nz, ts_backend_report *report,
                             ts_error *err);

ts_status ts_backend_shade_direct(ts_backend backend, const ts_direct_request *req,
                                  ts_backend_report *report, ts_error *err);

/* ts_backend_shade_direct with the normals of req->grid made on the way
 * (req->nx, ny, nz unused): on C without planes of normals
 * (ts_shade_direct_horn), on OpenCL from ts_cl_normals' planes. */
ts_status ts_backend_shade_direct_horn(ts_backend backend, const ts_direct_request *req,
                                       ts_backend_report *report, ts_error *err);

/** ts_shadowmap_compute (terrashade_shadowmap.h). */
ts_status ts_backend_shadowmap_compute(ts_backend backend, const ts_grid *grid,
                                       double azimuth, double elevation,
                                       const ts_shadowmap_opts *opts, float *visibility,
                                       ts_backend_report *report, ts_error *err);

ts_status ts_backend_sky_terms(ts_backend backend, const ts_sky_request *req,
                               ts_backend_report *report, ts_error *err);

/**
 * What a product's environment light keeps between its per-plane calls of
 * ts_backend_env_light_accumulate: the OpenCL session (light table and
 * normals on the device, uploaded once), or, after an OpenCL failure, why
 * the later planes run C. Zero it before the first plane; release it with
 * ts_backend_env_light_release after the last.
 */
typedef struct {
    struct ts_cl_env_light *cl; /**< the OpenCL session, or NULL */
    int failed;                 /**< OpenCL failed: the later planes go to C */
    char reason[256];           /**< the failure */
} ts_backend_env_light;

/**
 * ts_env_light_accumulate (terrashade_env.h) on a backend: add the
 * request's sector light to its r, g, b. `state` (may be NULL: every call
 * then uploads the table) carries the device state from plane to plane; the
 * C fallback carries on from the sums so far, which r, g, b hold after
 * every call.
 */
ts_status ts_backend_env_light_accumulate(ts_backend backend, ts_backend_env_light *state,
                                          const ts_env_light_request *req,
                                          ts_backend_report *report, ts_error *err);

/** Release the device state of `state` (NULL-safe) and zero it. */
void ts_backend_env_light_release(ts_backend_env_light *state);

#ifdef __cplusplus
}
#endif

#endif /* TERRASHADE_BACKEND_H */
