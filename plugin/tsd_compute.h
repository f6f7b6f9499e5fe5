/*
 * tsd_compute.h - how a product is computed: the region to compute (a
 * window of a DEM grid with its margin), the run state the driver derives
 * from the options, and each product's compute function (the sequence of
 * core calls, streaming one horizon direction at a time so that memory
 * stays bounded). The product table (tsd_products.h) names the function of
 * each product. No GDAL.
 */
#ifndef TSD_COMPUTE_H
#define TSD_COMPUTE_H

#include <stddef.h>
#include <stdint.h>

#include "terrashade.h"
#include "tsd_backend.h"
#include "tsd_options.h"
#include "tsd_sun.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * The region to compute: the window of width x height cells whose first
 * cell is (x0, y0) in `dem`, and `margin` cells of `dem` around it that the
 * window's values may depend on (the window plus its margin lies inside
 * dem). The output planes are width x height. Today the driver passes the
 * whole DEM with no margin (tsd_region_whole), and the compute functions
 * take only that; windowed computation keeps this shape.
 */
typedef struct {
    const ts_grid *dem;
    int x0, y0;
    int width, height;
    int margin;
} tsd_region;

/** The region of the whole of `dem`, no margin. */
void tsd_region_whole(tsd_region *r, const ts_grid *dem);

/* The light of ENV_MAP or SKY (tsd_compute_env.h). */
typedef struct tsd_environment tsd_environment;

/**
 * What the driver derives when it computes, apart from what the user said
 * (tsd_options): the sun that shade and shadow use (SUN_AZIMUTH and
 * SUN_ELEVATION, or the sun at DATETIME), the sun's day (NULL when the sun
 * is not placed by a date), and the progress callback.
 */
typedef struct {
    double sun_azimuth;      /* grid azimuth, degrees from north */
    double sun_elevation;    /* degrees above the horizontal */
    const tsd_sun *sun;      /* from tsd_sun_setup, or NULL */
    const tsd_environment *env; /* ENV_MAP or SKY (tsd_environment_setup), or NULL */
    ts_progress_fn progress; /* NULL = no reports */
    void *progress_user;
    /* a window of a larger DEM (tsd_window.h): horizons are swept within
     * near_distance metres and raised to the far field beyond; 0 / NULL
     * for the whole DEM */
    double near_distance;
    struct tsd_far_field *far;
    /* host memory a horizon stream may add for batches of planes, each
     * batch one OpenCL call (tsd_compute_stream); 0: one plane a call */
    double batch_bytes;
    /* MAX_MEMORY's limit and what the estimate at open left under it
     * (tsd_dataset_memory.cpp), for the buffers whose size is known only
     * when computing (METHOD=shadowmap's map, taller with the relief at a
     * low sun); 0: unchecked */
    double limit_bytes, headroom_bytes;
} tsd_run;

/** The run state of options `o`, with `sun` (may be NULL) placing the sun
 * of shade and shadow when it has an instant; no progress. */
void tsd_run_init(tsd_run *run, const tsd_options *o, const tsd_sun *sun);

/** Everything a compute function needs besides its region and output. */
typedef struct {
    const tsd_options *opts;
    const tsd_run *run;
    tsd_backend_summary *backend; /* what ran (may be NULL) */
    char *msg;                    /* the error sentence */
    size_t msg_size;
} tsd_compute_ctx;

/**
 * A product's compute function: tsd_options_band_count(opts) planes of
 * region->width * region->height values (row stride = width), in the
 * grid's orientation, into `out` as floats (NaN = nodata) or, for the
 * products stored as bytes (TSD_BYTE_ALWAYS), into `bytes` (out unused).
 * TS_OK, or the failure's status with a sentence in ctx->msg.
 */
typedef ts_status (*tsd_compute_fn)(const tsd_compute_ctx *ctx, const tsd_region *region,
                                    float *out, uint8_t *bytes);

/**
 * Compute the options' product over `region` with its table row's function,
 * after checking the grid and the horizon options; ctx->backend (if not
 * NULL) is zeroed first, then receives what ran.
 */
ts_status tsd_product_compute(const tsd_compute_ctx *ctx, const tsd_region *region,
                              float *out, uint8_t *bytes);

/* The signature of a compute function named `name` (declarations and
 * definitions). */
#define TSD_COMPUTE_FN(name)                                                             \
    ts_status name(const tsd_compute_ctx *c, const tsd_region *r, float *out, uint8_t *bytes)

