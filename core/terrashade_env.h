/*
 * terrashade_env.h - environments: the light arriving from every direction
 * of the sky (and below it), from an HDR map (OpenEXR, lat-long or cube
 * faces) or from a standard sky, in the terrain's frame.
 *
 * Terrain frame (DESIGN.md, "Environment light"): x east, y north, z up,
 * matching terrashade.h's grid (row 0 north). OpenEXR's map frame (ImfEnvmap)
 * has +Y up, and a lat-long map's centre column looks along +Z, its top row
 * is the zenith. With rotation 0, map +Z is grid north and map +X is west
 * (so a panorama photographed facing north, east to its right, lights the
 * terrain as photographed); rotation theta turns the environment clockwise
 * (seen from above) by theta degrees: what was at azimuth a comes from a + theta.
 *
 * An environment is held as texels: for each, a unit direction in the
 * terrain frame, the solid angle it covers (steradians; they sum to 4 pi)
 * and its radiance per colour (linear RGB, >= 0, finite). Light and
 * visibility are evaluated from these texels, whatever the map's layout.
 */
#ifndef TERRASHADE_ENV_H
#define TERRASHADE_ENV_H

#include <stddef.h>

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One texel of an environment. */
typedef struct {
    float dir[3];   /**< unit direction towards the light, terrain frame (x east, y north, z up) */
    float solid_angle; /**< steradians */
    float rgb[3];   /**< radiance per colour, linear, >= 0 */
} ts_env_texel;

/** An environment: texels covering the whole sphere. */
typedef struct {
    size_t count;
    ts_env_texel *texels;
} ts_env;

/** Free the texels (NULL-safe); leaves count 0. */
void ts_env_free(ts_env *env);

/* ---------------------------------------------------------------- reader
 *
 * Map conventions, exactly those of OpenEXR's ImfEnvmap (LatLongMap and
 * CubeMap::direction), in the map frame (+Y up):
 *
 *  - Lat-long, width w and height h (pixels counted from the data window's
 *    corner): pixel (i, j) looks at latitude pi/2 - pi j/(h-1) (row 0 is the
 *    zenith, the last row the nadir) and longitude pi - 2 pi i/(w-1), the
 *    direction (sin lon cos lat, sin lat, cos lon cos lat): the centre column
 *    looks along +Z, the left half towards +X. Pixel centres lie on the poles
 *    and on both ends' meridian (longitude +-pi), so each texel covers half a
 *    pixel spacing either side, clipped to the sphere: the first and last
 *    columns cover half a column each, the first and last rows a polar cap.
 *    Its solid angle is exact: (its longitude span) x (sin of its upper
 *    latitude - sin of its lower one).
 *  - Cube faces, w x 6w: faces +X, -X, +Y, -Y, +Z, -Z stacked top to bottom,
 *    each oriented as OpenEXR's CubeMap::pixelPosition places it (seen from
 *    the centre of the cube, unmirrored). Face position (px, py) maps to
 *    (u, v) = 2 p/(w-1) - 1 in [-1, 1], so again edge pixels sit on the
 *    cube's edges and cover half a pixel (a quarter at the corners); the
 *    solid angle of a texel is the exact one of its (u, v) rectangle on the
 *    face (atan(u v / sqrt(1 + u^2 + v^2)) at its corners).
 *
 * Then to the terrain: map +Z is north, +X west, +Y up, i.e.
 * (east, north, up) = (-x, z, y), and the rotation turns it clockwise seen
 * from above. The texels' solid angles sum to 4 pi (within float rounding).
 *
 * Pixel values: negative values (ringing of lossy compression, filters) are
 * clamped to 0; NaN and infinity are refused with an error naming the pixel.
 * All functions here are reentrant (no global state).
 */

/** The most pixels a map may have (2^26, e.g. 8192 x 8192; a 16384 x 8192
 *  lat-long map is refused): reading takes 12 bytes a pixel, plus 28 a
 *  texel (see max_texels). The fuzz build (tests/fuzz/build.sh) sets a
 *  smaller limit, so that a few-byte file declaring a legal but huge,
 *  highly compressible map cannot spend libFuzzer's per-input time on it. */
#ifndef TS_ENV_MAX_PIXELS
#define TS_ENV_MAX_PIXELS ((size_t)1 << 26)
#endif

/** An environment from a lat-long image in OpenEXR's convention (above):
 *  rgb holds width x height pixels, row 0 (the zenith) first, three floats
 *  per pixel. width and height >= 2. One texel per pixel. *out is
 *  overwritten (not freed); on error it is left empty. */
ts_status ts_env_from_latlong(const float *rgb, int width, int height, double rotation_deg,
                              ts_env *out, ts_error *err);

