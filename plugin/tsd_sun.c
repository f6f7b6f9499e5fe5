/* The sun from DATETIME / DATE / TIMEZONE; see tsd_sun.h. */
#include "tsd_sun.h"

#include "tsd_datetime.h"
#include "tsd_delta_t.h"
#include "tsd_dem_check.h"
#include "tsd_products.h"
#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


/* An offset from UTC in minutes (within a day) as +hh:mm or -hh:mm. */
#define OFFSET_TEXT 24
static void offset_text(int minutes, char buf[OFFSET_TEXT])
{
    snprintf(buf, OFFSET_TEXT, "%c%02d:%02d", minutes < 0 ? '-' : '+', abs(minutes) / 60,
             abs(minutes) % 60);
}

/* tsd_format_time, or with_ms tsd_format_instant. */
static void format_time(double t, int offset, int with_ms, char *buf, size_t n)
{
    if (!isfinite(t)) {
        snprintf(buf, n, "unknown");
        return;
    }
    /* the milliseconds begun, never the next second; or whole seconds,
     * rounded (computed instants: an atlas's read back differ in the µs) */
    const double whole = with_ms ? floor(t) : (double)llround(t);
    long long us = with_ms ? llround((t - whole) * 1e6) : 0;
    if (us > 999999)
        us = 999999;
    const long long ms = us / 1000;
    long long local = (long long)whole + offset * 60LL;
    long long days = local >= 0 ? local / 86400 : -((-local + 86399) / 86400);
    long long sec = local - days * 86400;
    /* civil from days (Howard Hinnant's algorithm) */
    long long z = days + 719468;
    long long era = (z >= 0 ? z : z - 146096) / 146097;
    long long doe = z - era * 146097;
    long long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    long long y = yoe + era * 400;
    long long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    long long mp = (5 * doy + 2) / 153;
    long long d = doy - (153 * mp + 2) / 5 + 1;
    long long m = mp < 10 ? mp + 3 : mp - 9;
    if (m <= 2)
        y++;
    char off[OFFSET_TEXT];
    if (offset == 0)
        snprintf(off, sizeof off, "Z");
    else
        offset_text(offset, off);
    char frac[8] = "";
    if (ms > 0) {
        snprintf(frac, sizeof frac, ".%03lld", ms);
        size_t k = strlen(frac);
        while (k > 2 && frac[k - 1] == '0')
            frac[--k] = '\0'; /* .500 as .5 */
    }
    snprintf(buf, n, "%04lld-%02lld-%02lldT%02lld:%02lld:%02lld%s%s", y, m, d, sec / 3600,
             sec / 60 % 60, sec % 60, frac, off);
}

void tsd_format_time(double t, int offset, char *buf, size_t n)
{
    format_time(t, offset, 0, buf, n);
}

void tsd_format_instant(double t, int offset, char *buf, size_t n)
{
    format_time(t, offset, 1, buf, n);
}

int tsd_sun_per_cell(const tsd_sun *sun)
{
    return sun && sun->sites.nx * sun->sites.ny > 1;
}

void tsd_sun_free(tsd_sun *s)
{
    if (!s)
        return;
    tsd_sites_free(&s->sites_owned);
    free(s->times);
    free(s->durations);
    free(s->samples);
    memset(s, 0, sizeof *s);
}

