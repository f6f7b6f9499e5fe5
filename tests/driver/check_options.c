/*
 * check_options - the driver's option table against the struct it fills:
 * every declared default (the text that gdalinfo --format TERRASHADE shows)
 * equals the default in tsd_options, whichever way it is read; and the
 * refraction default is the core's.
 *
 * - the value of each option in tsd_options_defaults, written back as text,
 *   is its declared default (OUTPUT_TYPE=AUTO: the field is TSD_OUT_AUTO);
 * - giving each declared default explicitly (the parser users go through)
 *   leaves the defaults struct unchanged;
 * - the open-option XML declares the same default for every option;
 * - REFRACTION's default is TSD_REFRACTION_DEFAULT and the core's
 *   ts_horizon_opts_default; the sun defaults are gdaldem's 315 / 45;
 * - sentences that scripts and tests read, made from the tables, are the
 *   ones written before the tables made them;
 * - the block copies' vectorised tsd_row_to_byte equals tsd_to_byte on
 *   every float of a stride through all 2^32 bit patterns and on the
 *   values where it changes (0, 1, NaN, inf and each rounding boundary);
 * - the order keys that reduce a DEM read's lowest and highest heights in
 *   integer lanes (tsd_dem_check.h) order as the floats do and give the
 *   float back, on a stride through all non-NaN bit patterns and their
 *   neighbours.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"
#include "tsd_dem_check.h"
#include "tsd_options.h"
#include "tsd_products.h"

static int failures = 0;

#define EXPECT(cond, ...)                                                                \
    do {                                                                                 \
        if (!(cond)) {                                                                   \
            failures++;                                                                  \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                                  \
            printf(__VA_ARGS__);                                                         \
            printf("\n");                                                                \
        }                                                                                \
    } while (0)

/* tsd_options without the given-bits (which say what was given, not values) */
static int same_values(tsd_options a, tsd_options b)
{
    a.given = b.given = 0;
    return memcmp(&a, &b, sizeof a) == 0;
}

static void check_round_trip(const tsd_options *d)
{
    for (int i = 0; i < tsd_options_count(); i++) {
        char value[TSD_PATH_MAX];
        const char *name = tsd_options_value(d, i, value, sizeof value);
        const char *declared = tsd_option_default(i);
        if (strcmp(name, "OUTPUT_TYPE") == 0) {
            /* the value written is the effective type; the field is AUTO */
            EXPECT(strcmp(declared, "AUTO") == 0 && d->output_type == TSD_OUT_AUTO,
                   "OUTPUT_TYPE: declared %s, field %d", declared, d->output_type);
            continue;
        }
        printf("%-16s declared '%s', struct '%s'\n", name, declared, value);
        EXPECT(strcmp(value, declared) == 0, "%s: declared default '%s', struct has '%s'",
               name, declared, value);
    }
}

static void check_given_explicitly(const tsd_options *d)
{
    for (int i = 0; i < tsd_options_count(); i++) {
        const char *declared = tsd_option_default(i);
        if (!declared[0])
            continue; /* a text option: off until given */
        char item[256], msg[512] = "";
        snprintf(item, sizeof item, "%s=%s", tsd_option_name(i), declared);
        const char *kv[] = {item, NULL};
        tsd_options o = *d;
        int rc = tsd_option_scope(i) & TSD_SCOPE_PRODUCT
                     ? tsd_options_apply(&o, kv, msg, sizeof msg)
                     : tsd_options_apply_atlas(&o, kv, msg, sizeof msg);
        EXPECT(rc == 0, "%s: %s", item, msg);
        EXPECT(same_values(o, *d), "%s given explicitly changes the defaults", item);
        EXPECT(tsd_options_given(&o, tsd_option_name(i)), "%s not marked as given", item);
    }
}

static void check_xml(void)
{
    char *xml = tsd_options_xml();
    EXPECT(xml != NULL, "no open-option XML");
    for (int i = 0; xml && i < tsd_options_count(); i++) {
        char key[64];
        snprintf(key, sizeof key, "<Option name='%s' ", tsd_option_name(i));
        const char *at = strstr(xml, key);
        EXPECT(at != NULL, "%s missing from the open-option XML", tsd_option_name(i));
        if (!at)
            continue;
        const char *end = strchr(at, '>');
        const char *def = strstr(at, " default='");
        const char *declared = tsd_option_default(i);
        if (!def || def > end) {
            EXPECT(!declared[0], "%s: no default in the XML, declared '%s'",
                   tsd_option_name(i), declared);
            continue;
        }
        def += strlen(" default='");
        EXPECT(strncmp(def, declared, strlen(declared)) == 0 &&
                   def[strlen(declared)] == '\'',
               "%s: XML default differs from the declared '%s'", tsd_option_name(i),
               declared);
    }
    free(xml);
}

