/*
 * methods_bench: the approximate horizon methods against the exact sweep,
 * error and time side by side (docs/methods.md).
 *
 *   methods_bench [--size N] [--dirs D] [--threads T] [--level-step K]
 *                 [--offset O] [--dems jacksboro,lux_elev,fractal]
 *
 * For each DEM (the real ones of tests/data, and an N x N fractal: fBm
 * value noise, Hurst 0.8, 1500 m relief, 10 m cells, as ts_bench) it
 * computes the D horizon planes with the exact sweep and with the pyramid
 * (HORIZON_METHOD=pyramid, level step K, offset O), one direction at a
 * time, and prints: the median and p99 of |pyramid - exact| horizon angle
 * over every cell and direction, the same of the sky-view factor (radiative,
 * SVF_MODEL's default), the time of each svf (horizons plus accumulation;
 * the pyramid's build included) on the C backend, and the memory each
 * keeps besides the DEM and the output.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "terrashade.h"
#include "test_dem.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
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

typedef struct {
    hist hor, svf;
    double t_exact, t_pyramid, t_build;
    double bytes_pyramid;
} result;

/* Both methods over every direction of g; errors and times into r. */
static void compare(const ts_grid *g, const setup *su, result *r)
{
    size_t n = (size_t)g->width * g->height;
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = su->dirs;
    o.threads = su->threads;
    ts_error err;
    float *nx = malloc(n * sizeof *nx), *ny = malloc(n * sizeof *ny), *nz = malloc(n * sizeof *nz);
    float *pe = malloc(n * sizeof *pe), *pp = malloc(n * sizeof *pp);
    float *se = calloc(n, sizeof *se), *sp = calloc(n, sizeof *sp);
    if (!nx || !ny || !nz || !pe || !pp || !se || !sp) {
        fprintf(stderr, "methods_bench: out of memory\n");
        exit(1);
    }
    if (ts_normals(g, nx, ny, nz, &err) != TS_OK)
        die("normals", &err);
    hist_init(&r->hor, 1e-4);
    hist_init(&r->svf, 1e-6);
    double t0 = now();
    ts_pyramid *pyr;
    if (ts_pyramid_build(g, &su->pyr, su->threads, &pyr, &err) != TS_OK)
        die("pyramid", &err);
    r->t_build = now() - t0;
    r->t_pyramid = r->t_build;
    r->t_exact = 0;
    r->bytes_pyramid = ts_pyramid_bytes(g->width, g->height, su->pyr.level_step);
    for (int k = 0; k < su->dirs; k++) {
        double az = ts_horizon_azimuth(&o, k);
        t0 = now();
        if (ts_horizon_sweep(g, az, &o, pe, &err) != TS_OK ||
            ts_sky_accumulate(g, nx, ny, nz, pe, az, su->dirs, se, NULL, NULL, &err) != TS_OK)
            die("exact", &err);
        double t1 = now();
        if (ts_pyramid_horizon(pyr, az, &o, pp, &err) != TS_OK ||
            ts_sky_accumulate(g, nx, ny, nz, pp, az, su->dirs, sp, NULL, NULL, &err) != TS_OK)
            die("pyramid", &err);
        double t2 = now();
        r->t_exact += t1 - t0;
        r->t_pyramid += t2 - t1;
        for (size_t i = 0; i < n; i++)
            if (pe[i] == pe[i] && pp[i] == pp[i])
                hist_add(&r->hor, fabs((double)pe[i] - pp[i]));
    }
    t0 = now();
    if (ts_sky_finish(g, su->dirs, se, NULL, NULL, &err) != TS_OK)
        die("exact svf", &err);
    r->t_exact += now() - t0;
    t0 = now();
    if (ts_sky_finish(g, su->dirs, sp, NULL, NULL, &err) != TS_OK)
        die("pyramid svf", &err);
    r->t_pyramid += now() - t0;
    for (size_t i = 0; i < n; i++)
        if (se[i] == se[i] && sp[i] == sp[i])
            hist_add(&r->svf, fabs((double)se[i] - sp[i]));
    ts_pyramid_free(pyr);
    free(nx), free(ny), free(nz), free(pe), free(pp), free(se), free(sp);
}

static void report(const char *name, const ts_grid *g, const setup *su, const result *r)
{
    double dem_mib = (double)g->width * g->height * 4 / 1048576.0;
    printf("%s %d x %d, %d directions, k=%g o=%g:\n", name, g->width, g->height, su->dirs,
           su->pyr.level_step, su->pyr.offset);
    printf("  horizon |pyramid - exact|: median %.3f p99 %.3f max %.2f deg\n",
           hist_quantile(&r->hor, 0.5), hist_quantile(&r->hor, 0.99), r->hor.max);
    printf("  svf     |pyramid - exact|: median %.4f p99 %.4f max %.3f\n",
           hist_quantile(&r->svf, 0.5), hist_quantile(&r->svf, 0.99), r->svf.max);
    printf("  svf time (C): exact %.3f s, pyramid %.3f s (build %.3f s) = %.2f x exact\n",
           r->t_exact, r->t_pyramid, r->t_build, r->t_pyramid / r->t_exact);
    printf("  memory besides DEM and output: exact 1 plane (%.1f MiB), pyramid %d levels "
           "%.1f MiB (%.1f x DEM) + 1 plane\n",
           dem_mib, ts_pyramid_level_count(g->width, g->height, su->pyr.level_step),
           r->bytes_pyramid / 1048576.0, r->bytes_pyramid / 1048576.0 / dem_mib);
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
        else {
            fprintf(stderr, "usage: methods_bench [--size N] [--dirs D] [--threads T] "
                            "[--level-step K] [--offset O] [--dems a,b,fractal]\n");
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
        free(r.hor.count);
        free(r.svf.count);
        ts_grid_free(&g);
    }
    return 0;
}
