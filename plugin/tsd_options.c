/* The TERRASHADE driver's options: declaration, parsing, validation. */
#include "tsd_options.h"

#include "day_cycle.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

typedef enum { T_SELECT, T_FLOAT, T_INT, T_BOOL, T_STRING } opt_type;

typedef enum {
    O_PRODUCT, O_SUN_AZIMUTH, O_SUN_ELEVATION, O_DIRECTIONS, O_START_AZIMUTH,
    O_METHOD, O_PENUMBRA_DEPTH, O_Z_FACTOR, O_MAX_DISTANCE, O_CURVATURE,
    O_REFRACTION, O_SKY_WEIGHT, O_BAND, O_THREADS, O_OUTPUT_TYPE,
    O_MAX_MEMORY, O_DATETIME, O_DATE, O_TIMEZONE, O_STEP_MINUTES, O_PRESSURE,
    O_TEMPERATURE, O_DELTA_T, O_SUN_POSITION, O_LINKE_TURBIDITY, O_FAR_THRESHOLD,
    O_ATLAS_STEPS, O_BACKEND, O_SUNHOURS_RULE, O_PROGRESS, O_COUNT
} opt_id;

typedef struct {
    const char *name;
    opt_type type;
    const char *def;      /* default, as written in the option list */
    double min, max;      /* inclusive range (numbers) */
    int min_exclusive;    /* value must be > min */
    int has_max;          /* 0: no upper bound */
    const char *values;   /* T_SELECT: '|'-separated, first is default */
    int affects_pixels;   /* part of the canonical string */
    const char *desc;
} opt_def;

