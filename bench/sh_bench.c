/*
 * sh_bench: order-4 SH light (core/terrashade_sh.h) against the exact
 * methods, on an N x N fractal (fBm, Hurst 0.8, 1500 m relief, 10 m cells).
 *
 *   sh_bench [--size 4096] [--dirs 32] [--swath 3]
 *
 * With every core it times, wall and CPU (of every thread, less disturbed by
 * other work on a shared machine):
 *  - environment light (CIE clear sky, 1024 x 360) on top of the same
 *    `dirs` sweeps: Timonen's table (build, accumulate, finish) against SH
 *    (projection, wedge tables, visibility, three triple products);
 *  - a key light (sun 315 / 45 degrees): the exact direct sun (one sweep
 *    and ts_shade_direct) against METHOD=sh (`swath` sweeps, wedge tables,
 *    visibility, triple product), normals included in both.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "terrashade_sh.h"
#include "test_dem.h"

static double clock_of(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

typedef struct {
    double wall, cpu;
} stamp;

static stamp now(void)
{
    stamp s = {clock_of(CLOCK_MONOTONIC), clock_of(CLOCK_PROCESS_CPUTIME_ID)};
    return s;
}

/* Adds the time since `from` to *acc. */
static void add_since(stamp from, stamp *acc)
{
    stamp t = now();
    acc->wall += t.wall - from.wall;
    acc->cpu += t.cpu - from.cpu;
}

static void check(ts_status st, const char *step, const ts_error *e)
{
    if (st != TS_OK) {
        fprintf(stderr, "sh_bench: %s failed: %s\n", step, e->message);
        exit(1);
    }
}

static float *floats(size_t n)
{
    float *p = calloc(n, sizeof *p);
    if (!p) {
        fprintf(stderr, "sh_bench: out of memory\n");
        exit(1);
    }
    return p;
}

/* Environment light: the table's lighting and SH's, on top of shared sweeps. */
static void bench_env(const ts_grid *g, int dirs, const float *nx, const float *ny,
                      const float *nz)
{
    ts_error e;
    ts_env env;
    size_t n = (size_t)g->width * g->height;
    float *plane = floats(n), *rgb = floats(3 * n);
    check(ts_env_sky(&env, TS_SKY_CLEAR, 0, 135, 30, 0, 0, &e), "sky", &e);
    stamp sweeps = {0, 0}, table = {0, 0}, sh = {0, 0}, t;
    ts_env_table_opts to;
    ts_env_table_opts_default(&to);
    to.directions = dirs;
    ts_env_table tab;
    t = now();
    check(ts_env_table_build(&env, &to, &tab, &e), "table", &e);
    add_since(t, &table);
    double light[3][TS_SH_COEFFS], m[TS_SH_COEFFS][TS_SH_COEFFS];
    ts_sh_swath s;
    ts_sh_wedges w;
    ts_sh_visibility v;
    t = now();
    check(ts_sh_project_env(&env, light, &e), "projection", &e);
    ts_sh_swath_complete(&s, dirs, 0);
    check(ts_sh_wedges_build(&s, 0, &w, &e), "wedges", &e);
    check(ts_sh_visibility_init(&v, g, &w, &e), "visibility", &e);
    add_since(t, &sh);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    for (int k = 0; k < dirs; k++) {
        t = now();
        check(ts_horizon_sweep(g, ts_env_table_azimuth(&tab, k), &o, plane, &e), "sweep", &e);
        add_since(t, &sweeps);
        t = now();
        const ts_env_light_request rq = {g,   &tab,    k,           nx, ny, nz,
                                         plane, rgb, rgb + n, rgb + 2 * n, 0};
        check(ts_env_light_accumulate(&rq, &e), "table lighting", &e);
        add_since(t, &table);
        t = now();
        check(ts_sh_visibility_add(&v, k, plane, &e), "visibility", &e);
        add_since(t, &sh);
    }
    t = now();
    check(ts_env_light_finish(g, rgb, rgb + n, rgb + 2 * n, &e), "finish", &e);
    add_since(t, &table);
    t = now();
    check(ts_sh_visibility_finish(&v, &e), "visibility", &e);
    for (int c = 0; c < 3; c++) {
        ts_sh_product_matrix(light[c], m);
        check(ts_sh_shade(g, m, nx, ny, nz, v.vis, 1 / M_PI, 0, rgb + c * n, &e), "shade", &e);
    }
    add_since(t, &sh);
    printf("envlight, %d directions: sweeps %.2f s (CPU %.2f); lighting on top: table %.2f s "
           "(CPU %.2f), sh %.2f s (CPU %.2f); sh / table %.2f (CPU %.2f)\n",
           dirs, sweeps.wall, sweeps.cpu, table.wall, table.cpu, sh.wall, sh.cpu,
           sh.wall / table.wall, sh.cpu / table.cpu);
    printf("envlight total (sweeps + lighting): table %.2f s, sh %.2f s\n",
           sweeps.wall + table.wall, sweeps.wall + sh.wall);
    ts_sh_visibility_free(&v);
    ts_sh_wedges_free(&w);
    ts_env_table_free(&tab);
    ts_env_free(&env);
    free(plane), free(rgb);
}

