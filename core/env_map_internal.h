/* Shared between the EXR reader (env_map_exr.c) and the texel builder
 * (env_map.c): an environment image already decoded to floats. */
#ifndef TS_ENV_MAP_INTERNAL_H
#define TS_ENV_MAP_INTERNAL_H

#include "terrashade_env.h"

typedef enum { ENV_LATLONG, ENV_CUBE } env_layout;

/* A decoded map: width x height pixels, three floats each, row 0 first. */
typedef struct {
    const float *rgb;
    int width, height;
    env_layout layout;
} env_image;

/* Turn img into texels in the terrain frame (terrashade_env.h), merged into
 * blocks when max_texels (0: no limit) asks for it. name is the map's name
 * for error messages. On error *out is left empty. */
ts_status env_from_image(const env_image *img, double rotation_deg, size_t max_texels,
                         const char *name, ts_env *out, ts_error *err);

#endif
