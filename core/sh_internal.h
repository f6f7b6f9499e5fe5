/* sh_internal.h - what the SH files share (core/sh_*.c); not installed. */
#ifndef TS_SH_INTERNAL_H
#define TS_SH_INTERNAL_H

#include <math.h>
#include <stddef.h>

#include "terrashade_sh.h"

/** Zonal coefficients (of y_l0) of the clamped cosine max(0, z)
 *  (Ramamoorthi & Hanrahan 2001): sqrt(pi)/2, sqrt(pi/3), sqrt(5 pi)/8, 0. */
static const double TS_SH_CLAMPED_COS_ZH[4] = {0.886226925452758014, 1.023326707946488488,
                                               0.495415912200751666, 0.0};

/** m (a light's product matrix) with the clamped cosine's zonal factors,
 *  so that the triple product with a normal n is sum_jk v_j mh[j][k] y_k(n). */
void ts_sh_fold_cosine(const double m[TS_SH_COEFFS][TS_SH_COEFFS],
                       float mh[TS_SH_COEFFS][TS_SH_COEFFS]);

/** The 16 basis functions at unit direction (x, y, z) in type T (double for
 *  ts_sh_eval, float in the per-cell loops, a vector of 16 floats in
 *  core/sh_block512.c): the one home of the formulas. K(c) makes the
 *  constant c a T: TS_SH_BASIS casts it; TS_SH_BASIS_K takes a maker for a
 *  T that a cast cannot make (a vector). The products run left to right,
 *  constant first, in any T: the same operations element by element. */
#define TS_SH_BASIS(T, x, y, z, out) TS_SH_BASIS_K(T, (T), x, y, z, out)
#define TS_SH_BASIS_K(T, K, x, y, z, out)                                                \
    do {                                                                                 \
        const T x_ = (x), y_ = (y), z_ = (z), zz_ = z_ * z_;                             \
        (out)[0] = K(0.282094791773878143);                                              \
        (out)[1] = K(0.488602511902919921) * y_;                                         \
        (out)[2] = K(0.488602511902919921) * z_;                                         \
        (out)[3] = K(0.488602511902919921) * x_;                                         \
        (out)[4] = K(1.092548430592079070) * x_ * y_;                                    \
        (out)[5] = K(1.092548430592079070) * y_ * z_;                                    \
        (out)[6] = K(0.315391565252520002) * (3 * zz_ - 1);                              \
        (out)[7] = K(1.092548430592079070) * x_ * z_;                                    \
        (out)[8] = K(0.546274215296039535) * (x_ * x_ - y_ * y_);                        \
        (out)[9] = K(0.590043589926643510) * y_ * (3 * x_ * x_ - y_ * y_);              \
        (out)[10] = K(2.890611442640554055) * x_ * y_ * z_;                              \
        (out)[11] = K(0.457045799464465737) * y_ * (5 * zz_ - 1);                        \
        (out)[12] = K(0.373176332590115391) * z_ * (5 * zz_ - 3);                        \
        (out)[13] = K(0.457045799464465737) * x_ * (5 * zz_ - 1);                        \
        (out)[14] = K(1.445305721320277027) * z_ * (x_ * x_ - y_ * y_);                  \
        (out)[15] = K(0.590043589926643510) * x_ * (x_ * x_ - 3 * y_ * y_);             \
    } while (0)

/** Gauss-Legendre nodes and weights of n points (n <= 32) on [-1, 1]. */
void ts_sh_gauss(int n, double *x, double *w);

/** The permutation of every rotation about z: m -> -m within each band
 *  (coefficient l (l + 1) + m to l (l + 1) - m), its own inverse. A
 *  constant, so that loops over the 16 coefficients permute in registers. */
static const int TS_SH_BAND_MIRROR[TS_SH_COEFFS] = {0, 3,  2,  1,  8,  7,  6,  5,
                                                    4, 15, 14, 13, 12, 11, 10, 9};

/** A rotation about z in the form
 *  out[k] = in[k] p[k] + in[TS_SH_BAND_MIRROR[k]] q[k]. */
typedef struct {
    float p[TS_SH_COEFFS], q[TS_SH_COEFFS];
} ts_sh_rotation;

/** The rotation that takes a canonical wedge to its start at azimuth
 *  `az_start` degrees (phi = 90 - az_start; ts_sh_rotate_z's formulas). */
void ts_sh_rotation_set(ts_sh_rotation *r, double az_start);

/** 16 floats as one vector (GCC's and clang's vector extension): one
 *  AVX-512 register, two AVX2 ones, four SSE ones, whatever the clone.
 *  Aligned as a float and may alias one, so that any 16 floats of an
 *  array load and store as one: TS_SH_V16(p). */
typedef float ts_sh_v16
    __attribute__((vector_size(TS_SH_COEFFS * sizeof(float)), aligned(4), may_alias));
