/*
 * The inner loops of the date-range products (sun_range.c): every sun
 * position of one azimuth bucket evaluated on every cell from the two
 * horizon planes around it. Cells in blocks, sun positions inside, so that
 * the per-cell loops vectorise and the accumulators stay in L1.
 */
#include <math.h>
#include <string.h>

#include "cellmath/cm_sun.h"
#include "simd_clones.h"
#include "sun_range_internal.h"

#define BLOCK 256

/* The horizon toward the sun of cell j of a block, raised to the floor;
 * NaN stays NaN (nodata). */
static inline float horizon_at(const float *h0, const float *dh, const float *fl, float w,
                               int j)
{
    float h = h0[j] + w * dh[j];
    return h > fl[j] ? h : fl[j];
}

TS_SIMD_CLONES
static void eval_range(void *ctx, int worker, long begin, long end)
{
    (void)worker;
    const ts_range_bucket *B = ctx;
    const float inv_r = (float)(1.0 / TS_SUN_RADIUS_DEG), rad = (float)TS_SUN_RADIUS_DEG;
    float h0[BLOCK], dh[BLOCK], fl[BLOCK], fr[BLOCK], cnx[BLOCK], cny[BLOCK], cnz[BLOCK];
    int ix[BLOCK];
    double acc[BLOCK];
    for (long i0 = begin; i0 < end; i0 += BLOCK) {
        int n = end - i0 < BLOCK ? (int)(end - i0) : BLOCK;
        for (int j = 0; j < n; j++) {
            h0[j] = B->pa[i0 + j];
            dh[j] = B->pb[i0 + j] - h0[j];
            fl[j] = B->floor ? B->floor[i0 + j] : -90.0f;
            acc[j] = 0.0;
        }
        if (B->mode == TS_RANGE_BEAM)
            for (int j = 0; j < n; j++) {
                cnx[j] = B->nx[i0 + j];
                cny[j] = B->ny[i0 + j];
                cnz[j] = B->nz[i0 + j];
                /* position of the cell's pressure factor in the tables */
                float u = (B->pc[i0 + j] - B->pc_min) * B->pc_inv;
                u = u > 0.0f ? u : 0.0f; /* NaN (nodata) -> 0 */
                u = u < (float)(TS_RANGE_TABLE - 1) ? u : (float)(TS_RANGE_TABLE - 1);
                int k = (int)u;
                k = k < TS_RANGE_TABLE - 2 ? k : TS_RANGE_TABLE - 2;
                ix[j] = k;
                fr[j] = u - (float)k;
            }
        for (int s = 0; s < B->count; s++) {
            const ts_range_sun *p = &B->sun[s];
            const float w = p->w, e = (float)p->el, hrs = (float)p->hours;
            if (B->mode == TS_RANGE_VISIBLE) {
                for (int j = 0; j < n; j++) {
                    float h = horizon_at(h0, dh, fl, w, j);
                    acc[j] += e - h > -rad ? hrs : 0.0f;
                }
            } else if (B->mode == TS_RANGE_FRACTION) {
                for (int j = 0; j < n; j++) {
                    float h = horizon_at(h0, dh, fl, w, j);
                    acc[j] += ts_disk_fraction_u((e - h) * inv_r) * hrs;
                }
            } else {
                const float *tab = p->table;
                const float lx = p->lx, ly = p->ly, lz = p->lz, gh = (float)p->g0_hours;
                for (int j = 0; j < n; j++) {
                    float h = horizon_at(h0, dh, fl, w, j);
                    float v = ts_disk_fraction_u((e - h) * inv_r);
                    float c = cnx[j] * lx + cny[j] * ly + cnz[j] * lz;
                    float t = tab[ix[j]] + fr[j] * (tab[ix[j] + 1] - tab[ix[j]]);
                    float b = gh * t * (c > 0.0f ? c : 0.0f) * v;
                    acc[j] += b == b ? b : 0.0f; /* nodata: NaN -> 0 */
                }
            }
        }
        for (int j = 0; j < n; j++)
            B->acc[i0 + j] += acc[j];
    }
}

ts_status ts_range_evaluate(const ts_range_bucket *b, int threads, ts_error *err)
{
    if (b->count < 1)
        return TS_OK;
    long cells = (long)b->cells;
    return ts_parallel_for_ranges(ts_thread_count(threads, (cells >> 14) + 1), cells,
                                  TS_CELLS_GRAIN, eval_range, (void *)b, err);
}
