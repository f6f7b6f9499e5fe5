/*
 * The sun over a day: dates and offsets, sampling times, per-cell sun
 * visibility, hours of sun and clear-sky irradiation. See day_cycle.h.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)
/* Sample the sun's track for the atlas every this many seconds. */
#define ATLAS_SCAN_S 60.0
/* Largest azimuth gap between the sweeps of a lattice, degrees. */
#define LATTICE_AZ_STEP 1.0

/* ------------------------------------------------------- dates, offsets */

static int digits(const char *s, int n, int *v)
{
    int x = 0;
    for (int i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return 0;
        x = x * 10 + (s[i] - '0');
    }
    *v = x;
    return 1;
}

ts_status ts_parse_date(const char *s, int *year, int *month, int *day,
                        ts_error *err)
{
    if (!s || !year || !month || !day)
        return ts_fail(err, TS_ERR_ARG, "ts_parse_date: NULL argument");
    int y, m, d;
    if (strlen(s) != 10 || !digits(s, 4, &y) || s[4] != '-' || !digits(s + 5, 2, &m) ||
        s[7] != '-' || !digits(s + 8, 2, &d))
        return ts_fail(err, TS_ERR_ARG,
                       "Cannot read '%.64s' as a date: expected YYYY-MM-DD, e.g. "
                       "2026-06-21.", s);
    if (m < 1 || m > 12)
        return ts_fail(err, TS_ERR_ARG,
                       "Cannot read '%.64s' as a date: month %d does not exist "
                       "(1..12).", s, m);
    int dim = ts_days_in_month(y, m);
    if (d < 1 || d > dim)
        return ts_fail(err, TS_ERR_ARG,
                       "Cannot read '%.64s' as a date: %04d-%02d has %d days, "
                       "there is no day %d.", s, y, m, dim, d);
    *year = y;
    *month = m;
    *day = d;
    return ts_ok(err);
}

ts_status ts_parse_utc_offset(const char *s, int *minutes, ts_error *err)
{
    if (!s || !minutes)
        return ts_fail(err, TS_ERR_ARG, "ts_parse_utc_offset: NULL argument");
    if (strcmp(s, "Z") == 0 || strcmp(s, "z") == 0 || strcmp(s, "UTC") == 0 ||
        strcmp(s, "utc") == 0) {
        *minutes = 0;
        return ts_ok(err);
    }
    int h = 0, m = 0, ok = 0;
    size_t n = strlen(s);
    if ((s[0] == '+' || s[0] == '-') && digits(s + 1, 2, &h)) {
        if (n == 3)
            ok = 1;
        else if (n == 6 && s[3] == ':' && digits(s + 4, 2, &m))
            ok = 1;
        else if (n == 5 && digits(s + 3, 2, &m))
            ok = 1;
    }
    if (!ok)
        return ts_fail(err, TS_ERR_ARG,
                       "Cannot read '%.64s' as an offset from UTC: expected Z or "
                       "+hh:mm / -hh:mm, e.g. +02:00 (named time zones are not "
                       "supported: give the offset that applies on the day).", s);
    if (h > 23 || m > 59)
        return ts_fail(err, TS_ERR_ARG,
                       "The offset from UTC '%.64s' is out of range (at most "
                       "23:59).", s);
    *minutes = (s[0] == '-' ? -1 : 1) * (h * 60 + m);
    return ts_ok(err);
}

double ts_local_midnight(int year, int month, int day, int offset_minutes)
{
    return (double)ts_days_from_civil(year, month, day) * 86400.0 -
           offset_minutes * 60.0;
}

double ts_local_day_start(double unix_time, int offset_minutes)
{
    double local = unix_time + offset_minutes * 60.0;
    return floor(local / 86400.0) * 86400.0 - offset_minutes * 60.0;
}

/* ------------------------------------------------------------ options */

