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

#ifdef __cplusplus
}
#endif

#endif
