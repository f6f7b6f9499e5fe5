/* The options that depend on each other and on the product's table row. */
#include "tsd_options.h"

#include "day_cycle.h"
#include "tsd_compute_env.h"
#include "tsd_options_light.h"
#include "tsd_products.h"
#include "tsd_pyramid.h"
#include "tsd_sun.h"
#include "tsd_text.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *tsd_options_product_name(const tsd_options *o)
{
    return tsd_product_of(o)->name;
}

int tsd_options_band_count(const tsd_options *o)
{
    return tsd_product_of(o)->band_count(o);
}

int tsd_options_output_byte(const tsd_options *o)
{
    switch (tsd_product_of(o)->byte) {
    case TSD_BYTE_ALWAYS: return 1;
    case TSD_BYTE_AUTO: return o->output_type != TSD_OUT_FLOAT32;
    default: return o->output_type == TSD_OUT_BYTE;
    }
}

ts_edge_mode tsd_options_edge(const tsd_options *o)
{
    static const ts_edge_mode modes[] = {TS_EDGE_HORIZON, TS_EDGE_OPEN, TS_EDGE_NODATA};
    if (!tsd_product_takes(tsd_product_of(o), tsd_option_find("EDGE")) || o->edge < 0 ||
        o->edge > 2)
        return TS_EDGE_OPEN;
    /* Negative openness sweeps the negated DEM. Ground beyond the edge at
     * sea level or higher bounds a horizon from below, not a negated one:
     * taken as the negated sea-level plane, it stood as a wall above every
     * negated height, so that a plane at 2000 m read 59 deg in its middle.
     * It sees the DEM alone there (docs/driver.md, openness). */
    if (modes[o->edge] == TS_EDGE_HORIZON && tsd_sweeps_negated_dem(o))
        return TS_EDGE_OPEN;
    return modes[o->edge];
}

int tsd_options_sun_from_time(const tsd_options *o)
{
    const tsd_product_def *p = tsd_product_of(o);
    return p->daily || (o->datetime[0] && tsd_product_takes(p, tsd_option_find("DATETIME")));
}

/* "shade, shadow, svf, sky, daycycle": the products that may be Byte. */
static void byte_products(char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < tsd_product_count() && used < n; i++) {
        const tsd_product_def *p = tsd_product_at(i);
        if (p->byte == TSD_BYTE_AUTO || p->byte == TSD_BYTE_ALLOWED)
            used += (size_t)snprintf(buf + used, n - used, "%s%s", used ? ", " : "",
                                     p->name);
    }
}

/* Refuse the combination with a sentence. */
#define REFUSE(...) return (tsd_fail(msg, n, TS_ERR_ARG, __VA_ARGS__), -1)

int tsd_options_is_range(const tsd_options *o)
{
    return o->start_date[0] != '\0';
}

int tsd_options_step_minutes(const tsd_options *o)
{
    if (tsd_options_is_range(o) && !tsd_options_given(o, "STEP_MINUTES"))
        return (int)TS_RANGE_STEP_MINUTES;
    return o->step_minutes;
}

/* A date range (START_DATE, END_DATE, DAY_INTERVAL, HORIZON_DIRECTIONS) of
 * sunhours and insolation; the core checks the range itself. */
