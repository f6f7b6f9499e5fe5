/* Pyramid horizons (core/pyramid*.c) against the exact sweep: convergence
 * with the level offset on a cone and a V-valley, the sky-view factor on
 * the real DEMs, nodata, threads and bad input. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"

static const double DEG = 3.14159265358979323846 / 180.0;

static ts_horizon_opts hopts(int directions, int curvature)
{
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = directions;
    o.start_azimuth = 7.5; /* off the axes as well */
    o.curvature = curvature;
    return o;
}

static ts_pyramid_opts popts(double k, double offset, ts_pyramid_reconstruction rec)
{
    ts_pyramid_opts p;
    ts_pyramid_opts_default(&p);
    p.level_step = k;
    p.offset = offset;
    p.reconstruction = rec;
    return p;
}

static float *exact_planes(const ts_grid *g, const ts_horizon_opts *o)
{
    float *out = tdem_floats((size_t)g->width * g->height * o->directions);
    ts_error err;
    ck_assert_msg(ts_horizon_compute(g, o, out, &err) == TS_OK, "%s", err.message);
    return out;
}

static float *pyramid_planes(const ts_grid *g, const ts_pyramid_opts *p,
                             const ts_horizon_opts *o)
{
    float *out = tdem_floats((size_t)g->width * g->height * o->directions);
    ts_error err;
    ck_assert_msg(ts_pyramid_horizon_compute(g, p, o, out, &err) == TS_OK, "%s", err.message);
    return out;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct {
    double median, p99, max;
    long n;
} err_stats;

/* |a - b| over the n values where both are finite; NaN-ness must agree. */
static err_stats diff_stats(const float *a, const float *b, size_t n)
{
    double *e = malloc(n * sizeof *e);
    ck_assert(e != NULL);
    err_stats s = {0, 0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg((a[i] != a[i]) == (b[i] != b[i]), "nodata differs at %zu: %g vs %g", i,
                      a[i], b[i]);
        if (a[i] == a[i])
            e[s.n++] = fabs((double)a[i] - b[i]);
    }
    if (s.n > 0) {
        qsort(e, (size_t)s.n, sizeof *e, cmp_double);
        s.median = e[s.n / 2];
        s.p99 = e[(size_t)(0.99 * (s.n - 1))];
        s.max = e[s.n - 1];
    }
    free(e);
    return s;
}

/* The horizon errors of the pyramid for each offset, printed and returned
 * (worst first offset last). */
static void offset_series(const char *label, const ts_grid *g, const ts_horizon_opts *o,
                          const double *offsets, int n_off, err_stats *st)
{
    size_t n = (size_t)g->width * g->height * o->directions;
    float *ex = exact_planes(g, o);
    for (int i = 0; i < n_off; i++) {
        ts_pyramid_opts p = popts(4, offsets[i], TS_PYRAMID_BSPLINE);
        float *py = pyramid_planes(g, &p, o);
        st[i] = diff_stats(ex, py, n);
        printf("%s k=4 o=%-4g horizon |pyramid - exact|: median %.4f p99 %.4f max %.4f deg\n",
               label, offsets[i], st[i].median, st[i].p99, st[i].max);
        free(py);
    }
    free(ex);
}

static void cone(ts_grid *g)
{
    /* z = 1000 - 0.5 r on a 10 m grid, 0 at the foot */
    tdem_create(g, 161, 161, 10.0, 10.0);
    for (int y = 0; y < 161; y++)
        for (int x = 0; x < 161; x++) {
            double z = 1000.0 - 0.5 * hypot(x - 80, y - 80) * 10.0;
            g->z[y * g->stride + x] = (float)(z > 300 ? z : 300);
        }
}

static void v_valley(ts_grid *g)
{
    /* walls at 30 degrees either side of a north-south bottom */
    tdem_create(g, 161, 161, 10.0, 10.0);
    for (int y = 0; y < 161; y++)
        for (int x = 0; x < 161; x++)
            g->z[y * g->stride + x] = (float)(tan(30 * DEG) * abs(x - 80) * 10.0);
}

static const double OFFSETS[] = {0, 0.5, 1, 2, 4, 8};
#define N_OFF ((int)(sizeof OFFSETS / sizeof OFFSETS[0]))

static void convergence(const char *label, void (*make)(ts_grid *), double want_p99,
                        double want_median)
{
    ts_grid g;
    make(&g);
    ts_horizon_opts o = hopts(16, 0);
    err_stats st[N_OFF];
    offset_series(label, &g, &o, OFFSETS, N_OFF, st);
    /* the error falls as the offset grows (a little noise allowed), and the
     * largest offset reads the DEM itself */
    for (int i = 1; i < N_OFF; i++)
        ck_assert_msg(st[i].p99 <= st[i - 1].p99 * 1.05 + 1e-3,
                      "%s: p99 grew from o=%g to o=%g (%g -> %g)", label, OFFSETS[i - 1],
                      OFFSETS[i], st[i - 1].p99, st[i].p99);
    ck_assert_msg(st[N_OFF - 1].p99 < st[0].p99 / 2, "%s: p99 %g at o=%g, %g at o=0", label,
                  st[N_OFF - 1].p99, OFFSETS[N_OFF - 1], st[0].p99);
    ck_assert_msg(st[N_OFF - 1].p99 <= want_p99 && st[N_OFF - 1].median <= want_median,
                  "%s: at o=%g median %g p99 %g (want <= %g, %g)", label, OFFSETS[N_OFF - 1],
                  st[N_OFF - 1].median, st[N_OFF - 1].p99, want_median, want_p99);
    ts_grid_free(&g);
}

START_TEST(test_cone_converges)
{
    convergence("cone", cone, 1.0, 0.05);
}
END_TEST

START_TEST(test_valley_converges)
{
    convergence("V-valley", v_valley, 1.0, 0.05);
}
END_TEST

/* svf of the real DEMs, pyramid against exact: the errors stated in
 * docs/methods.md (16 directions, curvature on, k = 4), bounded with room. */
static void real_svf(const char *name, double offset, double want_median, double want_p99)
{
    ts_grid g;
    tdem_load(&g, name);
    ts_horizon_opts o = hopts(16, 1);
    o.start_azimuth = 0;
    size_t n = (size_t)g.width * g.height;
    float *nx = tdem_floats(n), *ny = tdem_floats(n), *nz = tdem_floats(n);
    float *se = tdem_floats(n), *sp = tdem_floats(n);
    ts_error err;
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    float *ex = exact_planes(&g, &o);
    ts_pyramid_opts p = popts(4, offset, TS_PYRAMID_BSPLINE);
    float *py = pyramid_planes(&g, &p, &o);
    err_stats h = diff_stats(ex, py, n * o.directions);
    const ts_sky_request re = {.grid = &g, .nx = nx, .ny = ny, .nz = nz, .horizons = ex,
                               .opts = &o, .svf = se};
    ts_sky_request rp = re;
    rp.horizons = py;
    rp.svf = sp;
    ck_assert(ts_sky_terms(&re, &err) == TS_OK);
    ck_assert(ts_sky_terms(&rp, &err) == TS_OK);
    err_stats s = diff_stats(se, sp, n);
    printf("%s o=%g: horizon |pyramid - exact| median %.3f p99 %.3f deg; svf median %.4f "
           "p99 %.4f max %.4f\n", name, offset, h.median, h.p99, s.median, s.p99, s.max);
    ck_assert_msg(s.median <= want_median && s.p99 <= want_p99,
                  "%s o=%g: svf error median %g p99 %g (want <= %g, %g)", name, offset,
                  s.median, s.p99, want_median, want_p99);
    free(nx), free(ny), free(nz), free(se), free(sp), free(ex), free(py);
    ts_grid_free(&g);
}

START_TEST(test_jacksboro_svf)
{
    real_svf("jacksboro", 0, 0.010, 0.060);
    real_svf("jacksboro", 2, 0.005, 0.025);
}
END_TEST

START_TEST(test_lux_svf)
{
    /* nodata outside Luxembourg: the NaN cells must agree (diff_stats) */
    real_svf("lux_elev", 0, 0.001, 0.005);
}
END_TEST

/* The B-spline's maximum never exceeds its largest sample: below the
 * maximum over levels, which sees the same samples (both end where the
 * ray leaves the DEM). */
START_TEST(test_bspline_below_level_max)
{
    ts_grid g;
    tdem_load(&g, "jacksboro");
    ts_horizon_opts o = hopts(8, 1);
    size_t n = (size_t)g.width * g.height * o.directions;
    ts_pyramid_opts pb = popts(4, 0, TS_PYRAMID_BSPLINE), pm = popts(4, 0, TS_PYRAMID_LEVEL_MAX);
    float *b = pyramid_planes(&g, &pb, &o), *m = pyramid_planes(&g, &pm, &o);
    long above = 0;
    for (size_t i = 0; i < n; i++)
        above += b[i] > m[i] + 1e-3f;
    err_stats d = diff_stats(b, m, n);
    printf("jacksboro level max - B-spline: median %.3f p99 %.3f deg\n", d.median, d.p99);
    ck_assert_msg(above == 0, "%ld cells with the spline above the level maximum", above);
    free(b), free(m);
    ts_grid_free(&g);
}
END_TEST

/* A flat plane: 0 wherever something lies beyond the cell, -90 on the
 * edge cells that look out of the grid, as the exact sweep. */
START_TEST(test_flat_plane)
{
    ts_grid g;
    tdem_create(&g, 50, 40, 10.0, 10.0);
    tdem_fill(&g, 100.0f);
    ts_horizon_opts o = hopts(16, 0);
    size_t n = 50 * 40 * 16;
    float *ex = exact_planes(&g, &o);
    ts_pyramid_opts p = popts(4, 0, TS_PYRAMID_BSPLINE);
    float *py = pyramid_planes(&g, &p, &o);
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg((ex[i] == -90.0f) == (py[i] == -90.0f), "cell %zu: exact %g pyramid %g",
                      i, ex[i], py[i]);
        ck_assert_msg(py[i] == -90.0f || fabsf(py[i]) < 1e-4f, "cell %zu: %g", i, py[i]);
    }
    free(ex), free(py);
    ts_grid_free(&g);
}
END_TEST

