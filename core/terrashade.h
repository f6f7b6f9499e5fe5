/*
 * terrashade.h - public API of libterrashade, the terrain shading core.
 *
 * The core knows nothing of GDAL or OpenCL. It works on a DEM grid of float
 * heights in metres (NaN = nodata) with cell sizes in metres, and returns
 * status codes with a message a user can act on. There is no global state:
 * every function is re-entrant and may be called from several threads on
 * different outputs at once.
 *
 * Conventions (see docs/algorithms.md):
 *  - Row 0 is the northern edge, x grows to the east, y (row index) to the
 *    south, as in a north-up GDAL raster.
 *  - Azimuth: degrees clockwise from north (0 = north, 90 = east), as
 *    gdaldem -az; 0 and 360 are the same direction.
 *  - Elevation: degrees above the horizontal, as gdaldem -alt.
 *  - Horizon angles are signed elevation angles in degrees; -90 means that
 *    nothing in that direction rises above the point (no data beyond it).
 */
#ifndef TERRASHADE_H
#define TERRASHADE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- status */

/** Status codes returned by every fallible function. */
typedef enum {
    TS_OK = 0,
    TS_ERR_ARG,     /**< an argument is NULL, out of range or inconsistent */
    TS_ERR_NOMEM,   /**< an allocation failed (or the size overflows) */
    TS_ERR_THREAD,  /**< a worker thread could not be started */
    TS_ERR_INTERNAL, /**< a bug: please report it */
    TS_ERR_CANCELLED /**< the progress callback asked to stop */
} ts_status;

/** Error detail: the code and one sentence for the user. */
typedef struct {
    ts_status code;
    char message[256];
} ts_error;

/** Name of a status code, e.g. "invalid argument". Never NULL. */
const char *ts_status_name(ts_status code);

/* ------------------------------------------------------------------ grid */

/**
 * A DEM grid. Heights are float metres with NaN for nodata, stored row by
 * row, `stride` floats from the start of one row to the next (stride >=
 * width). Cell sizes are in metres. For a geographic grid the east-west cell
 * size shrinks with latitude: set `cell_x_row` to `height` per-row values
 * (row 0 first); NULL means every row has `cell_x`.
 */
/**
 * Where a grid lies in a larger DEM when it is a window of it (ts_grid's
 * `origin`): horizon sweeps then place their lines and measure distances
 * as they would on the whole DEM, so that a cell's horizon depends on the
 * terrain around it and not on where the window starts.
 */
typedef struct {
    int x0, y0;        /**< the grid's first cell in the larger DEM */
    double ref_cell_x; /**< east-west cell size the larger DEM's sweeps take
                            their direction from (its central row's) */
} ts_grid_origin;

typedef struct {
    int width;
    int height;
    ptrdiff_t stride;
    float *z;
    double cell_x;
    double cell_y;
    double *cell_x_row;
    int owns_memory; /* set by ts_grid_create; ts_grid_free frees only then */
    const ts_grid_origin *origin; /* a window of a larger DEM, or NULL */
} ts_grid;

/**
 * Allocate a width x height grid with stride = width, heights set to 0 and
 * constant cell sizes. Free it with ts_grid_free.
 */
ts_status ts_grid_create(ts_grid *grid, int width, int height, double cell_x,
                         double cell_y, ts_error *err);

/**
 * Give the grid per-row east-west cell sizes (copied; `height` values, all
 * finite and > 0). Only for a grid made by ts_grid_create.
 */
ts_status ts_grid_set_row_spacing(ts_grid *grid, const double *cell_x_row,
                                  ts_error *err);

/** Free what ts_grid_create / ts_grid_set_row_spacing allocated. */
void ts_grid_free(ts_grid *grid);

/** Check a grid (made here or filled in by the caller) for consistency. */
ts_status ts_grid_validate(const ts_grid *grid, ts_error *err);

/** Height at (x, y); no bounds check. */
static inline float ts_grid_at(const ts_grid *g, int x, int y)
{
    return g->z[(ptrdiff_t)y * g->stride + x];
}

/** East-west cell size of row y in metres. */
static inline double ts_grid_cell_x(const ts_grid *g, int y)
{
    return g->cell_x_row ? g->cell_x_row[y] : g->cell_x;
}

/* -------------------------------------------------------------- horizons */

/** Mean Earth radius used for the curvature correction, metres. */
#define TS_EARTH_RADIUS 6371008.8
/** Default refraction coefficient k: drop = (1 - k) d^2 / (2 R). */
#define TS_DEFAULT_REFRACTION 0.13

