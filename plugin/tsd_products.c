/* The product table and what is derived from it; see tsd_products.h. */
#include "tsd_products.h"

#include "simd_clones.h"
#include "terrashade_sh.h"
#include "tsd_compute_env.h"
#include "tsd_pyramid.h"
#include "tsd_text.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

static int one_band(const tsd_options *o)
{
    (void)o;
    return 1;
}

static int per_direction(const tsd_options *o)
{
    return o->directions;
}

static int per_step(const tsd_options *o)
{
    return ts_day_step_count(86400.0, o->step_minutes * 60.0);
}

static int per_atlas_step(const tsd_options *o)
{
    return o->atlas_steps;
}

static const char *const INSOLATION_BANDS[] = {"global", "beam", "diffuse"};
#define N_INSOLATION_BANDS ((int)(sizeof INSOLATION_BANDS / sizeof INSOLATION_BANDS[0]))

static int insolation_bands(const tsd_options *o)
{
    (void)o;
    return N_INSOLATION_BANDS;
}

/* a single band: named after the product */
static void band_named(const tsd_product_def *p, const tsd_options *o, int k,
                       tsd_band_info *info)
{
    (void)o;
    (void)k;
    snprintf(info->description, sizeof info->description, "%s", p->name);
}

/* one band per azimuth: "azimuth 22.5", AZIMUTH=22.5 */
static void band_azimuth(const tsd_product_def *p, const tsd_options *o, int k,
                         tsd_band_info *info)
{
    (void)p;
    ts_horizon_opts h;
    ts_horizon_opts_default(&h);
    h.directions = o->directions;
    h.start_azimuth = o->start_azimuth;
    snprintf(info->value, sizeof info->value, "%.10g", ts_horizon_azimuth(&h, k));
    snprintf(info->description, sizeof info->description, "azimuth %s", info->value);
    info->key = "AZIMUTH";
}

static void band_insolation(const tsd_product_def *p, const tsd_options *o, int k,
                            tsd_band_info *info)
{
    (void)o;
    snprintf(info->description, sizeof info->description, "%s %s", p->name,
             k >= 0 && k < N_INSOLATION_BANDS ? INSOLATION_BANDS[k] : "?");
}

static const char *const COLOUR_BANDS[] = {"Red", "Green", "Blue"};

static int colour_bands(const tsd_options *o)
{
    (void)o;
    return 3;
}

/* "envlight red", colour interpretation Red */
static void band_colour(const tsd_product_def *p, const tsd_options *o, int k,
                        tsd_band_info *info)
{
    (void)o;
    info->color = k >= 0 && k < 3 ? COLOUR_BANDS[k] : NULL;
    snprintf(info->description, sizeof info->description, "%s %s", p->name,
             k == 0 ? "red" : k == 1 ? "green" : k == 2 ? "blue" : "?");
}

static int backend_always(const tsd_options *o, const tsd_sun *sun)
{
    (void)o;
    (void)sun;
    return 1;
}

/* shadow: not with the exact method and a per-cell sun (the core's
 * ts_sun_visibility, C only) */
static int shadow_uses_backend(const tsd_options *o, const tsd_sun *sun)
{
    return !(tsd_sun_per_cell(sun) && o->method == TSD_METHOD_EXACT);
}

/* Option groups of the rows below. */
#define SUN_TIME "DATETIME PRESSURE TEMPERATURE DELTA_T "
#define SUN_OPTS                                                                           \
    "SUN_AZIMUTH SUN_ELEVATION METHOD PENUMBRA_DEPTH LIGHT_RADIUS SWATH_DIRECTIONS "       \
    "SHADOWMAP_SCALE PCF_KERNEL " SUN_TIME "SUN_POSITION "
#define SWEEP "DIRECTIONS START_AZIMUTH MAX_DISTANCE EDGE "
#define WINDOW "TILE_SIZE NEAR_DISTANCE "
#define DAY "DATE TIMEZONE " SUN_TIME
#define RANGE "START_DATE END_DATE DAY_INTERVAL HORIZON_DIRECTIONS"
#define ENV "ENV_MAP ENV_ROTATION SKY ENV_HORIZON_STEPS ENV_NORMAL_STEPS "
#define PYRAMID "HORIZON_METHOD PYRAMID_LEVEL_STEP PYRAMID_OFFSET "