/* Beside a void a cell's own height on the coarse levels, whose footprint
 * there is mostly void, is its DEM height. It was nodata, so each of the
 * cell's coarse samples was dropped: on jacksboro with a void of 40 x 50
 * cells, 17.5 % of the cell-directions within 10 cells of it read more
 * than 5 degrees below exact, against 11.7 % elsewhere; now 13.4 %. The
 * rest of the excess is the samples whose footprint touches the void (no
 * occluder there, methods.md). */
START_TEST(test_void_neighbours)
{
    ts_grid g;
    tdem_load(&g, "jacksboro");
    const int W = g.width, H = g.height, R = 10;
    for (int y = 100; y < 140; y++)
        for (int x = 150; x < 200; x++)
            g.z[(size_t)y * g.stride + x] = NAN;
    ts_horizon_opts o = hopts(16, 1);
    ts_pyramid_opts p = popts(4, 0, TS_PYRAMID_BSPLINE);
    float *ex = exact_planes(&g, &o), *py = pyramid_planes(&g, &p, &o);
    long low[2] = {0, 0}, all[2] = {0, 0}; /* [near the void, elsewhere] */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            if (g.z[(size_t)y * g.stride + x] != g.z[(size_t)y * g.stride + x])
                continue;
            const int near = y >= 100 - R && y < 140 + R && x >= 150 - R && x < 200 + R;
            for (int k = 0; k < o.directions; k++) {
                size_t i = ((size_t)k * H + y) * W + x;
                low[!near] += py[i] < ex[i] - 5.0f;
                all[!near]++;
            }
        }
    const double near_pct = 100.0 * low[0] / all[0], else_pct = 100.0 * low[1] / all[1];
    printf("jacksboro with a void: pyramid more than 5 deg below exact on %.1f %% of the "
           "cell-directions within %d cells of the void, %.1f %% elsewhere\n",
           near_pct, R, else_pct);
    ck_assert_msg(near_pct <= else_pct + 2.5, "%.2f %% beside the void, %.2f %% elsewhere",
                  near_pct, else_pct);
    free(ex), free(py);
    ts_grid_free(&g);
}
END_TEST

