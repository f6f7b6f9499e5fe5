/*
 * The sun over a day: hours of sun and clear-sky irradiation, from the
 * sun's visibility at each step (sun_visibility.c). See day_cycle.h.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "day_cycle_internal.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

static ts_status day_steps(double start, double length, double step, double **mid,
                           double **dur, int *n, ts_error *err)
{
    *mid = *dur = NULL;
    *n = ts_day_step_count(length, step);
    if (*n < 1 || !isfinite(start))
        return ts_fail(err, TS_ERR_ARG,
                       "a day needs a finite start, a positive length and a positive "
                       "step (got %g s and %g s)", length, step);
    *mid = malloc((size_t)*n * sizeof **mid);
    *dur = malloc((size_t)*n * sizeof **dur);
    if (!*mid || !*dur) {
        free(*mid);
        free(*dur);
        *mid = *dur = NULL;
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate %d time steps", *n);
    }
    return ts_day_uniform_times(start, length, step, *mid, *dur, err);
}

/* The time steps of a day and the visibility context over them: what
 * ts_sun_hours and ts_insolation both start with. Nothing to free on
 * failure; day_end frees what it made. */
static ts_status day_begin(const ts_grid *grid, const ts_sun_sites *sites,
                           const ts_day_opts *o, double start, double length, double step,
                           double **mid, double **dur, int *n, ts_vis_ctx *c, ts_error *err)
{
    ts_status st = day_steps(start, length, step, mid, dur, n, err);
    if (st == TS_OK)
        st = ts_vis_init(c, grid, sites, o, 1, err);
    if (st != TS_OK) {
        free(*mid);
        free(*dur);
    }
    return st;
}

static void day_end(double *mid, double *dur, ts_vis_ctx *c)
{
    free(mid);
    free(dur);
    ts_vis_free(c);
}

ts_status ts_sun_hours(const ts_grid *grid, const ts_sun_sites *sites,
                       const ts_day_opts *o, double start_unix, double length_s,
                       double step_s, float *hours, ts_error *err)
{
    if (!hours)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_hours: the output is NULL");
    double *mid, *dur;
    int n;
    ts_vis_ctx c;
    ts_status st = day_begin(grid, sites, o, start_unix, length_s, step_s, &mid, &dur, &n,
                             &c, err);
    if (st != TS_OK)
        return st;
    float *vis = malloc(c.cells * sizeof(float));
    double *acc = calloc(c.cells, sizeof(double));
    if (!vis || !acc) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the sun-hour planes");
        goto done;
    }
    for (int k = 0; k < n; k++) {
        int dark;
        if ((st = ts_progress(&o->horizon, (double)k / n, err)) != TS_OK ||
            (st = ts_vis_step(&c, mid[k], vis, NULL, NULL, NULL, &dark, err)) != TS_OK)
            goto done;
        if (dark)
            continue;
        double hrs = dur[k] / 3600.0;
        if (o->sun_hours_rule == TS_SUN_HOURS_DISK_FRACTION)
            for (size_t i = 0; i < c.cells; i++)
                acc[i] += vis[i] * hrs;
        else
            for (size_t i = 0; i < c.cells; i++)
                acc[i] += vis[i] > 0.0f ? hrs : vis[i] == vis[i] ? 0.0 : NAN;
    }
    if ((st = ts_progress(&o->horizon, 1.0, err)) != TS_OK)
        goto done;
    for (int y = 0; y < c.H; y++)
        for (int x = 0; x < c.W; x++) {
            size_t i = (size_t)y * c.W + x;
            hours[i] = isnan(ts_grid_at(grid, x, y)) ? NAN : (float)acc[i];
        }
    st = ts_ok(err);
done:
    free(vis);
    free(acc);
    day_end(mid, dur, &c);
    return st;
}

