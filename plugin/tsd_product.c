/* The products: which core calls, in which order, with how much memory. */
#include "tsd_product.h"

#include "shadow_atlas.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    float *nx, *ny, *nz;
} normals;

static int core_fail(char *msg, size_t n, const ts_error *err)
{
    snprintf(msg, n, "%s", err->message[0] ? err->message
                                           : ts_status_name(err->code));
    return -1;
}

static int oom(char *msg, size_t n, const char *what)
{
    snprintf(msg, n, "out of memory for %s", what);
    return -1;
}

ts_backend tsd_backend_to_ts(tsd_backend b)
{
    return b == TSD_BACKEND_OPENCL ? TS_BACKEND_OPENCL
           : b == TSD_BACKEND_C    ? TS_BACKEND_C
                                   : TS_BACKEND_AUTO;
}

int tsd_product_uses_backend(const tsd_options *o, const tsd_sun *sun)
{
    int lattice = sun && sun->sites.nx * sun->sites.ny > 1;
    switch (o->product) {
    case TSD_PRODUCT_SHADE: /* the normals at least */
    case TSD_PRODUCT_HORIZON:
    case TSD_PRODUCT_SVF:
    case TSD_PRODUCT_OPENNESS:
    case TSD_PRODUCT_SKY:
        return 1;
    case TSD_PRODUCT_SHADOW:
        return !(lattice && o->method == TSD_METHOD_EXACT);
    default:
        return 0;
    }
}

void tsd_backend_summary_add(tsd_backend_summary *s, const ts_backend_report *r)
{
    if (!s->calls)
        s->requested = r->requested;
    s->calls++;
    if (r->used == TS_BACKEND_OPENCL) {
        s->opencl_calls++;
        snprintf(s->device_opencl, sizeof s->device_opencl, "%s", r->device);
        return;
    }
    s->c_calls++;
    snprintf(s->device_c, sizeof s->device_c, "%s", r->device);
    /* the first reason; the first failure wins over a choice (auto on a CPU) */
    if (r->requested != TS_BACKEND_C && r->reason[0] &&
        (!s->reason[0] || (r->fell_back && !s->fell_back)))
        snprintf(s->reason, sizeof s->reason, "%s", r->reason);
    s->fell_back |= r->fell_back;
}

int tsd_backend_predict(const tsd_options *o, tsd_backend_summary *s, char *msg,
                        size_t n)
{
    ts_backend_report r;
    ts_error err;
    memset(s, 0, sizeof *s);
    if (ts_backend_choose(tsd_backend_to_ts(o->backend), &r, &err) != TS_OK)
        return core_fail(msg, n, &err);
    tsd_backend_summary_add(s, &r);
    return 0;
}

int tsd_backend_check_env(const tsd_options *o, char *msg, size_t n)
{
    const char *env = getenv("TERRASHADE_BACKEND");
    ts_backend b;
    ts_error err;
    if (o->backend != TSD_BACKEND_AUTO || !env || !*env ||
        ts_backend_parse(env, &b, &err) == TS_OK)
        return 0;
    snprintf(msg, n, "TERRASHADE_BACKEND must be auto, c or opencl, got '%.40s'", env);
    return -1;
}

void tsd_backend_summary_text(const tsd_backend_summary *s, char *backend, size_t bn,
                              char *device, size_t dn)
{
    if (s->opencl_calls && s->c_calls) {
        snprintf(backend, bn, "mixed");
        snprintf(device, dn, "opencl: %s; c: %s", s->device_opencl, s->device_c);
    } else if (s->opencl_calls) {
        snprintf(backend, bn, "opencl");
        snprintf(device, dn, "%s", s->device_opencl);
    } else {
        snprintf(backend, bn, "c");
        snprintf(device, dn, "%s", s->device_c);
    }
}

