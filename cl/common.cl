/*
 * Shared by every kernel: the precision of `real`. The formulas themselves
 * come from core/cellmath (embedded before this file), whose cm_prelude.h
 * turns FP_CONTRACT off, as the C core's -ffp-contract=off, so that the
 * same float expressions round the same way. TS_FP64 (a build option, set
 * when the device has cl_khr_fp64) makes `real` double, as the C code's
 * double arithmetic; without it the kernels compute in float.
 */
typedef cm_real real;
#ifdef TS_FP64
typedef double2 real2;
#else
typedef float2 real2;
#endif
#define RC(x) CM_R(x) /* a real constant */
