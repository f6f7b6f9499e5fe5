/*
 * tsd_text.h - text helpers of the plugin's C side: the one way to fail
 * with a sentence (tsd_fail), the one way to read a number
 * (tsd_parse_decimal), and a growing string for the XML lists the driver
 * publishes. Plain C, no GDAL.
 */
#ifndef TSD_TEXT_H
#define TSD_TEXT_H

#include <locale.h>
#include <stddef.h>

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Write a sentence (printf format) into msg (msg may be NULL) and return
 * `code`. A plugin function that fails returns its ts_status (TS_ERR_ARG
 * for bad input, TS_ERR_NOMEM, TS_ERR_CANCELLED...) so that the driver can
 * map it to a GDAL error number (tsd_gdal.h); never TS_OK.
 */
ts_status tsd_fail(char *msg, size_t msg_size, ts_status code, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/** tsd_fail with a core error: "what: message" (what may be NULL), its code. */
ts_status tsd_fail_core(char *msg, size_t msg_size, const char *what, const ts_error *err);

/**
 * The "C" locale, made once for the process (NULL: out of memory). The
 * driver holds it on its thread while it runs (tsd_entry_state.h); the parser
 * below takes it whatever the thread holds.
 */
locale_t tsd_c_locale(void);

/**
 * Read a decimal number: the whole of text but surrounding spaces, with a
 * '.' whatever the process's locale; C's hexadecimal floats (0x10),
 * infinities, NaN and overflow are refused; an underflow reads as what it
 * rounds to, but never as 0 where a digit is not 0 (1e-400 reads as the
 * least double of its sign). 0 with *x set, else -1.
 */
int tsd_parse_decimal(const char *text, double *x);

/** A growing string; zero it before use, free(s) after. */
typedef struct {
    char *s;
    size_t len, cap;
    int failed; /* an allocation failed: s holds what came before */
} tsd_strbuf;

/** Append printf-style text. */
void tsd_strbuf_add(tsd_strbuf *b, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/** Append text escaped for an XML attribute between single quotes. */
void tsd_strbuf_add_xml(tsd_strbuf *b, const char *text);

/** The string (caller frees), or NULL (and nothing to free) if an
 * allocation failed. */
char *tsd_strbuf_finish(tsd_strbuf *b);

#ifdef __cplusplus
}
#endif

#endif
