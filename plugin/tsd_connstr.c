/* TERRASHADE connection strings: inline options and the DEM's name. */
#include "tsd_connstr.h"

#include "tsd_text.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

int tsd_connstr_matches(const char *name)
{
    return name && strncasecmp(name, TSD_PREFIX, strlen(TSD_PREFIX)) == 0;
}

/* Is s[0..len) "KEY=VALUE" with KEY an identifier (blanks allowed around)? */
static int is_item(const char *s, size_t len)
{
    size_t i = 0;
    while (i < len && s[i] == ' ')
        i++;
    if (i == len || !(isalpha((unsigned char)s[i]) || s[i] == '_'))
        return 0;
    while (i < len && (isalnum((unsigned char)s[i]) || s[i] == '_'))
        i++;
    while (i < len && s[i] == ' ')
        i++;
    return i < len && s[i] == '=';
}

/* The first of the comma-separated items of s[0..len) that is not
 * KEY=VALUE: 1 with its offset and length, 0 where every one is. */
static int bad_item(const char *s, size_t len, size_t *at, size_t *n)
{
    size_t start = 0;
    for (size_t i = 0; i <= len; i++) {
        if (i == len || s[i] == ',') {
            if (!is_item(s + start, i - start)) {
                *at = start;
                *n = i - start;
                return 1;
            }
            start = i + 1;
        }
    }
    return 0;
}

/* Does s[0..len) consist of comma-separated KEY=VALUE items? */
static int is_option_segment(const char *s, size_t len)
{
    size_t at, n;
    return len > 0 && !bad_item(s, len, &at, &n);
}

static char *dup_range(const char *s, size_t len)
{
    char *d = malloc(len + 1);
    if (d) {
        memcpy(d, s, len);
        d[len] = '\0';
    }
    return d;
}

ts_status tsd_connstr_parse(const char *name, tsd_connstr *out, char *msg,
                            size_t msg_size)
{
    out->options = NULL;
    out->dem = NULL;
    if (!tsd_connstr_matches(name))
        return tsd_fail(msg, msg_size, TS_ERR_ARG, "'%s' does not start with " TSD_PREFIX,
                        name ? name : "");
    const char *rest = name + strlen(TSD_PREFIX);
    const char *colon = strchr(rest, ':');
    size_t seg_len = colon ? (size_t)(colon - rest) : strlen(rest);
    int n_items = 0;
    if (is_option_segment(rest, seg_len)) {
        if (!colon)
            return tsd_fail(msg, msg_size, TS_ERR_ARG,
                            "'%s' names no DEM: write TERRASHADE:KEY=VALUE,...:<dem> "
                            "(quote a DEM name that contains '=' before any ':')",
                            name);
        n_items = 1;
        for (size_t i = 0; i < seg_len; i++)
            n_items += rest[i] == ',';
    } else {
        seg_len = 0;
        colon = NULL;
    }
    out->options = calloc((size_t)n_items + 1, sizeof *out->options);
    if (!out->options)
        return tsd_fail(msg, msg_size, TS_ERR_NOMEM, "out of memory");
    const char *p = rest;
    for (int k = 0; k < n_items; k++) {
        const char *end = memchr(p, ',', (size_t)(rest + seg_len - p));
        if (!end)
            end = rest + seg_len;
        out->options[k] = dup_range(p, (size_t)(end - p));
        if (!out->options[k])
            return tsd_fail(msg, msg_size, TS_ERR_NOMEM, "out of memory");
        p = end + 1;
    }
    const char *dem = colon ? colon + 1 : rest;
    size_t dem_len = strlen(dem);
    if (dem_len >= 2 && dem[0] == '"' && dem[dem_len - 1] == '"') {
        dem++;
        dem_len -= 2;
    }
    if (dem_len == 0)
        return tsd_fail(msg, msg_size, TS_ERR_ARG, "'%s' names no DEM: write TERRASHADE:<dem> or "
                    "TERRASHADE:KEY=VALUE,...:<dem>", name);
    out->dem = dup_range(dem, dem_len);
    if (!out->dem)
        return tsd_fail(msg, msg_size, TS_ERR_NOMEM, "out of memory");
    return TS_OK;
}

