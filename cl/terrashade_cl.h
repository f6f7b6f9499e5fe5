/*
 * terrashade_cl.h - the OpenCL backend of libterrashade.
 *
 * The same products as the C core (terrashade.h), computed by OpenCL
 * kernels, with the same results: every ts_cl_X is declared with the
 * function type of the C function ts_X (ts_X_fn) and checks its arguments
 * with the same shared checks (core/arg_checks.h), so that both backends
 * accept and refuse the same calls with the same messages.
 * Measured differences to the C backend are in docs/opencl.md.
 *
 * Device: the environment variable TERRASHADE_OPENCL_DEVICE picks it, as a
 * flat index over all devices of all platforms ("0", "1", ...) or as
 * "platform:device" ("1:0"); unset or empty means the first GPU, else the
 * first accelerator, else the first device. ts_cl_devices lists them.
 * TERRASHADE_OPENCL_MAX_ALLOC (bytes, or with a k/M/G suffix) caps the size
 * of any one device buffer below the device's own limit, for a device shared
 * with other programs.
 *
 * Failures: no platform, no device, a bad TERRASHADE_OPENCL_DEVICE, a
 * kernel build failure, a device allocation that fails or is too large, a
 * kernel that fails: the function returns an error whose message names the
 * OpenCL call and the OpenCL error (e.g. "CL_INVALID_BUFFER_SIZE"); nothing
 * crashes and nothing is left allocated. Device memory errors give
 * TS_ERR_NOMEM, the other OpenCL failures TS_ERR_INTERNAL, argument errors
 * TS_ERR_ARG exactly as the C function would. The caller then uses the C
 * backend, which is what the dispatcher of terrashade_backend.h does.
 *
 * Process-wide state: the list of platforms and devices (read once, as the
 * ICD loader reads its vendor files once), and per device that has been used
 * one context, one in-order command queue and one built program. They are
 * made on first use under a mutex (pthread_once / pthread_mutex) and kept
 * until the process exits; this is the only global state of terrashade.
 * Every function is thread-safe: kernels and buffers are per call.
 *
 * Without OpenCL at build time (configure found no CL/cl.h or libOpenCL)
 * the functions exist and return TS_ERR_INTERNAL with the message "OpenCL
 * support was not built".
 */
#ifndef TERRASHADE_CL_H
#define TERRASHADE_CL_H

#include "terrashade.h"
#include "terrashade_shadowmap.h"
#include "terrashade_env.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What an OpenCL device is. */
typedef struct {
    char platform[128];     /**< CL_PLATFORM_NAME */
    char device[128];       /**< CL_DEVICE_NAME */
    char version[96];       /**< CL_DEVICE_VERSION, e.g. "OpenCL 3.0 PoCL ..." */
    char type[16];          /**< "GPU", "CPU", "accelerator" or "other" */
    int index;              /**< flat index (a TERRASHADE_OPENCL_DEVICE value) */
    int platform_index;     /**< platform:device form of the same */
    int device_index;
    int compute_units;      /**< CL_DEVICE_MAX_COMPUTE_UNITS */
    int fp64;               /**< 1: kernels compute in double where the C code does */
    unsigned long long global_mem; /**< bytes */
    unsigned long long max_alloc;  /**< bytes per buffer, after TERRASHADE_OPENCL_MAX_ALLOC */
    size_t max_work_group;  /**< CL_DEVICE_MAX_WORK_GROUP_SIZE */
} ts_cl_info;

/** 1 if the library was built with OpenCL support, else 0. */
int ts_cl_built(void);

/**
 * Select the device (TERRASHADE_OPENCL_DEVICE), make its context, queue and
 * program (first call only) and describe it in *info (may be NULL). TS_OK
 * means the OpenCL functions below can run.
 */
ts_status ts_cl_available(ts_cl_info *info, ts_error *err);

/**
 * The device ts_cl_available would select, described in *info (may be NULL)
 * without making its context, queue or program (no kernel is compiled), and
 * the same errors for a bad TERRASHADE_OPENCL_DEVICE or
 * TERRASHADE_OPENCL_MAX_ALLOC. TS_OK does not promise that making it works.
 */