/* The direct sun: exact (one sweep) against the SH key light. */
static void bench_key(const ts_grid *g, int swath, const float *nx, const float *ny,
                      const float *nz)
{
    ts_error e;
    size_t n = (size_t)g->width * g->height;
    float *plane = floats(n), *out = floats(n);
    const double az = 315, el = 45, radius = TS_SUN_RADIUS_DEG;
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 1;
    o.start_azimuth = az;
    stamp exact = {0, 0}, sh = {0, 0}, t = now();
    check(ts_horizon_sweep(g, az, &o, plane, &e), "sweep", &e);
    const ts_direct_request rq = {g, nx, ny, nz, plane, &o, az, el, out, TS_SUN_RADIUS_DEG};
    check(ts_shade_direct(&rq, &e), "direct", &e);
    add_since(t, &exact);
    t = now();
    ts_sh_swath s;
    ts_sh_wedges w;
    double l[TS_SH_COEFFS], shade_ref, share_ref;
    ts_sh_swath_key(&s, swath, az, el, radius);
    ts_sh_key_light(az, el, radius, l);
    check(ts_sh_wedges_build(&s, 0, &w, &e), "wedges", &e);
    stamp tables = now();
    tables.wall -= t.wall, tables.cpu -= t.cpu;
    ts_sh_key_reference(&w, l, az, el, &shade_ref, &share_ref);
    float **planes = malloc(sizeof *planes * (size_t)s.n);
    for (int k = 0; k < s.n; k++) {
        planes[k] = floats(n);
        check(ts_horizon_sweep(g, ts_sh_swath_azimuth(&s, k), &o, planes[k], &e), "sweep", &e);
    }
    check(ts_sh_swath_light(g, &w, (const float *const *)planes, l, nx, ny, nz, 1 / shade_ref,
                            out, 0, NULL, &e),
          "shade", &e);
    add_since(t, &sh);
    printf("key light 315/45, direct term: exact %.2f s (CPU %.2f), sh with %d sweeps %.2f s "
           "(CPU %.2f; of which wedge tables %.2f s); sh / exact %.2f\n",
           exact.wall, exact.cpu, swath, sh.wall, sh.cpu, tables.wall, sh.wall / exact.wall);
    for (int k = 0; k < s.n; k++)
        free(planes[k]);
    free(planes);
    ts_sh_wedges_free(&w);
    free(plane), free(out);
}

int main(int argc, char **argv)
{
    int size = 4096, dirs = 32, swath = 3, bad = 0;
    for (int i = 1; i < argc && !bad; i += 2) {
        if (strcmp(argv[i], "--size") && strcmp(argv[i], "--dirs") && strcmp(argv[i], "--swath")) {
            fprintf(stderr, "%s: unknown option %s\n", argv[0], argv[i]);
            bad = 1;
        } else if (i + 1 == argc)
            bad = 1; /* its value is missing */
        else if (!strcmp(argv[i], "--size"))
            size = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--dirs"))
            dirs = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--swath"))
            swath = atoi(argv[i + 1]);
    }
    if (bad || size < 2 || dirs < 1 || swath < 1) {
        fprintf(stderr, "usage: %s [--size N >= 2] [--dirs D >= 1] [--swath S >= 1]\n",
                argv[0]);
        return 2;
    }
    ts_error e;
    ts_grid g;
    check(ts_grid_create(&g, size, size, 10.0, 10.0, &e), "grid", &e);
    tdem_fbm(&g, 1234, 0.8, 1500.0);
    size_t n = (size_t)size * size;
    float *nx = floats(n), *ny = floats(n), *nz = floats(n);
    printf("sh_bench: %d x %d fractal, %d cores\n", size, size, ts_cpu_count());
    check(ts_normals(&g, nx, ny, nz, &e), "normals", &e);
    bench_key(&g, swath, nx, ny, nz);
    bench_env(&g, dirs, nx, ny, nz);
    free(nx), free(ny), free(nz);
    ts_grid_free(&g);
    return 0;
}
