/*
 * The shadow map's rasteriser on the CPU. A triangle of the DEM's mesh seen
 * from a low light is a few texels wide and tens of rows tall, so its box's
 * texel centres are taken row after row, laid end to end, sixteen (AVX-512)
 * or eight (AVX2) to a vector: each lane does ts_sm_tri_covers' and
 * ts_sm_tri_key's float operations in their order, so every key has the
 * same bits as the portable loop's (ts_sm_triangle), which other CPUs run.
 * That loop took ~8 ns a texel of the boxes (27 s of 58 at 135/10 on the
 * 4096^2 fractal, one thread: 3.4 G texels, 1.2 G of them covered).
 */
#include <math.h>

#include "cellmath/cm_shadowmap.h"
#include "shadowmap_raster.h"
#include "simd_clones.h"
#include "terrashade.h"

/* Where the first vector's lanes fall in a box of na texels a row, for
 * vectors of 16 and of 8 lanes: lane l at column l % na, row l / na where
 * na is less than the lanes, else at column l (index min(na, lanes)). */
typedef struct {
    int col16[17][16], row16[17][16], col8[9][8], row8[9][8];
} lane_start;

static void lane_start_make(lane_start *s)
{
    for (int na = 1; na <= 16; na++)
        for (int l = 0; l < 16; l++) {
            s->col16[na][l] = na < 16 ? l % na : l;
            s->row16[na][l] = na < 16 ? l / na : 0;
            if (na <= 8 && l < 8) {
                s->col8[na][l] = na < 8 ? l % na : l;
                s->row8[na][l] = na < 8 ? l / na : 0;
            }
        }
}

#if defined(__GNUC__) && defined(__x86_64__)
TS_AVX512 static void raster512(const ts_sm_tri *t, const lane_start *s, int *map, int mw)
{
    const int na = t->a1 - t->a0 + 1, k = na < 16 ? na : 16;
    const long total = (long)na * (t->b1 - t->b0 + 1);
    __m512i col = _mm512_loadu_si512(s->col16[k]), row = _mm512_loadu_si512(s->row16[k]);
    const __m512i dc = _mm512_set1_epi32(na < 16 ? 16 % na : 16),
                  dr = _mm512_set1_epi32(na < 16 ? 16 / na : 0), nav = _mm512_set1_epi32(na),
                  one = _mm512_set1_epi32(1), mwv = _mm512_set1_epi32(mw),
                  a0 = _mm512_set1_epi32(t->a0), b0 = _mm512_set1_epi32(t->b0),
                  mag = _mm512_set1_epi32(0x7fffffff);
    const __m512 u0 = _mm512_set1_ps(t->u0), v0 = _mm512_set1_ps(t->v0),
                 u1 = _mm512_set1_ps(t->u1), v1 = _mm512_set1_ps(t->v1),
                 u2 = _mm512_set1_ps(t->u2), v2 = _mm512_set1_ps(t->v2),
                 du10 = _mm512_set1_ps(t->u1 - t->u0), dv10 = _mm512_set1_ps(t->v1 - t->v0),
                 du21 = _mm512_set1_ps(t->u2 - t->u1), dv21 = _mm512_set1_ps(t->v2 - t->v1),
                 du02 = _mm512_set1_ps(t->u0 - t->u2), dv02 = _mm512_set1_ps(t->v0 - t->v2),
                 sg = _mm512_set1_ps(t->sg), d0 = _mm512_set1_ps(t->d0),
                 gu = _mm512_set1_ps(t->gu), gv = _mm512_set1_ps(t->gv),
                 off = _mm512_set1_ps(t->off), zero = _mm512_setzero_ps();
    int *base = map + (long)t->b0 * mw + t->a0;
    for (long p = 0; p < total; p += 16) {
        const __mmask16 valid = ts_first_lanes16(total - p < 16 ? (int)(total - p) : 16);
        const __m512 fa = _mm512_cvtepi32_ps(_mm512_add_epi32(a0, col));
        const __m512 fb = _mm512_cvtepi32_ps(_mm512_add_epi32(b0, row));
        const __m512 ua = _mm512_sub_ps(fa, u0);
        const __m512 e0 = _mm512_mul_ps(
            _mm512_sub_ps(_mm512_mul_ps(du10, _mm512_sub_ps(fb, v0)), _mm512_mul_ps(dv10, ua)),
            sg);
        const __m512 e1 = _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(du21, _mm512_sub_ps(fb, v1)),
                                                      _mm512_mul_ps(dv21, _mm512_sub_ps(fa, u1))),
                                        sg);
        const __m512 e2 = _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(du02, _mm512_sub_ps(fb, v2)),
                                                      _mm512_mul_ps(dv02, _mm512_sub_ps(fa, u2))),
                                        sg);
        /* !(e < 0): NaN counts as inside, as in ts_sm_tri_covers */
        __mmask16 in = _mm512_mask_cmp_ps_mask(valid, e0, zero, _CMP_NLT_UQ);
        in = _mm512_mask_cmp_ps_mask(in, e1, zero, _CMP_NLT_UQ);
        in = _mm512_mask_cmp_ps_mask(in, e2, zero, _CMP_NLT_UQ);
        if (in) {
            const __m512 d = _mm512_sub_ps(
                _mm512_add_ps(_mm512_add_ps(d0, _mm512_mul_ps(gu, ua)),
                              _mm512_mul_ps(gv, _mm512_sub_ps(fb, v0))),
                off);
            const __m512i bits = _mm512_castps_si512(d);
            const __m512i key =
                _mm512_xor_si512(bits, _mm512_and_si512(_mm512_srai_epi32(bits, 31), mag));
            /* the lanes' texels, distinct within a triangle; lanes out of
             * the box read the box's first texel */
            const __m512i at =
                _mm512_maskz_add_epi32(valid, _mm512_mullo_epi32(row, mwv), col);
            const __m512i old = _mm512_mask_i32gather_epi32(key, in, at, base, 4);
            _mm512_mask_i32scatter_epi32(base, in, at, _mm512_max_epi32(old, key), 4);
        }
        col = _mm512_add_epi32(col, dc);
        row = _mm512_add_epi32(row, dr);
        const __mmask16 wrap = _mm512_cmpge_epi32_mask(col, nav);
        col = _mm512_mask_sub_epi32(col, wrap, col, nav);
        row = _mm512_mask_add_epi32(row, wrap, row, one);
    }
}

