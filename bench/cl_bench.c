/*
 * cl_bench: the C and the OpenCL backend side by side, product by product.
 *
 *   cl_bench [--size N] [--dirs D] [--repeat R] [--threads T] [--no-streams]
 *   cl_bench --list
 *
 * Generates an N x N fractal DEM (default 1024, fBm value noise, Hurst 0.8,
 * 1500 m relief, 10 m cells), then times, best of R runs, each product on
 * both backends: horizons for D directions (default 16; million
 * pixel-directions per second), the shadow height map for 8 sun azimuths
 * (million pixels per second, per azimuth), normals and direct sun
 * (million pixels per second) and sky terms from D horizon planes (million
 * pixel-directions per second), and the environment light (envlight)
 * under a CIE sky from D horizon planes, plane by plane as the driver runs
 * it (million pixel-directions per second; the OpenCL side includes its
 * session: table and normals uploaded once, the sums read back per plane).
 * The OpenCL device is the one
 * TERRASHADE_OPENCL_DEVICE selects; its first use (context and kernel
 * build) is timed separately; --list prints the devices and their
 * TERRASHADE_OPENCL_DEVICE values. Also prints the largest difference
 * between the backends' results (every output: the three normal
 * components, svf, sky light and openness, the three colours), and, for the
 * horizons, the time the device takes to copy the planes to host memory
 * (the same bytes in the same buffer sizes, timed alone), so that the
 * kernels' own rate can be told from the bus's. Then, unless --no-streams,
 * the horizons on OpenCL as the driver's streams sweep them: one azimuth
 * per call, and 16 per call (the GPU default of TERRASHADE_OPENCL_BATCH).
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "terrashade.h"
#include "terrashade_cl.h"
#include "terrashade_env.h"
#include "bench_pages.h"
#include "bench_clock.h"
#include "test_dem.h"
#ifdef HAVE_OPENCL
#include "cl_internal.h"
#endif

static void die(const char *what, const ts_error *e)
{
    fprintf(stderr, "cl_bench: %s: %s\n", what, e->message);
    exit(1);
}

static double maxdiff(const float *a, const float *b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++)
        if (!isnan(a[i]) && !isnan(b[i]) && fabs((double)a[i] - b[i]) > m)
            m = fabs((double)a[i] - b[i]);
    return m;
}

/* The largest difference over the n-cell planes of a and b. */
static double maxdiff3(float *const a[3], float *const b[3], int planes, size_t n)
{
    double m = 0;
    for (int i = 0; i < planes; i++) {
        double d = maxdiff(a[i], b[i], n);
        m = d > m ? d : m;
    }
    return m;
}

/* Seconds the selected device takes to copy `bytes` of a buffer into host
 * memory dst, in reads of at most one horizon batch (32 planes of
 * `plane` bytes) and the device's largest buffer, as ts_cl_horizon_compute
 * reads its planes; best of `repeat`. -1 when it cannot be measured. */
static double readback_seconds(void *dst, size_t bytes, size_t plane, int repeat)
{
#ifdef HAVE_OPENCL
    ts_error e;
    ts_cl_job J;
    if (ts_cl_job_begin(&J, &e) != TS_OK)
        return -1;
    size_t chunk = 32 * plane < bytes ? 32 * plane : bytes;
    while (chunk > J.max_alloc && chunk > plane)
        chunk -= plane;
    cl_mem m = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, chunk, NULL, "read-back test");
    ts_cl_job_fill0(&J, m, chunk, "read-back test");
    if (J.st == TS_OK)
        clFinish(J.d->queue);
    double best = 1e30;
    for (int r = 0; r < repeat && J.st == TS_OK; r++) {
        double t = bench_now();
        for (size_t off = 0; off < bytes; off += chunk)
            ts_cl_job_read(&J, m, 0, bytes - off < chunk ? bytes - off : chunk,
                           (char *)dst + off, "read-back test");
        t = bench_now() - t;
        best = t < best ? t : best;
    }
    return ts_cl_job_end(&J) == TS_OK ? best : -1;
#else
    (void)dst, (void)bytes, (void)plane, (void)repeat;
    return -1;
#endif
}

