/*
 * atlas_bench: size of the far-shadow atlas (Chajdas et al. 2015) in bits
 * per cell per day, and the time to build it.
 *
 *   atlas_bench [--size N] [--steps S] [--threshold T] [--date YYYY-MM-DD]
 *               [--lat L] [--lon L] [--cell M] [--threads T]
 *               [--only jacksboro|fractal] [--out FILE]
 *
 * For jacksboro (tests/data/jacksboro.f32 + .hdr, written by
 * tests/data/make_raw.py) and an N x N fractal DEM (tests/test_dem.h:
 * fBm, Hurst 0.8, 1500 m relief, M metre cells, default 4096 and 30 m),
 * it builds the far-shadow maps of S sun positions (default 158, as in
 * the paper) between sunrise and sunset, denser near dawn and dusk, with
 * the far threshold T cells (default 512), stores them as an atlas (8 x 8
 * tile dictionary + index maps + LZMA) and reports the file size per cell,
 * the number of distinct tiles, the share of shadowed cells and the
 * times. Each atlas is read back and compared with the maps (lossless).
 * The fractal is placed at --lat/--lon (default 46.5 N, 7.9 E) on --date
 * (default 2026-06-21 and 2026-12-21); jacksboro at its own place.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "day_cycle.h"
#include "shadow_atlas.h"
#include "bench_clock.h"
#include "test_dem.h"

static void die(const char *what, const ts_error *e)
{
    fprintf(stderr, "atlas_bench: %s%s%s\n", what, e ? ": " : "", e ? e->message : "");
    exit(1);
}

typedef struct {
    int steps, threshold, threads;
    const char *out;
} params;

/* One atlas: S maps of one day. */
static void one_day(const char *name, const ts_grid *g, double lon, double lat,
                    const char *date, int offset, const params *p)
{
    ts_error err;
    int y, m, d;
    if (ts_parse_date(date, &y, &m, &d, &err))
        die("date", &err);
    double north = 0;
    ts_sun_sites s = {1, 1, 0, 0, 0, 0, &lon, &lat, &north};
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.threads = p->threads;
    double start = ts_local_midnight(y, m, d, offset);
    double *t = malloc((size_t)p->steps * sizeof *t);
    int n;
    if (ts_day_atlas_times(&s, &o, start, 86400, p->steps, t, &n, &err))
        die("times", &err);
    if (n == 0) {
        printf("%s %s: the sun does not rise\n", name, date);
        free(t);
        return;
    }
    size_t cells = (size_t)g->width * g->height;
    double cell_min = g->cell_y;
    for (int r = 0; r < g->height; r++)
        cell_min = fmin(cell_min, ts_grid_cell_x(g, r));
    double T = p->threshold * cell_min;
    uint8_t *map = malloc(cells), *back = malloc(cells);
    uint8_t **keep = calloc((size_t)n, sizeof *keep);
    if (!map || !back || !keep)
        die("out of memory", NULL);
    ts_atlas_writer *w;
    if (ts_atlas_writer_new(g->width, g->height, &w, &err))
        die("writer", &err);
    double t_far = 0, t_tile = 0, shadowed = 0;
    for (int k = 0; k < n; k++) {
        ts_sun_sample sun;
        if (ts_sun_at_site(&s, &o, t[k], &sun, &err))
            die("sun", &err);
        double t0 = bench_now();
        if (ts_far_shadow(g, sun.grid_azimuth, sun.elevation, T, &o.horizon, map, &err))
            die("far shadow", &err);
        double t1 = bench_now();
        ts_atlas_step rec = {t[k], sun.azimuth, sun.grid_azimuth, sun.elevation, offset};
        if (ts_atlas_writer_add(w, map, g->width, &rec, &err))
            die("add", &err);
        t_tile += bench_now() - t1;
        t_far += t1 - t0;
        size_t c = 0;
        for (size_t i = 0; i < cells; i++)
            c += map[i] == 1;
        shadowed += c;
        /* keep a few maps to check the round trip */
        if (k % 16 == 0 || k == n - 1) {
            keep[k] = malloc(cells);
            if (!keep[k])
                die("out of memory", NULL);
            memcpy(keep[k], map, cells);
        }
    }
    ts_atlas_info info;
    memset(&info, 0, sizeof info);
    info.threshold_cells = p->threshold;
    info.threshold_m = T;
    uint8_t *file;
    size_t size;
    double t0 = bench_now();
    if (ts_atlas_writer_finish(w, &info, &file, &size, &err))
        die("finish", &err);
    double t_lzma = bench_now() - t0;
    ts_atlas_writer_free(w);
    t0 = bench_now();
    ts_atlas *a;
    if (ts_atlas_open(file, size, &a, &err))
        die("open", &err);
    double t_open = bench_now() - t0;
    const ts_atlas_info *ai = ts_atlas_get_info(a);
    int same = 1;
    for (int k = 0; k < n; k++) {
        if (!keep[k])
            continue;
        if (ts_atlas_read(a, k, 0, 0, g->width, g->height, back, g->width, &err))
            die("read", &err);
        same &= memcmp(back, keep[k], cells) == 0;
        free(keep[k]);
    }
    if (p->out) {
        FILE *f = fopen(p->out, "wb");
        if (f) {
            fwrite(file, 1, size, f);
            fclose(f);
        }
    }
    double bits = size * 8.0 / cells;
    printf("%-10s %dx%d %s lat %.2f: %d maps %.2f..%.2f h, threshold %d cells (%.0f m): "
           "%.1f%% far shadow, %u tiles (%d-byte index), dict %zu B, index %zu B, "
           "file %zu B = %.4f bits/cell/day (%.5f per map); far shadows %.2f s, tiles "
           "%.2f s, LZMA %.2f s, open %.2f s; round trip %s\n",
           name, g->width, g->height, date, lat, n, (t[0] - start) / 3600,
           (t[n - 1] - start) / 3600, p->threshold, T, 100.0 * shadowed / (cells * (double)n),
           ai->dictionary_tiles, ai->index_bytes, ai->dictionary_bytes,
           ai->index_bytes_total, size, bits, bits / n, t_far, t_tile, t_lzma, t_open,
           same ? "identical" : "DIFFERENT");
    fflush(stdout);
    ts_atlas_free(a);
    free(file);
    free(keep);
    free(map);
    free(back);
    free(t);
    if (!same)
        exit(1);
}

