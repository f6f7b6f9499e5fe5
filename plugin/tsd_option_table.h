/*
 * tsd_option_table.h - the option table's rows, shared by the files that
 * read it: tsd_option_table.c (the rows), tsd_options.c (parsing,
 * defaults), tsd_options_text.c (values, the canonical key, the XML list).
 * Internal to the plugin's C side; the API is tsd_options.h.
 */
#ifndef TSD_OPTION_TABLE_H
#define TSD_OPTION_TABLE_H

#include <stddef.h>

#include "tsd_options.h"

/* How an option's text becomes its field: K_SELECT and K_PRODUCT store the
 * index of the value (int or enum field), K_BOOL 0/1 (int), K_INT an int,
 * K_FLOAT a double, K_TEXT a char array, K_FLOAT_AUTO a double or, for
 * the word in `values` (e.g. AUTO: decided from the data), NAN. */
typedef enum { K_SELECT, K_FLOAT, K_INT, K_BOOL, K_TEXT, K_PRODUCT, K_FLOAT_AUTO } opt_kind;

/* A reading of an option's value beyond its kind's check: 0, or -1 with
 * msg. A text option's reading also writes what the value means into
 * `meaning` (when not NULL), the same for two spellings of one meaning; a
 * number's leaves it alone (numbers are compared as numbers). */
typedef int (*opt_read_fn)(const char *value, char *meaning, size_t mn, char *msg, size_t n);

typedef struct {
    const char *name;
    opt_kind kind;
    size_t field, size;    /* offsetof and sizeof the field in tsd_options */
    const char *def;       /* the declared default, as written in the option list */
    double min, max;       /* inclusive range (numbers) */
    int min_exclusive;     /* value must be > min */
    int has_max;           /* 0: no upper bound */
    const char *values;    /* K_SELECT: '|'-separated; K_FLOAT_AUTO: the word */
    int affects_pixels;    /* part of the canonical string */
    int scope;             /* TSD_SCOPE_* */
    tsd_applies applies;
    opt_read_fn read;      /* NULL = the kind's check only */
    const char *desc;
} opt_def;

/** The rows, and their number. */
extern const opt_def TSD_OPTION_ROWS[];
extern const int TSD_OPTION_COUNT;

/** What a text option's value means, written so that two spellings of
 *  one meaning write the same (SKY=cie9 and cie:9; TIMEZONE=-0500 and
 *  -05:00; DATETIME's basic and extended forms; EXPOSURE=1 and 1.0): 0, or
 *  -1 where option id has no such reading or v does not parse. */
int tsd_option_meaning(int id, const char *v, char *out, size_t n);

/** The i-th value of a '|'-list into buf ("" past the end); returns buf. */
const char *tsd_select_value(const char *values, int index, char *buf, size_t n);

/** "a, b, c": the values of a select option, or the products' names. */
void tsd_option_list_values(const opt_def *d, char *buf, size_t n);

#endif