ts_status tsd_sun_date_range(const tsd_options *o, ts_date_range *r, int *days, int *sampled,
                             char *msg, size_t n)
{
    ts_error err;
    const char *last = o->end_date[0] ? o->end_date : o->start_date;
    ts_date_range_default(r);
    if (ts_parse_date(o->start_date, &r->first_year, &r->first_month, &r->first_day, &err) !=
        TS_OK)
        return tsd_fail_core(msg, n, "START_DATE", &err);
    if (ts_parse_date(last, &r->last_year, &r->last_month, &r->last_day, &err) != TS_OK)
        return tsd_fail_core(msg, n, "END_DATE", &err);
    if (ts_parse_utc_offset(o->timezone, &r->utc_offset_minutes, &err) != TS_OK)
        return tsd_fail_core(msg, n, "TIMEZONE", &err);
    if (ts_days_from_civil(r->last_year, r->last_month, r->last_day) <
        ts_days_from_civil(r->first_year, r->first_month, r->first_day))
        return tsd_fail(msg, n, TS_ERR_ARG,
                        "END_DATE=%s is before START_DATE=%s: the range runs from START_DATE "
                        "to END_DATE, both included", o->end_date, o->start_date);
    r->day_interval = o->day_interval;
    r->step_minutes = tsd_options_step_minutes(o);
    r->horizon_directions = o->horizon_directions;
    if (ts_date_range_check(r, days, sampled, &err) != TS_OK)
        return tsd_fail_core(msg, n, "START_DATE to END_DATE", &err);
    return TS_OK;
}

