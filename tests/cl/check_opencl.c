/*
 * check_opencl: the OpenCL backend against the C backend, product by
 * product, on synthetic DEMs (sums of sines plus hashed noise) of odd sizes
 * (1x1, 1xN, Nx1, primes), with nodata holes, geographic row spacing and a
 * padded row stride; the backend dispatcher; and forced failures: a bogus
 * TERRASHADE_OPENCL_DEVICE, no OpenCL platform (OCL_ICD_VENDORS pointing at
 * an empty directory, in a fresh process), buffers too large for the device.
 * The environment light (envlight) under a CIE sky and sunset.exr, exact
 * and bilinear tables, is held to 1e-4 relative.
 *
 * Never skips: without OpenCL support, or without an OpenCL device (PoCL
 * is installed by setup.sh), the tests fail and say why. Measured maximum
 * differences are printed to the log.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <check.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include "terrashade.h"
#include "terrashade_backend.h"
#include "terrashade_cl.h"
#include "terrashade_env.h"
#include "test_grid.h"
#include "test_run.h"

#define TOL_HORIZON 1e-3 /* degrees */
#define TOL 1e-4         /* shm, normals, direct, sky */
#define TOL_ENV_REL 1e-4 /* environment light, relative */

static char g_self[4096]; /* this program, for the fresh-process tests */

/* For helpers that also run outside a check test (the child modes). */
#define REQUIRE(cond)                                                                          \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "%s:%d: %s failed\n", __FILE__, __LINE__, #cond);                 \
            abort();                                                                           \
        }                                                                                      \
    } while (0)

/* ------------------------------------------------------------- DEMs */

typedef struct {
    int w, h;
    double cell;
    int holes;     /* nodata: a block and scattered cells */
    int geo;       /* per-row east-west spacing */
    int pad;       /* stride = w + pad */
    unsigned seed;
} dem_spec;

/* A grid per spec; free with free_dem. */
static void make_dem(ts_grid *g, const dem_spec *s)
{
    ts_error e;
    if (s->pad) {
        memset(g, 0, sizeof *g);
        g->width = s->w;
        g->height = s->h;
        g->stride = s->w + s->pad;
        g->cell_x = g->cell_y = s->cell;
        g->z = calloc((size_t)g->stride * s->h, sizeof(float));
        REQUIRE(g->z);
        for (size_t i = 0; i < (size_t)g->stride * s->h; i++)
            g->z[i] = 1e30f; /* garbage in the padding */
    } else {
        REQUIRE(ts_grid_create(g, s->w, s->h, s->cell, s->cell, &e) == TS_OK);
    }
    tdem_sines_hash_noise(g, s->seed, s->holes);
    if (s->geo) {
        double *row = malloc((size_t)s->h * sizeof *row);
        REQUIRE(row);
        for (int y = 0; y < s->h; y++)
            row[y] = s->cell * cos((50.0 - y * 0.05) * M_PI / 180.0);
        REQUIRE(ts_grid_set_row_spacing(g, row, &e) == TS_OK);
        free(row);
    }
}

static void free_dem(ts_grid *g, const dem_spec *s)
{
    if (s->pad) {
        free(g->z);
        memset(g, 0, sizeof *g);
    } else {
        ts_grid_free(g);
    }
}

static const dem_spec SHAPES[] = {
    {1, 1, 30, 0, 0, 0, 1},      {1, 17, 30, 0, 0, 0, 2},     {23, 1, 30, 0, 0, 0, 3},
    {2, 2, 30, 0, 0, 0, 4},      {37, 53, 30, 0, 0, 0, 5},    {53, 37, 25, 1, 0, 0, 6},
    {61, 47, 500, 1, 1, 0, 7},   {41, 29, 30, 1, 0, 5, 8},    {64, 64, 10, 1, 0, 0, 9},
    {3, 31, 30, 1, 0, 0, 10},
};
#define NSHAPES ((int)(sizeof SHAPES / sizeof *SHAPES))

static const char *shape_name(const dem_spec *s, char *buf, size_t n)
{
    snprintf(buf, n, "%dx%d%s%s%s", s->w, s->h, s->holes ? " holes" : "", s->geo ? " geo" : "",
             s->pad ? " padded" : "");
    return buf;
}

/* ------------------------------------------------------------ compare */

typedef struct {
    double max;
    long nan_mismatch;
    long valid;
} diff;

static diff compare(const float *a, const float *b, size_t n)
{
    diff d = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        if (isnan(a[i]) || isnan(b[i])) {
            if (isnan(a[i]) != isnan(b[i]))
                d.nan_mismatch++;
            continue;
        }
        d.valid++;
        double e = a[i] == b[i] ? 0.0 : fabs((double)a[i] - b[i]);
        if (!(e <= d.max))
            d.max = e; /* also catches inf - inf */
    }
    return d;
}

static void expect_close(const char *what, const float *c, const float *cl, size_t n, double tol)
{
    diff d = compare(c, cl, n);
    printf("  %-58s max |C - OpenCL| = %.3g over %ld cells\n", what, d.max, d.valid);
    ck_assert_msg(d.nan_mismatch == 0, "%s: %ld cells nodata in one backend only", what,
                  d.nan_mismatch);
    ck_assert_msg(d.max <= tol, "%s: max difference %g > %g", what, d.max, tol);
}

static void require_opencl(void)
{
    ts_error e;
    ts_cl_info info;
    ck_assert_msg(ts_cl_built(), "OpenCL support was not built: configure found no OpenCL "
                                 "(apt-get install ocl-icd-opencl-dev opencl-headers pocl-opencl-icd)");
    ts_status st = ts_cl_available(&info, &e);
    ck_assert_msg(st == TS_OK, "no usable OpenCL device (PoCL is installed by setup.sh): %s",
                  e.message);
}

/* -------------------------------------------------------------- tests */

static ts_backend_report dispatch_normals(ts_backend b, const dem_spec *s);

/* The build configuration: with OpenCL the backend says so; without it
 * every function answers "not built" and the dispatcher runs C. */
START_TEST(test_build_config)
{
    ts_error e;
#ifdef HAVE_OPENCL
    ck_assert_int_eq(ts_cl_built(), 1);
#else
    ck_assert_int_eq(ts_cl_built(), 0);
#endif
    if (ts_cl_built())
        return;
    ck_assert_int_ne(ts_cl_available(NULL, &e), TS_OK);
    ck_assert_ptr_nonnull(strstr(e.message, "OpenCL support was not built"));
    ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, &SHAPES[4]);
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    ck_assert_int_eq(r.fell_back, 1);
    ck_assert_ptr_nonnull(strstr(r.reason, "OpenCL support was not built"));
}
END_TEST

START_TEST(test_available)
{
    require_opencl();
    ts_cl_info info, list[8];
    ts_error e;
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    printf("  device %d (%d:%d): %s on %s, %s, %s, %d compute units, fp64 %d, "
           "max alloc %llu MiB\n",
           info.index, info.platform_index, info.device_index, info.device, info.platform,
           info.type, info.version, info.compute_units, info.fp64, info.max_alloc >> 20);
    ck_assert(info.device[0] && info.platform[0]);
    int count = 0;
    ck_assert_int_eq(ts_cl_devices(list, 8, &count, &e), TS_OK);
    ck_assert_int_ge(count, 1);
    ck_assert_str_eq(list[info.index].device, info.device);
}
END_TEST

