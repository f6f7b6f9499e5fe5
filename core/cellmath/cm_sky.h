/*
 * cm_sky.h - one direction's share of the sky terms at a cell (Timonen &
 * Westerholm 2010, eq. 4-5 with c = 1; see core/sky.c): the direction is a
 * swath of 360/n degrees inside which the sky is visible from the zenith
 * down to theta = min(horizon zenith angle, the zenith angle where the
 * tangent plane cuts the direction). Branch-free, so that loops vectorise;
 * NaN (nodata) in the horizon or the normal gives NaN.
 */
#ifndef TS_CM_SKY_H
#define TS_CM_SKY_H

#include "cm_prelude.h"
#include "cm_fastmath.h"

/* One swath's share of eq. 5 for zenith limit theta; a = n . (sin az,
 * cos az, 0), w1 = 1/n, w2 = sin(pi/n)/pi. */
CM_FN float cm_sky_swath(float nz, float a, float theta, float w1, float w2)
{
    float s, c;
    ts_sincos_0_pi(theta, &s, &c);
    return w1 * nz * s * s + w2 * (theta - s * c) * a;
}

/* Zenith limit of one swath at a cell: the horizon h's zenith angle,
 * raised to at most pi/2 (the horizontal) for sky light, and never below
 * the tangent plane; *a_out: the normal's component along the azimuth
 * (sin sa, cos ca). */
CM_FN float cm_swath_theta(float nx, float ny, float nz, float h, float sa, float ca,
                           int sky_only, float *a_out)
{
    float a = nx * sa + ny * ca;
    float theta_n = TS_PI_2_F + ts_atanf(a / nz);
    float theta_h = TS_PI_2_F - h * TS_DEG2RAD_F;
    if (sky_only)
        theta_h = theta_h < TS_PI_2_F ? theta_h : TS_PI_2_F;
    *a_out = a;
    return theta_h < theta_n ? theta_h : theta_n;
}

/* The term a direction adds to the sky-view factor (sky_only 0) or to the
 * uniform-sky light (sky_only 1) at a cell with horizon h (degrees). */
CM_FN float cm_sky_term(float nx, float ny, float nz, float h, float sa, float ca, float w1,
                        float w2, int sky_only)
{
    float a;
    float th = cm_swath_theta(nx, ny, nz, h, sa, ca, sky_only, &a);
    return cm_sky_swath(nz, a, th, w1, w2) + (h - h) + (nz - nz);
}

/* The term a direction adds to the solid-angle sky-view factor (Zaksek et
 * al. 2011, as RVT_py, SAGA and GRASS r.skyview): w1 * (1 - sin(max(h,
 * 0))), the horizon h in degrees relative to the horizontal, w1 = 1/n. */
CM_FN float cm_svf_solid_term(float h, float w1)
{
    float hp = h > 0.0f ? h : 0.0f, s, c;
    /* sin(hp) = cos of the zenith angle, which lies in [0, pi/2] */
    ts_sincos_0_pi(TS_PI_2_F - hp * TS_DEG2RAD_F, &s, &c);
    return w1 * (1.0f - c) + (h - h);
}

/* The term a direction adds to the openness sum (degrees). */
CM_FN float cm_openness_term(float h, float nz)
{
    return 90.0f - h + (nz - nz);
}

/* The sums' last step: discretisation can overshoot 1 by ~1e-4 on steep
 * open slopes (svf and sky light), and float rounding can leave ~-2e-8 on
 * near-vertical cells (whose sum is 0); openness is the mean over
 * directions. NaN (nodata) passes through. */
CM_FN float cm_sky_clamp(float v)
{
    return v > 1.0f ? 1.0f : v < 0.0f ? 0.0f : v;
}

#endif