/* Was the last inline item key=value cut at a ':' of its value, leaving
 * dem? A time (TIMEZONE, DATETIME) whose value ends in the hours or minutes,
 * the DEM starting with the next two digits, then a ':', an offset, Z, a ','
 * (more items) or nothing; or SKY=cie, the DEM starting with the sky type's
 * digits, then a ':', a ',' or nothing. (strchr finds the '\0' too.) */
static int cut_at_colon(const char *key, int key_len, const char *value, const char *dem)
{
    size_t n = strlen(value), digits = strspn(dem, "0123456789");
    if (key_len == 3 && !strncasecmp(key, "SKY", 3))
        return !strcasecmp(value, "cie") && digits > 0 && strchr(":,", dem[digits]);
    if (key_len != 8 || (strncasecmp(key, "TIMEZONE", 8) && strncasecmp(key, "DATETIME", 8)))
        return 0;
    return n > 0 && isdigit((unsigned char)value[n - 1]) && digits >= 2 &&
           strchr(":+-Z,", dem[2]);
}

void tsd_connstr_cut_colon_hint(const tsd_connstr *c, char *hint, size_t hint_size)
{
    hint[0] = '\0';
    if (!c->options || !c->options[0] || !c->dem)
        return;
    const char *last = c->options[0];
    for (char **p = c->options; *p; p++)
        last = *p;
    last += strspn(last, " ");
    int key_len = (int)strcspn(last, " =");
    const char *value = strchr(last, '=') + 1; /* an item is KEY=VALUE */
    if (!cut_at_colon(last, key_len, value, c->dem))
        return;
    snprintf(hint, hint_size,
             "; the inline options end at the first ':', so %.*s ends at '%s' and the "
             "rest, '%s', was taken as the DEM's name: write times and skies without ':' "
             "inline (TIMEZONE=-0500, DATETIME=2026-06-21T073000+0200, SKY=cie9) or give "
             "the option as an open option (-oo)",
             key_len, last, value, c->dem);
}

void tsd_connstr_segment_hint(const tsd_connstr *c, char *hint, size_t hint_size)
{
    hint[0] = '\0';
    if (!c->dem || (c->options && c->options[0]))
        return;
    const char *colon = strchr(c->dem, ':');
    const char *eq = strchr(c->dem, '=');
    if (!colon || !eq || eq > colon)
        return;
    /* the first item of the would-be segment that is not KEY=VALUE */
    const size_t len = (size_t)(colon - c->dem);
    size_t at, n;
    if (!bad_item(c->dem, len, &at, &n))
        return;
    if (n == 0)
        snprintf(hint, hint_size,
                 "; if '%.*s' was meant as inline options, it has an empty item (a doubled or "
                 "trailing ','): every item between the commas must be KEY=VALUE",
                 (int)len, c->dem);
    else
        snprintf(hint, hint_size,
                 "; if '%.*s' was meant as inline options, its item '%.*s' is not KEY=VALUE, "
                 "as every item between the commas must be",
                 (int)len, c->dem, (int)n, c->dem + at);
}

const char *tsd_connstr_add_hint(char *msg, size_t msg_size, const char *hint)
{
    size_t n = strlen(msg);
    if (!hint[0])
        return msg;
    if (n > 0 && msg[n - 1] == '.')
        msg[--n] = '\0';
    snprintf(msg + n, msg_size - n, "%s", hint);
    return msg;
}

void tsd_connstr_free(tsd_connstr *c)
{
    if (!c)
        return;
    if (c->options)
        for (char **p = c->options; *p; p++)
            free(*p);
    free(c->options);
    free(c->dem);
    c->options = NULL;
    c->dem = NULL;
}
