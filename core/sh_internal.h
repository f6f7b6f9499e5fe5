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

/** ts_sh_rotate_z for floats added to a sum: acc += R(angle) in, with
 *  cos and sin of m * angle for m = 1..3 given (cs[m-1], sn[m-1]). */
static inline void ts_sh_add_rotated(const float *in, const double *cs, const double *sn,
                                     double *acc)
{
    acc[0] += in[0];
    for (int l = 1; l <= 3; l++) {
        int c0 = l * (l + 1);
        acc[c0] += in[c0];
        for (int m = 1; m <= l; m++) {
            double c = in[c0 + m], s = in[c0 - m];
            acc[c0 + m] += c * cs[m - 1] - s * sn[m - 1];
            acc[c0 - m] += c * sn[m - 1] + s * cs[m - 1];
        }
    }
}

#endif
