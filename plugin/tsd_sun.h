/*
 * tsd_sun.h - the sun of a TERRASHADE dataset from DATETIME / DATE /
 * TIMEZONE: the instant or the local day, the time steps of the day
 * products (uniform every STEP_MINUTES, or the atlas's dawn/dusk-weighted
 * positions), the sun at each step, and the core's day options. Plain C,
 * no GDAL.
 */
#ifndef TSD_SUN_H
#define TSD_SUN_H

#include <stddef.h>

#include "day_cycle.h"
#include "tsd_geodesy.h"
#include "tsd_options.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    tsd_sites sites_owned;  /* where the sun is computed from (owned) */
    ts_sun_sites sites;     /* the core's view of them */
    ts_day_opts day;        /* SPA template, horizon options, turbidity */
    int offset_minutes;     /* of the local times written in the metadata */
    double instant;         /* DATETIME's instant (Unix), or NaN */
    ts_sun_sample sun;      /* shade/shadow: the sun at DATETIME (centre) */
    double day_start;       /* day products: local midnight (Unix) */
    double day_length;      /* seconds (86400: fixed offsets) */
    int steps;              /* daycycle / farshadow: bands */
    double *times;          /* their instants (middles of the steps) */
    double *durations;      /* daycycle: their lengths, seconds */
    ts_sun_sample *samples; /* the sun at the centre at each step */
    double threshold_m;     /* farshadow: FAR_THRESHOLD in metres */
} tsd_sun;

/**
 * Set up the sun of options `o` (tsd_options_sun_from_time(o) must be
 * true) over a grid whose smallest cell side is `min_cell_m` metres;
 * takes ownership of *sites (even on failure). For shade and shadow, `sun`
 * is the sun at DATETIME (tsd_run_init places the run's sun there). TS_OK,
 * or the failure's status with a sentence in msg (e.g. the sun never rises
 * on that day for PRODUCT=farshadow).
 */
ts_status tsd_sun_setup(const tsd_options *o, tsd_sites *sites, double min_cell_m,
                        tsd_sun *s, char *msg, size_t msg_size);

void tsd_sun_free(tsd_sun *s);

/** ISO 8601 local time with its offset, whole seconds:
 * 2026-06-21T07:30:00+02:00 (or ...Z for offset 0). */
void tsd_format_time(double unix_time, int offset_minutes, char *buf, size_t n);

#ifdef __cplusplus
}
#endif

#endif
