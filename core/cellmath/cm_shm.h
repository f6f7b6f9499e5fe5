/*
 * cm_shm.h - one step of the shadow height map (Lee & Kim; see
 * core/shadow_height_map.c): S = max(h, S_prev - drop), S_prev linearly
 * interpolated in the previous row, and the light that reaches the cell.
 */
#ifndef TS_CM_SHM_H
#define TS_CM_SHM_H

#include "cm_prelude.h"

/*
 * S of a cell of height h from the previous row's shadow heights pa (at
 * v + off) and pb (at v + off + 1), interpolated at fraction F (a NaN end
 * falls back to the other; with F = 0, pb is not read), less the drop
 * along the step. pa = pb = NaN: nothing toward the light. Nodata h is no
 * occluder: the shadow passes. Branch-free, so that rows vectorise.
 */
CM_FN float cm_shm_step(float pa, float pb, float F, float drop, float h)
{
    float a = pa != pa ? pb : pa, b = pb != pb ? pa : pb;
    float p = a + F * (b - a) - drop;
    float s = ((h >= p) | (p != p)) ? h : p;
    return h != h ? p : s;
}

/* Light reaching a cell of height h under shadow height s: 0 or 1, or
 * fading over `depth` metres below the shadow's edge (penumbra) when
 * depth > 0; NaN where h is nodata. */
CM_FN float cm_shm_lit(float s, float h, float depth)
{
    float under = s - h;
    float lit;
    if (depth <= 0.0f) {
        lit = under > 0.0f ? 0.0f : 1.0f;
    } else {
        float q = under / depth;
        lit = 1.0f - (q < 0.0f ? 0.0f : q > 1.0f ? 1.0f : q);
    }
    return h != h ? NAN : lit;
}

#endif
