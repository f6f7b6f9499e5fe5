/*
 * ts_bench: throughput and memory of the core algorithms.
 *
 *   ts_bench [--size N] [--threads T] [--cell M] [--relief Z] [--dirs 16,64]
 *            [--max-distance 0,100] [--repeat R] [--latitude L]
 *
 * Generates an N x N fractal DEM (fBm value noise, Hurst 0.8, Z metres of
 * relief, default 1500, M metre cells), then times the horizon sweep for
 * each direction count and each maximum distance (metres, 0 = unbounded;
 * million pixel-directions per second, and the time relative to the
 * unbounded sweep, in wall and in CPU time) and the shadow height map for
 * 8 sun azimuths (million pixels per second), and reports peak memory.
 * With --latitude, the DEM is geographic: rows M metres apart, centred on
 * latitude L (degrees), each M cos(latitude) metres wide east-west, as a
 * lat/lon GeoTIFF of square angular cells gives the core.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/utsname.h>
#include <time.h>

#include "bench_pages.h"
#include "terrashade.h"
#include "bench_clock.h"
#include "test_dem.h"

static double peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024.0;
}

static void cpu_name(char *buf, size_t n)
{
    snprintf(buf, n, "unknown CPU");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "model name", 10)) {
            char *c = strchr(line, ':');
            if (c) {
                snprintf(buf, n, "%s", c + 2);
                buf[strcspn(buf, "\n")] = 0;
            }
            break;
        }
    fclose(f);
}

static void die(const char *what, const ts_error *e)
{
    fprintf(stderr, "ts_bench: %s: %s\n", what, e->message);
    exit(1);
}

int main(int argc, char **argv)
{
    int size = 4096, threads = 0, repeat = 3;
    double cell = 10.0, relief = 1500.0, latitude = NAN;
    char dirs_arg[256] = "16,64", dist_arg[256] = "0";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--cell") && i + 1 < argc)
            cell = atof(argv[++i]);
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--relief") && i + 1 < argc)
            relief = atof(argv[++i]);
        else if (!strcmp(argv[i], "--dirs") && i + 1 < argc)
            snprintf(dirs_arg, sizeof dirs_arg, "%s", argv[++i]);
        else if (!strcmp(argv[i], "--latitude") && i + 1 < argc)
            latitude = atof(argv[++i]);
        else if (!strcmp(argv[i], "--max-distance") && i + 1 < argc)
            snprintf(dist_arg, sizeof dist_arg, "%s", argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--size N] [--threads T] [--cell M] [--relief Z] "
                    "[--dirs 16,64] [--max-distance 0,100] [--repeat R] [--latitude L]\n", argv[0]);
            return 2;
        }
    }
    if (size < 2 || repeat < 1 || !(cell > 0) || !(relief > 0) || fabs(latitude) > 80) {
        fprintf(stderr, "ts_bench: --size must be >= 2, --repeat >= 1, --cell and --relief > 0, "
                        "--latitude within 80 degrees\n");
        return 2;
    }
    double dists[16];
    int ndist = 0;
    char *dsave = NULL;
    for (char *tok = strtok_r(dist_arg, ",", &dsave); tok; tok = strtok_r(NULL, ",", &dsave)) {
        char *end;
        double v = strtod(tok, &end);
        if (end == tok || *end || !(v >= 0) || ndist == 16) {
            fprintf(stderr, "ts_bench: --max-distance takes up to 16 distances >= 0 in metres, "
                    "got '%s'\n", tok);
            return 2;
        }
        dists[ndist++] = v;
    }
    char cpu[256];
    cpu_name(cpu, sizeof cpu);
    struct utsname u;
    uname(&u);
    printf("command: ");
    for (int i = 0; i < argc; i++)
        printf("%s%s", argv[i], i + 1 < argc ? " " : "\n");
    printf("machine: %s, %d cores, %s %s; threads: %d; vectors: %s\n", cpu, ts_cpu_count(),
           u.sysname, u.release, threads > 0 ? threads : ts_cpu_count(),
           ts_cpu_vectors_name(ts_cpu_vector_level()));

    ts_error e;
    ts_grid g;
    if (ts_grid_create(&g, size, size, cell, cell, &e))
        die("grid", &e);
    double t0 = bench_now();
    tdem_fbm(&g, 1234, 0.8, relief);
    printf("DEM: %d x %d fractal (fBm value noise, Hurst 0.8, %g m relief), %g m cells, "
           "generated in %.2f s\n", size, size, relief, cell, bench_now() - t0);
    if (latitude == latitude) {
        double *cx = malloc((size_t)size * sizeof *cx);
        if (!cx) {
            fprintf(stderr, "ts_bench: out of memory\n");
            return 1;
        }
        const double deg = cell / 111320.0; /* a row's span in latitude */
        for (int y = 0; y < size; y++) /* (row 0: the northern edge) */
            cx[y] = cell * cos((latitude + (size / 2 - y) * deg) * M_PI / 180.0);
        if (ts_grid_set_row_spacing(&g, cx, &e))
            die("row spacing", &e);
        free(cx);
        printf("geographic: rows centred on latitude %g, east-west cells %.4f-%.4f m\n", latitude,
               cell * cos((fabs(latitude) + size / 2 * deg) * M_PI / 180.0),
               cell * cos((fabs(latitude) - size / 2 * deg) * M_PI / 180.0));
    }
    double cells = (double)size * size;
    double dem_mib = cells * 4 / 1048576.0;
    double base_mib = peak_mib();

    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.threads = threads;
    char *save = NULL;
    for (char *tok = strtok_r(dirs_arg, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        o.directions = atoi(tok);
        if (o.directions < 1)
            continue;
        float *out = malloc((size_t)cells * o.directions * sizeof(float));
        if (!out) {
            fprintf(stderr, "ts_bench: cannot allocate %d horizon planes\n", o.directions);
            return 1;
        }
        /* mapped here, not in the first timed run (bench_pages.h) */
        bench_touch_pages(out, (size_t)cells * o.directions * sizeof(float));
        /* Distances interleaved within each repeat, so that all see the
         * same load on a shared machine. */
        double best[16], best_cpu[16];
        for (int m = 0; m < ndist; m++)
            best[m] = best_cpu[m] = INFINITY;
        for (int r = 0; r < repeat; r++)
            for (int m = 0; m < ndist; m++) {
                o.max_distance = dists[m];
                t0 = bench_now();
                double c0 = bench_cpu_now();
                if (ts_horizon_compute(&g, &o, out, &e))
                    die("horizon", &e);
                double dt = bench_now() - t0, dc = bench_cpu_now() - c0;
                best[m] = dt < best[m] ? dt : best[m];
                best_cpu[m] = dc < best_cpu[m] ? dc : best_cpu[m];
            }
        double unbounded = 0.0, unbounded_cpu = 0.0;
        for (int m = 0; m < ndist; m++)
            if (dists[m] == 0) {
                unbounded = best[m];
                unbounded_cpu = best_cpu[m];
            }
        for (int m = 0; m < ndist; m++) {
            double out_mib = cells * o.directions * 4 / 1048576.0;
            printf("horizon %3d directions, max distance %8g m: %.3f s best of %d, "
                   "%8.1f M pixel-directions/s", o.directions, dists[m], best[m], repeat,
                   cells * o.directions / best[m] / 1e6);
            if (unbounded > 0 && dists[m] > 0)
                printf(", %.2fx the unbounded sweep", best[m] / unbounded);
            printf("; CPU %.3f s", best_cpu[m]);
            if (unbounded_cpu > 0 && dists[m] > 0)
                printf(", %.2fx the unbounded's", best_cpu[m] / unbounded_cpu);
            printf("; peak RSS %.0f MiB = DEM %.0f + outputs %.0f + %.0f other\n", peak_mib(),
                   dem_mib, out_mib, peak_mib() - dem_mib - out_mib);
        }
        fflush(stdout);
        free(out);
    }

    float *vis = malloc((size_t)cells * sizeof(float));
    if (!vis)
        return 1;
    const double az[8] = {0, 45, 90, 135, 180, 225, 270, 315};
    double total = 0;
    for (int a = 0; a < 8; a++) {
        double best = INFINITY;
        for (int r = 0; r < repeat; r++) {
            t0 = bench_now();
            if (ts_shm_compute(&g, az[a] + 17.0, 25.0, 0.0, threads, vis, NULL, &e))
                die("shadow height map", &e);
            double dt = bench_now() - t0;
            best = dt < best ? dt : best;
        }
        total += best;
    }
    printf("shadow height map: %.4f s mean per light over 8 azimuths, %8.1f M pixels/s\n",
           total / 8, cells * 8 / total / 1e6);
    printf("peak RSS %.0f MiB (baseline after DEM %.0f MiB)\n", peak_mib(), base_mib);
    free(vis);
    ts_grid_free(&g);
    return 0;
}
