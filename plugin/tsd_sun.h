/*
 * tsd_sun.h - the sun of a TERRASHADE dataset from DATETIME / DATE /
 * TIMEZONE: the instant or the local day (or, from START_DATE and END_DATE,
 * a range of days), the time steps of the day products (uniform every
 * STEP_MINUTES, or the atlas's dawn/dusk-weighted positions), the sun at
 * each step, and the core's day options. Plain C, no GDAL.
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
    /* a date range (START_DATE): is_range 1, the core's range; day_start is
     * the first day's start, day_length the whole range's */
    int is_range;
    ts_date_range range;
    int range_days, range_sampled; /* days in the range, days computed */
} tsd_sun;

/**
 * The core's date range of options `o` (START_DATE, END_DATE, TIMEZONE,
 * DAY_INTERVAL, the step of tsd_options_step_minutes, HORIZON_DIRECTIONS),
 * checked by the core (ts_date_range_check); *days and *sampled (may be
 * NULL) receive its length and the number of days computed. TS_OK, or
 * TS_ERR_ARG with a sentence naming the options. START_DATE and TIMEZONE
 * must be given.
 */
ts_status tsd_sun_date_range(const tsd_options *o, ts_date_range *r, int *days, int *sampled,
                             char *msg, size_t msg_size);

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

/** 1 if `sun` (may be NULL) is computed per cell: SUN_POSITION=per_cell's
 * lattice of sites. */
int tsd_sun_per_cell(const tsd_sun *sun);

/** 1 with a sentence in `warning` when DATETIME (shade, shadow) puts the
 * whole sun below the lowest horizon any terrain on Earth has (the sea-level
 * horizon seen from 9 000 m): a night no cell sees the sun in, most often a
 * local time given with Z. It gives the mean solar time at the DEM's
 * centre and its longitude's offset. 0 otherwise. */
int tsd_sun_night_warning(const tsd_sun *s, const tsd_options *o, char *warning,
                          size_t warning_size);

/**
 * A sentence when a date range's DAY_INTERVAL is so long that one computed
 * day counts for a stretch of the seasons (blocks of more than 61 days,
 * over a range that long): the total can then be off by percents (one day
 * for a whole year read 30 % more sun hours at 46.5 N than every 14 days).
 * Returns 1 with it in `warning`, else 0.
 */
int tsd_sun_range_warning(const tsd_sun *s, const tsd_options *o, char *warning, size_t n);

/** 1 with a sentence in `warning` when a day product's day (DATE or
 * START_DATE with TIMEZONE, or DATETIME with its own offset) is of an
 * offset beyond every civil time zone (-12:00 to +14:00: likely a sign's
 * typo, which names another date), or more than 4 hours from the mean
 * solar time at the DEM's centre (modulo a day): no civil time zone is that
 * far from its sun (western China's, the farthest, ~3 h), so its local
 * midnight may fall in daylight and a day's light be split between two
 * calendar days. 0 otherwise. */
int tsd_sun_zone_warning(const tsd_sun *s, const tsd_options *o, char *warning,
                         size_t warning_size);

/** 1 with a sentence in `warning` when DELTA_T was not given and its
 * default (69 s, the 2020s') is so far from Espenak & Meeus's estimate for
 * the year of the sun's instant or day (the first of a range) that the sun
 * moves by more than 0.01 deg along the ecliptic (dates before ~1130 or
 * after ~2370). The sentence gives the estimate to set (within the SPA's
 * limit of 8000 s). 0 otherwise. */
int tsd_sun_delta_t_warning(const tsd_sun *s, const tsd_options *o, char *warning,
                            size_t warning_size);

/** ISO 8601 local time with its offset, whole seconds:
 * 2026-06-21T07:30:00+02:00 (or ...Z for offset 0). */
void tsd_format_time(double unix_time, int offset_minutes, char *buf, size_t n);

/** tsd_format_time with the milliseconds an instant has begun, where it has
 * them (07:30:00.5; a leap second, its day's last instant, 23:59:59.999):
 * DATETIME as given (08:00:00.5 was said as 08:00:01). */
void tsd_format_instant(double unix_time, int offset_minutes, char *buf, size_t n);

#ifdef __cplusplus
}
#endif

#endif
