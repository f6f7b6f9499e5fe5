/*
 * cl_bench: the C and the OpenCL backend side by side, product by product.
 *
 *   cl_bench [--size N] [--dirs D] [--repeat R] [--threads T]
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
 * build) is timed separately. Also prints the largest difference between
 * the backends' results.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "terrashade.h"
#include "terrashade_cl.h"
#include "terrashade_env.h"
#include "test_dem.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

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
                                c->nz,  c->hz,     c->out, c->out2, c->out3};
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
        const ts_direct_request req = {&c->g, c->nx, c->ny, c->nz, c->hz, &c->o, 135, 30, c->out};
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

int main(int argc, char **argv)
{
    int size = 1024, dirs = 16, repeat = 3, threads = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dirs") && i + 1 < argc)
            dirs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--size N] [--dirs D] [--repeat R] [--threads T]\n",
                    argv[0]);
            return 2;
        }
    }
    if (size < 1 || dirs < 1 || repeat < 1 || threads < 0) {
        fprintf(stderr, "cl_bench: size, dirs and repeat must be >= 1, threads >= 0\n");
        return 2;
    }
    ts_error e;
    ts_cl_info info;
    double t0 = now();
    if (ts_cl_available(&info, &e) != TS_OK)
        die("OpenCL", &e);
    double t_init = now() - t0;
    printf("OpenCL device: %s (%s), %s, %d compute units, fp64 %s\n", info.device, info.platform,
           info.type, info.compute_units, info.fp64 ? "yes" : "no");
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
    float *ref = malloc(c.n * sizeof(float));
    if (!hz_cl || !c.hz || !c.nx || !c.ny || !c.nz || !c.out || !c.out2 || !c.out3 || !ref) {
        fprintf(stderr, "cl_bench: out of memory\n");
        return 1;
    }
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
    for (int p = 0; p < P_COUNT; p++) {
        double best[2] = {1e30, 1e30};
        double diff = 0;
        for (int b = 0; b < 2; b++)
            for (int r = 0; r < repeat; r++) {
                double t = now();
                run(&c, p, b, b ? hz_cl : c.hz);
                t = now() - t;
                if (t < best[b])
                    best[b] = t;
                if (r == 0 && b == 0 && p != P_HORIZON)
                    memcpy(ref, c.out, c.n * sizeof(float));
                if (r == 0 && b == 1)
                    diff = p == P_HORIZON ? maxdiff(c.hz, hz_cl, c.n * dirs)
                                          : maxdiff(ref, c.out, c.n);
            }
        const int per_dir = p == P_HORIZON || p == P_SKY || p == P_ENV;
        double work = per_dir ? (double)c.n * dirs
                      : p == P_SHM                   ? c.n * 8.0
                                                     : (double)c.n;
        const char *unit = per_dir ? "Mpx-dir/s" : "Mpx/s";
        printf("%-32s %10s %10.1f %10.1f %6.2fx %10.3g   (%.3f s vs %.3f s)\n", NAMES[p], unit,
               work / best[0] / 1e6, work / best[1] / 1e6, best[0] / best[1], diff, best[0],
               best[1]);
    }
    free(hz_cl), free(c.hz), free(c.nx), free(c.ny), free(c.nz);
    free(c.out), free(c.out2), free(c.out3), free(ref);
    ts_env_table_free(&c.table);
    ts_grid_free(&c.g);
    return 0;
}