/* Any thread count gives the same planes, bit for bit. */
START_TEST(test_threads_identical)
{
    ts_grid g;
    tdem_load(&g, "lux_elev");
    ts_horizon_opts o = hopts(8, 1);
    size_t n = (size_t)g.width * g.height * o.directions;
    ts_pyramid_opts p = popts(3, 0.5, TS_PYRAMID_BSPLINE);
    o.threads = 1;
    float *a = pyramid_planes(&g, &p, &o);
    o.threads = 3;
    float *b = pyramid_planes(&g, &p, &o);
    ck_assert(memcmp(a, b, n * sizeof *a) == 0);
    free(a), free(b);
    ts_grid_free(&g);
}
END_TEST

/* ts_pyramid_horizons: the azimuths computed together are bit for bit
 * those computed one at a time, for both reconstructions, with a level
 * offset, nodata (lux_elev) and a maximum distance. */
START_TEST(test_batch_identical)
{
    ts_grid g;
    tdem_load(&g, "lux_elev");
    size_t cells = (size_t)g.width * g.height;
    const double az[TS_PYRAMID_BATCH + 2] = {7.5, 100, 181.25, 271, 333.3, 45};
    float *one = tdem_floats(cells), *many = tdem_floats(cells * TS_PYRAMID_BATCH);
    ts_error err;
    for (int v = 0; v < 4; v++) {
        ts_pyramid_opts p = popts(4, v & 1 ? 0.5 : 0, v & 2 ? TS_PYRAMID_LEVEL_MAX
                                                          : TS_PYRAMID_BSPLINE);
        ts_horizon_opts o = hopts(1, 1);
        o.max_distance = v == 3 ? 900 : 0;
        ts_pyramid *pyr;
        ck_assert_msg(ts_pyramid_build(&g, &p, 0, &pyr, &err) == TS_OK, "%s", err.message);
        for (int count = 2; count <= TS_PYRAMID_BATCH; count++) {
            float *planes[TS_PYRAMID_BATCH];
            for (int k = 0; k < count; k++)
                planes[k] = many + cells * k;
            const double *a = az + (count + v) % 3;
            ck_assert_msg(ts_pyramid_horizons(pyr, count, a, &o, planes, &err) == TS_OK, "%s",
                          err.message);
            for (int k = 0; k < count; k++) {
                ck_assert(ts_pyramid_horizon(pyr, a[k], &o, one, &err) == TS_OK);
                ck_assert_msg(memcmp(one, planes[k], cells * sizeof *one) == 0,
                              "variant %d, %d at once: azimuth %g differs", v, count, a[k]);
            }
        }
        ts_pyramid_free(pyr);
    }
    free(one), free(many);
    ts_grid_free(&g);
}
END_TEST

