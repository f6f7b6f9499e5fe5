/* The exact stretches of a capped (MAX_DISTANCE) sweep that the near field
 * and the lines leave out; see sweep_cap_tail.h. */
#include <math.h>
#include <stdlib.h>

#include "cap_tail_bound.h"
#include "near_field.h"
#include "simd_clones.h"
#include "sweep_cap_tail.h"
#include "terrashade.h"

#if defined(__GNUC__) && defined(__x86_64__)
/* cells_left's first cells, sixteen at a time: those up to the return
 * value, their count in *n. */
TS_AVX512 static int cells_left512(const float *zrow, const float *bound, const float *orow,
                                   int W, int *left, int *n)
{
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    int x = 0, m = 0;
    for (; x + 16 <= W; x += 16) {
        const __m512 z = _mm512_loadu_ps(zrow + x);
        const __mmask16 keep =
            _mm512_cmp_ps_mask(z, z, _CMP_ORD_Q) &
            ~_mm512_cmp_ps_mask(_mm512_loadu_ps(bound + x), _mm512_loadu_ps(orow + x), _CMP_LT_OQ);
        _mm512_storeu_si512(left + m, _mm512_maskz_compress_epi32(
                                          keep, _mm512_add_epi32(iota, _mm512_set1_epi32(x))));
        m += __builtin_popcount(keep);
    }
    *n = m;
    return x;
}
#endif

/* The cells of a row that the row bound leaves (zrow[x] not nodata and
 * not bound[x] < orow[x]: a NaN bound leaves it) into left, in order;
 * their count. Listed without a branch per cell: most are ruled out, in no
 * pattern a branch predicts. left has room for W + 16. */
static int cells_left(const float *zrow, const float *bound, const float *orow, int W, int *left)
{
    int n = 0, x = 0;
#if defined(__GNUC__) && defined(__x86_64__)
    if (ts_cpu_vector_level() == TS_CPU_VECTORS_AVX512)
        x = cells_left512(zrow, bound, orow, W, left, &n);
#endif
    for (; x < W; x++) {
        left[n] = x;
        n += (zrow[x] == zrow[x]) & !(bound[x] < orow[x]);
    }
    return n;
}

/* An upper bound of the slope from cell (k, i) at height h to its ray
 * between whole steps j and j + 1: the highest corner of the patches it
 * crosses there; INFINITY if one is nodata or off the grid (then solve). */
static float between_steps_bound(const ts_line_geom *G, const float *z, int k, int i, float h,
                                 int j, double step, double c)
{
    double va = i - G->t * j, vb = i - G->t * (j + 1);
    double lo = va < vb ? va : vb, hi = va < vb ? vb : va;
    int r0 = (int)floor(lo), r1 = (int)ceil(hi), k0 = k - j - 1;
    if (k0 < 0 || r0 < 0 || r1 > G->V - 1)
        return INFINITY;
    float hmax = -INFINITY;
    const float *p = z + G->origin + (ptrdiff_t)k0 * G->u_stride + (ptrdiff_t)r0 * G->v_stride;
    for (int r = r0; r <= r1; r++, p += G->v_stride) {
        float a = p[0], b = p[G->u_stride];
        if (a != a || b != b)
            return INFINITY;
        hmax = a > hmax ? a : hmax;
        hmax = b > hmax ? b : hmax;
    }
    double dh = (double)hmax - h;
    return (float)(dh / ((dh > 0 ? j : j + 1) * step) - c * j * step);
}

/* Whether ts_ray_exact from s0 stops in its first piece, so returns -inf:
 * that piece's middle lies beyond s0, so behind step 0 where k < s0, and
 * off the rows where v = i - t s (the same rounded operations, monotone
 * in s) is already off at s0. */
static int ray_off_from(const ts_line_geom *G, int k, int i, double s0)
{
    if (k < s0)
        return 1;
    const double t = G->t;
    if (!(fabs(t) > 1e-12))
        return 0;
    const double v = i - t * s0;
    return t > 0 ? v < 0 : v >= G->V - 1;
}

/*
 * The part of a capped ray's last step before the distance ends, solved
 * exactly on each cell's own ray where a bound says it may raise the
 * horizon (a capped horizon is often at the distance itself): the near
 * field covers the first TS_NEAR_STEPS steps, the lines the whole steps
 * beyond. Most cells are ruled out by a row-wide bound (cap_tail_bound.h)
 * before the per-cell bound and the solve.
 */
void ts_cap_tail(const ts_line_geom *G, const ts_grid *grid, double cap, double c, int y,
                 const float *zrow, float *orow, double step)
{
    const int W = grid->width;
    double smax = cap / step, s0 = floor(smax);
    if (!(smax > TS_NEAR_STEPS && s0 < smax))
        return; /* within the near field, or the cap ends on a whole step */
    ts_cap_stencil st;
    ts_cap_stencil_init(&st, G, s0, smax, step, c);
    int xa = W, xb = W;
    /* the row's bounds (and the stencil's scratch), then the cells left */
    float *bound = malloc(2 * (size_t)W * sizeof *bound + ((size_t)W + 16) * sizeof(int));
    int *left = NULL, nleft = W;
    if (bound) {
        ts_cap_stencil_range(&st, G, W, y, &xa, &xb);
        for (int x = 0; x < W; x++)
            bound[x] = NAN; /* no row bound: the per-cell path */
        if (xa < xb)
            ts_cap_stencil_row(&st, zrow, xa, xb, bound, bound + W);
        left = (int *)(bound + 2 * (size_t)W);
        nleft = cells_left(zrow, bound, orow, W, left);
    }
    for (int j = 0; j < nleft; j++) {
        const int x = left ? left[j] : j;
        if (isnan(zrow[x]))
            continue;
        int u = G->x_major ? x : y, i = G->x_major ? y : x;
        int k = (u - G->u_start) * G->u_step;
        float h = zrow[x], best = orow[x], e;
        if (bound && st.exact && bound[x] == bound[x]) {
            /* solved from the row's stencil, ts_ray_exact's bits; the
             * corner bound decides only where it would raise */
            e = ts_cap_stencil_exact(&st, zrow, x);
            if (e > best && between_steps_bound(G, grid->z, k, i, h, (int)s0, step, c) < best)
                continue;
        } else {
            if (ts_cap_stencil_off_grid(&st, G, k, i) || ray_off_from(G, k, i, s0) ||
                between_steps_bound(G, grid->z, k, i, h, (int)s0, step, c) < best)
                continue; /* off the grid: ts_ray_exact's -inf */
            e = ts_ray_exact(G, grid->z, k, i, h, s0, smax, step, c);
        }
        orow[x] = e > best ? e : best;
    }
    free(bound);
}
