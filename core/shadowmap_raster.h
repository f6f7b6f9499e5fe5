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

/* Quads a row of the mesh that TS_SM_SEG_BOUNDS bounds together. */
#define TS_SM_SEG 32
/* Segments a row of a W-vertex mesh has. */
#define TS_SM_SEGS(W) (((W) - 1 + TS_SM_SEG - 1) / TS_SM_SEG)

/*
 * The rows of pv (the least and the greatest) that the quads of each
 * segment of TS_SM_SEG quads of mesh rows [y0, y1) reach, into lo and hi
 * (TS_SM_SEGS(W) a row, row y at y * TS_SM_SEGS(W)); as the render's own
 * test of each quad takes them (fminf, fmaxf: NaN only where every vertex
 * is).
 */
void ts_sm_seg_bounds(const float *pv, int W, int y0, int y1, float *lo, float *hi);

/*
 * ts_sm_render_band skipping the segments that bounds lo, hi (NULL: none)
 * put beyond its rows, as its test of each quad would skip their quads
 * one by one; the same keys (a texel keeps the greatest, whatever the
 * order): a band no longer scans every quad of the mesh.
 */
void ts_sm_render_band_segs(const float *P, int *map, int mw, int vlo, int vhi,
                            const float *pu, const float *pv, const float *pd, int W, int H,
                            const float *lo, const float *hi);

#endif
