/*
 * tsd_datetime.h - ISO 8601 dates and times as the driver's options take
 * them: inline options cannot hold colons, so the basic format is
 * normalised into the extended form the core parses. Plain C, no GDAL.
 */
#ifndef TSD_DATETIME_H
#define TSD_DATETIME_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Normalise an ISO 8601 date and time written without colons (basic
 * format, which inline options need: 2026-06-21T073000+0200 or
 * 20260621T0730Z) into the extended form ts_parse_iso8601 reads
 * (2026-06-21T07:30:00+02:00). Other text is copied unchanged.
 */
void tsd_datetime_normalise(const char *in, char *out, size_t out_size);

#ifdef __cplusplus
}
#endif

#endif
