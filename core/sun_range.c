/*
 * Hours of sun and clear-sky insolation over a range of days, from horizons
 * swept once for a fixed set of azimuths (see day_cycle.h and
 * docs/day-cycle.md). The sun's positions over all sampled days are sorted
 * into the azimuth buckets between consecutive horizon planes; the planes
 * are swept in order, two at a time, and each bucket is evaluated on every
 * cell as soon as its two planes exist.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle_internal.h"
#include "status_internal.h"
#include "sun_range_internal.h"

#define DEG2RAD (M_PI / 180.0)
/* Longest range, days: a century. */
#define RANGE_MAX_DAYS 36600
/* Most sun positions a range may hold (memory guard). */
#define RANGE_MAX_POSITIONS 20000000L

void ts_date_range_default(ts_date_range *r)
{
    memset(r, 0, sizeof *r);
    r->day_interval = TS_RANGE_DAY_INTERVAL;
    r->step_minutes = TS_RANGE_STEP_MINUTES;
    r->horizon_directions = TS_RANGE_HORIZON_DIRECTIONS;
}

static int date_ok(int y, int m, int d)
{
    return y >= 0 && y <= 9999 && m >= 1 && m <= 12 && d >= 1 && d <= ts_days_in_month(y, m);
}

ts_status ts_date_range_check(const ts_date_range *r, int *days, int *sampled, ts_error *err)
{
    if (!r)
        return ts_fail(err, TS_ERR_ARG, "the date range is NULL");
    if (!date_ok(r->first_year, r->first_month, r->first_day))
        return ts_fail(err, TS_ERR_ARG, "the first day of the range, %04d-%02d-%02d, is not a "
                       "date (years 0 to 9999)", r->first_year, r->first_month, r->first_day);
    if (!date_ok(r->last_year, r->last_month, r->last_day))
        return ts_fail(err, TS_ERR_ARG, "the last day of the range, %04d-%02d-%02d, is not a "
                       "date (years 0 to 9999)", r->last_year, r->last_month, r->last_day);
    long long n = ts_days_from_civil(r->last_year, r->last_month, r->last_day) -
                  ts_days_from_civil(r->first_year, r->first_month, r->first_day) + 1;
    if (n < 1)
        return ts_fail(err, TS_ERR_ARG, "the last day of the range, %04d-%02d-%02d, is before "
                       "its first, %04d-%02d-%02d", r->last_year, r->last_month, r->last_day,
                       r->first_year, r->first_month, r->first_day);
    if (n > RANGE_MAX_DAYS)
        return ts_fail(err, TS_ERR_ARG, "the date range is %lld days long; at most %d days "
                       "(a century) are supported", n, RANGE_MAX_DAYS);
    if (r->utc_offset_minutes <= -24 * 60 || r->utc_offset_minutes >= 24 * 60)
        return ts_fail(err, TS_ERR_ARG, "the offset from UTC must be less than 24 hours, got "
                       "%d minutes", r->utc_offset_minutes);
    if (r->day_interval < 1 || r->day_interval > 366)
        return ts_fail(err, TS_ERR_ARG, "DAY_INTERVAL must be between 1 and 366 days, got %d",
                       r->day_interval);
    if (!(r->step_minutes >= 1.0 && r->step_minutes <= 1440.0))
        return ts_fail(err, TS_ERR_ARG, "STEP_MINUTES must be between 1 and 1440 for a date "
                       "range, got %g", r->step_minutes);
    if (r->horizon_directions < 4 || r->horizon_directions > 3600)
        return ts_fail(err, TS_ERR_ARG, "HORIZON_DIRECTIONS must be between 4 and 3600, got %d",
                       r->horizon_directions);
    int s = (int)((n - 1) / r->day_interval + 1);
    long steps = (long)ts_day_step_count(86400.0, r->step_minutes * 60.0);
    if ((long)s * steps > RANGE_MAX_POSITIONS)
        return ts_fail(err, TS_ERR_ARG, "the range has %ld sun positions (%d days of %ld steps); "
                       "at most %ld: raise DAY_INTERVAL or STEP_MINUTES",
                       (long)s * steps, s, steps, RANGE_MAX_POSITIONS);
    if (days)
        *days = (int)n;
    if (sampled)
        *sampled = s;
    return ts_ok(err);
}

