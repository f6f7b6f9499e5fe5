/* What core/pyramid_horizon.c and core/pyramid_drop.c share: one
 * azimuth's context and a thread's rows of state. */
#ifndef TS_PYRAMID_HZ_H
#define TS_PYRAMID_HZ_H

#include "horizon_edge.h"
#include "pyramid_internal.h"
#include "simd_clones.h"
#include "sky_plane.h"

/* The clones of the loops with fused multiply-adds (pyramid_runs.c: the
 * level rows' vertical B-spline, the samples' interpolation and tangent):
 * each fmaf one instruction wherever the CPU has FMA (every AVX2 CPU has),
 * so that every clone computes the same bits; the baseline x86-64 clone
 * (no FMA) calls the library's fmaf, the same bits, slowly. */
#if defined(TS_PYR_FMA_CLONES)
/* given on the command line, as TS_SIMD_CLONES */
#elif defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define TS_PYR_FMA_CLONES __attribute__((target_clones("avx512f", "fma", "default")))
#else
#define TS_PYR_FMA_CLONES
#endif

/* "This loop's iterations do not depend on each other" (the rows it
 * reads and writes do not overlap): gcc's ivdep. Nothing for clang (the
 * fuzzers' build), which ignored the pragma with a warning under -Wall:
 * its assume_safety warns where a sanitizer keeps it from vectorising. */
#if defined(__clang__)
#define TS_PYR_IVDEP
#elif defined(__GNUC__)
#define TS_PYR_IVDEP _Pragma("GCC ivdep")
#else
#define TS_PYR_IVDEP
#endif

/* What sample j of every cell shares for one azimuth: its offset in
 * cells, split into a whole column ix and a fraction fx, the columns
 * [xa, xb] whose sample is on the grid, and the level it reads. */
typedef struct {
    double s;   /* distance in steps: the level's spacing */
    int ix;     /* floor of the column offset s vx */
    float fx;   /* the fraction of it */
    int xa, xb; /* cells whose sample lies within the grid's columns */
    int lev;    /* level read: j - k o, at least 0 */
} level_az;

typedef struct {
    const ts_pyramid *P;
    double vx, vy;      /* ray direction, DEM cells per step (major component +-1) */
    double *step;       /* metres per step, by row */
    double step_all;    /* the step of every row where they are all equal, else 0 */
    double c;           /* curvature coefficient (1 - k) / 2R, 0 when off */
    double cap;         /* maximum distance in metres, 0 = none */
    double ko;          /* level offset k o */
    int bspline;        /* 1: B-spline in log distance; 0: max over levels */
    const level_az *lv; /* by sample number j */
    float *out;         /* the plane; NULL: rows of scratch (only the sky sums wanted) */
    int *alloc_failed;
} hz_ctx;

/* Azimuths computed together: the cells' own heights on each level are
 * the same for all of them. */
typedef struct {
    int n;
    const hz_ctx *az; /* n */
    /* per azimuth, the first of the batch with its vy (itself where none
     * comes earlier): only such can read a level at the same rows with the
     * same weights (row_level_fill's `same`, share_level_row) */
    int same_vy[TS_PYRAMID_BATCH];
    /* whether any two share a vy (share_level_row; an x-major batch has
     * none, and its test would fail at every level) */
    int share;
    /* what each row span gets as soon as it is done, per azimuth, while
     * it is in the cache: the world beyond the edge (NULL: TS_EDGE_OPEN),
     * then the sky terms (NULL: none; ts_pyramid_horizons_sky) */
    const ts_edge_job *edge;
    const ts_sky_plane *sky;
} batch_ctx;

/* Rows whose per-level entries ts_pyr_rows_range fills at a time (so the
 * grain of its ranges). */
#define TS_PYR_ROW_BLOCK 32

/* The rows [y0, y1) of the batch ctx (a batch_ctx) for
 * ts_parallel_for_ranges: every azimuth's horizons, then each row span's
 * edge and sky terms (core/pyramid_horizon.c), TS_PYR_ROW_BLOCK rows at a
 * time. */
void ts_pyr_rows_range(void *ctx, int worker, long y0, long y1);

