/*
 * tsd_options.h - the TERRASHADE driver's options: one table whose rows say
 * each option's name, kind, range, declared default, description and the
 * field of tsd_options it fills (offsetof). The open-option list (XML),
 * parsing, validation, the defaults, the metadata values and the canonical
 * PAM key are all derived from it. Plain C, no GDAL.
 *
 * tsd_options holds only what the user said (or the declared defaults);
 * what the driver derives when it computes (the sun placed by DATETIME,
 * progress) lives in tsd_run (tsd_compute.h).
 */
#ifndef TSD_OPTIONS_H
#define TSD_OPTIONS_H

#include <stddef.h>

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Refraction coefficient k of the curvature correction, by default: the one
 * place the plugin writes it (the option table's default string is made
 * from it by TSD_XSTR). */
#define TSD_REFRACTION_DEFAULT 0.13
/** The shortest MAX_DISTANCE but 0 (metres) where it is also shorter than
 * the DEM's cells: within a cell's own surface a horizon is a height
 * difference over the distance, which the rounding of 32-bit heights
 * swamps (a micrometre raised horizons to 82 degrees on gentle ground; at
 * 0.5 m, on heights of 8000 m, a horizon is at most 0.04 degrees above the
 * one at 1 m, where it can only be lower). TSDataset::Setup refuses it. */
#define TSD_MAX_DISTANCE_MIN 0.5
#define TSD_STR(x) #x
#define TSD_XSTR(x) TSD_STR(x)

typedef enum { TSD_SUN_CENTER = 0, TSD_SUN_PER_CELL } tsd_sun_position;
typedef enum { TSD_PROGRESS_AUTO = 0, TSD_PROGRESS_YES, TSD_PROGRESS_NO } tsd_progress_mode;
/* CELL_SIZES: how a projected DEM's cells are measured (tsd_geodesy.h). */
typedef enum { TSD_CELLS_AUTO = 0, TSD_CELLS_GRID, TSD_CELLS_GROUND } tsd_cell_sizes;
typedef enum {
    TSD_METHOD_EXACT = 0,
    TSD_METHOD_SHM,
    TSD_METHOD_SHADOWMAP,
    TSD_METHOD_SH
} tsd_method;
/* HORIZON_METHOD: the exact sweep or pyramid horizons (tsd_pyramid.h). */
typedef enum { TSD_HORIZON_EXACT = 0, TSD_HORIZON_PYRAMID } tsd_horizon_method;
/* ENV_METHOD of envlight: Timonen's L_p table or order-4 SH. */
typedef enum { TSD_ENV_TABLE = 0, TSD_ENV_SH } tsd_env_method;
typedef enum { TSD_OUT_AUTO = 0, TSD_OUT_BYTE, TSD_OUT_FLOAT32 } tsd_output_type;
/* BACKEND: where the heavy core calls run (cl/terrashade_backend.h). */
typedef enum { TSD_BACKEND_AUTO = 0, TSD_BACKEND_OPENCL, TSD_BACKEND_C } tsd_backend;

/* Longest text value of a string option (DATETIME, DATE, TIMEZONE). */
#define TSD_TEXT_MAX 64
/* Longest path of the atlas option DEM. */
#define TSD_PATH_MAX 4096

/** Every option of a TERRASHADE dataset, with its value: as given, or the
 * declared default. Select options hold the index of their value in the
 * option's list (the enums above follow those lists). */
