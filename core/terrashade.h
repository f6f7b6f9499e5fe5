/*
 * terrashade.h - the API of libterrashade, the terrain shading core (used by
 * the plugin, the benches and the tests within the build; not installed).
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

/** Error detail: the code and one sentence for the user. Every function
 * that takes a `ts_error *err` accepts NULL there (the status is returned
 * either way). */
typedef struct {
    ts_status code;
    char message[256];
} ts_error;

/** Name of a status code, e.g. "invalid argument". Never NULL. */
const char *ts_status_name(ts_status code);

/* ------------------------------------------------------------------ grid */

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
    int full_width, full_height; /**< the larger DEM's size, cells: where its
                                      edge lies (ts_horizon_edge_apply) */
} ts_grid_origin;

/**
 * A DEM grid. Heights are float metres with NaN for nodata, stored row by
 * row, `stride` floats from the start of one row to the next (stride >=
 * width). Cell sizes are in metres. For a geographic grid the east-west cell
 * size shrinks with latitude: set `cell_x_row` to `height` per-row values
 * (row 0 first); NULL means every row has `cell_x`. Row 0 is north.
 */
typedef struct {
    int width;          /**< cells per row */
    int height;         /**< rows */
    ptrdiff_t stride;   /**< floats from one row's start to the next's */
    float *z;           /**< heights, metres; NaN: nodata */
    double cell_x;      /**< east-west cell size, metres */
    double cell_y;      /**< north-south cell size, metres */
    double *cell_x_row; /**< per-row east-west sizes (height values), or NULL */
    int owns_memory; /**< set by ts_grid_create; ts_grid_free frees only then */
    const ts_grid_origin *origin; /**< a window of a larger DEM, or NULL */
} ts_grid;

/** A grid's longest side, cells: keeps width*height*directions in size_t
 * and every index in ptrdiff_t, and turns absurd sizes into a clear error. */
#define TS_MAX_SIDE (1 << 20)

/** The cell sizes a grid may have, metres: below about 1e-45 (where a
 * float's range ends) the sweeps' steps overflowed and cells read NaN
 * (1e-320 m: every cell), so 1e-30 keeps a wide margin and takes the
 * rows near a pole of a geographic grid (R cos(lat) dlon, 1e-12 m on a
 * row centred on it); no terrain has cells of more than 100 000 km. */
#define TS_CELL_MIN_M 1e-30
#define TS_CELL_MAX_M 1e8

/**
 * Allocate a width x height grid (each side 1 .. TS_MAX_SIDE) with stride =
 * width, heights set to 0 and constant cell sizes (TS_CELL_MIN_M ..
 * TS_CELL_MAX_M). Free it with
 * ts_grid_free.
 */
ts_status ts_grid_create(ts_grid *grid, int width, int height, double cell_x,
                         double cell_y, ts_error *err);

/**
 * Give the grid per-row east-west cell sizes (copied; `height` values, all
 * TS_CELL_MIN_M .. TS_CELL_MAX_M). Only for a grid made by ts_grid_create.
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

/**
 * What lies beyond the DEM's edge (docs/algorithms.md, "The world beyond the
 * DEM edge"), for a ray from a cell that leaves the grid:
 */
typedef enum {
    /** nothing: an open sky down to -90 deg (the raw sweep) */
    TS_EDGE_OPEN = 0,
    /** the sea-level surface of the Earth, with curvature and refraction
     * as `curvature` and `refraction` say: the horizon is at least the
     * highest sea-level point beyond the edge (within max_distance) */
    TS_EDGE_HORIZON = 1,
    /** unknown: the cell is nodata (NaN) when its ray leaves the grid
     * within max_distance (at all, when max_distance is 0) */
    TS_EDGE_NODATA = 2
} ts_edge_mode;

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
    ts_edge_mode edge;    /**< the world beyond the grid's edge */
    /** 1: the caller reads the horizons only through a light whose disk is
     * wholly above the horizontal (ts_light_clears_horizontal), to which
     * every horizon at or below 0 deg is the same; the TS_EDGE_HORIZON
     * raises that cannot lift a cell above 0 deg (the sea-level surface
     * seen from a height >= 0, the Earth's horizon) are then skipped.
     * 0 (the default): every horizon exact. */
    int nonpositive_moot;
} ts_horizon_opts;

