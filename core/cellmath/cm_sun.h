/*
 * cm_sun.h - direct sun on a cell: the Lambert term times the visible
 * fraction of the sun's disk above the cell's horizon.
 */
#ifndef TS_CM_SUN_H
#define TS_CM_SUN_H

#include "cm_prelude.h"
#include "cm_fastmath.h"

/* Visible fraction of the sun's disk for u = (elevation - horizon) / radius:
 * the area of a unit disk above a chord at height -u, over pi. */
CM_FN float ts_disk_fraction_u(float u)
{
    float uc = u > 1.0f ? 1.0f : u < -1.0f ? -1.0f : u;
    float r = CM_SQRTF(1.0f - uc * uc);
    /* asin(uc) = atan(uc / r), and +-pi/2 where r is 0 */
    float q = uc / (r > 0.0f ? r : 1.0f);
    float as = r > 0.0f ? ts_atanf(q) : CM_COPYSIGNF(TS_PI_2_F, uc);
    return 0.5f + (uc * r + as) * 0.318309886f;
}

/*
 * Direct sun of one cell: normal (nx, ny, nz), horizon planes h0, h1 on
 * either side of the sun's azimuth mixed with weight w, light vector
 * (lx, ly, lz), sun elevation el in degrees, inv_r = 1 / the sun's angular
 * radius in degrees. Branch-free, so that loops over it vectorise; NaN
 * (nodata) in the normal or the horizon gives NaN.
 */
CM_FN float cm_direct_sun(float nx, float ny, float nz, float h0, float h1, float w, float lx,
                          float ly, float lz, float el, float inv_r)
{
    float hz = (1.0f - w) * h0 + w * h1;
    float ndotl = nx * lx + ny * ly + nz * lz;
    float lit = ts_disk_fraction_u((el - hz) * inv_r);
    float v = (ndotl > 0.0f ? ndotl : 0.0f) * lit;
    return v + (hz - hz) + (ndotl - ndotl); /* NaN stays NaN */
}

#endif