static void horizon_case(const dem_spec *s, int dirs, double start, int curvature,
                         double max_distance)
{
    char name[160], sh[64];
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = dirs;
    o.start_azimuth = start;
    o.curvature = curvature;
    o.max_distance = max_distance;
    o.threads = 2;
    size_t n = (size_t)s->w * s->h * dirs;
    float *c = tdem_floats(n), *cl = tdem_floats(n);
    ck_assert_int_eq(ts_horizon_compute(&g, &o, c, &e), TS_OK);
    snprintf(name, sizeof name, "horizon %s, %d dirs from %g%s%s", shape_name(s, sh, sizeof sh),
             dirs, start, curvature ? ", curvature" : "", max_distance > 0 ? ", capped" : "");
    /* Every test grid is shorter than 1e5 m: a shorter distance caps its
     * lines, and the kernel, without the C sweep's window hull, refuses it. */
    if (max_distance > 0 && max_distance < 1e5) {
        ck_assert_int_eq(ts_cl_horizon_compute(&g, &o, cl, &e), TS_ERR_ARG);
        ck_assert_str_eq(e.message, TS_CL_CAPPED_SWEEP_REASON);
        ck_assert_int_eq(ts_cl_horizon_sweep(&g, start, &o, cl, &e), TS_ERR_ARG);
        ck_assert_str_eq(e.message, TS_CL_CAPPED_SWEEP_REASON);
        /* BACKEND=opencl then runs C: its result bit for bit, and says why. */
        ts_backend_report r;
        ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &g, &o, cl, &r, &e),
                         TS_OK);
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, 1);
        ck_assert_str_eq(r.backend, "c");
        ck_assert_str_eq(r.reason, TS_CL_CAPPED_SWEEP_REASON);
        ck_assert_msg(memcmp(c, cl, n * sizeof *c) == 0, "%s: the fallback differs from C",
                      name);
        printf("  %-58s OpenCL refuses, C ran (bit-identical)\n", name);
    } else {
        ts_status st = ts_cl_horizon_compute(&g, &o, cl, &e);
        ck_assert_msg(st == TS_OK, "ts_cl_horizon_compute: %s", e.message);
        expect_close(name, c, cl, n, TOL_HORIZON);
    }
    free(c);
    free(cl);
    free_dem(&g, s);
}

START_TEST(test_horizon)
{
    require_opencl();
    for (int i = 0; i < NSHAPES; i++) {
        horizon_case(&SHAPES[i], 8, 0.0, 1, 0);     /* axes and diagonals */
        horizon_case(&SHAPES[i], 7, 10.0, i & 1, 0); /* odd angles */
    }
    /* a search radius of a few cells, and one of many */
    horizon_case(&SHAPES[4], 5, 3.0, 1, 200.0);
    horizon_case(&SHAPES[8], 6, 17.0, 0, 95.0);
    horizon_case(&SHAPES[6], 4, 45.0, 1, 4000.0);
    horizon_case(&SHAPES[5], 6, 7.0, 1, 500.0); /* occluders on both sides of it */
    /* a distance longer than every line caps nothing: OpenCL runs it */
    horizon_case(&SHAPES[6], 5, 3.0, 1, 1e6);
    /* more directions than one batch holds */
    horizon_case(&SHAPES[4], 40, 1.0, 1, 0);
}
END_TEST

/* Small buffers (TERRASHADE_OPENCL_MAX_ALLOC): several batches of azimuths
 * and several launches of hull stacks per batch, same results. */
START_TEST(test_horizon_small_buffers)
{
    require_opencl();
    setenv("TERRASHADE_OPENCL_MAX_ALLOC", "64k", 1);
    horizon_case(&SHAPES[8], 9, 2.0, 1, 0);     /* 64x64: 2 planes a batch */
    horizon_case(&SHAPES[8], 5, 31.0, 1, 300.0); /* with the raw samples */
    horizon_case(&SHAPES[6], 6, 12.0, 1, 0);    /* geographic */
    unsetenv("TERRASHADE_OPENCL_MAX_ALLOC");
}
END_TEST

/* EDGE: every mode gives the same planes in both backends (the clamp runs
 * on the planes read back, before any sum or test), with and without a
 * search radius that the kernel runs (one longer than every line). */
START_TEST(test_horizon_edge)
{
    require_opencl();
    static const ts_edge_mode modes[] = {TS_EDGE_OPEN, TS_EDGE_HORIZON, TS_EDGE_NODATA};
    const int shapes[] = {4, 6, 7}; /* holes, geographic, 500 m cells */
    for (int m = 0; m < 3; m++)
        for (int i = 0; i < 3; i++)
            for (int capped = 0; capped < 2; capped++) {
                const dem_spec *s = &SHAPES[shapes[i]];
                ts_grid g;
                ts_error e;
                char name[96], sh[64];
                make_dem(&g, s);
                ts_horizon_opts o;
                ts_horizon_opts_default(&o);
                o.directions = 7;
                o.start_azimuth = 5.0;
                o.edge = modes[m];
                o.max_distance = capped ? 1e7 : 0.0;
                size_t n = (size_t)s->w * s->h * o.directions;
                float *c = tdem_floats(n), *cl = tdem_floats(n);
                ck_assert_int_eq(ts_horizon_compute(&g, &o, c, &e), TS_OK);
                ck_assert_msg(ts_cl_horizon_compute(&g, &o, cl, &e) == TS_OK, "%s", e.message);
                snprintf(name, sizeof name, "horizon %s, edge mode %d%s",
                         shape_name(s, sh, sizeof sh), (int)modes[m], capped ? ", 1e7 m" : "");
                expect_close(name, c, cl, n, TOL_HORIZON);
                free(c);
                free(cl);
                free_dem(&g, s);
            }
}
END_TEST

START_TEST(test_horizon_sweep)
{
    require_opencl();
    const dem_spec *s = &SHAPES[5];
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    size_t n = (size_t)s->w * s->h;
    float *c = tdem_floats(n), *cl = tdem_floats(n);
    const double az[] = {0, 360, 33.3, -45, 90, 180.0001, 270, 1e-7, 719.5};
    for (size_t k = 0; k < sizeof az / sizeof *az; k++) {
        ck_assert_int_eq(ts_horizon_sweep(&g, az[k], &o, c, &e), TS_OK);
        ck_assert_msg(ts_cl_horizon_sweep(&g, az[k], &o, cl, &e) == TS_OK, "%s", e.message);
        char name[96];
        snprintf(name, sizeof name, "horizon sweep at %g", az[k]);
        expect_close(name, c, cl, n, TOL_HORIZON);
    }
    free(c);
    free(cl);
    free_dem(&g, s);
}
END_TEST