ts_status ts_cl_peek(ts_cl_info *info, ts_error *err);

/**
 * List every OpenCL device of every platform (nothing is built): up to
 * `max` entries into `list`, the number found into *count.
 */
ts_status ts_cl_devices(ts_cl_info *list, int max, int *count, ts_error *err);

/**
 * The error message of ts_cl_horizon_sweep and ts_cl_horizon_compute for a
 * maximum distance that caps a sweep line (TS_ERR_ARG): the C sweep keeps a
 * sliding-window hull per line there, which the kernel has not. A distance
 * beyond every line's length caps nothing and runs as the unbounded sweep.
 */
#define TS_CL_CAPPED_SWEEP_REASON                                                          \
    "a MAX_DISTANCE sweep runs on the C backend (the OpenCL kernel has no sliding-window " \
    "hull yet)"

/** The horizon sweep on the device (ts_horizon_sweep_fn): one azimuth. */
ts_horizon_sweep_fn ts_cl_horizon_sweep;

/**
 * The horizon sweeps of n azimuths (degrees from north, any value: each is
 * reduced to [0, 360)) in one call: n planes of width*height into `out`,
 * plane a that of azimuth a, each the plane ts_cl_horizon_sweep gives for
 * that azimuth, bit for bit. The DEM is uploaded once and the azimuths'
 * lines launched together (in batches that fit the device), so that a GPU
 * gets enough lines to fill it. opts->directions and start_azimuth are
 * ignored.
 */
ts_status ts_cl_horizon_sweeps(const ts_grid *grid, const double *azimuths, int n,
                               const ts_horizon_opts *opts, float *out, ts_error *err);

/** The horizons on the device (ts_horizon_compute_fn): opts->directions planes. */
ts_horizon_compute_fn ts_cl_horizon_compute;

/** The shadow height map on the device (ts_shm_compute_fn; `threads` is
 * checked, then unused). */
ts_shm_compute_fn ts_cl_shm_compute;

/** The normals on the device (ts_normals_fn). */
ts_normals_fn ts_cl_normals;

/** The direct sun on the device (ts_shade_direct_fn). */
ts_shade_direct_fn ts_cl_shade_direct;

/** ts_shadowmap_compute on the device (cl/cl_shadowmap.c): the same map,
 * rendered with atomic_max, and the same filter. */
ts_shadowmap_compute_fn ts_cl_shadowmap_compute;

/** The sky terms on the device (ts_sky_terms_fn). */
ts_sky_terms_fn ts_cl_sky_terms;

/** The environment light on the device, in one call
 * (ts_env_light_accumulate_fn; uploads the light table and the normals for
 * this one plane: a product uses a session). */
ts_env_light_accumulate_fn ts_cl_env_light_accumulate;

/**
 * A product's environment light on the device, one horizon plane at a time.
 * The device keeps its own copy of the sums: between two calls with the
 * same r, g, b the caller must not change them (new arrays are uploaded).
 * After a failure every later call fails.
 */
typedef struct ts_cl_env_light ts_cl_env_light;

/**
 * Open a session for the request's grid size, light table and normals
 * (the request is checked as ts_env_light_accumulate checks it): uploads
 * the table and the normals once; those arrays must stay as they are until
 * ts_cl_env_light_close.
 */
ts_status ts_cl_env_light_open(const ts_env_light_request *req, ts_cl_env_light **session,
                               ts_error *err);

/** 1 if the session was opened for this request's grid size, table and normals. */
int ts_cl_env_light_matches(const ts_cl_env_light *session, const ts_env_light_request *req);

/**
 * ts_env_light_accumulate in the session, for a request with its grid size,
 * table and normals (else TS_ERR_ARG): uploads the plane, launches, and
 * reads the sums back into r, g, b, so that they hold the light so far
 * after every call.
 */
ts_status ts_cl_env_light_add(ts_cl_env_light *session, const ts_env_light_request *req,
                              ts_error *err);

/** Release the session's device buffers (NULL-safe). */
void ts_cl_env_light_close(ts_cl_env_light *session);

#ifdef __cplusplus
}
#endif

#endif /* TERRASHADE_CL_H */
