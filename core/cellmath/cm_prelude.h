/*
 * cm_prelude.h - what the shared per-cell formulas (the core/cellmath headers)
 * need to compile both as C11, included by the core sources, and as OpenCL C 1.2,
 * embedded into the kernels by cl/embed.sh (which drops their #include
 * lines, so each header lists its own dependencies and the embed order in
 * cl/Makefile.inc follows them).
 *
 * A formula header uses only: CM_FN for its functions, CM_GLOBAL for
 * pointers into device memory, float, cm_real (double in C; in OpenCL
 * double where the device has cl_khr_fp64, TS_FP64, else float) and CM_R()
 * for its constants, and the math functions both languages have under one
 * name (sqrt, fabs, floor, isnan, ... on cm_real; the CM_*F macros on
 * float, since OpenCL overloads the plain names where C has sqrtf, ...).
 * Pointers without CM_GLOBAL point at the caller's variables.
 *
 * The C core is compiled with -ffp-contract=off and the kernels with
 * FP_CONTRACT OFF, so the same float expressions round the same way.
 */
#ifndef TS_CM_PRELUDE_H
#define TS_CM_PRELUDE_H

#ifdef __OPENCL_C_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#ifdef TS_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double cm_real;
#define CM_R(x) (x)
#else
typedef float cm_real;
#define CM_R(x) (x##f)
#endif
#define CM_FN static inline
#define CM_GLOBAL __global
#define CM_SQRTF(x) sqrt(x)
#define CM_FABSF(x) fabs(x)
#define CM_COPYSIGNF(a, b) copysign(a, b)
#else
#include <math.h>
typedef double cm_real;
#define CM_R(x) (x)
#define CM_FN static inline
#define CM_GLOBAL
#define CM_SQRTF(x) sqrtf(x)
#define CM_FABSF(x) fabsf(x)
#define CM_COPYSIGNF(a, b) copysignf(a, b)
#endif

#endif