static const opt_def OPTS[O_COUNT] = {
    {"PRODUCT", T_SELECT, "shade", 0, 0, 0, 0,
     "shade|shadow|horizon|svf|openness|sky|sunhours|insolation|daycycle|farshadow", 1,
     "What to compute: shade (sun-lit relief with cast shadows), shadow "
     "(visible fraction of the sun's disk, 0..1), horizon (one band per "
     "azimuth, horizon elevation angle in degrees), svf (sky-view factor "
     "0..1), openness (positive openness, degrees), sky (uniform-sky "
     "irradiance 0..1), sunhours (hours of direct sun on DATE), insolation "
     "(clear-sky irradiation on DATE, Wh/m2: total, beam, diffuse), daycycle "
     "(visible fraction of the sun, one band per STEP_MINUTES), farshadow "
     "(binary far-shadow maps of ATLAS_STEPS sun positions)"},
    {"SUN_AZIMUTH", T_FLOAT, "315", 0, 360, 0, 1, NULL, 1,
     "Sun azimuth in degrees clockwise from (grid) north (as gdaldem -az); "
     "not with DATETIME"},
    {"SUN_ELEVATION", T_FLOAT, "45", -90, 90, 0, 1, NULL, 1,
     "Sun elevation in degrees above the horizontal (as gdaldem -alt); not "
     "with DATETIME"},
    {"DIRECTIONS", T_INT, "16", 1, 3600, 0, 1, NULL, 1,
     "Number of azimuths of the horizon, svf, openness and sky products "
     "and of the sky term of shade"},
    {"START_AZIMUTH", T_FLOAT, "0", 0, 360, 0, 1, NULL, 1,
     "First of the DIRECTIONS azimuths, degrees from north; the others "
     "follow every 360/DIRECTIONS degrees"},
    {"METHOD", T_SELECT, "exact", 0, 0, 0, 0, "exact|shm", 1,
     "Shadow method of shade and shadow: exact (horizon sweep, penumbra "
     "from the sun's disk) or shm (shadow height map, faster, approximate)"},
    {"PENUMBRA_DEPTH", T_FLOAT, "0", 0, 1e6, 0, 1, NULL, 1,
     "METHOD=shm: metres below the shadow height over which light fades; "
     "0 = hard shadows"},
    {"Z_FACTOR", T_FLOAT, "1", 0, 1e6, 1, 1, NULL, 1,
     "Multiplies the heights (> 0), e.g. 0.3048 for heights in feet; the "
     "band's scale and offset are applied first"},
    {"MAX_DISTANCE", T_FLOAT, "0", 0, 1e8, 0, 1, NULL, 1,
     "Largest distance in metres at which terrain can cast a shadow or "
     "raise the horizon; 0 = unbounded"},
    {"CURVATURE", T_BOOL, "YES", 0, 0, 0, 0, NULL, 1,
     "Take Earth curvature (with refraction) into account"},
    {"REFRACTION", T_FLOAT, "0.13", 0, 1, 0, 1, NULL, 1,
     "Refraction coefficient k of the curvature correction: drop = (1-k) "
     "d^2 / 2R"},
    {"SKY_WEIGHT", T_FLOAT, "0", 0, 1, 0, 1, NULL, 1,
     "shade only: weight of the light of a uniform sky added to the direct "
     "sun (shade = direct + SKY_WEIGHT * sky); 0 = sun only, as gdaldem"},
    {"BAND", T_INT, "1", 1, 65536, 0, 1, NULL, 1,
     "Band of the DEM holding the heights"},
    {"THREADS", T_INT, "0", 0, 1024, 0, 1, NULL, 0,
     "Worker threads; 0 = one per CPU core"},
    {"OUTPUT_TYPE", T_SELECT, "AUTO", 0, 0, 0, 0, "AUTO|Byte|Float32", 1,
     "Data type: Byte (1..255, 0 = nodata, as gdaldem) or Float32 (0..1 or "
     "degrees, NaN = nodata); AUTO = Byte for shade, Float32 otherwise. "
     "Byte only for the 0..1 products (shade, shadow, svf, sky)"},
    {"MAX_MEMORY", T_INT, "0", 0, 1 << 30, 0, 1, NULL, 0,
     "Refuse to compute a product needing more than this many MiB; 0 = "
     "three quarters of the physical memory"},
    {"DATETIME", T_STRING, "", 0, 0, 0, 0, NULL, 1,
     "Place the sun by date and time (SPA) instead of SUN_AZIMUTH and "
     "SUN_ELEVATION: ISO 8601 with an offset, e.g. 2026-06-21T07:30:00+02:00 "
     "or 2026-06-21T05:30Z (inline: 2026-06-21T073000+0200). With the day "
     "products: the local day that contains it"},
    {"DATE", T_STRING, "", 0, 0, 0, 0, NULL, 1,
     "Day of sunhours, insolation, daycycle and farshadow: YYYY-MM-DD, local "
     "to TIMEZONE"},
    {"TIMEZONE", T_STRING, "", 0, 0, 0, 0, NULL, 1,
     "Fixed offset from UTC of the local day: Z, +hh:mm, -hh:mm, +hhmm; "
     "needed with DATE; with DATETIME it defaults to DATETIME's offset"},
    {"STEP_MINUTES", T_INT, "5", 1, 240, 0, 1, NULL, 1,
     "Time step of sunhours, insolation and daycycle, minutes"},
    {"PRESSURE", T_FLOAT, "1013.25", 0, 5000, 1, 1, NULL, 1,
     "Mean air pressure at the DEM, hPa (atmospheric refraction of the sun)"},
    {"TEMPERATURE", T_FLOAT, "15", -273, 6000, 1, 1, NULL, 1,
     "Mean air temperature at the DEM, degrees Celsius (atmospheric "
     "refraction of the sun)"},
    {"DELTA_T", T_FLOAT, "69", -8000, 8000, 0, 1, NULL, 1,
     "TT - UT in seconds (about 69 in the 2020s)"},
    {"SUN_POSITION", T_SELECT, "center", 0, 0, 0, 0, "center|per_cell", 1,
     "Where the sun is computed from: the DEM's centre (center), or every "
     "cell (per_cell: the SPA on a lattice over the DEM, interpolated), for "
     "extents of a few degrees or more"},
    {"LINKE_TURBIDITY", T_FLOAT, "3", 1, 10, 0, 1, NULL, 1,
     "Linke turbidity factor of the clear-sky model of insolation (2 very "
     "clear, 3 clear, 5 hazy)"},
    {"FAR_THRESHOLD", T_INT, "512", 1, 1000000, 0, 1, NULL, 1,
     "farshadow: occluders nearer than this many cells are left out (they "
     "are recomputed on read)"},
    {"ATLAS_STEPS", T_INT, "158", 1, 1024, 0, 1, NULL, 1,
     "farshadow: number of sun positions between sunrise and sunset, denser "
     "near dawn and dusk"},
    {"BACKEND", T_SELECT, "auto", 0, 0, 0, 0, "auto|opencl|c", 0,
     "Where the horizon sweeps, shadow height maps, normals and direct sun "
     "of shade, shadow, horizon, svf, openness and sky run: opencl (falls "
     "back to c, with a warning, when OpenCL cannot run), c (the "
     "multithreaded C core), or auto (the environment variable "
     "TERRASHADE_BACKEND, else OpenCL on a GPU or accelerator or on a device "
     "named by TERRASHADE_OPENCL_DEVICE, else c). The metadata item BACKEND "
     "says what ran"},
    {"SUNHOURS_RULE", T_SELECT, "visible", 0, 0, 0, 0, "visible|fraction", 1,
     "sunhours: what a time step counts: visible (the whole step while any "
     "part of the sun's disk is above the cell's horizon; on a flat plane "
     "the astronomical day length, sunrise to sunset by the upper limb) or "
     "fraction (the step times the visible fraction of the disk; on a flat "
     "plane the time the sun's centre is up)"},
    {"PROGRESS", T_SELECT, "auto", 0, 0, 0, 0, "auto|yes|no", 0,
     "Print the progress of the computation to stderr: yes, no, or auto "
     "(when stderr is a terminal and the computation takes more than a "
     "second)"},
};

