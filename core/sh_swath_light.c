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
 *
 * A swath of few samples (a key light's; FOLD_MAX_SAMPLES) goes further:
 * every slot's wedge table is folded once per run with its rotation and
 * the light (l . R t for share; mh^T R t for shade, mh the folded product
 * matrix), so that a cell reads its wedges from per-slot tables and needs
 * only a dot product with the basis at its normal (no 16 x 16 product, no
 * rotation): the same sums in another order, the folding in double.
 */
#include <math.h>
#include <stdlib.h>

#include "horn_row.h"
#include "parallel.h"
#include "sh_block512.h"
#include "sh_internal.h"
#include "simd_clones.h"
#include "status_internal.h"

#define N TS_SH_COEFFS

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
    const float *nx, *ny, *nz; /* NULL: each row's made from the grid */
    float *rows_n;             /* then 3 x width floats a worker for them */
    float scale_shade, scale_share;
    float *shade, *share;
    /* folded per-slot tables (slot k as rot[k]); NULL: the general path */
    float **fold_shade; /* 16 floats a node */
    float **fold_share; /* 1 float a node */
} swath_ctx;

/* Swaths of at most this many samples use the folded tables (4 MiB for
 * shade per interior slot: 32 MiB at most). */
#define FOLD_MAX_SAMPLES 8

static void slot_rotation_set(slot_rotation *s, double az_start)
{
    ts_sh_rotation r;
    ts_sh_rotation_set(&r, az_start);
    for (int k = 0; k < N; k++) {
        s->p[k] = r.p[k];
        s->q_mirrored[k] = r.q[TS_SH_BAND_MIRROR[k]];
    }
}

static inline float clamp_node(float w)
{
    const float scale = (TS_SH_WEDGE_STEPS - 1) / 90.0f;
    /* NaN (a nodata cell's, whose outputs are NaN anyway) as 0: its node
     * must stay an index (folded_cells finds a block's before the test) */
    return (w != w || w < 0 ? 0 : w > 90 ? 90 : w) * scale;
}

/* a1 += v p, a2 += v q' for the wedge v read bilinearly from the interior
 * table at horizons (wa, wb). */
/* The node index and fraction of horizon w on a table axis. */
static inline int node_of(float w, float *frac)
{
    const float t = clamp_node(w);
    int i = (int)t;
    i = i > TS_SH_WEDGE_STEPS - 2 ? TS_SH_WEDGE_STEPS - 2 : i;
    *frac = t - (float)i;
    return i;
}

/* The bilinear read of an interior table at horizons (wa, wb): the node
 * (ia, ib) (*at = ia * S + ib) and the weights of its four corners
 * (ia, ib), (ia, ib + 1), (ia + 1, ib), (ia + 1, ib + 1). */
static inline void bilinear_at(float wa, float wb, size_t *at, float wt[4])
{
    float fa, fb;
    const int ia = node_of(wa, &fa), ib = node_of(wb, &fb);
    *at = (size_t)ia * TS_SH_WEDGE_STEPS + ib;
    wt[0] = (1 - fa) * (1 - fb), wt[1] = (1 - fa) * fb, wt[2] = fa * (1 - fb), wt[3] = fa * fb;
}

static inline void add_interior(const float *restrict table, float wa, float wb,
                                const slot_rotation *restrict r, float *restrict a1,
                                float *restrict a2)
{
    const int S = TS_SH_WEDGE_STEPS;
    size_t at;
    float wt[4];
    bilinear_at(wa, wb, &at, wt);
    const float *t00 = table + at * N, *t01 = t00 + N;
    const float *t10 = t00 + (size_t)S * N, *t11 = t10 + N;
    const float w00 = wt[0], w01 = wt[1], w10 = wt[2], w11 = wt[3];
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
    float f;
    const float *t0 = table + (size_t)node_of(w, &f) * N;
    for (int k = 0; k < N; k++) {
        float v = (1 - f) * t0[k] + f * t0[k + N];
        a1[k] += v * r->p[k];
        a2[k] += v * r->q_mirrored[k];
    }
}

/* 1 if a horizon of cell c is NaN (nodata): its outputs are then NaN. */
static inline int cell_nodata(const swath_ctx *C, size_t c)
{
    int nodata = 0;
    for (int k = 0; k < C->w->swath.n; k++)
        nodata |= C->planes[k][c] != C->planes[k][c];
    if (nodata) {
        if (C->share)
            C->share[c] = NAN;
        if (C->shade)
            C->shade[c] = NAN;
    }
    return nodata;
}