static int check_range(const tsd_options *o, char *msg, size_t n)
{
    const tsd_product_def *p = tsd_product_of(o);
    const int o_start = tsd_option_find("START_DATE");
    char list[256];
    tsd_products_taking(o_start, "PRODUCT=", " and ", list, sizeof list);
    if (o->end_date[0] && !o->start_date[0])
        REFUSE("END_DATE=%s needs START_DATE, the first day of the range (for one day "
               "give DATE)", o->end_date);
    /* as ENV_ROTATION: a value other than the default that would do nothing */
    if (!o->start_date[0] && (o->day_interval != TS_RANGE_DAY_INTERVAL ||
                              o->horizon_directions != TS_RANGE_HORIZON_DIRECTIONS))
        REFUSE("%s applies to a date range (START_DATE, END_DATE) of %s; one day "
               "(DATE or DATETIME) has none",
               o->day_interval != TS_RANGE_DAY_INTERVAL ? "DAY_INTERVAL" : "HORIZON_DIRECTIONS",
               list);
    if (!o->start_date[0])
        return 0;
    if (!tsd_product_takes(p, o_start))
        REFUSE("a date range (START_DATE, END_DATE) applies to %s, not to PRODUCT=%s%s",
               list, p->name, p->daily ? ": give its day as DATE" : "");
    if (o->date[0])
        REFUSE("give DATE (one day) or START_DATE (a date range), not both");
    if (o->datetime[0])
        REFUSE("give DATETIME (its day) or START_DATE (a date range), not both");
    if (!o->timezone[0])
        REFUSE("START_DATE=%s needs TIMEZONE, the offset from UTC of its local days (e.g. "
               "TIMEZONE=+02:00, or Z for UTC): without it the days' start is unknown",
               o->start_date);
    /* at open, as the other combinations (the core refuses it too, on the first read) */
    if (o->sun_position == TSD_SUN_PER_CELL)
        REFUSE("SUN_POSITION=per_cell is not supported over a date range (START_DATE): its "
               "sun is computed at one site, the DEM's centre; give SUN_POSITION=center");
    ts_date_range r;
    return tsd_sun_date_range(o, &r, NULL, NULL, msg, n) == TS_OK ? 0 : -1;
}

