/*
 * day_cycle.h - the sun over a day: sampling times, per-cell sun
 * visibility at an instant, hours of direct sun, clear-sky irradiation
 * (insolation) over a local day or summed over a range of days (from
 * horizons at fixed azimuths), and the dawn/dusk-weighted times of the
 * far-shadow atlas (Chajdas et al. 2015). No GDAL, no global state.
 *
 * Where the sun is seen from: a `ts_sun_sites` is one site (the DEM's
 * centre) or a lattice of sites over the grid; with a lattice the sun's
 * azimuth and elevation are computed with the SPA at every node and
 * interpolated bilinearly to each cell as a unit vector (smooth beside the
 * zenith, where the angles are not). Azimuths from the SPA are true
 * azimuths; each site also gives the grid azimuth of true north (the
 * meridian convergence of a projected CRS, with the opposite sign), and the
 * horizon sweeps use grid azimuth = true azimuth + north_azimuth.
 *
 * See docs/day-cycle.md for the models.
 */
#ifndef TS_DAY_CYCLE_H
#define TS_DAY_CYCLE_H

#include "terrashade.h"
#include "terrashade_sun.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------- dates, offsets */

/**
 * Parse a calendar date "YYYY-MM-DD" (exactly that form; the date must
 * exist in the proleptic Gregorian calendar). The message says what is
 * wrong and what is expected.
 */
ts_status ts_parse_date(const char *s, int *year, int *month, int *day,
                        ts_error *err);

/**
 * Parse a fixed offset from UTC: "Z", "UTC", "+hh:mm", "-hh:mm", "+hhmm" or
 * "+hh" (hh <= 23, mm <= 59). *minutes receives the offset east of UTC.
 * Named time zones (Europe/Zurich) are refused: a fixed offset makes the
 * day exactly 24 hours long.
 */
ts_status ts_parse_utc_offset(const char *s, int *minutes, ts_error *err);

/** Unix time of local midnight starting the given date at a fixed offset. */
double ts_local_midnight(int year, int month, int day, int offset_minutes);

/** Unix time of the local midnight that starts the local day containing the
 * instant `unix_time`, at a fixed offset. */
double ts_local_day_start(double unix_time, int offset_minutes);

/* ------------------------------------------------------------ the sites */

/**
 * Where the sun is seen from. nx = ny = 1: one site for the whole grid.
 * Otherwise an nx x ny lattice, node (i, j) at pixel coordinates
 * (x0 + i dx, y0 + j dy), where the centre of cell (c, r) is (c + 0.5,
 * r + 0.5) and row 0 is north. Cells beyond the lattice take the nearest
 * edge values. Arrays hold nx*ny values, node (i, j) at j*nx + i.
 */
typedef struct {
    int nx, ny;
    double x0, y0, dx, dy;
    const double *longitude;     /**< degrees east, [-180, 180] */
    const double *latitude;      /**< degrees north, [-90, 90] */
    const double *north_azimuth; /**< grid azimuth of true north, degrees;
                                      NULL = 0 (grid north = true north) */
} ts_sun_sites;

/** How ts_sun_hours counts a time step. */
typedef enum {
    /** The step counts in full while any part of the sun's disk is above the
     * cell's horizon. Sunrise and sunset are defined by the upper limb, so
     * on a flat plane this is the astronomical day length. */
    TS_SUN_HOURS_VISIBLE = 0,
    /** The step is weighted by the visible fraction of the disk; on a flat
     * plane this is the time the sun's centre is above the horizon. */
    TS_SUN_HOURS_DISK_FRACTION = 1
} ts_sun_hours_rule;

/**
 * A horizon plane's last step before a day computation reads it: the plane
 * of `azimuth` (grid degrees) just swept on `grid`, changed in place. The
 * driver's windows raise it to the far field beyond the window's near
 * field (docs/windows.md). `sun_elevation` is the apparent elevation of
 * the sun when the plane is read only through the sun's disk at that
 * elevation, NaN when it serves other directions too (the sky term, a
 * date range's planes).
 */
typedef ts_status (*ts_day_plane_fn)(void *user, const ts_grid *grid, double azimuth,
                                     double sun_elevation, float *plane, ts_error *err);

/** ts_day_opts.plane_cache_bytes by default: 2 GiB. */
#define TS_DAY_PLANE_CACHE_DEFAULT ((size_t)2048 << 20)