/* The outputs of cell c from its share l . V and its shade before
 * scaling (NaN normal: NaN). */
static inline void store_share(const swath_ctx *C, size_t c, float share)
{
    float t = share * C->scale_share;
    C->share[c] = t < 0 ? 0 : t > 1 ? 1 : t;
}

static inline void store_shade(const swath_ctx *C, size_t c, float shade)
{
    float t = shade * C->scale_shade;
    C->shade[c] = t == t ? (t < 0 ? 0 : t) : NAN;
}

/* Cells c0..c1 (cloned for wider vectors where the CPU has them); their
 * normals nx[c - c0], ny, nz. */
TS_SIMD_CLONES
static void swath_cells(const swath_ctx *C, size_t c0, size_t c1, const float *nx,
                        const float *ny, const float *nz)
{
    const ts_sh_wedges *w = C->w;
    const float *const *P = C->planes;
    const int n = w->swath.n, complete = w->swath.complete;
    for (size_t c = c0; c < c1; c++) {
        if (cell_nodata(C, c))
            continue;
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
            v[k] = a1[k] + a2[TS_SH_BAND_MIRROR[k]];
        if (C->share) {
            float p[N];
            for (int k = 0; k < N; k++)
                p[k] = C->l[k] * v[k];
            store_share(C, c, ts_sh_sum16(p));
        }
        if (C->shade) {
            float yn[N];
            TS_SH_BASIS(float, nx[c - c0], ny[c - c0], nz[c - c0], yn);
            store_shade(C, c, ts_sh_triple_folded(C->mh, v, yn));
        }
    }
}

/* Cells a block of folded_cells takes at once. */
#define FOLD_BLOCK 16

/* The nodes and weights of a block's cells on every slot's table (an
 * interior slot bilinear at (wa, wb): weights of (ia, ib), (ia, ib + 1),
 * (ia + 1, ib), (ia + 1, ib + 1); a boundary slot linear at wa: of nodes
 * at and at + 1, the last two weights 0), cell by cell as bilinear_at and
 * node_of, in loops over the cells that the compiler vectorises. */
typedef struct {
    int at[FOLD_MAX_SAMPLES + 1][FOLD_BLOCK];
    float wt[FOLD_MAX_SAMPLES + 1][4][FOLD_BLOCK];
} block_nodes;

static inline void block_interior(const float *restrict pa, const float *restrict pb, int m,
                                  int slot, block_nodes *restrict B)
{
    for (int j = 0; j < m; j++) {
        size_t at;
        float wt[4];
        bilinear_at(pa[j], pb[j], &at, wt);
        B->at[slot][j] = (int)at;
        for (int i = 0; i < 4; i++)
            B->wt[slot][i][j] = wt[i];
    }
}

static inline void block_boundary(const float *restrict pa, int m, int slot,
                                  block_nodes *restrict B)
{
    for (int j = 0; j < m; j++) {
        float f;
        B->at[slot][j] = node_of(pa[j], &f);
        B->wt[slot][0][j] = 1 - f;
        B->wt[slot][1][j] = f;
    }
}

/* Cell j's wedge of an interior slot from its folded tables: shade's 16
 * floats into acc and share's one into *share (where the tables are there),
 * the same sums as bilinear_at's weights applied node by node. */
static inline void add_folded_interior(const swath_ctx *C, const block_nodes *B, int slot,
                                       int j, float *restrict acc, float *restrict share)
{
    const size_t S = TS_SH_WEDGE_STEPS, at = (size_t)B->at[slot][j];
    const float w0 = B->wt[slot][0][j], w1 = B->wt[slot][1][j];
    const float w2 = B->wt[slot][2][j], w3 = B->wt[slot][3][j];
    if (C->fold_shade) {
        const float *t00 = C->fold_shade[slot] + at * N, *t01 = t00 + N, *t10 = t00 + S * N,
                    *t11 = t10 + N;
        for (int k = 0; k < N; k++)
            acc[k] += (w0 * t00[k] + w1 * t01[k]) + (w2 * t10[k] + w3 * t11[k]);
    }
    if (C->fold_share) {
        const float *t = C->fold_share[slot] + at;
        *share += (w0 * t[0] + w1 * t[1]) + (w2 * t[S] + w3 * t[S + 1]);
    }
}

