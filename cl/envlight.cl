/*
 * Environment light (core/env_light.c): one horizon plane's sector added to
 * the three accumulators, one work-item per cell; the formulas are
 * core/cellmath/env_light.h. lp: the whole light table, the sector's part
 * from lp_off; normal_steps 0: the exact form (one row per sector).
 */
__kernel void ts_env_light(__global const float *nx, __global const float *ny,
                           __global const float *nz, __global const float *plane,
                           const long cells, __global const float *lp, const long lp_off,
                           const int normal_steps, const int horizon_steps, const float sa,
                           const float ca, __global float *r, __global float *g,
                           __global float *b)
{
    const long i = get_global_id(0);
    if (i >= cells)
        return;
    __global const float *sector = lp + lp_off;
    float ar = r[i], ag = g[i], ab = b[i];
    if (normal_steps) {
        cm_env_light_sector(nx[i], ny[i], nz[i], plane[i], sa, ca, sector, normal_steps,
                            horizon_steps, &ar, &ag, &ab);
    } else {
        float fv, a;
        int j = cm_env_exact_place(nx[i], ny[i], nz[i], plane[i], sa, ca, horizon_steps, &fv,
                                   &a);
        cm_env_exact_add(sector, j, fv, a, nz[i], &ar, &ag, &ab);
    }
    r[i] = ar;
    g[i] = ag;
    b[i] = ab;
}
