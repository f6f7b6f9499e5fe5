/*
 * tsd_products.h - the product table: one row per PRODUCT with everything
 * the driver knows about it (name, description, unit, bands and their
 * descriptions, data types and nodata, the Byte mapping, day or instant,
 * memory, the options that apply, the compute function). The PRODUCT
 * option's values, the checks, the memory check, the bands, the metadata
 * and the driver item TERRASHADE_PRODUCTS (read by the QGIS provider) are
 * all derived from it. Adding a product = a row here, its compute function
 * (tsd_compute.h) and its algorithm in core/. No GDAL.
 */
#ifndef TSD_PRODUCTS_H
#define TSD_PRODUCTS_H

#include <stddef.h>

#include "tsd_compute.h"
#include "tsd_options.h"
#include "tsd_sun.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How a product may be written as Byte. */
typedef enum {
    TSD_BYTE_NEVER,   /* Float32 only (values are degrees, hours, Wh/m2) */
    TSD_BYTE_ALLOWED, /* Float32 by default; OUTPUT_TYPE=Byte maps 0..1 to 1..255 */
    TSD_BYTE_AUTO,    /* Byte by default (as gdaldem), 1..255; Float32 allowed */
    TSD_BYTE_ALWAYS   /* computed as bytes (0, 1; nodata byte_nodata); Byte only */
} tsd_byte_rule;

/** The time steps of a day product's bands. */
typedef enum {
    TSD_STEPS_NONE,    /* one instant, or a whole day summed up */
    TSD_STEPS_UNIFORM, /* a band every STEP_MINUTES */
    TSD_STEPS_ATLAS    /* ATLAS_STEPS sun positions, denser near dawn and dusk */
} tsd_day_steps;

/** The description of one band, one metadata item of it (key NULL =
 * none) and its colour interpretation (GDAL's name, e.g. "Red"; NULL =
 * grey). */
typedef struct {
    char description[64];
    const char *key;
    char value[32];
    const char *color;
} tsd_band_info;

typedef struct tsd_product_def tsd_product_def;

struct tsd_product_def {
    const char *name;
    const char *description; /* what it is, one phrase (PRODUCT's option list) */
    const char *unit;        /* GDAL unit type of the bands ("" = none) */
    const char *values;      /* what the values are, for sentences: "0..1", "degrees" */
    int (*band_count)(const tsd_options *o);
    const char *bands_option; /* the option the band count follows, NULL = fixed */
    /* description (and metadata item) of band k (0-based); NULL: the bands
     * are the day's time steps, described by the sun (tsd_sun) */
    void (*describe_band)(const tsd_product_def *p, const tsd_options *o, int k,
                          tsd_band_info *info);
    tsd_byte_rule byte;      /* Float32 nodata is NaN; Byte nodata is byte_nodata */
    int byte_nodata;
    int daily;               /* the sun from DATE / DATETIME over a whole day */
    tsd_day_steps steps;
    /* float planes besides the DEM grid and the product at the peak: always,
     * with SKY_WEIGHT > 0, with SUN_POSITION=per_cell */
    int planes, sky_planes, per_cell_planes;
    /* 1 if it makes backend calls (BACKEND); NULL = never */
    int (*uses_backend)(const tsd_options *o, const tsd_sun *sun);
    /* the options that apply besides those of TSD_APPLIES_ALL, space-separated */
    const char *options;
    /* a metadata item naming the model (NULL = none) */
    const char *model_key, *model;
    tsd_compute_fn compute;
};

/** Number of products, and product i (NULL past the end). */
int tsd_product_count(void);
const tsd_product_def *tsd_product_at(int i);

/** Index of the product named `name` (case-insensitive), or -1. */
int tsd_product_find(const char *name);

/** The product of the options. */
const tsd_product_def *tsd_product_of(const tsd_options *o);

/** 1 if option i (tsd_options.h) applies to product p. */
int tsd_product_takes(const tsd_product_def *p, int option);

/** "shade, shadow and sky": the names of the products that take option i,
 * each after `prefix`, joined by ", " (and `last` before the last one). */
