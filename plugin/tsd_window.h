/*
 * tsd_window.h - windowed computation (docs/windows.md): a product is
 * computed chunk by chunk, each chunk from the full-resolution DEM around
 * it (a margin of NEAR_DISTANCE) for the near field, and from one coarse
 * grid of the whole DEM for the far field (Chajdas et al. 2015). This is
 * the C side: the chunk's geometry and the far field. The chunk cache and
 * the GDAL reads are in tsd_window_cache.cpp. No GDAL here.
 */
#ifndef TSD_WINDOW_H
#define TSD_WINDOW_H

#include <stddef.h>
#include <stdint.h>

#include "terrashade.h"
#include "tsd_compute.h"
#include "tsd_options.h"
#include "tsd_sun.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Smallest TILE_SIZE (0 = the whole DEM at once). */
#define TSD_TILE_MIN 64
/** The side of the blocks GDAL reads a product by (tsd_gdal.h's BLOCK):
 * the chunk cache keeps what a row of them spans. */
#define TSD_BLOCK_SIDE 256
/** NEAR_DISTANCE=0 (automatic): this many cells of the DEM, or
 * TSD_FAR_CELLS_PER_NEAR cells of the far grid if that is longer. */
#define TSD_NEAR_AUTO_CELLS 128
/** The near field must reach at least this many cells. */
#define TSD_NEAR_MIN_CELLS 16
/* The longest NEAR_DISTANCE, metres (its row of the option table). */
#define TSD_NEAR_MAX_M 1e6
/** The far grid is the DEM at full resolution where it fits (docs/windows.md:
 * the far field's error is the averaging of its cells): a DEM of at most
 * TSD_FAR_OWN_MAX_CELLS cells, with one plane of 16-bit angles per azimuth
 * (TSD_FAR_STEPS_PER_DEGREE), within the budget below. Else the DEM
 * averaged to at most TSD_FAR_MAX_CELLS cells (its planes are kept for the
 * dataset's life, one pair of float slopes per azimuth) and to the grid,
 * with its planes, within TSD_FAR_BUDGET_MB (or a quarter of MAX_MEMORY
 * where that is less), but never to cells coarser than NEAR_DISTANCE /
 * TSD_FAR_CELLS_PER_NEAR. */
#define TSD_FAR_OWN_MAX_CELLS (4096.0 * 4096.0)
#define TSD_FAR_STEPS_PER_DEGREE 360
#define TSD_FAR_MAX_CELLS (2048.0 * 2048.0)
#define TSD_FAR_BUDGET_MB 1024.0
#define TSD_FAR_CELLS_PER_NEAR 32

/** A window of a date range's insolation reads transmittance tables over
 * these heights, every window the same (the whole DEM's lowest and highest
 * cells are not known to a window): the Earth's land, from the Dead Sea's
 * shore to above Everest. Linear interpolation in 256 entries over them
 * moves the insolation by 4e-7 of itself at most (tests/check_day_hooks.c). */
#define TSD_DAY_TABLE_Z_MIN -500.0
#define TSD_DAY_TABLE_Z_MAX 9000.0
/** A day product's sun needs a far plane while its upper limb is above
 * this elevation (degrees): the Earth's horizon seen from 9000 m is 3.0
 * degrees down. */
#define TSD_DAY_SUN_UP_DEG -3.5

/** How a dataset is computed window by window; see tsd_window_plan. */
typedef struct {
    int windowed;          /* 0: the whole DEM at once */
    const char *why_whole; /* windowed == 0: why (for the debug log and docs) */
    int tile;              /* chunk side, cells */
    double near_m;         /* near field, metres (NEAR_DISTANCE or MAX_DISTANCE) */
    int margin_x, margin_y; /* the near field in cells, with the sweep's own reach */
    int far;               /* 1: a far field beyond near_m (MAX_DISTANCE=0) */
    int far_w, far_h;      /* the far grid's size */
    int far_own;           /* the far grid is the DEM itself (16-bit angle planes) */
    int far_planes;        /* far-field azimuths kept (the sweeps of a chunk) */
    int cache_chunks;      /* chunks the LRU cache keeps */
    int dem_w, dem_h;      /* the DEM's size (a chunk and its margins lie within it) */
} tsd_window_plan;

/**
 * Plan the windowed computation of options o on a W x H DEM of cells
 * `cells_min_x` (the smallest east-west cell size over its rows) by
 * `cell_y` metres: windowed when TILE_SIZE > 0, the DEM is larger than one
 * tile and the product is one whose value depends only on nearby terrain
 * and horizons (not farshadow, METHOD=shm or shadowmap, the pyramid).
 * `sun` (NULL for the products without one): the sun's sites and day,
 * whose steps and lattice count the far planes of its sweeps. 0, or -1
 * with a sentence in msg (NEAR_DISTANCE too short for this DEM).
 */
int tsd_window_plan_make(const tsd_options *o, const tsd_sun *sun, int W, int H,
                         double cells_min_x, double cell_y, tsd_window_plan *plan, char *msg,
                         size_t msg_size);

/**
 * For a product that needs more than `limit` bytes as planned: a clause
 * for the error that says how windows would fit it ("; TILE_SIZE=1024
 * computes it window by window in about 310 MiB"), or why it needs the
 * whole DEM and which method would window it; empty where windows do not
 * help. `extra`: bytes held beside the windows (an environment's light
 * table and texels), counted in the fit and the figure. The other
 * arguments as tsd_window_plan_make's.
 */
void tsd_window_advice(const tsd_options *o, const tsd_sun *sun, int W, int H,
                       double cells_min_x, double cell_y, double limit, double extra,
                       char *out, size_t n);

/** Bytes a windowed computation keeps at most: one chunk with its margin
 * while computing, the cache, and the far grid with its planes. */
double tsd_window_peak_bytes(const tsd_options *o, const tsd_window_plan *plan,
                             double *steady);

/**
 * The far field of a dataset: the coarse grid of the whole DEM (grid
 * orientation, as tsd_dem reads it) and, per azimuth swept so far, the
 * slopes of terrain at least near_m away from each coarse cell, as a
 * linear function of the observer's height (ts_far_slope_raised at two
 * heights): a full-resolution cell takes its coarse cell's function at its
 * own height. Where the coarse grid is the DEM itself (`own`), each cell's
 * far horizon from its own height instead, as an angle in 16 bits.
 * Computed once per dataset, so that every chunk sees the same.
 */
typedef struct tsd_far_field {
    ts_grid coarse;         /* owned */
    int fine_w, fine_h;     /* the DEM's size */
    double threshold;       /* metres: the near field's reach */
    float zmax;             /* highest coarse height */
    ts_horizon_opts hopts;  /* curvature and threads of the sweeps */
    int own;                /* the coarse grid is the DEM: angles, not slopes */
    int n, cap;
    struct tsd_far_plane {
        double azimuth;
        float *base;        /* slope seen from TSD_FAR_DZ below the coarse height (or
                             * above, where only that observer finds far terrain) */
        float *per_m;       /* its change per metre of observer height (0 there) */
        uint16_t *angle;    /* own: 0 none, else 1 + (degrees + 90) * STEPS_PER_DEGREE */
    } *planes;
} tsd_far_field;

/** Take `coarse` (the far grid, ownership passes) for a fine_w x fine_h
 * DEM; the options give curvature and threads. */
void tsd_far_field_init(tsd_far_field *f, ts_grid *coarse, int fine_w, int fine_h,
                        double threshold, const tsd_options *o);
void tsd_far_field_free(tsd_far_field *f);

#ifdef __cplusplus
}
#endif

#endif
