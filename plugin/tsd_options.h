/*
 * tsd_options.h - the TERRASHADE driver's options: one table that both
 * documents them (the GDAL open-option list) and parses and validates them.
 * Plain C, no GDAL.
 */
#ifndef TSD_OPTIONS_H
#define TSD_OPTIONS_H

#include <stddef.h>

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TSD_PRODUCT_SHADE = 0,
    TSD_PRODUCT_SHADOW,
    TSD_PRODUCT_HORIZON,
    TSD_PRODUCT_SVF,
    TSD_PRODUCT_OPENNESS,
    TSD_PRODUCT_SKY,
    TSD_PRODUCT_SUNHOURS,   /* hours of direct sun over a local day */
    TSD_PRODUCT_INSOLATION, /* clear-sky irradiation over a day: total, beam, diffuse */
    TSD_PRODUCT_DAYCYCLE,   /* visible fraction of the sun, one band per time step */
    TSD_PRODUCT_FARSHADOW   /* binary far-shadow maps of the atlas, one per sun position */
} tsd_product;

typedef enum { TSD_SUN_CENTER = 0, TSD_SUN_PER_CELL } tsd_sun_position;
typedef enum { TSD_PROGRESS_AUTO = 0, TSD_PROGRESS_YES, TSD_PROGRESS_NO } tsd_progress_mode;

/* Longest text value of a string option (DATETIME, DATE, TIMEZONE). */
#define TSD_TEXT_MAX 64

typedef enum { TSD_METHOD_EXACT = 0, TSD_METHOD_SHM } tsd_method;

typedef enum { TSD_OUT_AUTO = 0, TSD_OUT_BYTE, TSD_OUT_FLOAT32 } tsd_output_type;

/* BACKEND: where the heavy core calls run (cl/terrashade_backend.h). */
typedef enum { TSD_BACKEND_AUTO = 0, TSD_BACKEND_OPENCL, TSD_BACKEND_C } tsd_backend;

/** Every option of a TERRASHADE dataset, with its effective value. */
typedef struct {
    tsd_product product;
    double sun_azimuth;      /* degrees from north */
    double sun_elevation;    /* degrees above the horizontal */
    int directions;          /* azimuths of the sky / horizon products */
    double start_azimuth;    /* first of those azimuths */
    tsd_method method;       /* exact horizon or shadow height map */
    double penumbra_depth;   /* metres, METHOD=shm only */
    double z_factor;         /* multiplies the DEM's heights */
    double max_distance;     /* metres, 0 = unbounded */
    int curvature;           /* Earth curvature and refraction on/off */
    double refraction;       /* k */
    double sky_weight;       /* shade = direct + sky_weight * sky */
    int band;                /* DEM band, 1-based */
    int threads;             /* 0 = all cores */
    tsd_output_type output_type; /* as asked; see tsd_options_output_byte */
    int max_memory_mb;       /* 0 = automatic */
    /* the sun from a date and time (see tsd_sun.h) */
    char datetime[TSD_TEXT_MAX]; /* ISO 8601 with an offset, "" = not given */
    char date[TSD_TEXT_MAX];     /* YYYY-MM-DD, "" = not given */
    char timezone[TSD_TEXT_MAX]; /* fixed UTC offset, "" = not given */
    int step_minutes;        /* sampling step of the day products */
    double pressure;         /* hPa, for the refraction */
    double temperature;      /* degrees C, for the refraction */
    double delta_t;          /* TT - UT, seconds */
    tsd_sun_position sun_position; /* one site at the centre, or per cell */
    double linke_turbidity;  /* clear-sky model of PRODUCT=insolation */
    int far_threshold;       /* cells: nearer occluders are not in farshadow */
    int atlas_steps;         /* sun positions of PRODUCT=farshadow */
    tsd_backend backend;     /* auto (TERRASHADE_BACKEND, then the device), opencl, c */
    int sunhours_fraction;   /* sunhours: 0 = a step counts while any of the
                                disk is visible, 1 = weighted by the fraction */
    tsd_progress_mode progress_mode; /* PROGRESS: auto, yes, no */
    /* Not options: set by the dataset just before it computes. */
    ts_progress_fn progress; /* NULL = no reports */
    void *progress_user;
    /* which of SUN_AZIMUTH / SUN_ELEVATION were given explicitly */
    int sun_azimuth_given, sun_elevation_given;
} tsd_options;

/** 1 if the product takes its sun from DATE / DATETIME over a whole day. */
int tsd_product_is_daily(tsd_product p);

/** 1 if the options place the sun from a date and time (DATETIME with
 * shade or shadow, or a daily product). */
int tsd_options_sun_from_time(const tsd_options *o);

/**
 * Normalise an ISO 8601 date and time written without colons (basic
 * format, which inline options need: 2026-06-21T073000+0200 or
 * 20260621T0730Z) into the extended form ts_parse_iso8601 reads
 * (2026-06-21T07:30:00+02:00). Other text is copied unchanged.
 */
void tsd_datetime_normalise(const char *in, char *out, size_t out_size);

/** Fill `o` with the defaults (sun at 315 / 45 degrees as gdaldem). */
void tsd_options_defaults(tsd_options *o);

/**
 * Apply a NULL-terminated list of "KEY=VALUE" strings (keys are
 * case-insensitive). A key given twice with different values, an unknown
 * key, a malformed or out-of-range value are errors: returns -1 with a
 * sentence in msg. Returns 0 on success. Then checks the combination
 * (tsd_options_check).
 */
int tsd_options_apply(tsd_options *o, const char *const *kv, char *msg,
                      size_t msg_size);

/** Check options that depend on each other; -1 with msg on error. */
int tsd_options_check(const tsd_options *o, char *msg, size_t msg_size);

/** 1 if the product is written as Byte (1..255, 0 = nodata). */
int tsd_options_output_byte(const tsd_options *o);

/** Number of output bands. */
int tsd_options_band_count(const tsd_options *o);

/** Name of a product, e.g. "shade". */
const char *tsd_product_name(tsd_product p);

/** Name of a method, e.g. "exact". */
const char *tsd_method_name(tsd_method m);

/** Name of a BACKEND value: "auto", "opencl" or "c". */
const char *tsd_backend_name(tsd_backend b);

/**
 * The GDAL open-option list (XML) describing every option with its type,
 * default, range and description. Caller frees with free().
 */
char *tsd_options_xml(void);

/** Number of options in the table, and the name/effective value of option i
 * ("315", "YES", "shade"...) written to buf. Returns the name, NULL past the
 * end. */
int tsd_options_count(void);
const char *tsd_options_value(const tsd_options *o, int i, char *buf,
                              size_t buf_size);

/**
 * A canonical, comma-separated "KEY=VALUE,..." string of all the options
 * that change the product's pixels (not THREADS, MAX_MEMORY or BACKEND), in table
 * order. Returns 0, or -1 if buf is too small.
 */
int tsd_options_canonical(const tsd_options *o, char *buf, size_t buf_size);

#ifdef __cplusplus
}
#endif

#endif