/* What the sky terms are summed from and into (test_sky_fused_identical). */
typedef struct {
    const ts_grid *g;
    const float *nx, *ny, *nz;
    ts_svf_model model;
    int wanted[3]; /* svf, sky light, openness */
} sky_case;

/* The batch az[0..count) as before the sums were fused: the planes without
 * the edge, the edge applied after the rows (ts_horizon_edge_apply), then
 * each plane's terms in turn (ts_sky_accumulate_model) into acc. Returns
 * how many cells the edge changed. */
static size_t sky_by_planes(const ts_pyramid *pyr, const sky_case *c, const ts_horizon_opts *o,
                            int count, const double *az, float *const *planes,
                            float *const *acc)
{
    ts_error err;
    ts_horizon_opts open = *o;
    open.edge = TS_EDGE_OPEN;
    size_t cells = (size_t)c->g->width * c->g->height, changed = 0;
    float *before = tdem_floats(cells);
    ck_assert(ts_pyramid_horizons(pyr, count, az, &open, planes, &err) == TS_OK);
    for (int i = 0; i < count; i++) {
        memcpy(before, planes[i], cells * sizeof *before);
        ck_assert(ts_horizon_edge_apply(c->g, az[i], o, planes[i], &err) == TS_OK);
        for (size_t j = 0; j < cells; j++)
            changed += memcmp(&before[j], &planes[i][j], sizeof *before) != 0;
        ck_assert(ts_sky_accumulate_model(c->g, c->nx, c->ny, c->nz, planes[i], az[i],
                                          o->directions, c->model, o->threads, acc[0], acc[1],
                                          acc[2], &err) == TS_OK);
    }
    free(before);
    return changed;
}

