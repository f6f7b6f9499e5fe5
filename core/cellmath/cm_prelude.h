/*
 * cm_prelude.h - what the shared per-cell formulas (core/cellmath/*.h)
 * need to compile both as C11, included by core/*.c, and as OpenCL C 1.2,
 * embedded into the kernels by cl/embed.sh (which drops their #include
 * lines, so each header lists its own dependencies and embed order matters).
 *
 * A formula header uses only: CM_FN for its functions, CM_GLOBAL for
 * pointers into device memory, CM_CONST for constant tables, float and
 * double arithmetic, and the math functions both languages have under one
 * name (sqrt, fabs, floor, ... on double; the CM_*F macros on float, since
 * OpenCL overloads the plain names where C has sqrtf, fabsf, ...).
 */
#ifndef TS_CM_PRELUDE_H
#define TS_CM_PRELUDE_H

#ifdef __OPENCL_C_VERSION__
#define CM_FN static inline
#define CM_GLOBAL __global
#define CM_CONST __constant
#define CM_SQRTF(x) sqrt(x)
#define CM_FABSF(x) fabs(x)
#define CM_FLOORF(x) floor(x)
#define CM_FMINF(a, b) fmin(a, b)
#define CM_FMAXF(a, b) fmax(a, b)
#define CM_COPYSIGNF(a, b) copysign(a, b)
#else
#include <math.h>
#define CM_FN static inline
#define CM_GLOBAL
#define CM_CONST static const
#define CM_SQRTF(x) sqrtf(x)
#define CM_FABSF(x) fabsf(x)
#define CM_FLOORF(x) floorf(x)
#define CM_FMINF(a, b) fminf(a, b)
#define CM_FMAXF(a, b) fmaxf(a, b)
#define CM_COPYSIGNF(a, b) copysignf(a, b)
#endif

#endif
