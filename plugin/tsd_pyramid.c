/* HORIZON_METHOD=pyramid in the driver; see tsd_pyramid.h. */
#include "tsd_pyramid.h"

#include "tsd_products.h"
#include "tsd_text.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REFUSE(...) return (tsd_fail(msg, n, TS_ERR_ARG, __VA_ARGS__), -1)

int tsd_options_check_pyramid(const tsd_options *o, char *msg, size_t n)
{
    static const char *const own[] = {"HORIZON_METHOD", "PYRAMID_LEVEL_STEP", "PYRAMID_OFFSET"};
    const tsd_product_def *p = tsd_product_of(o);
    char list[256];
    double k0 = 0, o0 = 0; /* (the table's defaults are numbers) */
    tsd_parse_decimal(tsd_option_default(tsd_option_find("PYRAMID_LEVEL_STEP")), &k0);
    tsd_parse_decimal(tsd_option_default(tsd_option_find("PYRAMID_OFFSET")), &o0);
    /* given with its default, an option of another product is no mistake
     * (the warning of unused options names it: HORIZON_METHOD=exact with
     * sunhours, whose sweeps are exact, was refused until session 58) */
    enum { METHOD, LEVEL_STEP, OFFSET };
    const int set[] = {[METHOD] = o->horizon_method != TSD_HORIZON_EXACT,
                       [LEVEL_STEP] = o->pyramid_level_step != k0,
                       [OFFSET] = o->pyramid_offset != o0};
    for (size_t i = 0; i < sizeof own / sizeof own[0]; i++) {
        int id = tsd_option_find(own[i]);
        /* METHOD=sh's key light (shade, shadow) is built from horizons */
        if (!set[i] || tsd_product_takes(p, id) || o->method == TSD_METHOD_SH)
            continue;
        tsd_products_taking(id, "PRODUCT=", " and ", list, sizeof list);
        REFUSE("%s applies to the products whose horizons the pyramid can give (%s; shade: "
               "its sky term), not to PRODUCT=%s%s",
               own[i], list, p->name,
               tsd_product_takes(p, tsd_option_find("METHOD"))
                   ? ", whose shadows METHOD chooses (with METHOD=sh from horizons)"
                   : "");
    }
    /* as SVF_MODEL: a value that would do nothing is a mistake; the
     * default given explicitly is not */
    if (o->horizon_method != TSD_HORIZON_PYRAMID) {
        const char *which = set[OFFSET]       ? "PYRAMID_OFFSET"
                            : set[LEVEL_STEP] ? "PYRAMID_LEVEL_STEP"
                                              : NULL;
        if (which)
            REFUSE("%s applies with HORIZON_METHOD=pyramid; HORIZON_METHOD=exact (the "
                   "sweep) has no pyramid",
                   which);
        return 0;
    }
    /* shadow's only horizons are METHOD=sh's key light */
    if (!tsd_product_takes(p, tsd_option_find("SKY_WEIGHT")) &&
        tsd_product_takes(p, tsd_option_find("METHOD")) && o->method != TSD_METHOD_SH)
        REFUSE("HORIZON_METHOD=pyramid applies to PRODUCT=%s with METHOD=sh (its key light "
               "from horizons); the other METHODs cast their shadows without horizons or with "
               "the exact sweep",
               p->name);
    if (tsd_product_takes(p, tsd_option_find("SKY_WEIGHT")) && !(o->sky_weight > 0) &&
        o->method != TSD_METHOD_SH)
        REFUSE("HORIZON_METHOD=pyramid applies to the sky term of PRODUCT=%s, which "
               "SKY_WEIGHT=0 leaves out: give SKY_WEIGHT > 0 (the direct sun follows METHOD; "
               "METHOD=sh takes its horizons from the pyramid too)",
               p->name);
    return 0;
}

double tsd_pyramid_bytes(const tsd_options *o, int width, int height, int planes)
{
    if (o->horizon_method != TSD_HORIZON_PYRAMID)
        return 0;
    /* pyramid_run holds `planes` where the sweep holds one (counted with
     * the product's): the sky sums hold none, so that one comes off */
    double extra = (planes - 1) * (double)width * height * sizeof(float);
    return ts_pyramid_build_bytes(width, height, o->pyramid_level_step) + extra;
}

/* The backend report of the pyramid: C, and why not OpenCL when OpenCL
 * was wanted and usable. */
static ts_status note_backend(const tsd_compute_ctx *c)
{
    ts_backend_report r;
    ts_error err;
    if (ts_backend_choose(tsd_backend_to_ts(c->opts->backend), &r, &err) != TS_OK)
        return tsd_fail_core(c->msg, c->msg_size, NULL, &err);
    if (r.used == TS_BACKEND_OPENCL) {
        ts_backend_report cpu;
        if (ts_backend_choose(TS_BACKEND_C, &cpu, &err) != TS_OK)
            return tsd_fail_core(c->msg, c->msg_size, NULL, &err);
        r.used = TS_BACKEND_C;
        r.fell_back = 1;
        snprintf(r.backend, sizeof r.backend, "c");
        snprintf(r.device, sizeof r.device, "%s", cpu.device);
        snprintf(r.reason, sizeof r.reason, "%s", TSD_PYRAMID_C_REASON);
    }
    if (c->backend)
        tsd_backend_summary_add(c->backend, &r);
    return TS_OK;
}

