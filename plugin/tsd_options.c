/* The TERRASHADE driver's options: the table, parsing, values, the XML list. */
#include "tsd_options.h"

#include "tsd_datetime.h"
#include "tsd_products.h"
#include "tsd_text.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* How an option's text becomes its field: K_SELECT and K_PRODUCT store the
 * index of the value (int or enum field), K_BOOL 0/1 (int), K_INT an int,
 * K_FLOAT a double, K_TEXT a char array. */
typedef enum { K_SELECT, K_FLOAT, K_INT, K_BOOL, K_TEXT, K_PRODUCT } opt_kind;

/* A check of a text option's value beyond its kind: 0, or -1 with msg. */
typedef int (*opt_validate_fn)(const char *value, char *msg, size_t n);

typedef struct {
    const char *name;
    opt_kind kind;
    size_t field, size;    /* offsetof and sizeof the field in tsd_options */
    const char *def;       /* the declared default, as written in the option list */
    double min, max;       /* inclusive range (numbers) */
    int min_exclusive;     /* value must be > min */
    int has_max;           /* 0: no upper bound */
    const char *values;    /* K_SELECT: '|'-separated */
    int affects_pixels;    /* part of the canonical string */
    int scope;             /* TSD_SCOPE_* */
    tsd_applies applies;
    opt_validate_fn validate; /* NULL = the kind's check only */
    const char *desc;
} opt_def;

#define FIELD(f) offsetof(tsd_options, f), sizeof(((tsd_options *)0)->f)
#define P TSD_SCOPE_PRODUCT
#define A TSD_SCOPE_ATLAS
#define ALL TSD_APPLIES_ALL
#define LISTED TSD_APPLIES_LISTED

static int check_datetime(const char *v, char *msg, size_t n);
static int check_date(const char *v, char *msg, size_t n);
static int check_timezone(const char *v, char *msg, size_t n);

