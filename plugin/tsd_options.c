/* The TERRASHADE driver's options: looking them up, parsing, the defaults. */
#include "tsd_options.h"

#include "tsd_option_table.h"
#include "tsd_products.h"
#include "tsd_text.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

int tsd_options_count(void)
{
    return TSD_OPTION_COUNT;
}

const char *tsd_option_name(int i)
{
    return i >= 0 && i < TSD_OPTION_COUNT ? TSD_OPTION_ROWS[i].name : NULL;
}

int tsd_option_find(const char *name)
{
    for (int i = 0; i < TSD_OPTION_COUNT; i++)
        if (strcasecmp(name, TSD_OPTION_ROWS[i].name) == 0)
            return i;
    return -1;
}

int tsd_option_scope(int i)
{
    return i >= 0 && i < TSD_OPTION_COUNT ? TSD_OPTION_ROWS[i].scope : 0;
}

tsd_applies tsd_option_applies(int i)
{
    return i >= 0 && i < TSD_OPTION_COUNT ? TSD_OPTION_ROWS[i].applies : TSD_APPLIES_SELECTOR;
}

const char *tsd_option_default(int i)
{
    return i >= 0 && i < TSD_OPTION_COUNT ? TSD_OPTION_ROWS[i].def : NULL;
}

int tsd_options_given(const tsd_options *o, const char *name)
{
    int i = tsd_option_find(name);
    return i >= 0 && (o->given >> i & 1);
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
        if (end == v || *end)
            REFUSE("%s must be a whole number, got '%s'", d->name, v);
        /* a whole number too long for a long: past the range below */
        *out = errno == ERANGE ? (l < 0 ? -INFINITY : INFINITY) : (double)l;
    } else if (tsd_parse_decimal(v, out) != 0) {
        if (d->kind == K_FLOAT_AUTO)
            REFUSE("%s must be %s or a number, got '%s'", d->name, d->values, v);
        REFUSE("%s must be a number, got '%s'", d->name, v);
    }
    double x = *out;
    int low = d->min_exclusive ? !(x > d->min) : !(x >= d->min);
    int high = d->has_max && !(x <= d->max);
    if (!low && !high)
        return 0;
    /* whole numbers' limits in full (%g wrote 1 << 20 as 1.04858e+06) */
    char lo[32], hi[32];
    snprintf(lo, sizeof lo, d->kind == K_INT ? "%.0f" : "%g", d->min);
    snprintf(hi, sizeof hi, d->kind == K_INT ? "%.0f" : "%g", d->max);
    if (d->min_exclusive)
        REFUSE("%s must be greater than %s and at most %s, got %s", d->name, lo, hi, v);
    if (!d->has_max)
        REFUSE("%s must be at least %s, got %s", d->name, lo, v);
    REFUSE("%s must be between %s and %s, got %s", d->name, lo, hi, v);
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

/* Set option `id` of `o` from its text (not empty). */
static int set_option(tsd_options *o, int id, const char *v, char *msg, size_t n)
{
    const opt_def *d = &TSD_OPTION_ROWS[id];
    char *field = (char *)o + d->field;
    double x = 0;
    int k = 0;
    char list[256];
    switch (d->kind) {
    case K_PRODUCT:
    case K_SELECT:
        k = d->kind == K_PRODUCT ? tsd_product_find(v) : select_index(d->values, v);
        if (k < 0) {
            tsd_option_list_values(d, list, sizeof list);
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
    case K_FLOAT_AUTO:
        if (strcasecmp(v, d->values) == 0) {
            x = NAN;
            memcpy(field, &x, sizeof x);
            return 0;
        }
        /* fall through - a number */
    case K_FLOAT:
    case K_INT:
        /* the row's own check first: it may word the range better (LIGHT_RADIUS) */
        if ((d->read && d->read(v, NULL, 0, msg, n) != 0) || parse_number(d, v, &x, msg, n) != 0)
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
            REFUSE("%s is too long (%zu characters; at most %zu)", d->name, strlen(v),
                   d->size - 1);
        }
        if (d->read && d->read(v, NULL, 0, msg, n) != 0)
            return -1;
        snprintf(field, d->size, "%s", v);
        return 0;
    }
    return -1;
}

void tsd_options_defaults(tsd_options *o)
{
    memset(o, 0, sizeof *o);
    for (int i = 0; i < TSD_OPTION_COUNT; i++)
        if (TSD_OPTION_ROWS[i].def[0])
            set_option(o, i, TSD_OPTION_ROWS[i].def, NULL, 0); /* checked by check_options */
}

/* Copy s without surrounding blanks into buf; returns buf. */
/* s[0..len) without surrounding spaces into buf of n bytes; returns its
 * length, n or more where it did not fit (buf then holds its start). */
