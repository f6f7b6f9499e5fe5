/* The day products: the sun over a local day (tsd_sun), step by step. */
#include "tsd_compute.h"

#include "shadow_atlas.h"
#include "tsd_products.h"
#include "tsd_text.h"
#include "tsd_window.h"

#include <stdio.h>

/* The sun's day of a day product, or NULL with ctx->msg. */
static const tsd_sun *day_sun(const tsd_compute_ctx *c)
{
    if (!c->run->sun)
        tsd_fail(c->msg, c->msg_size, TS_ERR_INTERNAL,
                 "PRODUCT=%s needs the sun's day (internal error)",
                 tsd_options_product_name(c->opts));
    return c->run->sun;
}

/* A window's day sweep: raised to the far field beyond its near field
 * (ts_day_opts.plane_hook; tsd_window.h). */
static ts_status far_hook(void *user, const ts_grid *g, double azimuth, double sun_elevation,
                          float *plane, ts_error *err)
{
    const tsd_compute_ctx *c = user;
    ts_status st = tsd_compute_far_light(c, g, azimuth, sun_elevation, TS_SUN_RADIUS_DEG, plane);
    if (st != TS_OK) {
        err->code = st;
        snprintf(err->message, sizeof err->message, "%s", c->msg);
    }
    return st;
}

ts_day_opts tsd_compute_day_opts(const tsd_compute_ctx *c, const tsd_sun *sun)
{
    ts_day_opts day = sun->day;
    ts_horizon_opts h;
    tsd_compute_horizon_opts(c, &h);
    day.horizon.max_distance = h.max_distance;
    day.horizon.edge = h.edge;
    day.horizon.progress = c->run->progress;
    day.horizon.progress_user = c->run->progress_user;
    if (c->run->near_distance > 0) {
        day.table_heights_given = 1;
        day.table_height_min = TSD_DAY_TABLE_Z_MIN;
        day.table_height_max = TSD_DAY_TABLE_Z_MAX;
    }
    if (c->run->far) {
        day.plane_hook = far_hook;
        day.plane_hook_user = (void *)c;
    }
    return day;
}

ts_sun_sites tsd_compute_sun_sites(const tsd_sun *sun, const ts_grid *g)
{
    ts_sun_sites s = sun->sites;
    if (g->origin) { /* node (i, j) stays where it is on the whole DEM */
        s.x0 -= g->origin->x0;
        s.y0 -= g->origin->y0;
    }
    return s;
}

static ts_status done(const tsd_compute_ctx *c, ts_status st, const ts_error *err)
{
    return st == TS_OK ? TS_OK : tsd_fail_core(c->msg, c->msg_size, NULL, err);
}

/* The sun of a day product, with its day options and sun sites over
 * region r; NULL (an internal error) if the dataset has no sun. */
static const tsd_sun *day_setup(const tsd_compute_ctx *c, const tsd_region *r,
                                ts_day_opts *day, ts_sun_sites *sites)
{
    const tsd_sun *sun = day_sun(c);
    if (sun) {
        *day = tsd_compute_day_opts(c, sun);
        *sites = tsd_compute_sun_sites(sun, r->dem);
    }
    return sun;
}

/* sunhours and insolation: one day swept at each step, or a date range
 * (START_DATE) from horizons swept once (core/sun_range.c) */
TSD_COMPUTE_FN(tsd_compute_sunhours)
{
    (void)bytes;
    ts_day_opts day;
    ts_sun_sites sites;
    const tsd_sun *sun = day_setup(c, r, &day, &sites);
    ts_error err;
    if (!sun)
        return TS_ERR_INTERNAL;
    if (sun->is_range)
        return done(c, ts_sun_hours_range(r->dem, &sites, &day, &sun->range, out, &err),
                    &err);
    return done(c,
                ts_sun_hours(r->dem, &sites, &day, sun->day_start, sun->day_length,
                             tsd_options_step_minutes(c->opts) * 60.0, out, &err),
                &err);
}

TSD_COMPUTE_FN(tsd_compute_insolation)
{
    (void)bytes;
    size_t cells = (size_t)r->width * r->height;
    ts_day_opts day;
    ts_sun_sites sites;
    const tsd_sun *sun = day_setup(c, r, &day, &sites);
    ts_error err;
    if (!sun)
        return TS_ERR_INTERNAL;
    if (sun->is_range)
        return done(c,
                    ts_insolation_range(r->dem, &sites, &day, &sun->range, out,
                                        out + cells, out + 2 * cells, &err),
                    &err);
    return done(c,
                ts_insolation(r->dem, &sites, &day, sun->day_start, sun->day_length,
                              tsd_options_step_minutes(c->opts) * 60.0, out, out + cells,
                              out + 2 * cells, &err),
                &err);
}

/* One band per time step of the sun's day: step(k) fills band k. */
typedef ts_status (*step_fn)(const tsd_compute_ctx *c, const tsd_region *r, const tsd_sun *sun,
                             int k, size_t offset, float *out, uint8_t *bytes, ts_error *err);

static ts_status each_step(const tsd_compute_ctx *c, const tsd_region *r, step_fn step,
                           float *out, uint8_t *bytes)
{
    const tsd_sun *sun = day_sun(c);
    size_t cells = (size_t)r->width * r->height;
    ts_error err;
    ts_status st;
    if (!sun)
        return TS_ERR_INTERNAL;
    for (int k = 0; k < sun->steps; k++) {
        if ((st = tsd_compute_report(c, (double)k / sun->steps)) != TS_OK)
            return st;
        if ((st = step(c, r, sun, k, (size_t)k * cells, out, bytes, &err)) != TS_OK)
            return done(c, st, &err);
    }
    return TS_OK;
}

/* farshadow: the far shadows of the sun at step k */
static ts_status far_shadow_step(const tsd_compute_ctx *c, const tsd_region *r,
                                 const tsd_sun *sun, int k, size_t offset, float *out,
                                 uint8_t *bytes, ts_error *err)
{
    (void)c;
    (void)out;
    return ts_far_shadow(r->dem, sun->samples[k].grid_azimuth, sun->samples[k].elevation,
                         sun->threshold_m, &sun->day.horizon, bytes + offset, err);
}

TSD_COMPUTE_FN(tsd_compute_daycycle)
{
    /* every step at once, so that a lattice's planes serve them all */
    (void)bytes;
    ts_day_opts day;
    ts_sun_sites sites;
    const tsd_sun *sun = day_setup(c, r, &day, &sites);
    ts_error err;
    if (!sun)
        return TS_ERR_INTERNAL;
    return done(c, ts_sun_visibility_steps(r->dem, &sites, &day, sun->times, sun->steps, out,
                                           &err),
                &err);
}

TSD_COMPUTE_FN(tsd_compute_farshadow)
{
    return each_step(c, r, far_shadow_step, out, bytes);
}