#define TS_SH_V16(p) (*(ts_sh_v16 *)(p))
#define TS_SH_CV16(p) (*(const ts_sh_v16 *)(p))

/**
 * Add one wedge of one cell to acc (16 floats): kind 2 reads the interior
 * table bilinearly at (wa, wb), kind 0 the 1D rise table at wa, kind 1 the
 * fall table at wb (ts_sh_wedges); then turns it by r. A NaN horizon makes
 * acc NaN. In 16-float vectors, each coefficient's operations in the order
 * the scalar loops had (gcc left those loops scalar in the loop over the
 * cells: ~40 % of an ENV_METHOD=sh light's time).
 */
static inline void ts_sh_cell_wedge(const float *restrict table, int kind, float wa, float wb,
                                    const ts_sh_rotation *r, float *restrict acc)
{
    const int N = TS_SH_WEDGE_STEPS;
    const float scale = (N - 1) / 90.0f;
    if (wa != wa || wb != wb) {
        for (int k = 0; k < TS_SH_COEFFS; k++)
            acc[k] = NAN;
        return;
    }
    ts_sh_v16 v;
    float ta = (wa < 0 ? 0 : wa > 90 ? 90 : wa) * scale,
          tb = (wb < 0 ? 0 : wb > 90 ? 90 : wb) * scale;
    int ia = (int)ta, ib = (int)tb;
    ia = ia > N - 2 ? N - 2 : ia;
    ib = ib > N - 2 ? N - 2 : ib;
    const float fa = ta - (float)ia, fb = tb - (float)ib;
    if (kind == 2) {
        const float *t00 = table + ((size_t)ia * N + ib) * TS_SH_COEFFS;
        const float *t01 = t00 + TS_SH_COEFFS, *t10 = t00 + N * TS_SH_COEFFS;
        const float *t11 = t10 + TS_SH_COEFFS;
        const float w00 = (1 - fa) * (1 - fb), w01 = (1 - fa) * fb, w10 = fa * (1 - fb),
                    w11 = fa * fb;
        v = w00 * TS_SH_CV16(t00) + w01 * TS_SH_CV16(t01) + w10 * TS_SH_CV16(t10) +
            w11 * TS_SH_CV16(t11);
    } else {
        const int i = kind == 0 ? ia : ib;
        const float f = kind == 0 ? fa : fb, *t0 = table + (size_t)i * TS_SH_COEFFS;
        v = (1 - f) * TS_SH_CV16(t0) + f * TS_SH_CV16(t0 + TS_SH_COEFFS);
    }
    /* v at TS_SH_BAND_MIRROR */
    const ts_sh_v16 vp =
        __builtin_shufflevector(v, v, 0, 3, 2, 1, 8, 7, 6, 5, 4, 15, 14, 13, 12, 11, 10, 9);
    TS_SH_V16(acc) = TS_SH_CV16(acc) + (v * TS_SH_CV16(r->p) + vp * TS_SH_CV16(r->q));
}

/* Sum of 16 floats as a pairwise tree: vector halves, not a chain of 16
 * dependent scalar additions. */
static inline float ts_sh_sum16(const float p[TS_SH_COEFFS])
{
    float a[8], b[4];
    for (int k = 0; k < 8; k++)
        a[k] = p[k] + p[k + 8];
    for (int k = 0; k < 4; k++)
        b[k] = a[k] + a[k + 4];
    return (b[0] + b[2]) + (b[1] + b[3]);
}

/* sum_jk v_j mh[j][k] yn_k (mh of ts_sh_fold_cosine, yn the basis at the
 * normal: the triple product), the matrix-vector product in four independent
 * accumulators (a chain of 16 dependent vector additions would be its
 * latency). */
static inline float ts_sh_triple_folded(const float mh[TS_SH_COEFFS][TS_SH_COEFFS],
                                        const float v[TS_SH_COEFFS],
                                        const float yn[TS_SH_COEFFS])
{
    float u0[TS_SH_COEFFS] = {0}, u1[TS_SH_COEFFS] = {0}, u2[TS_SH_COEFFS] = {0},
          u3[TS_SH_COEFFS] = {0}, p[TS_SH_COEFFS];
    for (int j = 0; j < TS_SH_COEFFS; j += 4)
        for (int k = 0; k < TS_SH_COEFFS; k++) { /* one vector of k per line */
            u0[k] += v[j] * mh[j][k];
            u1[k] += v[j + 1] * mh[j + 1][k];
            u2[k] += v[j + 2] * mh[j + 2][k];
            u3[k] += v[j + 3] * mh[j + 3][k];
        }
    for (int k = 0; k < TS_SH_COEFFS; k++)
        p[k] = ((u0[k] + u1[k]) + (u2[k] + u3[k])) * yn[k];
    return ts_sh_sum16(p);
}

#endif