void tsd_products_taking(int option, const char *prefix, const char *last, char *buf,
                         size_t n);

/**
 * The options given in o (tsd_options_given) that product p does not
 * take, each with the products that do: "SUN_AZIMUTH (an option of shade,
 * shadow and envlight), STEP_MINUTES (...)" into buf; returns how many.
 */
int tsd_options_unused(const tsd_options *o, const tsd_product_def *p, char *buf, size_t n);

/**
 * Peak memory in bytes while computing a width x height product, the DEM
 * grid included; `steady` (may be NULL) receives what stays afterwards
 * (the product, as float planes, or byte planes). Doubles, so that nothing
 * overflows. map_x, map_y: METHOD=shadowmap's texels a cell against square
 * cells (tsd_shadowmap_aspect; 1, 1 for square cells).
 */
double tsd_product_peak_bytes(const tsd_options *o, int width, int height, double map_x,
                              double map_y, double *steady);

/**
 * How many times a square cell's texels METHOD=shadowmap's map gives a
 * cell of cell_x (or, where cell_x_row is not NULL, of its `height` rows'
 * sizes, row 0 north) x cell_y metres along x and y: the map's texels are
 * as fine as the shorter of cell_y and the central row's size
 * (ts_shadowmap_frame_make), and span the widest row.
 */
void tsd_shadowmap_aspect(double cell_x, const double *cell_x_row, int height, double cell_y,
                          double *map_x, double *map_y);

/**
 * METHOD=shadowmap's own buffers on a width x height grid (its cells'
 * aspect map_x, map_y) as counted at open: its depth map, SHADOWMAP_SCALE^2
 * int texels a cell turned to face the sun, without the rows that the
 * relief adds at a low sun (the relief is not known at open; tsd_compute
 * checks the real map against what the limit leaves), and three
 * projected-coordinate planes.
 */
double tsd_shadowmap_bytes(const tsd_options *o, int width, int height, double map_x,
                           double map_y);

/**
 * The driver metadata item TERRASHADE_PRODUCTS: an XML list
 * <Products><Product name='shade' description='...' unit='...' bands='1'
 * daily='no' byte='auto' options='SUN_AZIMUTH,...'/>...</Products>, where
 * bands is the band count with the default options (bands_option='NAME' is
 * added where that option sets it), byte is auto, allowed, never
 * or always (tsd_byte_rule) and options lists every open option that
 * applies (PRODUCT, which chooses the product, is not listed). Caller frees
 * with free(); NULL when out of memory.
 */
char *tsd_products_xml(void);

/** OPENNESS=negative: the openness of the DEM with its heights negated
 * (Yokoyama et al. 2002, as RVT_py computes it), swept without curvature,
 * which lowers far terrain and on the negated DEM would raise it. The one
 * home of that rule for the whole DEM's sweeps (tsd_compute.c) and the
 * windows' far grid (tsd_window.c): 1 where options o sweep the negated
 * DEM. */
int tsd_sweeps_negated_dem(const tsd_options *o);

/** The heights of `from` negated into `to` (the same size; may be the
 * same grid; NaN stays NaN): the surface that options for which
 * tsd_sweeps_negated_dem holds sweep. */
void tsd_negate_heights(const ts_grid *from, ts_grid *to);

/** Byte value of a 0..1 product as gdaldem writes it: 0 for nodata, else
 * 1 + 254 v rounded, 1 for v <= 0 (the mapping of TSD_BYTE_AUTO and
 * TSD_BYTE_ALLOWED). */
static inline unsigned char tsd_to_byte(float v)
{
    if (v != v)
        return 0;
    if (v <= 0)
        return 1;
    if (v >= 1)
        return 255;
    return (unsigned char)(1.0f + 254.0f * v + 0.5f);
}

/** tsd_to_byte of v[0..n-1] into out, branch-free so that it vectorises
 * (the driver's block copies of Byte products). */
void tsd_row_to_byte(const float *v, int n, unsigned char *out);

#ifdef __cplusplus
}
#endif

#endif
