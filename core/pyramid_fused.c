/*
 * One level's samples of the level maximum with the level row combined in
 * registers (AVX-512): ts_pyr_combine_rows into w->T, then
 * ts_pyr_level_run reading T back at x + ix and x + ix + 1, in one pass.
 *
 * The level row is combined 16 columns at a time at columns q that are a
 * multiple of 16 (each of its rows' loads within one cache line where the
 * rows start on one), and the samples' two neighbours T[x + ix] and
 * T[x + ix + 1] of 16 cells x come out of two such vectors by a lane
 * permute; so T is neither stored nor read back at an unaligned column,
 * and the cells' own vectors (R, the maxima) stay on their lines. The sums
 * are the same operations in the same order as those two functions (each
 * column's fused multiply-adds, the samples' interpolation and tangent),
 * so the maxima have the same bits.
 */
#include "pyramid_hz.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include "terrashade.h" /* ts_cpu_vector_level: whether the CPU has AVX-512 */

/* The lanes of the 16 columns from q that lie in [lo, hi]. */
TS_AVX512 static inline __mmask16 lanes_within(int q, int lo, int hi)
{
    return ts_first_lanes16(hi - q + 1) & (__mmask16)~ts_first_lanes16(lo - q);
}

/* Columns q..q+15 of row r: where `masked`, only the lanes of `in` (zeros
 * elsewhere), the columns before 0 (only where q < 0) not addressed at all;
 * else all 16, plainly. */
TS_AVX512 static inline __attribute__((always_inline)) __m512
row16(const float *r, int q, __mmask16 in, const int masked)
{
    if (!masked)
        return _mm512_loadu_ps(r + q);
    if (q >= 0)
        return _mm512_maskz_loadu_ps(in, r + q);
    /* `in` is then the lanes from -q on: columns 0.. packed into them */
    return _mm512_maskz_expandloadu_ps(in, r);
}

/* The level row of a sample: its rows, their weights (one set per grid
 * row: two where two grid rows read the same level rows), the row's width
 * and the last column the samples read (sample_cols' t1). */
typedef struct {
    const float *r[4];
    __m512 w[2][4];
    int taps, W, t1;
} level_rows;

/* The level row at columns q..q+15 into s[0] (and s[1] with `two`, the
 * second weights): ts_pyr_combine_rows' sums, the same fused multiply-adds
 * in the same order, each row loaded once for both; `masked` as row16
 * (the columns within the row), else all 16 columns lie within it. */
TS_AVX512 static inline __attribute__((always_inline)) void
combine16(const level_rows *L, int q, const int taps, const int masked, const int two,
          __m512 s[2])
{
    const __mmask16 in = masked ? lanes_within(q, 0, L->W - 1) : 0xFFFF;
    const __m512 v0 = row16(L->r[0], q, in, masked);
    if (taps == 1) {
        s[0] = s[1] = v0;
        return;
    }
    s[0] = _mm512_mul_ps(L->w[0][0], v0);
    if (two)
        s[1] = _mm512_mul_ps(L->w[1][0], v0);
    for (int t = 1; t < taps; t++) {
        const __m512 v = row16(L->r[t], q, in, masked);
        s[0] = _mm512_fmadd_ps(L->w[0][t], v, s[0]);
        if (two)
            s[1] = _mm512_fmadd_ps(L->w[1][t], v, s[1]);
    }
}

/* combine16 where the columns q..q+15 may leave the row, for the run's
 * number of taps (masked loads only where they do). */
TS_AVX512 static inline __attribute__((always_inline)) void
combine16_edge(const level_rows *L, int q, const int two, __m512 s[2])
{
    const int in = q >= 0 && q + 15 <= L->W - 1;
    if (L->taps == 4)
        in ? combine16(L, q, 4, 0, two, s) : combine16(L, q, 4, 1, two, s);
    else if (L->taps == 2)
        in ? combine16(L, q, 2, 0, two, s) : combine16(L, q, 2, 1, two, s);
    else
        in ? combine16(L, q, 1, 0, two, s) : combine16(L, q, 1, 1, two, s);
}

