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

/* atan(s) in degrees, branch-free (selects), error <= 6e-4 deg: Abramowitz
 * & Stegun 4.4.49 on [0, 1] (|error| <= 1e-5 rad), atan(1/x) identity
 * beyond; +-inf gives +-90. The table position needs no more, and libm's
 * atan2f alone cost more than the rest of the cell's work. */
CM_FN float cm_env_atan_deg(float s)
{
    float x = CM_FABSF(s);
    int big = x > 1.0f;
    float inv = 1.0f / x;
    float t = big ? inv : x, t2 = t * t;
    float p = ((((0.0208351f * t2 - 0.0851330f) * t2 + 0.1801410f) * t2 - 0.3302995f) * t2 +
               0.9998660f) * t;
    p = big ? 1.57079632679f - p : p;
    return CM_COPYSIGNF(p * 57.29577951f, s);
}

/* Lower node (0 .. steps - 2) of an angle in degrees on a table axis of
 * `steps` nodes over [-90, 90], and in *frac the weight of the upper node.
 * Angles outside the axis are clamped to its ends, NaN to the lower end. */
CM_FN int cm_env_node(float deg, int steps, float *frac)
{
    float top = (float)(steps - 1);
    float u = (deg + 90.0f) * (top / 180.0f);
    /* Selects, not fminf/fmaxf (a libm call each in C): NaN -> 0, so the
     * index stays valid whatever the input. */
    u = u > 0.0f ? u : 0.0f;
    u = u < top ? u : top;
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
 * theta_n = atan(a / nz) from the zenith (nz > 0, as ts_normals gives),
 * positive when the surface faces the sector, and |N_p| L_p = nz A + a B.
 */
CM_FN void cm_env_light_sector(float nx, float ny, float nz, float horizon_deg, float sa,
                               float ca, const CM_GLOBAL float *lp, int normal_steps,
                               int horizon_steps, float *r, float *g, float *b)
{
    float a = nx * sa + ny * ca;
    float theta_n = cm_env_atan_deg(a / nz); /* nz > 0 on a height field */
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

/*
 * The same with the normal axis exact (a table built with normal_steps 0:
 * one row of horizon_steps nodes of 8 floats per sector, no tangent-plane
 * cut in it). A texel of the sector is lit when its elevation exceeds both
 * the horizon and the tangent plane's cut -theta_n, so the moments are taken
 * at max(horizon, -theta_n), linear along the one axis. In two steps, so
 * that C can run the first, branch-free, over a row in vector registers:
 * cm_env_exact_place gives the node j, the weight fv of node j + 1 and the
 * in-plane component a (NaN for nodata); cm_env_exact_add reads the table.
 */
CM_FN int cm_env_exact_place(float nx, float ny, float nz, float horizon_deg, float sa,
                             float ca, int horizon_steps, float *fv, float *a_out)
{
    float a = nx * sa + ny * ca;
    float cut = -cm_env_atan_deg(a / nz); /* nz > 0 on a height field */
    *a_out = a + (horizon_deg - horizon_deg); /* a NaN horizon makes the cell NaN */
    return cm_env_node(horizon_deg > cut ? horizon_deg : cut, horizon_steps, fv);
}

CM_FN void cm_env_exact_add(const CM_GLOBAL float *lp, int j, float fv, float a, float nz,
                            float *r, float *g, float *b)
{
    const CM_GLOBAL float *p0 = lp + j * 8;
    const CM_GLOBAL float *p1 = p0 + 8;
    float a1 = nz * fv, a0 = nz - a1, b1 = a * fv, b0 = a - b1;
    *r += a0 * p0[0] + b0 * p0[4] + a1 * p1[0] + b1 * p1[4];
    *g += a0 * p0[1] + b0 * p0[5] + a1 * p1[1] + b1 * p1[5];
    *b += a0 * p0[2] + b0 * p0[6] + a1 * p1[2] + b1 * p1[6];
}

#endif
