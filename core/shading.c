/* Direct sun with the visible fraction of the sun's disk, and the final mix. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "arg_checks.h"
#include "disk_fraction.h"
#include "cellmath/cm_sun.h"
#include "horn_row.h"
#include "parallel.h"
#include "simd_clones.h"
#include "status_internal.h"

double ts_sun_disk_fraction(double sun_elevation, double horizon)
{
    return ts_disk_fraction(sun_elevation, horizon, TS_SUN_RADIUS_DEG);
}

double ts_disk_fraction(double light_elevation, double horizon, double radius)
{
    if (isnan(light_elevation) || isnan(horizon) || !(radius > 0))
        return NAN;
    double u = ts_disk_u(light_elevation, horizon, radius);
    if (u >= 1.0)
        return 1.0;
    if (u <= -1.0)
        return 0.0;
    /* Area of the disk above a horizontal chord at height -u radii. */
    return 0.5 + (u * sqrt(1.0 - u * u) + asin(u)) / M_PI;
}

int ts_light_clears_horizontal(double light_elevation, double radius)
{
    if (radius == 0)
        radius = TS_SUN_RADIUS_DEG;
    if (!(radius > 0) || !(light_elevation <= 90))
        return 0;
    /* the horizon 0 in ts_disk_fraction's u and in cm_direct_sun's: a
     * lower horizon gives a u at least as large (monotonic rounding), and
     * every u >= 1 the same fraction */
    double u = (light_elevation - 0.0) / radius;
    float uf = ((float)light_elevation - 0.0f) * (float)(1.0 / radius);
    return u >= 1.0 && uf >= 1.0f;
}

ts_status ts_check_light_radius(double radius, ts_error *err)
{
    if (!(radius > 0 && radius < TS_LIGHT_RADIUS_MAX))
        return ts_fail(err, TS_ERR_ARG,
                       "the light's angular radius must be > 0 and < %g degrees, got %g",
                       TS_LIGHT_RADIUS_MAX, radius);
    return ts_ok(err);
}

typedef struct {
    const float *nx, *ny, *nz, *h0, *h1;
    float w, lx, ly, lz;
    double sun_el, radius;
    float *out;
} direct_ctx;

/* cm_direct_sun is branch-free, so that this loop vectorises (AVX-512/AVX2
 * clones: the same float operations, no contraction under -std=c11). */
TS_SIMD_CLONES
static void direct_range(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const direct_ctx *C = ctx;
    const float *restrict nx = C->nx, *restrict ny = C->ny, *restrict nz = C->nz;
    const float *restrict h0 = C->h0, *restrict h1 = C->h1;
    float *restrict out = C->out;
    const float w = C->w, lx = C->lx, ly = C->ly, lz = C->lz;
    const float el = (float)C->sun_el, inv_r = (float)(1.0 / C->radius);
    for (long i = begin; i < end; i++)
        out[i] = cm_direct_sun(nx[i], ny[i], nz[i], h0[i], h1[i], w, lx, ly, lz, el, inv_r);
}

/* The direct term's loop state of a checked request and its plan. */
static direct_ctx direct_ctx_of(const ts_direct_request *req, const ts_direct_plan *p)
{
    size_t plane = (size_t)req->grid->width * req->grid->height;
    direct_ctx C = {req->nx, req->ny, req->nz, req->horizons + plane * p->k0,
                    req->horizons + plane * p->k1, (float)p->w, p->light[0], p->light[1],
                    p->light[2], req->sun_elevation, p->radius, req->out};
    return C;
}

typedef struct {
    direct_ctx d;
    const ts_grid *grid;
    int *alloc_failed;
} direct_horn_ctx;

/* Rows begin..end-1: the Horn normals of a row into row buffers, then
 * direct_range's term from them; the same bits as the two passes. In place
 * (the horizons in out), a row's horizons are copied first (restrict). */
static void direct_horn_rows(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const direct_horn_ctx *C = ctx;
    const int W = C->grid->width;
    const int in_place = C->d.h0 == C->d.out; /* and h1 (shade_direct) */
    float *n = malloc((in_place ? 4 : 3) * (size_t)W * sizeof *n);
    if (!n) {
        __atomic_store_n(C->alloc_failed, 1, __ATOMIC_RELAXED);
        return;
    }
    for (long y = begin; y < end; y++) {
        size_t o = (size_t)y * W;
        ts_horn_row(C->grid, (int)y, n, n + W, n + 2 * (size_t)W);
        direct_ctx row = C->d; /* this row's cells from index 0 */
        row.nx = n;
        row.ny = n + W;
        row.nz = n + 2 * (size_t)W;
        row.h0 += o;
        row.h1 += o;
        row.out += o;
        if (in_place) { /* one direction: h0 and h1 are the same plane */
            memcpy(n + 3 * (size_t)W, row.h0, (size_t)W * sizeof *n);
            row.h0 = row.h1 = n + 3 * (size_t)W;
        }
        direct_range(&row, worker, 0, W);
    }
    free(n);
}

/* The direct sun from the request's normals, or (horn) from rows of Horn
 * normals made on the way. */
static ts_status shade_direct(const ts_direct_request *req, int horn, ts_error *err)
{
    ts_direct_plan p;
    ts_status st = horn ? ts_direct_setup_horn(req, &p, err) : ts_direct_setup(req, &p, err);
    if (st != TS_OK)
        return st;
    if (req->out == req->horizons && !(horn && p.k0 == 0 && p.k1 == 0))
        return ts_fail(err, TS_ERR_ARG,
                       "the direct sun is computed in place only from one horizon plane");
    size_t plane = (size_t)req->grid->width * req->grid->height;
    int threads = ts_thread_count(req->opts ? req->opts->threads : 0, (long)(plane >> 16) + 1),
        failed = 0;
    direct_horn_ctx C = {direct_ctx_of(req, &p), req->grid, &failed};
    if (!horn)
        return ts_parallel_for_ranges(threads, (long)plane, TS_CELLS_GRAIN, direct_range, &C.d,
                                      err);
    st = ts_parallel_for_ranges(threads, req->grid->height, TS_ROWS_GRAIN, direct_horn_rows, &C,
                                err);
    if (st == TS_OK && failed)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the rows of normals");
    return st;
}

ts_status ts_shade_direct(const ts_direct_request *req, ts_error *err)
{
    return shade_direct(req, 0, err);
}

ts_status ts_shade_direct_horn(const ts_direct_request *req, ts_error *err)
{
    return shade_direct(req, 1, err);
}

ts_status ts_shade_combine(const ts_grid *grid, const float *direct, const float *sky,
                           double sky_weight, float *out, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!direct || !sky || !out)
        return ts_fail(err, TS_ERR_ARG, "direct, sky and output must not be NULL");
    if (!(sky_weight >= 0) || isinf(sky_weight))
        return ts_fail(err, TS_ERR_ARG, "sky weight must be a finite number >= 0, got %g",
                       sky_weight);
    size_t plane = (size_t)grid->width * grid->height;
    float wgt = (float)sky_weight;
    for (size_t i = 0; i < plane; i++) {
        float v = direct[i] + wgt * sky[i];
        out[i] = v > 1.0f ? 1.0f : v < 0.0f ? 0.0f : v; /* NaN passes through */
    }
    return ts_ok(err);
}