static const tsd_product_def PRODUCTS[] = {
    {"shade", "sun-lit relief with cast shadows", "", "0..1", one_band, NULL, band_named,
     TSD_BYTE_AUTO, 0, 0, TSD_STEPS_NONE,
     /* normals, a horizon plane or the SHM visibility; the sky accumulator
      * and its horizon plane; the per-cell sun */
     4, 2, 7, backend_always,
     SUN_OPTS SWEEP WINDOW ENV PYRAMID "SKY_WEIGHT OUTPUT_TYPE BACKEND", NULL,
     NULL,
     tsd_compute_shade},
    {"shadow", "visible fraction of the sun's disk, 0..1", "", "0..1", one_band, NULL,
     band_named, TSD_BYTE_ALLOWED, 0, 0, TSD_STEPS_NONE, 0, 0, 7, shadow_uses_backend,
     SUN_OPTS "MAX_DISTANCE EDGE " WINDOW PYRAMID "OUTPUT_TYPE BACKEND", NULL, NULL,
     tsd_compute_shadow},
    {"horizon", "one band per azimuth, horizon elevation angle in degrees", "degree",
     "degrees", per_direction, "DIRECTIONS", band_azimuth, TSD_BYTE_NEVER, 0, 0,
     TSD_STEPS_NONE, 0, 0, 0, backend_always, SWEEP WINDOW PYRAMID "BACKEND", NULL, NULL,
     tsd_compute_horizon},
    /* the sky products: normals and one horizon plane */
    {"svf", "sky-view factor 0..1", "", "0..1", one_band, NULL, band_named,
     TSD_BYTE_ALLOWED, 0, 0, TSD_STEPS_NONE, 4, 0, 0, backend_always,
     SWEEP WINDOW PYRAMID "SVF_MODEL OUTPUT_TYPE BACKEND", NULL, NULL, tsd_compute_svf},
    /* and, for OPENNESS=negative, the negated DEM */
    {"openness", "positive or negative openness, degrees", "degree", "degrees", one_band,
     NULL, band_named, TSD_BYTE_NEVER, 0, 0, TSD_STEPS_NONE, 5, 0, 0, backend_always,
     SWEEP WINDOW PYRAMID "OPENNESS BACKEND", NULL, NULL, tsd_compute_openness},
    {"sky", "uniform-sky irradiance 0..1", "", "0..1", one_band, NULL, band_named,
     TSD_BYTE_ALLOWED, 0, 0, TSD_STEPS_NONE, 4, 0, 0, backend_always,
     SWEEP WINDOW PYRAMID "OUTPUT_TYPE BACKEND", NULL, NULL, tsd_compute_sky},
    /* Earth horizon, horizon plane, visibility, double accumulator; over a
     * date range Earth horizon, three horizon planes, double accumulator */
    {"sunhours", "hours of direct sun on DATE, or in total from START_DATE to END_DATE",
     "hour", "hours", one_band, NULL, band_named, TSD_BYTE_NEVER, 0, 1, TSD_STEPS_NONE, 6, 0,
     3, NULL, "MAX_DISTANCE EDGE " WINDOW DAY "STEP_MINUTES SUN_POSITION SUNHOURS_RULE " RANGE,
     NULL,
     NULL, tsd_compute_sunhours},
    /* normals, sky, visibility, pressure factor, two double accumulators,
     * Earth horizon, horizon plane (a date range: three horizon planes,
     * one double accumulator) */
    {"insolation", "clear-sky irradiation on DATE, or in total from START_DATE to "
     "END_DATE, Wh/m2: global, beam, diffuse", "Wh/m2",
     "Wh/m2", insolation_bands, NULL, band_insolation, TSD_BYTE_NEVER, 0, 1,
     TSD_STEPS_NONE, 12, 0, 5, NULL,
     SWEEP WINDOW DAY "STEP_MINUTES SUN_POSITION LINKE_TURBIDITY " RANGE, "CLEAR_SKY_MODEL",
     "ESRA (Rigollier et al. 2000): beam on the tilted surface x visible "
     "fraction of the sun + diffuse horizontal x sky-view factor (sky term)",
     tsd_compute_insolation},
    {"daycycle", "visible fraction of the sun, one band per STEP_MINUTES", "", "0..1",
     per_step, "STEP_MINUTES", NULL, TSD_BYTE_ALLOWED, 0, 1, TSD_STEPS_UNIFORM, 2, 0, 3,
     NULL, "MAX_DISTANCE EDGE OUTPUT_TYPE " WINDOW DAY "STEP_MINUTES SUN_POSITION", NULL, NULL,
     tsd_compute_daycycle},
    /* the far-field slopes */
    {"farshadow", "binary far-shadow maps of ATLAS_STEPS sun positions", "", "0, 1",
     per_atlas_step, "ATLAS_STEPS", NULL, TSD_BYTE_ALWAYS, 255, 1, TSD_STEPS_ATLAS, 1, 0, 0,
     NULL, DAY "FAR_THRESHOLD ATLAS_STEPS", NULL, NULL, tsd_compute_farshadow},
    /* normals and one horizon plane (docs/envlight.md) */
    {"envlight", "light of an HDR environment map (ENV_MAP) or a standard sky (SKY) on a "
     "white Lambertian surface, E/pi per colour: red, green, blue", "", "E/pi", colour_bands,
     NULL, band_colour, TSD_BYTE_ALLOWED, 0, 0, TSD_STEPS_NONE, 4, 0, 0, backend_always,
     SWEEP WINDOW ENV PYRAMID "ENV_METHOD EXPOSURE OUTPUT_TYPE BACKEND SUN_AZIMUTH SUN_ELEVATION "
     SUN_TIME, NULL, NULL,
     tsd_compute_envlight},
};