/* Lane i of v in every lane. */
TS_AVX512 static inline __m512 lane_all(__m512 v, int i)
{
    return _mm512_permutexvar_ps(_mm512_set1_epi32(i), v);
}

/* What every block of a grid row's run shares. */
typedef struct {
    __m512i at0, at1; /* lanes of T[x + ix], T[x + ix + 1] in the pair (cur, next) */
    __m512 fx, gx, inv_d, ncd;
    const float *R;
    float *m;
} run_consts;

TS_AVX512 static inline __attribute__((always_inline)) run_consts
run_set(int ix, float fx, const float *R, float inv_d, float cd, float *m)
{
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i at0 = _mm512_add_epi32(lane, _mm512_set1_epi32(ix & 15));
    return (run_consts){at0,
                        _mm512_add_epi32(at0, _mm512_set1_epi32(1)),
                        _mm512_set1_ps(fx),
                        _mm512_set1_ps(1.0f - fx),
                        _mm512_set1_ps(inv_d),
                        _mm512_set1_ps(-cd),
                        R,
                        m};
}

/* The samples of the 16 cells from x (those of `cells`) from the level
 * row's columns q..q+31 in cur, next: the maximum's update. */
TS_AVX512 static inline __attribute__((always_inline)) void
block16(const run_consts *k, __m512 cur, __m512 next, int x, __mmask16 cells, int full)
{
    const __m512 ta = _mm512_permutex2var_ps(cur, k->at0, next);
    const __m512 tb = _mm512_permutex2var_ps(cur, k->at1, next);
    const __m512 h = _mm512_fmadd_ps(k->fx, tb, _mm512_mul_ps(k->gx, ta));
    if (full) {
        const __m512 t = _mm512_fmadd_ps(_mm512_sub_ps(h, _mm512_load_ps(k->R + x)), k->inv_d,
                                         k->ncd);
        _mm512_store_ps(k->m + x, _mm512_max_ps(t, _mm512_load_ps(k->m + x))); /* t > m ? t : m */
        return;
    }
    const __m512 d = _mm512_sub_ps(h, _mm512_maskz_loadu_ps(cells, k->R + x));
    const __m512 t = _mm512_fmadd_ps(d, k->inv_d, k->ncd);
    const __m512 mm = _mm512_maskz_loadu_ps(cells, k->m + x);
    _mm512_mask_storeu_ps(k->m + x, cells, _mm512_max_ps(t, mm));
}

/* The blocks from x (the level row's vector at q in cur) while their
 * cells and the next vector's columns are all in range (x + 15 <= x1,
 * q + 31 <= t1), for a constant number of taps; returns the next x. */
TS_AVX512 static inline __attribute__((always_inline)) int
body_blocks(const level_rows *L, const run_consts *k, __m512 cur[2], int x, int x1, int ix,
            const int taps, const int two)
{
    const int sh = ix & 15;
    __m512 c0 = cur[0], c1 = cur[1];
    int q = x + ix - sh;
    for (; x + 15 <= x1 && q + 31 <= L->t1; x += 16, q += 16) {
        __m512 next[2];
        combine16(L, q + 16, taps, 0, two, next);
        block16(&k[0], c0, next[0], x, 0xFFFF, 1);
        c0 = next[0];
        if (two) {
            block16(&k[1], c1, next[1], x, 0xFFFF, 1);
            c1 = next[1];
        }
    }
    cur[0] = c0, cur[1] = c1;
    return x;
}

/* Columns past t1 of the vector at q (t1 >= q): column t1's value, taken
 * from `from` (lane t1 - p of the vector at p). */
TS_AVX512 static inline __m512 pad_past(__m512 v, int q, int t1, __m512 from, int p)
{
    return _mm512_mask_mov_ps(v, (__mmask16)~ts_first_lanes16(t1 - q + 1),
                              lane_all(from, t1 - p));
}

/* ts_pyr_level_max_rows (and with `two` the second grid row's maxima, k[1],
 * from the same level rows): the blocks of 16 cells from x0's line to x1,
 * the first and the last masked to the run's cells and to the row's
 * columns. */
