/*
 * fuzz_options: the TERRASHADE connection string and the option parser, as
 * the driver's Open chains them (plugin/gdal_terrashade.cpp): parse
 * "TERRASHADE:[KEY=VALUE,...:]<dem>", then apply its inline options followed
 * by the open options (-oo KEY=VALUE) to the defaults.
 *
 * Input: the connection string on the first line, one open option per
 * following line. Besides the sanitizers, it checks what a caller relies on:
 * a failure always says why, a success leaves a DEM name and finite values,
 * and the derived strings fit. (Ranges are the driver tests' business:
 * tests/driver/test_hostile.py.)
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "tsd_connstr.h"
#include "tsd_options.h"

#define MAX_LINES 64

/* A message of a failure: non-empty and terminated inside the buffer. */
static void check_message(const char *msg, size_t size)
{
    fuzz_require(msg[0] != '\0', "a failure left no message");
    fuzz_require(memchr(msg, '\0', size) != NULL, "a message is not terminated");
}

/* Through the table's accessors only (fields may move): every value an
 * accepted list leaves is printable, numbers among them finite. */
static void check_applied(const tsd_options *o)
{
    char buf[128];
    for (int i = 0; i < tsd_options_count(); i++) {
        const char *name = tsd_options_value(o, i, buf, sizeof buf);
        fuzz_require(name != NULL, "an option has no name");
        fuzz_require(memchr(buf, '\0', sizeof buf) != NULL, "a value is unterminated");
        char *end = NULL;
        double x = strtod(buf, &end);
        if (end != buf && *end == '\0')
            fuzz_require(isfinite(x), "an accepted number is not finite");
    }
    fuzz_require(tsd_options_band_count(o) >= 1, "an accepted product has no band");
    static char canon[4 * TSD_PATH_MAX];
    fuzz_require(tsd_options_canonical(o, canon, sizeof canon) == 0,
                 "the canonical string does not fit 4 * TSD_PATH_MAX bytes");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = fuzz_cstring(data, size);
    if (!text)
        return 0;
    /* The connection string, then the open options, one a line. */
    char *lines[MAX_LINES + 1];
    size_t n = 0;
    char *p = text;
    char *nl = strchr(p, '\n');
    if (nl)
        *nl = '\0';
    const char *name = p;
    p = nl ? nl + 1 : NULL;
    while (p && n < MAX_LINES) {
        nl = strchr(p, '\n');
        if (nl)
            *nl = '\0';
        lines[n++] = p;
        p = nl ? nl + 1 : NULL;
    }
    lines[n] = NULL;

    char msg[1024];
    msg[0] = '\0';
    (void)tsd_connstr_matches(name);
    tsd_connstr c;
    if (tsd_connstr_parse(name, &c, msg, sizeof msg) != 0) {
        check_message(msg, sizeof msg);
    } else {
        fuzz_require(c.dem && c.dem[0] && c.options, "a parsed string has no DEM or list");
        char hint[256];
        tsd_connstr_cut_colon_hint(&c, hint, sizeof hint);
        fuzz_require(memchr(hint, '\0', sizeof hint) != NULL, "a hint is not terminated");
        fuzz_require(!hint[0] || !strncmp(hint, "; ", 2), "a hint does not go on a sentence");
        size_t k = 0;
        while (c.options[k])
            k++;
        const char **kv = calloc(k + n + 1, sizeof *kv);
        if (kv) {
            memcpy(kv, c.options, k * sizeof *kv);
            memcpy(kv + k, lines, n * sizeof *kv);
            tsd_options o;
            tsd_options_defaults(&o);
            msg[0] = '\0';
            if (tsd_options_apply(&o, kv, msg, sizeof msg) != 0)
                check_message(msg, sizeof msg);
            else
                check_applied(&o);
            free(kv);
        }
    }
    tsd_connstr_free(&c);
    free(text);
    return 0;
}