/** Options of the day computations. Fill with ts_day_opts_default. */
typedef struct {
    ts_horizon_opts horizon; /**< curvature, refraction, max_distance, threads;
                                  `directions` = azimuths of the sky-view term
                                  of the insolation */
    ts_sun_input sun;        /**< template of the SPA input: pressure,
                                  temperature, delta_t, atmos_refraction,
                                  elevation (jd, latitude, longitude are set
                                  per site and instant) */
    double linke_turbidity;  /**< Linke turbidity factor (air mass 2), >= 1 */
    int earth_horizon;       /**< 1: the horizon of a cell is at least the dip
                                  of the sea-level horizon seen from its height
                                  (ts_earth_horizon); 0: terrain only */
    ts_sun_hours_rule sun_hours_rule; /**< what a step of ts_sun_hours counts */
    /** 1: the date range's beam transmittance tables span heights
     * table_height_min..max (metres) instead of the grid's own lowest and
     * highest cell; a window of a larger DEM gives the whole DEM's, so that
     * every window reads the same tables (heights beyond take the end
     * values). */
    int table_heights_given;
    double table_height_min, table_height_max;
    /** A lattice of sites: bytes of horizon planes that ts_sun_hours,
     * ts_insolation and ts_sun_visibility_steps may keep from one time step
     * to the next. Where its suns span more than 2 degrees of azimuth (a
     * DEM spanning many degrees of longitude: up to 361 sweeps a step) a
     * lattice's planes lie at whole degrees, so the steps share them, and
     * a day sweeps each once while they fit; those beyond are swept again
     * at each step that needs them. 0 = keep none.
     * ts_day_opts_default: TS_DAY_PLANE_CACHE_DEFAULT. */
    size_t plane_cache_bytes;
    ts_day_plane_fn plane_hook; /**< after each horizon sweep; NULL = none */
    void *plane_hook_user;      /**< passed to plane_hook */
} ts_day_opts;

/** Defaults: ts_horizon_opts_default, ts_sun_input_default, Linke turbidity
 * 3, Earth horizon on, sun hours TS_SUN_HOURS_VISIBLE, no plane hook. */
void ts_day_opts_default(ts_day_opts *o);

/** Check options and sites (counts, finite coordinates, latitudes within
 * +/-90, longitudes within +/-180); the message names what is wrong. */
ts_status ts_sun_sites_validate(const ts_sun_sites *s, ts_error *err);

/**
 * Elevation angle (degrees, <= 0) of the sea-level horizon seen from
 * `height_m` metres: -acos(R' / (R' + h)) with R' = R / (1 - k) when
 * curvature is on (k = refraction), 0 when it is off or h <= 0.
 */
double ts_earth_horizon(double height_m, const ts_horizon_opts *o);

/** The sun seen from one site at one instant. */
typedef struct {
    double unix_time;
    double azimuth;      /**< true azimuth, degrees from true north */
    double grid_azimuth; /**< azimuth + north_azimuth, in [0, 360) */
    double elevation;    /**< apparent (refracted) elevation of the centre */
    double true_elevation; /**< its elevation without refraction (SPA e0) */
    double distance_au;  /**< Earth-Sun distance, astronomical units */
} ts_sun_sample;

/**
 * The sun at the reference site of `sites` (the single site, or the node
 * nearest the lattice's middle) at `unix_time`.
 */
ts_status ts_sun_at_site(const ts_sun_sites *sites, const ts_day_opts *o,
                         double unix_time, ts_sun_sample *out, ts_error *err);

/**
 * The sun at the site of `sites` where it stands highest at `unix_time`
 * (the single site, or the lattice node of largest elevation): whether any
 * part of the DEM can see it. *node (may be NULL) receives the node's index.
 */
ts_status ts_sun_highest_site(const ts_sun_sites *sites, const ts_day_opts *o,
                              double unix_time, ts_sun_sample *out, int *node, ts_error *err);

/* ------------------------------------------------------- sampling times */

/**
 * Number of steps of STEP seconds that cover [0, length): ceil(length/step).
 */
int ts_day_step_count(double length_s, double step_s);

/**
 * Uniform steps over [start, start + length): step i covers
 * [start + i step, min(start + (i+1) step, end)); mid[i] receives its
 * middle and dur[i] its length in seconds (the last step may be shorter).
 * Both arrays hold ts_day_step_count(length, step) values.
 */
ts_status ts_day_uniform_times(double start_unix, double length_s,
                               double step_s, double *mid, double *dur,
                               ts_error *err);

/**
 * Times of the far-shadow atlas: n instants within [start, start + length)
 * while the sun (at the reference site) is up, i.e. its apparent centre is
 * above -TS_SUN_RADIUS_DEG, sampled more densely near dawn and dusk: the
 * instants are the midpoints of n equal shares of the integral of
 * w(t) = 1 / max(sin e(t), sin 2 deg) over the daylight (e = apparent sun
 * elevation, evaluated every minute and interpolated linearly; the
 * minutes of sunrise and sunset count from or up to that instant, so every
 * instant has the sun's upper limb up). *n_out is
 * n, or 0 when the sun does not rise (polar night).
 */