#define AVX2 __attribute__((target("avx2")))

/* raster512 eight lanes at a time; the covered texels are kept one by one
 * (AVX2 has no scatter). */
AVX2 static void raster_avx2(const ts_sm_tri *t, const lane_start *s, int *map, int mw)
{
    const int na = t->a1 - t->a0 + 1, k = na < 8 ? na : 8;
    const long total = (long)na * (t->b1 - t->b0 + 1);
    int cs[8], rs[8], ks[8];
    __m256i col = _mm256_loadu_si256((const __m256i *)s->col8[k]),
            row = _mm256_loadu_si256((const __m256i *)s->row8[k]);
    const __m256i dc = _mm256_set1_epi32(na < 8 ? 8 % na : 8),
                  dr = _mm256_set1_epi32(na < 8 ? 8 / na : 0), nam1 = _mm256_set1_epi32(na - 1),
                  nav = _mm256_set1_epi32(na), one = _mm256_set1_epi32(1),
                  a0 = _mm256_set1_epi32(t->a0), b0 = _mm256_set1_epi32(t->b0),
                  mag = _mm256_set1_epi32(0x7fffffff);
    const __m256 u0 = _mm256_set1_ps(t->u0), v0 = _mm256_set1_ps(t->v0),
                 u1 = _mm256_set1_ps(t->u1), v1 = _mm256_set1_ps(t->v1),
                 u2 = _mm256_set1_ps(t->u2), v2 = _mm256_set1_ps(t->v2),
                 du10 = _mm256_set1_ps(t->u1 - t->u0), dv10 = _mm256_set1_ps(t->v1 - t->v0),
                 du21 = _mm256_set1_ps(t->u2 - t->u1), dv21 = _mm256_set1_ps(t->v2 - t->v1),
                 du02 = _mm256_set1_ps(t->u0 - t->u2), dv02 = _mm256_set1_ps(t->v0 - t->v2),
                 sg = _mm256_set1_ps(t->sg), d0 = _mm256_set1_ps(t->d0),
                 gu = _mm256_set1_ps(t->gu), gv = _mm256_set1_ps(t->gv),
                 off = _mm256_set1_ps(t->off), zero = _mm256_setzero_ps();
    int *base = map + (long)t->b0 * mw + t->a0;
    for (long p = 0; p < total; p += 8) {
        const int n = total - p < 8 ? (int)(total - p) : 8;
        const __m256 fa = _mm256_cvtepi32_ps(_mm256_add_epi32(a0, col));
        const __m256 fb = _mm256_cvtepi32_ps(_mm256_add_epi32(b0, row));
        const __m256 ua = _mm256_sub_ps(fa, u0);
        const __m256 e0 = _mm256_mul_ps(
            _mm256_sub_ps(_mm256_mul_ps(du10, _mm256_sub_ps(fb, v0)), _mm256_mul_ps(dv10, ua)),
            sg);
        const __m256 e1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(du21, _mm256_sub_ps(fb, v1)),
                                                      _mm256_mul_ps(dv21, _mm256_sub_ps(fa, u1))),
                                        sg);
        const __m256 e2 = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(du02, _mm256_sub_ps(fb, v2)),
                                                      _mm256_mul_ps(dv02, _mm256_sub_ps(fa, u2))),
                                        sg);
        const __m256 out = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(e0, zero, _CMP_LT_OQ),
                                                     _mm256_cmp_ps(e1, zero, _CMP_LT_OQ)),
                                        _mm256_cmp_ps(e2, zero, _CMP_LT_OQ));
        unsigned in = ~(unsigned)_mm256_movemask_ps(out) & ((1u << n) - 1);
        if (in) {
            const __m256 d = _mm256_sub_ps(
                _mm256_add_ps(_mm256_add_ps(d0, _mm256_mul_ps(gu, ua)),
                              _mm256_mul_ps(gv, _mm256_sub_ps(fb, v0))),
                off);
            const __m256i bits = _mm256_castps_si256(d);
            _mm256_storeu_si256((__m256i *)ks, _mm256_xor_si256(bits, _mm256_and_si256(
                                                                          _mm256_srai_epi32(bits, 31), mag)));
            _mm256_storeu_si256((__m256i *)cs, col);
            _mm256_storeu_si256((__m256i *)rs, row);
            for (; in; in &= in - 1) {
                const int l = __builtin_ctz(in);
                int *m = base + (long)rs[l] * mw + cs[l];
                *m = *m < ks[l] ? ks[l] : *m;
            }
        }
        col = _mm256_add_epi32(col, dc);
        row = _mm256_add_epi32(row, dr);
        const __m256i wrap = _mm256_cmpgt_epi32(col, nam1);
        col = _mm256_sub_epi32(col, _mm256_and_si256(wrap, nav));
        row = _mm256_add_epi32(row, _mm256_and_si256(wrap, one));
    }
}
#define HAVE_RASTER_X86 1
#else
#define HAVE_RASTER_X86 0
#endif

