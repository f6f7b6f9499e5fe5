/* Vectorised passes of a lockstep block's step; see lane_passes.h. */
#include <limits.h>
#include <math.h>

#include "cellmath/cm_near_field.h"
#include "lane_passes.h"
#include "simd_clones.h"

/* ts_lane_sample with the lines' cells vs elements apart: a constant 1
 * where they are neighbours in memory, so that the loops vectorise. */
static inline __attribute__((always_inline)) void
sample_run(const float *restrict zk, ptrdiff_t vs, float F, int j0, int j1, int jn,
           float *restrict hc, float *restrict hn, float *restrict hs)
{
    for (int j = j0; j <= j1; j++)
        hc[j] = zk[j * vs];
    if (F == 0.0f) {
        for (int j = j0; j <= j1; j++) {
            hn[j] = (float)NAN;
            hs[j] = hc[j];
        }
        return;
    }
    for (int j = j0; j <= jn; j++) {
        hn[j] = zk[(j + 1) * vs];
        hs[j] = hc[j] + F * (hn[j] - hc[j]);
    }
    for (int j = jn + 1; j <= j1; j++)
        hn[j] = hs[j] = (float)NAN;
}

TS_SIMD_CLONES
void ts_lane_sample(const ts_line_geom *G, const float *z, int k, int i0, int j0, int j1,
                    float *hc, float *hn, float *hs)
{
    const float F = G->fr[k];
    const ptrdiff_t vs = G->v_stride;
    const float *zk = z + G->origin + (ptrdiff_t)k * G->u_stride + (ptrdiff_t)i0 * vs;
    /* Every line has a next cell but one on the grid's last row. */
    int jn = G->V - 2 - i0 < j1 ? G->V - 2 - i0 : j1;
    if (vs == 1)
        sample_run(zk, 1, F, j0, j1, jn, hc, hn, hs);
    else
        sample_run(zk, vs, F, j0, j1, jn, hc, hn, hs);
}

/* The grid's layout as the direction sees it. */
typedef struct {
    ptrdiff_t origin, u_stride, v_stride;
    int V;
} ray_view;

/* Slope from cell (k, i) at height h to its own ray at the occluder of
 * step kc (< 0: none; else kc < k), dd metres away, as cm_ray_slope_at
 * with the ray's offset and fraction from ray_o and ray_f; -inf where the
 * occluder is none or within the near field, the ray is off the grid or
 * touches nodata. Branch-free, every load from a valid element (masks,
 * not selects, so that gcc gathers), so that the loop over cells
 * vectorises. Element offsets in 32 bits unless `wide` (gathers of 32-bit
 * offsets are the ones gcc vectorises). */
static inline __attribute__((always_inline)) float
ray_at(ray_view R, int wide, const int *restrict ray_o, const float *restrict ray_f,
       const float *restrict z, float cf, int k, int i, float h, int kc, float dd)
{
    const int dk = k - kc;
    int ok = (kc >= 0) & (dk > TS_NEAR_STEPS) & (dd > 0.0f);
    const int dks = dk & -ok;
    const int r0 = i + ray_o[dks];
    const float f = ray_f[dks];
    ok &= (r0 >= 0) & (r0 <= R.V - 1) & ((f <= 0.0f) | (r0 + 1 <= R.V - 1));
    const int two = ok & (f > 0.0f);
    float a, b;
    if (wide) {
        ptrdiff_t ia = (R.origin + (ptrdiff_t)kc * R.u_stride + (ptrdiff_t)r0 * R.v_stride) &
                       -(ptrdiff_t)ok;
        a = z[ia];
        b = z[ia + (R.v_stride & -(ptrdiff_t)two)];
    } else {
        /* unsigned: no overflow where !ok leaves the offset meaningless */
        unsigned ia = ((unsigned)R.origin + (unsigned)kc * (unsigned)R.u_stride +
                       (unsigned)r0 * (unsigned)R.v_stride) & -(unsigned)ok;
        a = z[(int)ia];
        b = z[(int)(ia + ((unsigned)R.v_stride & -(unsigned)two))];
    }
    const float hz = a + f * (b - a);
    const float s = (hz - h) / dd - cf * dd;
    return ok & (hz == hz) ? s : -INFINITY;
}

/* ts_lane_far_field's loop, with 32- or 64-bit offsets: every array its
 * own, as restrict parameters of the function that holds the loop (what
 * the vectoriser needs to gather without alias checks). */
#define FAR_LOOP(WIDE)                                                                         \
    for (int j = j0; j <= j1; j++) {                                                           \
        const float h = hc[j];                                                                 \
        const int kl = lo_k[j], kh = hi_k[j] | -(hi_k[j] == kl); /* -1: the same step */      \
        float best = -INFINITY;                                                                \
        float s = ray_at(R, WIDE, ray_o, ray_f, z, cf, k, i0 + j, h, kl, lo_dd[j]);            \
        best = s > best ? s : best;                                                            \
        s = ray_at(R, WIDE, ray_o, ray_f, z, cf, k, i0 + j, h, kh, hi_dd[j]);                  \
        best = s > best ? s : best;                                                            \
        slope[j] = h != h ? (float)NAN : best;                                                 \
    }

#define FAR_PARAMS                                                                             \
    ray_view R, const int *restrict ray_o, const float *restrict ray_f,                        \
        const float *restrict z, float cf, int k, int i0, int j0, int j1,                      \
        const float *restrict hc, const int *restrict lo_k, const float *restrict lo_dd,       \
        const int *restrict hi_k, const float *restrict hi_dd, float *restrict slope

TS_SIMD_CLONES
static void far_run32(FAR_PARAMS)
{
    FAR_LOOP(0)
}

TS_SIMD_CLONES
static void far_run64(FAR_PARAMS)
{
    FAR_LOOP(1)
}

void ts_lane_far_field(const ts_line_geom *G, const float *z, float cf, int k, int i0, int j0,
                       int j1, const float *hc, const ts_lane_occluders *occ, float *slope)
{
    const ray_view R = {G->origin, G->u_stride, G->v_stride, G->V};
    /* Every element the ray reads lies within U x V cells of the grid. */
    const ptrdiff_t span = (ptrdiff_t)(G->U - 1) * (G->u_stride < 0 ? -G->u_stride : G->u_stride) +
                           (ptrdiff_t)(G->V - 1) * G->v_stride + 1;
    (span > INT_MAX ? far_run64 : far_run32)(R, G->ray_o, G->ray_f, z, cf, k, i0, j0, j1, hc,
                                             occ->lo_k, occ->lo_dd, occ->hi_k, occ->hi_dd,
                                             slope);
}
