/*
 * The sun over a day: per-cell sun visibility, hours of sun and clear-sky
 * irradiation. See day_cycle.h.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "day_cycle_internal.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)
/* Largest azimuth gap between the sweeps of a lattice, degrees. */
#define LATTICE_AZ_STEP 1.0

/* ---------------------------------------------------- sun on the grid */

ts_status ts_day_sweep(const ts_grid *g, double azimuth, const ts_horizon_opts *h,
                       const ts_day_opts *o, double sun_elevation, float *plane,
                       ts_error *err)
{
    ts_status st = ts_horizon_sweep(g, azimuth, h, plane, err);
    if (st == TS_OK && o->plane_hook)
        st = o->plane_hook(o->plane_hook_user, g, azimuth, sun_elevation, plane, err);
    return st;
}

/* What stays the same from one instant to the next. */
typedef struct {
    const ts_grid *g;
    const ts_sun_sites *s;
    const ts_day_opts *o;
    int W, H, nodes;
    size_t cells;
    float *floor;       /* Earth horizon per cell, or NULL (terrain only) */
    double floor_min;   /* the lowest horizon any cell can have */
    float *pa, *pb;     /* horizon planes */
    float *cel, *caz;   /* lattice: per-cell elevation and azimuth offset */
    ts_sun_sample *ns;  /* per-node sun */
} vis_ctx;

static void vis_free(vis_ctx *c)
{
    free(c->floor);
    free(c->pa);
    free(c->pb);
    free(c->cel);
    free(c->caz);
    free(c->ns);
    memset(c, 0, sizeof *c);
}

static ts_status vis_init(vis_ctx *c, const ts_grid *g, const ts_sun_sites *s,
                          const ts_day_opts *o, ts_error *err)
{
    memset(c, 0, sizeof *c);
    ts_status st = ts_grid_validate(g, err);
    if (st != TS_OK)
        return st;
    if ((st = ts_sun_sites_validate(s, err)) != TS_OK)
        return st;
    if ((st = ts_day_opts_check(o, err)) != TS_OK)
        return st;
    c->g = g;
    c->s = s;
    c->o = o;
    c->W = g->width;
    c->H = g->height;
    c->cells = (size_t)g->width * g->height;
    c->nodes = s->nx * s->ny;
    int lattice = c->nodes > 1;
    c->pa = malloc(c->cells * sizeof(float));
    c->pb = lattice ? malloc(c->cells * sizeof(float)) : NULL;
    c->cel = lattice ? malloc(c->cells * sizeof(float)) : NULL;
    c->caz = lattice ? malloc(c->cells * sizeof(float)) : NULL;
    c->ns = malloc((size_t)c->nodes * sizeof *c->ns);
    c->floor = o->earth_horizon ? malloc(c->cells * sizeof(float)) : NULL;
    if (!c->pa || !c->ns || (lattice && (!c->pb || !c->cel || !c->caz)) ||
        (o->earth_horizon && !c->floor)) {
        vis_free(c);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the sun's work planes");
    }
    c->floor_min = c->floor ? ts_day_earth_floor(g, &o->horizon, c->floor) : -90.0;
    return TS_OK;
}

/* Bilinear weights of pixel coordinate p on a lattice axis. */
static void axis_weight(double p, double p0, double dp, int n, int *i, double *f)
{
    if (n < 2) {
        *i = 0;
        *f = 0;
        return;
    }
    double u = (p - p0) / dp;
    if (u <= 0) {
        *i = 0;
        *f = 0;
    } else if (u >= n - 1) {
        *i = n - 2;
        *f = 1;
    } else {
        *i = (int)u;
        if (*i > n - 2)
            *i = n - 2;
        *f = u - *i;
    }
}

static inline float cell_vis(double e, float h, float fl)
{
    if (isnan(h))
        return NAN;
    if (!isnan(fl) && fl > h)
        h = fl;
    return (float)ts_sun_disk_fraction(e, h);
}

/* The azimuths of a lattice's suns, as offsets lo..hi from a_ref, and
 * their highest elevation. */