/* The same for a boundary slot (rise or fall, 1D), linear. */
static inline void add_folded_boundary(const swath_ctx *C, const block_nodes *B, int slot,
                                       int j, float *restrict acc, float *restrict share)
{
    const size_t at = (size_t)B->at[slot][j];
    const float f0 = B->wt[slot][0][j], f1 = B->wt[slot][1][j];
    if (C->fold_shade) {
        const float *t0 = C->fold_shade[slot] + at * N, *t1 = t0 + N;
        for (int k = 0; k < N; k++)
            acc[k] += f0 * t0[k] + f1 * t1[k];
    }
    if (C->fold_share) {
        const float *t = C->fold_share[slot] + at;
        *share += f0 * t[0] + f1 * t[1];
    }
}

/* Cells c0..c1 from the folded tables, FOLD_BLOCK at a time: their nodes
 * and weights first, over the cells (vectorised: a quarter less time than
 * finding them cell by cell, session 15), then cell by cell the same sums. */
TS_SIMD_CLONES
static void folded_cells(const swath_ctx *C, size_t c0, size_t c1, const float *nx,
                         const float *ny, const float *nz)
{
    const float *const *P = C->planes;
    const int n = C->w->swath.n, complete = C->w->swath.complete;
    const int first = complete ? 0 : 1;
    block_nodes B;
    for (size_t b = c0; b < c1; b += FOLD_BLOCK) {
        const int m = c1 - b < FOLD_BLOCK ? (int)(c1 - b) : FOLD_BLOCK;
        /* slot k: from sample k - 1 (the last, for the closing slot 0) to k */
        for (int k = first; k < n; k++)
            block_interior(P[k] + b, P[k ? k - 1 : n - 1] + b, m, k, &B);
        if (!complete) {
            block_boundary(P[0] + b, m, 0, &B);
            block_boundary(P[n - 1] + b, m, n, &B);
        }
        float acc[FOLD_BLOCK][N] __attribute__((aligned(64)));
        unsigned skip = 0;
        for (int j = 0; j < m; j++) {
            const size_t c = b + (size_t)j;
            for (int k = 0; k < N; k++)
                acc[j][k] = 0;
            if (cell_nodata(C, c)) {
                skip |= 1u << j;
                continue;
            }
            float share = 0;
            for (int k = first; k < n; k++)
                add_folded_interior(C, &B, k, j, acc[j], &share);
            if (!complete) {
                add_folded_boundary(C, &B, 0, j, acc[j], &share);
                add_folded_boundary(C, &B, n, j, acc[j], &share);
            }
            if (C->share)
                store_share(C, c, share);
        }
        if (!C->shade)
            continue;
        const size_t o = b - c0;
        if (m == FOLD_BLOCK && ts_sh_block_shade512((const float(*)[N])acc, nx + o, ny + o,
                                                    nz + o, C->scale_shade, skip, C->shade + b))
            continue;
        for (int j = 0; j < m; j++) {
            if (skip >> j & 1)
                continue;
            float yn[N], p[N];
            TS_SH_BASIS(float, nx[o + j], ny[o + j], nz[o + j], yn);
            for (int k = 0; k < N; k++)
                p[k] = acc[j][k] * yn[k];
            store_shade(C, b + (size_t)j, ts_sh_sum16(p));
        }
    }
}

static void swath_span(const swath_ctx *C, size_t c0, size_t c1, const float *nx,
                       const float *ny, const float *nz)
{
    if (C->fold_shade || C->fold_share)
        folded_cells(C, c0, c1, nx, ny, nz);
    else
        swath_cells(C, c0, c1, nx, ny, nz);
}

static void swath_rows(void *ctx, int worker, long y0, long y1)
{
    const swath_ctx *C = ctx;
    const size_t W = (size_t)C->g->width;
    if (!C->shade || C->nx) {
        const size_t o = (size_t)y0 * W;
        swath_span(C, o, (size_t)y1 * W, C->nx ? C->nx + o : NULL, C->nx ? C->ny + o : NULL,
                   C->nx ? C->nz + o : NULL);
        return;
    }
    /* the normals row by row, as ts_normals makes them (ts_horn_row) */
    float *n = C->rows_n + (size_t)worker * 3 * W;
    for (long y = y0; y < y1; y++) {
        ts_horn_row(C->g, (int)y, n, n + W, n + 2 * W);
        swath_span(C, (size_t)y * W, (size_t)(y + 1) * W, n, n + W, n + 2 * W);
    }
}

