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
 *  texel (see max_texels). */
#define TS_ENV_MAX_PIXELS ((size_t)1 << 26)

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
 * (libterrashade.la lists -lstdc++ among its dependencies for it). Colour from the channels R, G and B (A and others are ignored),
 * or, without them, grey from Y (a luminance-chroma image's RY/BY are
 * ignored); the channels used must not be subsampled.
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
 * least 6 texels.
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

#ifdef __cplusplus
}
#endif

#endif
