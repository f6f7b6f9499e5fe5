/* The pyramid of ts_pyramid_build as core/pyramid_horizon.c reads it. */
#ifndef TS_PYRAMID_INTERNAL_H
#define TS_PYRAMID_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "terrashade.h"

/*
 * Level j's samples sit at DEM coordinate (i + 0.5) s_j - 0.5 (sample
 * centres, as mipmaps), so a DEM coordinate x is level coordinate
 * (x + 0.5) / s_j - 0.5. Each level row is kept reconstructed along x at
 * every DEM column ("hu": the horizontal cubic B-spline already applied);
 * reading the level at a row position applies the vertical one. Level 0
 * is the DEM itself, read bilinearly.
 */
typedef struct {
    double spacing; /* s_j, DEM cells */
    int rows;       /* rows of the level */
    float *hu;      /* rows x width; NULL for level 0 (the DEM) */
} ts_pyr_level;

struct ts_pyramid {
    const ts_grid *grid;
    ts_pyramid_opts opts;
    int levels;
    ts_pyr_level *level;
    /* the pairs of columns 0, 1 and W - 2, W - 1 (0, 0 and 0, 0 where
     * W = 1), interleaved by row, 2 H floats each: the rays that leave
     * through a side end on its outer column (x-major) or between its two
     * (y-major), pyramid_drop.c; a column read down the DEM's rows misses
     * the cache (and the TLB) at every row */
    float *pair[2];
};

/* n bytes on a 64-byte boundary (a cache line, an AVX-512 vector): a
 * vector load or store across two lines costs about two; free() frees. */
static inline void *ts_pyr_alloc(size_t n)
{
    return aligned_alloc(64, (n + 63) / 64 * 64);
}

/* Row r of level j, `width` floats (a DEM row for level 0). */
static inline const float *ts_pyr_row(const ts_pyramid *p, int j, int r)
{
    return j == 0 ? p->grid->z + (ptrdiff_t)r * p->grid->stride
                  : p->level[j].hu + (size_t)r * p->grid->width;
}

/* Uniform cubic B-spline weights at u in [0, 1) (S&N section 4). */
static inline void ts_pyr_bspline(double u, double w[4])
{
    double u2 = u * u, u3 = u2 * u;
    w[0] = (1 - u) * (1 - u) * (1 - u) / 6;
    w[1] = (3 * u3 - 6 * u2 + 4) / 6;
    w[2] = (-3 * u3 + 3 * u2 + 3 * u + 1) / 6;
    w[3] = u3 / 6;
}

/* The taps reading position `lambda` (level coordinates) on an axis of n
 * samples, clamped at the ends: cubic B-spline (4 taps) or, for `linear`,
 * the two neighbours with the second weight 0 when it is not needed.
 * Returns the number of taps. */
static inline int ts_pyr_taps(double lambda, int n, int linear, int idx[4], double w[4])
{
    double f = floor(lambda);
    double u = lambda - f;
    int i = (int)f;
    if (linear) {
        int a = i < 0 ? 0 : i > n - 1 ? n - 1 : i, b = i + 1 > n - 1 ? n - 1 : i + 1;
        b = b < 0 ? 0 : b;
        idx[0] = a, w[0] = 1 - u;
        idx[1] = b, w[1] = u;
        return u > 0 && i >= 0 && i + 1 <= n - 1 ? 2 : (w[0] = 1, 1);
    }
    ts_pyr_bspline(u, w);
    for (int t = 0; t < 4; t++) {
        int k = i - 1 + t;
        idx[t] = k < 0 ? 0 : k > n - 1 ? n - 1 : k;
    }
    return 4;
}

#endif