/* The folded tables' slots: interior ones (1 .. n - 1, and 0 when complete)
 * of S x S nodes, boundary ones (0 rise, n fall) of S. */
static int slot_count(const ts_sh_swath *s)
{
    return s->complete ? s->n : s->n + 1;
}

static int slot_interior(const ts_sh_swath *s, int k)
{
    return s->complete || (k > 0 && k < s->n);
}

typedef struct {
    swath_ctx *C;
    double mh[N][N], l[N];
    ts_sh_rotation *rot; /* of every slot */
} fold_job;

/* Items a: row a % S of slot a / S (a boundary slot's row is one node). */
static void fold_rows(void *ctx, int worker, long a0, long a1)
{
    (void)worker;
    const fold_job *J = ctx;
    const swath_ctx *C = J->C;
    const ts_sh_swath *s = &C->w->swath;
    const long S = TS_SH_WEDGE_STEPS;
    for (long a = a0; a < a1; a++) {
        const int slot = (int)(a / S), interior = slot_interior(s, slot);
        const ts_sh_rotation *r = &J->rot[slot];
        const float *src = !interior ? (slot == 0 ? C->w->rise : C->w->fall)
                                     : C->w->interior;
        const size_t first = interior ? (size_t)(a % S) * S : (size_t)(a % S);
        const size_t count = interior ? (size_t)S : 1;
        for (size_t e = first; e < first + count; e++) {
            const float *t = src + e * N;
            double u[N], share = 0;
            for (int k = 0; k < N; k++) { /* the rotation, as add_interior's */
                u[k] = (double)t[k] * r->p[k] + (double)t[TS_SH_BAND_MIRROR[k]] * r->q[k];
                share += J->l[k] * u[k];
            }
            if (C->fold_share)
                C->fold_share[slot][e] = (float)share;
            for (int k = 0; C->fold_shade && k < N; k++) {
                double f = 0;
                for (int j = 0; j < N; j++)
                    f += u[j] * J->mh[j][k];
                C->fold_shade[slot][e * N + k] = (float)f;
            }
        }
    }
}

static void fold_free(swath_ctx *C, int slots)
{
    for (int k = 0; k < slots; k++) {
        if (C->fold_shade)
            free(C->fold_shade[k]);
        if (C->fold_share)
            free(C->fold_share[k]);
    }
    free(C->fold_shade);
    free(C->fold_share);
    C->fold_shade = C->fold_share = NULL;
}

/* Fold the wedge tables of every slot with its rotation (whose canonical
 * start is az_start[slot]) and the light; mh the folded product matrix.
 * Out of memory leaves C on the general path. */
static ts_status fold_tables(swath_ctx *C, const double *az_start, ts_error *err)
{
    const ts_sh_swath *s = &C->w->swath;
    const int slots = slot_count(s), S = TS_SH_WEDGE_STEPS;
    fold_job J = {C, {{0}}, {0}, malloc(sizeof(ts_sh_rotation) * (size_t)slots)};
    int ok = J.rot != NULL;
    if (C->shade && ok)
        ok = (C->fold_shade = calloc((size_t)slots, sizeof *C->fold_shade)) != NULL;
    if (C->share && ok)
        ok = (C->fold_share = calloc((size_t)slots, sizeof *C->fold_share)) != NULL;
    for (int k = 0; ok && k < slots; k++) {
        size_t nodes = slot_interior(s, k) ? (size_t)S * S : (size_t)S;
        /* a node's 16 floats on one cache line, not across two */
        if (C->fold_shade)
            ok = (C->fold_shade[k] = aligned_alloc(64, nodes * N * sizeof(float))) != NULL;
        if (ok && C->fold_share)
            ok = (C->fold_share[k] = malloc(nodes * sizeof(float))) != NULL;
        if (ok)
            ts_sh_rotation_set(&J.rot[k], az_start[k]);
    }
    ts_status st = TS_OK;
    if (ok) {
        for (int j = 0; j < N; j++) {
            J.l[j] = C->l[j];
            for (int k = 0; k < N; k++)
                J.mh[j][k] = C->mh[j][k];
        }
        st = ts_parallel_for_ranges(ts_thread_count(C->w->threads, (long)slots * S),
                                    (long)slots * S, 1, fold_rows, &J, err);
    }
    if (!ok || st != TS_OK)
        fold_free(C, slots);
    free(J.rot);
    return st;
}