/* The planes of the pyramid read with `rec`, TS_PYRAMID_BATCH at a time
 * (one at a time where memory is short), to `add` in order, or with `sky`
 * their sky terms summed as the rows are done (add unused): at the `count`
 * azimuths `az` (degrees), or at DIRECTIONS' when az is NULL. */
static ts_status pyramid_run(const tsd_compute_ctx *c, const ts_grid *g,
                             ts_pyramid_reconstruction rec, int count, const double *azimuths,
                             const ts_pyramid_sky *sky, tsd_plane_fn add, void *user)
{
    const tsd_options *o = c->opts;
    ts_horizon_opts h;
    ts_pyramid_opts po;
    ts_error err;
    ts_status st = TS_OK;
    tsd_compute_horizon_opts(c, &h);
    h.progress = NULL; /* reported here, per batch of azimuths */
    ts_pyramid_opts_default(&po);
    po.level_step = o->pyramid_level_step;
    po.offset = o->pyramid_offset;
    po.reconstruction = rec;
    if ((st = note_backend(c)) != TS_OK)
        return st;
    if (!azimuths)
        count = h.directions;
    size_t cells = (size_t)g->width * g->height;
    int batch = count < TS_PYRAMID_BATCH ? count : TS_PYRAMID_BATCH;
    /* the sky sums need no planes: the pyramid sums each row as it is done */
    float *planes = NULL;
    if (!sky) {
        planes = malloc(cells * batch * sizeof(float));
        if (!planes && batch > 1)
            planes = malloc(cells * (batch = 1) * sizeof(float));
        if (!planes)
            return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM,
                            "out of memory for a horizon plane");
    }
    ts_pyramid *pyr = NULL;
    if (ts_pyramid_build(g, &po, o->threads, &pyr, &err) != TS_OK) {
        free(planes);
        return tsd_fail_core(c->msg, c->msg_size, NULL, &err);
    }
    for (int k = 0; st == TS_OK && k < count; k += batch) {
        int n = count - k < batch ? count - k : batch;
        double az[TS_PYRAMID_BATCH];
        float *out[TS_PYRAMID_BATCH];
        for (int i = 0; i < n; i++) {
            az[i] = azimuths ? azimuths[k + i] : ts_horizon_azimuth(&h, k + i);
            out[i] = planes ? planes + cells * i : NULL;
        }
        if ((st = tsd_compute_report(c, (double)k / count)) != TS_OK)
            break;
        if ((sky ? ts_pyramid_horizons_sky(pyr, n, az, &h, sky, NULL, &err)
                 : ts_pyramid_horizons(pyr, n, az, &h, out, &err)) != TS_OK)
            st = tsd_fail_core(c->msg, c->msg_size, NULL, &err);
        for (int i = 0; st == TS_OK && !sky && i < n; i++)
            if (add(user, g, k + i, az[i], out[i], &err) != TS_OK)
                st = tsd_fail_core(c->msg, c->msg_size, NULL, &err);
    }
    ts_pyramid_free(pyr);
    free(planes);
    return st;
}

static ts_status copy_plane(void *user, const ts_grid *g, int k, double azimuth,
                            const float *plane, ts_error *err)
{
    (void)azimuth;
    (void)err;
    size_t cells = (size_t)g->width * g->height;
    memcpy((float *)user + cells * k, plane, cells * sizeof(float));
    return TS_OK;
}

ts_status tsd_pyramid_stream(const tsd_compute_ctx *c, const ts_grid *g, tsd_plane_fn add,
                             void *user)
{
    return pyramid_run(c, g, TS_PYRAMID_LEVEL_MAX, 0, NULL, NULL, add, user);
}

ts_status tsd_pyramid_sky(const tsd_compute_ctx *c, const ts_grid *g, const ts_pyramid_sky *sky)
{
    return pyramid_run(c, g, TS_PYRAMID_LEVEL_MAX, 0, NULL, sky, NULL, NULL);
}

ts_status tsd_pyramid_planes(const tsd_compute_ctx *c, const ts_grid *g, float *out)
{
    return pyramid_run(c, g, TS_PYRAMID_BSPLINE, 0, NULL, NULL, copy_plane, out);
}

static ts_status copy_to_planes(void *user, const ts_grid *g, int k, double azimuth,
                                const float *plane, ts_error *err)
{
    (void)azimuth;
    (void)err;
    memcpy(((float **)user)[k], plane, (size_t)g->width * g->height * sizeof(float));
    return TS_OK;
}

ts_status tsd_pyramid_planes_at(const tsd_compute_ctx *c, const ts_grid *g, int count,
                                const double *azimuths, float **planes)
{
    return pyramid_run(c, g, TS_PYRAMID_BSPLINE, count, azimuths, NULL, copy_to_planes, planes);
}
