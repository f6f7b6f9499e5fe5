/*
 * Normals, direct sun and sky terms: the loops of core/normals.c,
 * core/shading.c and core/sky.c, one work-item per cell; the formulas are
 * core/cellmath/cm_normals.h, cm_sun.h and cm_sky.h.
 */

/* Horn normals; cxr: per-row east-west cell sizes when has_cxr. */
__kernel void ts_normals(__global const float *z, const int W, const int H,
                         __global const real *cxr, const int has_cxr, const real cell_x,
                         const real cell_y, __global float *nx, __global float *ny,
                         __global float *nz)
{
    const long o = get_global_id(0);
    if (o >= (long)W * H)
        return;
    const int y = (int)(o / W), x = (int)(o - (long)y * W);
    float a, b, c;
    cm_horn_normal(z, W, W, H, x, y, (real)8 * (has_cxr ? cxr[y] : cell_x), (real)8 * cell_y,
                   &a, &b, &c);
    nx[o] = a;
    ny[o] = b;
    nz[o] = c;
}

/* Direct sun: h0, h1 are the two horizon planes around the sun's azimuth,
 * mixed with weight w; el: the sun's elevation in degrees, inv_r: 1 / its
 * angular radius in degrees. */
__kernel void ts_direct(__global const float *nx, __global const float *ny,
                        __global const float *nz, __global const float *h0,
                        __global const float *h1, const long cells, const float w,
                        const float lx, const float ly, const float lz, const float el,
                        const float inv_r, __global float *out)
{
    const long i = get_global_id(0);
    if (i >= cells)
        return;
    out[i] = cm_direct_sun(nx[i], ny[i], nz[i], h0[i], h1[i], w, lx, ly, lz, el, inv_r);
}

/*
 * Sky terms: accumulate nplanes horizon planes (directions with sines and
 * cosines sa[k], ca[k]) onto the accumulators, then, when `finish`, clamp
 * and average as ts_sky_finish. want: bit 0 svf, 1 sky, 2 openness, 3 the
 * svf is the solid-angle one (TS_SVF_SOLID_ANGLE); w1, w2: 1/n and
 * sin(pi/n)/pi.
 */
__kernel void ts_sky(__global const float *nx, __global const float *ny,
                     __global const float *nz, __global const float *planes,
                     const int nplanes, const long cells, __global const float *sa,
                     __global const float *ca, const float w1, const float w2, const int want,
                     const int finish, const float directions, __global float *svf,
                     __global float *sky, __global float *open)
{
    const long i = get_global_id(0);
    if (i >= cells)
        return;
    float as = (want & 1) ? svf[i] : 0.0f;
    float ak = (want & 2) ? sky[i] : 0.0f;
    float ao = (want & 4) ? open[i] : 0.0f;
    const float nzi = nz[i], nxi = nx[i], nyi = ny[i];
    for (int k = 0; k < nplanes; k++) {
        const float h = planes[k * cells + i];
        as += (want & 8) ? cm_svf_solid_term(h, w1) + (nzi - nzi)
                         : cm_sky_term(nxi, nyi, nzi, h, sa[k], ca[k], w1, w2, 0);
        ak += cm_sky_term(nxi, nyi, nzi, h, sa[k], ca[k], w1, w2, 1);
        ao += cm_openness_term(h, nzi);
    }
    if (finish) {
        as = cm_sky_clamp(as);
        ak = cm_sky_clamp(ak);
        ao /= directions;
    }
    if (want & 1)
        svf[i] = as;
    if (want & 2)
        sky[i] = ak;
    if (want & 4)
        open[i] = ao;
}
