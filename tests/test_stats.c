/* Error statistics of a horizon plane against the oracle. */
#include "test_stats.h"

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "oracle.h"

static const double DEG = 3.14159265358979323846 / 180.0;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct { double err, got, want; int x, y; } cell_err;

/* Keep the 3 largest errors, largest first. */
static void keep_worst(cell_err w[3], cell_err c)
{
    for (int k = 0; k < 3; k++)
        if (c.err > w[k].err) {
            for (int j = 2; j > k; j--)
                w[j] = w[j - 1];
            w[k] = c;
            return;
        }
}

static void print_worst(const char *what, const cell_err w[3])
{
    for (int k = 0; k < 3 && w[k].x >= 0; k++)
        printf("%s(%d,%d) got %.3f want %.3f", k ? "; " : what, w[k].x, w[k].y,
               w[k].got, w[k].want);
}

/* One sweep step in metres at row y: the ray's advance to the next line
 * of the axis it crosses most often; 0 for an axis-aligned ray. */
static double sweep_step(const ts_grid *g, double azimuth, int y)
{
    double sa = fabs(sin(azimuth * DEG)), ca = fabs(cos(azimuth * DEG));
    if (sa < 1e-9 || ca < 1e-9)
        return 0;
    return fmin(ts_grid_cell_x(g, y) / sa, g->cell_y / ca);
}

/* Oracle with the options' max_distance further cut at `cut` metres. */
static double oracle_cut(const ts_grid *g, int x, int y, double azimuth,
                         const ts_horizon_opts *opts, int strict, double cut)
{
    ts_horizon_opts o = *opts;
    if (cut <= 0)
        return -90.0;
    if (!(o.max_distance > 0 && o.max_distance < cut))
        o.max_distance = cut;
    double d_best, d_edge;
    return oracle_horizon_ex(g, x, y, azimuth, &o, strict, &d_best, &d_edge);
}

static double distance_to(double v, double lo, double hi)
{
    return v < lo ? lo - v : v > hi ? v - hi : 0.0;
}

tstat tstat_vs_oracle(const char *label, const ts_grid *g, const float *plane,
                      double azimuth, const ts_horizon_opts *opts, int step)
{
    tstat s = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    s.axis = sweep_step(g, azimuth, 0) == 0;
    size_t cap = (size_t)((g->width + step - 1) / step) *
                 (size_t)((g->height + step - 1) / step);
    double *e = malloc(cap * sizeof *e);
    ck_assert(e != NULL);
    int has_nodata = 0;
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++)
            has_nodata |= isnan(ts_grid_at(g, x, y));
    cell_err worst[3], worst_edge[3], worst_nodata[3];
    for (int k = 0; k < 3; k++)
        worst[k] = worst_edge[k] = worst_nodata[k] = (cell_err){0, 0, 0, -1, -1};
    for (int y = 0; y < g->height; y += step)
        for (int x = 0; x < g->width; x += step) {
            double got = plane[(size_t)y * (size_t)g->width + (size_t)x];
            double d_best, d_edge;
            double want = oracle_horizon_ex(g, x, y, azimuth, opts, 0, &d_best, &d_edge);
            if (isnan(want) || isnan(got)) {
                if (isnan(want) != isnan(got))
                    s.nodata_bad++;
                continue;
            }
            if ((want == -90.0) != (got == -90.0))
                s.minus90_bad++;
            double lo = want, hi = want, err = fabs(got - want), e1;
            if (has_nodata && err > 0) {
                double strict = oracle_horizon_ex(g, x, y, azimuth, opts, 1, &d_best,
                                                  &d_edge);
                lo = fmin(lo, strict), hi = fmax(hi, strict);
                if ((e1 = distance_to(got, lo, hi)) < err) {
                    s.nodata_n++;
                    keep_worst(worst_nodata, (cell_err){err, got, want, x, y});
                    err = e1;
                }
            }
            double last = sweep_step(g, azimuth, y);
            if (got < lo && last > 0 && isfinite(d_edge)) {
                double cut = d_edge - last;
                lo = fmin(lo, oracle_cut(g, x, y, azimuth, opts, 0, cut));
                if (has_nodata)
                    lo = fmin(lo, oracle_cut(g, x, y, azimuth, opts, 1, cut));
                if ((e1 = distance_to(got, lo, hi)) < err) {
                    s.edge_n++;
                    keep_worst(worst_edge, (cell_err){err, got, want, x, y});
                    err = e1;
                }
            }
            e[s.n++] = err;
            s.over += err > 0.5;
            keep_worst(worst, (cell_err){err, got, want, x, y});
        }
    if (s.n > 0) {
        qsort(e, (size_t)s.n, sizeof *e, cmp_double);
        s.median = e[(s.n - 1) / 2];
        long k99 = (long)ceil(0.99 * (double)s.n) - 1;
        s.p99 = e[k99 < 0 ? 0 : k99];
        s.max = e[s.n - 1];
    }
    free(e);
    printf("%-34s az %6.1f: n %6ld median %.4f p99 %.4f max %.3f deg, %ld over 0.5;"
           " -90 mismatches %ld, nodata mismatches %ld", label, azimuth, s.n,
           s.median, s.p99, s.max, s.over, s.minus90_bad, s.nodata_bad);
    print_worst("; worst ", worst);
    printf("\n");
    if (s.edge_n > 0) {
        printf("%-34s az %6.1f: edge allowance used on %ld cells", "", azimuth,
               s.edge_n);
        print_worst(", largest before it: ", worst_edge);
        printf("\n");
    }
    if (s.nodata_n > 0) {
        printf("%-34s az %6.1f: nodata allowance used on %ld cells", "", azimuth,
               s.nodata_n);
        print_worst(", largest before it: ", worst_nodata);
        printf("\n");
    }
    fflush(stdout);
    return s;
}

void tstat_check(const tstat *s, const char *label)
{
    ck_assert_msg(s->n > 0, "%s: no cells compared", label);
    ck_assert_msg(s->nodata_bad == 0, "%s: %ld cells with NaN where the oracle "
                  "has none or vice versa", label, s->nodata_bad);
    ck_assert_msg(s->median <= 0.05, "%s: median error %.4f deg > 0.05", label,
                  s->median);
    ck_assert_msg(s->p99 <= 0.5, "%s: p99 error %.4f deg > 0.5", label, s->p99);
    ck_assert_msg(!s->axis || s->max <= 1e-3, "%s: error %.4f deg on a ray along a grid "
                  "axis, where it must be exact", label, s->max);
}
