/* The products' SH methods; see tsd_compute_sh.h. */
#include "tsd_compute_sh.h"

#include "terrashade_sh.h"
#include "tsd_compute_env.h"
#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static ts_status core_fail(const tsd_compute_ctx *c, const ts_error *err)
{
    return tsd_fail_core(c->msg, c->msg_size, NULL, err);
}

/* The SH part runs in C: say so in the backend summary when the sweeps'
 * backend was not chosen as C (as the other C-only steps do). */
static void note_c_part(const tsd_compute_ctx *c, const char *what)
{
    ts_backend_report r;
    ts_error err;
    if (!c->backend || !c->backend->calls || c->backend->requested == TS_BACKEND_C ||
        ts_backend_choose(TS_BACKEND_C, &r, &err) != TS_OK)
        return;
    r.requested = c->backend->requested;
    snprintf(r.reason, sizeof r.reason,
             "%s: the SH visibility and lighting have no OpenCL kernel and run in C", what);
    tsd_backend_summary_add(c->backend, &r);
}

/* The key light of METHOD=sh and its visibility. */
typedef struct {
    ts_sh_wedges w;
    ts_sh_visibility v;
    double l[TS_SH_COEFFS];
    double scale_shade, scale_share; /* the normalisers with the disk's share above 0 */
} key_light;

static void key_free(key_light *k)
{
    ts_sh_visibility_free(&k->v);
    ts_sh_wedges_free(&k->w);
}

/* The light, its swath's wedge tables, and the visibility from its sweeps. */
static ts_status key_visibility(const tsd_compute_ctx *c, const ts_grid *g, key_light *k)
{
    const tsd_options *o = c->opts;
    const double az = c->run->sun_azimuth, el = c->run->sun_elevation, r = o->light_radius;
    ts_sh_swath s;
    ts_horizon_opts h;
    ts_error err;
    ts_status st;
    memset(k, 0, sizeof *k);
    ts_sh_swath_key(&s, o->swath_directions, az, el, r);
    ts_sh_key_light(az, el, r, k->l);
    if ((st = ts_sh_wedges_build(&s, o->threads, &k->w, &err)) != TS_OK ||
        (st = ts_sh_visibility_init(&k->v, g, &k->w, &err)) != TS_OK)
        return core_fail(c, &err);
    double shade_ref, share_ref, above = ts_sh_disk_above(el, r);
    ts_sh_key_reference(&k->w, k->l, az, el, &shade_ref, &share_ref);
    k->scale_shade = above > 0 && shade_ref > 0 ? above / shade_ref : 0;
    k->scale_share = above > 0 && share_ref > 0 ? above / share_ref : 0;
    float *plane = malloc((size_t)g->width * g->height * sizeof(float));
    if (!plane)
        return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM, "out of memory for a horizon plane");
    tsd_compute_horizon_opts(c, &h);
    h.progress = NULL; /* reported here, per sweep */
    for (int i = 0; i < s.n; i++) {
        ts_backend_report rep = {0};
        if ((st = tsd_compute_report(c, (double)i / s.n)) != TS_OK)
            break;
        st = ts_backend_horizon_sweep(tsd_backend_to_ts(o->backend), g,
                                      ts_sh_swath_azimuth(&s, i), &h, plane, &rep, &err);
        if (c->backend && rep.backend[0])
            tsd_backend_summary_add(c->backend, &rep);
        if (st == TS_OK)
            st = ts_sh_visibility_add(&k->v, i, plane, &err);
        if (st != TS_OK) {
            st = core_fail(c, &err);
            break;
        }
    }
    free(plane);
    if (st == TS_OK && (st = ts_sh_visibility_finish(&k->v, &err)) != TS_OK)
        st = core_fail(c, &err);
    note_c_part(c, "METHOD=sh");
    return st;
}

ts_status tsd_sh_key_direct(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                            float *out)
{
    key_light k;
    ts_error err;
    double m[TS_SH_COEFFS][TS_SH_COEFFS];
    ts_status st = key_visibility(c, g, &k);
    if (st == TS_OK) {
        ts_sh_product_matrix(k.l, m);
        if ((st = ts_sh_shade(g, m, nm->nx, nm->ny, nm->nz, k.v.vis, k.scale_shade, out,
                              &err)) != TS_OK)
            st = core_fail(c, &err);
    }
    size_t cells = (size_t)g->width * g->height;
    for (size_t i = 0; st == TS_OK && i < cells; i++)
        if (out[i] > 1)
            out[i] = 1; /* as the exact max(0, N . L) */
    key_free(&k);
    return st;
}

ts_status tsd_sh_key_shadow(const tsd_compute_ctx *c, const ts_grid *g, float *out)
{
    key_light k;
    ts_error err;
    ts_status st = key_visibility(c, g, &k);
    if (st == TS_OK &&
        (st = ts_sh_visible_share(g, k.l, k.v.vis, k.scale_share, out, &err)) != TS_OK)
        st = core_fail(c, &err);
    key_free(&k);
    return st;
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
        if ((st = ts_sh_shade(g, m, nm->nx, nm->ny, nm->nz, v.vis, 1 / M_PI, out[k], &err)) !=
            TS_OK)
            st = core_fail(c, &err);
    }
    note_c_part(c, "ENV_METHOD=sh");
    ts_sh_visibility_free(&v);
    ts_sh_wedges_free(&w);
    return st;
}