/* The options of environment light (ENV_MAP, SKY and theirs). */
static int check_environment(const tsd_options *o, char *msg, size_t n)
{
    static const char *const own[] = {"ENV_MAP", "SKY", "ENV_ROTATION", "ENV_HORIZON_STEPS",
                                      "ENV_NORMAL_STEPS", "EXPOSURE"};
    const tsd_product_def *p = tsd_product_of(o);
    const int envlight = tsd_product_takes(p, tsd_option_find("EXPOSURE"));
    char list[256];
    /* what each holds other than its declared default: given with its
     * default, an option of another product is no mistake (the warning of
     * unused options names it), as METHOD=exact with svf */
    double stops;
    enum { MAP, SKY, ROTATION, HORIZON_STEPS, NORMAL_STEPS, EXPOSURE }; /* (own's order) */
    const int set[] = {[MAP] = o->env_map[0] != '\0', [SKY] = o->sky[0] != '\0',
                       [ROTATION] = o->env_rotation != 0,
                       [HORIZON_STEPS] = o->env_horizon_steps != TS_ENV_DEFAULT_HORIZON_STEPS,
                       [NORMAL_STEPS] = o->env_normal_steps != TS_ENV_DEFAULT_NORMAL_STEPS,
                       [EXPOSURE] = tsd_exposure_parse(o->exposure, &stops) == 0};
    for (size_t i = 0; i < sizeof own / sizeof own[0]; i++) {
        int id = tsd_option_find(own[i]);
        if (set[i] && !tsd_product_takes(p, id)) {
            tsd_products_taking(id, "PRODUCT=", " and ", list, sizeof list);
            REFUSE("%s applies to %s, not to PRODUCT=%s", own[i], list, p->name);
        }
    }
    if (o->env_map[0] && o->sky[0])
        REFUSE("give ENV_MAP or SKY, not both: both are the light of the sky (SKY=%s "
               "excludes ENV_MAP=%s)", o->sky, o->env_map);
    if (envlight && !o->env_map[0] && !o->sky[0])
        REFUSE("PRODUCT=%s needs a light: ENV_MAP=<an OpenEXR map> or "
               "SKY=uniform|overcast|clear|cie:N", p->name);
    tsd_options d; /* (a sun given at its defaults is warned of, as unused) */
    tsd_options_defaults(&d);
    if (o->env_map[0] && envlight && (o->sun_azimuth != d.sun_azimuth ||
                                      o->sun_elevation != d.sun_elevation || o->datetime[0]))
        REFUSE("PRODUCT=%s with ENV_MAP is lit by the map alone: SUN_AZIMUTH, "
               "SUN_ELEVATION and DATETIME place the sun of a SKY", p->name);
    if (set[ROTATION] && !o->env_map[0])
        REFUSE("ENV_ROTATION turns ENV_MAP; a SKY turns with its sun (SUN_AZIMUTH or "
               "DATETIME)");
    /* as ENV_ROTATION: shade's sky term without SKY or ENV_MAP is the
     * sky-view factor's uniform sky, which has no table (session 57's audit:
     * taken without a word) */
    const char *steps = set[HORIZON_STEPS]  ? "ENV_HORIZON_STEPS"
                        : set[NORMAL_STEPS] ? "ENV_NORMAL_STEPS"
                                            : NULL;
    if (steps && !envlight && !(o->sky_weight > 0))
        REFUSE("%s sets the light table of PRODUCT=%s's sky term, which SKY_WEIGHT=0 leaves "
               "out: give SKY_WEIGHT > 0 and a SKY or ENV_MAP", steps, p->name);
    if (steps && !o->env_map[0] && !o->sky[0])
        REFUSE("%s sets the light table of SKY or ENV_MAP; without them PRODUCT=%s's sky "
               "term is the sky-view factor's uniform sky, which has none: give a SKY "
               "(uniform, overcast, clear, cie:N) or ENV_MAP with it",
               steps, p->name);
    if (!envlight && (o->env_map[0] || o->sky[0]) && !(o->sky_weight > 0))
        REFUSE("%s sets the sky term of PRODUCT=%s, which SKY_WEIGHT=0 leaves out: give "
               "SKY_WEIGHT > 0", o->env_map[0] ? "ENV_MAP" : "SKY", p->name);
    /* a node at 0 degrees, where open flat ground has its normal and horizon */
    if (o->env_normal_steps == 1 || (o->env_normal_steps && o->env_normal_steps % 2 == 0))
        REFUSE("ENV_NORMAL_STEPS must be 0 (exact) or odd (3, 5, ...: a node at 0 degrees, "
               "the normal of flat ground), got %d", o->env_normal_steps);
    if (o->env_horizon_steps % 2 == 0)
        REFUSE("ENV_HORIZON_STEPS must be odd (3, 5, ..., 181: a node at 0 degrees, the "
               "horizon of open flat ground, which else reads too little light), got %d",
               o->env_horizon_steps);
    /* (EXPOSURE=AUTO, the default, is no mistake) */
    if (set[EXPOSURE] && !tsd_options_output_byte(o))
        REFUSE("EXPOSURE applies to OUTPUT_TYPE=Byte (the display image); Float32 "
               "keeps the light's own values");
    return 0;
}

/* The fewest DIRECTIONS of an integral over the sky (svf, openness, sky,
 * envlight, the sky terms of shade and insolation): with 1 to 3 azimuths
 * the sum is no integral (an 80 degree open plane read svf 0.005 or 0.17
 * with one, by START_AZIMUTH); 4, along the grid's axes, is the least that
 * sees every side. */
#define INTEGRAL_DIRECTIONS_MIN 4

static int check_integral_directions(const tsd_options *o, char *msg, size_t n)
{
    const tsd_product_def *p = tsd_product_of(o);
    const int per_band = p->bands_option && strcmp(p->bands_option, "DIRECTIONS") == 0;
    const int weighted = tsd_product_takes(p, tsd_option_find("SKY_WEIGHT"));
    if (!tsd_product_takes(p, tsd_option_find("DIRECTIONS")) || per_band ||
        (weighted && !(o->sky_weight > 0)) || o->directions >= INTEGRAL_DIRECTIONS_MIN)
        return 0;
    /* shade's SKY_WEIGHT term and insolation's diffuse light are sky terms */
    REFUSE("DIRECTIONS=%d is too few for PRODUCT=%s: its %s is an integral over the sky's "
           "azimuths; give at least %d (16 by default; 32 or more on steep ground)",
           o->directions, p->name, weighted || p->daily ? "sky term" : "value",
           INTEGRAL_DIRECTIONS_MIN);
}

