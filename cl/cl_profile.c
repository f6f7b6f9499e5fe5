/*
 * Kernel times for tuning (TERRASHADE_OPENCL_PROFILE=1): the queue is made
 * with profiling on, every launch waits for its event and adds its device
 * time to a per-kernel total, and the totals go to stderr when the process
 * exits. Off by default: waiting after each launch costs the host's latency
 * between kernels, which a plain run does not pay.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cl_internal.h"

#define PROFILE_KERNELS 32

typedef struct {
    char name[48];
    long launches;
    double seconds;
} kernel_total;

static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static kernel_total g_total[PROFILE_KERNELS];
static int g_count;

int ts_cl_profiling(void)
{
    static int known = -1; /* (atomic: every OpenCL job asks, from any thread) */
    int on = __atomic_load_n(&known, __ATOMIC_RELAXED);
    if (on < 0) {
        const char *s = getenv("TERRASHADE_OPENCL_PROFILE");
        on = s && *s && strcmp(s, "0") != 0;
        __atomic_store_n(&known, on, __ATOMIC_RELAXED);
    }
    return on;
}

static void report(void)
{
    pthread_mutex_lock(&g_lock);
    if (g_count > 0)
        fprintf(stderr, "TERRASHADE_OPENCL_PROFILE: device time per kernel, all calls of "
                        "this process\n  %-28s %9s %12s %12s\n",
                "kernel", "launches", "total s", "mean ms");
    for (int i = 0; i < g_count; i++)
        fprintf(stderr, "  %-28s %9ld %12.4f %12.4f\n", g_total[i].name, g_total[i].launches,
                g_total[i].seconds, 1e3 * g_total[i].seconds / (double)g_total[i].launches);
    pthread_mutex_unlock(&g_lock);
}

void ts_cl_profile_add(const char *name, cl_event ev)
{
    cl_ulong t0 = 0, t1 = 0;
    if (clWaitForEvents(1, &ev) != CL_SUCCESS ||
        clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_START, sizeof t0, &t0, NULL) !=
            CL_SUCCESS ||
        clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_END, sizeof t1, &t1, NULL) !=
            CL_SUCCESS)
        return; /* a failed launch reports itself through the job */
    pthread_mutex_lock(&g_lock);
    int i = 0;
    while (i < g_count && strcmp(g_total[i].name, name) != 0)
        i++;
    if (i == g_count && g_count < PROFILE_KERNELS) {
        if (g_count == 0)
            atexit(report);
        snprintf(g_total[i].name, sizeof g_total[i].name, "%s", name);
        g_count++;
    }
    if (i < g_count) {
        g_total[i].launches++;
        g_total[i].seconds += t1 > t0 ? (double)(t1 - t0) * 1e-9 : 0.0;
    }
    pthread_mutex_unlock(&g_lock);
}
