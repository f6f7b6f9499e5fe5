/*
 * cl_test_common: what the OpenCL test programs share: synthetic DEM specs,
 * the C-versus-OpenCL comparison, the OpenCL requirement, C scenes for the
 * shading tests and the dispatcher helper. Linked into each program.
 */
#ifndef CL_TEST_COMMON_H
#define CL_TEST_COMMON_H

#include <check.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "terrashade.h"
#include "terrashade_backend.h"
#include "terrashade_cl.h"
#include "terrashade_env.h"

#define TOL_HORIZON 1e-3 /* degrees */
#define TOL 1e-4         /* shm, normals, direct, sky */
#define TOL_ENV_REL 1e-4 /* environment light, relative */

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

/* The test shapes: odd sizes, holes, geographic spacing, padded strides. */
#define NSHAPES 10
extern const dem_spec SHAPES[NSHAPES];

/* A grid per spec; free with free_dem. */
void make_dem(ts_grid *g, const dem_spec *s);
void free_dem(ts_grid *g, const dem_spec *s);
const char *shape_name(const dem_spec *s, char *buf, size_t n);

typedef struct {
    double max;
    long nan_mismatch;
    long valid;
} diff;

/* Max |a - b| over cells valid in both, and cells nodata in one only. */
diff compare(const float *a, const float *b, size_t n);
/* Asserts C and OpenCL agree within tol, printing the measured difference. */
void expect_close(const char *what, const float *c, const float *cl, size_t n, double tol);
/* Fails the test, saying why, without OpenCL support or device. */
void require_opencl(void);

/* C horizons and normals for the shading tests. */
typedef struct {
    ts_grid g;
    ts_horizon_opts o;
    size_t n;
    float *h, *nx, *ny, *nz;
} scene;

void scene_make(scene *sc, const dem_spec *s, int dirs, double start);
void scene_free(scene *sc, const dem_spec *s);
ts_direct_request scene_direct(const scene *sc, double az, double el, float *out);
ts_sky_request scene_sky(const scene *sc, ts_svf_model m, float *svf, float *sky,
                         float *open);
ts_env_light_request scene_env(const scene *sc, const ts_env_table *t, int k, float *rgb);

/* Unsets the backend selection variables. */
void clear_env(void);
/* Normals through the dispatcher; returns the report, checks the result. */
ts_backend_report dispatch_normals(ts_backend b, const dem_spec *s);

#endif
