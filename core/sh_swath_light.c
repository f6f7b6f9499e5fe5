/*
 * A swath's light in one pass over the cells (ts_sh_swath_light): each
 * cell's visibility summed from its wedges, then the triple product with the
 * light and the clamped cosine around its normal (shade) and the double
 * product with the light (share).
 *
 * The per-cell work is arranged for 16-float vectors (one AVX-512 register):
 * a wedge is a bilinear read of 16 floats from the table, and its rotation
 * about z, out[k] = v[k] p[k] + v[perm k] q[k], is summed as two
 * accumulators, a1 += v p and a2 += v q' with q'[j] = q[perm j] (perm is its
 * own inverse), so that the permutation is applied once per cell
 * (v = a1 + a2[perm]) instead of once per wedge. The light's product matrix
 * is folded with the clamped cosine's zonal factors once per run, and the
 * basis at the normal is evaluated in float. Same sums as
 * ts_sh_visibility + ts_sh_shade up to float rounding.
 */
#include <math.h>
#include <stdlib.h>

#include "parallel.h"
#include "sh_internal.h"
#include "status_internal.h"

#define N TS_SH_COEFFS

/* perm of every rotation about z: m -> -m within each band
 * (ts_sh_rotation_set: perm[k] = l (l + 1) - m). */
static const int BAND_MIRROR[N] = {0, 3, 2, 1, 8, 7, 6, 5, 4, 15, 14, 13, 12, 11, 10, 9};

/* One wedge's rotation in the two-accumulator form. */
typedef struct {
    float p[N], q_mirrored[N];
} slot_rotation;

typedef struct {
    const ts_grid *g;
    const ts_sh_wedges *w;
    const float *const *planes;
    slot_rotation *rot; /* n + 1: wedge k ends at sample k; [0] rise or closing; [n] fall */
    float mh[N][N];     /* product matrix with the clamped cosine's zonal factors */
    float l[N];
    const float *nx, *ny, *nz;
    float scale_shade, scale_share;
    float *shade, *share;
} swath_ctx;

static void slot_rotation_set(slot_rotation *s, double az_start)
{
    ts_sh_rotation r;
    ts_sh_rotation_set(&r, az_start);
    for (int k = 0; k < N; k++) {
        s->p[k] = r.p[k];
        s->q_mirrored[k] = r.q[BAND_MIRROR[k]];
    }
}

static inline float clamp_node(float w)
{
    const float scale = (TS_SH_WEDGE_STEPS - 1) / 90.0f;
    return (w < 0 ? 0 : w > 90 ? 90 : w) * scale;
}

/* a1 += v p, a2 += v q' for the wedge v read bilinearly from the interior
 * table at horizons (wa, wb). */
static inline void add_interior(const float *restrict table, float wa, float wb,
                                const slot_rotation *restrict r, float *restrict a1,
                                float *restrict a2)
{
    const int S = TS_SH_WEDGE_STEPS;
    const float ta = clamp_node(wa), tb = clamp_node(wb);
    int ia = (int)ta, ib = (int)tb;
    ia = ia > S - 2 ? S - 2 : ia;
    ib = ib > S - 2 ? S - 2 : ib;
    const float fa = ta - (float)ia, fb = tb - (float)ib;
    const float *t00 = table + ((size_t)ia * S + ib) * N, *t01 = t00 + N;
    const float *t10 = t00 + (size_t)S * N, *t11 = t10 + N;
    const float w00 = (1 - fa) * (1 - fb), w01 = (1 - fa) * fb, w10 = fa * (1 - fb),
                w11 = fa * fb;
    for (int k = 0; k < N; k++) {
        float v = w00 * t00[k] + w01 * t01[k] + w10 * t10[k] + w11 * t11[k];
        a1[k] += v * r->p[k];
        a2[k] += v * r->q_mirrored[k];
    }
}

/* The same for a boundary wedge of the 1D table (rise or fall) at w. */
static inline void add_boundary(const float *restrict table, float w,
                                const slot_rotation *restrict r, float *restrict a1,
                                float *restrict a2)
{
    const float t = clamp_node(w);
    int i = (int)t;
    i = i > TS_SH_WEDGE_STEPS - 2 ? TS_SH_WEDGE_STEPS - 2 : i;
    const float f = t - (float)i, *t0 = table + (size_t)i * N;
    for (int k = 0; k < N; k++) {
        float v = (1 - f) * t0[k] + f * t0[k + N];
        a1[k] += v * r->p[k];
        a2[k] += v * r->q_mirrored[k];
    }
}