#define N_PRODUCTS ((int)(sizeof PRODUCTS / sizeof PRODUCTS[0]))

int tsd_product_count(void)
{
    return N_PRODUCTS;
}

const tsd_product_def *tsd_product_at(int i)
{
    return i >= 0 && i < N_PRODUCTS ? &PRODUCTS[i] : NULL;
}

int tsd_product_find(const char *name)
{
    for (int i = 0; i < N_PRODUCTS; i++)
        if (strcasecmp(name, PRODUCTS[i].name) == 0)
            return i;
    return -1;
}

const tsd_product_def *tsd_product_of(const tsd_options *o)
{
    const tsd_product_def *p = tsd_product_at(o->product);
    return p ? p : &PRODUCTS[0];
}

/* 1 if the space-separated list holds the word. */
static int list_has(const char *list, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = list; p && *p;) {
        p += strspn(p, " ");
        size_t len = strcspn(p, " ");
        if (len == n && strncmp(p, word, n) == 0)
            return 1;
        p += len;
    }
    return 0;
}

int tsd_product_takes(const tsd_product_def *p, int option)
{
    if (!(tsd_option_scope(option) & TSD_SCOPE_PRODUCT))
        return 0;
    switch (tsd_option_applies(option)) {
    case TSD_APPLIES_ALL: return 1;
    case TSD_APPLIES_LISTED: return list_has(p->options, tsd_option_name(option));
    default: return 0;
    }
}

void tsd_products_taking(int option, const char *prefix, const char *last, char *buf,
                         size_t n)
{
    int total = 0, k = 0;
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < N_PRODUCTS; i++)
        total += tsd_product_takes(&PRODUCTS[i], option);
    for (int i = 0; i < N_PRODUCTS && used < n; i++) {
        if (!tsd_product_takes(&PRODUCTS[i], option))
            continue;
        const char *sep = k == 0 ? "" : k == total - 1 ? last : ", ";
        used += (size_t)snprintf(buf + used, n - used, "%s%s%s", sep, prefix,
                                 PRODUCTS[i].name);
        k++;
    }
}

/* Why option `name`, which p takes, does nothing beside o's other options
 * (NULL: it does something); the sentence may be written in why[n]. */