/**
 * Progress of a long computation: called from the calling thread between
 * its steps (horizon azimuths, time steps of a day) with the fraction done,
 * 0 at the start and 1 at the end. Return non-zero to stop: the computation
 * then fails with TS_ERR_CANCELLED.
 */
typedef int (*ts_progress_fn)(double done, void *user);

/** Options of the horizon sweep. Fill with ts_horizon_opts_default. */
typedef struct {
    int directions;       /**< number of azimuths, >= 1 */
    double start_azimuth; /**< first azimuth, degrees from north */
    double max_distance;  /**< search radius in metres; 0 = unbounded */
    int curvature;        /**< 1 = apply Earth curvature and refraction */
    double refraction;    /**< k in [0, 1] */
    int threads;          /**< worker threads; 0 = number of cores */
    ts_progress_fn progress; /**< NULL = no progress reports */
    void *progress_user;  /**< passed to progress */
} ts_horizon_opts;

/** Defaults: 16 directions from 0 deg, unbounded, curvature on, k = 0.13. */
void ts_horizon_opts_default(ts_horizon_opts *opts);

/** Check horizon options; the message names the offending field. */
ts_status ts_horizon_opts_validate(const ts_horizon_opts *opts, ts_error *err);

/** Azimuth of direction k: start + k * 360 / directions, in [0, 360). */
double ts_horizon_azimuth(const ts_horizon_opts *opts, int k);

/**
 * Exact horizon for one azimuth (Timonen & Westerholm 2010, Algorithm 1):
 * `out` receives width*height signed elevation angles in degrees (row stride
 * = width); NaN where the DEM is nodata, -90 where nothing lies beyond the
 * cell in that direction. O(cells). opts->directions and start_azimuth are
 * ignored.
 */
ts_status ts_horizon_sweep(const ts_grid *grid, double azimuth,
                           const ts_horizon_opts *opts, float *out,
                           ts_error *err);

/**
 * Horizons for opts->directions azimuths (ts_horizon_azimuth): `out` holds
 * directions planes of width*height floats, plane k for azimuth k.
 */
ts_status ts_horizon_compute(const ts_grid *grid, const ts_horizon_opts *opts,
                             float *out, ts_error *err);

/**
 * Horizon sweep along the sample lines only, for tests: the horizon slope
 * tangent (not angle) of every sample of every line, exactly as the hull
 * computes it before it is resampled onto the cells. Calls `visit` for each
 * line with its samples' grid positions, heights, distances and slopes
 * (-INFINITY where no occluder). Single-threaded.
 */
typedef void (*ts_line_visitor)(void *user, int n, const float *x,
                                const float *y, const float *h,
                                const double *d, const float *slope);
ts_status ts_horizon_sweep_lines(const ts_grid *grid, double azimuth,
                                 const ts_horizon_opts *opts,
                                 ts_line_visitor visit, void *user,
                                 ts_error *err);

/* ---------------------------------------------------- shadow height map */

/**
 * Shadow height map (Lee & Kim) for a directional light at `azimuth`,
 * `elevation` (degrees, elevation in [-90, 90]). One O(cells) recurrence,
 * heights propagated from the light's side with linear interpolation.
 * `visibility` (width*height, may be NULL) receives the lit fraction:
 * 1 - clamp((S - h) / penumbra_depth, 0, 1), or the binary test S <= h when
 * penumbra_depth is 0; NaN for nodata. `shadow_height` (may be NULL)
 * receives S itself. Both have row stride = width.
 */
ts_status ts_shm_compute(const ts_grid *grid, double azimuth, double elevation,
                         double penumbra_depth, int threads, float *visibility,
                         float *shadow_height, ts_error *err);

/* --------------------------------------------------------------- shading */

/** Angular radius of the sun's disk, degrees. */
#define TS_SUN_RADIUS_DEG 0.2666

/*
 * Layout of per-cell arrays: normals, horizon planes and every output are
 * width*height floats with a row stride of width, whatever the grid's
 * stride. Functions without a thread count use all cores.
 */

/**
 * Unit surface normals by Horn's method (as gdaldem hillshade), components
 * x = east, y = north, z = up; each array width*height (may not be NULL).
 * On edges and next to nodata the missing neighbours are replaced by the
 * centre cell; a nodata cell gets NaN.
 */
ts_status ts_normals(const ts_grid *grid, float *nx, float *ny, float *nz,
                     ts_error *err);