ts_status ts_day_atlas_times(const ts_sun_sites *sites, const ts_day_opts *o,
                             double start_unix, double length_s, int n,
                             double *times, int *n_out, ts_error *err);

/* ---------------------------------------------------- sun on the grid */

/**
 * The sun seen from every cell at one instant: vis (width*height, may not
 * be NULL) receives the visible fraction (0..1) of the sun's disk above
 * the cell's horizon toward the sun (ts_horizon_sweep at the sun's grid
 * azimuth; with a lattice, sweeps at most 1 deg apart across the cells'
 * range, at the whole degrees where it is wider than 2 deg, interpolated
 * linearly), raised to the Earth's horizon
 * when o->earth_horizon; NaN for nodata. az and el (may be NULL) receive
 * each cell's grid azimuth and apparent elevation of the sun. `ref` (may
 * be NULL) receives the sun at the reference site. No sweep is run while
 * the sun is below every cell's possible horizon.
 */
ts_status ts_sun_visibility(const ts_grid *grid, const ts_sun_sites *sites,
                            const ts_day_opts *o, double unix_time, float *vis,
                            float *az, float *el, ts_sun_sample *ref,
                            ts_error *err);

/**
 * ts_sun_visibility at n instants, instant k into vis + k * width*height,
 * with the horizon planes of a lattice kept from one instant to the next
 * (o->plane_cache_bytes) as ts_sun_hours does: the same values, each
 * azimuth swept once while its planes fit. Progress (o->horizon.progress)
 * per instant.
 */
ts_status ts_sun_visibility_steps(const ts_grid *grid, const ts_sun_sites *sites,
                                  const ts_day_opts *o, const double *unix_times, int n,
                                  float *vis, ts_error *err);

/**
 * The horizon sweeps ts_sun_visibility runs at `unix_time` for `sites`:
 * 1 for one site; for a lattice, enough for its suns' azimuths 1 degree
 * apart or less (at the whole degrees that bracket them where they span
 * more than 2; none are run while the sun is below every cell's horizon). -1 if the sun cannot be computed or memory runs out.
 */
int ts_sun_visibility_sweeps(const ts_sun_sites *sites, const ts_day_opts *o,
                             double unix_time);

/**
 * The distinct horizon planes that the steps at unix_times[0..n) sweep for
 * `sites` when each step's sweeps run (ts_sun_visibility_sweeps): a
 * narrow lattice's at its own azimuths, summed over the steps; a wide one's
 * at whole degrees, which the steps share, each counted once (at most
 * 360). n for one site. -1 if the sun cannot be computed or memory runs
 * out. A windowed day's far field keeps one plane for each (the driver's
 * memory estimate).
 */
int ts_sun_visibility_planes(const ts_sun_sites *sites, const ts_day_opts *o,
                             const double *unix_times, int n);

/**
 * Hours of direct sun over [start, start + length): the sum over uniform
 * steps of step_s seconds of the step's length times, at the middle of the
 * step, 1 if any of the sun's disk is visible (o->sun_hours_rule
 * TS_SUN_HOURS_VISIBLE) or the visible fraction of the disk
 * (TS_SUN_HOURS_DISK_FRACTION). `hours` width*height, NaN for nodata.
 */
ts_status ts_sun_hours(const ts_grid *grid, const ts_sun_sites *sites,
                       const ts_day_opts *o, double start_unix,
                       double length_s, double step_s, float *hours,
                       ts_error *err);

/* ------------------------------------------------------------ clear sky */

/** Solar constant of the clear-sky model, W/m^2 (ESRA). */
#define TS_SOLAR_CONSTANT 1367.0

/** Clear-sky irradiances, W/m^2. */
typedef struct {
    double beam_normal;        /**< on a plane facing the sun */
    double beam_horizontal;    /**< beam_normal x sin(elevation) */
    double diffuse_horizontal; /**< from the whole sky on a level plane */
} ts_clear_sky;

/**
 * ESRA clear-sky model (Rigollier, Bauer & Wald 2000, as in the European
 * Solar Radiation Atlas and GRASS r.sun): beam normal
 * I0 eps exp(-0.8662 TL m dR(m)) with the Kasten & Young (1989) air mass m
 * corrected for the site's height (p/p0 = exp(-z / 8434.5 m)) and Kasten's
 * Rayleigh optical thickness dR; diffuse horizontal I0 eps Trd(TL) Fd(h).
 * eps = 1 / distance_au^2. `elevation` is the apparent sun elevation in
 * degrees; everything is 0 when it is <= 0.
 */
void ts_clear_sky_esra(double elevation, double height_m, double linke,
                       double distance_au, ts_clear_sky *out);