/** Defaults: 16 directions from 0 deg, unbounded, curvature on, k = 0.13,
 * TS_EDGE_OPEN (the raw sweep; the driver's default is TS_EDGE_HORIZON). */
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
 * ignored. The type of every backend's sweep (terrashade_cl.h).
 */
typedef ts_status ts_horizon_sweep_fn(const ts_grid *grid, double azimuth,
                                      const ts_horizon_opts *opts, float *out, ts_error *err);

/** The horizon sweep on the C backend. */
ts_horizon_sweep_fn ts_horizon_sweep;

/**
 * The world beyond the edge (opts->edge) applied to a horizon plane of the
 * sweep toward `azimuth`, in place: TS_EDGE_HORIZON raises each cell's angle
 * to ts_edge_horizon of its height and distance to the edge along the
 * azimuth, TS_EDGE_NODATA sets NaN where that distance is within
 * max_distance (every cell when it is 0), TS_EDGE_OPEN changes nothing.
 * ts_horizon_sweep ends with it; a backend that sweeps otherwise calls it.
 */
ts_status ts_horizon_edge_apply(const ts_grid *grid, double azimuth,
                                const ts_horizon_opts *opts, float *plane,
                                ts_error *err);

/**
 * Elevation angle (degrees) of the highest point of the sea-level surface
 * beyond the edge seen from `height_m` metres, `edge_m` metres from the edge
 * along the ray: the maximum over s in [edge_m, max_distance] (no upper
 * bound when max_distance is 0) of atan((-h - c s^2) / s), c = (1 - k) / 2R
 * with curvature, 0 without. -90 when edge_m > max_distance > 0 (the ray
 * stays on the grid), NaN for a NaN height.
 */
double ts_edge_horizon(double height_m, double edge_m, const ts_horizon_opts *opts);

/**
 * Distance in metres from the centre of cell (x, y) to the grid's outer edge
 * along `azimuth` (the sweep lines' direction: cells of the central row's
 * size).
 */
double ts_edge_distance(const ts_grid *grid, int x, int y, double azimuth);

/**
 * The Earth's horizon as a floor of the direct sun: raise each cell of a
 * horizon plane to the dip of the sea-level horizon seen from its height
 * (ts_earth_horizon), when opts->edge is TS_EDGE_HORIZON; otherwise nothing.
 * So a sun below the Earth's horizon lights no cell, whatever max_distance.
 */
ts_status ts_horizon_earth_floor(const ts_grid *grid, const ts_horizon_opts *opts,
                                 float *plane, ts_error *err);

/**
 * The direct sun of a method that sees no edge (the shadow height map):
 * multiply each visibility in `vis` (width*height; NaN stays NaN) by the
 * fraction of the sun's disk at (azimuth, elevation) above the horizon that
 * the world beyond the edge (opts->edge) and, with TS_EDGE_HORIZON, the
 * Earth (as ts_horizon_earth_floor) put before the cell alone; NaN where
 * TS_EDGE_NODATA blanks the cell. TS_EDGE_OPEN changes nothing.
 */
ts_status ts_horizon_edge_sun(const ts_grid *grid, double azimuth, double elevation,
                              const ts_horizon_opts *opts, float *vis, ts_error *err);

/**
 * Horizons for opts->directions azimuths (ts_horizon_azimuth): `out` holds
 * directions planes of width*height floats, plane k for azimuth k. The type
 * of every backend's horizons.
 */
typedef ts_status ts_horizon_compute_fn(const ts_grid *grid, const ts_horizon_opts *opts,
                                        float *out, ts_error *err);