static int fail(char *msg, size_t n, const char *fmt, ...)
{
    if (msg && n) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, n, fmt, ap);
        va_end(ap);
    }
    return -1;
}

static const char *const PRODUCT_NAMES[] = {
    "shade", "shadow", "horizon", "svf", "openness", "sky",
    "sunhours", "insolation", "daycycle", "farshadow"};

const char *tsd_product_name(tsd_product p)
{
    return (unsigned)p < sizeof PRODUCT_NAMES / sizeof PRODUCT_NAMES[0]
               ? PRODUCT_NAMES[p] : "?";
}

int tsd_product_is_daily(tsd_product p)
{
    return p == TSD_PRODUCT_SUNHOURS || p == TSD_PRODUCT_INSOLATION ||
           p == TSD_PRODUCT_DAYCYCLE || p == TSD_PRODUCT_FARSHADOW;
}

int tsd_options_sun_from_time(const tsd_options *o)
{
    return tsd_product_is_daily(o->product) ||
           ((o->product == TSD_PRODUCT_SHADE || o->product == TSD_PRODUCT_SHADOW) &&
            o->datetime[0]);
}

static int all_digits(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (s[i] < '0' || s[i] > '9')
            return 0;
    return 1;
}

void tsd_datetime_normalise(const char *in, char *out, size_t n)
{
    char buf[128];
    size_t k = 0;
    const char *p = in;
    snprintf(out, n, "%s", in);
    if (strchr(in, ':') || strlen(in) > 60)
        return;
    /* date: YYYY-MM-DD or YYYYMMDD */
    if (all_digits(p, 4) && p[4] == '-' && all_digits(p + 5, 2) && p[7] == '-' &&
        all_digits(p + 8, 2)) {
        memcpy(buf, p, 10);
        p += 10;
    } else if (all_digits(p, 8)) {
        memcpy(buf, p, 4);
        buf[4] = '-';
        memcpy(buf + 5, p + 4, 2);
        buf[7] = '-';
        memcpy(buf + 8, p + 6, 2);
        p += 8;
    } else {
        return;
    }
    k = 10;
    if (*p != 'T' && *p != 't' && *p != ' ')
        return;
    buf[k++] = *p++;
    /* time: hhmm[ss[.fff]] */
    if (!all_digits(p, 4))
        return;
    buf[k++] = p[0];
    buf[k++] = p[1];
    buf[k++] = ':';
    buf[k++] = p[2];
    buf[k++] = p[3];
    p += 4;
    if (all_digits(p, 2)) {
        buf[k++] = ':';
        buf[k++] = p[0];
        buf[k++] = p[1];
        p += 2;
        if (*p == '.' || *p == ',') {
            buf[k++] = *p++;
            while (*p >= '0' && *p <= '9' && k < sizeof buf - 16)
                buf[k++] = *p++;
        }
    }
    /* offset: Z, +hh, +hhmm */
    if (*p == '+' || *p == '-') {
        buf[k++] = *p++;
        if (!all_digits(p, 2))
            return;
        buf[k++] = p[0];
        buf[k++] = p[1];
        p += 2;
        if (all_digits(p, 2)) {
            buf[k++] = ':';
            buf[k++] = p[0];
            buf[k++] = p[1];
            p += 2;
        }
    }
    while (*p && k < sizeof buf - 1)
        buf[k++] = *p++;
    buf[k] = '\0';
    snprintf(out, n, "%s", buf);
}

const char *tsd_backend_name(tsd_backend b)
{
    return b == TSD_BACKEND_OPENCL ? "opencl" : b == TSD_BACKEND_C ? "c" : "auto";
}