void ts_sm_seg_bounds(const float *pv, int W, int y0, int y1, float *lo, float *hi)
{
    const int segs = TS_SM_SEGS(W);
    for (int y = y0; y < y1; y++)
        for (int s = 0; s < segs; s++) {
            const int xe = (s + 1) * TS_SM_SEG < W - 1 ? (s + 1) * TS_SM_SEG : W - 1;
            float a = NAN, b = NAN;
            for (int x = s * TS_SM_SEG; x <= xe; x++) /* the quads' vertex columns */
                for (int r = 0; r < 2; r++) {
                    const float v = pv[(long)(y + r) * W + x];
                    a = fminf(a, v);
                    b = fmaxf(b, v);
                }
            lo[(long)y * segs + s] = a;
            hi[(long)y * segs + s] = b;
        }
}

void ts_sm_render_band(const float *P, int *map, int mw, int vlo, int vhi, const float *pu,
                       const float *pv, const float *pd, int W, int H)
{
    ts_sm_render_band_segs(P, map, mw, vlo, vhi, pu, pv, pd, W, H, NULL, NULL);
}

void ts_sm_render_band_segs(const float *P, int *map, int mw, int vlo, int vhi,
                            const float *pu, const float *pv, const float *pd, int W, int H,
                            const float *slo, const float *shi)
{
    lane_start s;
    lane_start_make(&s);
    const int level = HAVE_RASTER_X86 ? ts_cpu_vector_level() : TS_CPU_VECTORS_NONE;
    const int segs = TS_SM_SEGS(W);
    for (int y = 0; y + 1 < H; y++)
        for (int x = 0; x + 1 < W; x++) {
            if (slo && x % TS_SM_SEG == 0) {
                /* the segment's bounds, the quads' own test: NaN bounds are in */
                const long k = (long)y * segs + x / TS_SM_SEG;
                if (shi[k] < (float)vlo - 1.0f || slo[k] > (float)vhi) {
                    x += TS_SM_SEG - 1;
                    continue;
                }
            }
            const long i = (long)y * W + x, c[4] = {i, i + 1, i + W + 1, i + W};
            float lo = fminf(fminf(pv[c[0]], pv[c[1]]), fminf(pv[c[2]], pv[c[3]]));
            float hi = fmaxf(fmaxf(pv[c[0]], pv[c[1]]), fmaxf(pv[c[2]], pv[c[3]]));
            if (hi < (float)vlo - 1.0f || lo > (float)vhi) /* NaN: in, then skipped */
                continue;
            /* the quad's two triangles, as ts_sm_quad: 00-10-11, 00-11-01 */
            for (int k = 0; k < 2; k++) {
                const long p = c[1 + k], q = c[2 + k];
                ts_sm_tri t;
                if (!ts_sm_tri_setup(P, mw, vlo, vhi, pu[i], pv[i], pd[i], pu[p], pv[p], pd[p],
                                     pu[q], pv[q], pd[q], &t))
                    continue;
#if HAVE_RASTER_X86
                if (level == TS_CPU_VECTORS_AVX512) {
                    raster512(&t, &s, map, mw);
                    continue;
                }
                if (level == TS_CPU_VECTORS_AVX2) {
                    raster_avx2(&t, &s, map, mw);
                    continue;
                }
#endif
                for (int b = t.b0; b <= t.b1; b++)
                    for (int a = t.a0; a <= t.a1; a++)
                        if (ts_sm_tri_covers(&t, (float)a, (float)b)) {
                            int key = ts_sm_tri_key(&t, (float)a, (float)b), *m;
                            m = &map[(long)b * mw + a];
                            *m = *m < key ? key : *m;
                        }
            }
        }
}