/* ts_pyramid_horizons_sky against sky_by_planes over every direction of o:
 * the planes and each sum memcmp-equal, also the sums without planes (out
 * NULL: each row in scratch); and ts_pyramid_horizons, which applies the
 * edge span by span too, gives the same planes. */
static void check_sky_fused(const ts_pyramid *pyr, const sky_case *c, const ts_horizon_opts *o)
{
    size_t cells = (size_t)c->g->width * c->g->height;
    float *a = tdem_floats(cells * TS_PYRAMID_BATCH), *b = tdem_floats(cells * TS_PYRAMID_BATCH);
    float *sums = tdem_floats(cells * 9), *acc_a[3], *acc_b[3], *acc_c[3];
    memset(sums, 0, cells * 9 * sizeof *sums);
    for (int t = 0; t < 3; t++) {
        acc_a[t] = c->wanted[t] ? sums + cells * t : NULL;
        acc_b[t] = c->wanted[t] ? sums + cells * (3 + t) : NULL;
        acc_c[t] = c->wanted[t] ? sums + cells * (6 + t) : NULL;
    }
    ts_pyramid_sky sky = {c->nx, c->ny, c->nz, o->directions, c->model, acc_b[0], acc_b[1],
                          acc_b[2]};
    ts_pyramid_sky sky_c = {c->nx, c->ny, c->nz, o->directions, c->model, acc_c[0], acc_c[1],
                            acc_c[2]};
    ts_error err;
    size_t changed = 0;
    for (int k = 0; k < o->directions; k += TS_PYRAMID_BATCH) {
        int count = o->directions - k < TS_PYRAMID_BATCH ? o->directions - k : TS_PYRAMID_BATCH;
        double az[TS_PYRAMID_BATCH];
        float *pa[TS_PYRAMID_BATCH], *pb[TS_PYRAMID_BATCH];
        for (int i = 0; i < count; i++) {
            az[i] = ts_horizon_azimuth(o, k + i);
            pa[i] = a + cells * i, pb[i] = b + cells * i;
        }
        changed += sky_by_planes(pyr, c, o, count, az, pa, acc_a);
        ck_assert_msg(ts_pyramid_horizons_sky(pyr, count, az, o, &sky, pb, &err) == TS_OK,
                      "%s", err.message);
        ck_assert_msg(ts_pyramid_horizons_sky(pyr, count, az, o, &sky_c, NULL, &err) == TS_OK,
                      "%s", err.message);
        ck_assert_msg(memcmp(a, b, cells * count * sizeof *a) == 0, "edge %d: planes differ",
                      (int)o->edge);
        ck_assert(ts_pyramid_horizons(pyr, count, az, o, pb, &err) == TS_OK);
        ck_assert(memcmp(a, b, cells * count * sizeof *a) == 0);
    }
    /* the edge had cells to change (none with TS_EDGE_OPEN) */
    ck_assert((o->edge == TS_EDGE_OPEN) == (changed == 0));
    for (int t = 0; t < 3; t++) {
        ck_assert_msg(!c->wanted[t] || memcmp(acc_a[t], acc_b[t], cells * sizeof(float)) == 0,
                      "edge %d, model %d: sum %d differs", (int)o->edge, (int)c->model, t);
        ck_assert_msg(!c->wanted[t] || memcmp(acc_a[t], acc_c[t], cells * sizeof(float)) == 0,
                      "edge %d, model %d: sum %d without planes differs", (int)o->edge,
                      (int)c->model, t);
    }
    free(a), free(b), free(sums);
}