static const opt_def OPTS[] = {
    {"PRODUCT", K_PRODUCT, FIELD(product), "shade", 0, 0, 0, 0, NULL, 1, P,
     TSD_APPLIES_SELECTOR, NULL,
     "What to compute: " /* then each product's name (description) */},
    {"SUN_AZIMUTH", K_FLOAT, FIELD(sun_azimuth), "315", 0, 360, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "Sun azimuth in degrees clockwise from (grid) north (as gdaldem -az); "
     "not with DATETIME"},
    {"SUN_ELEVATION", K_FLOAT, FIELD(sun_elevation), "45", -90, 90, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "Sun elevation in degrees above the horizontal (as gdaldem -alt); not "
     "with DATETIME"},
    {"DIRECTIONS", K_INT, FIELD(directions), "16", 1, 3600, 0, 1, NULL, 1, P, LISTED, NULL,
     "Number of azimuths of the horizon, svf, openness and sky products "
     "and of the sky term of shade"},
    {"START_AZIMUTH", K_FLOAT, FIELD(start_azimuth), "0", 0, 360, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "First of the DIRECTIONS azimuths, degrees from north; the others "
     "follow every 360/DIRECTIONS degrees"},
    {"METHOD", K_SELECT, FIELD(method), "exact", 0, 0, 0, 0, "exact|shm", 1, P, LISTED,
     NULL,
     "Shadow method of shade and shadow: exact (horizon sweep, penumbra "
     "from the sun's disk) or shm (shadow height map, faster, approximate)"},
    {"PENUMBRA_DEPTH", K_FLOAT, FIELD(penumbra_depth), "0", 0, 1e6, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "METHOD=shm: metres below the shadow height over which light fades; "
     "0 = hard shadows"},
    {"Z_FACTOR", K_FLOAT, FIELD(z_factor), "1", 0, 1e6, 1, 1, NULL, 1, P, ALL, NULL,
     "Multiplies the heights (> 0), e.g. 0.3048 for heights in feet; the "
     "band's scale and offset are applied first"},
    {"MAX_DISTANCE", K_FLOAT, FIELD(max_distance), "0", 0, 1e8, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "Largest distance in metres at which terrain can cast a shadow or "
     "raise the horizon; 0 = unbounded"},
    {"CURVATURE", K_BOOL, FIELD(curvature), "YES", 0, 0, 0, 0, NULL, 1, P, ALL, NULL,
     "Take Earth curvature (with refraction) into account"},
    {"REFRACTION", K_FLOAT, FIELD(refraction), TSD_XSTR(TSD_REFRACTION_DEFAULT), 0, 1, 0, 1,
     NULL, 1, P, ALL, NULL,
     "Refraction coefficient k of the curvature correction: drop = (1-k) "
     "d^2 / 2R"},
    {"SKY_WEIGHT", K_FLOAT, FIELD(sky_weight), "0", 0, 1, 0, 1, NULL, 1, P, LISTED, NULL,
     "shade only: weight of the light of a uniform sky added to the direct "
     "sun (shade = direct + SKY_WEIGHT * sky); 0 = sun only, as gdaldem"},
    {"BAND", K_INT, FIELD(band), "1", 1, 65536, 0, 1, NULL, 1, P, ALL, NULL,
     "Band of the DEM holding the heights"},
    {"THREADS", K_INT, FIELD(threads), "0", 0, 1024, 0, 1, NULL, 0, P | A, ALL, NULL,
     "Worker threads; 0 = one per CPU core"},
    {"OUTPUT_TYPE", K_SELECT, FIELD(output_type), "AUTO", 0, 0, 0, 0, "AUTO|Byte|Float32",
     1, P, LISTED, NULL,
     "Data type: Byte (1..255, 0 = nodata, as gdaldem) or Float32 (0..1 or "
     "degrees, NaN = nodata); AUTO = Byte for shade, Float32 otherwise. "
     "Byte only for the 0..1 products (shade, shadow, svf, sky)"},
    {"MAX_MEMORY", K_INT, FIELD(max_memory_mb), "0", 0, 1 << 30, 0, 1, NULL, 0, P, ALL,
     NULL,
     "Refuse to compute a product needing more than this many MiB; 0 = "
     "three quarters of the physical memory"},
    {"DATETIME", K_TEXT, FIELD(datetime), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_datetime,
     "Place the sun by date and time (SPA) instead of SUN_AZIMUTH and "
     "SUN_ELEVATION: ISO 8601 with an offset, e.g. 2026-06-21T07:30:00+02:00 "
     "or 2026-06-21T05:30Z (inline: 2026-06-21T073000+0200). With the day "
     "products: the local day that contains it"},
    {"DATE", K_TEXT, FIELD(date), "", 0, 0, 0, 0, NULL, 1, P, LISTED, check_date,
     "Day of sunhours, insolation, daycycle and farshadow: YYYY-MM-DD, local "
     "to TIMEZONE"},
    {"TIMEZONE", K_TEXT, FIELD(timezone), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_timezone,
     "Fixed offset from UTC of the local day: Z, +hh:mm, -hh:mm, +hhmm; "
     "needed with DATE; with DATETIME it defaults to DATETIME's offset"},
    {"STEP_MINUTES", K_INT, FIELD(step_minutes), "5", 1, 240, 0, 1, NULL, 1, P, LISTED,
     NULL, "Time step of sunhours, insolation and daycycle, minutes"},
    {"PRESSURE", K_FLOAT, FIELD(pressure), "1013.25", 0, 5000, 1, 1, NULL, 1, P, LISTED,
     NULL, "Mean air pressure at the DEM, hPa (atmospheric refraction of the sun)"},
    {"TEMPERATURE", K_FLOAT, FIELD(temperature), "15", -273, 6000, 1, 1, NULL, 1, P,
     LISTED, NULL,
     "Mean air temperature at the DEM, degrees Celsius (atmospheric "
     "refraction of the sun)"},
    {"DELTA_T", K_FLOAT, FIELD(delta_t), "69", -8000, 8000, 0, 1, NULL, 1, P, LISTED, NULL,
     "TT - UT in seconds (about 69 in the 2020s)"},
    {"SUN_POSITION", K_SELECT, FIELD(sun_position), "center", 0, 0, 0, 0,
     "center|per_cell", 1, P, LISTED, NULL,
     "Where the sun is computed from: the DEM's centre (center), or every "
     "cell (per_cell: the SPA on a lattice over the DEM, interpolated), for "
     "extents of a few degrees or more"},
    {"LINKE_TURBIDITY", K_FLOAT, FIELD(linke_turbidity), "3", 1, 10, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "Linke turbidity factor of the clear-sky model of insolation (2 very "
     "clear, 3 clear, 5 hazy)"},
    {"FAR_THRESHOLD", K_INT, FIELD(far_threshold), "512", 1, 1000000, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "farshadow: occluders nearer than this many cells are left out (they "
     "are recomputed on read)"},
    {"ATLAS_STEPS", K_INT, FIELD(atlas_steps), "158", 1, 1024, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "farshadow: number of sun positions between sunrise and sunset, denser "
     "near dawn and dusk"},
    {"BACKEND", K_SELECT, FIELD(backend), "auto", 0, 0, 0, 0, "auto|opencl|c", 0, P,
     LISTED, NULL,
     "Where the horizon sweeps, shadow height maps, normals and direct sun "
     "of shade, shadow, horizon, svf, openness and sky run: opencl (falls "
     "back to c, with a warning, when OpenCL cannot run), c (the "
     "multithreaded C core), or auto (the environment variable "
     "TERRASHADE_BACKEND, else OpenCL on a GPU or accelerator or on a device "
     "named by TERRASHADE_OPENCL_DEVICE, else c). The metadata item BACKEND "
     "says what ran"},
    {"SUNHOURS_RULE", K_SELECT, FIELD(sunhours_fraction), "visible", 0, 0, 0, 0,
     "visible|fraction", 1, P, LISTED, NULL,
     "sunhours: what a time step counts: visible (the whole step while any "
     "part of the sun's disk is above the cell's horizon; on a flat plane "
     "the astronomical day length, sunrise to sunset by the upper limb) or "
     "fraction (the step times the visible fraction of the disk; on a flat "
     "plane the time the sun's centre is up)"},
    {"PROGRESS", K_SELECT, FIELD(progress_mode), "auto", 0, 0, 0, 0, "auto|yes|no", 0, P,
     ALL, NULL,
     "Print the progress of the computation to stderr: yes, no, or auto "
     "(when stderr is a terminal and the computation takes more than a "
     "second)"},
    /* options of atlas files (*.tsa) only */
    {"SHADOWS", K_SELECT, FIELD(shadows_all), "far", 0, 0, 0, 0, "far|all", 0, A, LISTED,
     NULL,
     "Atlas files (.tsa) only: far (the stored far shadows) or all (far "
     "shadows OR near shadows recomputed from the DEM on read)"},
    {"DEM", K_TEXT, FIELD(dem), "", 0, 0, 0, 0, NULL, 0, A, LISTED, NULL,
     "Atlas files (.tsa) with SHADOWS=all: the DEM to recompute the near "
     "shadows from (default: the SOURCE_DEM the atlas records)"},
};