ts_status tsd_sun_setup(const tsd_options *o, tsd_sites *sites, double min_cell_m,
                        tsd_sun *s, char *msg, size_t n)
{
    const tsd_product_def *p = tsd_product_of(o);
    memset(s, 0, sizeof *s);
    s->sites_owned = *sites;
    memset(sites, 0, sizeof *sites);
    s->instant = NAN;
    s->sites.nx = s->sites_owned.nx;
    s->sites.ny = s->sites_owned.ny;
    s->sites.x0 = s->sites_owned.x0;
    s->sites.y0 = s->sites_owned.y0;
    s->sites.dx = s->sites_owned.dx;
    s->sites.dy = s->sites_owned.dy;
    s->sites.longitude = s->sites_owned.lon;
    s->sites.latitude = s->sites_owned.lat;
    s->sites.north_azimuth = s->sites_owned.north;

    ts_day_opts_default(&s->day);
    s->day.horizon.directions = o->directions;
    s->day.horizon.start_azimuth = o->start_azimuth;
    s->day.horizon.max_distance = o->max_distance;
    s->day.horizon.curvature = o->curvature;
    s->day.horizon.refraction = o->refraction;
    s->day.horizon.edge = tsd_options_edge(o);
    s->day.horizon.threads = o->threads;
    s->day.sun.pressure = o->pressure;
    s->day.sun.temperature = o->temperature;
    s->day.sun.delta_t = o->delta_t;
    s->day.linke_turbidity = o->linke_turbidity;
    s->day.sun_hours_rule =
        o->sunhours_fraction ? TS_SUN_HOURS_DISK_FRACTION : TS_SUN_HOURS_VISIBLE;

    ts_error err;
    if (ts_sun_sites_validate(&s->sites, &err) != TS_OK)
        return tsd_fail_core(msg, n, "cannot place the sun over the DEM", &err);
    if (o->datetime[0]) {
        char norm[2 * TSD_TEXT_MAX];
        tsd_datetime_normalise(o->datetime, norm, sizeof norm);
        if (ts_parse_iso8601(norm, &s->instant, &s->offset_minutes, &err) != TS_OK)
            return tsd_fail_core(msg, n, "DATETIME", &err);
    }
    if (o->timezone[0] && ts_parse_utc_offset(o->timezone, &s->offset_minutes, &err) != TS_OK)
        return tsd_fail_core(msg, n, "TIMEZONE", &err);

    if (!p->daily) {
        /* shade, shadow: the sun at DATETIME (tsd_run_init uses it) */
        if (ts_sun_at_site(&s->sites, &s->day, s->instant, &s->sun, &err) != TS_OK)
            return tsd_fail_core(msg, n, "cannot compute the sun's position", &err);
        if (o->method == TSD_METHOD_SHADOWMAP && !(s->sun.elevation > 0))
            return tsd_fail(msg, n, TS_ERR_ARG,
                            "METHOD=shadowmap needs the light above the horizon: at DATETIME=%s "
                            "the sun's elevation is %.2f degrees at the DEM's centre "
                            "(METHOD=exact handles a low light)",
                            o->datetime, s->sun.elevation);
        return TS_OK;
    }

    /* the local day, or the first of a range */
    if (tsd_options_is_range(o)) {
        ts_status st = tsd_sun_date_range(o, &s->range, &s->range_days, &s->range_sampled,
                                          msg, n);
        if (st != TS_OK)
            return st;
        s->is_range = 1;
        s->day_start = ts_local_midnight(s->range.first_year, s->range.first_month,
                                         s->range.first_day, s->offset_minutes);
    } else if (o->date[0]) {
        int y, m, d;
        if (ts_parse_date(o->date, &y, &m, &d, &err) != TS_OK)
            return tsd_fail_core(msg, n, "DATE", &err);
        s->day_start = ts_local_midnight(y, m, d, s->offset_minutes);
    } else {
        s->day_start = ts_local_day_start(s->instant, s->offset_minutes);
    }
    s->day_length = 86400.0 * (s->is_range ? s->range_days : 1);
    /* the SPA's range of years, checked once here: at both ends of the day
     * or range (a day ending past it failed on the first read, after the
     * open). The end less a second: the steps sample their middles, half a
     * step (30 s at least) before it, and a day ending at the limit itself
     * computes */
    ts_sun_sample probe;
    const char *first = s->is_range ? "START_DATE" : o->date[0] ? "DATE" : "DATETIME";
    if (ts_sun_at_site(&s->sites, &s->day, s->day_start, &probe, &err) != TS_OK)
        return tsd_fail_core(msg, n, first, &err);
    if (ts_sun_at_site(&s->sites, &s->day, s->day_start + s->day_length - 1.0, &probe, &err) !=
        TS_OK)
        return tsd_fail_core(msg, n, s->is_range ? "END_DATE (the range's end)" : first, &err);

    if (p->steps != TSD_STEPS_NONE) {
        int steps = tsd_options_band_count(o);
        s->times = malloc((size_t)steps * sizeof *s->times);
        s->durations = malloc((size_t)steps * sizeof *s->durations);
        s->samples = malloc((size_t)steps * sizeof *s->samples);
        if (!s->times || !s->durations || !s->samples)
            return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory for the time steps");
        if (p->steps == TSD_STEPS_UNIFORM) {
            if (ts_day_uniform_times(s->day_start, s->day_length, o->step_minutes * 60.0,
                                     s->times, s->durations, &err) != TS_OK)
                return tsd_fail_core(msg, n, "cannot lay out the day's steps", &err);
        } else {
            int got = 0;
            if (ts_day_atlas_times(&s->sites, &s->day, s->day_start, s->day_length, steps,
                                   s->times, &got, &err) != TS_OK)
                return tsd_fail_core(msg, n, "cannot lay out the atlas's sun positions", &err);
            if (got == 0) {
                char day[40];
                tsd_format_time(s->day_start, s->offset_minutes, day, sizeof day);
                return tsd_fail(msg, n, TS_ERR_ARG,
                                "the sun does not rise on the day starting %s at latitude "
                                "%.4g (polar night): PRODUCT=%s has no sun positions to "
                                "map; PRODUCT=sunhours gives 0 hours there",
                                day, s->sites.latitude[0], p->name);
            }
            for (int k = 0; k < steps; k++)
                s->durations[k] = NAN;
            s->threshold_m = o->far_threshold * min_cell_m;
        }
        s->steps = steps;
        for (int k = 0; k < steps; k++)
            if (ts_sun_at_site(&s->sites, &s->day, s->times[k], &s->samples[k], &err) != TS_OK)
                return tsd_fail_core(msg, n, "cannot compute the sun's position", &err);
    }
    return TS_OK;
}