static void horizon_opts(const tsd_options *o, ts_horizon_opts *h)
{
    ts_horizon_opts_default(h);
    h->directions = o->directions;
    h->start_azimuth = o->start_azimuth;
    h->max_distance = o->max_distance;
    h->curvature = o->curvature;
    h->refraction = o->refraction;
    h->threads = o->threads;
    h->progress = o->progress;
    h->progress_user = o->progress_user;
}

/* Report progress `done` (0..1) of a loop the plugin runs itself; -1 with
 * msg filled when the caller cancels. */
static int report(const tsd_options *o, double done, char *msg, size_t n)
{
    if (o->progress && o->progress(done, o->progress_user)) {
        snprintf(msg, n, "cancelled by the caller");
        return -1;
    }
    return 0;
}

/* Extra float planes (besides the DEM grid and the product) at the peak. */
static int extra_planes(const tsd_options *o)
{
    int lattice = o->sun_position == TSD_SUN_PER_CELL;
    switch (o->product) {
    case TSD_PRODUCT_SHADE:
        /* normals, a horizon plane or the SHM visibility, the sky
         * accumulator and its horizon plane */
        return 3 + 1 + (o->sky_weight > 0 ? 2 : 0) + (lattice ? 7 : 0);
    case TSD_PRODUCT_SHADOW:
        return lattice ? 7 : 0;
    case TSD_PRODUCT_HORIZON:
        return 0;
    case TSD_PRODUCT_SVF:
    case TSD_PRODUCT_OPENNESS:
    case TSD_PRODUCT_SKY:
        return 3 + 1; /* normals and one horizon plane */
    case TSD_PRODUCT_SUNHOURS:
        /* Earth horizon, horizon plane, visibility, double accumulator */
        return 5 + (lattice ? 3 : 0);
    case TSD_PRODUCT_INSOLATION:
        /* normals, sky, visibility, pressure factor, two double
         * accumulators, Earth horizon, horizon plane */
        return 12 + (lattice ? 5 : 0);
    case TSD_PRODUCT_DAYCYCLE:
        return 2 + (lattice ? 3 : 0);
    case TSD_PRODUCT_FARSHADOW:
        return 1; /* the far-field slopes */
    }
    return 0;
}

double tsd_product_peak_bytes(const tsd_options *o, int width, int height,
                              double *steady)
{
    double plane = (double)width * (double)height * sizeof(float);
    double bands = tsd_options_band_count(o);
    /* farshadow keeps bytes, a quarter of a float plane per band */
    double kept = o->product == TSD_PRODUCT_FARSHADOW ? bands / 4 : bands;
    if (steady)
        *steady = kept * plane;
    return (1 + kept + extra_planes(o)) * plane;
}

/* The backend of the options, and the report of a call added to bs. */
#define BK(o) tsd_backend_to_ts((o)->backend)
#define NOTE(bs, call, rep) note((bs), (call), &(rep))

/* After a ts_backend_* call (its status st): add its report, if filled. */
static ts_status note(tsd_backend_summary *bs, ts_status st, const ts_backend_report *r)
{
    if (bs && r->backend[0])
        tsd_backend_summary_add(bs, r);
    return st;
}

static void free_normals(normals *nm)
{
    free(nm->nx);
    free(nm->ny);
    free(nm->nz);
}

static int make_normals(const ts_grid *g, const tsd_options *o, normals *nm,
                        tsd_backend_summary *bs, char *msg, size_t n)
{
    size_t cells = (size_t)g->width * g->height;
    ts_error err;
    ts_backend_report rep = {0};
    nm->nx = malloc(cells * sizeof(float));
    nm->ny = malloc(cells * sizeof(float));
    nm->nz = malloc(cells * sizeof(float));
    if (!nm->nx || !nm->ny || !nm->nz)
        return oom(msg, n, "the surface normals");
    if (NOTE(bs, ts_backend_normals(BK(o), g, nm->nx, nm->ny, nm->nz, &rep, &err), rep) !=
        TS_OK)
        return core_fail(msg, n, &err);
    return 0;
}