/* The rows in SWATH_BATCHES batches between reports, where the caller
 * wants them (the pass of a swath of thousands of samples is half a
 * METHOD=sh run). */
#define SWATH_BATCHES 32

ts_status ts_sh_swath_light(const ts_grid *grid, const ts_sh_wedges *w,
                            const float *const *planes, const double l[TS_SH_COEFFS],
                            const float *nx, const float *ny, const float *nz,
                            double scale_shade, float *shade, double scale_share, float *share,
                            ts_error *err)
{
    return ts_sh_swath_light_reported(grid, w, planes, l, nx, ny, nz, scale_shade, shade,
                                      scale_share, share, NULL, 0, 1, err);
}

ts_status ts_sh_swath_light_reported(const ts_grid *grid, const ts_sh_wedges *w,
                                     const float *const *planes, const double l[TS_SH_COEFFS],
                                     const float *nx, const float *ny, const float *nz,
                                     double scale_shade, float *shade, double scale_share,
                                     float *share, const ts_horizon_opts *report, double from,
                                     double to, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!w || !w->interior || !planes || !l || (!shade && !share) ||
        (shade && (!nx != !ny || !nx != !nz)))
        return ts_fail(err, TS_ERR_ARG, "the wedge tables, the horizon planes, the light and "
                       "an output must not be NULL, and for shade the three planes of normals "
                       "must be given or all NULL");
    const ts_sh_swath *s = &w->swath;
    for (int k = 0; k < s->n; k++)
        if (!planes[k])
            return ts_fail(err, TS_ERR_ARG, "horizon plane %d is NULL", k);
    slot_rotation *rot = malloc(sizeof *rot * (size_t)(s->n + 1));
    double *az_start = malloc(sizeof *az_start * (size_t)(s->n + 1));
    if (!rot || !az_start) {
        free(rot);
        free(az_start);
        return ts_fail(err, TS_ERR_NOMEM, "out of memory for the swath's rotations");
    }
    /* canonical starts (core/sh_visibility.c): wedge k at sample k, the rise
     * at sample 0, the closing wedge at sample 0, the fall at the far edge */
    for (int k = 0; k < s->n; k++)
        az_start[k] = ts_sh_swath_azimuth(s, k);
    az_start[s->n] = ts_sh_swath_azimuth(s, s->n - 1) + s->step / 2;
    for (int k = 0; k <= s->n; k++)
        slot_rotation_set(&rot[k], az_start[k]);
    swath_ctx C = {grid, w, planes, rot, {{0}}, {0}, nx, ny, nz, NULL, (float)scale_shade,
                   (float)scale_share, shade, share, NULL, NULL};
    for (int k = 0; k < N; k++)
        C.l[k] = (float)l[k];
    if (shade) {
        double m[N][N];
        ts_sh_product_matrix(l, m);
        ts_sh_fold_cosine(m, C.mh);
    }
    /* the tables only pay on a large grid: an interior slot's costs some
     * S^2 x 290 multiply-adds to build, against about 300 saved a cell */
    const int interior_slots = s->complete ? s->n : s->n - 1;
    /* a window's: the whole DEM's, so that every window takes its path */
    const ts_grid_origin *o = grid->origin;
    const double cells = o ? (double)o->full_width * o->full_height
                           : (double)grid->width * grid->height;
    if (report && report->progress)
        st = ts_progress(report, from, err);
    if (st == TS_OK && s->n <= FOLD_MAX_SAMPLES &&
        cells >= (double)interior_slots * TS_SH_WEDGE_STEPS * TS_SH_WEDGE_STEPS)
        st = fold_tables(&C, az_start, err);
    const int threads = ts_thread_count(w->threads, grid->height);
    if (st == TS_OK && shade && !nx &&
        !(C.rows_n = malloc((size_t)threads * 3 * grid->width * sizeof(float))))
        st = ts_fail(err, TS_ERR_NOMEM, "out of memory for rows of normals");
    if (st == TS_OK)
        st = ts_parallel_reported(threads, grid->height, TS_ROWS_GRAIN, swath_rows, &C, report,
                                  from, to, SWATH_BATCHES, err);
    free(C.rows_n);
    fold_free(&C, slot_count(s));
    free(rot);
    free(az_start);
    return st;
}