/* The civil offsets from UTC in use: -12:00 (Baker Island) to +14:00 (Line
 * Islands). Beyond, a day's offset is likely a sign or a typo, which the
 * solar-time test below, modulo a day, does not see (+21:00 for -03:00
 * named the day before). */
#define CIVIL_OFFSET_WEST_MIN (-12 * 60)
#define CIVIL_OFFSET_EAST_MIN (14 * 60)

/* The DEM's centre among the sun's sites: the middle node of a lattice. */
static size_t centre_node(const tsd_sites *st)
{
    return (size_t)(st->ny / 2) * st->nx + st->nx / 2;
}

int tsd_sun_zone_warning(const tsd_sun *s, const tsd_options *o, char *warning, size_t n)
{
    /* the day products' day: from DATE and TIMEZONE, a range's, or DATETIME's
     * own offset */
    if (!tsd_product_of(o)->daily || !(s->day_length > 0))
        return 0;
    /* TIMEZONE, where given, sets the day's offset over DATETIME's own */
    const char *whose = o->timezone[0] ? "TIMEZONE's" : "DATETIME's";
    char given[OFFSET_TEXT], sun[OFFSET_TEXT];
    offset_text(s->offset_minutes, given);
    if (s->offset_minutes < CIVIL_OFFSET_WEST_MIN || s->offset_minutes > CIVIL_OFFSET_EAST_MIN) {
        snprintf(warning, n,
                 "%s offset (%s) is beyond every civil time zone (-12:00 to +14:00): the "
                 "day it names starts %.4g hours %s UTC's midnight of that date, so that its "
                 "sun is another date's than the site's. Is its sign right?",
                 whose, given, abs(s->offset_minutes) / 60.0,
                 s->offset_minutes > 0 ? "before" : "after");
        return 1;
    }
    const double lon = s->sites_owned.lon[centre_node(&s->sites_owned)];
    const double solar = lon * 4.0; /* minutes east of UTC */
    const double apart = remainder(s->offset_minutes - solar, 1440.0);
    if (!(fabs(apart) > 240.0))
        return 0;
    offset_text((int)lround(solar), sun);
    snprintf(warning, n,
             "%s offset (%s) is %.1f hours from the mean solar time at the DEM's centre "
             "(longitude %.1f: UTC%s), farther than any time zone: its day's midnight falls "
             "%.1f hours from the site's, where the sun may be up, and a day's sun may be "
             "split between two dates. Is it the site's offset?",
             whose, given, fabs(apart) / 60.0, lon, sun, fabs(apart) / 60.0);
    return 1;
}

/* The longest DAY_INTERVAL that keeps a range's total within about a
 * percent: midpoint samples of the seasons' curve err by ~I^2/24 of its
 * curvature, ~1 % of a block's sun at 46.5 N at 61 days, 3 % at 91. */
#define RANGE_INTERVAL_WARN_DAYS 61

/* No polar night nor midnight sun on flat ground nearer the equator (the
 * polar circles less the refraction and the disk: ~65.7 degrees) */
#define POLAR_EDGE_LATITUDE 63.0
/* Warned of where the blocks across such an edge put a range's flat ground
 * this share of its sun hours off, and an hour or more (a year at 78 N at
 * the defaults: -0.6 %; 14 October to 10 November: +13 %) */
#define POLAR_EDGE_ERROR 0.02

/* Hours of a day (from `start`, Unix) with part of the sun's disk above
 * flat ground at the reference site, in the range's steps (`mid`, `dur`:
 * room for a day's), as the product counts them. */
static double flat_sun_hours(const tsd_sun *s, double start, double *mid, double *dur)
{
    ts_error err;
    const double step = s->range.step_minutes * 60.0;
    const int steps = ts_day_step_count(86400.0, step);
    double hours = 0;
    if (ts_day_uniform_times(start, 86400.0, step, mid, dur, &err) != TS_OK)
        return 0;
    for (int k = 0; k < steps; k++) {
        ts_sun_sample at;
        if (ts_sun_at_site(&s->sites, &s->day, mid[k], &at, &err) == TS_OK &&
            at.elevation + TS_SUN_RADIUS_DEG > 0)
            hours += dur[k] / 3600.0;
    }
    return hours;
}