/* --list: every OpenCL device with its TERRASHADE_OPENCL_DEVICE value. */
static int list_devices(void)
{
    ts_cl_info d[32];
    int n = 0;
    ts_error e;
    if (ts_cl_devices(d, 32, &n, &e) != TS_OK) {
        fprintf(stderr, "cl_bench: %s\n", e.message);
        return 1;
    }
    for (int i = 0; i < n && i < 32; i++)
        printf("%d\t%d:%d\t%s\t%s\t%s\t%s\n", d[i].index, d[i].platform_index,
               d[i].device_index, d[i].type, d[i].platform, d[i].device, d[i].version);
    return 0;
}

/* Everything a product needs, so that one function can run either backend. */
typedef struct {
    ts_grid g;
    ts_horizon_opts o;
    size_t n;
    float *hz, *nx, *ny, *nz, *out, *out2, *out3;
    int threads;
    ts_env_table table; /* envlight: a CIE sky's */
} ctx;

enum { P_HORIZON, P_SHM, P_NORMALS, P_DIRECT, P_SKY, P_ENV, P_COUNT };
static const char *NAMES[P_COUNT] = {"horizons", "shadow height map", "normals", "direct sun",
                                     "sky terms (svf, sky, openness)",
                                     "envlight (CIE sky 7, RGB)"};

static const double SHM_AZ[8] = {15, 60, 105, 150, 195, 240, 285, 330};

/* The environment light of every plane of c->hz into out, out2, out3. */
static ts_status run_env(ctx *c, int cl, ts_error *e)
{
    ts_status st = TS_OK;
    ts_cl_env_light *s = NULL;
    for (int i = 0; i < 3; i++)
        memset(i == 0 ? c->out : i == 1 ? c->out2 : c->out3, 0, c->n * sizeof(float));
    ts_env_light_request req = {&c->g,  &c->table, 0,      c->nx,  c->ny,
                                c->nz,  c->hz,     c->out, c->out2, c->out3, 0};
    if (cl)
        st = ts_cl_env_light_open(&req, &s, e);
    for (req.k = 0; req.k < c->o.directions && st == TS_OK; req.k++) {
        req.plane = c->hz + c->n * req.k;
        st = cl ? ts_cl_env_light_add(s, &req, e) : ts_env_light_accumulate(&req, e);
    }
    ts_cl_env_light_close(s);
    return st;
}

/* Run product p on backend cl (0 = C); results into c->out (horizons into
 * `hout`). */
static void run(ctx *c, int p, int cl, float *hout)
{
    ts_error e;
    ts_status st = TS_OK;
    switch (p) {
    case P_HORIZON:
        st = cl ? ts_cl_horizon_compute(&c->g, &c->o, hout, &e)
                : ts_horizon_compute(&c->g, &c->o, hout, &e);
        break;
    case P_SHM:
        for (int k = 0; k < 8 && st == TS_OK; k++)
            st = cl ? ts_cl_shm_compute(&c->g, SHM_AZ[k], 20, 0, c->threads, c->out, NULL, &e)
                    : ts_shm_compute(&c->g, SHM_AZ[k], 20, 0, c->threads, c->out, NULL, &e);
        break;
    case P_NORMALS:
        st = cl ? ts_cl_normals(&c->g, c->out, c->out2, c->out3, &e)
                : ts_normals(&c->g, c->out, c->out2, c->out3, &e);
        break;
    case P_DIRECT: {
        const ts_direct_request req = {&c->g, c->nx, c->ny, c->nz, c->hz,
                                       &c->o, 135,   30,    c->out, TS_SUN_RADIUS_DEG};
        st = (cl ? ts_cl_shade_direct : ts_shade_direct)(&req, &e);
        break;
    }
    case P_SKY: {
        const ts_sky_request req = {&c->g, c->nx, c->ny, c->nz, c->hz, &c->o, TS_SVF_RADIATIVE,
                                    c->out, c->out2, c->out3};
        st = (cl ? ts_cl_sky_terms : ts_sky_terms)(&req, &e);
        break;
    }
    case P_ENV:
        st = run_env(c, cl, &e);
        break;
    }
    if (st != TS_OK)
        die(NAMES[p], &e);
}

/* The driver's horizon streams (plugin/tsd_compute.c) on OpenCL: every
 * azimuth in its own call (the DEM uploaded and the lines of one azimuth
 * launched each time), then in calls of 16 (the GPU default of
 * ts_cl_horizon_sweeps' batches); each plane checked against the
 * all-at-once planes `want`, which it must equal bit for bit. */
