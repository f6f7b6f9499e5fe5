/*
 * Internals of the OpenCL backend: the cached device (context, queue,
 * program) and a "job" that owns the buffers and kernels of one call and
 * keeps its first error, so that the product code reads straight through.
 */
#ifndef TS_CL_INTERNAL_H
#define TS_CL_INTERNAL_H

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include "terrashade_cl.h"

/* A device in use: made once per process by ts_cl_device, never freed. */
typedef struct {
    cl_platform_id platform;
    cl_device_id id;
    cl_context ctx;
    cl_command_queue queue;
    cl_program prog;
    ts_cl_info info;     /* max_alloc: the device's own limit */
    int is_cpu;
    cl_ulong local_mem;
} ts_cl_dev;

/* The device TERRASHADE_OPENCL_DEVICE selects, made and built on first use. */
ts_status ts_cl_device(ts_cl_dev **dev, ts_error *err);

/* "CL_OUT_OF_RESOURCES", ...; "CL error <n>" for unknown codes (static
 * buffer only for those: not re-entrant for unknown codes). */
const char *ts_cl_error_name(cl_int code);

/* The status of an OpenCL error: TS_ERR_NOMEM for device memory, else
 * TS_ERR_INTERNAL. */
ts_status ts_cl_status_of(cl_int e);

/* TERRASHADE_OPENCL_PROFILE is set (and not "0"): queues are made with
 * profiling on and every launch is timed (cl_profile.c). */
int ts_cl_profiling(void);

/* Wait for a launch's event and add its device time to the total of kernel
 * `name`; the totals go to stderr at exit. */
void ts_cl_profile_add(const char *name, cl_event ev);

/* TERRASHADE_OPENCL_MAX_ALLOC in bytes (k, M, G suffixes), 0 when unset. */
ts_status ts_cl_env_max_alloc(unsigned long long *limit, ts_error *err);

#define TS_CL_JOB_MEM 24
#define TS_CL_JOB_KERNELS 4

typedef struct {
    ts_cl_dev *d;
    ts_error *err;
    ts_status st;        /* first failure; later operations do nothing */
    unsigned long long max_alloc; /* largest buffer: the device's limit, or
                                     TERRASHADE_OPENCL_MAX_ALLOC if lower */
    int capped;          /* max_alloc comes from TERRASHADE_OPENCL_MAX_ALLOC */
    unsigned long long budget;    /* device memory one call may use in all */
    cl_mem mem[TS_CL_JOB_MEM];
    int nmem;
    cl_kernel kern[TS_CL_JOB_KERNELS];
    int nkern;
} ts_cl_job;

/* Start a job on the selected device; fails like ts_cl_device. */
ts_status ts_cl_job_begin(ts_cl_job *j, ts_error *err);

/* A device buffer of `bytes` (at least 1), filled from `host` when not
 * NULL. `what` names it in error messages. NULL after a failure. */
cl_mem ts_cl_job_buffer(ts_cl_job *j, cl_mem_flags flags, size_t bytes, const void *host,
                        const char *what);

/* Release a buffer of the job early (to reuse its memory). */
void ts_cl_job_release(ts_cl_job *j, cl_mem m);

cl_kernel ts_cl_job_kernel(ts_cl_job *j, const char *name);

void ts_cl_job_arg(ts_cl_job *j, cl_kernel k, cl_uint index, size_t size, const void *value);

/* One kernel argument: its size and where its value is. */
typedef struct {
    size_t size;
    const void *value;
} ts_cl_arg;

/* The kernel argument held by the lvalue x (a cl_mem, cl_int, cl_float...). */
#define TS_CL_ARG(x) ((ts_cl_arg){sizeof(x), &(x)})

/* The count and the array of ts_cl_job_args from a list of TS_CL_ARGs. */
#define TS_CL_ARGS(...)                                                                        \
    (int)(sizeof((ts_cl_arg[]){__VA_ARGS__}) / sizeof(ts_cl_arg)), (const ts_cl_arg[]){__VA_ARGS__}

/* Kernel arguments first .. first + n - 1 in one call:
 * ts_cl_job_args(j, k, first, TS_CL_ARGS(TS_CL_ARG(a), TS_CL_ARG(b))). */
void ts_cl_job_args(ts_cl_job *j, cl_kernel k, cl_uint first, int n, const ts_cl_arg *args);

/* Work-group size for kernel k: at most `want`, a power of two, within the
 * kernel's and the device's limits. */
size_t ts_cl_job_wg(ts_cl_job *j, cl_kernel k, size_t want);

/* Launch k over global[dims] (rounded up to local by the caller). */
void ts_cl_job_run(ts_cl_job *j, cl_kernel k, cl_uint dims, const size_t *global,
                   const size_t *local, const char *what);

void ts_cl_job_write(ts_cl_job *j, cl_mem m, size_t offset, size_t bytes, const void *src,
                     const char *what);
void ts_cl_job_read(ts_cl_job *j, cl_mem m, size_t offset, size_t bytes, void *dst,
                    const char *what);
void ts_cl_job_fill0(ts_cl_job *j, cl_mem m, size_t bytes, const char *what);

/* Fail the job with a message of our own (not an OpenCL error). */
void ts_cl_job_fail(ts_cl_job *j, ts_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Finish: wait for the queue, release everything; returns the job status
 * (err already filled). */
ts_status ts_cl_job_end(ts_cl_job *j);

/* Round n up to a multiple of m. */
static inline size_t ts_cl_round_up(size_t n, size_t m)
{
    return (n + m - 1) / m * m;
}

/* Size in bytes of a device `real` (double with cl_khr_fp64, else float). */
static inline size_t ts_cl_real_size(const ts_cl_dev *d)
{
    return d->info.fp64 ? sizeof(double) : sizeof(float);
}

/* Store doubles as device reals (in place is not allowed): dst holds n
 * reals of ts_cl_real_size bytes. */
void ts_cl_to_real(const ts_cl_dev *d, void *dst, const double *src, size_t n);

/* Set a `real` kernel argument from a double. */
void ts_cl_job_arg_real(ts_cl_job *j, cl_kernel k, cl_uint index, double value);

#endif
