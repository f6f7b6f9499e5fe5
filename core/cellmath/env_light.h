/*
 * env_light.h - environment light at one cell from one azimuth sector
 * (Timonen & Westerholm 2010, section 6.2, eq. 6): |N_p| L_p(theta_n, h),
 * bilinear in both axes of the sector's table (ts_env_table, built by
 * core/env_table.c). Shared by the C core (core/env_light.c) and the OpenCL
 * kernels; written in the common subset of C11 and OpenCL C 1.2.
 */
#ifndef TS_CM_ENV_LIGHT_H
#define TS_CM_ENV_LIGHT_H

#include "cm_prelude.h"

#ifdef __OPENCL_C_VERSION__
#define CM_ENV_ATAN2F(y, x) atan2(y, x)
#else
#define CM_ENV_ATAN2F(y, x) atan2f(y, x)
#endif

/* Lower node (0 .. steps - 2) of an angle in degrees on a table axis of
 * `steps` nodes over [-90, 90], and in *frac the weight of the upper node.
 * Angles outside the axis are clamped to its ends. */
CM_FN int cm_env_node(float deg, int steps, float *frac)
{
    float top = (float)(steps - 1);
    float u = CM_FMINF(CM_FMAXF((deg + 90.0f) * (top / 180.0f), 0.0f), top);
    int i = (int)u;
    i = i > steps - 2 ? steps - 2 : i;
    *frac = u - (float)i;
    return i;
}

/*
 * Add one sector's light to *r, *g, *b. (nx, ny, nz): the unit normal (x east,
 * y north, z up); horizon_deg: the cell's horizon elevation in the sector's
 * azimuth; (sa, ca): sine and cosine of that azimuth; lp: the sector's
 * table, normal_steps x horizon_steps nodes of 8 floats (moment A per
 * colour, padding, moment B per colour, padding). The normal's component in
 * the sector's vertical plane, N_p = (a, nz) with a = N . (sa, ca, 0), is at
 * theta_n = atan2(a, nz) from the zenith, positive when the surface faces
 * the sector, and |N_p| L_p = nz A + a B.
 */
CM_FN void cm_env_light_sector(float nx, float ny, float nz, float horizon_deg, float sa,
                               float ca, const CM_GLOBAL float *lp, int normal_steps,
                               int horizon_steps, float *r, float *g, float *b)
{
    float a = nx * sa + ny * ca;
    float theta_n = CM_ENV_ATAN2F(a, nz) * 57.29577951f;
    float fu, fv;
    int i = cm_env_node(theta_n, normal_steps, &fu);
    int j = cm_env_node(horizon_deg, horizon_steps, &fv);
    const CM_GLOBAL float *p00 = lp + ((i * horizon_steps) + j) * 8;
    const CM_GLOBAL float *p01 = p00 + 8;
    const CM_GLOBAL float *p10 = p00 + horizon_steps * 8;
    const CM_GLOBAL float *p11 = p10 + 8;
    float w11 = fu * fv, w10 = fu - w11, w01 = fv - w11, w00 = 1.0f - fu - fv + w11;
    /* A NaN horizon (nodata) is clamped to a valid node above: carry it on
     * so that the cell becomes NaN, as a NaN normal does through nz and a. */
    float nodata = horizon_deg - horizon_deg;
    float va = nz * w00, vb = a * w00;
    float out[3];
    for (int c = 0; c < 3; c++)
        out[c] = va * p00[c] + vb * p00[4 + c];
    va = nz * w01, vb = a * w01;
    for (int c = 0; c < 3; c++)
        out[c] += va * p01[c] + vb * p01[4 + c];
    va = nz * w10, vb = a * w10;
    for (int c = 0; c < 3; c++)
        out[c] += va * p10[c] + vb * p10[4 + c];
    va = nz * w11, vb = a * w11;
    for (int c = 0; c < 3; c++)
        out[c] += va * p11[c] + vb * p11[4 + c];
    *r += out[0] + nodata;
    *g += out[1] + nodata;
    *b += out[2] + nodata;
}

#endif