/* Stream the DIRECTIONS horizon planes into one sky accumulator; `which`:
 * 0 = svf, 1 = sky, 2 = openness. acc must be zeroed. */
static int sky_stream(const ts_grid *g, const normals *nm, const tsd_options *o,
                      int which, float *acc, tsd_backend_summary *bs, char *msg,
                      size_t n)
{
    size_t cells = (size_t)g->width * g->height;
    ts_horizon_opts h;
    ts_error err;
    horizon_opts(o, &h);
    float *plane = malloc(cells * sizeof(float));
    if (!plane)
        return oom(msg, n, "a horizon plane");
    float *svf = which == 0 ? acc : NULL, *sky = which == 1 ? acc : NULL,
          *open = which == 2 ? acc : NULL;
    h.progress = NULL; /* reported here, per azimuth */
    for (int k = 0; k < h.directions; k++) {
        double az = ts_horizon_azimuth(&h, k);
        ts_backend_report rep = {0};
        if (report(o, (double)k / h.directions, msg, n) != 0) {
            free(plane);
            return -1;
        }
        /* the sweep on the backend; the accumulation is C only */
        if (NOTE(bs, ts_backend_horizon_sweep(BK(o), g, az, &h, plane, &rep, &err), rep) !=
                TS_OK ||
            ts_sky_accumulate(g, nm->nx, nm->ny, nm->nz, plane, az, h.directions,
                              svf, sky, open, &err) != TS_OK) {
            free(plane);
            return core_fail(msg, n, &err);
        }
    }
    free(plane);
    if (ts_sky_finish(g, h.directions, svf, sky, open, &err) != TS_OK)
        return core_fail(msg, n, &err);
    return 0;
}

/* Shadow height map visibility of the sun into vis. */
static int shm_visibility(const ts_grid *g, const tsd_options *o, float *vis,
                          tsd_backend_summary *bs, char *msg, size_t n)
{
    ts_error err;
    ts_backend_report rep = {0};
    if (NOTE(bs, ts_backend_shm_compute(BK(o), g, o->sun_azimuth, o->sun_elevation,
                                        o->penumbra_depth, o->threads, vis, NULL, &rep,
                                        &err),
             rep) != TS_OK)
        return core_fail(msg, n, &err);
    return 0;
}

/* Exact horizon at the sun's azimuth into plane; *h describes it. */
static int sun_horizon(const ts_grid *g, const tsd_options *o, ts_horizon_opts *h,
                       float *plane, tsd_backend_summary *bs, char *msg, size_t n)
{
    ts_error err;
    ts_backend_report rep = {0};
    horizon_opts(o, h);
    h->directions = 1;
    h->start_azimuth = o->sun_azimuth;
    h->progress = NULL; /* one sweep */
    if (NOTE(bs, ts_backend_horizon_sweep(BK(o), g, o->sun_azimuth, h, plane, &rep, &err),
             rep) != TS_OK)
        return core_fail(msg, n, &err);
    return 0;
}

/* Per-cell sun (SUN_POSITION=per_cell): visibility of the disk, and the
 * sun's grid azimuth and elevation per cell; terrain only, as the
 * classic shade and shadow. */
static int sun_per_cell(const ts_grid *g, const tsd_sun *sun, float *vis, float *az,
                        float *el, char *msg, size_t n)
{
    ts_error err;
    ts_day_opts d = sun->day;
    d.earth_horizon = 0;
    if (ts_sun_visibility(g, &sun->sites, &d, sun->instant, vis, az, el, NULL, &err) !=
        TS_OK)
        return core_fail(msg, n, &err);
    return 0;
}

