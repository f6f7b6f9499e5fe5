/*
 * env_bench: the cost of environment lighting on top of the horizon sweeps.
 *
 *   env_bench [--sizes 1024,4096] [--dirs 64] [--limit K] [--map 1024x512]
 *             [--normal-steps N] [--horizon-steps H]
 *
 * For each DEM size (an N x N fractal: fBm value noise, Hurst 0.8, 1500 m
 * relief, 10 m cells) it times, with every core:
 *  - building the L_p table of a CIE clear sky on a map of the given size
 *    (the build never sees the DEM, so its time must not change with it);
 *  - the horizon sweeps alone, one plane at a time (ts_horizon_sweep), for
 *    the first K of the `dirs` azimuths (all by default: K only shortens a
 *    run on a small machine, the cost per azimuth is what is compared);
 *  - the lighting on top: normals once, ts_env_light_accumulate per plane
 *    and ts_env_light_finish, as the envlight product runs them;
 * and prints lighting / sweeps (the goal is at most 25 %).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>

#include "test_dem.h"
#include "terrashade_env.h"

static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Wall time; and CPU time of the whole process (every thread), which a
 * machine shared with other work disturbs less. */
static double seconds(void) { return clock_s(CLOCK_MONOTONIC); }
static double cpu_seconds(void) { return clock_s(CLOCK_PROCESS_CPUTIME_ID); }

static void fail(const char *step, const ts_error *e)
{
    fprintf(stderr, "env_bench: %s failed: %s\n", step, e->message);
    exit(1);
}

static void print_machine(int argc, char **argv)
{
    printf("command:");
    for (int i = 0; i < argc; i++)
        printf(" %s", argv[i]);
    char model[256] = "unknown CPU", line[512];
    FILE *f = fopen("/proc/cpuinfo", "r");
    while (f && fgets(line, sizeof line, f)) {
        char *colon = strchr(line, ':');
        if (!strncmp(line, "model name", 10) && colon) {
            snprintf(model, sizeof model, "%s", colon + 2);
            model[strcspn(model, "\n")] = 0;
            break;
        }
    }
    if (f)
        fclose(f);
    struct utsname u;
    uname(&u);
    printf("\nmachine: %s, %d cores (all used), %s %s\n", model, ts_cpu_count(), u.sysname,
           u.release);
}

