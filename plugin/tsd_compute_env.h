/*
 * tsd_compute_env.h - environment light in the driver: the environment of
 * ENV_MAP (an OpenEXR map, its bytes read by the GDAL side) or SKY (a
 * standard sky placed by the run's sun), its light table (Timonen's L_p,
 * core/terrashade_env.h), PRODUCT=envlight and the sky term of shade.
 * Conventions and choices: docs/envlight.md. No GDAL.
 */
#ifndef TSD_COMPUTE_ENV_H
#define TSD_COMPUTE_ENV_H

#include <stddef.h>

#include "terrashade_env.h"
#include "tsd_compute.h"
#include "tsd_options.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest |EXPOSURE|, stops. */
#define TSD_EXPOSURE_MAX 64.0

/* A map with more pixels is box-filtered to at most this many texels
 * (ts_env_load_exr_memory's max_texels; 2048 x 1024): finer than the
 * table's one-degree horizon steps. */
#define TSD_ENV_MAX_TEXELS ((size_t)1 << 21)

/* The largest light table (bytes): DIRECTIONS x ENV_NORMAL_STEPS x
 * ENV_HORIZON_STEPS nodes of 32 bytes. */
#define TSD_ENV_MAX_TABLE_BYTES (512.0 * 1048576.0)

/* The environment, its table and what the driver reports of it. */
struct tsd_environment {
    ts_env env;            /* texels, terrain frame */
    ts_env_table table;    /* for DIRECTIONS from START_AZIMUTH */
    int has_map;           /* 1: ENV_MAP (map below), 0: SKY */
    ts_env_map_info map;   /* the map's layout, channels and size */
    double flat[3];        /* E/pi per colour of an open flat plane (via the table) */
    double peak;           /* the largest E/pi channel of an unshadowed surface */
    double exposure;       /* stops applied before the sRGB curve (Byte) */
    int exposure_auto;     /* 1: exposure from peak */
};

/* 1 if the options light with an environment (ENV_MAP or SKY given). */
int tsd_options_env(const tsd_options *o);

/* 1 if that environment places no sun: ENV_MAP (the map is the light), or
 * a SKY that does not follow one (uniform, overcast, cie:1, cie:3, cie:5). */
int tsd_environment_sunless(const tsd_options *o);

/* EXPOSURE's text: 1 for automatic ("" or AUTO), 0 with *stops set, -1 if
 * it is neither (or out of +-TSD_EXPOSURE_MAX). */
int tsd_exposure_parse(const char *text, double *stops);

/* TS_OK, or the sentence refusing a light table over
 * TSD_ENV_MAX_TABLE_BYTES kept (whatever MAX_MEMORY allows). */
ts_status tsd_environment_check_table(const tsd_options *o, char *msg, size_t n);

/* What an environment takes (bytes), for MAX_MEMORY (docs/driver.md). */
typedef struct {
    double map_peak;   /* decoding ENV_MAP: its file, its pixels as floats, the texels */
    double table_peak; /* building the light table: its double sums beside its floats */
    double peak;       /* the larger, while the environment is set up */
    double kept;       /* held while the product computes: texels and table */
    double texels;     /* how many */
} tsd_env_cost;

/* The cost of the options' environment: `map` is ENV_MAP's header
 * (ts_env_exr_info) and map_bytes its file's size, or NULL / 0 for SKY. */
void tsd_environment_cost(const tsd_options *o, const ts_env_map_info *map, double map_bytes,
                          tsd_env_cost *c);

/* 1 if options a with run ra set up the same environment as b with rb:
 * the same map or sky, rotation, table and exposure, and a sky that follows
 * the sun placed by the same sun (within 1e-9 degrees). */
int tsd_environment_same(const tsd_options *a, const tsd_run *ra, const tsd_options *b,
                         const tsd_run *rb);

/**
 * The environment of the options: the map in `map` (map_size bytes of an
 * OpenEXR file, read from ENV_MAP by the caller) or the SKY with the sun of
 * `run`; then its table, the flat plane's light, the peak and the exposure.
 * TS_OK, or a status with a sentence in msg (e is then empty).
 */
ts_status tsd_environment_setup(const tsd_options *o, const tsd_run *run, const void *map,
                                size_t map_size, tsd_environment *e, char *msg, size_t n);

/* Free what setup allocated (NULL-safe, idempotent). */
void tsd_environment_free(tsd_environment *e);

/* "lat-long" or "cube" of the map. */
const char *tsd_environment_layout(const tsd_environment *e);

/**
 * The sky term of shade from c->run->env instead of the uniform sky: the
 * luminance (Rec. 709 weights) of the environment light at each cell,
 * divided by that of an open flat plane, so that the sky term is 1 on open
 * flat ground as with the uniform sky. sky: a zeroed plane of the grid.
 */
ts_status tsd_env_sky_term(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                           float *sky);

#ifdef __cplusplus
}
#endif

#endif
