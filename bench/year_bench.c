/*
 * year_bench: a year of sun on a large DEM. Times, in one run, hours of sun
 * and insolation over a year sampled every DAY_INTERVAL days at
 * STEP_MINUTES steps (ts_sun_hours_range, ts_insolation_range: horizons
 * swept once for HORIZON_DIRECTIONS azimuths) and one day at the same step
 * by the per-step exact ts_sun_hours (one sweep per sun position), with the
 * machine, its load and the command.
 *
 *   year_bench [--size N] [--cell M] [--year Y] [--interval D]
 *              [--step MIN] [--dirs D1,D2,...] [--day YYYY-MM-DD]
 *              [--lat L] [--lon L] [--threads T] [--no-insolation]
 *
 * The DEM is an N x N fBm (tests/test_dem.h: Hurst 0.8, 1500 m relief,
 * M metre cells; default 4096 and 30 m) at --lat/--lon (default 46.5 N,
 * 7.9 E, UTC+1); the year default 2026, interval 14 days, 30-minute steps,
 * directions TS_RANGE_HORIZON_DIRECTIONS; the single day 2026-03-20 (an
 * equinox: a median day length).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include "bench_pages.h"
#include "day_cycle.h"
#include "bench_clock.h"
#include "test_dem.h"

static void die(const char *what, const ts_error *e)
{
    fprintf(stderr, "year_bench: %s%s%s\n", what, e ? ": " : "", e ? e->message : "");
    exit(1);
}

static void usage(FILE *to)
{
    fprintf(to,
            "usage: year_bench [--size N] [--cell M] [--year Y] [--interval D]\n"
            "                  [--step MIN] [--dirs D1,D2,...] [--day YYYY-MM-DD]\n"
            "                  [--lat L] [--lon L] [--threads T] [--no-insolation]\n"
            "  --size N          the N x N fBm DEM, 16..65536 (default 4096)\n"
            "  --cell M          its cells in metres (default 30)\n"
            "  --year Y          the year (default 2026)\n"
            "  --interval D      one day every D days of it (default %d)\n"
            "  --step MIN        minutes between sun positions (default %g)\n"
            "  --dirs D1,D2,...  horizon directions of the year's runs, one run each\n"
            "                    (default %d)\n"
            "  --day YYYY-MM-DD  the day of per-step sweeps (default 2026-03-20)\n"
            "  --lat L, --lon L  where the DEM lies, UTC+1 (default 46.5, 7.9)\n"
            "  --threads T       worker threads (default 0: every core)\n"
            "  --no-insolation   hours of sun only, no insolation\n",
            TS_RANGE_DAY_INTERVAL, TS_RANGE_STEP_MINUTES, TS_RANGE_HORIZON_DIRECTIONS);
}

static void usage_error(const char *what, const char *opt)
{
    fprintf(stderr, "year_bench: %s%s\n", what, opt ? opt : "");
    usage(stderr);
    exit(2);
}

/* Whether `a` is one of the options that take a value. */
static int takes_value(const char *a)
{
    static const char *const opts[] = {"--size", "--cell",  "--year", "--interval",
                                       "--step", "--dirs",  "--day",  "--lat",
                                       "--lon",  "--threads"};
    for (size_t k = 0; k < sizeof opts / sizeof *opts; k++)
        if (!strcmp(a, opts[k]))
            return 1;
    return 0;
}

static void print_load(const char *when)
{
    double l[3] = {0, 0, 0};
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf %lf %lf", &l[0], &l[1], &l[2]) != 3)
            l[0] = l[1] = l[2] = NAN;
        fclose(f);
    }
    printf("load average %s: %.2f %.2f %.2f\n", when, l[0], l[1], l[2]);
}

static void print_machine(int argc, char **argv)
{
    printf("command:");
    for (int i = 0; i < argc; i++)
        printf(" %s", argv[i]);
    struct utsname u;
    if (uname(&u) == 0)
        printf("\nmachine: %s %s %s", u.sysname, u.release, u.machine);
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "model name", 10) == 0) {
            char *c = strchr(line, ':');
            printf(", %s", c ? c + 2 : line);
            break;
        }
    if (f)
        fclose(f);
    printf("cores online: %ld\n", sysconf(_SC_NPROCESSORS_ONLN));
    print_load("at start");
}