void ts_date_range_block(const ts_date_range *r, int days, int i, int *first, int *length,
                         int *sampled)
{
    /* sampled at its middle day: its first day stood for the days after
     * it, the shortest of them while the days lengthen (-5 % of a spring's
     * insolation at interval 14) */
    *first = i * r->day_interval;
    *length = days - *first < r->day_interval ? days - *first : r->day_interval;
    *sampled = *first + (*length - 1) / 2;
}

/* Everything a range computation holds. */
typedef struct {
    const ts_grid *g;
    const ts_day_opts *o;
    const ts_date_range *r;
    size_t cells;
    int D;               /* horizon azimuths */
    ts_range_sun *sun;   /* sorted by bucket */
    int nsun;
    int *first;          /* D + 1 bucket starts into sun */
    float *floor;        /* Earth horizon per cell, or NULL */
    double floor_min;
    float *tables;       /* beam transmittances, TS_RANGE_TABLE per position */
    unsigned char *blank; /* TS_EDGE_NODATA: 1 where a swept plane was nodata */
} range_ctx;

static void range_free(range_ctx *c)
{
    free(c->sun);
    free(c->first);
    free(c->floor);
    free(c->tables);
    free(c->blank);
}

static ts_status range_init(range_ctx *c, const ts_grid *g, const ts_sun_sites *sites,
                            const ts_day_opts *o, const ts_date_range *r, const void *out,
                            ts_error *err)
{
    memset(c, 0, sizeof *c);
    ts_status st;
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "the output of the date-range product is NULL");
    if ((st = ts_grid_validate(g, err)) != TS_OK ||
        (st = ts_sun_sites_validate(sites, err)) != TS_OK ||
        (st = ts_day_opts_check(o, err)) != TS_OK ||
        (st = ts_date_range_check(r, NULL, NULL, err)) != TS_OK)
        return st;
    if (sites->nx * sites->ny > 1)
        return ts_fail(err, TS_ERR_ARG, "sun positions per cell (a lattice of sun sites) are "
                       "not supported over a date range: use one sun site (the DEM's centre)");
    c->g = g;
    c->o = o;
    c->r = r;
    c->cells = (size_t)g->width * g->height;
    c->D = r->horizon_directions;
    c->floor_min = -90.0;
    if (o->earth_horizon) {
        if (!(c->floor = malloc(c->cells * sizeof(float))))
            return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the Earth-horizon plane");
        c->floor_min = ts_day_earth_floor(g, &o->horizon, c->floor);
    }
    if (o->horizon.edge == TS_EDGE_NODATA && !(c->blank = calloc(c->cells, 1)))
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the nodata mask of the edge");
    return TS_OK;
}

/* The progress bar's share of finding the sun positions (some 3 us each)
 * against the sweeps (some 20 ns a cell and plane): ten years at 1-minute
 * steps, 5.3 M positions, took 16 s before the first report. */
static double positions_share(const range_ctx *c, double positions)
{
    const double t_pos = positions * 3e-6, t_sweep = (double)c->cells * c->D * 2e-8;
    return t_pos / (t_pos + t_sweep);
}

/* The sun at every step of every sampled day, kept where `keep` says it can
 * count (dawn to dusk), with its weight in hours; progress reported (and a
 * cancel taken) after each day, up to *share, the part of the whole this
 * takes. */