typedef struct {
    int product;             /* index into the product table (tsd_products.h) */
    double sun_azimuth;      /* degrees from north */
    double sun_elevation;    /* degrees above the horizontal */
    int directions;          /* azimuths of the sky / horizon products */
    double start_azimuth;    /* first of those azimuths */
    tsd_method method;       /* exact horizon or shadow height map */
    double penumbra_depth;   /* metres, METHOD=shm only */
    double light_radius;     /* degrees: the light's disk (LIGHT_RADIUS) */
    double shadowmap_scale;  /* METHOD=shadowmap: texels per DEM cell */
    double pcf_kernel;       /* METHOD=shadowmap: PCF width in cells, NAN = auto */
    double z_factor;         /* multiplies the DEM's heights; NAN = AUTO, decided
                                from the DEM (tsd_dem_z_factor) */
    tsd_cell_sizes cell_sizes; /* CELL_SIZES: auto, grid or ground */
    double max_distance;     /* metres, 0 = unbounded */
    int curvature;           /* Earth curvature and refraction on/off */
    double refraction;       /* k */
    double sky_weight;       /* shade = direct + sky_weight * sky */
    int band;                /* DEM band, 1-based */
    int threads;             /* 0 = all cores */
    tsd_output_type output_type; /* as asked; see tsd_options_output_byte */
    int max_memory_mb;       /* 0 = automatic */
    int tile_size;           /* cells of a chunk (tsd_window.h); 0 = the whole DEM */
    double near_distance;    /* metres of the exact near field; 0 = automatic */
    /* the sun from a date and time (see tsd_sun.h) */
    char datetime[TSD_TEXT_MAX]; /* ISO 8601 with an offset, "" = not given */
    char date[TSD_TEXT_MAX];     /* YYYY-MM-DD, "" = not given */
    char timezone[TSD_TEXT_MAX]; /* fixed UTC offset, "" = not given */
    int step_minutes;        /* sampling step of the day products; a date
                                range's when given (tsd_options_step_minutes) */
    /* a date range of sunhours and insolation (START_DATE given) */
    char start_date[TSD_TEXT_MAX]; /* YYYY-MM-DD, "" = one day (DATE) */
    char end_date[TSD_TEXT_MAX];   /* YYYY-MM-DD, "" = START_DATE */
    int day_interval;        /* every day_interval-th day is computed */
    int horizon_directions;  /* azimuths of the range's horizon planes */
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
    /* environment light: PRODUCT=envlight, and the sky term of shade */
    char env_map[TSD_PATH_MAX];  /* ENV_MAP: an OpenEXR map (a GDAL path), "" = none */
    double env_rotation;         /* ENV_ROTATION: degrees, clockwise seen from above */
    char sky[TSD_TEXT_MAX];      /* SKY: uniform, overcast, clear, cie:N; "" = none */
    int env_horizon_steps;       /* ENV_HORIZON_STEPS: the L_p table's horizon axis */
    int env_normal_steps;        /* ENV_NORMAL_STEPS: its normal axis, 0 = exact */
    char exposure[TSD_TEXT_MAX]; /* EXPOSURE: stops (Byte), "" or AUTO = automatic */
    tsd_env_method env_method;   /* ENV_METHOD: table or sh (envlight) */
    /* the key light of METHOD=sh (tsd_compute_sh.c) */
    int swath_directions;        /* SWATH_DIRECTIONS: azimuths of its partial swath */

    int svf_model;           /* SVF_MODEL: a ts_svf_model (0 radiative, 1 solid_angle) */
    int openness_negative;   /* OPENNESS: 0 = positive, 1 = negative */
    int edge;                /* EDGE: 0 = horizon, 1 = open, 2 = nodata (tsd_options_edge) */
    tsd_horizon_method horizon_method; /* HORIZON_METHOD: exact or pyramid */
    double pyramid_level_step; /* PYRAMID_LEVEL_STEP: k, b = 2^(1/k) */
    double pyramid_offset;     /* PYRAMID_OFFSET: level offset o */
    /* options of far-shadow atlas files (*.tsa) */
    int shadows_all;         /* SHADOWS: 0 = far, 1 = all */
    char dem[TSD_PATH_MAX];  /* DEM: "" = the atlas's SOURCE_DEM */
    /* which options the user gave (bit i = option i of the table): what
     * the user said, e.g. SUN_AZIMUTH given with DATETIME is an error */
    unsigned long long given;
} tsd_options;

/** Which datasets an option is an open option of (bit flags). */
enum { TSD_SCOPE_PRODUCT = 1, TSD_SCOPE_ATLAS = 2 };