#define N_OPTS ((int)(sizeof OPTS / sizeof OPTS[0]))

/* tsd_options.given has a bit per option */
_Static_assert(sizeof OPTS / sizeof OPTS[0] <= 64, "too many options for tsd_options.given");
/* select fields are enums written through int pointers */
_Static_assert(sizeof(tsd_method) == sizeof(int) && sizeof(tsd_output_type) == sizeof(int) &&
                   sizeof(tsd_sun_position) == sizeof(int) &&
                   sizeof(tsd_backend) == sizeof(int) &&
                   sizeof(tsd_progress_mode) == sizeof(int),
               "enum options are int-sized");

static int check_datetime(const char *v, char *msg, size_t n)
{
    char norm[TSD_TEXT_MAX * 2];
    double t;
    ts_error err;
    tsd_datetime_normalise(v, norm, sizeof norm);
    if (ts_parse_iso8601(norm, &t, NULL, &err) != TS_OK)
        return (tsd_fail_core(msg, n, "DATETIME", &err), -1);
    return 0;
}

static int check_date(const char *v, char *msg, size_t n)
{
    int y, m, d;
    ts_error err;
    if (ts_parse_date(v, &y, &m, &d, &err) != TS_OK)
        return (tsd_fail_core(msg, n, "DATE", &err), -1);
    return 0;
}

static int check_timezone(const char *v, char *msg, size_t n)
{
    int off;
    ts_error err;
    if (ts_parse_utc_offset(v, &off, &err) != TS_OK)
        return (tsd_fail_core(msg, n, "TIMEZONE", &err), -1);
    return 0;
}

