/* ISO 8601 basic format to extended format; see tsd_datetime.h. */
#include "tsd_datetime.h"

#include <stdio.h>
#include <string.h>

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
