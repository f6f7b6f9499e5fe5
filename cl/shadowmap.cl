/*
 * Shadow map with percentage-closer filtering: the loops of
 * core/shadowmap.c, the formulas of core/cellmath/cm_shadowmap.h. P is the
 * frame's parameters (ts_shadowmap_frame_make); the map holds mw x mh keys.
 */

/* Project vertex i (heights z with row stride `stride`, cxr: the east-west
 * cell size of each row) into texel coordinates and depth. */
__kernel void ts_shadowmap_project(__global const float *z, const long stride, const int W,
                                   const int H, __global const float *cxr,
                                   __global const float *P, __global float *pu,
                                   __global float *pv, __global float *pd)
{
    const long i = get_global_id(0);
    if (i >= (long)W * H)
        return;
    const int y = (int)(i / W), x = (int)(i - (long)y * W);
    float u, v, d;
    ts_sm_project(P, x, y, cxr[y], z[(long)y * stride + x], &u, &v, &d);
    pu[i] = u;
    pv[i] = v;
    pd[i] = d;
}

/* The map and its tiles: empty. */
__kernel void ts_shadowmap_clear(__global int *map, const long n)
{
    const long i = get_global_id(0);
    if (i < n)
        map[i] = TS_SM_EMPTY;
}

/* One work-item per quad of the DEM; texels and their tiles keep the
 * largest key by atomic_max, so the order of the work-items does not
 * matter. */
__kernel void ts_shadowmap_render(__global const float *P, __global int *map, const int mw,
                                  const int mh, __global const float *pu,
                                  __global const float *pv, __global const float *pd,
                                  const int W, const int H)
{
    const long q = get_global_id(0);
    if (q >= (long)(W - 1) * (H - 1))
        return;
    const int y = (int)(q / (W - 1)), x = (int)(q - (long)y * (W - 1));
    ts_sm_quad(P, map, mw, mh, 0, mh, pu, pv, pd, W, x, y);
}

__kernel void ts_shadowmap_filter(__global const float *P, __global const int *map,
                                  const int mw, const int mh, __global const float *pu,
                                  __global const float *pv, __global const float *pd,
                                  const int W, const int H, __global float *out)
{
    const long i = get_global_id(0);
    if (i >= (long)W * H)
        return;
    const int y = (int)(i / W), x = (int)(i - (long)y * W);
    out[i] = ts_sm_cell_at(P, map, mw, mh, pu, pv, pd, W, H, x, y);
}
