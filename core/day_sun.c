/*
 * The sun over a day, the common part: dates and UTC offsets, the day
 * options, the sun at the sites, sampling times (uniform steps and the
 * atlas's). Split from day_cycle.c unchanged. See day_cycle.h.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "day_cycle_internal.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)
/* Sample the sun's track for the atlas every this many seconds. */
#define ATLAS_SCAN_S 60.0

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
    const int dated = strlen(s) >= 10 && digits(s, 4, &y) && s[4] == '-' &&
                      digits(s + 5, 2, &m) && s[7] == '-' && digits(s + 8, 2, &d);
    if (dated && s[10] != '\0')
        return ts_fail(err, TS_ERR_ARG,
                       "Cannot read '%.64s' as a date: a date is YYYY-MM-DD alone, here "
                       "followed by '%.24s' (the day's offset from UTC is TIMEZONE's, e.g. "
                       "TIMEZONE=+02:00; an instant is DATETIME's).", s, s + 10);
    if (!dated)
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
                       "Cannot read '%.64s' as an offset from UTC: expected Z (or UTC), "
                       "+hh:mm, -hh:mm, +hhmm or +hh, e.g. +02:00 (named time zones are "
                       "not supported: give the offset that applies on the day).", s);
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
    o->plane_cache_bytes = TS_DAY_PLANE_CACHE_DEFAULT;
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

ts_status ts_day_opts_check(const ts_day_opts *o, ts_error *err)
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
    if (o->table_heights_given &&
        !(isfinite(o->table_height_min) && isfinite(o->table_height_max) &&
          o->table_height_min <= o->table_height_max))
        return ts_fail(err, TS_ERR_ARG,
                       "the transmittance tables' heights must be finite, lowest first, "
                       "got %g to %g m", o->table_height_min, o->table_height_max);
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

double ts_day_earth_floor(const ts_grid *g, const ts_horizon_opts *o, float *floor)
{
    double lo = 0.0;
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            float h = ts_grid_at(g, x, y);
            float f = isnan(h) ? NAN : (float)ts_earth_horizon(h, o);
            floor[(size_t)y * g->width + x] = f;
            if (f < lo)
                lo = f;
        }
    return lo;
}

double ts_wrap360(double a)
{
    a = fmod(a, 360.0);
    if (a < 0)
        a += 360.0;
    if (a >= 360.0)
        a -= 360.0;
    return a;
}

double ts_wrap180(double a)
{
    a = ts_wrap360(a);
    return a > 180.0 ? a - 360.0 : a;
}

/* The sun at node i at t; instant: the detail of a node at t (its part
 * that depends on the instant only), or NULL. */
static ts_status node_sun(const ts_sun_sites *s, const ts_day_opts *o, int i, double t,
                          const ts_sun_detail *instant, ts_sun_sample *out,
                          ts_sun_detail *det, ts_error *err)
{
    ts_sun_input in = o->sun;
    ts_sun_output sun;
    in.jd = ts_julian_day_from_unix(t);
    in.longitude = s->longitude[i];
    in.latitude = s->latitude[i];
    ts_status st = instant ? ts_sun_position_from(&in, instant, &sun, det, err)
                           : ts_sun_position_detail(&in, &sun, det, err);
    if (st != TS_OK)
        return st;
    out->unix_time = t;
    out->azimuth = sun.azimuth;
    out->elevation = sun.elevation;
    out->true_elevation = det->e0;
    out->grid_azimuth = ts_wrap360(sun.azimuth + (s->north_azimuth ? s->north_azimuth[i] : 0.0));
    out->distance_au = det->R;
    return TS_OK;
}

ts_status ts_day_node_sun(const ts_sun_sites *s, const ts_day_opts *o, int i,
                          double t, ts_sun_sample *out, ts_error *err)
{
    ts_sun_detail det;
    return node_sun(s, o, i, t, NULL, out, &det, err);
}

/* node_sun of nodes 0, 1, ... in turn at one t: node 0's detail is kept in
 * *instant, and the nodes after take the instant's part from it. */
static ts_status node_sun_in_turn(const ts_sun_sites *s, const ts_day_opts *o, int i,
                                  double t, ts_sun_detail *instant, ts_sun_sample *out,
                                  ts_error *err)
{
    ts_sun_detail det;
    return node_sun(s, o, i, t, i ? instant : NULL, out, i ? &det : instant, err);
}