/* One DEM size: table build, sweeps alone, lighting on top. */
static void bench_size(int size, int dirs, int limit, const ts_env *env,
                       const ts_env_table_opts *to)
{
    ts_error e;
    ts_grid g;
    if (ts_grid_create(&g, size, size, 10.0, 10.0, &e))
        fail("grid", &e);
    tdem_fbm(&g, 1234, 0.8, 1500.0);
    size_t n = (size_t)size * size;
    float *plane = malloc(n * sizeof *plane), *nx = malloc(n * sizeof *nx);
    float *ny = malloc(n * sizeof *ny), *nz = malloc(n * sizeof *nz);
    float *r = calloc(n, sizeof *r), *gr = calloc(n, sizeof *gr), *b = calloc(n, sizeof *b);
    if (!plane || !nx || !ny || !nz || !r || !gr || !b) {
        fprintf(stderr, "env_bench: no memory for a %d x %d DEM\n", size, size);
        exit(1);
    }
    ts_env_table t;
    double t0 = seconds();
    if (ts_env_table_build(env, to, &t, &e))
        fail("table", &e);
    double t_table = seconds() - t0;

    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = dirs;
    double t_sweep = 0, t_light = 0, c_sweep = 0, c_light = 0, c0 = cpu_seconds();
    t0 = seconds();
    if (ts_normals(&g, nx, ny, nz, &e))
        fail("normals", &e);
    double t_normals = seconds() - t0, c_on_top = cpu_seconds() - c0;
    for (int k = 0; k < limit; k++) {
        t0 = seconds(), c0 = cpu_seconds();
        if (ts_horizon_sweep(&g, ts_env_table_azimuth(&t, k), &o, plane, &e))
            fail("sweep", &e);
        double t1 = seconds(), c1 = cpu_seconds();
        const ts_env_light_request req = {&g, &t, k, nx, ny, nz, plane, r, gr, b, 0};
        if (ts_env_light_accumulate(&req, &e))
            fail("lighting", &e);
        t_sweep += t1 - t0, c_sweep += c1 - c0;
        t_light += seconds() - t1, c_light += cpu_seconds() - c1;
    }
    t0 = seconds(), c0 = cpu_seconds();
    if (ts_env_light_finish(&g, r, gr, b, &e))
        fail("finish", &e);
    double t_finish = seconds() - t0;
    c_on_top += c_light + cpu_seconds() - c0;
    double on_top = t_normals + t_light + t_finish;
    printf("DEM %d x %d: table build %.3f s (%d directions x %d normal steps (0 = exact) x %d, "
           "%.2f MiB); %d of %d azimuths: "
           "sweeps %.2f s (%.1f M pixel-directions/s), lighting %.2f s "
           "(normals %.2f + accumulate %.2f + finish %.3f) = %.1f %% on top of the sweeps; "
           "CPU time: sweeps %.2f s, lighting %.2f s = %.1f %%\n",
           size, size, t_table, t.directions, t.normal_steps, t.horizon_steps,
           (double)t.directions * (t.normal_steps ? t.normal_steps : 1) * t.horizon_steps * 8 *
               4 / 1048576.0, limit,
           dirs, t_sweep, (double)n * limit / t_sweep / 1e6, on_top, t_normals, t_light,
           t_finish, 100.0 * on_top / t_sweep, c_sweep, c_on_top, 100.0 * c_on_top / c_sweep);
    fflush(stdout);
    ts_env_table_free(&t);
    free(plane), free(nx), free(ny), free(nz), free(r), free(gr), free(b);
    ts_grid_free(&g);
}

int main(int argc, char **argv)
{
    char sizes[256] = "1024,4096";
    int dirs = 64, limit = 0, map_w = 1024, map_h = 512;
    ts_env_table_opts to;
    ts_env_table_opts_default(&to);
    for (int i = 1; i < argc; i += 2) { /* an option and its value */
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            goto usage;
        if (!strcmp(a, "--sizes"))
            snprintf(sizes, sizeof sizes, "%s", v);
        else if (!strcmp(a, "--dirs"))
            dirs = atoi(v);
        else if (!strcmp(a, "--limit"))
            limit = atoi(v);
        else if (!strcmp(a, "--map") && sscanf(v, "%dx%d", &map_w, &map_h) == 2)
            ;
        else if (!strcmp(a, "--normal-steps"))
            to.normal_steps = atoi(v);
        else if (!strcmp(a, "--horizon-steps"))
            to.horizon_steps = atoi(v);
        else
            goto usage;
    }
    if (dirs < 1 || limit < 0) {
        fprintf(stderr, "env_bench: --dirs must be >= 1 and --limit >= 0\n");
        return 2;
    }
    limit = limit == 0 || limit > dirs ? dirs : limit;
    to.directions = dirs;
    print_machine(argc, argv);
    ts_env env;
    ts_error e;
    double t0 = seconds();
    if (ts_env_sky(&env, TS_SKY_CLEAR, 0, 135, 30, map_w, map_h, &e))
        fail("sky", &e);
    printf("environment: CIE clear sky on a %d x %d lat-long map (%zu texels), made in %.3f s\n",
           map_w, map_h, env.count, seconds() - t0);
    char *save = NULL;
    for (char *tok = strtok_r(sizes, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int size = atoi(tok);
        if (size < 2) {
            fprintf(stderr, "env_bench: DEM size %s is too small\n", tok);
            return 2;
        }
        bench_size(size, dirs, limit, &env, &to);
    }
    ts_env_free(&env);
    return 0;
usage:
    fprintf(stderr, "usage: %s [--sizes 1024,4096] [--dirs 64] [--limit K] [--map WxH] "
            "[--normal-steps N] [--horizon-steps H]\n", argv[0]);
    return 2;
}