static ts_status range_positions(range_ctx *c, const ts_sun_sites *sites, int beam,
                                 double *share, ts_error *err)
{
    const ts_date_range *r = c->r;
    int days, sampled;
    ts_status st = ts_date_range_check(r, &days, &sampled, err);
    if (st != TS_OK)
        return st;
    double step = r->step_minutes * 60.0;
    int n = ts_day_step_count(86400.0, step);
    *share = positions_share(c, (double)sampled * n);
    double *mid = malloc((size_t)n * sizeof *mid), *dur = malloc((size_t)n * sizeof *dur);
    c->sun = malloc((size_t)sampled * n * sizeof *c->sun);
    if (!mid || !dur || !c->sun) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate %d x %d sun positions", sampled, n);
        goto done;
    }
    long long day0 = ts_days_from_civil(r->first_year, r->first_month, r->first_day);
    int node = ts_day_ref_node(sites);
    for (int i = 0; i < sampled; i++) {
        if ((st = ts_progress(&c->o->horizon, *share * i / sampled, err)) != TS_OK)
            goto done;
        int block, weight, d;
        ts_date_range_block(r, days, i, &block, &weight, &d);
        double start = (double)(day0 + d) * 86400.0 - r->utc_offset_minutes * 60.0;
        if ((st = ts_day_uniform_times(start, 86400.0, step, mid, dur, err)) != TS_OK)
            goto done;
        for (int k = 0; k < n; k++) {
            ts_sun_sample s;
            if ((st = ts_day_node_sun(sites, c->o, node, mid[k], &s, err)) != TS_OK)
                goto done;
            /* as ts_insolation (sun above the horizon) and ts_sun_hours
             * (some cell's horizon can be below the sun's upper limb) */
            if (beam ? !(s.elevation > 0) : s.elevation + TS_SUN_RADIUS_DEG <= c->floor_min)
                continue;
            ts_range_sun *p = &c->sun[c->nsun++];
            memset(p, 0, sizeof *p);
            p->az = s.grid_azimuth;
            p->el = s.elevation;
            p->hours = dur[k] / 3600.0 * weight;
            double a = s.grid_azimuth * DEG2RAD, e = s.elevation * DEG2RAD;
            p->lx = (float)(sin(a) * cos(e));
            p->ly = (float)(cos(a) * cos(e));
            p->lz = (float)sin(e);
            p->g0_hours = TS_SOLAR_CONSTANT / (s.distance_au * s.distance_au) * p->hours;
        }
    }
    st = TS_OK;
done:
    free(mid);
    free(dur);
    return st;
}

/* Azimuth bucket k of a position: between planes k and k + 1 (mod D), plane
 * k at k * 360 / D degrees from grid north. (Not from the sky term's
 * start_azimuth: a START_AZIMUTH for insolation's sky turned the beam's
 * planes too, and its beam then differed from sunhours' on the same range,
 * by up to 336 Wh/m^2 in three days: session 58's audit.) */
static int bucket_of(const range_ctx *c, double az, float *w)
{
    double span = 360.0 / c->D, p = fmod(az, 360.0);
    if (p < 0)
        p += 360.0;
    p /= span;
    int k = (int)floor(p);
    double f = p - k;
    if (k >= c->D) {
        k = 0;
        f = 0;
    }
    *w = (float)f;
    return k;
}

/* Sort the positions into buckets (counting sort, stable). */
static ts_status range_sort(range_ctx *c, ts_error *err)
{
    int D = c->D;
    c->first = calloc((size_t)D + 1, sizeof *c->first);
    int *bk = malloc(((size_t)c->nsun + 1) * sizeof *bk);
    ts_range_sun *sorted = malloc(((size_t)c->nsun + 1) * sizeof *sorted);
    if (!c->first || !bk || !sorted) {
        free(bk);
        free(sorted);
        return ts_fail(err, TS_ERR_NOMEM, "cannot sort %d sun positions", c->nsun);
    }
    for (int i = 0; i < c->nsun; i++) {
        bk[i] = bucket_of(c, c->sun[i].az, &c->sun[i].w);
        c->first[bk[i] + 1]++;
    }
    for (int k = 0; k < D; k++)
        c->first[k + 1] += c->first[k];
    int *fill = malloc((size_t)D * sizeof *fill);
    if (!fill) {
        free(bk);
        free(sorted);
        return ts_fail(err, TS_ERR_NOMEM, "cannot sort %d sun positions", c->nsun);
    }
    memcpy(fill, c->first, (size_t)D * sizeof *fill);
    for (int i = 0; i < c->nsun; i++)
        sorted[fill[bk[i]]++] = c->sun[i];
    free(fill);
    free(bk);
    free(c->sun);
    c->sun = sorted;
    return TS_OK;
}

