/*
 * Shared by every kernel: precision and small helpers ported from core/.
 *
 * The C core is compiled with -ffp-contract=off; so are the kernels, so
 * that the same float expressions round the same way. TS_FP64 (a build
 * option, set when the device has cl_khr_fp64) makes `real` double, as the
 * C code's double arithmetic; without it the kernels compute in float.
 */
#pragma OPENCL FP_CONTRACT OFF

#ifdef TS_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double real;
typedef double2 real2;
#define RC(x) (x) /* a real constant */
#else
typedef float real;
typedef float2 real2;
#define RC(x) (x##f)
#endif

/* ts_atan_deg of core/fastmath.h: the same polynomial in the same order. */
float ts_atan_deg(float s)
{
    float a = fabs(s);
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
    return copysign(p, s) * 57.295779513082321f;
}