const char *tsd_method_name(tsd_method m)
{
    return m == TSD_METHOD_SHM ? "shm" : "exact";
}

void tsd_options_defaults(tsd_options *o)
{
    memset(o, 0, sizeof *o);
    o->product = TSD_PRODUCT_SHADE;
    o->sun_azimuth = 315;
    o->sun_elevation = 45;
    o->directions = 16;
    o->start_azimuth = 0;
    o->method = TSD_METHOD_EXACT;
    o->penumbra_depth = 0;
    o->z_factor = 1;
    o->max_distance = 0;
    o->curvature = 1;
    o->refraction = 0.13;
    o->sky_weight = 0;
    o->band = 1;
    o->threads = 0;
    o->output_type = TSD_OUT_AUTO;
    o->max_memory_mb = 0;
    o->step_minutes = 5;
    o->pressure = 1013.25;
    o->temperature = 15;
    o->delta_t = 69;
    o->sun_position = TSD_SUN_CENTER;
    o->linke_turbidity = 3;
    o->far_threshold = 512;
    o->atlas_steps = 158;
    o->backend = TSD_BACKEND_AUTO;
    o->sunhours_fraction = 0;
    o->progress_mode = TSD_PROGRESS_AUTO;
    o->progress = NULL;
    o->progress_user = NULL;
}

/* Copy s without surrounding blanks into buf; returns buf. */
static char *trim(const char *s, size_t len, char *buf, size_t n)
{
    while (len && isspace((unsigned char)*s)) {
        s++;
        len--;
    }
    while (len && isspace((unsigned char)s[len - 1]))
        len--;
    if (len >= n)
        len = n - 1;
    memcpy(buf, s, len);
    buf[len] = '\0';
    return buf;
}

static int find_option(const char *name)
{
    for (int i = 0; i < O_COUNT; i++)
        if (strcasecmp(name, OPTS[i].name) == 0)
            return i;
    return -1;
}

/* Index of value in the '|'-list (case-insensitive), or -1. */
static int select_index(const char *values, const char *value)
{
    int idx = 0;
    size_t len = strlen(value);
    for (const char *p = values; *p; idx++) {
        const char *bar = strchr(p, '|');
        size_t n = bar ? (size_t)(bar - p) : strlen(p);
        if (n == len && strncasecmp(p, value, n) == 0)
            return idx;
        p += n + (bar ? 1 : 0);
    }
    return -1;
}

static int parse_number(const opt_def *d, const char *v, double *out, char *msg,
                        size_t n)
{
    char *end = NULL;
    errno = 0;
    if (d->type == T_INT) {
        long l = strtol(v, &end, 10);
        if (end == v || *end || errno)
            return fail(msg, n, "%s must be a whole number, got '%s'", d->name, v);
        *out = (double)l;
    } else {
        double x = strtod(v, &end);
        if (end == v || *end || !isfinite(x))
            return fail(msg, n, "%s must be a number, got '%s'", d->name, v);
        *out = x;
    }
    double x = *out;
    int low = d->min_exclusive ? !(x > d->min) : !(x >= d->min);
    int high = d->has_max && !(x <= d->max);
    if (low || high) {
        if (d->min_exclusive)
            return fail(msg, n, "%s must be greater than %g and at most %g, got %s",
                        d->name, d->min, d->max, v);
        if (!d->has_max)
            return fail(msg, n, "%s must be at least %g, got %s", d->name, d->min, v);
        return fail(msg, n, "%s must be between %g and %g, got %s", d->name,
                    d->min, d->max, v);
    }
    return 0;
}

static int parse_bool(const char *v, int *out)
{
    static const char *const yes[] = {"YES", "TRUE", "ON", "1"};
    static const char *const no[] = {"NO", "FALSE", "OFF", "0"};
    for (int i = 0; i < 4; i++) {
        if (strcasecmp(v, yes[i]) == 0)
            return *out = 1, 0;
        if (strcasecmp(v, no[i]) == 0)
            return *out = 0, 0;
    }
    return -1;
}

