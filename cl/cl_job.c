/*
 * The job of one OpenCL call (cl_internal.h): its buffers and kernels, its
 * first error, the launch and transfer helpers the product code uses.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cl_internal.h"
#include "status_internal.h"

/* ------------------------------------------------------------------ jobs */

/* "12.3 MiB", or "4096 bytes" below a MiB. */
static const char *size_text(char *buf, size_t n, unsigned long long bytes)
{
    if (bytes >= (1ull << 20))
        snprintf(buf, n, "%.1f MiB", bytes / 1048576.0);
    else
        snprintf(buf, n, "%llu bytes", bytes);
    return buf;
}

static void job_cl_fail(ts_cl_job *j, cl_int e, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static void job_cl_fail(ts_cl_job *j, cl_int e, const char *fmt, ...)
{
    if (j->st != TS_OK)
        return;
    char what[128];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    j->st = ts_fail(j->err, ts_cl_status_of(e), "OpenCL %s failed on %.60s: %s", what,
                 j->d ? j->d->info.device : "?", ts_cl_error_name(e));
}

void ts_cl_job_fail(ts_cl_job *j, ts_status code, const char *fmt, ...)
{
    if (j->st != TS_OK)
        return;
    if (j->err) {
        va_list ap;
        va_start(ap, fmt);
        j->err->code = code;
        vsnprintf(j->err->message, sizeof j->err->message, fmt, ap);
        va_end(ap);
    }
    j->st = code;
}

ts_status ts_cl_job_begin(ts_cl_job *j, ts_error *err)
{
    memset(j, 0, sizeof *j);
    j->err = err;
    ts_status st = ts_cl_device(&j->d, err);
    if (st == TS_OK) {
        unsigned long long cap;
        st = ts_cl_env_max_alloc(&cap, err);
        j->max_alloc = j->d->info.max_alloc;
        j->capped = 0;
        if (st == TS_OK && cap && cap < j->max_alloc) {
            j->max_alloc = cap;
            j->capped = 1;
        }
        /* Half the device memory for one call, at most. */
        j->budget = j->d->info.global_mem / 2;
        if (j->budget < j->max_alloc)
            j->budget = j->max_alloc;
    }
    j->st = st;
    return st;
}

cl_mem ts_cl_job_buffer(ts_cl_job *j, cl_mem_flags flags, size_t bytes, const void *host,
                        const char *what)
{
    if (j->st != TS_OK)
        return NULL;
    if (j->nmem >= TS_CL_JOB_MEM) {
        ts_cl_job_fail(j, TS_ERR_INTERNAL, "OpenCL job has too many buffers");
        return NULL;
    }
    size_t host_bytes = bytes; /* what `host` holds: never read past it */
    if (bytes < 16)
        bytes = 16;
    /* Over the TERRASHADE_OPENCL_MAX_ALLOC cap: refused here. Over the
     * device's own limit: clCreateBuffer says so (CL_INVALID_BUFFER_SIZE). */
    if (j->capped && bytes > j->max_alloc) {
        char a[32], b[32];
        ts_cl_job_fail(j, TS_ERR_NOMEM,
                       "OpenCL clCreateBuffer (%s, %s) refused on %.60s: larger than the "
                       "TERRASHADE_OPENCL_MAX_ALLOC limit of %s (CL_INVALID_BUFFER_SIZE)",
                       what, size_text(a, sizeof a, bytes), j->d->info.device,
                       size_text(b, sizeof b, j->max_alloc));
        return NULL;
    }
    cl_int e;
    cl_mem m = clCreateBuffer(j->d->ctx, flags, bytes, NULL, &e);
    if (e != CL_SUCCESS) {
        char a[32];
        job_cl_fail(j, e, "clCreateBuffer (%s, %s)", what, size_text(a, sizeof a, bytes));
        return NULL;
    }
    j->mem[j->nmem++] = m;
    if (host)
        ts_cl_job_write(j, m, 0, host_bytes, host, what);
    return j->st == TS_OK ? m : NULL;
}

void ts_cl_job_release(ts_cl_job *j, cl_mem m)
{
    for (int i = 0; i < j->nmem; i++)
        if (j->mem[i] == m) {
            clReleaseMemObject(m);
            j->mem[i] = j->mem[--j->nmem];
            return;
        }
}

cl_kernel ts_cl_job_kernel(ts_cl_job *j, const char *name)
{
    if (j->st != TS_OK)
        return NULL;
    if (j->nkern >= TS_CL_JOB_KERNELS) {
        ts_cl_job_fail(j, TS_ERR_INTERNAL, "OpenCL job has too many kernels");
        return NULL;
    }
    cl_int e;
    cl_kernel k = clCreateKernel(j->d->prog, name, &e);
    if (e != CL_SUCCESS) {
        job_cl_fail(j, e, "clCreateKernel (%s)", name);
        return NULL;
    }
    j->kern[j->nkern++] = k;
    return k;
}

void ts_cl_job_arg(ts_cl_job *j, cl_kernel k, cl_uint index, size_t size, const void *value)
{
    if (j->st != TS_OK)
        return;
    cl_int e = clSetKernelArg(k, index, size, value);
    if (e != CL_SUCCESS)
        job_cl_fail(j, e, "clSetKernelArg (argument %u)", index);
}

void ts_cl_job_args(ts_cl_job *j, cl_kernel k, cl_uint first, int n, const ts_cl_arg *args)
{
    for (int i = 0; i < n; i++)
        ts_cl_job_arg(j, k, first + (cl_uint)i, args[i].size, args[i].value);
}

void ts_cl_job_arg_real(ts_cl_job *j, cl_kernel k, cl_uint index, double value)
{
    if (j->st != TS_OK)
        return;
    if (j->d->info.fp64) {
        ts_cl_job_arg(j, k, index, sizeof(double), &value);
    } else {
        float f = (float)value;
        ts_cl_job_arg(j, k, index, sizeof(float), &f);
    }
}

size_t ts_cl_job_wg(ts_cl_job *j, cl_kernel k, size_t want)
{
    if (j->st != TS_OK)
        return 1;
    size_t kmax = 0;
    cl_int e = clGetKernelWorkGroupInfo(k, j->d->id, CL_KERNEL_WORK_GROUP_SIZE, sizeof kmax,
                                        &kmax, NULL);
    if (e != CL_SUCCESS) {
        job_cl_fail(j, e, "clGetKernelWorkGroupInfo");
        return 1;
    }
    size_t lim = j->d->info.max_work_group;
    if (kmax && kmax < lim)
        lim = kmax;
    size_t wg = 1;
    while (wg * 2 <= want && wg * 2 <= lim)
        wg *= 2;
    return wg;
}

void ts_cl_job_run(ts_cl_job *j, cl_kernel k, cl_uint dims, const size_t *global,
                   const size_t *local, const char *what)
{
    if (j->st != TS_OK)
        return;
    for (cl_uint i = 0; i < dims; i++)
        if (global[i] == 0)
            return; /* nothing to do */
    cl_event ev = NULL;
    cl_int e = clEnqueueNDRangeKernel(j->d->queue, k, dims, NULL, global, local, 0, NULL,
                                      ts_cl_profiling() ? &ev : NULL);
    if (e != CL_SUCCESS)
        job_cl_fail(j, e, "clEnqueueNDRangeKernel (%s)", what);
    if (ev) {
        ts_cl_profile_add(what, ev);
        clReleaseEvent(ev);
    }
}

void ts_cl_job_write(ts_cl_job *j, cl_mem m, size_t offset, size_t bytes, const void *src,
                     const char *what)
{
    if (j->st != TS_OK || bytes == 0)
        return;
    cl_int e = clEnqueueWriteBuffer(j->d->queue, m, CL_TRUE, offset, bytes, src, 0, NULL, NULL);
    if (e != CL_SUCCESS)
        job_cl_fail(j, e, "clEnqueueWriteBuffer (%s)", what);
}

void ts_cl_job_read(ts_cl_job *j, cl_mem m, size_t offset, size_t bytes, void *dst,
                    const char *what)
{
    if (j->st != TS_OK || bytes == 0)
        return;
    cl_int e = clEnqueueReadBuffer(j->d->queue, m, CL_TRUE, offset, bytes, dst, 0, NULL, NULL);
    if (e != CL_SUCCESS)
        job_cl_fail(j, e, "clEnqueueReadBuffer (%s)", what);
}

void ts_cl_job_fill0(ts_cl_job *j, cl_mem m, size_t bytes, const char *what)
{
    if (j->st != TS_OK || bytes == 0)
        return;
    float zero = 0.0f;
    cl_int e = clEnqueueFillBuffer(j->d->queue, m, &zero, sizeof zero, 0, bytes, 0, NULL, NULL);
    if (e != CL_SUCCESS)
        job_cl_fail(j, e, "clEnqueueFillBuffer (%s)", what);
}

ts_status ts_cl_job_end(ts_cl_job *j)
{
    if (j->d) {
        cl_int e = clFinish(j->d->queue);
        if (e != CL_SUCCESS)
            job_cl_fail(j, e, "clFinish");
    }
    for (int i = 0; i < j->nkern; i++)
        clReleaseKernel(j->kern[i]);
    for (int i = 0; i < j->nmem; i++)
        clReleaseMemObject(j->mem[i]);
    j->nkern = j->nmem = 0;
    if (j->st == TS_OK)
        ts_ok(j->err);
    return j->st;
}

void ts_cl_to_real(const ts_cl_dev *d, void *dst, const double *src, size_t n)
{
    if (d->info.fp64) {
        memcpy(dst, src, n * sizeof(double));
    } else {
        float *f = dst;
        for (size_t i = 0; i < n; i++)
            f[i] = (float)src[i];
    }
}