ts_status ts_day_nodes_sun(const ts_sun_sites *s, const ts_day_opts *o, double t,
                           ts_sun_sample *ns, ts_error *err)
{
    ts_sun_detail instant;
    ts_status st;
    for (int i = 0; i < s->nx * s->ny; i++)
        if ((st = node_sun_in_turn(s, o, i, t, &instant, &ns[i], err)) != TS_OK)
            return st;
    return TS_OK;
}

int ts_day_ref_node(const ts_sun_sites *s)
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
    if ((st = ts_day_node_sun(sites, o, ts_day_ref_node(sites), unix_time, out, err)) != TS_OK)
        return st;
    return ts_ok(err);
}

ts_status ts_sun_highest_site(const ts_sun_sites *sites, const ts_day_opts *o,
                              double unix_time, ts_sun_sample *out, int *node, ts_error *err)
{
    ts_status st = ts_sun_sites_validate(sites, err);
    if (st != TS_OK)
        return st;
    if (!o || !out)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_highest_site: NULL argument");
    int best = -1;
    ts_sun_detail instant;
    for (int i = 0; i < sites->nx * sites->ny; i++) {
        ts_sun_sample s;
        if ((st = node_sun_in_turn(sites, o, i, unix_time, &instant, &s, err)) != TS_OK)
            return st;
        if (best < 0 || s.elevation > out->elevation)
            best = i, *out = s;
    }
    if (node)
        *node = best;
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

/* Where in [a, a + dt] the sun's upper limb crosses the horizon (it is up
 * at one end only): the fraction of dt at the lit side of the crossing, by
 * bisection (to 1e-6 of the minute). */
static ts_status limb_crossing(const ts_sun_sites *sites, const ts_day_opts *o, int node,
                               double a, double dt, int rising, double *frac, ts_error *err)
{
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 20; i++) {
        double mid = 0.5 * (lo + hi);
        ts_sun_sample s;
        ts_status st = ts_day_node_sun(sites, o, node, a + mid * dt, &s, err);
        if (st != TS_OK)
            return st;
        if ((s.elevation > -TS_SUN_RADIUS_DEG) == rising)
            hi = mid;
        else
            lo = mid;
    }
    *frac = rising ? hi : lo;
    return TS_OK;
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
    double *lit = malloc(2 * (size_t)m * sizeof *lit); /* lit part of each minute */
    if (!c || !w || !lit) {
        free(c), free(w), free(lit);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the sun's track");
    }
    const double wmax = 1.0 / sin(2.0 * DEG2RAD);
    int node = ts_day_ref_node(sites);
    for (int k = 0; k <= m && st == TS_OK; k++) {
        ts_sun_sample s;
        if ((st = ts_day_node_sun(sites, o, node, start_unix + k * dt, &s, err)) != TS_OK)
            break;
        double e = s.elevation;
        w[k] = e > -TS_SUN_RADIUS_DEG ? fmin(wmax, 1.0 / sin(fmax(e, 2.0) * DEG2RAD)) : 0.0;
    }
    /* A minute in which the sun rises or sets counts from or up to the
     * instant it does (w is wmax there), so that no instant falls while
     * the sun is below the horizon: interpolated across the minute, a map
     * could show the sun 0.9 deg down (the SPA's refraction starts there). */
    c[0] = 0;
    for (int k = 0; k < m && st == TS_OK; k++) {
        double a = 0.0, b = 1.0, wa = w[k], wb = w[k + 1];
        if ((wa > 0) != (wb > 0)) {
            double x = 0.5;
            st = limb_crossing(sites, o, node, start_unix + k * dt, dt, wb > 0, &x, err);
            if (wb > 0)
                a = x, wa = wmax;
            else
                b = x, wb = wmax;
        }
        lit[2 * k] = a, lit[2 * k + 1] = b;
        c[k + 1] = c[k] + 0.5 * (wa + wb) * (b - a) * dt;
    }
    double total = st == TS_OK ? c[m] : 0.0;
    if (total > 0) {
        int k = 0;
        for (int i = 0; i < n; i++) {
            double target = (i + 0.5) / n * total;
            while (k < m - 1 && c[k + 1] <= target)
                k++;
            double span = c[k + 1] - c[k];
            double f = span > 0 ? (target - c[k]) / span : 0.5;
            times[i] = start_unix + (k + lit[2 * k] + f * (lit[2 * k + 1] - lit[2 * k])) * dt;
        }
        *n_out = n;
    }
    free(c), free(w), free(lit);
    return st == TS_OK ? ts_ok(err) : st;
}