START_TEST(test_shm)
{
    require_opencl();
    const double az[] = {0, 90, 180, 270, 45, 135, 225, 315, 30.5, 200.7, 359.9, 63.4349};
    const double el[][2] = {{5, 0}, {30, 20}, {90, 0}, {-10, 5}, {2, 50}};
    double worst_v = 0, worst_s = 0;
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        ts_grid g;
        ts_error e;
        make_dem(&g, s);
        size_t n = (size_t)s->w * s->h;
        float *vc = tdem_floats(n), *vl = tdem_floats(n);
        float *sc = tdem_floats(n), *sl = tdem_floats(n);
        for (size_t a = 0; a < sizeof az / sizeof *az; a++)
            for (size_t k = 0; k < sizeof el / sizeof *el; k++) {
                if ((a + k + (size_t)i) % 2 && s->w * s->h > 100)
                    continue; /* half the combinations on the bigger grids */
                ck_assert_int_eq(ts_shm_compute(&g, az[a], el[k][0], el[k][1], 2, vc, sc, &e),
                                 TS_OK);
                ts_status st = ts_cl_shm_compute(&g, az[a], el[k][0], el[k][1], 0, vl, sl, &e);
                ck_assert_msg(st == TS_OK, "ts_cl_shm_compute: %s", e.message);
                diff dv = compare(vc, vl, n), ds = compare(sc, sl, n);
                char sh[64];
                ck_assert_msg(dv.nan_mismatch == 0 && ds.nan_mismatch == 0,
                              "shm %s az %g el %g: nodata differs", shape_name(s, sh, sizeof sh),
                              az[a], el[k][0]);
                ck_assert_msg(dv.max <= TOL && ds.max <= TOL,
                              "shm %s az %g el %g depth %g: visibility %g, height %g",
                              shape_name(s, sh, sizeof sh), az[a], el[k][0], el[k][1], dv.max,
                              ds.max);
                worst_v = fmax(worst_v, dv.max);
                worst_s = fmax(worst_s, ds.max);
            }
        /* one output at a time */
        ck_assert_int_eq(ts_shm_compute(&g, 123.0, 12.0, 0, 0, vc, NULL, &e), TS_OK);
        ck_assert_int_eq(ts_cl_shm_compute(&g, 123.0, 12.0, 0, 0, vl, NULL, &e), TS_OK);
        expect_close("shm visibility only", vc, vl, n, TOL);
        ck_assert_int_eq(ts_shm_compute(&g, 300.0, 8.0, 0, 0, NULL, sc, &e), TS_OK);
        ck_assert_int_eq(ts_cl_shm_compute(&g, 300.0, 8.0, 0, 0, NULL, sl, &e), TS_OK);
        expect_close("shm shadow height only", sc, sl, n, TOL);
        free(vc), free(vl), free(sc), free(sl);
        free_dem(&g, s);
    }
    printf("  shm, all shapes and lights: max |C - OpenCL| visibility %.3g, shadow height %.3g m\n",
           worst_v, worst_s);
}
END_TEST

/* A grid wider than one work-group band, so that the halo tiles matter. */
START_TEST(test_shm_wide)
{
    require_opencl();
    const dem_spec s = {331, 293, 20, 1, 0, 0, 11};
    ts_grid g;
    ts_error e;
    make_dem(&g, &s);
    size_t n = (size_t)s.w * s.h;
    float *vc = tdem_floats(n), *vl = tdem_floats(n);
    float *sc = tdem_floats(n), *sl = tdem_floats(n);
    const double az[] = {10, 100, 190, 280, 45, 315, 0, 90};
    for (size_t a = 0; a < sizeof az / sizeof *az; a++) {
        ck_assert_int_eq(ts_shm_compute(&g, az[a], 7.0, 3.0, 0, vc, sc, &e), TS_OK);
        ck_assert_msg(ts_cl_shm_compute(&g, az[a], 7.0, 3.0, 0, vl, sl, &e) == TS_OK, "%s",
                      e.message);
        char name[96];
        snprintf(name, sizeof name, "shm 331x293 az %g visibility", az[a]);
        expect_close(name, vc, vl, n, TOL);
        snprintf(name, sizeof name, "shm 331x293 az %g shadow height (m)", az[a]);
        expect_close(name, sc, sl, n, TOL);
    }
    free(vc), free(vl), free(sc), free(sl);
    free_dem(&g, &s);
}
END_TEST

START_TEST(test_normals)
{
    require_opencl();
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        ts_grid g;
        ts_error e;
        make_dem(&g, s);
        size_t n = (size_t)s->w * s->h;
        float *c[3] = {tdem_floats(n), tdem_floats(n), tdem_floats(n)};
        float *l[3] = {tdem_floats(n), tdem_floats(n), tdem_floats(n)};
        ck_assert_int_eq(ts_normals(&g, c[0], c[1], c[2], &e), TS_OK);
        ck_assert_msg(ts_cl_normals(&g, l[0], l[1], l[2], &e) == TS_OK, "%s", e.message);
        for (int k = 0; k < 3; k++) {
            char name[192], sh[64];
            snprintf(name, sizeof name, "normals %s, n%c", shape_name(s, sh, sizeof sh), "xyz"[k]);
            expect_close(name, c[k], l[k], n, TOL);
            free(c[k]);
            free(l[k]);
        }
        free_dem(&g, s);
    }
}
END_TEST

/* C horizons and normals for the shading tests. */
typedef struct {
    ts_grid g;
    ts_horizon_opts o;
    size_t n;
    float *h, *nx, *ny, *nz;
} scene;

static void scene_make(scene *sc, const dem_spec *s, int dirs, double start)
{
    ts_error e;
    make_dem(&sc->g, s);
    ts_horizon_opts_default(&sc->o);
    sc->o.directions = dirs;
    sc->o.start_azimuth = start;
    sc->n = (size_t)s->w * s->h;
    sc->h = tdem_floats(sc->n * dirs);
    sc->nx = tdem_floats(sc->n);
    sc->ny = tdem_floats(sc->n);
    sc->nz = tdem_floats(sc->n);
    ck_assert_int_eq(ts_horizon_compute(&sc->g, &sc->o, sc->h, &e), TS_OK);
    ck_assert_int_eq(ts_normals(&sc->g, sc->nx, sc->ny, sc->nz, &e), TS_OK);
}

static void scene_free(scene *sc, const dem_spec *s)
{
    free(sc->h), free(sc->nx), free(sc->ny), free(sc->nz);
    free_dem(&sc->g, s);
}

/* The scene's direct sun at azimuth az, elevation el into out. */
static ts_direct_request scene_direct(const scene *sc, double az, double el, float *out)
{
    return (ts_direct_request){&sc->g, sc->nx, sc->ny, sc->nz, sc->h,
                               &sc->o, az,     el,     out,    TS_SUN_RADIUS_DEG};
}

/* The scene's sky terms of model m into svf, sky, open (each may be NULL). */
static ts_sky_request scene_sky(const scene *sc, ts_svf_model m, float *svf, float *sky,
                                float *open)
{
    return (ts_sky_request){&sc->g, sc->nx, sc->ny, sc->nz, sc->h, &sc->o, m, svf, sky, open};
}

/* The scene's environment light of table t's sector k (its horizon plane k)
 * into rgb: three planes of sc->n floats. */
static ts_env_light_request scene_env(const scene *sc, const ts_env_table *t, int k, float *rgb)
{
    return (ts_env_light_request){&sc->g, t,   k, sc->nx, sc->ny, sc->nz, sc->h + sc->n * k,
                                  rgb,    rgb + sc->n, rgb + 2 * sc->n};
}

START_TEST(test_direct)
{
    require_opencl();
    const double sun[][2] = {{123.4, 25}, {0, 0.1}, {359.99, 3}, {270, 60}, {45, -0.1}, {200, 90}};
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        scene sc;
        scene_make(&sc, s, 8, 5.0);
        float *c = tdem_floats(sc.n), *l = tdem_floats(sc.n);
        ts_error e;
        for (size_t k = 0; k < sizeof sun / sizeof *sun; k++) {
            const ts_direct_request qc = scene_direct(&sc, sun[k][0], sun[k][1], c);
            const ts_direct_request ql = scene_direct(&sc, sun[k][0], sun[k][1], l);
            ck_assert_int_eq(ts_shade_direct(&qc, &e), TS_OK);
            ck_assert_msg(ts_cl_shade_direct(&ql, &e) == TS_OK, "%s", e.message);
            char name[192], sh[64];
            snprintf(name, sizeof name, "direct %s, sun %g/%g", shape_name(s, sh, sizeof sh),
                     sun[k][0], sun[k][1]);
            expect_close(name, c, l, sc.n, TOL);
        }
        /* one direction, the sun on it */
        sc.o.directions = 1;
        const ts_direct_request qc = scene_direct(&sc, 5.0, 20, c), ql = scene_direct(&sc, 5.0, 20, l);
        ck_assert_int_eq(ts_shade_direct(&qc, &e), TS_OK);
        ck_assert_int_eq(ts_cl_shade_direct(&ql, &e), TS_OK);
        expect_close("direct, one direction", c, l, sc.n, TOL);
        sc.o.directions = 8;
        free(c), free(l);
        scene_free(&sc, s);
    }
}
END_TEST