/* Cells c0..c1 (cloned for wider vectors where the CPU has them). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
static void swath_cells(const swath_ctx *C, size_t c0, size_t c1)
{
    const ts_sh_wedges *w = C->w;
    const float *const *P = C->planes;
    const int n = w->swath.n, complete = w->swath.complete;
    for (size_t c = c0; c < c1; c++) {
        int nodata = 0;
        for (int k = 0; k < n; k++)
            nodata |= P[k][c] != P[k][c];
        if (nodata) { /* a NaN horizon (nodata) makes the cell NaN */
            if (C->share)
                C->share[c] = NAN;
            if (C->shade)
                C->shade[c] = NAN;
            continue;
        }
        float a1[N] = {0}, a2[N] = {0}, v[N];
        for (int k = 1; k < n; k++)
            add_interior(w->interior, P[k][c], P[k - 1][c], &C->rot[k], a1, a2);
        if (complete) {
            add_interior(w->interior, P[0][c], P[n - 1][c], &C->rot[0], a1, a2);
        } else {
            add_boundary(w->rise, P[0][c], &C->rot[0], a1, a2);
            add_boundary(w->fall, P[n - 1][c], &C->rot[n], a1, a2);
        }
        for (int k = 0; k < N; k++)
            v[k] = a1[k] + a2[BAND_MIRROR[k]];
        if (C->share) {
            float p[N];
            for (int k = 0; k < N; k++)
                p[k] = C->l[k] * v[k];
            float t = ts_sh_sum16(p) * C->scale_share;
            C->share[c] = t < 0 ? 0 : t > 1 ? 1 : t;
        }
        if (C->shade) {
            float yn[N];
            TS_SH_BASIS(float, C->nx[c], C->ny[c], C->nz[c], yn);
            float t = ts_sh_triple_folded(C->mh, v, yn) * C->scale_shade;
            C->shade[c] = t == t ? (t < 0 ? 0 : t) : NAN; /* NaN normal: NaN */
        }
    }
}

static void swath_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const swath_ctx *C = ctx;
    const size_t W = (size_t)C->g->width;
    swath_cells(C, (size_t)y0 * W, (size_t)y1 * W);
}

ts_status ts_sh_swath_light(const ts_grid *grid, const ts_sh_wedges *w,
                            const float *const *planes, const double l[TS_SH_COEFFS],
                            const float *nx, const float *ny, const float *nz,
                            double scale_shade, float *shade, double scale_share, float *share,
                            ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!w || !w->interior || !planes || !l || (!shade && !share) ||
        (shade && (!nx || !ny || !nz)))
        return ts_fail(err, TS_ERR_ARG, "the wedge tables, the horizon planes, the light, an "
                       "output and, for shade, the normals must not be NULL");
    const ts_sh_swath *s = &w->swath;
    for (int k = 0; k < s->n; k++)
        if (!planes[k])
            return ts_fail(err, TS_ERR_ARG, "horizon plane %d is NULL", k);
    slot_rotation *rot = malloc(sizeof *rot * (size_t)(s->n + 1));
    if (!rot)
        return ts_fail(err, TS_ERR_NOMEM, "out of memory for the swath's rotations");
    /* canonical starts (core/sh_visibility.c): wedge k at sample k, the rise
     * at sample 0, the closing wedge at sample 0, the fall at the far edge */
    for (int k = 0; k < s->n; k++)
        slot_rotation_set(&rot[k], ts_sh_swath_azimuth(s, k));
    slot_rotation_set(&rot[s->n], ts_sh_swath_azimuth(s, s->n - 1) + s->step / 2);
    swath_ctx C = {grid, w, planes, rot, {{0}}, {0}, nx, ny, nz, (float)scale_shade,
                   (float)scale_share, shade, share};
    for (int k = 0; k < N; k++)
        C.l[k] = (float)l[k];
    if (shade) {
        double m[N][N];
        ts_sh_product_matrix(l, m);
        ts_sh_fold_cosine(m, C.mh);
    }
    st = ts_parallel_for(ts_thread_count(0, grid->height), grid->height, swath_rows, &C, err);
    free(rot);
    return st;
}