void ts_day_opts_default(ts_day_opts *o)
{
    memset(o, 0, sizeof *o);
    ts_horizon_opts_default(&o->horizon);
    ts_sun_input_default(&o->sun);
    o->linke_turbidity = 3.0;
    o->earth_horizon = 1;
    o->sun_hours_rule = TS_SUN_HOURS_VISIBLE;
}

ts_status ts_sun_sites_validate(const ts_sun_sites *s, ts_error *err)
{
    if (!s)
        return ts_fail(err, TS_ERR_ARG, "the sun sites are NULL");
    if (s->nx < 1 || s->ny < 1 || s->nx > 100000 || s->ny > 100000)
        return ts_fail(err, TS_ERR_ARG, "the lattice of sun sites must have 1 to "
                       "100000 nodes along each axis, got %d x %d", s->nx, s->ny);
    if (!s->longitude || !s->latitude)
        return ts_fail(err, TS_ERR_ARG, "the sun sites have no coordinates");
    if ((s->nx > 1 && !(s->dx > 0)) || (s->ny > 1 && !(s->dy > 0)) ||
        !isfinite(s->x0) || !isfinite(s->y0))
        return ts_fail(err, TS_ERR_ARG, "the lattice of sun sites needs a finite "
                       "origin and a positive spacing");
    for (int i = 0; i < s->nx * s->ny; i++) {
        double lat = s->latitude[i], lon = s->longitude[i];
        if (!isfinite(lat) || lat < -90.0 || lat > 90.0)
            return ts_fail(err, TS_ERR_ARG,
                           "latitude %g is beyond +/-90 degrees: the DEM's "
                           "georeferencing does not describe a place on Earth", lat);
        if (!isfinite(lon) || lon < -180.0 || lon > 180.0)
            return ts_fail(err, TS_ERR_ARG,
                           "longitude %g is not within -180..180 degrees", lon);
        if (s->north_azimuth && !isfinite(s->north_azimuth[i]))
            return ts_fail(err, TS_ERR_ARG, "the grid azimuth of true north is not "
                           "finite at a sun site");
    }
    return ts_ok(err);
}

static ts_status opts_validate(const ts_day_opts *o, ts_error *err)
{
    if (!o)
        return ts_fail(err, TS_ERR_ARG, "the day options are NULL");
    ts_horizon_opts h = o->horizon;
    if (h.directions < 1)
        h.directions = 1;
    ts_status st = ts_horizon_opts_validate(&h, err);
    if (st != TS_OK)
        return st;
    if (!(o->linke_turbidity >= 1.0 && o->linke_turbidity <= 10.0))
        return ts_fail(err, TS_ERR_ARG,
                       "the Linke turbidity must be between 1 and 10, got %g",
                       o->linke_turbidity);
    if (o->sun_hours_rule != TS_SUN_HOURS_VISIBLE &&
        o->sun_hours_rule != TS_SUN_HOURS_DISK_FRACTION)
        return ts_fail(err, TS_ERR_ARG,
                       "unknown sun-hours rule %d (visible or disk fraction)",
                       (int)o->sun_hours_rule);
    return ts_ok(err);
}

double ts_earth_horizon(double height_m, const ts_horizon_opts *o)
{
    if (!o || !o->curvature || !(height_m > 0))
        return 0.0;
    double k = o->refraction;
    if (k >= 1.0)
        return 0.0;
    double r = TS_EARTH_RADIUS / (1.0 - k);
    return -acos(r / (r + height_m)) * RAD2DEG;
}

static double wrap360(double a)
{
    a = fmod(a, 360.0);
    if (a < 0)
        a += 360.0;
    if (a >= 360.0)
        a -= 360.0;
    return a;
}

static double wrap180(double a)
{
    a = wrap360(a);
    return a > 180.0 ? a - 360.0 : a;
}