START_TEST(test_sky)
{
    require_opencl();
    for (int i = 0; i < NSHAPES; i++) {
        const dem_spec *s = &SHAPES[i];
        scene sc;
        scene_make(&sc, s, 16, 0.0);
        float *c[3], *l[3];
        for (int k = 0; k < 3; k++)
            c[k] = tdem_floats(sc.n), l[k] = tdem_floats(sc.n);
        ts_error e;
        const ts_svf_model rad = TS_SVF_RADIATIVE, solid = TS_SVF_SOLID_ANGLE;
        ts_sky_request qc = scene_sky(&sc, rad, c[0], c[1], c[2]);
        ts_sky_request ql = scene_sky(&sc, rad, l[0], l[1], l[2]);
        ck_assert_int_eq(ts_sky_terms(&qc, &e), TS_OK);
        ck_assert_msg(ts_cl_sky_terms(&ql, &e) == TS_OK, "%s", e.message);
        static const char *what[3] = {"svf", "sky", "openness (deg)"};
        for (int k = 0; k < 3; k++) {
            char name[192], sh[64];
            snprintf(name, sizeof name, "%s %s", what[k], shape_name(s, sh, sizeof sh));
            expect_close(name, c[k], l[k], sc.n, TOL);
        }
        /* outputs one at a time */
        ql = scene_sky(&sc, rad, NULL, l[1], NULL);
        ck_assert_int_eq(ts_cl_sky_terms(&ql, &e), TS_OK);
        expect_close("sky alone", c[1], l[1], sc.n, TOL);
        /* the solid-angle svf (Zaksek et al. 2011), with and without the others */
        qc = scene_sky(&sc, solid, c[0], NULL, NULL);
        ck_assert_int_eq(ts_sky_terms(&qc, &e), TS_OK);
        ql = scene_sky(&sc, solid, l[0], l[1], l[2]);
        ck_assert_msg(ts_cl_sky_terms(&ql, &e) == TS_OK, "%s", e.message);
        char name[192], sh[64];
        snprintf(name, sizeof name, "svf solid_angle %s", shape_name(s, sh, sizeof sh));
        expect_close(name, c[0], l[0], sc.n, TOL);
        expect_close("sky beside svf solid_angle", c[1], l[1], sc.n, TOL);
        ql = scene_sky(&sc, solid, l[0], NULL, NULL);
        ck_assert_int_eq(ts_cl_sky_terms(&ql, &e), TS_OK);
        expect_close("svf solid_angle alone", c[0], l[0], sc.n, TOL);
        ql = scene_sky(&sc, (ts_svf_model)5, l[0], NULL, NULL);
        ck_assert_int_eq(ts_cl_sky_terms(&ql, &e), TS_ERR_ARG);
        for (int k = 0; k < 3; k++)
            free(c[k]), free(l[k]);
        scene_free(&sc, s);
    }
}
END_TEST

