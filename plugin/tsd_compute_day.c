/* The day products: the sun over a local day (tsd_sun), step by step. */
#include "tsd_compute.h"

#include "shadow_atlas.h"
#include "tsd_products.h"
#include "tsd_text.h"

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

/* The core's day options, reporting the day's steps to the run's progress. */
static ts_day_opts day_opts(const tsd_compute_ctx *c, const tsd_sun *sun)
{
    ts_day_opts day = sun->day;
    day.horizon.progress = c->run->progress;
    day.horizon.progress_user = c->run->progress_user;
    return day;
}

static ts_status done(const tsd_compute_ctx *c, ts_status st, const ts_error *err)
{
    return st == TS_OK ? TS_OK : tsd_fail_core(c->msg, c->msg_size, NULL, err);
}

TSD_COMPUTE_FN(tsd_compute_sunhours)
{
    (void)bytes;
    const tsd_sun *sun = day_sun(c);
    ts_error err;
    if (!sun)
        return TS_ERR_INTERNAL;
    ts_day_opts day = day_opts(c, sun);
    return done(c,
                ts_sun_hours(r->dem, &sun->sites, &day, sun->day_start, sun->day_length,
                             c->opts->step_minutes * 60.0, out, &err),
                &err);
}

TSD_COMPUTE_FN(tsd_compute_insolation)
{
    (void)bytes;
    const tsd_sun *sun = day_sun(c);
    size_t cells = (size_t)r->width * r->height;
    ts_error err;
    if (!sun)
        return TS_ERR_INTERNAL;
    ts_day_opts day = day_opts(c, sun);
    return done(c,
                ts_insolation(r->dem, &sun->sites, &day, sun->day_start, sun->day_length,
                              c->opts->step_minutes * 60.0, out, out + cells,
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

/* daycycle: the visible fraction of the sun's disk at step k */
static ts_status visibility_step(const tsd_compute_ctx *c, const tsd_region *r,
                                 const tsd_sun *sun, int k, size_t offset, float *out,
                                 uint8_t *bytes, ts_error *err)
{
    (void)c;
    (void)bytes;
    return ts_sun_visibility(r->dem, &sun->sites, &sun->day, sun->times[k], out + offset,
                             NULL, NULL, NULL, err);
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
    return each_step(c, r, visibility_step, out, bytes);
}

TSD_COMPUTE_FN(tsd_compute_farshadow)
{
    return each_step(c, r, far_shadow_step, out, bytes);
}
