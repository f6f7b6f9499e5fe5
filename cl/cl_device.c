/*
 * OpenCL platform and device discovery, device selection, the per-device
 * cache (context, queue, program) and error names; the job helpers are in
 * cl_job.c.
 *
 * Process-wide state, the only in terrashade: the device list (filled once
 * by pthread_once: the ICD loader reads its vendor files once anyway) and
 * the devices made so far (under a mutex; a device is made once and kept
 * until exit, a failure to make it is remembered too). See terrashade_cl.h.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cl_host_guard.h"
#include "cl_internal.h"
#include "status_internal.h"

extern const char *const ts_cl_source[];
extern const size_t ts_cl_source_count;

#define TS_CL_MAX_DEVICES 64

/* ------------------------------------------------------------ error names */

const char *ts_cl_error_name(cl_int code)
{
    switch (code) {
#define E(x) case x: return #x;
    E(CL_SUCCESS) E(CL_DEVICE_NOT_FOUND) E(CL_DEVICE_NOT_AVAILABLE)
    E(CL_COMPILER_NOT_AVAILABLE) E(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    E(CL_OUT_OF_RESOURCES) E(CL_OUT_OF_HOST_MEMORY) E(CL_PROFILING_INFO_NOT_AVAILABLE)
    E(CL_MEM_COPY_OVERLAP) E(CL_IMAGE_FORMAT_MISMATCH) E(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    E(CL_BUILD_PROGRAM_FAILURE) E(CL_MAP_FAILURE) E(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    E(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST) E(CL_COMPILE_PROGRAM_FAILURE)
    E(CL_LINKER_NOT_AVAILABLE) E(CL_LINK_PROGRAM_FAILURE) E(CL_DEVICE_PARTITION_FAILED)
    E(CL_KERNEL_ARG_INFO_NOT_AVAILABLE) E(CL_INVALID_VALUE) E(CL_INVALID_DEVICE_TYPE)
    E(CL_INVALID_PLATFORM) E(CL_INVALID_DEVICE) E(CL_INVALID_CONTEXT)
    E(CL_INVALID_QUEUE_PROPERTIES) E(CL_INVALID_COMMAND_QUEUE) E(CL_INVALID_HOST_PTR)
    E(CL_INVALID_MEM_OBJECT) E(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR) E(CL_INVALID_IMAGE_SIZE)
    E(CL_INVALID_SAMPLER) E(CL_INVALID_BINARY) E(CL_INVALID_BUILD_OPTIONS)
    E(CL_INVALID_PROGRAM) E(CL_INVALID_PROGRAM_EXECUTABLE) E(CL_INVALID_KERNEL_NAME)
    E(CL_INVALID_KERNEL_DEFINITION) E(CL_INVALID_KERNEL) E(CL_INVALID_ARG_INDEX)
    E(CL_INVALID_ARG_VALUE) E(CL_INVALID_ARG_SIZE) E(CL_INVALID_KERNEL_ARGS)
    E(CL_INVALID_WORK_DIMENSION) E(CL_INVALID_WORK_GROUP_SIZE) E(CL_INVALID_WORK_ITEM_SIZE)
    E(CL_INVALID_GLOBAL_OFFSET) E(CL_INVALID_EVENT_WAIT_LIST) E(CL_INVALID_EVENT)
    E(CL_INVALID_OPERATION) E(CL_INVALID_GL_OBJECT) E(CL_INVALID_BUFFER_SIZE)
    E(CL_INVALID_MIP_LEVEL) E(CL_INVALID_GLOBAL_WORK_SIZE) E(CL_INVALID_PROPERTY)
    E(CL_INVALID_IMAGE_DESCRIPTOR) E(CL_INVALID_COMPILER_OPTIONS) E(CL_INVALID_LINKER_OPTIONS)
    E(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef E
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    case -9999: return "CL_INVALID_COMMAND (device fault)";
    }
    return "unknown OpenCL error";
}

ts_status ts_cl_status_of(cl_int e)
{
    switch (e) {
    case CL_MEM_OBJECT_ALLOCATION_FAILURE:
    case CL_OUT_OF_RESOURCES:
    case CL_OUT_OF_HOST_MEMORY:
    case CL_INVALID_BUFFER_SIZE:
        return TS_ERR_NOMEM;
    default:
        return TS_ERR_INTERNAL;
    }
}

/* ------------------------------------------------------------- discovery */

typedef struct {
    cl_platform_id platform;
    cl_device_id id;
    int p, d;
} dev_ref;

static struct {
    cl_int err;          /* CL_SUCCESS, or why there is no device */
    const char *call;
    int ndev;
    dev_ref dev[TS_CL_MAX_DEVICES];
} g_list;
static pthread_once_t g_list_once = PTHREAD_ONCE_INIT;

static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static ts_cl_dev *g_dev[TS_CL_MAX_DEVICES];
static ts_error g_dev_fail[TS_CL_MAX_DEVICES]; /* code != OK: making it failed */

static atomic_int g_discovered; /* discover() has run: no thread needed */

static void discover(void)
{
    cl_uint np = 0;
    cl_platform_id plat[16];
    cl_int e = clGetPlatformIDs(16, plat, &np);
    g_list.call = "clGetPlatformIDs";
    if (e != CL_SUCCESS) {
        g_list.err = e;
        return;
    }
    if (np > 16)
        np = 16;
    for (cl_uint p = 0; p < np; p++) {
        cl_uint nd = 0;
        cl_device_id ids[TS_CL_MAX_DEVICES];
        e = clGetDeviceIDs(plat[p], CL_DEVICE_TYPE_ALL, TS_CL_MAX_DEVICES, ids, &nd);
        if (e != CL_SUCCESS)
            continue; /* CL_DEVICE_NOT_FOUND: a platform without devices */
        if (nd > TS_CL_MAX_DEVICES)
            nd = TS_CL_MAX_DEVICES;
        for (cl_uint d = 0; d < nd && g_list.ndev < TS_CL_MAX_DEVICES; d++)
            g_list.dev[g_list.ndev++] = (dev_ref){plat[p], ids[d], (int)p, (int)d};
    }
    if (g_list.ndev == 0) {
        g_list.err = CL_DEVICE_NOT_FOUND;
        g_list.call = "clGetDeviceIDs";
    }
}

static void fill_info(const dev_ref *r, int index, ts_cl_info *info)
{
    memset(info, 0, sizeof *info);
    clGetPlatformInfo(r->platform, CL_PLATFORM_NAME, sizeof info->platform - 1, info->platform,
                      NULL);
    clGetDeviceInfo(r->id, CL_DEVICE_NAME, sizeof info->device - 1, info->device, NULL);
    clGetDeviceInfo(r->id, CL_DEVICE_VERSION, sizeof info->version - 1, info->version, NULL);
    cl_device_type type = 0;
    clGetDeviceInfo(r->id, CL_DEVICE_TYPE, sizeof type, &type, NULL);
    snprintf(info->type, sizeof info->type, "%s",
             (type & CL_DEVICE_TYPE_GPU)           ? "GPU"
             : (type & CL_DEVICE_TYPE_ACCELERATOR) ? "accelerator"
             : (type & CL_DEVICE_TYPE_CPU)         ? "CPU"
                                                   : "other");
    info->index = index;
    info->platform_index = r->p;
    info->device_index = r->d;
    cl_uint cu = 0;
    clGetDeviceInfo(r->id, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
    info->compute_units = (int)cu;
    cl_device_fp_config fp = 0;
    clGetDeviceInfo(r->id, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp, &fp, NULL);
    info->fp64 = fp != 0;
    cl_ulong gm = 0, ma = 0;
    clGetDeviceInfo(r->id, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof gm, &gm, NULL);
    clGetDeviceInfo(r->id, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof ma, &ma, NULL);
    info->global_mem = gm;
    info->max_alloc = ma;
    size_t wg = 0;
    clGetDeviceInfo(r->id, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof wg, &wg, NULL);
    info->max_work_group = wg;
}

ts_status ts_cl_env_max_alloc(unsigned long long *limit, ts_error *err)
{
    *limit = 0;
    const char *s = getenv("TERRASHADE_OPENCL_MAX_ALLOC");
    if (!s || !*s)
        return TS_OK;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    double mul = 1;
    if (*end == 'k' || *end == 'K')
        mul = 1024.0, end++;
    else if (*end == 'm' || *end == 'M')
        mul = 1024.0 * 1024, end++;
    else if (*end == 'g' || *end == 'G')
        mul = 1024.0 * 1024 * 1024, end++;
    const char *digits = s;
    while (isspace((unsigned char)*digits))
        digits++;
    digits += *digits == '+' || *digits == '-';
    const int hex = digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X');
    while (isspace((unsigned char)*end)) /* trailing spaces, as leading ones */
        end++;
    const double bytes = v * mul; /* 0.5M is half a megabyte */
    /* below 2^63: beyond, the conversion to a count of bytes is undefined */
    if (end == s || *end || errno || hex || !isfinite(bytes) || !(bytes >= 1) ||
        !(bytes < 9.2e18))
        return ts_fail(err, TS_ERR_ARG,
                    "TERRASHADE_OPENCL_MAX_ALLOC must be a number of bytes from 1 to 8E "
                    "(decimal, k, M, G suffixes allowed), got '%.60s'",
                    s);
    *limit = (unsigned long long)bytes;
    return TS_OK;
}

/* Which device: TERRASHADE_OPENCL_DEVICE, or the first GPU, accelerator,
 * device. Call after discovery succeeded. */
static ts_status select_device(int *index, ts_error *err)
{
    const char *s = getenv("TERRASHADE_OPENCL_DEVICE");
    while (s && isspace((unsigned char)*s))
        s++;
    if (!s || !*s) {
        int best = 0, rank = 3;
        for (int i = 0; i < g_list.ndev; i++) {
            cl_device_type t = 0;
            clGetDeviceInfo(g_list.dev[i].id, CL_DEVICE_TYPE, sizeof t, &t, NULL);
            int r = (t & CL_DEVICE_TYPE_GPU) ? 0 : (t & CL_DEVICE_TYPE_ACCELERATOR) ? 1 : 2;
            if (r < rank) {
                rank = r;
                best = i;
            }
        }
        *index = best;
        return TS_OK;
    }
    char *end;
    long a = strtol(s, &end, 10);
    int found = -1;
    if (end != s && a >= 0 && (*end == '\0' || isspace((unsigned char)*end))) {
        if (a < g_list.ndev)
            found = (int)a;
    } else if (end != s && a >= 0 && *end == ':') {
        const char *t = end + 1;
        long b = strtol(t, &end, 10);
        if (end == t || b < 0 || (*end && !isspace((unsigned char)*end)))
            goto bad;
        for (int i = 0; i < g_list.ndev; i++)
            if (g_list.dev[i].p == a && g_list.dev[i].d == b)
                found = i;
    } else {
        goto bad;
    }
    if (found < 0) {
        char name[96] = "";
        clGetDeviceInfo(g_list.dev[0].id, CL_DEVICE_NAME, sizeof name - 1, name, NULL);
        return ts_fail(err, TS_ERR_INTERNAL,
                    "TERRASHADE_OPENCL_DEVICE=%.40s: no such OpenCL device; there %s %d "
                    "(0 = platform 0 device 0: %.60s)",
                    s, g_list.ndev == 1 ? "is" : "are", g_list.ndev, name);
    }
    *index = found;
    return TS_OK;
bad:
    return ts_fail(err, TS_ERR_INTERNAL,
                "TERRASHADE_OPENCL_DEVICE must be a device index (0, 1, ...) or "
                "platform:device (e.g. 0:1), got '%.40s'",
                s);
}

static void *discover_once(void *unused)
{
    (void)unused;
    pthread_once(&g_list_once, discover);
    atomic_store_explicit(&g_discovered, 1, memory_order_release);
    return NULL;
}

static ts_status list_ready(ts_error *err)
{
    if (ts_cl_host_forked())
        return ts_fail(err, TS_ERR_INTERNAL,
                       "OpenCL was set up in the parent of this process before the fork that "
                       "made it, and its drivers' threads stayed there: OpenCL cannot run "
                       "here (use BACKEND=c in forked children, or start them with spawn)");
    if (!atomic_load_explicit(&g_discovered, memory_order_acquire))
        ts_cl_host_call(discover_once, NULL); /* (cl_host_guard.h) */
    if (g_list.err != CL_SUCCESS) {
        if (g_list.err == -1001 || (g_list.err == CL_DEVICE_NOT_FOUND && g_list.ndev == 0))
            return ts_fail(err, TS_ERR_INTERNAL,
                        "no OpenCL %s found (%s: %s); check the ICD files in "
                        "/etc/OpenCL/vendors or OCL_ICD_VENDORS",
                        g_list.err == -1001 ? "platform" : "device", g_list.call,
                        ts_cl_error_name(g_list.err));
        return ts_fail(err, ts_cl_status_of(g_list.err), "OpenCL %s failed: %s", g_list.call,
                    ts_cl_error_name(g_list.err));
    }
    return TS_OK;
}

/* Make context, queue and program for device i; on failure err is set. */
static ts_cl_dev *make_device(int i, ts_error *err)
{
    const dev_ref *r = &g_list.dev[i];
    ts_cl_dev *d = calloc(1, sizeof *d);
    if (!d) {
        ts_fail(err, TS_ERR_NOMEM, "cannot allocate the OpenCL device record");
        return NULL;
    }
    d->platform = r->platform;
    d->id = r->id;
    fill_info(r, i, &d->info);
    const char *fp = getenv("TERRASHADE_OPENCL_FP64");
    if (fp && !strcmp(fp, "0"))
        d->info.fp64 = 0;
    cl_device_type type = 0;
    clGetDeviceInfo(r->id, CL_DEVICE_TYPE, sizeof type, &type, NULL);
    d->is_cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
    clGetDeviceInfo(r->id, CL_DEVICE_LOCAL_MEM_SIZE, sizeof d->local_mem, &d->local_mem, NULL);

    cl_int e;
    const char *call = "clCreateContext";
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)r->platform, 0};
    d->ctx = clCreateContext(props, 1, &r->id, NULL, NULL, &e);
    if (e == CL_SUCCESS) {
        call = "clCreateCommandQueue";
        d->queue = clCreateCommandQueue(
            d->ctx, r->id, ts_cl_profiling() ? CL_QUEUE_PROFILING_ENABLE : 0, &e);
    }
    if (e == CL_SUCCESS) {
        call = "clCreateProgramWithSource";
        d->prog = clCreateProgramWithSource(d->ctx, (cl_uint)ts_cl_source_count,
                                            (const char **)ts_cl_source, NULL, &e);
    }
    if (e == CL_SUCCESS) {
        call = "clBuildProgram";
        char opts[512];
        char cver[64] = "";
        clGetDeviceInfo(r->id, CL_DEVICE_OPENCL_C_VERSION, sizeof cver - 1, cver, NULL);
        int major = 0, minor = 0;
        sscanf(cver, "OpenCL C %d.%d", &major, &minor);
        cl_device_fp_config sp = 0;
        clGetDeviceInfo(r->id, CL_DEVICE_SINGLE_FP_CONFIG, sizeof sp, &sp, NULL);
        /* TS_NEAR_* come with the embedded core/cellmath/cm_near_field.h */
        /* TERRASHADE_OPENCL_BUILD_OPTIONS: kernel variants for tuning (the
         * TS_* macros the .cl files test with #ifndef) */
        const char *extra = getenv("TERRASHADE_OPENCL_BUILD_OPTIONS");
        if (extra && strlen(extra) > 200) {
            ts_fail(err, TS_ERR_ARG,
                    "TERRASHADE_OPENCL_BUILD_OPTIONS is %zu characters long, more than the "
                    "200 the kernels' build options have room for",
                    strlen(extra));
            goto failed;
        }
        snprintf(opts, sizeof opts, "%s%s%s %s",
                 (major > 1 || (major == 1 && minor >= 2)) ? "-cl-std=CL1.2 " : "",
                 d->info.fp64 ? "-DTS_FP64=1 " : "",
                 (sp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT)
                     ? "-cl-fp32-correctly-rounded-divide-sqrt"
                     : "",
                 extra ? extra : "");
        e = clBuildProgram(d->prog, 1, &r->id, opts, NULL, NULL);
        if (e == CL_SUCCESS && getenv("TERRASHADE_OPENCL_VERBOSE")) {
            char log[4096] = "";
            clGetProgramBuildInfo(d->prog, r->id, CL_PROGRAM_BUILD_LOG, sizeof log - 1, log,
                                  NULL);
            fprintf(stderr, "terrashade: OpenCL kernels built on %s with '%s'%s%s\n",
                    d->info.device, opts, log[0] ? ", log:\n" : "", log);
        }
        if (e != CL_SUCCESS) {
            char log[4096] = "";
            clGetProgramBuildInfo(d->prog, r->id, CL_PROGRAM_BUILD_LOG, sizeof log - 1, log,
                                  NULL);
            if (getenv("TERRASHADE_OPENCL_VERBOSE"))
                fprintf(stderr, "terrashade: OpenCL build log for %s:\n%s\n", d->info.device,
                        log);
            /* first error line of the log */
            char *l = strstr(log, "error");
            if (!l)
                l = log;
            l[strcspn(l, "\n")] = '\0';
            ts_fail(err, TS_ERR_INTERNAL,
                 "OpenCL kernels failed to build on %.60s (%s): %.120s", d->info.device,
                 ts_cl_error_name(e), l);
            goto failed;
        }
    }
    if (e != CL_SUCCESS) {
        ts_fail(err, ts_cl_status_of(e), "OpenCL %s failed on %.60s: %s", call, d->info.device,
             ts_cl_error_name(e));
        goto failed;
    }
    return d;
failed:
    if (d->prog)
        clReleaseProgram(d->prog);
    if (d->queue)
        clReleaseCommandQueue(d->queue);
    if (d->ctx)
        clReleaseContext(d->ctx);
    free(d);
    return NULL;
}

typedef struct {
    int index;
    ts_cl_dev *made;
    ts_error err;
} make_call;

static void *make_device_call(void *arg)
{
    make_call *c = arg;
    c->made = make_device(c->index, &c->err);
    return NULL;
}

ts_status ts_cl_device(ts_cl_dev **dev, ts_error *err)
{
    *dev = NULL;
    ts_status st = list_ready(err);
    if (st != TS_OK)
        return st;
    int i = 0;
    if ((st = select_device(&i, err)) != TS_OK)
        return st;
    pthread_mutex_lock(&g_lock);
    if (!g_dev[i] && g_dev_fail[i].code == TS_OK) {
        make_call c = {i, NULL, {0}};
        ts_cl_host_call(make_device_call, &c);
        g_dev[i] = c.made;
        if (!g_dev[i])
            g_dev_fail[i] =
                c.err.code != TS_OK ? c.err : (ts_error){TS_ERR_INTERNAL, "OpenCL failure"};
    }
    ts_cl_dev *d = g_dev[i];
    ts_error f = g_dev_fail[i];
    pthread_mutex_unlock(&g_lock);
    if (!d) {
        if (err)
            *err = f;
        return f.code;
    }
    *dev = d;
    return ts_ok(err);
}

int ts_cl_built(void)
{
    return 1;
}

/* *info = *dev (if info is given), its max_alloc capped by
 * TERRASHADE_OPENCL_MAX_ALLOC. */
static ts_status report_info(const ts_cl_info *dev, ts_cl_info *info, ts_error *err)
{
    unsigned long long cap;
    ts_status st = ts_cl_env_max_alloc(&cap, err);
    if (st != TS_OK)
        return st;
    if (info) {
        *info = *dev;
        if (cap && cap < info->max_alloc)
            info->max_alloc = cap;
    }
    return ts_ok(err);
}

ts_status ts_cl_available(ts_cl_info *info, ts_error *err)
{
    ts_cl_dev *d;
    ts_status st = ts_cl_device(&d, err);
    return st != TS_OK ? st : report_info(&d->info, info, err);
}

ts_status ts_cl_peek(ts_cl_info *info, ts_error *err)
{
    ts_status st = list_ready(err);
    int i = 0;
    if (st != TS_OK || (st = select_device(&i, err)) != TS_OK)
        return st;
    ts_cl_info listed;
    fill_info(&g_list.dev[i], i, &listed);
    return report_info(&listed, info, err);
}

ts_status ts_cl_devices(ts_cl_info *list, int max, int *count, ts_error *err)
{
    if (!count || (max > 0 && !list))
        return ts_fail(err, TS_ERR_ARG, "device list or count is NULL");
    *count = 0;
    ts_status st = list_ready(err);
    if (st != TS_OK)
        return st;
    *count = g_list.ndev;
    for (int i = 0; i < g_list.ndev && i < max; i++)
        fill_info(&g_list.dev[i], i, &list[i]);
    return ts_ok(err);
}
