/*
 * fuzz_exr: the environment-map reader (core/env_map.c) on arbitrary bytes,
 * as an OpenEXR file's contents (lat-long or cube-face maps). Built by
 * tests/fuzz/build.sh only once core/terrashade_env.h declares
 * ts_env_load_exr_memory. Besides the sanitizers, it checks the promises of
 * terrashade_env.h on a map that loads: unit directions, solid angles that
 * sum to 4 pi, radiances finite and >= 0; and that a failure says why.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "terrashade_env.h"

static void check_env(const ts_env *env)
{
    double total = 0;
    fuzz_require(env->count == 0 || env->texels != NULL, "texels missing");
    for (size_t i = 0; i < env->count; i++) {
        const ts_env_texel *t = &env->texels[i];
        double len = sqrt((double)t->dir[0] * t->dir[0] + (double)t->dir[1] * t->dir[1] +
                          (double)t->dir[2] * t->dir[2]);
        fuzz_require(fabs(len - 1.0) < 1e-3, "a texel direction is not a unit vector");
        fuzz_require(isfinite(t->solid_angle) && t->solid_angle >= 0, "bad solid angle");
        for (int c = 0; c < 3; c++)
            fuzz_require(isfinite(t->rgb[c]) && t->rgb[c] >= 0,
                         "a radiance is negative or not finite");
        total += t->solid_angle;
    }
    if (env->count)
        fuzz_require(fabs(total - 4 * M_PI) < 1e-2 * 4 * M_PI,
                     "the solid angles do not cover the sphere");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* The first byte picks the rotation, so the frame turn is fuzzed too. */
    double rotation = size ? data[0] * (360.0 / 256.0) : 0.0;
    ts_env env;
    ts_error err;
    memset(&env, 0, sizeof env);
    memset(&err, 0, sizeof err);
    /* at most 4096 texels: merged blocks are checked too, and runs stay fast */
    if (ts_env_load_exr_memory(size ? data + 1 : data, size ? size - 1 : 0, "fuzz input",
                               rotation, 4096, &env, &err) == TS_OK)
        check_env(&env);
    else
        fuzz_require(err.message[0] != '\0', "a refused map says nothing");
    ts_env_free(&env);
    return 0;
}