/** The horizons on the C backend. */
ts_horizon_compute_fn ts_horizon_compute;

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
 * receives S itself. Both have row stride = width. The type of every
 * backend's shadow height map.
 */
typedef ts_status ts_shm_compute_fn(const ts_grid *grid, double azimuth, double elevation,
                                    double penumbra_depth, int threads, float *visibility,
                                    float *shadow_height, ts_error *err);

/** The shadow height map on the C backend. */
ts_shm_compute_fn ts_shm_compute;

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
 * At the grid's edge the row or column beyond is extrapolated as gdaldem's
 * -compute_edges does (cm_horn_normal); a neighbour that is nodata, or
 * extrapolated from nodata, is replaced by the centre cell; a nodata cell
 * gets NaN. The type of every backend's normals.
 */
typedef ts_status ts_normals_fn(const ts_grid *grid, float *nx, float *ny, float *nz,
                                ts_error *err);

/** The normals on the C backend (on every core). */
ts_normals_fn ts_normals;

/** ts_normals on `threads` threads (0 = every core). */
ts_status ts_normals_threads(const ts_grid *grid, int threads, float *nx, float *ny, float *nz,
                             ts_error *err);

/**
 * Fraction (0..1) of the sun's disk, centre at `sun_elevation`, radius
 * TS_SUN_RADIUS_DEG, that lies above a horizon at `horizon` degrees.
 */
double ts_sun_disk_fraction(double sun_elevation, double horizon);

/** Largest angular radius of a light's disk, degrees (exclusive). */
#define TS_LIGHT_RADIUS_MAX 45.0

/**
 * Fraction (0..1) of a light's disk of angular radius `radius` degrees
 * (> 0), centre at `light_elevation`, that lies above a horizon at
 * `horizon` degrees; NaN if an argument is NaN or radius <= 0.
 * ts_sun_disk_fraction is this with radius TS_SUN_RADIUS_DEG.
 */
double ts_disk_fraction(double light_elevation, double horizon, double radius);

/**
 * 1 if a light at `light_elevation` of angular radius `radius` degrees
 * (0: TS_SUN_RADIUS_DEG) is wholly visible above every horizon at or below
 * 0 deg, in ts_disk_fraction's double arithmetic and in the float one of the
 * direct sun (cm_direct_sun, both backends): both are monotonic in the
 * horizon, so a horizon raised from one value <= 0 to another changes no
 * lit fraction (ts_horizon_opts.nonpositive_moot). 0 otherwise.
 */
int ts_light_clears_horizontal(double light_elevation, double radius);

/** TS_OK if 0 < radius < TS_LIGHT_RADIUS_MAX degrees, else TS_ERR_ARG with
 * a sentence. */
ts_status ts_check_light_radius(double radius, ts_error *err);

/** What the direct sun is computed from and into (ts_shade_direct_fn). */
typedef struct {
    const ts_grid *grid;
    const float *nx, *ny, *nz;   /**< unit normals from ts_normals */
    const float *horizons;       /**< opts->directions planes, layout of ts_horizon_compute */
    const ts_horizon_opts *opts; /**< the options the horizons were computed with */
    double sun_azimuth;          /**< degrees from north, finite */
    double sun_elevation;        /**< degrees, in [-90, 90] */
    float *out;                  /**< width*height: the direct light, NaN for nodata */
    double light_radius;         /**< the light's angular radius, degrees, in
                                      (0, TS_LIGHT_RADIUS_MAX); 0 (unset): the
                                      sun's, TS_SUN_RADIUS_DEG. A wider disk
                                      casts soft shadows: the exact reference
                                      of the approximate soft-shadow methods */
} ts_direct_request;

/**
 * Direct sun: max(0, N.L) times the visible fraction of the sun's disk above
 * the horizon at the sun's azimuth, interpolated between the two nearest of
 * the `opts->directions` computed azimuths. Every pointer of the request
 * must be set. The type of every backend's direct sun (terrashade_cl.h).
 */