/* Applying `item` fails with exactly `sentence`. */
static void expect_sentence(int atlas, const char *item, const char *sentence)
{
    tsd_options o;
    char msg[1024] = "";
    const char *kv[] = {item, NULL};
    tsd_options_defaults(&o);
    int rc = atlas ? tsd_options_apply_atlas(&o, kv, msg, sizeof msg)
                   : tsd_options_apply(&o, kv, msg, sizeof msg);
    printf("%s -> %s\n", item, msg);
    EXPECT(rc != 0 && strcmp(msg, sentence) == 0, "%s: got '%s', expected '%s'", item, msg,
           sentence);
}

static void check_sentences(void)
{
    expect_sentence(1, "PRODUCT=shade",
                    "an atlas takes the open options SHADOWS, DEM and THREADS, not 'PRODUCT'");
    expect_sentence(1, "SHADOWS=near", "SHADOWS must be one of far, all, got 'near'");
    expect_sentence(0, "SHADOWS=all",
                    "SHADOWS is an open option of far-shadow atlas files (.tsa), not of "
                    "TERRASHADE:<dem>");
    expect_sentence(0, "PRODUCT=x",
                    "PRODUCT must be one of shade, shadow, horizon, svf, openness, sky, "
                    "sunhours, insolation, daycycle, farshadow, envlight, got 'x'");
    expect_sentence(0, "SUN_AZIMUT=1",
                    "unknown option 'SUN_AZIMUT'; the options are PRODUCT, SUN_AZIMUTH, "
                    "SUN_ELEVATION, DIRECTIONS, START_AZIMUTH, METHOD, PENUMBRA_DEPTH, "
                    "LIGHT_RADIUS, SWATH_DIRECTIONS, SHADOWMAP_SCALE, PCF_KERNEL, "
                    "Z_FACTOR, CELL_SIZES, MAX_DISTANCE, CURVATURE, REFRACTION, SKY_WEIGHT, BAND, "
                    "THREADS, OUTPUT_TYPE, MAX_MEMORY, TILE_SIZE, NEAR_DISTANCE, DATETIME, DATE, "
                    "START_DATE, "
                    "END_DATE, "
                    "TIMEZONE, STEP_MINUTES, DAY_INTERVAL, HORIZON_DIRECTIONS, PRESSURE, "
                    "TEMPERATURE, DELTA_T, SUN_POSITION, "
                    "LINKE_TURBIDITY, FAR_THRESHOLD, ATLAS_STEPS, BACKEND, SUNHOURS_RULE, "
                    "PROGRESS, ENV_MAP, ENV_ROTATION, SKY, ENV_HORIZON_STEPS, "
                    "ENV_NORMAL_STEPS, EXPOSURE, ENV_METHOD, SVF_MODEL, OPENNESS, EDGE, "
                    "HORIZON_METHOD, PYRAMID_LEVEL_STEP, PYRAMID_OFFSET (see gdalinfo --format "
                    "TERRASHADE)");
    expect_sentence(0, "EDGE=foo", "EDGE must be one of horizon, open, nodata, got 'foo'");
    expect_sentence(0, "Z_FACTOR=0", "Z_FACTOR must be greater than 0 and at most 1e+06, got 0");
    expect_sentence(0, "Z_FACTOR=feet", "Z_FACTOR must be AUTO or a number, got 'feet'");
    expect_sentence(0, "SUN_POSITION=per_cell",
                    "SUN_POSITION=per_cell needs the sun from DATETIME or DATE");
}

/* tsd_row_to_byte against tsd_to_byte on n floats of bits u[] */
static void expect_bytes(const uint32_t *u, int n)
{
    float v[256];
    unsigned char b[256];
    for (int i = 0; i < n; i++)
        memcpy(&v[i], &u[i], sizeof v[i]);
    tsd_row_to_byte(v, n, b);
    for (int i = 0; i < n; i++)
        EXPECT(b[i] == tsd_to_byte(v[i]), "tsd_row_to_byte(%a) = %d, tsd_to_byte %d", v[i],
               b[i], tsd_to_byte(v[i]));
}