/** The same from a cube-face image: face_size (>= 1) x (6 face_size)
 *  pixels, faces +X, -X, +Y, -Y, +Z, -Z top to bottom, three floats per
 *  pixel. */
ts_status ts_env_from_cube(const float *rgb, int face_size, double rotation_deg, ts_env *out,
                           ts_error *err);

/**
 * Read an environment map from an OpenEXR file with OpenEXRCore: the first
 * part of the file (multi-part files too), scanline or tiled (level 0 of a
 * mip-map), half, float or uint channels, every OpenEXR compression: what
 * OpenEXRCore cannot decode yet (DWAA and DWAB before OpenEXR 3.2, e.g. the
 * Blender / Poly Haven maps) is decoded by OpenEXR's C++ library instead
 * (libterrashade.la lists -lstdc++ among its dependencies for it). Colour
 * from the channels R, G and B (A and others are ignored), or, without
 * them, grey from Y (a luminance-chroma image's RY/BY are ignored); the
 * channels used must not be subsampled.
 *
 * Layout: the `envmap` attribute (lat-long or cube) when present, else the
 * aspect ratio: width = 2 height is lat-long, height = 6 width is cube
 * faces, anything else is refused. A cube map must be w x 6w.
 *
 * max_texels: 0 keeps one texel per pixel; otherwise, when the map has more
 * pixels, they are merged in k x k blocks (the smallest k that gives at
 * most max_texels texels, blocks never straddle a cube face; the edge
 * blocks may be smaller): a block's solid angle is the sum of its pixels',
 * its radiance their solid-angle-weighted mean (a box filter that keeps the
 * energy), its direction the mean of theirs weighted by power (r + g + b
 * times solid angle; by solid angle in a black block), normalised, so that
 * a bright spot (the sun) keeps its direction. A hint: a cube map keeps at
 * least 6 texels. With max_texels, a map coarser than one degree a pixel
 * is cut the other way: each pixel into parts of at most a degree (each
 * the pixel's radiance over its exact solid angle, their count within
 * max_texels), since a texel's light comes from its centre.
 *
 * Errors (TS_ERR_ARG, a sentence naming the file): missing or unreadable
 * file, not an OpenEXR file, damaged or truncated data, deep data, no
 * usable channel, an empty or too large data window (TS_ENV_MAX_PIXELS),
 * an aspect that fits neither layout, a cube map not w x 6w, a NaN or
 * infinite pixel. TS_ERR_NOMEM when memory runs out.
 */
ts_status ts_env_load_exr_file(const char *path, double rotation_deg, size_t max_texels,
                               ts_env *out, ts_error *err);

/** The same from the bytes of an EXR file in memory (e.g. read by GDAL's
 *  VSI from a /vsi path); name (may be NULL) is used in error messages. */
ts_status ts_env_load_exr_memory(const void *buf, size_t size, const char *name,
                                 double rotation_deg, size_t max_texels, ts_env *out,
                                 ts_error *err);

/** What an EXR environment map is, from its header (ts_env_exr_info). */
typedef struct {
    int cube;          /**< 1: cube faces, 0: lat-long */
    int grey;          /**< 1: grey from Y, 0: colour from R, G, B */
    int chroma;        /**< 1: grey from Y of a luminance/chroma file (it has RY and
                            BY, OpenEXR's YC colour): its colour is not read */
    int width, height; /**< of the data window, pixels */
} ts_env_map_info;

/** The layout, channels and size ts_env_load_exr_memory would use, from the
 *  header only (no pixels decoded); the same errors for what the header
 *  shows (not an EXR, no usable channel, bad size or aspect). */
ts_status ts_env_exr_info(const void *buf, size_t size, const char *name,
                          ts_env_map_info *info, ts_error *err);

/** The texels ts_env_load_exr_memory makes of that map with max_texels
 *  (blocks merged, coarse pixels cut), without decoding it: what a caller
 *  checks its memory against (28 bytes a texel, 12 a pixel while read). */
size_t ts_env_map_texels(const ts_env_map_info *info, size_t max_texels);

/* ------------------------------------------------- lat-long texel grids */

/**
 * Texels of an equal-angle grid over the whole sphere, radiance 0, for the
 * caller to fill (standard skies, tests): `width` columns of azimuth, column
 * c spanning [c, c + 1] * 360 / width degrees clockwise from north, and
 * `height` rows of elevation, row 0 at the zenith, row height - 1 at the
 * nadir. Texel (row r, column c) is texels[r * width + c]; its direction is
 * the cell's centre in angle, its solid angle the exact area of the cell,
 * (sin e_top - sin e_bottom) * 2 pi / width, so they sum to 4 pi.
 * width >= 1, height >= 2, width * height <= 2^26. Free with ts_env_free.
 */
ts_status ts_env_sphere_grid(ts_env *env, int width, int height, ts_error *err);

