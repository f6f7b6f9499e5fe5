/* The products' SH methods; see tsd_compute_sh.h. */
#include "tsd_compute_sh.h"

#include "terrashade_sh.h"
#include "tsd_compute_env.h"
#include "tsd_pyramid.h"
#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static ts_status core_fail(const tsd_compute_ctx *c, const ts_error *err)
{
    return tsd_fail_core(c->msg, c->msg_size, NULL, err);
}

/* A step of the SH methods that runs in C, noted after the product's other
 * calls (tsd_backend_note_c). */
static void note_c_part(const tsd_compute_ctx *c, const char *what)
{
    char why[160];
    if (!c->backend || !c->backend->calls || c->backend->requested == TS_BACKEND_C)
        return;
    snprintf(why, sizeof why, "%s: the SH visibility and lighting have no OpenCL kernel and "
             "run in C", what);
    tsd_backend_note_c(c->backend, c->backend->requested, why);
}

/* HORIZON_METHOD=pyramid: the swath's horizons from the pyramid (B-spline). */
static ts_status pyramid_planes(const tsd_compute_ctx *c, const ts_grid *g,
                                const ts_sh_swath *s, float **planes)
{
    double *az = malloc((size_t)s->n * sizeof *az);
    if (!az)
        return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM, "out of memory for the swath");
    for (int i = 0; i < s->n; i++)
        az[i] = ts_sh_swath_azimuth(s, i);
    ts_status st = tsd_pyramid_planes_at(c, g, s->n, az, planes);
    free(az);
    return st;
}

/* The progress bar's part for the sweeps; the SH pass has the rest (from
 * a tenth of a run at SWATH_DIRECTIONS=3 to half at thousands). */
#define SWEEPS_SHARE 0.75

/* The key light of METHOD=sh: its swath's SWATH_DIRECTIONS horizons (sweeps
 * on the backend, or the pyramid's with HORIZON_METHOD=pyramid), all kept,
 * the first in the output, then one pass of ts_sh_swath_light into shade
 * (with the normals nm) or share (one of them NULL). */
static ts_status key_light(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                           float *shade, float *share)
{
    const tsd_options *o = c->opts;
    const double az = c->run->sun_azimuth, el = c->run->sun_elevation,
                 r = o->light_radius > TS_SH_KEY_RADIUS_MIN ? o->light_radius
                                                            : TS_SH_KEY_RADIUS_MIN;
    const size_t cells = (size_t)g->width * g->height;
    ts_sh_swath s;
    ts_sh_wedges w;
    ts_horizon_opts h;
    ts_error err;
    ts_status st;
    double l[TS_SH_COEFFS], shade_ref, share_ref, above = ts_sh_disk_above(el, r);
    ts_sh_swath_key(&s, o->swath_directions, az, el, r);
    ts_sh_key_light(az, el, r, l);
    if ((st = ts_sh_wedges_build(&s, o->threads, &w, &err)) != TS_OK)
        return core_fail(c, &err);
    ts_sh_key_reference(&w, l, az, el, &shade_ref, &share_ref);
    /* the first horizon plane is the output itself (ts_sh_swath_light reads
     * a cell's planes before it writes the cell): one fresh plane fewer, and
     * its page faults; on a GPU that takes the swath in one call
     * (tsd_compute_batch), the planes in one block instead, so that one
     * upload of the DEM and one launch serve them all */
    const int one_call = o->horizon_method != TSD_HORIZON_PYRAMID && s.n > 1 &&
                         tsd_compute_batch(c, cells, s.n) >= s.n;
    float **planes = calloc((size_t)s.n, sizeof *planes);
    /* (without the block's memory, plane by plane as on C) */
    float *block = one_call && planes ? malloc((size_t)s.n * cells * sizeof(float)) : NULL;
    if (planes)
        planes[0] = block ? block : shade ? shade : share;
    for (int i = 1; planes && i < s.n; i++)
        if (!(planes[i] = block ? block + (size_t)i * cells : malloc(cells * sizeof(float)))) {
            for (int j = 1; j < i; j++)
                free(planes[j]);
            free(planes);
            planes = NULL;
        }
    if (!planes) {
        ts_sh_wedges_free(&w);
        return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM,
                        "out of memory for the %d horizon planes of SWATH_DIRECTIONS", s.n);
    }
    tsd_compute_horizon_opts(c, &h);
    h.progress = NULL; /* reported here, per sweep */
    /* the wedge tables clamp every horizon at 0 deg (the sky ends at the
     * horizontal), so horizons at or below it are all the same here: the
     * sweep may skip the edge's raises that stay there */
    h.nonpositive_moot = 1;
    if (o->horizon_method == TSD_HORIZON_PYRAMID)
        st = pyramid_planes(c, g, &s, planes);
    double az_list[TSD_OPENCL_BATCH_MAX];
    const int per_call = block ? s.n : 1;
    for (int i = 0; o->horizon_method != TSD_HORIZON_PYRAMID && st == TS_OK && i < s.n;
         i += per_call) {
        ts_backend_report rep = {0};
        if ((st = tsd_compute_report(c, SWEEPS_SHARE * i / s.n)) != TS_OK)
            break;
        for (int k = 0; k < per_call; k++)
            az_list[k] = ts_sh_swath_azimuth(&s, i + k);
        /* (with the block, i is 0 and planes[0] the block) */
        st = ts_backend_horizon_sweeps(tsd_backend_to_ts(o->backend), g, az_list, per_call, &h,
                                       planes[i], &rep, &err);
        if (c->backend && rep.backend[0])
            tsd_backend_summary_add(c->backend, &rep);
        if (st != TS_OK)
            st = core_fail(c, &err);
        for (int k = 0; st == TS_OK && k < per_call; k++) /* a window's: raised to the far
                                                            * field and the DEM's edge */
            st = tsd_compute_far(c, g, az_list[k], 0, planes[i + k]);
    }
    ts_horizon_opts report; /* the SH pass's share of the bar, and a cancel */
    tsd_compute_horizon_opts(c, &report);
    if (st == TS_OK &&
        (st = ts_sh_swath_light_reported(
             g, &w, (const float *const *)planes, l, nm ? nm->nx : NULL, nm ? nm->ny : NULL,
             nm ? nm->nz : NULL, above > 0 && shade_ref > 0 ? above / shade_ref : 0, shade,
             above > 0 && share_ref > 0 ? above / share_ref : 0, share, &report, SWEEPS_SHARE,
             1.0, &err)) != TS_OK)
        st = core_fail(c, &err);
    note_c_part(c, "METHOD=sh");
    for (int i = 1; !block && i < s.n; i++)
        free(planes[i]);
    free(planes);
    free(block);
    ts_sh_wedges_free(&w);
    return st;
}