/* Per-thread rows of state, one entry per cell of the grid row. */
typedef struct {
    float *s0, *s1, *s2; /* the last three samples (degrees, or tangents) */
    float *m;            /* spline maximum (or largest tangent) so far */
    float *T;            /* the level row at the samples */
    float *A;            /* the samples being pushed */
    double *tpp;         /* drop_cells: t, px, py of the cells (3 rows) */
    int *jd;             /* the sample number at which each cell drops out */
    /* the next sample's level row, columns [t_lo, t_hi] already combined in
     * Tsh with the other azimuths that read the same rows (t_lo > t_hi: no) */
    const float *Tsh;
    int t_lo, t_hi;
    float *out; /* the grid row's horizons (cell x at out[x]): its plane's row, or scratch */
} row_ws;

/* Sample a (c >= 2) after p0, p1, p2: the spline's midpoint before the
 * last sample and its last knot join the maximum *m. */
static inline void spline_push(float *p0, float *p1, float *p2, float *m, float a)
{
    a = a == a ? a : *p2; /* nodata: the sample before */
    float mid = (*p0 + 23.0f * *p1 + 23.0f * *p2 + a) * (1.0f / 48.0f);
    float knot = (*p1 + 4.0f * *p2 + a) * (1.0f / 6.0f);
    float mm = *m;
    mm = mid > mm ? mid : mm;
    mm = knot > mm ? knot : mm;
    *m = mm;
    *p0 = *p1;
    *p1 = *p2;
    *p2 = a;
}

/* core/pyramid_runs.c: the loops over the cells [x0, x1] of a grid row. */

/* dst[x] = sum of weights w[t] * rows r[t] at x, for x in [x0, x1]. */
void ts_pyr_combine_rows(const float *const r[4], const float w[4], int taps, int x0, int x1,
                         float *restrict dst);

/* A row's start: m = -inf over the cells [x0, x1]. */
void ts_pyr_clear_max(row_ws *w, int x0, int x1);

/* Whether z[x0..x1] holds nodata (NaN). */
int ts_pyr_has_nodata(const float *z, int x0, int x1);

/* R[x] = R0[x] where R[x] is nodata (NaN), for x in [x0, x1]. */
void ts_pyr_fill_nodata(float *restrict R, const float *restrict R0, int x0, int x1);

/* Add sample number c (value a_in[x]) to the spline (or the maximum). */
void ts_pyr_push_run(row_ws *w, int bspline, int c, int x0, int x1, const float *restrict a_in);

/* One level's samples: the level row T at x + ix and x + ix + 1 (weight
 * fx) against the cells' own heights on the level R, at d metres (1 / d =
 * inv_d, curvature drop over d = cd). Pushed as sample c in the same pass
 * where the spline allows, else left in w->A for ts_pyr_push_run (returns
 * 0 then). */
int ts_pyr_level_run(row_ws *w, const float *restrict T, int ix, float fx,
                     const float *restrict R, float inv_d, float cd, int bspline, int c, int x0,
                     int x1);

/* One grid row of ts_pyr_level_max_rows: its maxima, its cells' heights on
 * the level, the level rows' weights at its samples' row, 1 / d and the
 * curvature drop over d. */
typedef struct {
    float *m;
    const float *R;
    const float *wt;
    float inv_d, cd;
} level_max_row;

/* For each of the `rows` (1 or 2) grid rows g whose samples read the level
 * rows r (`taps` of them, rows of W columns; each grid row with its own
 * weights) at the same cells [x0, x1] and offset ix + fx:
 * ts_pyr_combine_rows over [x0 + ix, t1] into T, T[t1 + 1] = T[t1], then
 * ts_pyr_level_run of the level maximum (bspline 0). The same maxima, with
 * the level row kept in registers, T not written, and each level row loaded
 * once for both grid rows (core/pyramid_fused.c; R and m on cache lines,
 * ts_pyr_alloc). Returns 0, doing nothing, where the CPU has no AVX-512. */
int ts_pyr_level_max_rows(const level_max_row *g, int rows, const float *const r[4], int taps,
                          int W, int t1, int ix, float fx, int x0, int x1);

/* The horizons of the cells after `count` >= 1 samples, into out. */
void ts_pyr_finish_run(row_ws *w, int bspline, int count, int x0, int x1, float *restrict out);

/* The cells of [a, b] of row y whose rays ended before the samples of
 * the levels (through a side of the grid, or at t_row steps), each after
 * w->jd[x] samples (B-spline; the level maximum needs no count): the last
 * sample of each where its ray ends, read bilinearly on the DEM, then
 * their horizons into out. A dropped cell's state is left as it was, so
 * this runs once a row for all of them (core/pyramid_drop.c). */
void ts_pyr_drop_cells(const hz_ctx *C, row_ws *w, int y, int a, int b, double t_row,
                       float *out);

#endif
