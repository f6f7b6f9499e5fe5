/*
 * tsd_connstr.h - split a TERRASHADE connection string into inline options
 * and the DEM's name. Plain C, no GDAL.
 *
 *   TERRASHADE:<dem>
 *   TERRASHADE:KEY=VALUE,KEY=VALUE:<dem>
 *   TERRASHADE:KEY=VALUE:"<dem>"      (quotes: a name that itself starts
 *                                      like KEY=VALUE:)
 *
 * The option segment is recognised only if every comma-separated item is
 * KEY=VALUE with KEY an identifier ([A-Za-z_][A-Za-z0-9_]*) and it ends at a
 * ':'; values cannot contain ',' or ':'. Everything after it is the DEM's
 * name, passed to GDAL unchanged: /vsi paths, names with colons, drive
 * letters ("C:\dem.tif" starts with "C", which has no '=').
 */
#ifndef TSD_CONNSTR_H
#define TSD_CONNSTR_H

#include <stddef.h>

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TSD_PREFIX "TERRASHADE:"

typedef struct {
    char **options; /* NULL-terminated "KEY=VALUE" list (never NULL on success) */
    char *dem;      /* the DEM's name */
} tsd_connstr;

/** 1 if name starts with TERRASHADE: (case-insensitive). Cheap, silent. */
int tsd_connstr_matches(const char *name);

/** Parse; TS_OK, or the failure's status with a sentence in msg. Free with
 * tsd_connstr_free (also after a failure). */
ts_status tsd_connstr_parse(const char *name, tsd_connstr *out, char *msg,
                      size_t msg_size);

/** Into hint ("" if not so): a sentence, starting "; ", for a connection
 * string whose last inline option is TIMEZONE, DATETIME or SKY cut at its
 * ':' (TIMEZONE=-05:00, DATETIME=...T07:30:00, SKY=cie:9), which leaves the
 * DEM's name starting with digits and ':' or ',' ("00:dem.tif",
 * "00,PRODUCT=sunhours:dem.tif"). The caller appends it to the failure that
 * follows (tsd_connstr_add_hint). */
void tsd_connstr_cut_colon_hint(const tsd_connstr *c, char *hint, size_t hint_size);

/** Into hint ("" if not so): a sentence, starting "; ", for a DEM name that
 * looks like inline options that did not parse ("PRODUCT=svf,:dem.tif": an
 * item before the first ':' that is not KEY=VALUE, e.g. the empty one of a
 * doubled or trailing comma), naming the item; for the failure to open it. */
void tsd_connstr_segment_hint(const tsd_connstr *c, char *hint, size_t hint_size);

/** msg with hint appended (msg's final '.' dropped, so the sentence goes on);
 * msg unchanged if hint is "". Returns msg. */
const char *tsd_connstr_add_hint(char *msg, size_t msg_size, const char *hint);

void tsd_connstr_free(tsd_connstr *c);

#ifdef __cplusplus
}
#endif

#endif