typedef ts_status ts_shade_direct_fn(const ts_direct_request *req, ts_error *err);

/** The direct sun on the C backend. */
ts_shade_direct_fn ts_shade_direct;

/**
 * ts_shade_direct with the normals computed on the fly, row by row, from
 * req->grid by Horn's method (as ts_normals): req->nx, ny, nz are not read
 * and may be NULL. The same values as ts_normals then ts_shade_direct,
 * without the three planes of normals. With one direction, req->out may be
 * req->horizons (in place: no plane besides the output).
 */
ts_shade_direct_fn ts_shade_direct_horn;

/** Which sky-view factor the svf output of the sky terms holds. */
typedef enum {
    /** Timonen eq. 5 with the cell's normal: the cosine-weighted visible
     * fraction of the hemisphere around the normal (the default). */
    TS_SVF_RADIATIVE = 0,
    /** Zaksek et al. (2011), as RVT_py and GRASS r.skyview: 1 - the
     * mean over directions of sin(max(horizon, 0)), relative to the
     * horizontal; no normal. */
    TS_SVF_SOLID_ANGLE = 1
} ts_svf_model;

/** TS_OK if `model` is a ts_svf_model, else TS_ERR_ARG with a sentence. */
ts_status ts_check_svf_model(ts_svf_model model, ts_error *err);

/** What the sky terms are computed from and into (ts_sky_terms_fn). */
typedef struct {
    const ts_grid *grid;
    const float *nx, *ny, *nz;   /**< unit normals from ts_normals */
    const float *horizons;       /**< opts->directions planes, layout of ts_horizon_compute */
    const ts_horizon_opts *opts; /**< the options the horizons were computed with */
    ts_svf_model svf_model;      /**< which sky-view factor `svf` holds */
    float *svf;                  /**< width*height or NULL: the sky-view factor */
    float *sky;                  /**< width*height or NULL: uniform-sky light */
    float *openness;             /**< width*height or NULL: positive openness, degrees */
} ts_sky_request;

/**

 * Sky terms from horizons, each output only where the request has one:
 *  - svf: sky-view factor of model svf_model; TS_SVF_RADIATIVE is Timonen
 *    eq. 5 with c = 1 (cosine-weighted visible fraction of the hemisphere
 *    around the normal; 1 on an open plane, cos(slope) at the bottom of a
 *    V-valley);
 *  - sky: irradiance from a uniform sky of unit radiance, the same integral
 *    with the horizon raised to at least 0 deg (the sky ends at the
 *    horizontal);
 *  - openness: positive openness (Yokoyama et al. 2002), the mean of
 *    90 - horizon angle, degrees; negative openness is the same on the
 *    negated DEM's horizons.
 * The type of every backend's sky terms (terrashade_cl.h).
 */
typedef ts_status ts_sky_terms_fn(const ts_sky_request *req, ts_error *err);

/** The sky terms on the C backend. */
ts_sky_terms_fn ts_sky_terms;

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
/** Turn the accumulators of `directions` ts_sky_accumulate calls into the
 * terms themselves, in place (svf and sky 0..1, openness degrees); the same
 * NULLs as there. */
ts_status ts_sky_finish(const ts_grid *grid, int directions, float *svf_acc,
                        float *sky_acc, float *openness_acc, ts_error *err);

/** ts_sky_accumulate with the svf accumulator of model `svf_model` (finish
 * it with ts_sky_finish as well), on `threads` threads (0 = every core, as
 * ts_sky_accumulate). */
ts_status ts_sky_accumulate_model(const ts_grid *grid, const float *nx, const float *ny,
                                  const float *nz, const float *plane, double azimuth,
                                  int directions, ts_svf_model svf_model, int threads,
                                  float *svf_acc, float *sky_acc, float *openness_acc,
                                  ts_error *err);

/**
 * Combined shade = clamp(direct + sky_weight * sky, 0, 1); NaN stays NaN.
 * `out` may alias `direct`.
 */