int main(int argc, char **argv)
{
    params p = {158, 512, 0, NULL};
    int size = 4096;
    double cell = 30.0, lat = 46.5, lon = 7.9;
    const char *date = NULL, *only = NULL;
    int thresholds_given = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--steps") && i + 1 < argc)
            p.steps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threshold") && i + 1 < argc) {
            p.threshold = atoi(argv[++i]);
            thresholds_given = 1;
        } else if (!strcmp(argv[i], "--date") && i + 1 < argc)
            date = argv[++i];
        else if (!strcmp(argv[i], "--lat") && i + 1 < argc)
            lat = atof(argv[++i]);
        else if (!strcmp(argv[i], "--lon") && i + 1 < argc)
            lon = atof(argv[++i]);
        else if (!strcmp(argv[i], "--cell") && i + 1 < argc)
            cell = atof(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            p.threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--only") && i + 1 < argc)
            only = argv[++i];
        else if (!strcmp(argv[i], "--out") && i + 1 < argc)
            p.out = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--size N] [--steps S] [--threshold T] [--date "
                    "YYYY-MM-DD] [--lat L] [--lon L] [--cell M] [--threads T] [--only "
                    "jacksboro|fractal] [--out FILE]\n", argv[0]);
            return 2;
        }
    }
    if (size < 8 || p.steps < 1 || p.threshold < 1) {
        fprintf(stderr, "atlas_bench: --size >= 8, --steps >= 1, --threshold >= 1\n");
        return 2;
    }
    printf("command:");
    for (int i = 0; i < argc; i++)
        printf(" %s", argv[i]);
    printf("\ncores: %d, threads: %d\n", ts_cpu_count(),
           p.threads > 0 ? p.threads : ts_cpu_count());
    const char *dates[] = {"2026-06-21", "2026-12-21"};
    int ndates = date ? 1 : 2;
    if (date)
        dates[0] = date;
    ts_error err;
    if (!only || !strcmp(only, "jacksboro")) {
        ts_grid g;
        double jlon, jlat;
        char msg[4200];
        if (tdem_read(&g, "jacksboro", &jlon, &jlat, msg, sizeof msg) != 0) {
            fprintf(stderr, "atlas_bench: %s\n", msg);
        } else {
            /* the default threshold (512 cells) exceeds most of this small
             * DEM; smaller ones show what its relief casts */
            int ths[] = {p.threshold, 64, 16};
            int nth = thresholds_given ? 1 : 3;
            for (int k = 0; k < nth; k++)
                for (int di = 0; di < ndates; di++) {
                    params q = p;
                    q.threshold = ths[k];
                    one_day("jacksboro", &g, jlon, jlat, dates[di], -300, &q);
                }
            ts_grid_free(&g);
        }
    }
    if (!only || !strcmp(only, "fractal")) {
        ts_grid g;
        if (ts_grid_create(&g, size, size, cell, cell, &err))
            die("grid", &err);
        tdem_fbm(&g, 1, 0.8, 1500.0);
        for (int di = 0; di < ndates; di++)
            one_day("fractal", &g, lon, lat, dates[di], (int)lround(lon / 15.0) * 60, &p);
        ts_grid_free(&g);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("peak memory: %.0f MiB\n", ru.ru_maxrss / 1024.0);
    return 0;
}