/* ts_pyramid_horizons_sky: the planes, and the sums of svf (both models),
 * sky light and openness, bit for bit those of the planes summed one by
 * one after the edge, with nodata (lux_elev), 3 threads, batches of 8 and
 * 5, both reconstructions and every edge (one capped by a distance). */
START_TEST(test_sky_fused_identical)
{
    ts_grid g;
    tdem_load(&g, "lux_elev");
    size_t cells = (size_t)g.width * g.height;
    float *nx = tdem_floats(cells), *ny = tdem_floats(cells), *nz = tdem_floats(cells);
    ts_error err;
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    for (int rec = TS_PYRAMID_BSPLINE; rec <= TS_PYRAMID_LEVEL_MAX; rec++) {
        ts_pyramid_opts p = popts(4, 0, (ts_pyramid_reconstruction)rec);
        ts_pyramid *pyr;
        ck_assert_msg(ts_pyramid_build(&g, &p, 0, &pyr, &err) == TS_OK, "%s", err.message);
        for (int edge = TS_EDGE_OPEN; edge <= TS_EDGE_NODATA; edge++) {
            ts_horizon_opts o = hopts(2 * TS_PYRAMID_BATCH - 3, 1);
            o.threads = 3;
            o.edge = (ts_edge_mode)edge;
            o.max_distance = edge == TS_EDGE_NODATA ? 3000.0 : 0.0;
            sky_case c = {&g, nx, ny, nz, TS_SVF_RADIATIVE, {1, 1, 1}};
            check_sky_fused(pyr, &c, &o);
            c = (sky_case){&g, nx, ny, nz, TS_SVF_SOLID_ANGLE, {1, 0, 1}};
            check_sky_fused(pyr, &c, &o);
        }
        ts_pyramid_sky bad = {nx, ny, nz, 0, TS_SVF_RADIATIVE, NULL, NULL, NULL};
        double az0 = 0;
        float *one = tdem_floats(cells);
        ck_assert(ts_pyramid_horizons_sky(pyr, 1, &az0, NULL, &bad, &one, &err) == TS_ERR_ARG);
        ck_assert(ts_pyramid_horizons_sky(pyr, 1, &az0, NULL, NULL, &one, &err) == TS_ERR_ARG);
        ts_horizon_opts o1;
        ts_horizon_opts_default(&o1);
        ts_pyramid_sky good = {nx, ny, nz, 1, TS_SVF_RADIATIVE, NULL, NULL, NULL};
        for (int k = 0; k < 2; k++) {
            double az_bad = k ? INFINITY : NAN;
            ck_assert(ts_pyramid_horizons_sky(pyr, 1, &az_bad, &o1, &good, &one, &err) ==
                      TS_ERR_ARG);
        }
        free(one);
        ts_pyramid_free(pyr);
    }
    free(nx), free(ny), free(nz);
    ts_grid_free(&g);
}
END_TEST

/* The sums without planes on a grid wider than a chunk of columns (1024),
 * with nodata: each row of scratch serves several chunks and rows, and the
 * sums stay those of the planes, level max and B-spline, 1 and 3 threads. */