ts_status ts_shade_combine(const ts_grid *grid, const float *direct,
                           const float *sky, double sky_weight, float *out,
                           ts_error *err);

/* ------------------------------------------------------ pyramid horizons */

/*
 * Approximate horizons from a multi-resolution pyramid (Snyder &
 * Nowrouzezahrai 2008, sections 3-4; docs/methods.md). Level j has a
 * spacing of s_j = b^j DEM cells, b = 2^(1/k) for a level step k, and is
 * made from level j - 1 by bilinear decimation; level 0 is the DEM. Levels
 * from 1 up are read through a bicubic B-spline (reconstructed once at
 * every DEM column, then bilinear between columns, as the paper's section
 * 6), level 0 bilinearly. For a cell and an azimuth, level j gives the
 * multi-scale directional derivative at distance d_j = s_j steps of the
 * ray: tan w_j = (f(x + d_j) - f(x) - c d_j^2) / d_j, both heights read on
 * the same level, in metres (per-row geographic cell sizes, curvature c as
 * the sweep). The horizon is the maximum of the cubic B-spline through the
 * w_j in log distance, sampled at its knots and midpoints (eq. 4-5); or,
 * cheaper, the maximum over the levels (section 6, for environment light).
 * The last sample is where the ray leaves the DEM (or reaches
 * max_distance), read on the DEM itself. Cost: O(levels) per cell and
 * azimuth, wherever the occluder is. Signed degrees, NaN for nodata, -90
 * where nothing lies beyond the cell, as ts_horizon_sweep.
 */

/** How the blocking angles of the levels become one horizon angle. */
typedef enum {
    /** Cubic B-spline in log distance, its maximum at knots and midpoints. */
    TS_PYRAMID_BSPLINE = 0,
    /** The maximum over the levels (no spline, one arctangent). */
    TS_PYRAMID_LEVEL_MAX = 1
} ts_pyramid_reconstruction;

/** Options of the pyramid. Fill with ts_pyramid_opts_default. */
typedef struct {
    double level_step; /**< k in [1, 16]: levels per halving of resolution */
    double offset;     /**< o in [0, 64]: sample j reads level
                            max(0, floor(j - k o)) (finer, sharper), at the
                            same distance */
    ts_pyramid_reconstruction reconstruction;
} ts_pyramid_opts;

/** Defaults: k = 4, o = 0, B-spline. */
void ts_pyramid_opts_default(ts_pyramid_opts *opts);

/** Check pyramid options; the message names the offending field. */
ts_status ts_pyramid_opts_validate(const ts_pyramid_opts *opts, ts_error *err);

/** Number of levels of a width x height pyramid of level step k:
 * ceil(k log2(max(width, height))) + 1, so that the coarsest level's
 * spacing spans the grid. 0 if the arguments are invalid. */
int ts_pyramid_level_count(int width, int height, double level_step);

/** Bytes a width x height pyramid of level step k keeps (about
 * 1 / (1 - 2^(-1/k)) times the DEM: 6.3 for k = 4). */
double ts_pyramid_bytes(int width, int height, double level_step);

/** Bytes ts_pyramid_build holds at its peak: what the pyramid keeps, and
 * the four level-sized buffers (heights and valid fractions of two
 * levels, each about 1 / 2^(2/k) of the DEM) it decimates through. */
double ts_pyramid_build_bytes(int width, int height, double level_step);

/** A built pyramid (opaque). */
typedef struct ts_pyramid ts_pyramid;

/**
 * Build the pyramid of `grid` (threads: 0 = all cores). The pyramid reads
 * grid's heights and cell sizes later: keep the grid alive and unchanged
 * until ts_pyramid_free.
 */
ts_status ts_pyramid_build(const ts_grid *grid, const ts_pyramid_opts *opts, int threads,
                           ts_pyramid **out, ts_error *err);

/** Free a pyramid (NULL is fine). */
void ts_pyramid_free(ts_pyramid *pyr);

