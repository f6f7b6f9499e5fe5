/*
 * cm_fastmath.h - small branch-free math, the same in both backends: the C
 * compiler vectorises it (glibc's libm calls cannot be), and the kernels
 * round exactly as the C code. Accuracy is stated per function.
 */
#ifndef TS_CM_FASTMATH_H
#define TS_CM_FASTMATH_H

#include "cm_prelude.h"

#define TS_RAD2DEG_F 57.295779513082321f
#define TS_DEG2RAD_F 0.017453292519943295f
#define TS_PI_2_F 1.57079632679f

/* atan(s) in radians, max error 5e-8 rad; +-inf -> +-pi/2, NaN -> NaN.
 * Odd least-squares polynomial on [0, 1], atan(1/x) identity beyond. */
CM_FN float ts_atanf(float s)
{
    float a = CM_FABSF(s);
    int big = a > 1.0f;
    float inv = 1.0f / a; /* always computed: a select, not a branch */
    float x = big ? inv : a;
    float x2 = x * x;
    float p = -4.065356858e-03f;
    p = p * x2 + 2.189318185e-02f;
    p = p * x2 - 5.594107285e-02f;
    p = p * x2 + 9.643018630e-02f;
    p = p * x2 - 1.390835283e-01f;
    p = p * x2 + 1.994636661e-01f;
    p = p * x2 - 3.332982797e-01f;
    p = p * x2 + 9.999993225e-01f;
    p *= x;
    p = big ? TS_PI_2_F - p : p;
    return CM_COPYSIGNF(p, s);
}

/* atan(s) in degrees, max error 3e-6 deg. */
CM_FN float ts_atan_deg(float s)
{
    return ts_atanf(s) * TS_RAD2DEG_F;
}

/* sin and cos of x in [0, pi] (zenith angles), max error 1e-7, from
 * polynomials in y = x - pi/2 on [-pi/2, pi/2]: sin x = cos y,
 * cos x = -sin y. */
CM_FN void ts_sincos_0_pi(float x, float *s, float *c)
{
    float y = x - TS_PI_2_F, y2 = y * y;
    float sy = -2.3843565983e-08f;
    sy = sy * y2 + 2.7521933788e-06f;
    sy = sy * y2 - 1.9840772786e-04f;
    sy = sy * y2 + 8.3333299520e-03f;
    sy = sy * y2 - 1.6666666569e-01f;
    sy = (sy * y2 + 9.9999999992e-01f) * y;
    float cy = 1.9942810736e-09f;
    cy = cy * y2 - 2.7527114971e-07f;
    cy = cy * y2 + 2.4801102961e-05f;
    cy = cy * y2 - 1.3888884914e-03f;
    cy = cy * y2 + 4.1666666512e-02f;
    cy = cy * y2 - 4.9999999998e-01f;
    cy = cy * y2 + 1.0f;
    *s = cy;
    *c = -sy;
}

#endif
