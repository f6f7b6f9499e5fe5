/*
 * tsd_options.h - the TERRASHADE driver's options: one table that both
 * documents them (the GDAL open-option list) and parses and validates them.
 * Plain C, no GDAL.
 */
#ifndef TSD_OPTIONS_H
#define TSD_OPTIONS_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TSD_PRODUCT_SHADE = 0,
    TSD_PRODUCT_SHADOW,
    TSD_PRODUCT_HORIZON,
    TSD_PRODUCT_SVF,
    TSD_PRODUCT_OPENNESS,
    TSD_PRODUCT_SKY
} tsd_product;

typedef enum { TSD_METHOD_EXACT = 0, TSD_METHOD_SHM } tsd_method;

typedef enum { TSD_OUT_AUTO = 0, TSD_OUT_BYTE, TSD_OUT_FLOAT32 } tsd_output_type;

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
} tsd_options;

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
 * that change the product's pixels (not THREADS or MAX_MEMORY), in table
 * order. Returns 0, or -1 if buf is too small.
 */
int tsd_options_canonical(const tsd_options *o, char *buf, size_t buf_size);

#ifdef __cplusplus
}
#endif

#endif