/* Called with each horizon plane as it is swept (e.g. the sky term). */
typedef ts_status (*plane_fn)(void *user, int k, double azimuth, const float *plane,
                              ts_error *err);

/* Report progress `done`, sweep plane k into `out`, hand it to on_plane. */
static ts_status sweep_plane(const range_ctx *c, const ts_horizon_opts *h, int k, float *out,
                             plane_fn on_plane, void *user, double done, ts_error *err)
{
    double a = ts_horizon_azimuth(h, k);
    ts_status st = ts_progress(&c->o->horizon, done, err);
    if (st == TS_OK)
        st = ts_day_sweep(c->g, a, h, c->o, NAN, out, err);
    for (size_t i = 0; st == TS_OK && c->blank && i < c->cells; i++)
        c->blank[i] |= isnan(out[i]); /* EDGE=nodata: the ray leaves the grid */
    if (st == TS_OK && on_plane)
        st = on_plane(user, k, a, out, err);
    return st;
}

/*
 * Sweep the planes that a bucket needs (or that `extra` asks for: the
 * planes k with k % extra == phase, extra 0 = none), in order, and evaluate
 * each bucket with its two planes. `tmpl` is filled per bucket (planes,
 * positions). Progress runs from p0 to 1.
 */
static ts_status range_stream(range_ctx *c, ts_range_bucket *tmpl, int extra, int phase,
                              plane_fn on_plane, void *user, double p0, ts_error *err)
{
    const int D = c->D;
    ts_horizon_opts h = c->o->horizon;
    h.directions = D;
    h.start_azimuth = 0; /* (bucket_of) */
    int count = 0, *need = calloc((size_t)D, sizeof *need);
    if (!need)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the plane list");
    for (int k = 0; k < D; k++) {
        int prev = (k + D - 1) % D;
        need[k] = c->first[k + 1] > c->first[k] || c->first[prev + 1] > c->first[prev] ||
                  (extra > 0 && k % extra == phase);
        count += need[k];
    }
    int wrap = c->first[D] > c->first[D - 1]; /* the last bucket needs plane 0 */
    float *pa = malloc(c->cells * sizeof(float)), *pb = malloc(c->cells * sizeof(float));
    float *p0_keep = wrap ? malloc(c->cells * sizeof(float)) : NULL;
    ts_status st = TS_OK;
    if (!pa || !pb || (wrap && !p0_keep)) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the horizon planes");
        goto done;
    }
    int cur = -1, swept = 0;
    for (int k = 0; k < D; k++) {
        if (!need[k])
            continue;
        if (cur != k) {
            if ((st = sweep_plane(c, &h, k, pa, on_plane, user,
                                  p0 + (1 - p0) * swept++ / count, err)) != TS_OK)
                goto done;
            if (k == 0 && wrap)
                memcpy(p0_keep, pa, c->cells * sizeof(float));
            cur = k;
        }
        if (c->first[k + 1] == c->first[k])
            continue;
        int k1 = (k + 1) % D;
        const float *right = p0_keep;
        if (k1 != 0) {
            if ((st = sweep_plane(c, &h, k1, pb, on_plane, user,
                                  p0 + (1 - p0) * swept++ / count, err)) != TS_OK)
                goto done;
            right = pb;
        }
        tmpl->pa = pa;
        tmpl->pb = right;
        tmpl->sun = c->sun + c->first[k];
        tmpl->count = c->first[k + 1] - c->first[k];
        if ((st = ts_range_evaluate(tmpl, c->o->horizon.threads, err)) != TS_OK)
            goto done;
        if (k1 != 0) {
            float *t = pa;
            pa = pb;
            pb = t;
            cur = k1;
        }
    }
    st = ts_progress(&c->o->horizon, 1.0, err);
done:
    free(need);
    free(pa);
    free(pb);
    free(p0_keep);
    return st;
}

