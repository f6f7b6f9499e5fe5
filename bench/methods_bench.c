/*
 * methods_bench: the approximate horizon methods against the exact sweep,
 * error and time side by side (docs/methods.md).
 *
 *   methods_bench [--size N] [--dirs D] [--threads T] [--level-step K]
 *                 [--offset O] [--dems jacksboro,lux_elev,fractal] [--cpu | --user]
 *
 * For each DEM (the real ones of tests/data, and an N x N fractal: fBm
 * value noise, Hurst 0.8, 1500 m relief, 10 m cells, as ts_bench) it
 * computes the D horizon planes with the exact sweep and with the pyramid
 * (level step K, offset O) read both ways (the B-spline in log distance,
 * and the maximum over levels), one direction at a time, and prints for
 * each pyramid: the median and p99 of |pyramid - exact| horizon angle over
 * every cell and direction, the same of the sky-view factor (radiative,
 * SVF_MODEL's default), the time of each svf (horizons plus accumulation;
 * the pyramid's build included) on the C backend, and the memory each
 * keeps besides the DEM and the output. Times are wall-clock seconds, or
 * with --cpu the process's CPU seconds, with --user its user CPU seconds
 * (each method's kernel CPU seconds printed beside); the outputs' pages are touched
 * before any timing, so that no method pays for the kernel's first mapping
 * of them.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <time.h>

#include "bench_pages.h"
#include "terrashade.h"
#include "test_dem.h"

/* --cpu: the process's CPU time (user and kernel) instead of the wall
 * clock, steadier than wall time on a shared machine (with --threads 1,
 * one core's time); --user: its user time only, which leaves out the
 * kernel's work for the process, mostly the first mapping of each page it
 * allocates (docs/performance-history.md: on the development VM that cost 4-23 us
 * a page, depending on how long ago the host last backed the page). Every
 * method's kernel time is printed beside it in any mode. */
enum { TIME_WALL, TIME_CPU, TIME_USER };
static int timer = TIME_WALL;

static double tv_sec(struct timeval t)
{
    return t.tv_sec + t.tv_usec * 1e-6;
}