static void stream_calls(ctx *c, const float *want, int repeat)
{
    const int dirs = c->o.directions, per[2] = {1, 16};
    float *planes = malloc(c->n * 16 * sizeof(float));
    double az[16];
    if (!planes) {
        fprintf(stderr, "cl_bench: out of memory\n");
        exit(1);
    }
    bench_touch_pages(planes, c->n * 16 * sizeof(float));
    printf("\nhorizons as the driver streams them (OpenCL, best of %d):\n", repeat);
    for (int v = 0; v < 2; v++) {
        double best = 1e30;
        int same = 1;
        for (int r = 0; r < repeat; r++) {
            double t = bench_now();
            for (int k0 = 0; k0 < dirs; k0 += per[v]) {
                const int n = dirs - k0 < per[v] ? dirs - k0 : per[v];
                ts_error e;
                for (int i = 0; i < n; i++)
                    az[i] = ts_horizon_azimuth(&c->o, k0 + i);
                if (ts_cl_horizon_sweeps(&c->g, az, n, &c->o, planes, &e) != TS_OK)
                    die("horizon sweeps", &e);
                if (r == 0)
                    same &= !memcmp(planes, want + c->n * k0, c->n * n * sizeof(float));
            }
            t = bench_now() - t;
            best = t < best ? t : best;
        }
        printf("  %2d azimuth(s) per call: %.3f s = %.1f Mpx-dir/s; planes %s\n", per[v], best,
               (double)c->n * dirs / best / 1e6,
               same ? "bit-identical to all at once" : "DIFFER from all at once");
    }
    free(planes);
}