TS_AVX512 static inline __attribute__((always_inline)) void
level_max_n(const level_rows *L, const run_consts *k, int ix, int x0, int x1, const int two)
{
    const int t1 = L->t1, taps = L->taps, n = 1 + two;
    const int sh = ix & 15; /* x + ix is lane sh of the vector at x + ix - sh */
    int x = x0 & ~15, q = x + ix - sh;
    __m512 cur[2] = {_mm512_setzero_ps(), _mm512_setzero_ps()}, next[2];
    combine16_edge(L, q, two, cur);
    for (int i = 0; q + 15 > t1 && i < n; i++)
        cur[i] = pad_past(cur[i], q, t1, cur[i], q);
    for (; x <= x1; x += 16, q += 16) {
        if (x >= x0 && x + 15 <= x1 && q + 31 <= t1) {
            /* the run's inner blocks: no masks, no pad, the rows' loads
             * and the cells' on their lines where the rows start on one */
            x = taps == 4   ? body_blocks(L, k, cur, x, x1, ix, 4, two)
                : taps == 2 ? body_blocks(L, k, cur, x, x1, ix, 2, two)
                            : body_blocks(L, k, cur, x, x1, ix, 1, two);
            q = x + ix - sh;
            if (x > x1)
                break;
        }
        if (q + 16 <= t1)
            combine16_edge(L, q + 16, two, next);
        else
            next[0] = cur[0], next[1] = cur[1];
        for (int i = 0; q + 31 > t1 && i < n; i++) /* columns past t1: column t1's value */
            next[i] = t1 >= q + 16 ? pad_past(next[i], q + 16, t1, next[i], q + 16)
                                   : pad_past(next[i], q + 16, t1, cur[i], q);
        for (int i = 0; i < n; i++) {
            block16(&k[i], cur[i], next[i], x, lanes_within(x, x0, x1), 0);
            cur[i] = next[i];
        }
    }
}

/* level_max_n for the grid rows g (one, or two with `two`): their weights
 * and run constants. */
TS_AVX512 static inline __attribute__((always_inline)) void
level_max_g(const level_max_row *g, const float *const r[4], int taps, int W, int t1, int ix,
            float fx, int x0, int x1, const int two)
{
    level_rows L = {.r = {r[0], r[1], r[2], r[3]}, .taps = taps, .W = W, .t1 = t1};
    run_consts k[2];
    for (int i = 0; i <= two; i++) {
        for (int t = 0; t < 4; t++)
            L.w[i][t] = _mm512_set1_ps(g[i].wt[t]);
        k[i] = run_set(ix, fx, g[i].R, g[i].inv_d, g[i].cd, g[i].m);
    }
    level_max_n(&L, k, ix, x0, x1, two);
}

/* level_max_g for one and for two rows, each its own constant-folded copy */
TS_AVX512 static void level_max1(const level_max_row *g, const float *const r[4], int taps,
                                 int W, int t1, int ix, float fx, int x0, int x1)
{
    level_max_g(g, r, taps, W, t1, ix, fx, x0, x1, 0);
}

TS_AVX512 static void level_max2(const level_max_row *g, const float *const r[4], int taps,
                                 int W, int t1, int ix, float fx, int x0, int x1)
{
    level_max_g(g, r, taps, W, t1, ix, fx, x0, x1, 1);
}

int ts_pyr_level_max_rows(const level_max_row *g, int rows, const float *const r[4], int taps,
                          int W, int t1, int ix, float fx, int x0, int x1)
{
    if (ts_cpu_vector_level() != TS_CPU_VECTORS_AVX512)
        return 0;
    (rows == 2 ? level_max2 : level_max1)(g, r, taps, W, t1, ix, fx, x0, x1);
    return 1;
}
#else
int ts_pyr_level_max_rows(const level_max_row *g, int rows, const float *const r[4], int taps,
                          int W, int t1, int ix, float fx, int x0, int x1)
{
    (void)g, (void)rows, (void)r, (void)taps, (void)W, (void)t1, (void)ix, (void)fx, (void)x0;
    (void)x1;
    return 0;
}
#endif