static int shade(const ts_grid *g, const tsd_options *o, const tsd_sun *sun, float *out,
                 tsd_backend_summary *bs, char *msg, size_t n)
{
    size_t cells = (size_t)g->width * g->height;
    normals nm = {0};
    ts_error err;
    int rc = -1;
    int lattice = sun && sun->sites.nx * sun->sites.ny > 1;
    float *work = malloc(cells * sizeof(float));
    float *az = lattice ? malloc(cells * sizeof(float)) : NULL;
    float *el = lattice ? malloc(cells * sizeof(float)) : NULL;
    if (!work || (lattice && (!az || !el))) {
        oom(msg, n, "a horizon plane");
        goto done;
    }
    if (make_normals(g, o, &nm, bs, msg, n) != 0)
        goto done;
    if (lattice) {
        if (sun_per_cell(g, sun, work, az, el, msg, n) != 0)
            goto done;
        for (size_t i = 0; i < cells; i++) {
            double a = az[i] * M_PI / 180, e = el[i] * M_PI / 180;
            double d = nm.nx[i] * sin(a) * cos(e) + nm.ny[i] * cos(a) * cos(e) +
                       nm.nz[i] * sin(e);
            out[i] = (float)((d > 0 ? d : 0) * work[i]); /* NaN stays NaN */
        }
    } else if (o->method == TSD_METHOD_EXACT) {
        ts_horizon_opts h;
        ts_backend_report rep = {0};
        if (sun_horizon(g, o, &h, work, bs, msg, n) != 0)
            goto done;
        if (NOTE(bs, ts_backend_shade_direct(BK(o), g, nm.nx, nm.ny, nm.nz, work, &h,
                                             o->sun_azimuth, o->sun_elevation, out, &rep,
                                             &err),
                 rep) != TS_OK) {
            core_fail(msg, n, &err);
            goto done;
        }
    } else {
        if (shm_visibility(g, o, work, bs, msg, n) != 0)
            goto done;
        double az0 = o->sun_azimuth * M_PI / 180, el0 = o->sun_elevation * M_PI / 180;
        double lx = sin(az0) * cos(el0), ly = cos(az0) * cos(el0), lz = sin(el0);
        for (size_t i = 0; i < cells; i++) {
            double d = nm.nx[i] * lx + nm.ny[i] * ly + nm.nz[i] * lz;
            out[i] = (float)((d > 0 ? d : 0) * work[i]); /* NaN stays NaN */
        }
    }
    if (o->sky_weight > 0) {
        memset(work, 0, cells * sizeof(float));
        if (sky_stream(g, &nm, o, 1, work, bs, msg, n) != 0)
            goto done;
        if (ts_shade_combine(g, out, work, o->sky_weight, out, &err) != TS_OK) {
            core_fail(msg, n, &err);
            goto done;
        }
    }
    rc = 0;
done:
    free(work);
    free(az);
    free(el);
    free_normals(&nm);
    return rc;
}

static int shadow(const ts_grid *g, const tsd_options *o, const tsd_sun *sun, float *out,
                  tsd_backend_summary *bs, char *msg, size_t n)
{
    size_t cells = (size_t)g->width * g->height;
    if (sun && sun->sites.nx * sun->sites.ny > 1 && o->method == TSD_METHOD_EXACT)
        return sun_per_cell(g, sun, out, NULL, NULL, msg, n);
    if (o->method == TSD_METHOD_SHM)
        return shm_visibility(g, o, out, bs, msg, n);
    ts_horizon_opts h;
    if (sun_horizon(g, o, &h, out, bs, msg, n) != 0)
        return -1;
    for (size_t i = 0; i < cells; i++)
        if (out[i] == out[i])
            out[i] = (float)ts_sun_disk_fraction(o->sun_elevation, out[i]);
    return 0;
}