/* 1 if `shade` under options o, with the sun on a lattice of sites
 * (SUN_POSITION=per_cell) or not, computes its direct sun alone without
 * planes of normals or a work plane (the exact method and METHOD=sh make
 * their normals row by row; without a sky term): what tsd_compute_shade
 * does and the memory estimate counts. */
int tsd_shade_without_planes(const tsd_options *o, int sun_lattice);

/* The products' compute functions (tsd_compute.c, tsd_compute_day.c). */
TSD_COMPUTE_FN(tsd_compute_shade);
TSD_COMPUTE_FN(tsd_compute_shadow);
TSD_COMPUTE_FN(tsd_compute_horizon);
TSD_COMPUTE_FN(tsd_compute_svf);
TSD_COMPUTE_FN(tsd_compute_openness);
TSD_COMPUTE_FN(tsd_compute_sky);
TSD_COMPUTE_FN(tsd_compute_sunhours);
TSD_COMPUTE_FN(tsd_compute_insolation);
TSD_COMPUTE_FN(tsd_compute_daycycle);
TSD_COMPUTE_FN(tsd_compute_farshadow);
TSD_COMPUTE_FN(tsd_compute_envlight);

/* Shared by the compute files: the core's horizon options of the options
 * and run state, and a progress report of a loop the plugin runs itself
 * (TS_ERR_CANCELLED with ctx->msg when the caller cancels). */
void tsd_compute_horizon_opts(const tsd_compute_ctx *c, ts_horizon_opts *h);
ts_status tsd_compute_report(const tsd_compute_ctx *c, double done);

/* Surface normals of a grid, computed on the backend. */
typedef struct {
    float *nx, *ny, *nz;
} tsd_normals;
ts_status tsd_normals_make(const tsd_compute_ctx *c, const ts_grid *g, tsd_normals *nm);
void tsd_normals_free(tsd_normals *nm);

/* What each horizon plane of tsd_compute_stream is added to: sector k of
 * DIRECTIONS, at `azimuth` degrees. */
typedef ts_status (*tsd_plane_fn)(void *user, const ts_grid *g, int k, double azimuth,
                                  const float *plane, ts_error *err);

/* Azimuths per backend call for `n` horizon planes of `cells` each: on
 * OpenCL up to TERRASHADE_OPENCL_BATCH (by default 16 on a GPU, 1 on a CPU
 * device) and as many as c->run->batch_bytes holds beside the first plane;
 * 1 on C, and for capped sweeps (MAX_DISTANCE, a window's near field),
 * which the OpenCL kernel leaves to C. */
int tsd_compute_batch(const tsd_compute_ctx *c, size_t cells, int n);

/* Sweep the DIRECTIONS horizon planes on the backend, tsd_compute_batch at
 * a time (with progress per call), and hand each to `add` in order. */
ts_status tsd_compute_stream(const tsd_compute_ctx *c, const ts_grid *g, tsd_plane_fn add,
                             void *user);

/* A horizon plane of g toward `azimuth` (degrees), just swept: raised to
 * the far field of a window (c->run->far; nothing without one). `sun`:
 * the sun's own sweep, which the sun's elevation may spare the far field. */
ts_status tsd_compute_far(const tsd_compute_ctx *c, const ts_grid *g, double azimuth, int sun,
                          float *plane);

/* tsd_compute_far for a light at `elevation` degrees of angular radius
 * `radius` that alone reads the plane (NaN elevation: no such light, the
 * plane serves every direction): the day products' sweeps. */
ts_status tsd_compute_far_light(const tsd_compute_ctx *c, const ts_grid *g, double azimuth,
                                double elevation, double radius, float *plane);

/* The core's day options of `sun` for a computation: the run's progress;
 * in a window, sweeps that reach the near field, the far field joined
 * after each through the core's plane hook (tsd_compute_far_light), and a
 * date range's tables over fixed heights (tsd_window.h). */
ts_day_opts tsd_compute_day_opts(const tsd_compute_ctx *c, const tsd_sun *sun);

/* The sun's sites seen from grid g: a window's lattice (SUN_POSITION=
 * per_cell) shifted to its first cell, so that every node stays where it
 * is on the whole DEM. */
ts_sun_sites tsd_compute_sun_sites(const tsd_sun *sun, const ts_grid *g);

#ifdef __cplusplus
}
#endif

#endif