int main(int argc, char **argv)
{
    int size = 1024, dirs = 16, repeat = 3, threads = 0, streams = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--list"))
            return list_devices();
        if (!strcmp(argv[i], "--size") && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dirs") && i + 1 < argc)
            dirs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-streams"))
            streams = 0;
        else {
            fprintf(stderr,
                    "usage: %s [--size N] [--dirs D] [--repeat R] [--threads T] "
                    "[--no-streams] | --list\n",
                    argv[0]);
            return 2;
        }
    }
    if (size < 1 || dirs < 1 || repeat < 1 || threads < 0) {
        fprintf(stderr, "cl_bench: size, dirs and repeat must be >= 1, threads >= 0\n");
        return 2;
    }
    if (dirs % 8) {
        fprintf(stderr, "cl_bench: --dirs must be a multiple of 8 (the direct sun comes from "
                        "135 degrees, which must be one of the horizons' azimuths), got %d\n",
                dirs);
        return 2;
    }
    ts_error e;
    ts_cl_info info;
    double t0 = bench_now();
    if (ts_cl_available(&info, &e) != TS_OK)
        die("OpenCL", &e);
    double t_init = bench_now() - t0;
    printf("OpenCL device %d: %s (%s), %s, %d compute units, %.1f GiB, fp64 %s\n", info.index,
           info.device, info.platform, info.type, info.compute_units,
           info.global_mem / 1073741824.0, info.fp64 ? "yes" : "no");
    printf("OpenCL version: %s\n", info.version);
    printf("first use (context, program build): %.2f s\n", t_init);
    printf("C backend: %d threads\n", threads ? threads : ts_cpu_count());

    ctx c;
    memset(&c, 0, sizeof c);
    c.threads = threads;
    if (ts_grid_create(&c.g, size, size, 10.0, 10.0, &e) != TS_OK)
        die("grid", &e);
    tdem_fbm(&c.g, 42, 0.8, 1500.0);
    ts_horizon_opts_default(&c.o);
    c.o.directions = dirs;
    c.o.threads = threads;
    c.n = (size_t)size * size;
    float *hz_cl = malloc(c.n * dirs * sizeof(float));
    c.hz = malloc(c.n * dirs * sizeof(float));
    c.nx = malloc(c.n * sizeof(float));
    c.ny = malloc(c.n * sizeof(float));
    c.nz = malloc(c.n * sizeof(float));
    c.out = malloc(c.n * sizeof(float));
    c.out2 = malloc(c.n * sizeof(float));
    c.out3 = malloc(c.n * sizeof(float));
    float *ref = malloc(c.n * sizeof(float)), *ref2 = malloc(c.n * sizeof(float)),
          *ref3 = malloc(c.n * sizeof(float));
    if (!hz_cl || !c.hz || !c.nx || !c.ny || !c.nz || !c.out || !c.out2 || !c.out3 || !ref ||
        !ref2 || !ref3) {
        fprintf(stderr, "cl_bench: out of memory\n");
        return 1;
    }
    /* mapped before the first timed run, not by it (bench_pages.h) */
    bench_touch_pages(hz_cl, c.n * dirs * sizeof(float));
    bench_touch_pages(c.hz, c.n * dirs * sizeof(float));
    float *one_plane[] = {c.out, c.out2, c.out3, ref, ref2, ref3};
    for (int i = 0; i < 6; i++)
        bench_touch_pages(one_plane[i], c.n * sizeof(float));
    if (ts_normals(&c.g, c.nx, c.ny, c.nz, &e) != TS_OK)
        die("normals", &e);
    ts_env sky;
    ts_env_table_opts to;
    ts_env_table_opts_default(&to);
    to.directions = dirs;
    if (ts_env_sky(&sky, TS_SKY_CIE, 7, 120.0, 25.0, 0, 0, &e) != TS_OK ||
        ts_env_table_build(&sky, &to, &c.table, &e) != TS_OK)
        die("light table", &e);
    ts_env_free(&sky);

    printf("\n%d x %d DEM, %d directions; best of %d\n", size, size, dirs, repeat);
    printf("%-32s %10s %10s %10s %7s %10s\n", "product", "unit", "C", "OpenCL", "CL/C",
           "max diff");
    float *const refs[3] = {ref, ref2, ref3}, *const outs[3] = {c.out, c.out2, c.out3};
    double t_horizon_cl = 0;
    for (int p = 0; p < P_COUNT; p++) {
        const int planes = p == P_NORMALS || p == P_SKY || p == P_ENV ? 3 : 1;
        double best[2] = {1e30, 1e30};
        double diff = 0;
        for (int b = 0; b < 2; b++)
            for (int r = 0; r < repeat; r++) {
                double t = bench_now();
                run(&c, p, b, b ? hz_cl : c.hz);
                t = bench_now() - t;
                if (t < best[b])
                    best[b] = t;
                if (r == 0 && b == 0 && p != P_HORIZON)
                    for (int i = 0; i < planes; i++)
                        memcpy(refs[i], outs[i], c.n * sizeof(float));
                if (r == 0 && b == 1)
                    diff = p == P_HORIZON ? maxdiff(c.hz, hz_cl, c.n * dirs)
                                          : maxdiff3(refs, outs, planes, c.n);
            }
        if (p == P_HORIZON)
            t_horizon_cl = best[1];
        const int per_dir = p == P_HORIZON || p == P_SKY || p == P_ENV;
        double work = per_dir ? (double)c.n * dirs
                      : p == P_SHM                   ? c.n * 8.0
                                                     : (double)c.n;
        const char *unit = per_dir ? "Mpx-dir/s" : "Mpx/s";
        printf("%-32s %10s %10.1f %10.1f %6.2fx %10.3g   (%.3f s vs %.3f s)\n", NAMES[p], unit,
               work / best[0] / 1e6, work / best[1] / 1e6, best[0] / best[1], diff, best[0],
               best[1]);
    }
    if (streams)
        stream_calls(&c, hz_cl, repeat); /* (before the copy below overwrites hz_cl) */
    /* The horizon planes go to host memory: on a GPU that copy can take
     * longer than the kernels. */
    double rb = readback_seconds(hz_cl, c.n * dirs * sizeof(float), c.n * sizeof(float), repeat);
    if (rb >= 0) {
        double bytes = (double)c.n * dirs * sizeof(float);
        printf("\nhorizons, OpenCL: %.3f s in all; copying the %d planes (%.0f MiB) to the host "
               "alone: %.3f s (%.1f GB/s)\n",
               t_horizon_cl, dirs, bytes / 1048576.0, rb, bytes / rb / 1e9);
        if (t_horizon_cl > rb)
            printf("horizons, OpenCL without the copy (difference): %.3f s = %.1f Mpx-dir/s\n",
                   t_horizon_cl - rb, (double)c.n * dirs / (t_horizon_cl - rb) / 1e6);
    }
    free(ref2), free(ref3);
    free(hz_cl), free(c.hz), free(c.nx), free(c.ny), free(c.nz);
    free(c.out), free(c.out2), free(c.out3), free(ref);
    ts_env_table_free(&c.table);
    ts_grid_free(&c.g);
    return 0;
}