START_TEST(test_sky_without_planes_wide)
{
    ts_grid g;
    ts_error err;
    ck_assert(ts_grid_create(&g, 1300, 37, 10.0, 10.0, &err) == TS_OK);
    tdem_fbm(&g, 77, 0.8, 900.0);
    for (int x = 500; x < 540; x++)
        g.z[(size_t)20 * g.stride + x] = NAN;
    size_t cells = (size_t)g.width * g.height;
    float *nx = tdem_floats(cells), *ny = tdem_floats(cells), *nz = tdem_floats(cells);
    ck_assert(ts_normals(&g, nx, ny, nz, &err) == TS_OK);
    for (int rec = TS_PYRAMID_BSPLINE; rec <= TS_PYRAMID_LEVEL_MAX; rec++) {
        ts_pyramid_opts p = popts(4, 0, (ts_pyramid_reconstruction)rec);
        ts_pyramid *pyr;
        ck_assert_msg(ts_pyramid_build(&g, &p, 0, &pyr, &err) == TS_OK, "%s", err.message);
        for (int threads = 1; threads <= 3; threads += 2) {
            ts_horizon_opts o = hopts(TS_PYRAMID_BATCH + 3, 1);
            o.threads = threads;
            o.edge = TS_EDGE_HORIZON;
            sky_case c = {&g, nx, ny, nz, TS_SVF_RADIATIVE, {1, 1, 1}};
            check_sky_fused(pyr, &c, &o);
        }
        ts_pyramid_free(pyr);
    }
    free(nx), free(ny), free(nz);
    ts_grid_free(&g);
}
END_TEST

/* MAX_DISTANCE: the rays end at the distance, where their last sample
 * is; on jacksboro (curvature on) the capped pyramid stays as close to
 * the capped sweep as the unbounded ones are to each other. */