ts_status ts_insolation(const ts_grid *grid, const ts_sun_sites *sites,
                        const ts_day_opts *o, double start_unix, double length_s,
                        double step_s, float *total, float *beam, float *diffuse,
                        ts_error *err)
{
    if (!total)
        return ts_fail(err, TS_ERR_ARG, "ts_insolation: the output is NULL");
    double *mid, *dur;
    int n;
    ts_vis_ctx c;
    ts_status st = day_begin(grid, sites, o, start_unix, length_s, step_s, &mid, &dur, &n,
                             &c, err);
    if (st != TS_OK)
        return st;
    size_t cells = c.cells;
    float *nx = malloc(cells * sizeof(float)), *ny = malloc(cells * sizeof(float));
    float *nz = malloc(cells * sizeof(float)), *sky = calloc(cells, sizeof(float));
    float *vis = malloc(cells * sizeof(float)), *pc = malloc(cells * sizeof(float));
    float *caz = NULL, *cel = NULL;
    double *accb = calloc(cells, sizeof(double)), *accd = calloc(cells, sizeof(double));
    int lattice = c.nodes > 1;
    if (lattice) {
        caz = malloc(cells * sizeof(float));
        cel = malloc(cells * sizeof(float));
    }
    if (!nx || !ny || !nz || !sky || !vis || !pc || !accb || !accd ||
        (lattice && (!caz || !cel))) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the insolation planes");
        goto done;
    }
    if ((st = ts_normals(grid, nx, ny, nz, err)) != TS_OK)
        goto done;
    /* Sky term: stream the horizon planes through the accumulator. Progress
     * counts its sweeps and then the time steps. */
    const int sweeps = o->horizon.directions < 1 ? 1 : o->horizon.directions;
    {
        ts_horizon_opts h = o->horizon;
        h.directions = sweeps;
        for (int k = 0; k < h.directions; k++) {
            double a = ts_horizon_azimuth(&h, k);
            if ((st = ts_progress(&o->horizon, (double)k / (sweeps + n), err)) !=
                    TS_OK ||
                (st = ts_day_sweep(grid, a, &h, o, NAN, c.pa, err)) != TS_OK ||
                (st = ts_sky_accumulate(grid, nx, ny, nz, c.pa, a, h.directions, NULL,
                                        sky, NULL, err)) != TS_OK)
                goto done;
        }
        if ((st = ts_sky_finish(grid, h.directions, NULL, sky, NULL, err)) != TS_OK)
            goto done;
    }
    for (int y = 0; y < c.H; y++)
        for (int x = 0; x < c.W; x++) {
            float h = ts_grid_at(grid, x, y);
            pc[(size_t)y * c.W + x] = isnan(h) ? NAN : (float)exp(-h / 8434.5);
        }
    const double tl = o->linke_turbidity;
    for (int k = 0; k < n; k++) {
        int dark;
        ts_sun_sample ref;
        if ((st = ts_progress(&o->horizon, (double)(sweeps + k) / (sweeps + n), err)) !=
                TS_OK ||
            (st = ts_vis_step(&c, mid[k], vis, caz, cel, &ref, &dark, err)) != TS_OK)
            goto done;
        double hrs = dur[k] / 3600.0;
        double g0 = TS_SOLAR_CONSTANT / (ref.distance_au * ref.distance_au);
        if (!lattice) {
            double e = ref.elevation;
            if (!(e > 0))
                continue;
            double m0 = ts_esra_air_mass(e), sh = sin(e * DEG2RAD);
            double dh = g0 * ts_esra_diffuse_factor(tl, sh) * hrs;
            double a = ref.grid_azimuth * DEG2RAD, ce = cos(e * DEG2RAD);
            double lx = sin(a) * ce, ly = cos(a) * ce, lz = sh;
            for (size_t i = 0; i < cells; i++) {
                if (isnan(pc[i]))
                    continue;
                accd[i] += dh * sky[i];
                if (!dark && isnan(vis[i])) /* EDGE=nodata */
                    accb[i] = NAN;
                if (dark || !(vis[i] > 0))
                    continue;
                double cosi = nx[i] * lx + ny[i] * ly + nz[i] * lz;
                if (cosi <= 0)
                    continue;
                double bn = g0 * ts_esra_beam_transmittance(pc[i] * m0, tl);
                accb[i] += bn * cosi * vis[i] * hrs;
            }
        } else {
            for (size_t i = 0; i < cells; i++) {
                double e = cel[i];
                if (isnan(pc[i]) || !(e > 0))
                    continue;
                double sh = sin(e * DEG2RAD);
                accd[i] += g0 * ts_esra_diffuse_factor(tl, sh) * hrs * sky[i];
                if (!dark && isnan(vis[i])) /* EDGE=nodata */
                    accb[i] = NAN;
                if (dark || !(vis[i] > 0))
                    continue;
                double a = caz[i] * DEG2RAD, ce = cos(e * DEG2RAD);
                double cosi = nx[i] * sin(a) * ce + ny[i] * cos(a) * ce + nz[i] * sh;
                if (cosi <= 0)
                    continue;
                double bn = g0 * ts_esra_beam_transmittance(pc[i] * ts_esra_air_mass(e), tl);
                accb[i] += bn * cosi * vis[i] * hrs;
            }
        }
    }
    if ((st = ts_progress(&o->horizon, 1.0, err)) != TS_OK)
        goto done;
    for (size_t i = 0; i < cells; i++) {
        int nd = isnan(pc[i]) || isnan(accb[i] + accd[i]); /* EDGE=nodata: all bands */
        total[i] = nd ? NAN : (float)(accb[i] + accd[i]);
        if (beam)
            beam[i] = nd ? NAN : (float)accb[i];
        if (diffuse)
            diffuse[i] = nd ? NAN : (float)accd[i];
    }
    st = ts_ok(err);
done:
    free(nx);
    free(ny);
    free(nz);
    free(sky);
    free(vis);
    free(pc);
    free(caz);
    free(cel);
    free(accb);
    free(accd);
    day_end(mid, dur, &c);
    return st;
}