static const char *moot_beside(const tsd_options *o, const tsd_product_def *p, const char *name,
                               char *why, size_t n)
{
    /* envlight under a sky without a sun (uniform, overcast, cie:1, 3, 5):
     * nothing of the sun's (ENV_MAP with a sun is refused,
     * tsd_options_check); the sky named as the user gave it */
    if (tsd_product_takes(p, tsd_option_find("EXPOSURE")) && tsd_environment_sunless(o) &&
        (!strcmp(name, "SUN_AZIMUTH") || !strcmp(name, "SUN_ELEVATION") ||
         !strcmp(name, "DATETIME") || !strcmp(name, "PRESSURE") ||
         !strcmp(name, "TEMPERATURE") || !strcmp(name, "DELTA_T"))) {
        snprintf(why, n, "the sun's, and %s%s has none", o->sky[0] ? "SKY=" : "ENV_MAP",
                 o->sky[0] ? o->sky : "");
        return why;
    }
    if ((!strcmp(name, "PRESSURE") || !strcmp(name, "TEMPERATURE") ||
         !strcmp(name, "DELTA_T")) &&
        !tsd_options_sun_from_time(o))
        return "it refracts and places a sun computed from DATETIME";
    /* given at their defaults (other values are refused, tsd_options_check) */
    if ((!strcmp(name, "SUN_AZIMUTH") || !strcmp(name, "SUN_ELEVATION")) &&
        tsd_options_sun_from_time(o))
        return o->datetime[0] ? "DATETIME places the sun" : "the day places the sun";
    if (!strcmp(name, "EXPOSURE") && !tsd_options_output_byte(o))
        return "it sets the exposure of OUTPUT_TYPE=Byte; Float32 keeps the light's values";
    if (!strcmp(name, "ENV_ROTATION") && !o->env_map[0])
        return "it turns ENV_MAP; a SKY turns with its sun";
    if ((!strcmp(name, "ENV_HORIZON_STEPS") || !strcmp(name, "ENV_NORMAL_STEPS")) &&
        !tsd_product_takes(p, tsd_option_find("EXPOSURE")) &&
        (!(o->sky_weight > 0) || (!o->sky[0] && !o->env_map[0])))
        return "of the sky term's SKY or ENV_MAP, which SKY_WEIGHT > 0 with one of them "
               "would use";
    if ((!strcmp(name, "DIRECTIONS") || !strcmp(name, "START_AZIMUTH")) &&
        tsd_product_takes(p, tsd_option_find("SKY_WEIGHT")) && !(o->sky_weight > 0))
        return "of the sky term, which SKY_WEIGHT=0 leaves out";
    return NULL;
}

int tsd_options_unused(const tsd_options *o, const tsd_product_def *p, char *buf, size_t n)
{
    int count = 0;
    size_t used = 0;
    char list[256];
    buf[0] = '\0';
    for (int i = 0; i < tsd_options_count(); i++) {
        if (!(o->given >> i & 1) || !(tsd_option_scope(i) & TSD_SCOPE_PRODUCT) ||
            tsd_option_applies(i) != TSD_APPLIES_LISTED)
            continue;
        char why[TSD_TEXT_MAX + 64];
        const char *moot = tsd_product_takes(p, i)
                               ? moot_beside(o, p, tsd_option_name(i), why, sizeof why)
                               : NULL;
        if (tsd_product_takes(p, i) && !moot)
            continue;
        /* a Byte-only product's OUTPUT_TYPE=Byte or AUTO names what it
         * writes (Float32 is refused): "does nothing here" misled */
        if (p->byte == TSD_BYTE_ALWAYS && !strcmp(tsd_option_name(i), "OUTPUT_TYPE"))
            continue;
        /* "SUN_AZIMUTH (an option of shade, shadow and envlight)" */
        if (!moot)
            tsd_products_taking(i, "", " and ", list, sizeof list);
        if (used < n)
            used += (size_t)snprintf(buf + used, n - used, "%s%s (%s%s)", count ? ", " : "",
                                     tsd_option_name(i), moot ? "" : "an option of ",
                                     moot ? moot : list);
        count++;
    }
    return count;
}

/* Horizon planes a HORIZON_METHOD=pyramid run holds at once: none where it
 * sums the sky terms row by row (svf, sky, openness, shade's uniform sky);
 * METHOD=sh's swath, or a batch of DIRECTIONS, where it hands out planes. */