/* Set option `id` from its textual value. */
static int set_option(tsd_options *o, int id, const char *v, char *msg, size_t n)
{
    const opt_def *d = &OPTS[id];
    double x = 0;
    int sel = 0, b = 0;
    if (!*v)
        return fail(msg, n, "%s needs a value (%s=...)", d->name, d->name);
    switch (d->type) {
    case T_SELECT:
        sel = select_index(d->values, v);
        if (sel < 0) {
            char list[256];
            size_t k = 0;
            for (const char *p = d->values; *p && k + 3 < sizeof list; p++) {
                if (*p == '|') {
                    list[k++] = ',';
                    list[k++] = ' ';
                } else {
                    list[k++] = *p;
                }
            }
            list[k] = '\0';
            return fail(msg, n, "%s must be one of %s, got '%s'", d->name, list, v);
        }
        break;
    case T_BOOL:
        if (parse_bool(v, &b) != 0)
            return fail(msg, n, "%s must be YES or NO, got '%s'", d->name, v);
        break;
    case T_FLOAT:
    case T_INT:
        if (parse_number(d, v, &x, msg, n) != 0)
            return -1;
        break;
    case T_STRING:
        if (strlen(v) >= TSD_TEXT_MAX)
            return fail(msg, n, "%s is too long (%zu characters)", d->name, strlen(v));
        break;
    }
    ts_error err;
    if (id == O_DATETIME) {
        char norm[TSD_TEXT_MAX * 2];
        double t;
        tsd_datetime_normalise(v, norm, sizeof norm);
        if (ts_parse_iso8601(norm, &t, NULL, &err) != TS_OK)
            return fail(msg, n, "DATETIME: %s", err.message);
    } else if (id == O_DATE) {
        int y, m, dd;
        if (ts_parse_date(v, &y, &m, &dd, &err) != TS_OK)
            return fail(msg, n, "DATE: %s", err.message);
    } else if (id == O_TIMEZONE) {
        int off;
        if (ts_parse_utc_offset(v, &off, &err) != TS_OK)
            return fail(msg, n, "TIMEZONE: %s", err.message);
    }
    switch ((opt_id)id) {
    case O_PRODUCT: o->product = (tsd_product)sel; break;
    case O_SUN_AZIMUTH: o->sun_azimuth = x; o->sun_azimuth_given = 1; break;
    case O_SUN_ELEVATION: o->sun_elevation = x; o->sun_elevation_given = 1; break;
    case O_DIRECTIONS: o->directions = (int)x; break;
    case O_START_AZIMUTH: o->start_azimuth = x; break;
    case O_METHOD: o->method = (tsd_method)sel; break;
    case O_PENUMBRA_DEPTH: o->penumbra_depth = x; break;
    case O_Z_FACTOR: o->z_factor = x; break;
    case O_MAX_DISTANCE: o->max_distance = x; break;
    case O_CURVATURE: o->curvature = b; break;
    case O_REFRACTION: o->refraction = x; break;
    case O_SKY_WEIGHT: o->sky_weight = x; break;
    case O_BAND: o->band = (int)x; break;
    case O_THREADS: o->threads = (int)x; break;
    case O_OUTPUT_TYPE: o->output_type = (tsd_output_type)sel; break;
    case O_MAX_MEMORY: o->max_memory_mb = (int)x; break;
    case O_DATETIME: snprintf(o->datetime, sizeof o->datetime, "%s", v); break;
    case O_DATE: snprintf(o->date, sizeof o->date, "%s", v); break;
    case O_TIMEZONE: snprintf(o->timezone, sizeof o->timezone, "%s", v); break;
    case O_STEP_MINUTES: o->step_minutes = (int)x; break;
    case O_PRESSURE: o->pressure = x; break;
    case O_TEMPERATURE: o->temperature = x; break;
    case O_DELTA_T: o->delta_t = x; break;
    case O_SUN_POSITION: o->sun_position = (tsd_sun_position)sel; break;
    case O_LINKE_TURBIDITY: o->linke_turbidity = x; break;
    case O_FAR_THRESHOLD: o->far_threshold = (int)x; break;
    case O_ATLAS_STEPS: o->atlas_steps = (int)x; break;
    case O_BACKEND: o->backend = (tsd_backend)sel; break;
    case O_SUNHOURS_RULE: o->sunhours_fraction = sel; break;
    case O_PROGRESS: o->progress_mode = (tsd_progress_mode)sel; break;
    case O_COUNT: break;
    }
    return 0;
}

static void list_names(char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < O_COUNT && used < n; i++)
        used += (size_t)snprintf(buf + used, n - used, "%s%s", i ? ", " : "",
                                 OPTS[i].name);
}