ts_status tsd_sh_key_direct(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                            float *out)
{
    ts_status st = key_light(c, g, nm, out, NULL);
    size_t cells = (size_t)g->width * g->height;
    for (size_t i = 0; st == TS_OK && i < cells; i++)
        if (out[i] > 1)
            out[i] = 1; /* as the exact max(0, N . L) */
    return st;
}

ts_status tsd_sh_key_shadow(const tsd_compute_ctx *c, const ts_grid *g, float *out)
{
    return key_light(c, g, NULL, NULL, out);
}

static ts_status env_add(void *user, const ts_grid *g, int k, double azimuth,
                         const float *plane, ts_error *err)
{
    (void)g;
    (void)azimuth; /* the swath's sample k is the sweep's azimuth k */
    return ts_sh_visibility_add(user, k, plane, err);
}

ts_status tsd_sh_env_light(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                           float *r, float *gr, float *b)
{
    const tsd_options *o = c->opts;
    ts_sh_swath s;
    ts_sh_wedges w;
    ts_sh_visibility v = {0};
    ts_error err;
    ts_status st;
    double light[3][TS_SH_COEFFS], m[TS_SH_COEFFS][TS_SH_COEFFS];
    float *out[3] = {r, gr, b};
    ts_sh_swath_complete(&s, o->directions, o->start_azimuth);
    if ((st = ts_sh_project_env(&c->run->env->env, light, &err)) != TS_OK ||
        (st = ts_sh_wedges_build(&s, o->threads, &w, &err)) != TS_OK)
        return core_fail(c, &err);
    if ((st = ts_sh_visibility_init(&v, g, &w, &err)) != TS_OK)
        st = core_fail(c, &err);
    else if ((st = tsd_compute_stream(c, g, env_add, &v)) == TS_OK &&
             (st = ts_sh_visibility_finish(&v, &err)) != TS_OK)
        st = core_fail(c, &err);
    for (int k = 0; st == TS_OK && k < 3; k++) {
        ts_sh_product_matrix(light[k], m);
        if ((st = ts_sh_shade(g, m, nm->nx, nm->ny, nm->nz, v.vis, 1 / M_PI, o->threads, out[k],
                              &err)) != TS_OK)
            st = core_fail(c, &err);
    }
    note_c_part(c, "ENV_METHOD=sh");
    ts_sh_visibility_free(&v);
    ts_sh_wedges_free(&w);
    return st;
}