/**
 * Fraction (0..1) of the sun's disk, centre at `sun_elevation`, radius
 * TS_SUN_RADIUS_DEG, that lies above a horizon at `horizon` degrees.
 */
double ts_sun_disk_fraction(double sun_elevation, double horizon);

/**
 * Direct sun: max(0, N.L) times the visible fraction of the sun's disk above
 * the horizon at the sun's azimuth, interpolated between the two nearest of
 * the `opts->directions` computed azimuths in `horizons` (layout of
 * ts_horizon_compute). Normals from ts_normals. `out` width*height, NaN for
 * nodata.
 */
ts_status ts_shade_direct(const ts_grid *grid, const float *nx, const float *ny,
                          const float *nz, const float *horizons,
                          const ts_horizon_opts *opts, double sun_azimuth,
                          double sun_elevation, float *out, ts_error *err);

/**
 * Sky terms from horizons (layout of ts_horizon_compute), any output may be
 * NULL:
 *  - svf: sky-view factor with the surface normal, Timonen eq. 5 with c = 1
 *    (cosine-weighted visible fraction of the hemisphere around the normal;
 *    1 on an open plane, cos(slope) at the bottom of a V-valley);
 *  - sky: irradiance from a uniform sky of unit radiance, the same integral
 *    with the horizon raised to at least 0 deg (the sky ends at the
 *    horizontal);
 *  - openness: positive openness (Yokoyama et al. 2002), the mean of
 *    90 - horizon angle, degrees; negative openness is the same on the
 *    negated DEM's horizons.
 */
ts_status ts_sky_terms(const ts_grid *grid, const float *nx, const float *ny,
                       const float *nz, const float *horizons,
                       const ts_horizon_opts *opts, float *svf, float *sky,
                       float *openness, ts_error *err);

/**
 * Accumulating form of ts_sky_terms for one direction at a time, so that a
 * caller need not keep every horizon plane: call ts_sky_accumulate for each
 * direction k (plane = its horizon plane) on zeroed accumulators, then
 * ts_sky_finish. Accumulator arrays are width*height floats; any of them
 * may be NULL when that term is not wanted.
 */
ts_status ts_sky_accumulate(const ts_grid *grid, const float *nx,
                            const float *ny, const float *nz,
                            const float *plane, double azimuth, int directions,
                            float *svf_acc, float *sky_acc,
                            float *openness_acc, ts_error *err);
ts_status ts_sky_finish(const ts_grid *grid, int directions, float *svf_acc,
                        float *sky_acc, float *openness_acc, ts_error *err);

/** Which sky-view factor the svf output of the sky terms holds. */
typedef enum {
    /** Timonen eq. 5 with the cell's normal: the cosine-weighted visible
     * fraction of the hemisphere around the normal (what ts_sky_terms
     * computes). */
    TS_SVF_RADIATIVE = 0,
    /** Zaksek et al. (2011), as RVT_py, SAGA and GRASS r.skyview: 1 - the
     * mean over directions of sin(max(horizon, 0)), relative to the
     * horizontal; no normal. */
    TS_SVF_SOLID_ANGLE = 1
} ts_svf_model;

/** TS_OK if `model` is a ts_svf_model, else TS_ERR_ARG with a sentence. */
ts_status ts_check_svf_model(ts_svf_model model, ts_error *err);

/** ts_sky_terms with the svf output of model `svf_model`. */
ts_status ts_sky_terms_model(const ts_grid *grid, const float *nx, const float *ny,
                             const float *nz, const float *horizons,
                             const ts_horizon_opts *opts, ts_svf_model svf_model, float *svf,
                             float *sky, float *openness, ts_error *err);

/** ts_sky_accumulate with the svf accumulator of model `svf_model` (finish
 * it with ts_sky_finish as well). */
ts_status ts_sky_accumulate_model(const ts_grid *grid, const float *nx, const float *ny,
                                  const float *nz, const float *plane, double azimuth,
                                  int directions, ts_svf_model svf_model, float *svf_acc,
                                  float *sky_acc, float *openness_acc, ts_error *err);

/**
 * Combined shade = clamp(direct + sky_weight * sky, 0, 1); NaN stays NaN.
 * `out` may alias `direct`.
 */
ts_status ts_shade_combine(const ts_grid *grid, const float *direct,
                           const float *sky, double sky_weight, float *out,
                           ts_error *err);

/* ----------------------------------------------------------------- misc */

/** Number of online CPU cores (>= 1). */
int ts_cpu_count(void);

#ifdef __cplusplus
}
#endif

#endif /* TERRASHADE_H */