int tsd_options_apply(tsd_options *o, const char *const *kv, char *msg,
                      size_t msg_size)
{
    char seen[O_COUNT][128];
    memset(seen, 0, sizeof seen);
    for (size_t i = 0; kv && kv[i]; i++) {
        const char *item = kv[i];
        const char *eq = strchr(item, '=');
        char key[128], value[128];
        if (!eq)
            return fail(msg, msg_size,
                        "option '%s' is not of the form KEY=VALUE", item);
        trim(item, (size_t)(eq - item), key, sizeof key);
        trim(eq + 1, strlen(eq + 1), value, sizeof value);
        int id = find_option(key);
        if (id < 0 && (strcasecmp(key, "SHADOWS") == 0 || strcasecmp(key, "DEM") == 0))
            return fail(msg, msg_size,
                        "%s is an open option of far-shadow atlas files (.tsa), not of "
                        "TERRASHADE:<dem>", key);
        if (id < 0) {
            char names[512];
            list_names(names, sizeof names);
            return fail(msg, msg_size,
                        "unknown option '%s'; the options are %s (see gdalinfo "
                        "--format TERRASHADE)", key, names);
        }
        if (seen[id][0] && strcasecmp(seen[id], value) != 0)
            return fail(msg, msg_size, "%s is given twice, as %s and as %s",
                        OPTS[id].name, seen[id], value);
        snprintf(seen[id], sizeof seen[id], "%s", value);
        if (set_option(o, id, value, msg, msg_size) != 0)
            return -1;
    }
    return tsd_options_check(o, msg, msg_size);
}

int tsd_options_check(const tsd_options *o, char *msg, size_t msg_size)
{
    const char *pn = tsd_product_name(o->product);
    int sun_product = o->product == TSD_PRODUCT_SHADE ||
                      o->product == TSD_PRODUCT_SHADOW;
    int daily = tsd_product_is_daily(o->product);
    int unit_range = o->product == TSD_PRODUCT_SHADE || o->product == TSD_PRODUCT_SHADOW ||
                     o->product == TSD_PRODUCT_SVF || o->product == TSD_PRODUCT_SKY ||
                     o->product == TSD_PRODUCT_DAYCYCLE;
    if (o->product == TSD_PRODUCT_FARSHADOW && o->output_type == TSD_OUT_FLOAT32)
        return fail(msg, msg_size,
                    "PRODUCT=farshadow is binary: its bands are Byte (0 lit, 1 in far "
                    "shadow, 255 nodata); OUTPUT_TYPE=Float32 does not apply");
    if (o->output_type == TSD_OUT_BYTE && !unit_range &&
        o->product != TSD_PRODUCT_FARSHADOW)
        return fail(msg, msg_size,
                    "OUTPUT_TYPE=Byte is only for the products with values in "
                    "0..1 (shade, shadow, svf, sky, daycycle); PRODUCT=%s is in %s",
                    pn, o->product == TSD_PRODUCT_SUNHOURS     ? "hours"
                        : o->product == TSD_PRODUCT_INSOLATION ? "Wh/m2"
                                                               : "degrees");
    if (o->method == TSD_METHOD_SHM && !sun_product)
        return fail(msg, msg_size,
                    "METHOD=shm applies to PRODUCT=shade and PRODUCT=shadow only, "
                    "not to PRODUCT=%s", pn);
    if (o->datetime[0] && !sun_product && !daily)
        return fail(msg, msg_size,
                    "DATETIME applies to PRODUCT=shade, shadow, sunhours, insolation, "
                    "daycycle and farshadow, not to PRODUCT=%s", pn);
    if (o->date[0] && !daily)
        return fail(msg, msg_size,
                    "DATE applies to the day products (sunhours, insolation, daycycle, "
                    "farshadow), not to PRODUCT=%s%s", pn,
                    sun_product ? "; give the sun's instant as DATETIME" : "");
    if (o->date[0] && o->datetime[0])
        return fail(msg, msg_size,
                    "give DATE (with TIMEZONE) or DATETIME, not both: both name the day");
    if (daily && !o->date[0] && !o->datetime[0])
        return fail(msg, msg_size,
                    "PRODUCT=%s needs a day: DATE=YYYY-MM-DD with TIMEZONE (e.g. "
                    "+02:00), or DATETIME with an offset", pn);
    if (o->date[0] && !o->timezone[0])
        return fail(msg, msg_size,
                    "DATE=%s needs TIMEZONE, the offset from UTC of its local day (e.g. "
                    "TIMEZONE=+02:00, or Z for UTC): without it the day's start is "
                    "unknown", o->date);
    if (o->timezone[0] && !o->date[0] && !(o->datetime[0] && daily))
        return fail(msg, msg_size,
                    "TIMEZONE applies with DATE (or DATETIME) to the day products only");
    if (tsd_options_sun_from_time(o) && (o->sun_azimuth_given || o->sun_elevation_given))
        return fail(msg, msg_size,
                    "%s places the sun: do not give %s with it",
                    o->datetime[0] ? "DATETIME" : "DATE",
                    o->sun_azimuth_given ? "SUN_AZIMUTH" : "SUN_ELEVATION");
    if (o->product == TSD_PRODUCT_FARSHADOW && o->sun_position == TSD_SUN_PER_CELL)
        return fail(msg, msg_size,
                    "PRODUCT=farshadow computes the sun at the DEM's centre only "
                    "(SUN_POSITION=center)");
    if (o->product == TSD_PRODUCT_FARSHADOW && o->max_distance > 0)
        return fail(msg, msg_size,
                    "MAX_DISTANCE does not apply to PRODUCT=farshadow (its far shadows "
                    "start at FAR_THRESHOLD cells and have no end)");
    if (o->sun_position == TSD_SUN_PER_CELL && !tsd_options_sun_from_time(o))
        return fail(msg, msg_size,
                    "SUN_POSITION=per_cell needs the sun from DATETIME or DATE");
    return 0;
}