static int pyramid_planes(const tsd_options *o, const tsd_product_def *p, int env_sky)
{
    int batch = o->directions < TS_PYRAMID_BATCH ? o->directions : TS_PYRAMID_BATCH;
    if (o->method == TSD_METHOD_SH && tsd_product_takes(p, tsd_option_find("METHOD")))
        return o->swath_directions < TS_PYRAMID_BATCH ? o->swath_directions : TS_PYRAMID_BATCH;
    if (p->compute == tsd_compute_svf || p->compute == tsd_compute_sky ||
        p->compute == tsd_compute_openness)
        return 0;
    if (p->compute == tsd_compute_shade)
        return env_sky ? batch : 0;
    return batch;
}

void tsd_shadowmap_aspect(double cell_x, const double *cell_x_row, int height, double cell_y,
                          double *map_x, double *map_y)
{
    /* the frame's cell: the shorter of cell_y and the central row's
     * (the narrowest row's counted a 0-80 N DEM's map 23 times over, the
     * review); its width: the widest row's */
    double hi = cell_x;
    for (int y = 0; cell_x_row && y < height; y++)
        hi = fmax(hi, cell_x_row[y]);
    const double shorter = fmin(cell_y, cell_x_row && height > 0 ? cell_x_row[height / 2] : cell_x);
    *map_x = shorter > 0 ? hi / shorter : 1;
    *map_y = shorter > 0 ? cell_y / shorter : 1;
}

double tsd_shadowmap_bytes(const tsd_options *o, int width, int height, double map_x,
                           double map_y)
{
    /* (non-square cells: a map of 30 x 89 m cells at 70 N was 3 times the
     * square cells' one counted, session 58's review) */
    const double w = width * map_x, h = height * map_y;
    const double plane = (double)width * height * sizeof(float);
    /* the sun's azimuth is known here unless DATETIME sets it: then the
     * widest, a diagonal */
    const double az = (o->datetime[0] ? 45.0 : o->sun_azimuth) * M_PI / 180;
    const double ca = fabs(cos(az)), sa = fabs(sin(az)), k = o->shadowmap_scale;
    /* (+ 4: the frame's ceil and its 3 texels of border, at every scale) */
    const double texels = (k * (w * ca + h * sa) + 4) * (k * (w * sa + h * ca) + 4);
    return 3 * plane + texels * (1 + 1.0 / 256) * sizeof(int);
}

/* Bytes of the shading method's own buffers beside its planes:
 * METHOD=shadowmap's map (SHADOWMAP_SCALE^2 int texels a cell of the DEM
 * turned to face the sun, the relief's extra rows at a low sun left out)
 * and its three projected-coordinate planes; METHOD=sh's folded wedge
 * tables (core/sh_swath_light.c: 256 x 256 x 16 floats an interior slot). */
static double method_bytes(const tsd_options *o, const tsd_product_def *p, int width,
                           int height, double map_x, double map_y)
{
    if (!tsd_product_takes(p, tsd_option_find("METHOD")))
        return 0;
    if (o->method == TSD_METHOD_SHADOWMAP)
        return tsd_shadowmap_bytes(o, width, height, map_x, map_y);
    if (o->method == TSD_METHOD_SH && o->swath_directions <= 8)
        return (o->swath_directions - 1) * (double)TS_SH_WEDGE_STEPS * TS_SH_WEDGE_STEPS *
               TS_SH_COEFFS * sizeof(float);
    return 0;
}