ts_status ts_sun_hours_range(const ts_grid *grid, const ts_sun_sites *sites,
                             const ts_day_opts *o, const ts_date_range *r, float *hours,
                             ts_error *err)
{
    range_ctx c;
    ts_status st = range_init(&c, grid, sites, o, r, hours, err);
    if (st != TS_OK)
        return st;
    double *acc = calloc(c.cells, sizeof *acc);
    if (!acc) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the sun-hour sums");
        goto done;
    }
    double share = 0;
    if ((st = range_positions(&c, sites, 0, &share, err)) != TS_OK ||
        (st = range_sort(&c, err)) != TS_OK)
        goto done;
    ts_range_bucket b = {.cells = c.cells, .floor = c.floor, .acc = acc,
                         .mode = o->sun_hours_rule == TS_SUN_HOURS_DISK_FRACTION
                                     ? TS_RANGE_FRACTION
                                     : TS_RANGE_VISIBLE};
    if ((st = range_stream(&c, &b, 0, 0, NULL, NULL, share, err)) != TS_OK)
        goto done;
    for (int y = 0; y < grid->height; y++)
        for (int x = 0; x < grid->width; x++) {
            size_t i = (size_t)y * grid->width + x;
            int nd = isnan(ts_grid_at(grid, x, y)) || (c.blank && c.blank[i]);
            hours[i] = nd ? NAN : (float)acc[i];
        }
    st = ts_ok(err);
done:
    free(acc);
    range_free(&c);
    return st;
}

/* The sky term accumulated from the planes the stream sweeps anyway. */
typedef struct {
    const ts_grid *g;
    const float *nx, *ny, *nz;
    float *sky;
    int every, phase, dirs; /* the planes k with k % every == phase */
} sky_share;

static ts_status sky_plane(void *user, int k, double azimuth, const float *plane,
                           ts_error *err)
{
    const sky_share *s = user;
    if (k % s->every != s->phase)
        return TS_OK;
    return ts_sky_accumulate(s->g, s->nx, s->ny, s->nz, plane, azimuth, s->dirs, NULL, s->sky,
                             NULL, err);
}

/* Beam transmittance tables over the grid's pressure factors; pc receives
 * them per cell (NaN for nodata). */
static ts_status beam_tables(range_ctx *c, float *pc, ts_range_bucket *b, ts_error *err)
{
    const ts_grid *g = c->g;
    double lo = INFINITY, hi = -INFINITY;
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            float h = ts_grid_at(g, x, y);
            float v = isnan(h) ? NAN : (float)exp(-h / 8434.5);
            pc[(size_t)y * g->width + x] = v;
            if (!isnan(v)) {
                lo = v < lo ? v : lo;
                hi = v > hi ? v : hi;
            }
        }
    if (c->o->table_heights_given) {
        lo = (float)exp(-c->o->table_height_max / 8434.5);
        hi = (float)exp(-c->o->table_height_min / 8434.5);
    }
    if (!(lo <= hi))
        lo = hi = 1.0;
    const int N = TS_RANGE_TABLE;
    b->pc_min = (float)lo;
    b->pc_inv = hi > lo ? (float)((N - 1) / (hi - lo)) : 0.0f;
    c->tables = malloc(((size_t)c->nsun * N + 1) * sizeof(float));
    if (!c->tables)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the transmittance tables");
    for (int i = 0; i < c->nsun; i++) {
        float *t = c->tables + (size_t)i * N;
        double m0 = ts_esra_air_mass(c->sun[i].el);
        for (int n = 0; n < N; n++)
            t[n] = (float)ts_esra_beam_transmittance((lo + (hi - lo) * n / (N - 1)) * m0,
                                                     c->o->linke_turbidity);
        c->sun[i].table = t;
    }
    return TS_OK;
}