/* The SH options: ENV_METHOD, METHOD=sh's key light. */
static int check_sh(const tsd_options *o, char *msg, size_t n)
{
    const tsd_product_def *p = tsd_product_of(o);
    const int o_env_method = tsd_option_find("ENV_METHOD");
    char list[256];
    if (o->env_method != TSD_ENV_TABLE && !tsd_product_takes(p, o_env_method)) {
        tsd_products_taking(o_env_method, "PRODUCT=", " and ", list, sizeof list);
        REFUSE("ENV_METHOD=sh applies to %s only, not to PRODUCT=%s%s", list, p->name,
               tsd_product_takes(p, tsd_option_find("METHOD"))
                   ? ": its soft SH key light is METHOD=sh"
                   : "");
    }
    /* as ENV_ROTATION: a value other than the default that would do nothing */
    const int o_swath = tsd_option_find("SWATH_DIRECTIONS");
    if (o->swath_directions != atoi(tsd_option_default(o_swath)) && o->method != TSD_METHOD_SH)
        REFUSE("SWATH_DIRECTIONS=%d sets the horizon sweeps of METHOD=sh's key light; "
               "give METHOD=sh with it (PRODUCT=shade and PRODUCT=shadow)",
               o->swath_directions);
    if (o->method == TSD_METHOD_SH && o->sun_position == TSD_SUN_PER_CELL)
        REFUSE("METHOD=sh lights with one key light, the sun at the DEM's centre: "
               "SUN_POSITION=per_cell needs METHOD=exact");
    return 0;
}