/* The day products. */
static int daily(const ts_grid *g, const tsd_options *o, const tsd_sun *sun, float *out,
                 uint8_t *bytes, char *msg, size_t n)
{
    size_t cells = (size_t)g->width * g->height;
    ts_error err;
    ts_status st = TS_OK;
    if (!sun) {
        snprintf(msg, n, "PRODUCT=%s needs the sun's day (internal error)",
                 tsd_product_name(o->product));
        return -1;
    }
    ts_day_opts day = sun->day; /* the core reports the day's steps */
    day.horizon.progress = o->progress;
    day.horizon.progress_user = o->progress_user;
    switch (o->product) {
    case TSD_PRODUCT_SUNHOURS:
        st = ts_sun_hours(g, &sun->sites, &day, sun->day_start, sun->day_length,
                          o->step_minutes * 60.0, out, &err);
        break;
    case TSD_PRODUCT_INSOLATION:
        st = ts_insolation(g, &sun->sites, &day, sun->day_start, sun->day_length,
                           o->step_minutes * 60.0, out, out + cells, out + 2 * cells, &err);
        break;
    case TSD_PRODUCT_DAYCYCLE:
        for (int k = 0; k < sun->steps && st == TS_OK; k++) {
            if (report(o, (double)k / sun->steps, msg, n) != 0)
                return -1;
            st = ts_sun_visibility(g, &sun->sites, &sun->day, sun->times[k],
                                   out + (size_t)k * cells, NULL, NULL, NULL, &err);
        }
        break;
    case TSD_PRODUCT_FARSHADOW:
        for (int k = 0; k < sun->steps && st == TS_OK; k++) {
            if (report(o, (double)k / sun->steps, msg, n) != 0)
                return -1;
            st = ts_far_shadow(g, sun->samples[k].grid_azimuth, sun->samples[k].elevation,
                               sun->threshold_m, &sun->day.horizon,
                               bytes + (size_t)k * cells, &err);
        }
        break;
    default:
        break;
    }
    return st == TS_OK ? 0 : core_fail(msg, n, &err);
}

static int sky_product(const ts_grid *g, const tsd_options *o, int which,
                       float *out, tsd_backend_summary *bs, char *msg, size_t n)
{
    normals nm = {0};
    int rc = -1;
    memset(out, 0, (size_t)g->width * g->height * sizeof(float));
    if (make_normals(g, o, &nm, bs, msg, n) == 0 &&
        sky_stream(g, &nm, o, which, out, bs, msg, n) == 0)
        rc = 0;
    free_normals(&nm);
    return rc;
}

int tsd_product_compute(const ts_grid *grid, const tsd_options *o, const tsd_sun *sun,
                        float *out, uint8_t *bytes, tsd_backend_summary *bs, char *msg,
                        size_t n)
{
    ts_error err;
    ts_horizon_opts h;
    ts_backend_report rep = {0};
    if (bs)
        memset(bs, 0, sizeof *bs);
    if (ts_grid_validate(grid, &err) != TS_OK)
        return core_fail(msg, n, &err);
    horizon_opts(o, &h);
    if (ts_horizon_opts_validate(&h, &err) != TS_OK)
        return core_fail(msg, n, &err);
    switch (o->product) {
    case TSD_PRODUCT_SHADE:
        return shade(grid, o, sun, out, bs, msg, n);
    case TSD_PRODUCT_SHADOW:
        return shadow(grid, o, sun, out, bs, msg, n);
    case TSD_PRODUCT_SUNHOURS:
    case TSD_PRODUCT_INSOLATION:
    case TSD_PRODUCT_DAYCYCLE:
    case TSD_PRODUCT_FARSHADOW:
        return daily(grid, o, sun, out, bytes, msg, n);
    case TSD_PRODUCT_HORIZON:
        if (NOTE(bs, ts_backend_horizon_compute(BK(o), grid, &h, out, &rep, &err), rep) !=
            TS_OK)
            return core_fail(msg, n, &err);
        return 0;
    case TSD_PRODUCT_SVF:
        return sky_product(grid, o, 0, out, bs, msg, n);
    case TSD_PRODUCT_SKY:
        return sky_product(grid, o, 1, out, bs, msg, n);
    case TSD_PRODUCT_OPENNESS:
        return sky_product(grid, o, 2, out, bs, msg, n);
    }
    snprintf(msg, n, "unknown product");
    return -1;
}
