/* Failing with a sentence, reading a number, and a growing string; see
 * tsd_text.h. */
#include "tsd_text.h"

#include <ctype.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

ts_status tsd_fail(char *msg, size_t n, ts_status code, const char *fmt, ...)
{
    if (msg && n) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, n, fmt, ap);
        va_end(ap);
    }
    return code == TS_OK ? TS_ERR_INTERNAL : code;
}

ts_status tsd_fail_core(char *msg, size_t n, const char *what, const ts_error *err)
{
    const char *text = err->message[0] ? err->message : ts_status_name(err->code);
    if (what)
        return tsd_fail(msg, n, err->code, "%s: %s", what, text);
    return tsd_fail(msg, n, err->code, "%s", text);
}

static locale_t c_locale;
static pthread_once_t c_locale_once = PTHREAD_ONCE_INIT;

static void make_c_locale(void)
{
    c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
}

locale_t tsd_c_locale(void)
{
    pthread_once(&c_locale_once, make_c_locale);
    return c_locale;
}

/* Whether the digits before the exponent hold one that is not 0: a value
 * so small that strtod rounds it to 0 (1e-400) keeps its sign of being
 * positive, so that MAX_DISTANCE=1e-400 is refused as too short instead of
 * read as 0, "unbounded". */
static int nonzero_mantissa(const char *digits, const char *end)
{
    for (; digits < end && *digits != 'e' && *digits != 'E'; digits++)
        if (*digits >= '1' && *digits <= '9')
            return 1;
    return 0;
}

int tsd_parse_decimal(const char *text, double *x)
{
    const char *digits = text;
    while (isspace((unsigned char)*digits))
        digits++;
    digits += *digits == '+' || *digits == '-';
    if (!isdigit((unsigned char)digits[0]) && digits[0] != '.')
        return -1; /* (strtod also reads "inf" and "nan") */
    if (digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
        return -1;
    const locale_t c = tsd_c_locale();
    char *end;
    const double v = c ? strtod_l(text, &end, c) : strtod(text, &end);
    if (end == text || !isfinite(v))
        return -1;
    const char *tail = end;
    while (isspace((unsigned char)*tail))
        tail++;
    if (*tail)
        return -1;
    *x = v == 0 && nonzero_mantissa(digits, end) ? copysign(DBL_TRUE_MIN, v) : v;
    return 0;
}

void tsd_strbuf_add(tsd_strbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int need = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (b->failed || need < 0) {
        b->failed = 1;
        return;
    }
    if (b->len + (size_t)need + 1 > b->cap) {
        size_t cap = (b->cap ? b->cap * 2 : 4096) + (size_t)need;
        char *s = realloc(b->s, cap);
        if (!s) {
            b->failed = 1;
            return;
        }
        b->s = s;
        b->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(b->s + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    b->len += (size_t)need;
}

void tsd_strbuf_add_xml(tsd_strbuf *b, const char *text)
{
    for (const char *c = text; *c && !b->failed; c++)
        switch (*c) {
        case '\'': tsd_strbuf_add(b, "&apos;"); break;
        case '&': tsd_strbuf_add(b, "&amp;"); break;
        case '<': tsd_strbuf_add(b, "&lt;"); break;
        default: tsd_strbuf_add(b, "%c", *c); break;
        }
}

char *tsd_strbuf_finish(tsd_strbuf *b)
{
    if (b->failed) {
        free(b->s);
        b->s = NULL;
    }
    return b->s;
}