/* SPA at node i. */
static ts_status node_sun(const ts_sun_sites *s, const ts_day_opts *o, int i,
                          double t, ts_sun_sample *out, ts_error *err)
{
    ts_sun_input in = o->sun;
    ts_sun_output sun;
    ts_sun_detail det;
    in.jd = ts_julian_day_from_unix(t);
    in.longitude = s->longitude[i];
    in.latitude = s->latitude[i];
    ts_status st = ts_sun_position_detail(&in, &sun, &det, err);
    if (st != TS_OK)
        return st;
    out->unix_time = t;
    out->azimuth = sun.azimuth;
    out->elevation = sun.elevation;
    out->grid_azimuth = wrap360(sun.azimuth + (s->north_azimuth ? s->north_azimuth[i] : 0.0));
    out->distance_au = det.R;
    return TS_OK;
}

static int ref_node(const ts_sun_sites *s)
{
    return (s->ny / 2) * s->nx + s->nx / 2;
}

ts_status ts_sun_at_site(const ts_sun_sites *sites, const ts_day_opts *o,
                         double unix_time, ts_sun_sample *out, ts_error *err)
{
    ts_status st = ts_sun_sites_validate(sites, err);
    if (st != TS_OK)
        return st;
    if (!o || !out)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_at_site: NULL argument");
    if ((st = node_sun(sites, o, ref_node(sites), unix_time, out, err)) != TS_OK)
        return st;
    return ts_ok(err);
}

/* ------------------------------------------------------- sampling times */

int ts_day_step_count(double length_s, double step_s)
{
    if (!(length_s > 0) || !(step_s > 0))
        return 0;
    double n = ceil(length_s / step_s - 1e-9);
    return n > 1e7 ? 0 : (int)n;
}

ts_status ts_day_uniform_times(double start_unix, double length_s, double step_s,
                               double *mid, double *dur, ts_error *err)
{
    int n = ts_day_step_count(length_s, step_s);
    if (n < 1 || !isfinite(start_unix))
        return ts_fail(err, TS_ERR_ARG,
                       "a day needs a finite start, a positive length and a positive "
                       "step (got %g s and %g s)", length_s, step_s);
    if (!mid || !dur)
        return ts_fail(err, TS_ERR_ARG, "ts_day_uniform_times: NULL output");
    double end = start_unix + length_s;
    for (int i = 0; i < n; i++) {
        double a = start_unix + i * step_s;
        double b = i == n - 1 ? end : fmin(start_unix + (i + 1) * step_s, end);
        mid[i] = 0.5 * (a + b);
        dur[i] = b - a;
    }
    return ts_ok(err);
}

ts_status ts_day_atlas_times(const ts_sun_sites *sites, const ts_day_opts *o,
                             double start_unix, double length_s, int n,
                             double *times, int *n_out, ts_error *err)
{
    ts_status st = ts_sun_sites_validate(sites, err);
    if (st != TS_OK)
        return st;
    if (!o || !times || !n_out || n < 1 || !(length_s > 0) || !isfinite(start_unix))
        return ts_fail(err, TS_ERR_ARG,
                       "ts_day_atlas_times needs options, an output, n >= 1 and a "
                       "positive day length");
    *n_out = 0;
    int m = (int)ceil(length_s / ATLAS_SCAN_S);
    double dt = length_s / m;
    double *c = malloc((size_t)(m + 1) * sizeof *c);
    double *w = malloc((size_t)(m + 1) * sizeof *w);
    if (!c || !w) {
        free(c);
        free(w);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the sun's track");
    }
    const double wmax = 1.0 / sin(2.0 * DEG2RAD);
    int node = ref_node(sites);
    for (int k = 0; k <= m; k++) {
        ts_sun_sample s;
        if ((st = node_sun(sites, o, node, start_unix + k * dt, &s, err)) != TS_OK) {
            free(c);
            free(w);
            return st;
        }
        double e = s.elevation;
        w[k] = e > -TS_SUN_RADIUS_DEG ? fmin(wmax, 1.0 / sin(fmax(e, 2.0) * DEG2RAD)) : 0.0;
    }
    c[0] = 0;
    for (int k = 0; k < m; k++)
        c[k + 1] = c[k] + 0.5 * (w[k] + w[k + 1]) * dt;
    double total = c[m];
    if (total > 0) {
        int k = 0;
        for (int i = 0; i < n; i++) {
            double target = (i + 0.5) / n * total;
            while (k < m - 1 && c[k + 1] <= target)
                k++;
            double span = c[k + 1] - c[k];
            double f = span > 0 ? (target - c[k]) / span : 0.5;
            times[i] = start_unix + (k + f) * dt;
        }
        *n_out = n;
    }
    free(c);
    free(w);
    return ts_ok(err);
}