/* ------------------------------------------------------- standard skies */

/** The standard skies (choices explained in core/env_sky.c). */
typedef enum {
    TS_SKY_UNIFORM = 0, /**< the same radiance everywhere above the horizontal */
    TS_SKY_OVERCAST,    /**< CIE standard overcast sky (Moon & Spencer 1942, CIE 1955):
                             L(Z) = Lz (1 + 2 cos Z) / 3, no sun dependence */
    TS_SKY_CLEAR,       /**< CIE standard clear sky: general sky type 12 */
    TS_SKY_CIE          /**< one of the 15 CIE general sky types (ISO 15469, CIE S 011) */
} ts_sky_kind;

/** Default lat-long resolution of a standard sky (ts_env_sky with 0 x 0):
 * rows of 0.5 deg, so that row edges fall on the default table's 1 deg
 * horizon nodes (a texel row cut by a node counts wholly on one side). */
#define TS_SKY_DEFAULT_WIDTH 1024
#define TS_SKY_DEFAULT_HEIGHT 360

/**
 * Relative luminance L / Lz of CIE general sky `type` (1..15) at a sky
 * element `zenith_deg` from the zenith and `sun_distance_deg` from the sun,
 * with the sun `sun_zenith_deg` from the zenith (ISO 15469 / CIE S 011):
 * f(chi) phi(Z) / (f(Zs) phi(0)), gradation phi(Z) = 1 + a exp(b / cos Z)
 * (phi = 1 at and below the horizontal), indicatrix f(chi) = 1 + c (exp(d chi)
 * - exp(d pi / 2)) + e cos^2 chi. NaN for a type out of range.
 */
double ts_cie_sky_relative(int type, double zenith_deg, double sun_distance_deg,
                           double sun_zenith_deg);

/**
 * Parse a sky name: "uniform", "overcast", "clear" or "cie:N" (N in 1..15;
 * also "cieN", for inline connection strings; case-insensitive). Sets *kind and *cie_type (0 unless TS_SKY_CIE).
 */
ts_status ts_sky_parse(const char *name, ts_sky_kind *kind, int *cie_type, ts_error *err);

/**
 * 1 if the sky's radiance depends on where the sun is (clear, and the CIE
 * types with a circumsolar indicatrix: all but 1, 3 and 5), else 0
 * (uniform, overcast, CIE types 1, 3, 5).
 */
int ts_sky_follows_sun(ts_sky_kind kind, int cie_type);

/**
 * A standard sky as an environment on a width x height lat-long grid
 * (ts_env_sphere_grid; 0 x 0 = TS_SKY_DEFAULT_WIDTH x HEIGHT), grey
 * (R = G = B). Normalised so that the horizontal diffuse irradiance is pi
 * (summed over the grid's own texels), i.e. a flat open plane reflects
 * E/pi = 1, as under the uniform sky of radiance 1 and as the shade
 * product's uniform `sky` term: skies are interchangeable at one
 * SKY_WEIGHT. Zero below the horizontal (the ground is not a light; the
 * terrain's horizon does the rest). The sun's disk itself is not part of the
 * sky: the shade product's direct term adds it. cie_type is used only for
 * TS_SKY_CIE; the sun (azimuth degrees from north, elevation in [-90, 90])
 * only for the sun-dependent skies (ignored, but still checked, by the others).
 */
ts_status ts_env_sky(ts_env *env, ts_sky_kind kind, int cie_type, double sun_azimuth,
                     double sun_elevation, int width, int height, ts_error *err);

/* -------------------------------------------------- Timonen's L_p table */

/**
 * Default table resolutions, chosen by measurement (tests/check_env_light.c,
 * bench/env_bench.c): the exact normal axis (0) is more accurate than a
 * bilinear normal axis of 65 steps, its table is 65 times smaller and the
 * lighting costs less than half as much; 1-degree horizon steps (finer ones
 * gave nothing against the brute-force reference).
 */
#define TS_ENV_DEFAULT_NORMAL_STEPS 0
#define TS_ENV_DEFAULT_HORIZON_STEPS 181

/**
 * Options of the light table. The sectors must be the horizon sweep's
 * azimuths: sector k is centred on start_azimuth + k * 360 / directions.
 */
typedef struct {
    int directions;       /**< azimuth sectors, >= 1 (DIRECTIONS) */
    double start_azimuth; /**< centre of sector 0, degrees from north */
    int normal_steps;     /**< samples of the projected normal angle over [-90, 90] deg,
                               odd >= 3 (bilinear, as Timonen), or 0: exact (see
                               ts_env_table); odd counts put a node at 0 */
    int horizon_steps;    /**< samples of the horizon angle over [-90, 90] deg, odd >= 3 */
    int ground;           /**< 0: light from below the horizontal is ignored (the sky
                               ends at the horizontal, as the `sky` product);
                               1: it counts where the terrain's horizon is lower */
} ts_env_table_opts;