START_TEST(test_arguments)
{
    require_opencl();
    const dem_spec *s = &SHAPES[4];
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    size_t n = (size_t)s->w * s->h;
    float *a = tdem_floats(n), *b = tdem_floats(n), *c = tdem_floats(n);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    ck_assert_int_eq(ts_cl_shm_compute(&g, 10, 95, 0, 0, a, NULL, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "between -90 and 90, got 95"));
    ck_assert_int_eq(ts_cl_shm_compute(&g, NAN, 5, 0, 0, a, NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_shm_compute(&g, 10, 5, 0, 0, NULL, NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_horizon_sweep(&g, INFINITY, &o, a, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_horizon_sweep(&g, 0, NULL, a, &e), TS_ERR_ARG);
    o.directions = 0;
    ck_assert_int_eq(ts_cl_horizon_compute(&g, &o, a, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_normals(&g, a, b, NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_normals(NULL, a, b, c, &e), TS_ERR_ARG);
    o.directions = 1;
    const ts_direct_request dq = {&g, a, b, c, a, &o, 100, 20, b, TS_SUN_RADIUS_DEG};
    ck_assert_int_eq(ts_cl_shade_direct(&dq, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "computed for azimuth 0 only"));
    const ts_sky_request sq = {&g, a, b, c, NULL, &o, TS_SVF_RADIATIVE, a, NULL, NULL};
    ck_assert_int_eq(ts_cl_sky_terms(&sq, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_sky_terms(NULL, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_shade_direct(NULL, &e), TS_ERR_ARG);
    free(a), free(b), free(c);
    free_dem(&g, s);
}
END_TEST

/* ------------------------------------------------------ environment light */

static void clear_env(void);

/* The two environments of the envlight tests: a CIE sky and a real map. */
static void env_make(ts_env *env, int which)
{
    ts_error e;
    if (which == 0)
        REQUIRE(ts_env_sky(env, TS_SKY_CIE, 7, 120.0, 25.0, 0, 0, &e) == TS_OK);
    else
        REQUIRE(ts_env_load_exr_file(TS_TEST_DATA "/envmaps/sunset.exr", 30.0, 0, env, &e) ==
                TS_OK);
}

static void env_table(ts_env_table *t, const ts_env *env, const scene *sc, int normal_steps)
{
    ts_env_table_opts to;
    ts_error e;
    ts_env_table_opts_default(&to);
    to.directions = sc->o.directions;
    to.start_azimuth = sc->o.start_azimuth;
    to.normal_steps = normal_steps;
    REQUIRE(ts_env_table_build(env, &to, t, &e) == TS_OK);
}

/* Largest |C - OpenCL| relative to the C value, the C value floored at
 * 1e-3 of the image's largest (dark cells: a difference there is absolute
 * at that scale); NaN must match. */
static double env_rel_diff(const float *c, const float *l, size_t n, long *nan_mismatch)
{
    double peak = 0, worst = 0;
    for (size_t i = 0; i < n; i++)
        if (c[i] == c[i] && fabs(c[i]) > peak)
            peak = fabs(c[i]);
    for (size_t i = 0; i < n; i++) {
        if (isnan(c[i]) || isnan(l[i])) {
            *nan_mismatch += isnan(c[i]) != isnan(l[i]);
            continue;
        }
        double d = fabs((double)c[i] - l[i]) / fmax(fabs(c[i]), 1e-3 * peak + 1e-30);
        if (!(d <= worst))
            worst = d;
    }
    return worst;
}

/* Every plane of a scene through the C function and an OpenCL session,
 * then finished; the worst relative difference over the colours. */
static double env_compare(const scene *sc, const ts_env_table *t, float *c, float *l)
{
    ts_error e;
    const size_t n = sc->n;
    memset(c, 0, 3 * n * sizeof *c);
    memset(l, 0, 3 * n * sizeof *l);
    ts_cl_env_light *s;
    const ts_env_light_request first = scene_env(sc, t, 0, l);
    ck_assert_msg(ts_cl_env_light_open(&first, &s, &e) == TS_OK, "%s", e.message);
    for (int k = 0; k < t->directions; k++) {
        const ts_env_light_request qc = scene_env(sc, t, k, c), ql = scene_env(sc, t, k, l);
        ck_assert_int_eq(ts_env_light_accumulate(&qc, &e), TS_OK);
        ck_assert_msg(ts_cl_env_light_add(s, &ql, &e) == TS_OK, "%s", e.message);
    }
    ts_cl_env_light_close(s);
    ck_assert_int_eq(ts_env_light_finish(&sc->g, c, c + n, c + 2 * n, &e), TS_OK);
    ck_assert_int_eq(ts_env_light_finish(&sc->g, l, l + n, l + 2 * n, &e), TS_OK);
    long nan_mismatch = 0;
    double worst = env_rel_diff(c, l, 3 * n, &nan_mismatch);
    ck_assert_int_eq(nan_mismatch, 0);
    return worst;
}

START_TEST(test_env_light)
{
    require_opencl();
    static const char *env_name[2] = {"CIE sky 7", "sunset.exr"};
    double worst_all = 0;
    for (int which = 0; which < 2; which++) {
        ts_env env;
        env_make(&env, which);
        for (int i = 0; i < NSHAPES; i++) {
            const dem_spec *s = &SHAPES[i];
            scene sc;
            scene_make(&sc, s, 8, 10.0);
            float *c = tdem_floats(3 * sc.n), *l = tdem_floats(3 * sc.n);
            static const int steps[2] = {0, 33}; /* exact, bilinear */
            for (int m = 0; m < 2; m++) {
                ts_env_table t;
                env_table(&t, &env, &sc, steps[m]);
                double worst = env_compare(&sc, &t, c, l);
                char sh[64];
                printf("  envlight %-10s %-6s %-30s max |C - OpenCL| / C = %.3g\n",
                       env_name[which], steps[m] ? "bilin" : "exact",
                       shape_name(s, sh, sizeof sh), worst);
                ck_assert_msg(worst <= TOL_ENV_REL, "envlight %s: %g", sh, worst);
                worst_all = fmax(worst_all, worst);
                ts_env_table_free(&t);
            }
            free(c), free(l);
            scene_free(&sc, s);
        }
        ts_env_free(&env);
    }
    printf("  envlight: largest relative difference %.3g\n", worst_all);
}
END_TEST

/* The dispatcher's envlight: OpenCL with a state, one-shot, argument
 * errors as C's, and a forced fallback (TERRASHADE_OPENCL_MAX_ALLOC) that
 * gives C's sums exactly. */
START_TEST(test_env_light_dispatch)
{
    require_opencl();
    clear_env();
    const dem_spec *s = &SHAPES[4];
    scene sc;
    scene_make(&sc, s, 8, 0.0);
    ts_env env;
    env_make(&env, 1);
    ts_env_table t;
    env_table(&t, &env, &sc, 0);
    const size_t n = sc.n;
    float *c = tdem_floats(3 * n), *l = tdem_floats(3 * n);
    ts_error e;
    ts_backend_report r;
    memset(c, 0, 3 * n * sizeof *c);
    for (int k = 0; k < 8; k++) {
        const ts_env_light_request qc = scene_env(&sc, &t, k, c);
        ck_assert_int_eq(ts_env_light_accumulate(&qc, &e), TS_OK);
    }
    for (int pass = 0; pass < 3; pass++) {
        /* 0: a state, 1: no state, 2: a state with the allocations capped */
        if (pass == 2)
            setenv("TERRASHADE_OPENCL_MAX_ALLOC", "4k", 1); /* table 46 kB, normals 7.8 kB */
        ts_backend_env_light st = {0};
        memset(l, 0, 3 * n * sizeof *l);
        for (int k = 0; k < 8; k++) {
            const ts_env_light_request ql = scene_env(&sc, &t, k, l);
            ck_assert_msg(ts_backend_env_light_accumulate(TS_BACKEND_OPENCL, pass == 1 ? NULL : &st,
                                                          &ql, &r, &e) == TS_OK,
                          "%s", e.message);
            ck_assert_int_eq(r.used, pass == 2 ? TS_BACKEND_C : TS_BACKEND_OPENCL);
            ck_assert_int_eq(r.fell_back, pass == 2);
        }
        if (pass == 2) {
            ck_assert_int_eq(st.failed, 1);
            ck_assert_ptr_nonnull(strstr(r.reason, "TERRASHADE_OPENCL_MAX_ALLOC"));
            ck_assert(memcmp(c, l, 3 * n * sizeof *c) == 0);
            printf("  envlight fallback: %s\n", r.reason);
        } else {
            long nan_mismatch = 0;
            double d = env_rel_diff(c, l, 3 * n, &nan_mismatch);
            printf("  envlight dispatch %s: max |C - OpenCL| / C = %.3g\n",
                   pass ? "one-shot" : "session", d);
            ck_assert(d <= TOL_ENV_REL && nan_mismatch == 0);
        }
        ts_backend_env_light_release(&st);
        ck_assert_ptr_null(st.cl);
    }
    clear_env();
    /* A fallback in the middle: planes 0..3 on OpenCL; then copies of the
     * normals make the dispatcher reopen its session, which the cap refuses,
     * so planes 4..7 run C from the sums so far (and stay on C). */
    float *nc = tdem_floats(3 * n);
    memcpy(nc, sc.nx, n * sizeof *nc);
    memcpy(nc + n, sc.ny, n * sizeof *nc);
    memcpy(nc + 2 * n, sc.nz, n * sizeof *nc);
    ts_backend_env_light st = {0};
    memset(l, 0, 3 * n * sizeof *l);
    for (int k = 0; k < 8; k++) {
        if (k == 4)
            setenv("TERRASHADE_OPENCL_MAX_ALLOC", "4k", 1);
        ts_env_light_request ql = scene_env(&sc, &t, k, l);
        if (k >= 4)
            ql.nx = nc, ql.ny = nc + n, ql.nz = nc + 2 * n;
        ck_assert_int_eq(ts_backend_env_light_accumulate(TS_BACKEND_OPENCL, &st, &ql, &r, &e),
                         TS_OK);
        ck_assert_int_eq(r.used, k < 4 ? TS_BACKEND_OPENCL : TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, k >= 4);
    }
    ts_backend_env_light_release(&st);
    long mid_nan = 0;
    double mid = env_rel_diff(c, l, 3 * n, &mid_nan);
    printf("  envlight OpenCL then C from plane 4: max |C - mixed| / C = %.3g\n", mid);
    ck_assert(mid <= TOL_ENV_REL && mid_nan == 0);
    free(nc);
    clear_env();
    /* argument errors: the C function's */
    const ts_env_light_request q0 = scene_env(&sc, &t, 0, l);
    ts_env_light_request bad = q0;
    bad.k = 8;
    ck_assert_int_eq(ts_backend_env_light_accumulate(TS_BACKEND_OPENCL, NULL, &bad, &r, &e),
                     TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "outside the light table's 8 directions"));
    bad = q0, bad.ny = NULL;
    ck_assert_int_eq(ts_cl_env_light_accumulate(&bad, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_cl_env_light_accumulate(NULL, &e), TS_ERR_ARG);
    /* a session is for the arrays it was opened with */
    ts_cl_env_light *ss;
    ck_assert_int_eq(ts_cl_env_light_open(&q0, &ss, &e), TS_OK);
    bad = q0, bad.nx = sc.ny;
    ck_assert_int_eq(ts_cl_env_light_add(ss, &bad, &e), TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "opened for another"));
    ts_cl_env_light_close(ss);
    ts_env_table_free(&t);
    ts_env_free(&env);
    free(c), free(l);
    scene_free(&sc, s);
}
END_TEST

/* ------------------------------------------------------------ dispatcher */

static void clear_env(void)
{
    unsetenv("TERRASHADE_BACKEND");
    unsetenv("TERRASHADE_OPENCL_DEVICE");
    unsetenv("TERRASHADE_OPENCL_MAX_ALLOC");
}

/* Normals through the dispatcher; returns the report, checks the result. */
static ts_backend_report dispatch_normals(ts_backend b, const dem_spec *s)
{
    ts_grid g;
    ts_error e;
    make_dem(&g, s);
    size_t n = (size_t)s->w * s->h;
    float *c[3] = {tdem_floats(n), tdem_floats(n), tdem_floats(n)};
    float *l[3] = {tdem_floats(n), tdem_floats(n), tdem_floats(n)};
    ts_backend_report r;
    memset(&r, 0xff, sizeof r);
    ck_assert_int_eq(ts_normals(&g, c[0], c[1], c[2], &e), TS_OK);
    ts_status st = ts_backend_normals(b, &g, l[0], l[1], l[2], &r, &e);
    ck_assert_msg(st == TS_OK, "ts_backend_normals: %s", e.message);
    for (int k = 0; k < 3; k++) {
        diff d = compare(c[k], l[k], n);
        ck_assert(d.nan_mismatch == 0 && d.max <= TOL);
        free(c[k]);
        free(l[k]);
    }
    free_dem(&g, s);
    printf("  dispatch %-6s (TERRASHADE_BACKEND=%s): ran %s on %s%s%s\n", ts_backend_name(b),
           getenv("TERRASHADE_BACKEND") ? getenv("TERRASHADE_BACKEND") : "", r.backend, r.device,
           r.fell_back ? ", fell back: " : r.reason[0] ? ", " : "", r.reason);
    ck_assert(r.used == TS_BACKEND_C || r.used == TS_BACKEND_OPENCL);
    ck_assert_str_eq(r.backend, r.used == TS_BACKEND_C ? "c" : "opencl");
    return r;
}

START_TEST(test_dispatch)
{
    require_opencl();
    clear_env();
    const dem_spec *s = &SHAPES[5];
    ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, s);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    ck_assert_int_eq(r.fell_back, 0);
    ts_cl_info info;
    ts_error e;
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    ck_assert_ptr_nonnull(strstr(r.device, info.device));

    r = dispatch_normals(TS_BACKEND_C, s);
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    ck_assert_int_eq(r.fell_back, 0);

    /* auto: OpenCL on a GPU or accelerator; on a CPU device picked by
     * default (PoCL), the C backend, and it says why */
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.requested, TS_BACKEND_AUTO);
    ck_assert_int_eq(r.fell_back, 0);
    if (!strcmp(info.type, "CPU")) {
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_ptr_nonnull(strstr(r.reason, "is a CPU"));
    } else {
        ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    }
    /* auto with a device named explicitly: OpenCL */
    setenv("TERRASHADE_OPENCL_DEVICE", "0", 1);
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    unsetenv("TERRASHADE_OPENCL_DEVICE");

    setenv("TERRASHADE_BACKEND", "opencl", 1);
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.requested, TS_BACKEND_OPENCL);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    r = dispatch_normals(TS_BACKEND_C, s); /* an explicit argument wins */
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    setenv("TERRASHADE_BACKEND", "C", 1);
    r = dispatch_normals(TS_BACKEND_AUTO, s);
    ck_assert_int_eq(r.requested, TS_BACKEND_C);
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    setenv("TERRASHADE_BACKEND", "cuda", 1);
    ts_grid g;
    make_dem(&g, s);
    float *a = tdem_floats(g.width * g.height * 3);
    ck_assert_int_eq(ts_backend_normals(TS_BACKEND_AUTO, &g, a, a + g.width * g.height,
                                        a + 2 * g.width * g.height, NULL, &e),
                     TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "TERRASHADE_BACKEND"));
    free(a);
    free_dem(&g, s);
    clear_env();

    ts_backend b;
    ck_assert_int_eq(ts_backend_parse(" OpenCL ", &b, &e), TS_OK);
    ck_assert_int_eq(b, TS_BACKEND_OPENCL);
    ck_assert_int_eq(ts_backend_parse("gpu", &b, &e), TS_ERR_ARG);
    ck_assert_str_eq(ts_backend_name(TS_BACKEND_AUTO), "auto");
    ck_assert_int_eq(ts_backend_choose(TS_BACKEND_OPENCL, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
}
END_TEST

static int last_progress(double done, void *user)
{
    *(double *)user = done;
    return 0;
}

static int cancel_progress(double done, void *user)
{
    (void)done;
    (void)user;
    return 1;
}

/* Every product through the dispatcher, forced onto OpenCL. */
START_TEST(test_dispatch_products)
{
    require_opencl();
    clear_env();
    const dem_spec *s = &SHAPES[4];
    scene sc;
    scene_make(&sc, s, 8, 0.0);
    ts_error e;
    ts_backend_report r;
    float *a = tdem_floats(sc.n * 8), *b = tdem_floats(sc.n * 8), *c = tdem_floats(sc.n);
    ck_assert_int_eq(
        ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &sc.o, a, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch horizon_compute", sc.h, a, sc.n * 8, TOL_HORIZON);
    ck_assert_int_eq(ts_backend_horizon_sweep(TS_BACKEND_OPENCL, &sc.g, 90.0, &sc.o, a, &r, &e),
                     TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch horizon_sweep", sc.h + sc.n * 2, a, sc.n, TOL_HORIZON);
    ck_assert_int_eq(ts_shm_compute(&sc.g, 77, 9, 1, 0, c, b, &e), TS_OK);
    ck_assert_int_eq(
        ts_backend_shm_compute(TS_BACKEND_OPENCL, &sc.g, 77, 9, 1, 0, a, a + sc.n, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch shm visibility", c, a, sc.n, TOL);
    expect_close("dispatch shm height", b, a + sc.n, sc.n, TOL);
    const ts_direct_request dc = scene_direct(&sc, 150, 30, c), dl = scene_direct(&sc, 150, 30, a);
    ck_assert_int_eq(ts_shade_direct(&dc, &e), TS_OK);
    ck_assert_int_eq(ts_backend_shade_direct(TS_BACKEND_OPENCL, &dl, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch direct", c, a, sc.n, TOL);
    const ts_sky_request sc_ = scene_sky(&sc, TS_SVF_RADIATIVE, c, NULL, NULL);
    const ts_sky_request sl = scene_sky(&sc, TS_SVF_RADIATIVE, a, NULL, NULL);
    ck_assert_int_eq(ts_sky_terms(&sc_, &e), TS_OK);
    ck_assert_int_eq(ts_backend_sky_terms(TS_BACKEND_OPENCL, &sl, &r, &e), TS_OK);
    ck_assert_int_eq(r.used, TS_BACKEND_OPENCL);
    expect_close("dispatch svf", c, a, sc.n, TOL);
    /* an argument error is the C backend's error */
    ck_assert_int_eq(
        ts_backend_shm_compute(TS_BACKEND_OPENCL, &sc.g, 77, 91, 1, 0, a, NULL, &r, &e),
        TS_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(e.message, "got 91"));
    /* progress on OpenCL ends at 1; a cancel is final, not a reason to
     * fall back to C */
    double last = -1;
    ts_horizon_opts po = sc.o;
    po.progress = last_progress;
    po.progress_user = &last;
    ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &po, a, &r, &e),
                     TS_OK);
    ck_assert(last == 1.0 && r.used == TS_BACKEND_OPENCL);
    po.progress = cancel_progress;
    ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &po, a, &r, &e),
                     TS_ERR_CANCELLED);
    ck_assert(!r.fell_back);
    ck_assert_ptr_nonnull(strstr(e.message, "cancelled"));
    free(a), free(b), free(c);
    scene_free(&sc, s);
}
END_TEST

START_TEST(test_bogus_device)
{
    require_opencl();
    clear_env();
    ts_error e;
    ts_cl_info info;
    int count = 0;
    ck_assert_int_eq(ts_cl_devices(NULL, 0, &count, &e), TS_OK);
    static const char *bad[] = {"99", "0:42", "7:0", "gpu", "-1", "1x"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        setenv("TERRASHADE_OPENCL_DEVICE", bad[i], 1);
        ts_status st = ts_cl_available(&info, &e);
        ck_assert_int_ne(st, TS_OK);
        ck_assert_ptr_nonnull(strstr(e.message, "TERRASHADE_OPENCL_DEVICE"));
        printf("  TERRASHADE_OPENCL_DEVICE=%s: %s\n", bad[i], e.message);
        ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, &SHAPES[5]);
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, 1);
        ck_assert_ptr_nonnull(strstr(r.reason, "TERRASHADE_OPENCL_DEVICE"));
        r = dispatch_normals(TS_BACKEND_AUTO, &SHAPES[5]);
        ck_assert_int_eq(r.used, TS_BACKEND_C);
        ck_assert_int_eq(r.fell_back, 1);
    }
    setenv("TERRASHADE_OPENCL_DEVICE", "0:0", 1);
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    ck_assert_int_eq(info.platform_index, 0);
    ck_assert_int_eq(info.device_index, 0);
    char last[16];
    snprintf(last, sizeof last, "%d", count - 1);
    setenv("TERRASHADE_OPENCL_DEVICE", last, 1);
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    clear_env();
}
END_TEST

/* Fresh processes: this program re-run with a mode argument. */
static int run_child(const char *mode, const char *env_name, const char *env_value)
{
    fflush(stdout);
    pid_t pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        if (env_name)
            setenv(env_name, env_value, 1);
        execl(g_self, g_self, mode, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    ck_assert_int_eq(waitpid(pid, &status, 0), pid);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* Child: no platform at all (OCL_ICD_VENDORS is an empty directory). */
static int child_no_platform(void)
{
    ts_error e;
    ts_cl_info info;
    ts_status st = ts_cl_available(&info, &e);
    printf("  child, OCL_ICD_VENDORS=%s: ts_cl_available: %s\n", getenv("OCL_ICD_VENDORS"),
           st == TS_OK ? "OK" : e.message);
    if (st == TS_OK || !strstr(e.message, "no OpenCL platform"))
        return 1;
    ts_grid g;
    if (ts_grid_create(&g, 13, 11, 30, 30, &e) != TS_OK)
        return 2;
    for (int i = 0; i < 13 * 11; i++)
        g.z[i] = (float)(i % 7) * 3.0f;
    float *a = malloc(3 * 143 * sizeof *a), *b = malloc(3 * 143 * sizeof *b);
    ts_backend_report r;
    int rc = 0;
    if (ts_normals(&g, a, a + 143, a + 286, &e) != TS_OK)
        rc = 3;
    for (int k = 0; k < 2 && !rc; k++) {
        ts_backend want = k ? TS_BACKEND_AUTO : TS_BACKEND_OPENCL;
        if (ts_backend_normals(want, &g, b, b + 143, b + 286, &r, &e) != TS_OK)
            rc = 4;
        else if (r.used != TS_BACKEND_C || !r.fell_back || !strstr(r.reason, "no OpenCL platform"))
            rc = 5;
        else if (memcmp(a, b, 3 * 143 * sizeof *a))
            rc = 6;
        printf("  child: dispatch %s ran %s on %s, fell back: %s\n", ts_backend_name(want),
               r.backend, r.device, r.reason);
    }
    free(a);
    free(b);
    ts_grid_free(&g);
    return rc;
}

START_TEST(test_no_platform)
{
    require_opencl();
    char dir[] = "/tmp/ts_no_icd_XXXXXX";
    ck_assert_ptr_nonnull(mkdtemp(dir));
    int rc = run_child("--child-no-platform", "OCL_ICD_VENDORS", dir);
    rmdir(dir);
    ck_assert_msg(rc == 0, "the no-platform child failed with %d", rc);
}
END_TEST

/* Child: kernels in float only (a device without cl_khr_fp64). */
static int child_fp32(void)
{
    ts_error e;
    ts_cl_info info;
    if (ts_cl_available(&info, &e) != TS_OK || info.fp64) {
        printf("  child fp32: %s\n", info.fp64 ? "fp64 still on" : e.message);
        return 1;
    }
    const dem_spec s = {67, 59, 30, 1, 1, 0, 12};
    ts_grid g;
    make_dem(&g, &s);
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 8;
    size_t n = (size_t)s.w * s.h;
    float *c = malloc(n * 8 * sizeof *c), *l = malloc(n * 8 * sizeof *l);
    int rc = 0;
    if (ts_horizon_compute(&g, &o, c, &e) != TS_OK || ts_cl_horizon_compute(&g, &o, l, &e))
        rc = 2;
    diff d = compare(c, l, n * 8);
    printf("  child fp32: horizon 67x59 holes geo, 8 dirs: max |C - OpenCL (float)| = %.3g deg\n",
           d.max);
    if (!rc && (d.nan_mismatch || d.max > TOL_HORIZON))
        rc = 3;
    ts_shm_compute(&g, 33, 10, 0, 0, c, c + n, &e);
    if (!rc && ts_cl_shm_compute(&g, 33, 10, 0, 0, l, l + n, &e) != TS_OK)
        rc = 4;
    d = compare(c, l, 2 * n);
    printf("  child fp32: shm: max difference %.3g\n", d.max);
    if (!rc && (d.nan_mismatch || d.max > TOL))
        rc = 5;
    if (!rc && (ts_normals(&g, c, c + n, c + 2 * n, &e) != TS_OK ||
                ts_cl_normals(&g, l, l + n, l + 2 * n, &e) != TS_OK))
        rc = 6;
    d = compare(c, l, 3 * n);
    printf("  child fp32: normals: max difference %.3g\n", d.max);
    if (!rc && (d.nan_mismatch || d.max > TOL))
        rc = 7;
    free(c);
    free(l);
    ts_grid_free(&g);
    return rc;
}

START_TEST(test_fp32_kernels)
{
    require_opencl();
    int rc = run_child("--child-fp32", "TERRASHADE_OPENCL_FP64", "0");
    ck_assert_msg(rc == 0, "the float-kernel child failed with %d", rc);
}
END_TEST

/* Buffers larger than the device allows: a clean error, then fallback. */
START_TEST(test_too_large)
{
    require_opencl();
    clear_env();
    ts_error e;
    ts_cl_info info;
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    /* A grid one row larger than the device's largest buffer, in pages
     * that are never touched (the upload is refused before any copy). */
    const int W = 1 << 20;
    const int H = (int)(info.max_alloc / sizeof(float) / (unsigned long long)W) + 1;
    size_t bytes = (size_t)W * H * sizeof(float);
    printf("  %d x %d grid (%zu MiB) against a %llu MiB maximum allocation\n", W, H, bytes >> 20,
           info.max_alloc >> 20);
    void *mem = mmap(NULL, 4 * bytes, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    ck_assert_msg(mem != MAP_FAILED, "mmap of %zu MiB: %s", 4 * bytes >> 20, strerror(errno));
    ts_grid g = {0};
    g.width = W;
    g.height = H;
    g.stride = W;
    g.cell_x = g.cell_y = 30;
    g.z = mem;
    float *o = (float *)mem + (size_t)W * H;
    ts_status st = ts_cl_normals(&g, o, o + (size_t)W * H, o + 2 * (size_t)W * H, &e);
    printf("  ts_cl_normals: %s\n", e.message);
    ck_assert_int_eq(st, TS_ERR_NOMEM);
    ck_assert_msg(strstr(e.message, "CL_INVALID_BUFFER_SIZE") ||
                      strstr(e.message, "CL_MEM_OBJECT_ALLOCATION_FAILURE") ||
                      strstr(e.message, "CL_OUT_OF_RESOURCES"),
                  "no OpenCL error name in '%s'", e.message);
    st = ts_cl_shm_compute(&g, 10, 10, 0, 0, o, NULL, &e);
    ck_assert_int_eq(st, TS_ERR_NOMEM);
    munmap(mem, 4 * bytes);

    /* The same through TERRASHADE_OPENCL_MAX_ALLOC on a small grid, where
     * the dispatcher can afford the fallback. */
    setenv("TERRASHADE_OPENCL_MAX_ALLOC", "4k", 1);
    ck_assert_int_eq(ts_cl_available(&info, &e), TS_OK);
    ck_assert_int_eq(info.max_alloc, 4096);
    ts_backend_report r = dispatch_normals(TS_BACKEND_OPENCL, &SHAPES[4]); /* 7.8 kB */
    ck_assert_int_eq(r.used, TS_BACKEND_C);
    ck_assert_int_eq(r.fell_back, 1);
    ck_assert_ptr_nonnull(strstr(r.reason, "CL_INVALID_BUFFER_SIZE"));
    ck_assert_ptr_nonnull(strstr(r.reason, "TERRASHADE_OPENCL_MAX_ALLOC"));
    /* horizons: the planes do not fit either */
    scene sc;
    scene_make(&sc, &SHAPES[4], 4, 0.0);
    float *h = tdem_floats(sc.n * 4);
    ck_assert_int_eq(ts_cl_horizon_compute(&sc.g, &sc.o, h, &e), TS_ERR_NOMEM);
    ck_assert_int_eq(ts_backend_horizon_compute(TS_BACKEND_OPENCL, &sc.g, &sc.o, h, &r, &e),
                     TS_OK);
    ck_assert_int_eq(r.fell_back, 1);
    ck_assert(memcmp(h, sc.h, sc.n * 4 * sizeof *h) == 0);
    setenv("TERRASHADE_OPENCL_MAX_ALLOC", "lots", 1);
    ck_assert_int_ne(ts_cl_normals(&sc.g, h, h + sc.n, h + 2 * sc.n, &e), TS_OK);
    ck_assert_ptr_nonnull(strstr(e.message, "TERRASHADE_OPENCL_MAX_ALLOC"));
    free(h);
    scene_free(&sc, &SHAPES[4]);
    clear_env();
}
END_TEST

/* Two threads on the shared device at once. */
typedef struct {
    const dem_spec *s;
    int which;
    double maxdiff;
    int fail;
} thread_job;

static void *thread_main(void *arg)
{
    thread_job *t = arg;
    ts_grid g;
    ts_error e;
    make_dem(&g, t->s);
    size_t n = (size_t)t->s->w * t->s->h;
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.directions = 6;
    float *c = malloc(n * 6 * sizeof *c), *l = malloc(n * 6 * sizeof *l);
    for (int rep = 0; rep < 3; rep++) {
        ts_status a, b;
        size_t m = n;
        if (t->which == 0) {
            a = ts_horizon_compute(&g, &o, c, &e);
            b = ts_cl_horizon_compute(&g, &o, l, &e);
            m = n * 6;
        } else {
            a = ts_shm_compute(&g, 40.0 * rep, 15, 0, 0, c, NULL, &e);
            b = ts_cl_shm_compute(&g, 40.0 * rep, 15, 0, 0, l, NULL, &e);
        }
        diff d = compare(c, l, m);
        if (a != TS_OK || b != TS_OK || d.nan_mismatch)
            t->fail = 1;
        t->maxdiff = fmax(t->maxdiff, d.max);
    }
    free(c);
    free(l);
    ts_grid_free(&g);
    return NULL;
}

START_TEST(test_threads)
{
    require_opencl();
    thread_job jobs[2] = {{&SHAPES[5], 0, 0, 0}, {&SHAPES[4], 1, 0, 0}};
    pthread_t th[2];
    for (int i = 0; i < 2; i++)
        ck_assert_int_eq(pthread_create(&th[i], NULL, thread_main, &jobs[i]), 0);
    for (int i = 0; i < 2; i++)
        pthread_join(th[i], NULL);
    printf("  two threads: horizon max diff %.3g deg, shm %.3g\n", jobs[0].maxdiff,
           jobs[1].maxdiff);
    ck_assert(!jobs[0].fail && !jobs[1].fail);
    ck_assert(jobs[0].maxdiff <= TOL_HORIZON && jobs[1].maxdiff <= TOL);
}
END_TEST

static Suite *opencl_suite(void)
{
    Suite *s = suite_create("opencl");
    TCase *t = tcase_create("backends");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, test_build_config);
    tcase_add_test(t, test_available);
    tcase_add_test(t, test_horizon);
    tcase_add_test(t, test_horizon_small_buffers);
    tcase_add_test(t, test_horizon_sweep);
    tcase_add_test(t, test_horizon_edge);
    tcase_add_test(t, test_shm);
    tcase_add_test(t, test_shm_wide);
    tcase_add_test(t, test_normals);
    tcase_add_test(t, test_direct);
    tcase_add_test(t, test_sky);
    tcase_add_test(t, test_arguments);
    tcase_add_test(t, test_env_light);
    suite_add_tcase(s, t);
    TCase *d = tcase_create("dispatch and failures");
    tcase_set_timeout(d, 600);
    tcase_add_test(d, test_dispatch);
    tcase_add_test(d, test_dispatch_products);
    tcase_add_test(d, test_env_light_dispatch);
    tcase_add_test(d, test_bogus_device);
    tcase_add_test(d, test_no_platform);
    tcase_add_test(d, test_fp32_kernels);
    tcase_add_test(d, test_too_large);
    tcase_add_test(d, test_threads);
    suite_add_tcase(s, d);
    return s;
}

int main(int argc, char **argv)
{
    ssize_t len = readlink("/proc/self/exe", g_self, sizeof g_self - 1);
    if (len <= 0)
        snprintf(g_self, sizeof g_self, "%s", argv[0]);
    else
        g_self[len] = '\0';
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 1 && !strcmp(argv[1], "--child-no-platform"))
        return child_no_platform();
    if (argc > 1 && !strcmp(argv[1], "--child-fp32"))
        return child_fp32();
    return test_run_suite_mode(opencl_suite(), CK_VERBOSE);
}