/* Whether the sun rises and sets over flat ground at the reference site on
 * the local day from `start`: 0 polar night, 2 midnight sun, 1 both; from
 * its elevation at the site's mean solar noon and midnight. */
static int day_kind(const tsd_sun *s, double start, double lon)
{
    const double noon = start + s->offset_minutes * 60.0 + 43200.0 - lon * 240.0;
    ts_sun_sample hi, lo;
    ts_error err;
    if (ts_sun_at_site(&s->sites, &s->day, noon, &hi, &err) != TS_OK ||
        ts_sun_at_site(&s->sites, &s->day, noon + 43200.0, &lo, &err) != TS_OK)
        return 1;
    return hi.elevation + TS_SUN_RADIUS_DEG <= 0 ? 0 : lo.elevation + TS_SUN_RADIUS_DEG > 0 ? 2 : 1;
}

/* Blocks of a range across the edge of a polar night or midnight sun (or
 * holding a whole short one),
 * where the sun's hours change too fast for one day to stand for others
 * (6.2 h for 10.5 h over 12 days at 70 N: session 59's audit): a sentence
 * where they put the flat ground's sun hours at the DEM's centre
 * POLAR_EDGE_ERROR off, over the range or its first year (a century's
 * blocks would take seconds; the error repeats year by year). */
static int polar_edge_warning(const tsd_sun *s, const tsd_options *o, char *warning, size_t n)
{
    const size_t centre = centre_node(&s->sites_owned);
    const double lat = s->sites_owned.lat[centre], lon = s->sites_owned.lon[centre];
    if (o->day_interval <= 1 || fabs(lat) < POLAR_EDGE_LATITUDE)
        return 0;
    const size_t steps = (size_t)ts_day_step_count(86400.0, s->range.step_minutes * 60.0);
    double *mid = malloc(steps * sizeof *mid), *dur = malloc(steps * sizeof *dur);
    double off = 0, total = 0, worst = 0, worst_all = 0, worst_one = 0;
    int worst_block = -1, kind = 1, days = 0;
    if (!mid || !dur)
        days = 366; /* (no memory: no warning) */
    for (int i = 0; i < s->range_sampled && days < 366; i++) {
        int first, length, sampled;
        ts_date_range_block(&s->range, s->range_days, i, &first, &length, &sampled);
        days += length;
        const double one = length * flat_sun_hours(s, s->day_start + sampled * 86400.0, mid, dur);
        total += one;
        /* every day's kind: between ~63 and ~68 degrees a whole polar night
         * fits within a block, its first and last days rising and setting */
        int kinds = 0; /* the kinds seen, a bit each */
        for (int d = first; d < first + length; d++)
            kinds |= 1 << day_kind(s, s->day_start + d * 86400.0, lon);
        if (kinds == 1 << 0 || kinds == 1 << 1 || kinds == 1 << 2)
            continue;
        double all = 0;
        for (int d = first; d < first + length; d++)
            all += flat_sun_hours(s, s->day_start + d * 86400.0, mid, dur);
        off += one - all;
        total += all - one;
        if (fabs(one - all) >= worst) {
            worst = fabs(one - all);
            worst_all = all;
            worst_one = one;
            worst_block = i;
            kind = kinds & 1 << 0 ? 0 : 2;
        }
    }
    free(mid);
    free(dur);
    if (worst_block < 0 || !(fabs(off) >= 1.0 && fabs(off) > POLAR_EDGE_ERROR * total))
        return 0;
    int first, length, sampled;
    ts_date_range_block(&s->range, s->range_days, worst_block, &first, &length, &sampled);
    char from[40], to[40], day[40];
    tsd_format_time(s->day_start + first * 86400.0, s->offset_minutes, from, sizeof from);
    tsd_format_time(s->day_start + (first + length - 1) * 86400.0, s->offset_minutes, to,
                    sizeof to);
    tsd_format_time(s->day_start + sampled * 86400.0, s->offset_minutes, day, sizeof day);
    snprintf(warning, n,
             "DAY_INTERVAL=%d counts one computed day for each block of days, and blocks cross "
             "the edge of the %s at the DEM's centre (latitude %.1f), where the sun's hours "
             "change too fast for one day to stand for others: on flat ground there the "
             "block %.10s to %.10s counts %.1f hours of sun from %.10s, where its %d days have "
             "%.1f, and the %s's total is %+.0f %% off (%+.1f of %.1f hours). DAY_INTERVAL=1 "
             "computes every day",
             o->day_interval, kind == 0 ? "polar night" : "midnight sun", lat, from, to,
             worst_one, day, length, worst_all, s->range_days > days ? "first year" : "range",
             100.0 * off / total, off, total);
    return 1;
}