START_TEST(test_max_distance)
{
    ts_grid g;
    tdem_load(&g, "jacksboro");
    ts_horizon_opts o = hopts(8, 1);
    o.max_distance = 1500;
    size_t n = (size_t)g.width * g.height * o.directions;
    ts_pyramid_opts p = popts(4, 0, TS_PYRAMID_BSPLINE);
    float *ex = exact_planes(&g, &o), *py = pyramid_planes(&g, &p, &o);
    err_stats d = diff_stats(ex, py, n);
    o.max_distance = 0;
    float *free_py = pyramid_planes(&g, &p, &o);
    long changed = 0;
    for (size_t i = 0; i < n; i++)
        changed += fabsf(free_py[i] - py[i]) > 0.01f;
    printf("jacksboro MAX_DISTANCE=1500 m: |pyramid - exact| median %.3f p99 %.3f deg; %ld "
           "of %zu cell-directions differ from the unbounded pyramid\n",
           d.median, d.p99, changed, n);
    ck_assert_msg(d.median <= 2.0 && d.p99 <= 12.0, "median %g p99 %g", d.median, d.p99);
    ck_assert_msg(changed > (long)(n / 20), "the distance changed only %ld values", changed);
    free(ex), free(py), free(free_py);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_bad_input)
{
    ts_pyramid_opts p;
    ts_error err;
    ts_pyramid_opts_default(&p);
    ck_assert(p.level_step == 4 && p.offset == 0 && p.reconstruction == TS_PYRAMID_BSPLINE);
    ck_assert(ts_pyramid_opts_validate(&p, &err) == TS_OK);
    const double bad_k[] = {0.999, 0, -1, 16.5, NAN, INFINITY};
    for (size_t i = 0; i < sizeof bad_k / sizeof bad_k[0]; i++) {
        ts_pyramid_opts q = p;
        q.level_step = bad_k[i];
        ck_assert(ts_pyramid_opts_validate(&q, &err) == TS_ERR_ARG);
        ck_assert_msg(strstr(err.message, "level step k must be between 1"), "%s",
                      err.message);
    }
    const double bad_o[] = {-0.1, 64.5, NAN};
    for (size_t i = 0; i < sizeof bad_o / sizeof bad_o[0]; i++) {
        ts_pyramid_opts q = p;
        q.offset = bad_o[i];
        ck_assert(ts_pyramid_opts_validate(&q, &err) == TS_ERR_ARG);
        ck_assert_msg(strstr(err.message, "level offset o must be between 0 and 64"), "%s",
                      err.message);
    }
    ts_pyramid_opts q = p;
    q.reconstruction = (ts_pyramid_reconstruction)7;
    ck_assert(ts_pyramid_opts_validate(&q, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_opts_validate(NULL, &err) == TS_ERR_ARG);
    printf("bad level step: %s\n", err.message);
    ts_grid g;
    tdem_create(&g, 8, 8, 1.0, 1.0);
    ts_pyramid *pyr = (ts_pyramid *)1;
    ck_assert(ts_pyramid_build(&g, &p, 0, NULL, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_build(NULL, &p, 0, &pyr, &err) == TS_ERR_ARG && pyr == NULL);
    ck_assert(ts_pyramid_build(&g, &p, -1, &pyr, &err) == TS_ERR_ARG);
    q.reconstruction = TS_PYRAMID_BSPLINE;
    q.level_step = 0.5;
    ck_assert(ts_pyramid_build(&g, &q, 0, &pyr, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_build(&g, &p, 0, &pyr, &err) == TS_OK);
    ts_horizon_opts o = hopts(1, 0);
    float out[64];
    ck_assert(ts_pyramid_horizon(NULL, 0, &o, out, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizon(pyr, 0, &o, NULL, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizon(pyr, NAN, &o, out, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizon(pyr, 0, NULL, out, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizon(pyr, 370, &o, out, &err) == TS_OK);
    double az[TS_PYRAMID_BATCH + 1] = {0};
    float *outs[TS_PYRAMID_BATCH + 1] = {out, out};
    ck_assert(ts_pyramid_horizons(pyr, 0, az, &o, outs, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizons(pyr, TS_PYRAMID_BATCH + 1, az, &o, outs, &err) == TS_ERR_ARG);
    printf("too many azimuths: %s\n", err.message);
    ck_assert(ts_pyramid_horizons(pyr, 1, NULL, &o, outs, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizons(pyr, 1, az, &o, NULL, &err) == TS_ERR_ARG);
    ck_assert(ts_pyramid_horizons(pyr, 3, az, &o, outs, &err) == TS_ERR_ARG); /* outs[2] NULL */
    ck_assert(ts_pyramid_horizons(NULL, 1, az, &o, outs, &err) == TS_ERR_ARG);
    ts_pyramid_free(pyr);
    ts_pyramid_free(NULL);
    ck_assert_int_eq(ts_pyramid_level_count(4096, 100, 4), 49);
    ck_assert_int_eq(ts_pyramid_level_count(1, 1, 4), 1);
    ck_assert_int_eq(ts_pyramid_level_count(10, 10, 0.5), 0);
    ts_grid_free(&g);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("pyramid");
    TCase *tc = tcase_create("pyramid");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_cone_converges);
    tcase_add_test(tc, test_valley_converges);
    tcase_add_test(tc, test_jacksboro_svf);
    tcase_add_test(tc, test_lux_svf);
    tcase_add_test(tc, test_bspline_below_level_max);
    tcase_add_test(tc, test_flat_plane);
    tcase_add_test(tc, test_void_neighbours);
    tcase_add_test(tc, test_threads_identical);
    tcase_add_test(tc, test_batch_identical);
    tcase_add_test(tc, test_sky_fused_identical);
    tcase_add_test(tc, test_sky_without_planes_wide);
    tcase_add_test(tc, test_max_distance);
    tcase_add_test(tc, test_bad_input);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return test_run_suite_mode(suite(), CK_VERBOSE);
}