/* Mean of the valid cells. */
static double mean_of(const float *v, size_t n)
{
    double s = 0;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (!isnan(v[i])) {
            s += v[i];
            k++;
        }
    return k ? s / k : NAN;
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* lines as they come, when redirected */
    int size = 4096, year = 2026, interval = TS_RANGE_DAY_INTERVAL, threads = 0, insol = 1;
    double cell = 30, step = TS_RANGE_STEP_MINUTES, lat = 46.5, lon = 7.9;
    const char *dirs = NULL, *day = "2026-03-20";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(a, "--no-insolation")) {
            insol = 0;
            continue;
        }
        if (!takes_value(a))
            usage_error("unknown option ", a);
        if (!v)
            usage_error("a value is missing after ", a);
        i++;
        if (!strcmp(a, "--size")) size = atoi(v);
        else if (!strcmp(a, "--cell")) cell = atof(v);
        else if (!strcmp(a, "--year")) year = atoi(v);
        else if (!strcmp(a, "--interval")) interval = atoi(v);
        else if (!strcmp(a, "--step")) step = atof(v);
        else if (!strcmp(a, "--dirs")) dirs = v;
        else if (!strcmp(a, "--day")) day = v;
        else if (!strcmp(a, "--lat")) lat = atof(v);
        else if (!strcmp(a, "--lon")) lon = atof(v);
        else if (!strcmp(a, "--threads")) threads = atoi(v);
        else usage_error("unknown option ", a); /* not reached: takes_value */
    }
    if (size < 16 || size > 65536 || !(cell > 0))
        die("--size must be 16..65536 and --cell positive", NULL);
    print_machine(argc, argv);

    ts_error err;
    ts_grid g;
    if (ts_grid_create(&g, size, size, cell, cell, &err))
        die("grid", &err);
    double t0 = bench_now();
    tdem_fbm(&g, 1, 0.8, 1500.0);
    printf("DEM: %d x %d fBm, %g m cells, 1500 m relief, at %.2f N %.2f E, UTC+1 (%.1f s to "
           "make)\n", size, size, cell, lat, lon, bench_now() - t0);
    size_t n = (size_t)size * size;
    float *out = malloc(n * sizeof *out);
    if (!out)
        die("cannot allocate the output", NULL);
    bench_touch_pages(out, n * sizeof *out); /* mapped before the day's run, not in it */
    double north = 0;
    ts_sun_sites s = {1, 1, 0, 0, 0, 0, &lon, &lat, &north};
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.threads = threads;

    /* one day by the per-step exact sweeps */
    int y, m, d;
    if (ts_parse_date(day, &y, &m, &d, &err))
        die("--day", &err);
    t0 = bench_now();
    double c0 = bench_cpu_now();
    if (ts_sun_hours(&g, &s, &o, ts_local_midnight(y, m, d, 60), 86400, step * 60, out, &err))
        die("ts_sun_hours", &err);
    double t_day = bench_now() - t0, c_day = bench_cpu_now() - c0;
    printf("one day %s, %g-min steps, ts_sun_hours (a sweep per sun position): %.1f s wall, "
           "%.1f s CPU, mean %.2f h\n", day, step, t_day, c_day, mean_of(out, n));
    print_load("after the day");

    ts_date_range r;
    ts_date_range_default(&r);
    r.first_year = r.last_year = year;
    r.first_month = r.first_day = 1;
    r.last_month = 12;
    r.last_day = 31;
    r.utc_offset_minutes = 60;
    r.day_interval = interval;
    r.step_minutes = step;
    char list[256];
    snprintf(list, sizeof list, "%s", dirs ? dirs : "");
    if (!dirs)
        snprintf(list, sizeof list, "%d", TS_RANGE_HORIZON_DIRECTIONS);
    for (char *tok = strtok(list, ","); tok; tok = strtok(NULL, ",")) {
        r.horizon_directions = atoi(tok);
        t0 = bench_now();
        c0 = bench_cpu_now();
        if (ts_sun_hours_range(&g, &s, &o, &r, out, &err))
            die("ts_sun_hours_range", &err);
        double t_sh = bench_now() - t0, c_sh = bench_cpu_now() - c0;
        printf("year %d, interval %d d, %g-min steps, HORIZON_DIRECTIONS %d: sun hours %.1f s "
               "wall (%.2fx the day), %.1f s CPU (%.2fx), mean %.1f h\n", year, interval, step,
               r.horizon_directions, t_sh, t_sh / t_day, c_sh, c_sh / c_day, mean_of(out, n));
        if (insol) {
            t0 = bench_now();
            c0 = bench_cpu_now();
            if (ts_insolation_range(&g, &s, &o, &r, out, NULL, NULL, &err))
                die("ts_insolation_range", &err);
            double t_in = bench_now() - t0, c_in = bench_cpu_now() - c0;
            printf("year %d, interval %d d, %g-min steps, HORIZON_DIRECTIONS %d: insolation "
                   "%.1f s wall (%.2fx the day), %.1f s CPU (%.2fx), mean %.1f kWh/m2\n", year,
                   interval, step, r.horizon_directions, t_in, t_in / t_day, c_in, c_in / c_day,
                   mean_of(out, n) / 1000.0);
        }
        print_load("after the year");
    }
    free(out);
    ts_grid_free(&g);
    return 0;
}