int tsd_sun_range_warning(const tsd_sun *s, const tsd_options *o, char *warning, size_t n)
{
    if (!s->is_range)
        return 0;
    /* a block's days: the interval, or the whole range where it is shorter */
    if (o->day_interval <= RANGE_INTERVAL_WARN_DAYS || s->range_days <= RANGE_INTERVAL_WARN_DAYS)
        return polar_edge_warning(s, o, warning, n);
    snprintf(warning, n,
             "DAY_INTERVAL=%d computes one day of every %d of the range (%d days, %d "
             "computed) and counts it for the others: the sun's days change with the "
             "seasons across such a block, so the total can be off by percents (one day "
             "for a whole year read 30 %% more sun hours at 46.5 N than every 14 days). "
             "At most %d (14 by default) keeps it within about a percent",
             o->day_interval, o->day_interval, s->range_days, s->range_sampled,
             RANGE_INTERVAL_WARN_DAYS);
    return 1;
}

int tsd_sun_night_warning(const tsd_sun *s, const tsd_options *o, char *warning, size_t n)
{
    const char *product = tsd_product_of(o)->name;
    if (!isfinite(s->instant) || (strcmp(product, "shade") != 0 && strcmp(product, "shadow") != 0))
        return 0;
    /* no cell's horizon dips below the sea-level one from the highest terrain;
     * per cell, night only where the sun is that low at every lattice node
     * (the middle node's sun may have set while the DEM's west is in sun) */
    const double lowest = ts_earth_horizon(TSD_EARTH_HIGHEST_M, &s->day.horizon);
    ts_sun_sample sun = s->sun;
    int node = 0;
    ts_error err;
    if (tsd_sun_per_cell(s) &&
        ts_sun_highest_site(&s->sites, &s->day, s->instant, &sun, &node, &err) != TS_OK)
        return 0;
    if (!(sun.elevation + o->light_radius < lowest))
        return 0;
    /* in the polar night no time of that day helps: say so, not the offset.
     * The sun climbs highest at the site nearest the equator (per cell: the
     * lattice's least or greatest latitude), sampled every 10 minutes. */
    int ends[2] = {0, 0};
    for (int k = 1; k < s->sites.nx * s->sites.ny; k++) {
        ends[0] = s->sites.latitude[k] < s->sites.latitude[ends[0]] ? k : ends[0];
        ends[1] = s->sites.latitude[k] > s->sites.latitude[ends[1]] ? k : ends[1];
    }
    double day_max = sun.elevation;
    for (int e = 0; e < 2; e++) {
        ts_sun_sites one = {1, 1, 0, 0, 1, 1, s->sites.longitude + ends[e],
                            s->sites.latitude + ends[e], NULL};
        for (int k = -72; k <= 72 && day_max + o->light_radius < lowest; k++) {
            ts_sun_sample at;
            if (ts_sun_at_site(&one, &s->day, s->instant + k * 600.0, &at, &err) == TS_OK)
                day_max = fmax(day_max, at.elevation);
        }
    }
    const int polar = day_max + o->light_radius < lowest;
    /* mean solar time at the site: UTC plus 4 minutes per degree east */
    const double lon = s->sites_owned.lon[node];
    const long solar = lround(fmod(fmod(s->instant / 60.0 + lon * 4.0, 1440.0) + 1440.0, 1440.0));
    char when[64], given[48], at[OFFSET_TEXT];
    tsd_format_instant(s->instant, s->offset_minutes, when, sizeof when);
    offset_text((int)lround(lon * 4.0), at);
    if (s->offset_minutes == 0) {
        snprintf(given, sizeof given, "Z is UTC itself");
    } else {
        char off[OFFSET_TEXT];
        offset_text(s->offset_minutes, off);
        snprintf(given, sizeof given, "given as %s", off);
    }
    int len = snprintf(warning, n,
                       "DATETIME=%s puts the sun's centre %.1f degrees below the horizon at %s "
                       "(mean solar time %02ld:%02ld there): it is night, no terrain sees the "
                       "sun, and its direct light is nil everywhere. ",
                       when, -sun.elevation,
                       tsd_sun_per_cell(s) ? "the highest of the SUN_POSITION=per_cell sites"
                                           : "the DEM's centre",
                       solar / 60 % 24, solar % 60);
    if (len < 0 || (size_t)len >= n)
        return 1;
    if (polar)
        snprintf(warning + len, n - (size_t)len,
                 "The sun stays below every horizon for 12 hours either side (polar night): "
                 "no time of that day lights the DEM");
    else
        snprintf(warning + len, n - (size_t)len,
                 "If that is not the time meant, check DATETIME's offset from UTC (%s; mean "
                 "solar time at longitude %.1f is UTC%s)",
                 given, lon, at);
    return 1;
}

