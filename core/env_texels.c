/*
 * Environments as texels: the equal-angle lat-long grid
 * of directions and exact solid angles that standard skies (and tests) fill.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "status_internal.h"
#include "terrashade_env.h"

#define TS_ENV_MAX_GRID_TEXELS ((size_t)1 << 26)

ts_status ts_env_sphere_grid(ts_env *env, int width, int height, ts_error *err)
{
    if (!env)
        return ts_fail(err, TS_ERR_ARG, "the environment must not be NULL");
    env->count = 0;
    env->texels = NULL;
    if (width < 1 || height < 2)
        return ts_fail(err, TS_ERR_ARG,
                       "a lat-long grid needs at least 1 column and 2 rows, got %d x %d",
                       width, height);
    if ((size_t)width * (size_t)height > TS_ENV_MAX_GRID_TEXELS)
        return ts_fail(err, TS_ERR_ARG, "a lat-long grid of %d x %d texels is too large "
                       "(at most %zu texels)", width, height, TS_ENV_MAX_GRID_TEXELS);
    size_t n = (size_t)width * height;
    ts_env_texel *t = calloc(n, sizeof *t);
    if (!t)
        return ts_fail(err, TS_ERR_NOMEM, "no memory for %zu environment texels", n);
    const double dphi = 2 * M_PI / width, dele = M_PI / height;
    for (int r = 0; r < height; r++) {
        /* Row r spans elevations [pi/2 - (r+1) dele, pi/2 - r dele]. */
        double top = M_PI / 2 - r * dele, bottom = top - dele, mid = top - dele / 2;
        double omega = (sin(top) - sin(bottom)) * dphi;
        double ce = cos(mid), se = sin(mid);
        for (int c = 0; c < width; c++) {
            double az = (c + 0.5) * dphi;
            ts_env_texel *x = &t[(size_t)r * width + c];
            x->dir[0] = (float)(ce * sin(az));
            x->dir[1] = (float)(ce * cos(az));
            x->dir[2] = (float)se;
            x->solid_angle = (float)omega;
        }
    }
    env->texels = t;
    env->count = n;
    return ts_ok(err);
}