static double now(void)
{
    if (timer == TIME_USER) {
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        return tv_sec(ru.ru_utime);
    }
    struct timespec ts;
    clock_gettime(timer == TIME_CPU ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* The process's kernel CPU seconds so far. */
static double kernel_now(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return tv_sec(ru.ru_stime);
}

static void die(const char *what, const ts_error *e)
{
    fprintf(stderr, "methods_bench: %s: %s\n", what, e->message);
    exit(1);
}

/* |error| histogram: median and p99 without keeping every value. */
#define BINS 200000
typedef struct {
    double width; /* bin width */
    long *count;
    long n;
    double max;
} hist;

static void hist_init(hist *h, double width)
{
    h->width = width;
    h->count = calloc(BINS, sizeof *h->count);
    h->n = 0;
    h->max = 0;
    if (!h->count) {
        fprintf(stderr, "methods_bench: out of memory\n");
        exit(1);
    }
}

static void hist_add(hist *h, double e)
{
    long b = (long)(e / h->width);
    h->count[b < BINS - 1 ? b : BINS - 1]++;
    h->n++;
    h->max = e > h->max ? e : h->max;
}

/* The upper edge of the bin holding quantile q. */
static double hist_quantile(const hist *h, double q)
{
    long want = (long)ceil(q * h->n), seen = 0;
    for (long b = 0; b < BINS; b++)
        if ((seen += h->count[b]) >= want && want > 0)
            return (b + 1) * h->width;
    return h->max;
}

typedef struct {
    int dirs, threads;
    ts_pyramid_opts pyr;
} setup;

/* One method's errors against exact and time. */
typedef struct {
    hist hor, svf;
    double t, t_build, t_kernel; /* t_kernel: kernel CPU seconds within t */
    float *plane, *svf_acc;
    ts_pyramid *pyr;
} method;

typedef struct {
    method m[3]; /* exact, pyramid B-spline, pyramid max over levels */
    double bytes_pyramid;
} result;

static const char *const NAMES[3] = {"exact", "pyramid (B-spline)", "pyramid (level max)"};

/* Directions az[0..count) of method i into its planes and svf
 * accumulator: the sweep one at a time, the pyramid count at once (as the
 * driver does, the svf summed as the rows are done). */
static void run_method(int i, method *m, const ts_grid *g, const float *nx, const float *ny,
                       const float *nz, int count, const double *az, const ts_horizon_opts *o,
                       int dirs)
{
    ts_error err;
    size_t cells = (size_t)g->width * g->height;
    float *planes[TS_PYRAMID_BATCH];
    for (int k = 0; k < count; k++)
        planes[k] = m->plane + cells * k;
    double t0 = now(), k0 = kernel_now();
    ts_status st = TS_OK;
    if (i == 0)
        for (int k = 0; st == TS_OK && k < count; k++)
            st = ts_horizon_sweep(g, az[k], o, planes[k], &err);
    else {
        /* the svf summed row by row as the pyramid writes them */
        ts_pyramid_sky sky = {nx, ny, nz, dirs, TS_SVF_RADIATIVE, m->svf_acc, NULL, NULL};
        st = ts_pyramid_horizons_sky(m->pyr, count, az, o, &sky, planes, &err);
    }
    for (int k = 0; st == TS_OK && i == 0 && k < count; k++)
        st = ts_sky_accumulate(g, nx, ny, nz, planes[k], az[k], dirs, m->svf_acc, NULL, NULL,
                               &err);
    if (st != TS_OK)
        die(NAMES[i], &err);
    m->t += now() - t0;
    m->t_kernel += kernel_now() - k0;
}

/* Every method over every direction of g; errors and times into r. */
static void compare(const ts_grid *g, const setup *su, result *r)
{
    size_t n = (size_t)g->width * g->height;
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = su->dirs;
    o.threads = su->threads;
    ts_error err;
    float *nx = malloc(n * sizeof *nx), *ny = malloc(n * sizeof *ny), *nz = malloc(n * sizeof *nz);
    if (!nx || !ny || !nz) {
        fprintf(stderr, "methods_bench: out of memory\n");
        exit(1);
    }
    if (ts_normals(g, nx, ny, nz, &err) != TS_OK)
        die("normals", &err);
    for (int i = 0; i < 3; i++) {
        method *m = &r->m[i];
        memset(m, 0, sizeof *m);
        hist_init(&m->hor, 1e-3);
        hist_init(&m->svf, 1e-6);
        m->plane = malloc(n * TS_PYRAMID_BATCH * sizeof(float));
        m->svf_acc = malloc(n * sizeof(float));
        if (!m->plane || !m->svf_acc) {
            fprintf(stderr, "methods_bench: out of memory\n");
            exit(1);
        }
        /* each method's 0.5 GiB of planes mapped before any timing, not by
         * whichever method writes them first (bench_pages.h) */
        bench_touch_pages(m->plane, n * TS_PYRAMID_BATCH * sizeof(float));
        bench_touch_pages(m->svf_acc, n * sizeof(float));
        memset(m->svf_acc, 0, n * sizeof(float));
        if (i == 0)
            continue;
        ts_pyramid_opts po = su->pyr;
        po.reconstruction = i == 1 ? TS_PYRAMID_BSPLINE : TS_PYRAMID_LEVEL_MAX;
        double t0 = now(), k0 = kernel_now();
        if (ts_pyramid_build(g, &po, su->threads, &m->pyr, &err) != TS_OK)
            die("pyramid", &err);
        m->t = m->t_build = now() - t0;
        m->t_kernel = kernel_now() - k0;
    }
    r->bytes_pyramid = ts_pyramid_bytes(g->width, g->height, su->pyr.level_step);
    for (int k = 0; k < su->dirs; k += TS_PYRAMID_BATCH) {
        int count = su->dirs - k < TS_PYRAMID_BATCH ? su->dirs - k : TS_PYRAMID_BATCH;
        double az[TS_PYRAMID_BATCH];
        for (int b = 0; b < count; b++)
            az[b] = ts_horizon_azimuth(&o, k + b);
        for (int i = 0; i < 3; i++)
            run_method(i, &r->m[i], g, nx, ny, nz, count, az, &o, su->dirs);
        const float *pe = r->m[0].plane;
        for (int i = 1; i < 3; i++)
            for (size_t c = 0; c < n * count; c++)
                if (pe[c] == pe[c] && r->m[i].plane[c] == r->m[i].plane[c])
                    hist_add(&r->m[i].hor, fabs((double)pe[c] - r->m[i].plane[c]));
    }
    for (int i = 0; i < 3; i++) {
        double t0 = now(), k0 = kernel_now();
        if (ts_sky_finish(g, su->dirs, r->m[i].svf_acc, NULL, NULL, &err) != TS_OK)
            die(NAMES[i], &err);
        r->m[i].t += now() - t0;
        r->m[i].t_kernel += kernel_now() - k0;
    }
    const float *se = r->m[0].svf_acc;
    for (int i = 1; i < 3; i++)
        for (size_t c = 0; c < n; c++)
            if (se[c] == se[c] && r->m[i].svf_acc[c] == r->m[i].svf_acc[c])
                hist_add(&r->m[i].svf, fabs((double)se[c] - r->m[i].svf_acc[c]));
    free(nx), free(ny), free(nz);
}

static void result_free(result *r)
{
    for (int i = 0; i < 3; i++) {
        free(r->m[i].hor.count);
        free(r->m[i].svf.count);
        free(r->m[i].plane);
        free(r->m[i].svf_acc);
        ts_pyramid_free(r->m[i].pyr);
    }
}

static void report(const char *name, const ts_grid *g, const setup *su, const result *r)
{
    double dem_mib = (double)g->width * g->height * 4 / 1048576.0;
    printf("%s %d x %d, %d directions, k=%g o=%g, %d levels:\n", name, g->width, g->height,
           su->dirs, su->pyr.level_step, su->pyr.offset,
           ts_pyramid_level_count(g->width, g->height, su->pyr.level_step));
    static const char *const UNIT[3] = {"", " (CPU time)", " (user CPU time)"};
    printf("  %-20s svf time (C) %8.3f s%s; kernel CPU %.3f s\n", NAMES[0], r->m[0].t,
           UNIT[timer], r->m[0].t_kernel);
    for (int i = 1; i < 3; i++) {
        const method *m = &r->m[i];
        printf("  %-20s svf time (C) %8.3f s (build %.3f s) = %.2f x exact; kernel CPU %.3f s; "
               "|horizon - exact| median %.3f p99 %.3f max %.2f deg; |svf - exact| median %.4f "
               "p99 %.4f max %.3f\n",
               NAMES[i], m->t, m->t_build, m->t / r->m[0].t, m->t_kernel,
               hist_quantile(&m->hor, 0.5),
               hist_quantile(&m->hor, 0.99), m->hor.max, hist_quantile(&m->svf, 0.5),
               hist_quantile(&m->svf, 0.99), m->svf.max);
    }
    printf("  memory besides DEM, normals and output: exact one plane (%.1f MiB), pyramid "
           "%.1f MiB (%.1f x DEM) + %d planes (as many azimuths at once)\n",
           dem_mib, r->bytes_pyramid / 1048576.0, r->bytes_pyramid / 1048576.0 / dem_mib,
           TS_PYRAMID_BATCH);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    int size = 4096;
    char dems[256] = "jacksboro,lux_elev,fractal";
    setup su;
    su.dirs = 64;
    su.threads = 0;
    ts_pyramid_opts_default(&su.pyr);
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dirs") && i + 1 < argc)
            su.dirs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            su.threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--level-step") && i + 1 < argc)
            su.pyr.level_step = atof(argv[++i]);
        else if (!strcmp(argv[i], "--offset") && i + 1 < argc)
            su.pyr.offset = atof(argv[++i]);
        else if (!strcmp(argv[i], "--dems") && i + 1 < argc)
            snprintf(dems, sizeof dems, "%s", argv[++i]);
        else if (!strcmp(argv[i], "--cpu"))
            timer = TIME_CPU;
        else if (!strcmp(argv[i], "--user"))
            timer = TIME_USER;
        else {
            fprintf(stderr, "usage: methods_bench [--size N] [--dirs D] [--threads T] "
                            "[--level-step K] [--offset O] [--dems a,b,fractal] "
                            "[--cpu | --user]\n");
            return 2;
        }
    }
    ts_error err;
    if (ts_pyramid_opts_validate(&su.pyr, &err) != TS_OK)
        die("options", &err);
    for (char *name = strtok(dems, ","); name; name = strtok(NULL, ",")) {
        ts_grid g;
        char msg[256];
        if (!strcmp(name, "fractal")) {
            if (ts_grid_create(&g, size, size, 10.0, 10.0, &err) != TS_OK)
                die("grid", &err);
            tdem_fbm(&g, 1234, 0.8, 1500.0);
        } else if (tdem_read(&g, name, NULL, NULL, msg, sizeof msg) != 0) {
            fprintf(stderr, "methods_bench: %s\n", msg);
            return 1;
        }
        result r;
        compare(&g, &su, &r);
        report(name, &g, &su, &r);
        result_free(&r);
        ts_grid_free(&g);
    }
    return 0;
}