static void lattice_span(const ts_sun_sample *ns, int nodes, double a_ref, double *lo,
                         double *hi, double *emax)
{
    *lo = INFINITY;
    *hi = *emax = -INFINITY;
    for (int i = 0; i < nodes; i++) {
        double d = ts_wrap180(ns[i].grid_azimuth - a_ref);
        *lo = fmin(*lo, d);
        *hi = fmax(*hi, d);
        *emax = fmax(*emax, ns[i].elevation);
    }
}

/* Sweeps across a lattice's azimuths lo..hi: LATTICE_AZ_STEP apart or less. */
static int lattice_sweeps(double lo, double hi)
{
    double span = hi - lo;
    return span < 1e-9 ? 1 : (int)ceil(span / LATTICE_AZ_STEP) + 1;
}

int ts_sun_visibility_sweeps(const ts_sun_sites *sites, const ts_day_opts *o,
                             double unix_time)
{
    ts_error err;
    int nodes = sites->nx * sites->ny;
    if (nodes == 1)
        return 1;
    ts_sun_sample *ns = malloc((size_t)nodes * sizeof *ns);
    int K = -1;
    for (int i = 0; ns && i < nodes; i++)
        if (ts_day_node_sun(sites, o, i, unix_time, &ns[i], &err) != TS_OK)
            goto done;
    if (ns) {
        double lo, hi, emax;
        lattice_span(ns, nodes, ns[ts_day_ref_node(sites)].grid_azimuth, &lo, &hi, &emax);
        K = lattice_sweeps(lo, hi);
    }
done:
    free(ns);
    return K;
}

/*
 * Visibility at instant t into vis; az/el (may be NULL) per cell. Returns
 * *dark = 1 when the sun is below every cell's horizon (vis = 0 for valid
 * cells), so callers may skip the step.
 */
static ts_status vis_step(vis_ctx *c, double t, float *vis, float *az, float *el,
                          ts_sun_sample *ref, int *dark, ts_error *err)
{
    const ts_grid *g = c->g;
    const ts_sun_sites *s = c->s;
    ts_status st;
    for (int i = 0; i < c->nodes; i++)
        if ((st = ts_day_node_sun(s, c->o, i, t, &c->ns[i], err)) != TS_OK)
            return st;
    const ts_sun_sample *r = &c->ns[ts_day_ref_node(s)];
    if (ref)
        *ref = *r;
    const double rad = TS_SUN_RADIUS_DEG;
    const int W = c->W, H = c->H;
    ts_horizon_opts ho = c->o->horizon;
    ho.directions = 1;
    *dark = 0;

    if (c->nodes == 1) {
        double e = r->elevation, a = r->grid_azimuth;
        if (az || el)
            for (size_t i = 0; i < c->cells; i++) {
                if (az) az[i] = (float)a;
                if (el) el[i] = (float)e;
            }
        if (e + rad <= c->floor_min) {
            *dark = 1;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++)
                    vis[(size_t)y * W + x] = isnan(ts_grid_at(g, x, y)) ? NAN : 0.0f;
            return TS_OK;
        }
        if ((st = ts_day_sweep(g, a, &ho, c->o, e, c->pa, err)) != TS_OK)
            return st;
        for (size_t i = 0; i < c->cells; i++)
            vis[i] = cell_vis(e, c->pa[i], c->floor ? c->floor[i] : NAN);
        return TS_OK;
    }

    /* Lattice: azimuths as offsets from the reference node's. */
    double a_ref = r->grid_azimuth, lo, hi, emax;
    lattice_span(c->ns, c->nodes, a_ref, &lo, &hi, &emax);
    for (int y = 0; y < H; y++) {
        int j;
        double fy;
        axis_weight(y + 0.5, s->y0, s->dy, s->ny, &j, &fy);
        for (int x = 0; x < W; x++) {
            int i;
            double fx;
            axis_weight(x + 0.5, s->x0, s->dx, s->nx, &i, &fx);
            int i1 = s->nx > 1 ? i + 1 : i, j1 = s->ny > 1 ? j + 1 : j;
            const ts_sun_sample *n00 = &c->ns[j * s->nx + i], *n10 = &c->ns[j * s->nx + i1],
                                *n01 = &c->ns[j1 * s->nx + i], *n11 = &c->ns[j1 * s->nx + i1];
            double w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy,
                   w11 = fx * fy;
            /* refracted after: the refraction jumps at its cut-off, which
             * a lattice of sunrise and sunset straddles */
            double e0 = w00 * n00->true_elevation + w10 * n10->true_elevation +
                        w01 * n01->true_elevation + w11 * n11->true_elevation;
            double e = e0 + ts_sun_refraction(e0, &c->o->sun);
            double d = w00 * ts_wrap180(n00->grid_azimuth - a_ref) +
                       w10 * ts_wrap180(n10->grid_azimuth - a_ref) +
                       w01 * ts_wrap180(n01->grid_azimuth - a_ref) +
                       w11 * ts_wrap180(n11->grid_azimuth - a_ref);
            size_t k = (size_t)y * W + x;
            c->cel[k] = (float)e;
            c->caz[k] = (float)d;
            if (el) el[k] = (float)e;
            if (az) az[k] = (float)ts_wrap360(a_ref + d);
        }
    }
    if (emax + rad <= c->floor_min) {
        *dark = 1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                vis[(size_t)y * W + x] = isnan(ts_grid_at(g, x, y)) ? NAN : 0.0f;
        return TS_OK;
    }
    const int K = lattice_sweeps(lo, hi);
    double step = K > 1 ? (hi - lo) / (K - 1) : 0.0;
    if ((st = ts_day_sweep(g, a_ref + lo, &ho, c->o, NAN, c->pa, err)) != TS_OK)
        return st;
    if (K == 1) {
        for (size_t i = 0; i < c->cells; i++)
            vis[i] = cell_vis(c->cel[i], c->pa[i], c->floor ? c->floor[i] : NAN);
        return TS_OK;
    }
    for (int j = 1; j < K; j++) {
        if ((st = ts_day_sweep(g, a_ref + lo + j * step, &ho, c->o, NAN, c->pb,
                                    err)) != TS_OK)
            return st;
        for (size_t i = 0; i < c->cells; i++) {
            double u = (c->caz[i] - lo) / step;
            int b = (int)floor(u);
            if (b < 0) b = 0;
            if (b > K - 2) b = K - 2;
            if (b != j - 1)
                continue;
            float f = (float)(u - b);
            if (f < 0) f = 0;
            if (f > 1) f = 1;
            float h = c->pa[i] + f * (c->pb[i] - c->pa[i]);
            vis[i] = cell_vis(c->cel[i], h, c->floor ? c->floor[i] : NAN);
        }
        float *t = c->pa;
        c->pa = c->pb;
        c->pb = t;
    }
    return TS_OK;
}

