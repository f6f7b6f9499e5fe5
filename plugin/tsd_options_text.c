/* The options as text: values, the canonical PAM key, the open-option XML. */
#include "tsd_options.h"

#include "tsd_option_table.h"
#include "tsd_products.h"
#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The i-th value of a '|'-list into buf ("" past the end). */
const char *tsd_select_value(const char *values, int index, char *buf, size_t n)
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

/* "a, b, c" of a '|'-list, or of the products' names. */
void tsd_option_list_values(const opt_def *d, char *buf, size_t n)
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
                                             : tsd_select_value(d->values, k, value, sizeof value);
        used += (size_t)snprintf(buf + used, n - used, "%s%s", k ? ", " : "", v);
    }
}

const char *tsd_options_value(const tsd_options *o, int i, char *buf, size_t n)
{
    if (i < 0 || i >= TSD_OPTION_COUNT)
        return NULL;
    const opt_def *d = &TSD_OPTION_ROWS[i];
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
        tsd_select_value(d->values, k, buf, n);
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
    case K_FLOAT_AUTO:
        memcpy(&x, field, sizeof x);
        if (d->kind == K_FLOAT_AUTO && isnan(x))
            snprintf(buf, n, "%s", d->values); /* not decided yet */
        else
            snprintf(buf, n, "%.10g", x + 0.0); /* (-0 as 0: one value, one PAM entry) */
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
    for (int i = 0; i < TSD_OPTION_COUNT; i++) {
        char value[TSD_PATH_MAX]; /* a path's whole length: the key must tell maps apart */
        if (!TSD_OPTION_ROWS[i].affects_pixels)
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
    /* K_FLOAT_AUTO: a string for GDAL, which has no type "number or word" */
    static const char *const type_names[] = {"string-select", "float", "int", "boolean",
                                             "string", "string-select", "string"};
    tsd_strbuf b = {0};
    tsd_strbuf_add(&b, "<OpenOptionList>");
    for (int i = 0; i < TSD_OPTION_COUNT; i++) {
        const opt_def *d = &TSD_OPTION_ROWS[i];
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
            for (int k = 0; d->kind == K_SELECT && tsd_select_value(d->values, k, value,
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