/** Which products an option applies to (TERRASHADE_PRODUCTS, QGIS). */
typedef enum {
    TSD_APPLIES_SELECTOR = 0, /* PRODUCT itself: it chooses the product */
    TSD_APPLIES_ALL,          /* every product */
    TSD_APPLIES_LISTED        /* the products whose row lists it */
} tsd_applies;

/** Fill `o` with the declared defaults (parsed from the table's default
 * strings; sun at 315 / 45 degrees as gdaldem). */
void tsd_options_defaults(tsd_options *o);

/**
 * Apply a NULL-terminated list of "KEY=VALUE" strings of a TERRASHADE:<dem>
 * dataset (keys are case-insensitive). A key given twice with different
 * values, an unknown key, a malformed or out-of-range value are errors:
 * returns -1 with a sentence in msg. Returns 0 on success. Then checks the
 * combination (tsd_options_check).
 */
int tsd_options_apply(tsd_options *o, const char *const *kv, char *msg,
                      size_t msg_size);

/** The same for the open options of a far-shadow atlas (*.tsa): SHADOWS,
 * DEM and THREADS. */
int tsd_options_apply_atlas(tsd_options *o, const char *const *kv, char *msg,
                            size_t msg_size);

/** Check options that depend on each other; -1 with msg on error
 * (tsd_options_check.c). */
int tsd_options_check(const tsd_options *o, char *msg, size_t msg_size);

/** 1 if the options place the sun from a date and time (DATETIME with
 * shade or shadow, or a daily product). */
int tsd_options_sun_from_time(const tsd_options *o);

/** 1 if the options ask for a date range (START_DATE given). */
int tsd_options_is_range(const tsd_options *o);

/** The time step of the day products in minutes: STEP_MINUTES as given, or
 * its default, 5 for one day and TS_RANGE_STEP_MINUTES (30) for a date
 * range (the table declares 5). */
int tsd_options_step_minutes(const tsd_options *o);

/** 1 if option `name` was given by the user. */
int tsd_options_given(const tsd_options *o, const char *name);

/** 1 if the product is written as Byte. */
int tsd_options_output_byte(const tsd_options *o);

/** The core's edge mode of EDGE; TS_EDGE_OPEN for a product without EDGE. */
ts_edge_mode tsd_options_edge(const tsd_options *o);

/** Number of output bands. */
int tsd_options_band_count(const tsd_options *o);

/** Name of the options' product, e.g. "shade". */
const char *tsd_options_product_name(const tsd_options *o);

/* ------------------------------------------------------------ the table */

/** Number of options in the table (product and atlas options). */
int tsd_options_count(void);

/** Name of option i, or NULL past the end. */
const char *tsd_option_name(int i);

/** Index of the option named `name` (case-insensitive), or -1. */
int tsd_option_find(const char *name);

/** Scope bits of option i (TSD_SCOPE_*). */
int tsd_option_scope(int i);

/** Which products option i applies to. */
tsd_applies tsd_option_applies(int i);

/** The declared default of option i, as written in the option list. */
const char *tsd_option_default(int i);

/**
 * The value of option i in `o` written to buf ("315", "YES", "shade"...;
 * OUTPUT_TYPE: the type written, Byte or Float32), cut to buf_size (a
 * path option's whole value needs TSD_PATH_MAX). Returns the option's
 * name, NULL past the end.
 */
const char *tsd_options_value(const tsd_options *o, int i, char *buf,
                              size_t buf_size);

/**
 * The GDAL open-option list (XML) describing every option with its type,
 * default, range and description. Caller frees with free().
 */
char *tsd_options_xml(void);

/**
 * A canonical, comma-separated "KEY=VALUE,..." string of all the options
 * that change the product's pixels (not THREADS, MAX_MEMORY or BACKEND), in table
 * order, every value whole (the key of a product's auxiliary-file entry:
 * two ENV_MAP paths alike in their first hundred characters are two
 * keys); 4 * TSD_PATH_MAX bytes always suffice. Returns 0, or -1 if buf is
 * too small.
 */
int tsd_options_canonical(const tsd_options *o, char *buf, size_t buf_size);

#ifdef __cplusplus
}
#endif

#endif
