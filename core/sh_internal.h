/* sh_internal.h - what the SH files share (core/sh_*.c); not installed. */
#ifndef TS_SH_INTERNAL_H
#define TS_SH_INTERNAL_H

#include "terrashade_sh.h"

/** Zonal coefficients (of y_l0) of the clamped cosine max(0, z)
 *  (Ramamoorthi & Hanrahan 2001): sqrt(pi)/2, sqrt(pi/3), sqrt(5 pi)/8, 0. */
static const double TS_SH_CLAMPED_COS_ZH[4] = {0.886226925452758014, 1.023326707946488488,
                                               0.495415912200751666, 0.0};

/** Gauss-Legendre nodes and weights of n points (n <= 32) on [-1, 1]. */
void ts_sh_gauss(int n, double *x, double *w);

#endif