/* add the float of bits x to the batch u (n of them), checked when full */
static void push_bits(uint32_t *u, int *n, uint32_t x)
{
    u[(*n)++] = x;
    if (*n == 256)
        expect_bytes(u, *n), *n = 0;
}

static void push_float(uint32_t *u, int *n, float f)
{
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    push_bits(u, n, x);
}

static void check_row_to_byte(void)
{
    uint32_t u[256];
    int n = 0;
    for (uint64_t x = 0; x < (1ull << 32); x += 4093)
        push_bits(u, &n, (uint32_t)x);
    static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, INFINITY, -INFINITY, NAN, -NAN};
    for (size_t i = 0; i < sizeof special / sizeof *special; i++) {
        push_float(u, &n, nextafterf(special[i], -INFINITY));
        push_float(u, &n, special[i]);
        push_float(u, &n, nextafterf(special[i], INFINITY));
    }
    for (int k = 1; k <= 255; k++) { /* 1 + 254 v + 0.5 crosses k + 1 */
        float f = (float)((k - 0.5) / 254.0);
        push_float(u, &n, nextafterf(f, 0.0f));
        push_float(u, &n, f);
        push_float(u, &n, nextafterf(f, 1.0f));
    }
    expect_bytes(u, n);
}

/* f < g => key(f) < key(g); key(f) < key(g) => f <= g (-0 keys below +0) */
static void expect_keys_order(uint32_t a, uint32_t b)
{
    float f, g;
    memcpy(&f, &a, sizeof f);
    memcpy(&g, &b, sizeof g);
    if (isnan(f) || isnan(g))
        return;
    uint32_t ka = tsd_order_key(a), kb = tsd_order_key(b);
    EXPECT(!(f < g) || ka < kb, "key(%a) = %#x not below key(%a) = %#x", f, ka, g, kb);
    EXPECT(!(ka < kb) || f <= g, "key(%a) = %#x below key(%a) = %#x", f, ka, g, kb);
    float back = tsd_key_float(ka);
    EXPECT(memcmp(&back, &f, sizeof f) == 0, "key_float(key(%a)) = %a", f, back);
}

static void check_order_keys(void)
{
    const uint32_t special[] = {0, 0x80000000u, 1, 0x80000001u, 0x7f7fffffu, 0xff7fffffu,
                                0x7f800000u, 0xff800000u, 0x3f800000u, 0xbf800000u};
    const int ns = (int)(sizeof special / sizeof special[0]);
    for (int i = 0; i < ns; i++)
        for (int j = 0; j < ns; j++)
            expect_keys_order(special[i], special[j]);
    for (uint64_t b = 0; b <= UINT32_MAX; b += 65521) {
        uint32_t u = (uint32_t)b;
        expect_keys_order(u, u + 1);
        expect_keys_order(u + 1, u);
        expect_keys_order(u, u ^ 0x80000000u);
        expect_keys_order(u, (uint32_t)(b * 2654435761u));
    }
}

int main(void)
{
    tsd_options d;
    ts_horizon_opts h;
    tsd_options_defaults(&d);
    ts_horizon_opts_default(&h);
    EXPECT(d.given == 0, "defaults marked as given");
    check_round_trip(&d);
    check_given_explicitly(&d);
    check_xml();
    check_sentences();
    check_row_to_byte();
    check_order_keys();
    EXPECT(d.refraction == TSD_REFRACTION_DEFAULT, "REFRACTION default %g", d.refraction);
    EXPECT(h.refraction == TSD_REFRACTION_DEFAULT,
           "the core's refraction default %g differs from the driver's %g", h.refraction,
           TSD_REFRACTION_DEFAULT);
    EXPECT(d.sun_azimuth == 315 && d.sun_elevation == 45, "sun default %g / %g",
           d.sun_azimuth, d.sun_elevation);
    EXPECT(strcmp(tsd_product_of(&d)->name, "shade") == 0, "PRODUCT default %s",
           tsd_product_of(&d)->name);
    /* Z_FACTOR=AUTO: NAN until the DEM's vertical unit decides it */
    EXPECT(d.curvature == 1 && isnan(d.z_factor) && d.band == 1 && d.directions == 16,
           "curvature %d, z %g, band %d, directions %d", d.curvature, d.z_factor, d.band,
           d.directions);
    printf("%s: %d option(s), %d failure(s)\n", failures ? "FAIL" : "PASS",
           tsd_options_count(), failures);
    return failures ? 1 : 0;
}