/* DELTA_T moves the sun along the ecliptic (the planetary theory runs on
 * TT; the Earth's turn on UT), at its mean 360 deg a tropical year: an
 * error worth a word from 0.01 deg (~880 s: before ~1130, after ~2370). */
#define SUN_DEG_PER_S (360.0 / (365.2422 * 86400.0))
#define DELTA_T_WARN_DEG 0.01

int tsd_sun_delta_t_warning(const tsd_sun *s, const tsd_options *o, char *warning, size_t n)
{
    const double t = isfinite(s->instant) ? s->instant : s->day_start;
    if (tsd_options_given(o, "DELTA_T") || !isfinite(t))
        return 0;
    const double year = 1970.0 + t / (365.2425 * 86400.0);
    const double est = tsd_delta_t_estimate(year);
    /* the calendar year of the date as given (its local time: a day
     * product's local midnight east of UTC is the year before's in UTC),
     * where the fractional year above may fall a day short of 1 January */
    char iso[64];
    tsd_format_instant(t, s->offset_minutes, iso, sizeof iso);
    const int calendar_year = atoi(iso);
    if (!(fabs(est - o->delta_t) * SUN_DEG_PER_S > DELTA_T_WARN_DEG))
        return 0;
    const double give = est > 8000 ? 8000 : est < -8000 ? -8000 : est;
    snprintf(warning, n,
             "DELTA_T (TT - UT) was not given: its default, %g s, is the 2020s' value, where "
             "Espenak & Meeus estimate %.0f s for the year %d%s, which moves the sun by "
             "%.2f deg along the ecliptic. Give DELTA_T=%.0f%s",
             o->delta_t, est, calendar_year, year > 2025 ? " (an extrapolation)" : "",
             fabs(est - o->delta_t) * SUN_DEG_PER_S, give,
             give != est ? " (the SPA takes at most 8000 s)" : "");
    return 1;
}