/**
 * Pyramid horizon for one azimuth into `out` (width*height, row stride =
 * width), as ts_horizon_sweep: opts->curvature, refraction, max_distance
 * and threads are used (and opts->edge, through ts_horizon_edge_apply, as
 * the sweep), directions and start_azimuth ignored.
 */
ts_status ts_pyramid_horizon(const ts_pyramid *pyr, double azimuth,
                             const ts_horizon_opts *opts, float *out, ts_error *err);

/** The most azimuths ts_pyramid_horizons computes at once. */
#define TS_PYRAMID_BATCH 8

/**
 * Pyramid horizons for `count` azimuths (1 to TS_PYRAMID_BATCH) into
 * out[k] (each width*height): bit for bit ts_pyramid_horizon of each, in
 * less time than one at a time (the cells' own heights on each level,
 * the same for every azimuth, are read once).
 */
ts_status ts_pyramid_horizons(const ts_pyramid *pyr, int count, const double *azimuths,
                              const ts_horizon_opts *opts, float *const *out, ts_error *err);

/** What ts_pyramid_horizons_sky adds each plane's sky terms to. */
typedef struct {
    const float *nx, *ny, *nz; /**< unit normals from ts_normals, width*height each */
    int directions;            /**< as ts_sky_accumulate_model's */
    ts_svf_model svf_model;    /**< which sky-view factor svf sums */
    float *svf, *sky, *openness; /**< width*height each, added to; NULL: not wanted */
} ts_pyramid_sky;

/**
 * ts_pyramid_horizons (the planes written as it writes them), and each
 * plane's sky terms added to sky's accumulators bit for bit as
 * ts_sky_accumulate_model of the planes in order (at `azimuths`) would,
 * each row span summed as soon as it is done, while it is in the cache.
 * With out NULL no plane is written (each row's horizons go to a row of
 * scratch, summed, then reused): the same sums without count planes of
 * memory. Finish the sums with ts_sky_finish.
 */
ts_status ts_pyramid_horizons_sky(const ts_pyramid *pyr, int count, const double *azimuths,
                                  const ts_horizon_opts *opts, const ts_pyramid_sky *sky,
                                  float *const *out, ts_error *err);

/** Build a pyramid and compute opts->directions planes, as
 * ts_horizon_compute (with its progress reports). */
ts_status ts_pyramid_horizon_compute(const ts_grid *grid, const ts_pyramid_opts *popts,
                                     const ts_horizon_opts *opts, float *out,
                                     ts_error *err);

/* ----------------------------------------------------------------- misc */

/** Number of CPU cores this process may run on (its affinity mask: taskset,
 * a container's cpuset; else the online ones; >= 1). */
int ts_cpu_count(void);

/** Levels of the hand-written vector code (ts_cpu_vector_level). */
enum {
    TS_CPU_VECTORS_NONE = 0,  /**< the portable C paths */
    TS_CPU_VECTORS_AVX2 = 1,  /**< AVX2 where a path has it, else portable C */
    TS_CPU_VECTORS_AVX512 = 2 /**< AVX-512 (with AVX-512VL and BW) */
};

/** The widest hand-written vector code this process runs: the CPU's,
 * capped by the environment variable TERRASHADE_SIMD (auto, avx512, avx2 or
 * none; asked once per process, a bad value counts as auto). Every level
 * gives the same results; the cap is for tests and timings of the paths a
 * CPU without AVX-512 takes. */
int ts_cpu_vector_level(void);

/** Parse a TERRASHADE_SIMD value into the cap it sets (NULL, "" and auto:
 * TS_CPU_VECTORS_AVX512, no cap); TS_ERR_ARG, naming the value, otherwise. */
ts_status ts_cpu_vectors_parse(const char *text, int *cap, ts_error *err);

/** "AVX-512", "AVX2" or "portable C", for a level. */
const char *ts_cpu_vectors_name(int level);

#ifdef __cplusplus
}
#endif

#endif /* TERRASHADE_H */