/**
 * Clear-sky irradiation over [start, start + length) in Wh/m^2 on each
 * cell's own tilted surface: at the middle of each step of step_s seconds,
 *   beam = beam_normal x max(0, N.L) x visible fraction of the sun's disk,
 *   diffuse = diffuse_horizontal x sky,
 * with N the Horn normal, L the direction to the sun, and `sky` the
 * irradiance of a uniform sky (ts_sky_terms, o->horizon.directions
 * azimuths: the sky-view factor with the horizon raised to at least 0 deg,
 * 1 on an open level plane); times the step's length in hours. `total`
 * (may not be NULL), `beam` and `diffuse` (may be NULL) width*height, NaN
 * for nodata. Ground-reflected light is not included.
 */
ts_status ts_insolation(const ts_grid *grid, const ts_sun_sites *sites,
                        const ts_day_opts *o, double start_unix,
                        double length_s, double step_s, float *total,
                        float *beam, float *diffuse, ts_error *err);

/* ---------------------------------------------------------- date ranges */

/** ArcGIS Area Solar Radiation's defaults for date ranges. */
#define TS_RANGE_DAY_INTERVAL 14
#define TS_RANGE_STEP_MINUTES 30.0
/** Horizon azimuths of the range products by default: the error it gives
 * against per-step exact sweeps is measured in docs/day-cycle.md. */
#define TS_RANGE_HORIZON_DIRECTIONS 64

/**
 * A range of local days, first to last inclusive, at a fixed UTC offset,
 * cut into blocks of `day_interval` days from the first (the last block
 * shorter); each block's middle day (first + i x day_interval + (w - 1) / 2,
 * w its length) is sampled, cut into steps of `step_minutes` as
 * ts_sun_hours does with one day, and stands for the block's w days, so the
 * weights add up to the range's length and day_interval = 1 gives the
 * exact sum over every day.
 */
typedef struct {
    int first_year, first_month, first_day;
    int last_year, last_month, last_day;
    int utc_offset_minutes;  /**< east of UTC, |offset| < 24 h */
    int day_interval;        /**< days between sampled days, 1..366 */
    double step_minutes;     /**< time step within a day, 1..1440 */
    int horizon_directions;  /**< horizon azimuths the sun's positions are
                                  interpolated between, 4..3600 */
} ts_date_range;

/** Defaults: TS_RANGE_DAY_INTERVAL, TS_RANGE_STEP_MINUTES,
 * TS_RANGE_HORIZON_DIRECTIONS, offset 0, and no dates (all 0: set them). */
void ts_date_range_default(ts_date_range *r);

/**
 * Check a range; *days (may be NULL) receives its length in days and
 * *sampled (may be NULL) the number of sampled days. The message says what
 * is wrong (a date that does not exist, the last day before the first, an
 * interval, step or direction count out of range).
 */
ts_status ts_date_range_check(const ts_date_range *r, int *days, int *sampled,
                              ts_error *err);

/**
 * Block i (0 .. sampled - 1) of a range of `days` days (as
 * ts_date_range_check gives them): *first its first day and *length its
 * days, counted from the range's first day, and *sampled the day that
 * stands for it.
 */
void ts_date_range_block(const ts_date_range *r, int days, int i, int *first, int *length,
                         int *sampled);

/**
 * Hours of direct sun over a date range: the sum over the sampled days,
 * weighted as described at ts_date_range, of what ts_sun_hours gives for
 * that local day (same steps, same o->sun_hours_rule, same Earth horizon),
 * except that the horizon toward the sun is not swept at each sun position:
 * the horizons are swept once for r->horizon_directions azimuths, k * 360
 * / r->horizon_directions degrees from grid north (not from
 * o->horizon.start_azimuth, which turns only ts_insolation_range's sky
 * term's azimuths), and the horizon at
 * the sun's azimuth interpolated linearly between the two nearest. Planes
 * are streamed (three at most in memory). Progress through
 * o->horizon.progress. One sun site only: a lattice is refused
 * (TS_ERR_ARG). `hours` width*height, NaN for nodata.
 */
ts_status ts_sun_hours_range(const ts_grid *grid, const ts_sun_sites *sites,
                             const ts_day_opts *o, const ts_date_range *r,
                             float *hours, ts_error *err);

/**
 * Clear-sky irradiation over a date range in Wh/m^2, weighted as
 * ts_sun_hours_range: what ts_insolation gives for each sampled day, with
 * the horizons interpolated as in ts_sun_hours_range. The sky term uses
 * o->horizon.directions azimuths as ts_insolation does. `total` (may not be
 * NULL), `beam` and `diffuse` (may be NULL) width*height, NaN for nodata.
 */
ts_status ts_insolation_range(const ts_grid *grid, const ts_sun_sites *sites,
                              const ts_day_opts *o, const ts_date_range *r,
                              float *total, float *beam, float *diffuse,
                              ts_error *err);

#ifdef __cplusplus
}
#endif

#endif /* TS_DAY_CYCLE_H */