int tsd_options_check(const tsd_options *o, char *msg, size_t n)
{
    const tsd_product_def *p = tsd_product_of(o);
    const char *pn = p->name;
    const int o_method = tsd_option_find("METHOD"), o_datetime = tsd_option_find("DATETIME"),
              o_date = tsd_option_find("DATE");
    const int from_time = tsd_options_sun_from_time(o);
    char list[256];
    if (p->byte == TSD_BYTE_ALWAYS && o->output_type == TSD_OUT_FLOAT32)
        REFUSE("PRODUCT=%s is binary: its bands are Byte (0 lit, 1 in far "
                    "shadow, 255 nodata); OUTPUT_TYPE=Float32 does not apply", pn);
    if (o->output_type == TSD_OUT_BYTE && p->byte == TSD_BYTE_NEVER) {
        byte_products(list, sizeof list);
        REFUSE("OUTPUT_TYPE=Byte is only for the products with values in "
               "0..1 (%s); PRODUCT=%s is in %s", list, pn, p->values);
    }
    if (o->method != TSD_METHOD_EXACT && !tsd_product_takes(p, o_method)) {
        tsd_products_taking(o_method, "PRODUCT=", " and ", list, sizeof list);
        REFUSE("METHOD=%s applies to %s only, not to PRODUCT=%s",
               o->method == TSD_METHOD_SH    ? "sh"
               : o->method == TSD_METHOD_SHM ? "shm"
                                             : "shadowmap",
               list, pn);
    }
    if (tsd_options_check_light(o, msg, n) != 0)
        return -1;
    /* a model chosen for another product is a mistake, not a no-op */
    if (o->svf_model != 0 && !tsd_product_takes(p, tsd_option_find("SVF_MODEL")))
        REFUSE("SVF_MODEL=solid_angle applies to PRODUCT=svf only, not to PRODUCT=%s", pn);
    if (o->edge != 0 && !tsd_product_takes(p, tsd_option_find("EDGE"))) {
        tsd_products_taking(tsd_option_find("EDGE"), "", ", ", list, sizeof list);
        REFUSE("EDGE applies to the products that see past the DEM's edge (%s), not to "
               "PRODUCT=%s", list, pn);
    }
    if (o->openness_negative && !tsd_product_takes(p, tsd_option_find("OPENNESS")))
        REFUSE("OPENNESS=negative applies to PRODUCT=openness only, not to PRODUCT=%s", pn);
    if (o->datetime[0] && !tsd_product_takes(p, o_datetime)) {
        tsd_products_taking(o_datetime, "", " and ", list, sizeof list);
        REFUSE("DATETIME applies to PRODUCT=%s, not to PRODUCT=%s", list, pn);
    }
    if (o->date[0] && !tsd_product_takes(p, o_date)) {
        tsd_products_taking(o_date, "", ", ", list, sizeof list);
        REFUSE("DATE applies to the day products (%s), not to PRODUCT=%s%s", list, pn,
               tsd_product_takes(p, o_datetime) ? "; give the sun's instant as DATETIME"
                                                : "");
    }
    if (o->date[0] && o->datetime[0])
        REFUSE("give DATE (with TIMEZONE) or DATETIME, not both: both name the day");
    if (check_range(o, msg, n) != 0)
        return -1;
    if (p->daily && !o->date[0] && !o->datetime[0] && !o->start_date[0])
        REFUSE("PRODUCT=%s needs a day: DATE=YYYY-MM-DD with TIMEZONE (e.g. "
                    "+02:00), or DATETIME with an offset%s", pn,
               tsd_product_takes(p, tsd_option_find("START_DATE"))
                   ? "; or days: START_DATE (and END_DATE) with TIMEZONE"
                   : "");
    if (o->date[0] && !o->timezone[0])
        REFUSE("DATE=%s needs TIMEZONE, the offset from UTC of its local day (e.g. "
                    "TIMEZONE=+02:00, or Z for UTC): without it the day's start is "
                    "unknown", o->date);
    if (o->timezone[0] && !o->date[0] && !o->start_date[0] && !(o->datetime[0] && p->daily))
        REFUSE("TIMEZONE applies with DATE (or DATETIME) to the day products only");
    /* (at their defaults, 315 and 45, they are warned of as doing nothing:
     * a script's one set of options, tsd_options_unused) */
    tsd_options d;
    tsd_options_defaults(&d);
    const int az_set = o->sun_azimuth != d.sun_azimuth,
              el_set = o->sun_elevation != d.sun_elevation;
    if (from_time && (az_set || el_set))
        REFUSE("%s places the sun: do not give %s with it",
                    o->datetime[0] ? "DATETIME" : o->start_date[0] ? "START_DATE" : "DATE",
                    az_set ? "SUN_AZIMUTH" : "SUN_ELEVATION");
    if (p->daily && o->sun_position == TSD_SUN_PER_CELL &&
        !tsd_product_takes(p, tsd_option_find("SUN_POSITION")))
        REFUSE("PRODUCT=%s computes the sun at the DEM's centre only "
                    "(SUN_POSITION=center)", pn);
    /* the reason is farshadow's, the one product without MAX_DISTANCE */
    if (o->max_distance > 0 && !tsd_product_takes(p, tsd_option_find("MAX_DISTANCE")))
        REFUSE("MAX_DISTANCE does not apply to PRODUCT=%s (its far shadows "
                    "start at FAR_THRESHOLD cells and have no end)", pn);
    if (o->sun_position == TSD_SUN_PER_CELL &&
        !tsd_product_takes(p, tsd_option_find("SUN_POSITION"))) {
        tsd_products_taking(tsd_option_find("SUN_POSITION"), "PRODUCT=", " and ", list,
                            sizeof list);
        REFUSE("SUN_POSITION=per_cell applies to %s, not to PRODUCT=%s", list, pn);
    }
    if (o->sun_position == TSD_SUN_PER_CELL && !from_time)
        REFUSE("SUN_POSITION=per_cell needs the sun from DATETIME or DATE");
    if (check_integral_directions(o, msg, n) != 0 || tsd_options_check_pyramid(o, msg, n) != 0 ||
        check_sh(o, msg, n) != 0)
        return -1;
    return check_environment(o, msg, n);
}