int tsd_options_count(void)
{
    return N_OPTS;
}

const char *tsd_option_name(int i)
{
    return i >= 0 && i < N_OPTS ? OPTS[i].name : NULL;
}

int tsd_option_find(const char *name)
{
    for (int i = 0; i < N_OPTS; i++)
        if (strcasecmp(name, OPTS[i].name) == 0)
            return i;
    return -1;
}

int tsd_option_scope(int i)
{
    return i >= 0 && i < N_OPTS ? OPTS[i].scope : 0;
}

tsd_applies tsd_option_applies(int i)
{
    return i >= 0 && i < N_OPTS ? OPTS[i].applies : TSD_APPLIES_SELECTOR;
}

const char *tsd_option_default(int i)
{
    return i >= 0 && i < N_OPTS ? OPTS[i].def : NULL;
}

int tsd_options_given(const tsd_options *o, const char *name)
{
    int i = tsd_option_find(name);
    return i >= 0 && (o->given >> i & 1);
}

/* The i-th value of a '|'-list into buf ("" past the end). */
static const char *select_value(const char *values, int index, char *buf, size_t n)
{
    const char *p = values;
    for (int k = 0; k < index && p; k++) {
        p = strchr(p, '|');
        p = p ? p + 1 : NULL;
    }
    size_t len = p ? strcspn(p, "|") : 0;
    snprintf(buf, n, "%.*s", (int)len, p ? p : "");
    return buf;
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

/* Refuse with a sentence. */
#define REFUSE(...) return (tsd_fail(msg, n, TS_ERR_ARG, __VA_ARGS__), -1)

static int parse_number(const opt_def *d, const char *v, double *out, char *msg,
                        size_t n)
{
    char *end = NULL;
    errno = 0;
    if (d->kind == K_INT) {
        long l = strtol(v, &end, 10);
        if (end == v || *end || errno)
            REFUSE("%s must be a whole number, got '%s'", d->name, v);
        *out = (double)l;
    } else {
        double x = strtod(v, &end);
        if (end == v || *end || !isfinite(x))
            REFUSE("%s must be a number, got '%s'", d->name, v);
        *out = x;
    }
    double x = *out;
    int low = d->min_exclusive ? !(x > d->min) : !(x >= d->min);
    int high = d->has_max && !(x <= d->max);
    if (!low && !high)
        return 0;
    if (d->min_exclusive)
        REFUSE("%s must be greater than %g and at most %g, got %s", d->name, d->min, d->max,
               v);
    if (!d->has_max)
        REFUSE("%s must be at least %g, got %s", d->name, d->min, v);
    REFUSE("%s must be between %g and %g, got %s", d->name, d->min, d->max, v);
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

/* "a, b, c" of a '|'-list, or of the products' names. */
static void list_values(const opt_def *d, char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    int count = d->kind == K_PRODUCT ? tsd_product_count() : 0;
    if (d->kind == K_SELECT)
        for (const char *p = d->values; p; p = strchr(p, '|'), p = p ? p + 1 : NULL)
            count++;
    for (int k = 0; k < count && used < n; k++) {
        char value[64];
        const char *v = d->kind == K_PRODUCT ? tsd_product_at(k)->name
                                             : select_value(d->values, k, value, sizeof value);
        used += (size_t)snprintf(buf + used, n - used, "%s%s", k ? ", " : "", v);
    }
}

/* Set option `id` of `o` from its text (not empty). */
static int set_option(tsd_options *o, int id, const char *v, char *msg, size_t n)
{
    const opt_def *d = &OPTS[id];
    char *field = (char *)o + d->field;
    double x = 0;
    int k = 0;
    char list[256];
    switch (d->kind) {
    case K_PRODUCT:
    case K_SELECT:
        k = d->kind == K_PRODUCT ? tsd_product_find(v) : select_index(d->values, v);
        if (k < 0) {
            list_values(d, list, sizeof list);
            REFUSE("%s must be one of %s, got '%s'", d->name, list, v);
        }
        memcpy(field, &k, sizeof k);
        return 0;
    case K_BOOL:
        if (parse_bool(v, &k) != 0) {
            REFUSE("%s must be YES or NO, got '%s'", d->name, v);
        }
        memcpy(field, &k, sizeof k);
        return 0;
    case K_FLOAT:
    case K_INT:
        if (parse_number(d, v, &x, msg, n) != 0)
            return -1;
        if (d->kind == K_INT) {
            k = (int)x;
            memcpy(field, &k, sizeof k);
        } else {
            memcpy(field, &x, sizeof x);
        }
        return 0;
    case K_TEXT:
        if (strlen(v) >= d->size) {
            REFUSE("%s is too long (%zu characters)", d->name, strlen(v));
        }
        if (d->validate && d->validate(v, msg, n) != 0)
            return -1;
        snprintf(field, d->size, "%s", v);
        return 0;
    }
    return -1;
}

void tsd_options_defaults(tsd_options *o)
{
    memset(o, 0, sizeof *o);
    for (int i = 0; i < N_OPTS; i++)
        if (OPTS[i].def[0])
            set_option(o, i, OPTS[i].def, NULL, 0); /* checked by check_options */
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

/* The names of the options of `scope`, "A, B, C"; for an atlas "A, B and
 * C", its own options before those it shares with products (THREADS). */
static void list_names(int scope, char *buf, size_t n)
{
    const int atlas = scope == TSD_SCOPE_ATLAS;
    size_t used = 0;
    int total = 0, k = 0;
    buf[0] = '\0';
    for (int i = 0; i < N_OPTS; i++)
        total += (OPTS[i].scope & scope) != 0;
    for (int pass = atlas ? 0 : 1; pass < 2; pass++)
        for (int i = 0; i < N_OPTS && used < n; i++) {
            if (!(OPTS[i].scope & scope) || (pass == 0 && OPTS[i].scope != scope))
                continue;
            if (atlas && pass == 1 && OPTS[i].scope == scope)
                continue; /* listed in pass 0 */
            const char *sep = k == 0 ? "" : atlas && k == total - 1 ? " and " : ", ";
            used += (size_t)snprintf(buf + used, n - used, "%s%s", sep, OPTS[i].name);
            k++;
        }
}

/* Apply "KEY=VALUE" items of a dataset of `scope`. */
static int apply_scope(tsd_options *o, const char *const *kv, int scope, char *msg,
                       size_t n)
{
    const char *seen[N_OPTS] = {0}; /* the item that set each option */
    for (size_t i = 0; kv && kv[i]; i++) {
        const char *item = kv[i];
        const char *eq = strchr(item, '=');
        char key[128], value[TSD_PATH_MAX], before[TSD_PATH_MAX], names[1024];
        if (!eq)
            REFUSE("%s '%s' is not of the form KEY=VALUE",
                   scope == TSD_SCOPE_ATLAS ? "open option" : "option", item);
        trim(item, (size_t)(eq - item), key, sizeof key);
        trim(eq + 1, strlen(eq + 1), value, sizeof value);
        int id = tsd_option_find(key);
        if (id >= 0 && !(OPTS[id].scope & scope) && scope == TSD_SCOPE_PRODUCT)
            REFUSE("%s is an open option of far-shadow atlas files (.tsa), not of "
                   "TERRASHADE:<dem>", key);
        if (id < 0 || !(OPTS[id].scope & scope)) {
            list_names(scope, names, sizeof names);
            if (scope == TSD_SCOPE_ATLAS)
                REFUSE("an atlas takes the open options %s, not '%s'", names, key);
            REFUSE("unknown option '%s'; the options are %s (see gdalinfo "
                   "--format TERRASHADE)", key, names);
        }
        if (seen[id]) {
            const char *e = strchr(seen[id], '=');
            trim(e + 1, strlen(e + 1), before, sizeof before);
            if (strcasecmp(before, value) != 0)
                REFUSE("%s is given twice, as %s and as %s", OPTS[id].name, before, value);
        }
        seen[id] = item;
        if (!value[0])
            REFUSE("%s needs a value (%s=...)", OPTS[id].name, OPTS[id].name);
        if (set_option(o, id, value, msg, n) != 0)
            return -1;
        o->given |= 1ULL << id;
    }
    return 0;
}

int tsd_options_apply(tsd_options *o, const char *const *kv, char *msg, size_t msg_size)
{
    if (apply_scope(o, kv, TSD_SCOPE_PRODUCT, msg, msg_size) != 0)
        return -1;
    return tsd_options_check(o, msg, msg_size);
}

int tsd_options_apply_atlas(tsd_options *o, const char *const *kv, char *msg,
                            size_t msg_size)
{
    return apply_scope(o, kv, TSD_SCOPE_ATLAS, msg, msg_size);
}

const char *tsd_options_value(const tsd_options *o, int i, char *buf, size_t n)
{
    if (i < 0 || i >= N_OPTS)
        return NULL;
    const opt_def *d = &OPTS[i];
    const char *field = (const char *)o + d->field;
    int k;
    double x;
    switch (d->kind) {
    case K_PRODUCT:
        memcpy(&k, field, sizeof k);
        snprintf(buf, n, "%s", tsd_product_at(k) ? tsd_product_at(k)->name : "?");
        break;
    case K_SELECT:
        memcpy(&k, field, sizeof k);
        if (d->field == offsetof(tsd_options, output_type)) /* the type written */
            k = tsd_options_output_byte(o) ? TSD_OUT_BYTE : TSD_OUT_FLOAT32;
        select_value(d->values, k, buf, n);
        break;
    case K_BOOL:
        memcpy(&k, field, sizeof k);
        snprintf(buf, n, "%s", k ? "YES" : "NO");
        break;
    case K_INT:
        memcpy(&k, field, sizeof k);
        snprintf(buf, n, "%d", k);
        break;
    case K_FLOAT:
        memcpy(&x, field, sizeof x);
        snprintf(buf, n, "%.10g", x);
        break;
    case K_TEXT:
        snprintf(buf, n, "%s", field);
        break;
    }
    return d->name;
}

int tsd_options_canonical(const tsd_options *o, char *buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < N_OPTS; i++) {
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

char *tsd_options_xml(void)
{
    static const char *const type_names[] = {"string-select", "float", "int",
                                             "boolean", "string", "string-select"};
    tsd_strbuf b = {0};
    tsd_strbuf_add(&b, "<OpenOptionList>");
    for (int i = 0; i < N_OPTS; i++) {
        const opt_def *d = &OPTS[i];
        tsd_strbuf_add(&b, "  <Option name='%s' type='%s'", d->name, type_names[d->kind]);
        if (d->kind != K_TEXT || d->def[0])
            tsd_strbuf_add(&b, " default='%s'", d->def);
        else if (d->scope & TSD_SCOPE_PRODUCT)
            tsd_strbuf_add(&b, " default=''"); /* off until given */
        if (d->kind == K_FLOAT || d->kind == K_INT) {
            tsd_strbuf_add(&b, " min='%.10g'", d->min);
            if (d->has_max)
                tsd_strbuf_add(&b, " max='%.10g'", d->max);
        }
        tsd_strbuf_add(&b, " description='");
        tsd_strbuf_add_xml(&b, d->desc);
        for (int k = 0; d->kind == K_PRODUCT && k < tsd_product_count(); k++) {
            const tsd_product_def *p = tsd_product_at(k);
            tsd_strbuf_add(&b, "%s%s (", k ? ", " : "", p->name);
            tsd_strbuf_add_xml(&b, p->description);
            tsd_strbuf_add(&b, ")");
        }
        tsd_strbuf_add(&b, "'");
        if (d->kind == K_SELECT || d->kind == K_PRODUCT) {
            char value[64];
            tsd_strbuf_add(&b, ">");
            for (int k = 0; d->kind == K_PRODUCT && k < tsd_product_count(); k++)
                tsd_strbuf_add(&b, "<Value>%s</Value>", tsd_product_at(k)->name);
            for (int k = 0; d->kind == K_SELECT && select_value(d->values, k, value,
                                                                sizeof value)[0];
                 k++)
                tsd_strbuf_add(&b, "<Value>%s</Value>", value);
            tsd_strbuf_add(&b, "</Option>");
        } else {
            tsd_strbuf_add(&b, "/>");
        }
    }
    tsd_strbuf_add(&b, "</OpenOptionList>");
    return tsd_strbuf_finish(&b);
}