int tsd_options_output_byte(const tsd_options *o)
{
    if (o->product == TSD_PRODUCT_FARSHADOW)
        return 1;
    if (o->output_type == TSD_OUT_AUTO)
        return o->product == TSD_PRODUCT_SHADE;
    return o->output_type == TSD_OUT_BYTE;
}

int tsd_options_band_count(const tsd_options *o)
{
    switch (o->product) {
    case TSD_PRODUCT_HORIZON: return o->directions;
    case TSD_PRODUCT_INSOLATION: return 3;
    case TSD_PRODUCT_DAYCYCLE: return ts_day_step_count(86400.0, o->step_minutes * 60.0);
    case TSD_PRODUCT_FARSHADOW: return o->atlas_steps;
    default: return 1;
    }
}

int tsd_options_count(void)
{
    return O_COUNT;
}

const char *tsd_options_value(const tsd_options *o, int i, char *buf,
                              size_t n)
{
    if (i < 0 || i >= O_COUNT)
        return NULL;
    switch ((opt_id)i) {
    case O_PRODUCT: snprintf(buf, n, "%s", tsd_product_name(o->product)); break;
    case O_SUN_AZIMUTH: snprintf(buf, n, "%.10g", o->sun_azimuth); break;
    case O_SUN_ELEVATION: snprintf(buf, n, "%.10g", o->sun_elevation); break;
    case O_DIRECTIONS: snprintf(buf, n, "%d", o->directions); break;
    case O_START_AZIMUTH: snprintf(buf, n, "%.10g", o->start_azimuth); break;
    case O_METHOD: snprintf(buf, n, "%s", tsd_method_name(o->method)); break;
    case O_PENUMBRA_DEPTH: snprintf(buf, n, "%.10g", o->penumbra_depth); break;
    case O_Z_FACTOR: snprintf(buf, n, "%.10g", o->z_factor); break;
    case O_MAX_DISTANCE: snprintf(buf, n, "%.10g", o->max_distance); break;
    case O_CURVATURE: snprintf(buf, n, "%s", o->curvature ? "YES" : "NO"); break;
    case O_REFRACTION: snprintf(buf, n, "%.10g", o->refraction); break;
    case O_SKY_WEIGHT: snprintf(buf, n, "%.10g", o->sky_weight); break;
    case O_BAND: snprintf(buf, n, "%d", o->band); break;
    case O_THREADS: snprintf(buf, n, "%d", o->threads); break;
    case O_OUTPUT_TYPE:
        snprintf(buf, n, "%s", tsd_options_output_byte(o) ? "Byte" : "Float32");
        break;
    case O_MAX_MEMORY: snprintf(buf, n, "%d", o->max_memory_mb); break;
    case O_DATETIME: snprintf(buf, n, "%s", o->datetime); break;
    case O_DATE: snprintf(buf, n, "%s", o->date); break;
    case O_TIMEZONE: snprintf(buf, n, "%s", o->timezone); break;
    case O_STEP_MINUTES: snprintf(buf, n, "%d", o->step_minutes); break;
    case O_PRESSURE: snprintf(buf, n, "%.10g", o->pressure); break;
    case O_TEMPERATURE: snprintf(buf, n, "%.10g", o->temperature); break;
    case O_DELTA_T: snprintf(buf, n, "%.10g", o->delta_t); break;
    case O_SUN_POSITION:
        snprintf(buf, n, "%s", o->sun_position == TSD_SUN_PER_CELL ? "per_cell" : "center");
        break;
    case O_LINKE_TURBIDITY: snprintf(buf, n, "%.10g", o->linke_turbidity); break;
    case O_FAR_THRESHOLD: snprintf(buf, n, "%d", o->far_threshold); break;
    case O_ATLAS_STEPS: snprintf(buf, n, "%d", o->atlas_steps); break;
    case O_BACKEND: snprintf(buf, n, "%s", tsd_backend_name(o->backend)); break;
    case O_SUNHOURS_RULE:
        snprintf(buf, n, "%s", o->sunhours_fraction ? "fraction" : "visible");
        break;
    case O_PROGRESS:
        snprintf(buf, n, "%s", o->progress_mode == TSD_PROGRESS_YES  ? "yes"
                               : o->progress_mode == TSD_PROGRESS_NO ? "no"
                                                                     : "auto");
        break;
    case O_COUNT: break;
    }
    return OPTS[i].name;
}