/* ---------------------------------------------------- sun on the grid */

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
    if ((st = opts_validate(o, err)) != TS_OK)
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
    c->floor_min = -90.0;
    if (c->floor) {
        double lo = 0.0;
        for (int y = 0; y < c->H; y++)
            for (int x = 0; x < c->W; x++) {
                float h = ts_grid_at(g, x, y);
                float f = isnan(h) ? NAN : (float)ts_earth_horizon(h, &o->horizon);
                c->floor[(size_t)y * c->W + x] = f;
                if (f < lo)
                    lo = f;
            }
        c->floor_min = lo;
    }
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
        if ((st = node_sun(s, c->o, i, t, &c->ns[i], err)) != TS_OK)
            return st;
    const ts_sun_sample *r = &c->ns[ref_node(s)];
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
        if ((st = ts_horizon_sweep(g, a, &ho, c->pa, err)) != TS_OK)
            return st;
        for (size_t i = 0; i < c->cells; i++)
            vis[i] = cell_vis(e, c->pa[i], c->floor ? c->floor[i] : NAN);
        return TS_OK;
    }

    /* Lattice: azimuths as offsets from the reference node's. */
    double a_ref = r->grid_azimuth, lo = INFINITY, hi = -INFINITY, emax = -INFINITY;
    for (int i = 0; i < c->nodes; i++) {
        double d = wrap180(c->ns[i].grid_azimuth - a_ref);
        lo = fmin(lo, d);
        hi = fmax(hi, d);
        emax = fmax(emax, c->ns[i].elevation);
    }
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
            double e = w00 * n00->elevation + w10 * n10->elevation + w01 * n01->elevation +
                       w11 * n11->elevation;
            double d = w00 * wrap180(n00->grid_azimuth - a_ref) +
                       w10 * wrap180(n10->grid_azimuth - a_ref) +
                       w01 * wrap180(n01->grid_azimuth - a_ref) +
                       w11 * wrap180(n11->grid_azimuth - a_ref);
            size_t k = (size_t)y * W + x;
            c->cel[k] = (float)e;
            c->caz[k] = (float)d;
            if (el) el[k] = (float)e;
            if (az) az[k] = (float)wrap360(a_ref + d);
        }
    }
    if (emax + rad <= c->floor_min) {
        *dark = 1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                vis[(size_t)y * W + x] = isnan(ts_grid_at(g, x, y)) ? NAN : 0.0f;
        return TS_OK;
    }
    double span = hi - lo;
    int K = span < 1e-9 ? 1 : (int)ceil(span / LATTICE_AZ_STEP) + 1;
    double step = K > 1 ? span / (K - 1) : 0.0;
    if ((st = ts_horizon_sweep(g, a_ref + lo, &ho, c->pa, err)) != TS_OK)
        return st;
    if (K == 1) {
        for (size_t i = 0; i < c->cells; i++)
            vis[i] = cell_vis(c->cel[i], c->pa[i], c->floor ? c->floor[i] : NAN);
        return TS_OK;
    }
    for (int j = 1; j < K; j++) {
        if ((st = ts_horizon_sweep(g, a_ref + lo + j * step, &ho, c->pb, err)) != TS_OK)
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
                acc[i] += vis[i] > 0.0f ? hrs : 0.0;
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

/* ------------------------------------------------------------ clear sky */

/* Kasten & Young (1989) relative optical air mass at sea level, apparent
 * elevation h in degrees (> 0). */
static double air_mass(double h)
{
    return 1.0 / (sin(h * DEG2RAD) + 0.50572 * pow(h + 6.07995, -1.6364));
}

/* Rayleigh optical thickness at air mass m (Kasten 1996, as in ESRA). */
static double rayleigh(double m)
{
    if (m <= 20.0)
        return 1.0 / (6.6296 + m * (1.7513 + m * (-0.1202 + m * (0.0065 - m * 0.00013))));
    return 1.0 / (10.4 + 0.718 * m);
}

/* Diffuse transmission at zenith and its angular function (ESRA). */
static double diffuse_factor(double linke, double sin_h)
{
    double tl = linke;
    double trd = -1.5843e-2 + tl * (3.0543e-2 + tl * 3.797e-4);
    double a0 = 2.6463e-1 + tl * (-6.1581e-2 + tl * 3.1408e-3);
    double a1 = 2.0402 + tl * (1.8945e-2 - tl * 1.1161e-2);
    double a2 = -1.3025 + tl * (3.9231e-2 + tl * 8.5079e-3);
    if (a0 * trd < 2e-3)
        a0 = 2e-3 / trd;
    double fd = a0 + sin_h * (a1 + sin_h * a2);
    double d = trd * fd;
    return d > 0 ? d : 0;
}

static double beam_transmittance(double m, double linke)
{
    return exp(-0.8662 * linke * m * rayleigh(m));
}

void ts_clear_sky_esra(double elevation, double height_m, double linke,
                       double distance_au, ts_clear_sky *out)
{
    memset(out, 0, sizeof *out);
    if (!(elevation > 0) || !(distance_au > 0) || !(linke > 0))
        return;
    double eps = 1.0 / (distance_au * distance_au);
    double g0 = TS_SOLAR_CONSTANT * eps;
    double pc = exp(-(isfinite(height_m) ? height_m : 0.0) / 8434.5);
    double m = pc * air_mass(elevation);
    double sh = sin(elevation * DEG2RAD);
    out->beam_normal = g0 * beam_transmittance(m, linke);
    out->beam_horizontal = out->beam_normal * sh;
    out->diffuse_horizontal = g0 * diffuse_factor(linke, sh);
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
                (st = ts_horizon_sweep(grid, a, &h, c.pa, err)) != TS_OK ||
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
            double m0 = air_mass(e), sh = sin(e * DEG2RAD);
            double dh = g0 * diffuse_factor(tl, sh) * hrs;
            double a = ref.grid_azimuth * DEG2RAD, ce = cos(e * DEG2RAD);
            double lx = sin(a) * ce, ly = cos(a) * ce, lz = sh;
            for (size_t i = 0; i < cells; i++) {
                if (isnan(pc[i]))
                    continue;
                accd[i] += dh * sky[i];
                if (dark || !(vis[i] > 0))
                    continue;
                double cosi = nx[i] * lx + ny[i] * ly + nz[i] * lz;
                if (cosi <= 0)
                    continue;
                double bn = g0 * beam_transmittance(pc[i] * m0, tl);
                accb[i] += bn * cosi * vis[i] * hrs;
            }
        } else {
            for (size_t i = 0; i < cells; i++) {
                double e = cel[i];
                if (isnan(pc[i]) || !(e > 0))
                    continue;
                double sh = sin(e * DEG2RAD);
                accd[i] += g0 * diffuse_factor(tl, sh) * hrs * sky[i];
                if (dark || !(vis[i] > 0))
                    continue;
                double a = caz[i] * DEG2RAD, ce = cos(e * DEG2RAD);
                double cosi = nx[i] * sin(a) * ce + ny[i] * cos(a) * ce + nz[i] * sh;
                if (cosi <= 0)
                    continue;
                double bn = g0 * beam_transmittance(pc[i] * air_mass(e), tl);
                accb[i] += bn * cosi * vis[i] * hrs;
            }
        }
    }
    if ((st = ts_progress(&o->horizon, 1.0, err)) != TS_OK)
        goto done;
    for (size_t i = 0; i < cells; i++) {
        int nd = isnan(pc[i]);
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
