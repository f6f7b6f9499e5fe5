/* The C backend's rasteriser of the shadow map (core/shadowmap.c). */
#ifndef TS_SHADOWMAP_RASTER_H
#define TS_SHADOWMAP_RASTER_H

/*
 * Render into map (mw texels a row) rows [vlo, vhi) of the depth map: every
 * triangle of the W x H mesh of projected vertices pu, pv, pd (the frame's
 * parameters P) that reaches them, as ts_sm_triangle does, the same keys.
 * The rows must be cleared to TS_SM_EMPTY before.
 */
void ts_sm_render_band(const float *P, int *map, int mw, int vlo, int vhi, const float *pu,
                       const float *pv, const float *pd, int W, int H);

#endif