ts_status ts_sun_visibility(const ts_grid *grid, const ts_sun_sites *sites,
                            const ts_day_opts *o, double unix_time, float *vis,
                            float *az, float *el, ts_sun_sample *ref, ts_error *err)
{
    if (!vis)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_visibility: the output is NULL");
    if (!isfinite(unix_time))
        return ts_fail(err, TS_ERR_ARG, "the instant must be finite");
    vis_ctx c;
    ts_status st = vis_init(&c, grid, sites, o, err);
    if (st != TS_OK)
        return st;
    int dark;
    st = vis_step(&c, unix_time, vis, az, el, ref, &dark, err);
    vis_free(&c);
    return st == TS_OK ? ts_ok(err) : st;
}

/* Uniform steps of a day, allocated. */
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
                           double **mid, double **dur, int *n, vis_ctx *c, ts_error *err)
{
    ts_status st = day_steps(start, length, step, mid, dur, n, err);
    if (st == TS_OK)
        st = vis_init(c, grid, sites, o, err);
    if (st != TS_OK) {
        free(*mid);
        free(*dur);
    }
    return st;
}

static void day_end(double *mid, double *dur, vis_ctx *c)
{
    free(mid);
    free(dur);
    vis_free(c);
}

ts_status ts_sun_hours(const ts_grid *grid, const ts_sun_sites *sites,
                       const ts_day_opts *o, double start_unix, double length_s,
                       double step_s, float *hours, ts_error *err)
{
    if (!hours)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_hours: the output is NULL");
    double *mid, *dur;
    int n;
    vis_ctx c;
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
            (st = vis_step(&c, mid[k], vis, NULL, NULL, NULL, &dark, err)) != TS_OK)
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
    vis_ctx c;
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
            (st = vis_step(&c, mid[k], vis, caz, cel, &ref, &dark, err)) != TS_OK)
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