ts_status ts_insolation_range(const ts_grid *grid, const ts_sun_sites *sites,
                              const ts_day_opts *o, const ts_date_range *r, float *total,
                              float *beam, float *diffuse, ts_error *err)
{
    range_ctx c;
    ts_status st = range_init(&c, grid, sites, o, r, total, err);
    if (st != TS_OK)
        return st;
    size_t cells = c.cells;
    float *nx = malloc(cells * sizeof(float)), *ny = malloc(cells * sizeof(float));
    float *nz = malloc(cells * sizeof(float)), *sky = calloc(cells, sizeof(float));
    float *pc = malloc(cells * sizeof(float));
    double *acc = calloc(cells, sizeof *acc);
    if (!nx || !ny || !nz || !sky || !pc || !acc) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the insolation planes");
        goto done;
    }
    ts_range_bucket b = {.cells = cells, .floor = c.floor, .acc = acc, .mode = TS_RANGE_BEAM,
                         .nx = nx, .ny = ny, .nz = nz, .pc = pc};
    double s0 = 0; /* the positions' share of the bar */
    if ((st = ts_normals(grid, nx, ny, nz, err)) != TS_OK ||
        (st = range_positions(&c, sites, 1, &s0, err)) != TS_OK ||
        (st = range_sort(&c, err)) != TS_OK || (st = beam_tables(&c, pc, &b, err)) != TS_OK)
        goto done;
    /* The sky term over o->horizon.directions azimuths, as ts_insolation:
     * from the stream's own planes when they include those azimuths (the
     * first, start_azimuth, on plane `first`: a whole number of the
     * planes' span from north) */
    ts_horizon_opts h = o->horizon;
    h.directions = h.directions < 1 ? 1 : h.directions;
    double start = fmod(h.start_azimuth, 360.0); /* in [0, 360): a plane's index */
    start = start < 0 ? start + 360.0 : start;
    const int first = (int)floor(start / (360.0 / c.D) + 0.5) % c.D;
    int shared = c.D % h.directions == 0;
    const int every = shared ? c.D / h.directions : 1;
    /* shared where every sky azimuth is a plane's to the bit (a start a
     * hair off a plane, 359.9999999999 by plane 0, is swept on its own) */
    ts_horizon_opts planes = h;
    planes.directions = c.D;
    planes.start_azimuth = 0;
    for (int k = 0; shared && k < h.directions; k++)
        shared = ts_horizon_azimuth(&planes, (first + k * every) % c.D) ==
                 ts_horizon_azimuth(&h, k);
    sky_share share = {grid, nx, ny, nz, sky, every, first % every, h.directions};
    double p0 = s0;
    if (!shared) {
        p0 = s0 + (1 - s0) * h.directions / (h.directions + c.D);
        float *plane = malloc(cells * sizeof(float));
        if (!plane) {
            st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate a horizon plane");
            goto done;
        }
        for (int k = 0; k < h.directions && st == TS_OK; k++) {
            double a = ts_horizon_azimuth(&h, k);
            if ((st = ts_progress(&o->horizon, s0 + (p0 - s0) * k / h.directions, err)) ==
                    TS_OK &&
                (st = ts_day_sweep(grid, a, &h, o, NAN, plane, err)) == TS_OK)
                st = sky_plane(&(sky_share){grid, nx, ny, nz, sky, 1, 0, h.directions}, k, a,
                               plane, err);
        }
        free(plane);
        if (st != TS_OK)
            goto done;
    }
    if ((st = range_stream(&c, &b, shared ? every : 0, share.phase,
                           shared ? sky_plane : NULL, &share, p0, err)) != TS_OK ||
        (st = ts_sky_finish(grid, h.directions, NULL, sky, NULL, err)) != TS_OK)
        goto done;
    double dsum = 0.0;
    for (int i = 0; i < c.nsun; i++)
        dsum += c.sun[i].g0_hours *
                ts_esra_diffuse_factor(o->linke_turbidity, sin(c.sun[i].el * DEG2RAD));
    for (size_t i = 0; i < cells; i++) {
        int nd = isnan(pc[i]) || (c.blank && c.blank[i]);
        double d = dsum * sky[i];
        total[i] = nd ? NAN : (float)(acc[i] + d);
        if (beam)
            beam[i] = nd ? NAN : (float)acc[i];
        if (diffuse)
            diffuse[i] = nd ? NAN : (float)d;
    }
    st = ts_ok(err);
done:
    free(nx);
    free(ny);
    free(nz);
    free(sky);
    free(pc);
    free(acc);
    range_free(&c);
    return st;
}
