/* Small branch-free math that the compiler can vectorise. */
#ifndef TS_FASTMATH_H
#define TS_FASTMATH_H

#include <math.h>

#define TS_RAD2DEG_F 57.295779513082321f

/* atan(s) in degrees, max error 3e-6 deg; +-inf -> +-90, NaN -> NaN.
 * Odd least-squares polynomial on [0, 1], atan(1/x) identity beyond. */
static inline float ts_atan_deg(float s)
{
    float a = fabsf(s);
    int big = a > 1.0f;
    float x = big ? 1.0f / a : a;
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
    p = big ? 1.57079632679f - p : p;
    return copysignf(p, s) * TS_RAD2DEG_F;
}

#endif