double tsd_product_peak_bytes(const tsd_options *o, int width, int height, double map_x,
                              double map_y, double *steady)
{
    const tsd_product_def *p = tsd_product_of(o);
    double plane = (double)width * (double)height * sizeof(float);
    double bands = tsd_options_band_count(o);
    /* bytes are a quarter of a float plane per band */
    double kept = p->byte == TSD_BYTE_ALWAYS ? bands / 4 : bands;
    /* shade's sky term from SKY or ENV_MAP: two more colour accumulators */
    int env_sky = o->sky_weight > 0 && p->sky_planes > 0 && (o->sky[0] || o->env_map[0]);
    /* SH: METHOD=sh keeps its SWATH_DIRECTIONS horizon planes, the first in
     * the product; ENV_METHOD=sh 16 visibility floats a cell and the first
     * and last horizon planes */
    int sh = o->method == TSD_METHOD_SH && tsd_product_takes(p, tsd_option_find("METHOD"))
                 ? o->swath_directions - 1
                 : o->env_method == TSD_ENV_SH ? 18 : 0;
    int extra = p->planes + (o->sky_weight > 0 ? p->sky_planes : 0) + 2 * env_sky + sh +
                (o->sun_position == TSD_SUN_PER_CELL ? p->per_cell_planes : 0);
    if (p->compute == tsd_compute_shade &&
        tsd_shade_without_planes(o, o->sun_position == TSD_SUN_PER_CELL))
        extra -= p->planes;
    if (steady)
        *steady = kept * plane;
    return (1 + kept + extra) * plane + method_bytes(o, p, width, height, map_x, map_y) +
           tsd_pyramid_bytes(o, width, height, pyramid_planes(o, p, env_sky));
}

char *tsd_products_xml(void)
{
    static const char *const byte_names[] = {"never", "allowed", "auto", "always"};
    tsd_options defaults;
    tsd_strbuf b = {0};
    tsd_options_defaults(&defaults);
    tsd_strbuf_add(&b, "<Products>");
    for (int i = 0; i < N_PRODUCTS; i++) {
        const tsd_product_def *p = &PRODUCTS[i];
        defaults.product = i;
        tsd_strbuf_add(&b, "<Product name='%s' description='", p->name);
        tsd_strbuf_add_xml(&b, p->description);
        tsd_strbuf_add(&b, "' unit='");
        tsd_strbuf_add_xml(&b, p->unit);
        tsd_strbuf_add(&b, "' bands='%d'", p->band_count(&defaults));
        if (p->bands_option)
            tsd_strbuf_add(&b, " bands_option='%s'", p->bands_option);
        tsd_strbuf_add(&b, " daily='%s' byte='%s' options='", p->daily ? "yes" : "no",
                       byte_names[p->byte]);
        for (int k = 0, listed = 0; k < tsd_options_count(); k++)
            if (tsd_product_takes(p, k))
                tsd_strbuf_add(&b, "%s%s", listed++ ? "," : "", tsd_option_name(k));
        tsd_strbuf_add(&b, "'/>");
    }
    tsd_strbuf_add(&b, "</Products>");
    return tsd_strbuf_finish(&b);
}

/* AVX-512/AVX2 clones: CopyRow runs in the caller's one thread. */
TS_SIMD_CLONES
void tsd_row_to_byte(const float *restrict v, int n, unsigned char *restrict out)
{
    /* on the bits, without float compares (which would keep the loop from
     * vectorising under trapping math): masks of 0 < v < 1, v NaN and
     * 1 <= v <= inf; heights of the rest 0 before the conversion, so that
     * it is defined; then tsd_to_byte's rounding or its constants */
    for (int i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &v[i], sizeof u);
        uint32_t in = -(uint32_t)(u - 1u < 0x3f7fffffu);
        uint32_t uc = u & in;
        float c;
        memcpy(&c, &uc, sizeof c);
        uint32_t b = (uint32_t)(int32_t)(1.0f + 254.0f * c + 0.5f);
        uint32_t nan = -(uint32_t)((u & 0x7fffffffu) > 0x7f800000u);
        uint32_t big = -(uint32_t)(u - 0x3f800000u <= 0x7f800000u - 0x3f800000u);
        out[i] = (unsigned char)(((b & ~big) | (255u & big)) & ~nan);
    }
}

int tsd_sweeps_negated_dem(const tsd_options *o)
{
    /* OPENNESS is refused on every product but openness (tsd_options_check) */
    return o->openness_negative && strcmp(tsd_product_of(o)->name, "openness") == 0;
}

void tsd_negate_heights(const ts_grid *from, ts_grid *to)
{
    for (int y = 0; y < from->height; y++)
        for (int x = 0; x < from->width; x++)
            to->z[(ptrdiff_t)y * to->stride + x] =
                from->z[(ptrdiff_t)y * from->stride + x] * -1.0f;
}
