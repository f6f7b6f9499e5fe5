/* cl_test_common: the shared helpers of the OpenCL test programs. */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <math.h>
#include <string.h>

#include "cl_test_common.h"
#include "test_grid.h"

/* A grid per spec; free with free_dem. */
void make_dem(ts_grid *g, const dem_spec *s)
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

void free_dem(ts_grid *g, const dem_spec *s)
{
    if (s->pad) {
        free(g->z);
        memset(g, 0, sizeof *g);
    } else {
        ts_grid_free(g);
    }
}

const dem_spec SHAPES[NSHAPES] = {
    {1, 1, 30, 0, 0, 0, 1},      {1, 17, 30, 0, 0, 0, 2},     {23, 1, 30, 0, 0, 0, 3},
    {2, 2, 30, 0, 0, 0, 4},      {37, 53, 30, 0, 0, 0, 5},    {53, 37, 25, 1, 0, 0, 6},
    {61, 47, 500, 1, 1, 0, 7},   {41, 29, 30, 1, 0, 5, 8},    {64, 64, 10, 1, 0, 0, 9},
    {3, 31, 30, 1, 0, 0, 10},
};
_Static_assert(sizeof SHAPES / sizeof *SHAPES == NSHAPES, "NSHAPES");

const char *shape_name(const dem_spec *s, char *buf, size_t n)
{
    snprintf(buf, n, "%dx%d%s%s%s", s->w, s->h, s->holes ? " holes" : "", s->geo ? " geo" : "",
             s->pad ? " padded" : "");
    return buf;
}

/* ------------------------------------------------------------ compare */

diff compare(const float *a, const float *b, size_t n)
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

void expect_close(const char *what, const float *c, const float *cl, size_t n, double tol)
{
    diff d = compare(c, cl, n);
    printf("  %-58s max |C - OpenCL| = %.3g over %ld cells\n", what, d.max, d.valid);
    ck_assert_msg(d.nan_mismatch == 0, "%s: %ld cells nodata in one backend only", what,
                  d.nan_mismatch);
    ck_assert_msg(d.max <= tol, "%s: max difference %g > %g", what, d.max, tol);
}

void require_opencl(void)
{
    ts_error e;
    ts_cl_info info;
    ck_assert_msg(ts_cl_built(),
                  "OpenCL support was not built: configure found no OpenCL "
                  "(apt-get install ocl-icd-opencl-dev opencl-headers pocl-opencl-icd)");
    ts_status st = ts_cl_available(&info, &e);
    ck_assert_msg(st == TS_OK, "no usable OpenCL device (PoCL is installed by setup.sh): %s",
                  e.message);
}

/* -------------------------------------------------------------- tests */

void scene_make(scene *sc, const dem_spec *s, int dirs, double start)
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

void scene_free(scene *sc, const dem_spec *s)
{
    free(sc->h), free(sc->nx), free(sc->ny), free(sc->nz);
    free_dem(&sc->g, s);
}

/* The scene's direct sun at azimuth az, elevation el into out. */
ts_direct_request scene_direct(const scene *sc, double az, double el, float *out)
{
    return (ts_direct_request){&sc->g, sc->nx, sc->ny, sc->nz, sc->h,
                               &sc->o, az,     el,     out,    TS_SUN_RADIUS_DEG};
}

/* The scene's sky terms of model m into svf, sky, open (each may be NULL). */
ts_sky_request scene_sky(const scene *sc, ts_svf_model m, float *svf, float *sky,
                                float *open)
{
    return (ts_sky_request){&sc->g, sc->nx, sc->ny, sc->nz, sc->h, &sc->o, m, svf, sky, open};
}

/* The scene's environment light of table t's sector k (its horizon plane k)
 * into rgb: three planes of sc->n floats. */
ts_env_light_request scene_env(const scene *sc, const ts_env_table *t, int k, float *rgb)
{
    return (ts_env_light_request){&sc->g, t,   k, sc->nx, sc->ny, sc->nz, sc->h + sc->n * k,
                                  rgb,    rgb + sc->n, rgb + 2 * sc->n, 0};
}

void clear_env(void)
{
    unsetenv("TERRASHADE_BACKEND");
    unsetenv("TERRASHADE_OPENCL_DEVICE");
    unsetenv("TERRASHADE_OPENCL_MAX_ALLOC");
}

/* Normals through the dispatcher; returns the report, checks the result. */
ts_backend_report dispatch_normals(ts_backend b, const dem_spec *s)
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
    ts_status st = ts_backend_normals(b, &g, 0, l[0], l[1], l[2], &r, &e);
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