static size_t trim(const char *s, size_t len, char *buf, size_t n)
{
    while (len && isspace((unsigned char)*s)) {
        s++;
        len--;
    }
    while (len && isspace((unsigned char)s[len - 1]))
        len--;
    const size_t full = len;
    if (len >= n)
        len = n - 1;
    memcpy(buf, s, len);
    buf[len] = '\0';
    return full;
}

/* Whether two spellings of option id's value mean the same: as numbers,
 * booleans, choices or the text options' readings (tsd_option_meaning),
 * else as text (case aside). */
static int same_value(int id, const char *a, const char *b)
{
    const opt_def *d = &TSD_OPTION_ROWS[id];
    double x, y;
    int p, q;
    switch (d->kind) {
    case K_FLOAT:
    case K_FLOAT_AUTO:
    case K_INT:
        if (tsd_parse_decimal(a, &x) == 0 && tsd_parse_decimal(b, &y) == 0)
            return x == y;
        break;
    case K_BOOL:
        if (parse_bool(a, &p) == 0 && parse_bool(b, &q) == 0)
            return p == q;
        break;
    default: {
        char ma[128], mb[128];
        if (tsd_option_meaning(id, a, ma, sizeof ma) == 0 &&
            tsd_option_meaning(id, b, mb, sizeof mb) == 0)
            return strcmp(ma, mb) == 0;
        break;
    }
    }
    return strcasecmp(a, b) == 0;
}

/* The names of the options of `scope`, "A, B, C"; for an atlas "A, B and
 * C", its own options before those it shares with products (THREADS). */
static void list_names(int scope, char *buf, size_t n)
{
    const int atlas = scope == TSD_SCOPE_ATLAS;
    size_t used = 0;
    int total = 0, k = 0;
    buf[0] = '\0';
    for (int i = 0; i < TSD_OPTION_COUNT; i++)
        total += (TSD_OPTION_ROWS[i].scope & scope) != 0;
    for (int pass = atlas ? 0 : 1; pass < 2; pass++)
        for (int i = 0; i < TSD_OPTION_COUNT && used < n; i++) {
            if (!(TSD_OPTION_ROWS[i].scope & scope) ||
                (pass == 0 && TSD_OPTION_ROWS[i].scope != scope))
                continue;
            if (atlas && pass == 1 && TSD_OPTION_ROWS[i].scope == scope)
                continue; /* listed in pass 0 */
            const char *sep = k == 0 ? "" : atlas && k == total - 1 ? " and " : ", ";
            used += (size_t)snprintf(buf + used, n - used, "%s%s", sep, TSD_OPTION_ROWS[i].name);
            k++;
        }
}

/* Apply "KEY=VALUE" items of a dataset of `scope`. */
static int apply_scope(tsd_options *o, const char *const *kv, int scope, char *msg,
                       size_t n)
{
    const char *seen[64] = {0}; /* the item that set each option (<= 64 options) */
    for (size_t i = 0; kv && kv[i]; i++) {
        const char *item = kv[i];
        const char *eq = strchr(item, '=');
        char key[128], value[TSD_PATH_MAX], before[TSD_PATH_MAX], names[1024];
        if (!eq)
            REFUSE("%s '%s' is not of the form KEY=VALUE",
                   scope == TSD_SCOPE_ATLAS ? "open option" : "option", item);
        trim(item, (size_t)(eq - item), key, sizeof key);
        const size_t nvalue = trim(eq + 1, strlen(eq + 1), value, sizeof value);
        int id = tsd_option_find(key);
        if (id >= 0 && !(TSD_OPTION_ROWS[id].scope & scope) && scope == TSD_SCOPE_PRODUCT)
            REFUSE("%s is an open option of far-shadow atlas files (.tsa), not of "
                   "TERRASHADE:<dem>", key);
        if (id < 0 || !(TSD_OPTION_ROWS[id].scope & scope)) {
            list_names(scope, names, sizeof names);
            if (scope == TSD_SCOPE_ATLAS)
                REFUSE("an atlas takes the open options %s, not '%s'", names, key);
            REFUSE("unknown option '%s'; the options are %s (see gdalinfo "
                   "--format TERRASHADE)", key, names);
        }
        if (nvalue >= sizeof value)
            REFUSE("%s is too long (%zu characters; at most %zu)", TSD_OPTION_ROWS[id].name,
                   nvalue, sizeof value - 1);
        if (seen[id]) {
            const char *e = strchr(seen[id], '=');
            trim(e + 1, strlen(e + 1), before, sizeof before);
            if (!same_value(id, before, value))
                REFUSE("%s is given twice, as %s and as %s", TSD_OPTION_ROWS[id].name, before,
                       value);
        }
        seen[id] = item;
        if (!value[0])
            REFUSE("%s needs a value (%s=...)", TSD_OPTION_ROWS[id].name, TSD_OPTION_ROWS[id].name);
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