/** Defaults: 16 directions from 0 deg, the default steps, ground 0. */
void ts_env_table_opts_default(ts_env_table_opts *opts);

/**
 * Timonen's L_p (eq. 7) per sector k, tabulated over the projected normal
 * angle theta_n (the normal's angle from the zenith in the vertical plane of
 * azimuth k, positive towards k) and the horizon angle h (elevation), held
 * as its two moments over the sector's texels above both h and the tangent
 * plane (cut at the sector's centre, as eq. 4): A = 1/pi sum L omega e_z and
 * B = 1/pi sum L omega e . u_k (u_k the sector's horizontal unit vector),
 * so that L_p = cos theta_n A + sin theta_n B (core/env_table.c says why).
 * Layout: lp[((k * normal_steps + i) * horizon_steps + j) * 8 + m], m = 0..2
 * A per colour (RGB), m = 4..6 B per colour, 3 and 7 padding; node i at
 * theta_n = -90 + 180 i / (normal_steps - 1), node j at h = -90 + 180 j /
 * (horizon_steps - 1) degrees.
 *
 * A texel is lit when its elevation exceeds max(h, -theta_n), so A and B
 * depend on theta_n only through that cut. With normal_steps 0 the table
 * keeps one row per sector (lp[(k * horizon_steps + j) * 8 + m], no cut)
 * and each cell reads it at its own
 * max(h, -theta_n): L_p(theta_n, h) = cos theta_n A(max(h, -theta_n)) +
 * sin theta_n B(max(h, -theta_n)), exact in theta_n, linear in the cut.
 */
typedef struct {
    int directions;
    double start_azimuth;
    int normal_steps;
    int horizon_steps;
    float *lp;
} ts_env_table;

/**
 * Build the table from an environment: O(texels + directions *
 * max(normal_steps, 1) * horizon_steps), independent of any DEM.
 * Texels with zero radiance are skipped. Free with ts_env_table_free.
 */
ts_status ts_env_table_build(const ts_env *env, const ts_env_table_opts *opts,
                             ts_env_table *table, ts_error *err);

/** Free the table (NULL-safe). */
void ts_env_table_free(ts_env_table *table);

/** Azimuth of the table's sector k, degrees in [0, 360). */
double ts_env_table_azimuth(const ts_env_table *table, int k);

/** What one sector's environment light is computed from and added to
 *  (ts_env_light_accumulate_fn). Every pointer must be set. */
typedef struct {
    const ts_grid *grid;
    const ts_env_table *table;
    int k;                     /**< the sector, 0 <= k < table->directions */
    const float *nx, *ny, *nz; /**< unit normals from ts_normals (nz > 0) */
    const float *plane;        /**< sector k's horizon plane (ts_horizon_sweep at
                                    ts_env_table_azimuth(table, k)) */
    float *r, *g, *b;          /**< width*height accumulators, zeroed before sector 0 */
    int threads;               /**< threads of the C backend, 0 (unset) = every core */
} ts_env_light_request;

/**
 * Environment light, one horizon plane at a time (Timonen eq. 6): add
 * |N_p| L_p(k, theta_n, h) = nz A + (N . u_k) B per colour, A and B bilinear
 * in both table axes (or, with normal_steps 0, linear at the cell's own cut),
 * to the request's accumulators for its sector k. Nodata (NaN normal or
 * horizon) gives NaN. Then ts_env_light_finish. The type of every backend's
 * environment light (terrashade_cl.h).
 */
typedef ts_status ts_env_light_accumulate_fn(const ts_env_light_request *req, ts_error *err);

/** The environment light on the C backend. */
ts_env_light_accumulate_fn ts_env_light_accumulate;

/**
 * Finish the accumulated light: E/pi per colour, the light reflected by a
 * white Lambertian surface (a flat open plane under a constant radiance L
 * gives L). Tiny negative sums (the tangent-plane cut is taken at the
 * sector's centre) become 0; NaN stays NaN.
 */
ts_status ts_env_light_finish(const ts_grid *grid, float *r, float *g, float *b,
                              ts_error *err);

/**
 * All sectors at once from horizons in the layout of ts_horizon_compute
 * (opts->directions planes; they must match the table's directions and start
 * azimuth): zeroes r, g, b, accumulates and finishes.
 */
ts_status ts_env_light(const ts_grid *grid, const ts_env_table *table, const float *nx,
                       const float *ny, const float *nz, const float *horizons,
                       const ts_horizon_opts *opts, float *r, float *g, float *b,
                       ts_error *err);

#ifdef __cplusplus
}
#endif

#endif