int tsd_options_canonical(const tsd_options *o, char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < O_COUNT; i++) {
        char value[64];
        if (!OPTS[i].affects_pixels)
            continue;
        const char *name = tsd_options_value(o, i, value, sizeof value);
        if (!value[0])
            continue; /* a text option not given */
        int w = snprintf(buf + used, n - used, "%s%s=%s", used ? "," : "", name,
                         value);
        if (w < 0 || (size_t)w >= n - used)
            return -1;
        used += (size_t)w;
    }
    return 0;
}

/* Append to a growing string; returns 0 or -1 when out of memory. */
typedef struct {
    char *s;
    size_t len, cap;
} sbuf;

static int sb_add(sbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int need = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (need < 0)
        return -1;
    if (b->len + (size_t)need + 1 > b->cap) {
        size_t cap = (b->cap ? b->cap * 2 : 4096) + (size_t)need;
        char *s = realloc(b->s, cap);
        if (!s)
            return -1;
        b->s = s;
        b->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(b->s + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    b->len += (size_t)need;
    return 0;
}

char *tsd_options_xml(void)
{
    static const char *const type_names[] = {"string-select", "float", "int",
                                             "boolean", "string"};
    sbuf b = {0};
    int err = sb_add(&b, "<OpenOptionList>");
    for (int i = 0; i < O_COUNT && !err; i++) {
        const opt_def *d = &OPTS[i];
        err |= sb_add(&b, "  <Option name='%s' type='%s' default='%s'", d->name,
                      type_names[d->type], d->def);
        if (d->type == T_STRING) {
            /* no default: the option is off until given */
        } else if (d->type == T_FLOAT || d->type == T_INT) {
            err |= sb_add(&b, " min='%.10g'", d->min);
            if (d->has_max)
                err |= sb_add(&b, " max='%.10g'", d->max);
        }
        err |= sb_add(&b, " description='");
        for (const char *c = d->desc; *c && !err; c++)
            err |= *c == '\'' ? sb_add(&b, "&apos;")
                   : *c == '&' ? sb_add(&b, "&amp;")
                   : *c == '<' ? sb_add(&b, "&lt;")
                               : sb_add(&b, "%c", *c);
        err |= sb_add(&b, "'");
        if (d->type == T_SELECT) {
            err |= sb_add(&b, ">");
            for (const char *p = d->values; *p && !err;) {
                const char *bar = strchr(p, '|');
                int len = bar ? (int)(bar - p) : (int)strlen(p);
                err |= sb_add(&b, "<Value>%.*s</Value>", len, p);
                p += len + (bar ? 1 : 0);
            }
            err |= sb_add(&b, "</Option>");
        } else {
            err |= sb_add(&b, "/>");
        }
    }
    /* options of atlas files (*.tsa) only */
    err |= sb_add(&b, "  <Option name='SHADOWS' type='string-select' default='far' "
                      "description='Atlas files (.tsa) only: far (the stored far "
                      "shadows) or all (far shadows OR near shadows recomputed from the "
                      "DEM on read)'><Value>far</Value><Value>all</Value></Option>");
    err |= sb_add(&b, "  <Option name='DEM' type='string' description='Atlas files "
                      "(.tsa) with SHADOWS=all: the DEM to recompute the near shadows "
                      "from (default: the SOURCE_DEM the atlas records)'/>");
    err |= sb_add(&b, "</OpenOptionList>");
    if (err) {
        free(b.s);
        return NULL;
    }
    return b.s;
}
