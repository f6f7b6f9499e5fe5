/*
 * One step of the hulls of a lockstep block of sweep lines (the unbounded
 * sweep's sweep_block, core/horizon_sweep.c), eight lines per AVX-512
 * vector (four per AVX2 one), several vectors at once so that their gathers
 * overlap: each line pushes its sample onto its upper convex hull, popping
 * the points it hides (masked: a vector's pop loop runs while any of its
 * lines still pops), moves its first point beyond the near field, and asks
 * its hull for the far-field occluders of the cells below and above it.
 * Per line the same double operations in the same order as the scalar
 * hull_push, far_advance and stack_query, so the results are the same bit
 * for bit.
 */
#ifndef TS_LANE_HULL_H
#define TS_LANE_HULL_H

#include "lane_passes.h"
#include "window_hull.h"

/* The block's hulls: line j's points at pts + j * stride, n[j] of them,
 * far[j] the top-most one at least near_skip behind the line's sample
 * (-1: none). */
typedef struct {
    ts_hull_pt *pts;
    int stride;
    int *n, *far;
    /* NULL, or the points the AVX-512 step reads most, kept beside the
     * stacks so that it needs no gather for them: TS_BESIDE arrays of
     * beside_n doubles (line j's at [j] of each). Only that step reads and
     * keeps them: hulls that have them must take every step there. */
    double *beside;
    int beside_n;
} ts_lane_hulls;

/* The arrays of ts_lane_hulls' beside: the d and g of the top point (T)
 * and of the one under it (S), each where the stack has it. */
enum { TS_BESIDE_TD, TS_BESIDE_TG, TS_BESIDE_SD, TS_BESIDE_SG, TS_BESIDE };

/* Step k of lines j0..j1: each line's distance d[j] from its first sample,
 * its height hs[j] (NaN: no sample to push), and the heights hc[j], hn[j]
 * of the cells below and above it (NaN: no query). Line j asks for its own
 * cell's occluder (hi) only when hi_from <= j <= hi_to; line j's answer
 * for the cell above goes to lo entry j + 1. c: the curvature
 * coefficient. */
typedef struct {
    int k, j0, j1, hi_from, hi_to;
    const double *d;
    const float *hs, *hc, *hn;
    double c, near_skip;
    /* where set (ts_lane_delayed_pushes sets them): line j pushes the
     * point of distance push_d[j] (NaN: none), hull height push_g[j] and
     * step push_ks[j], instead of its sample */
    const double *push_d, *push_g;
    const int *push_ks;
    /* > 0: every distance is (its step - its line's first) x k_step (or
     * (its step + a constant) x k_step), each one rounding, so that an
     * occluder's step follows from its distance to the query (to far less
     * than half a step) and the points' steps are neither stored nor read;
     * 0: they are (per-row steps). The same for every step of a sweep. */
    double k_step;
} ts_lane_step;

/*
 * Delayed pushes, for hulls that must hold exactly the samples at least
 * `behind` metres back (the far-only sweep; the bounded sweep's hybrid):
 * each line's samples wait in a ring (slot k % slots of line j: distance
 * d_ring[slot * slot_stride + j], NaN where it has none, and hull height
 * g_ring[...]) until the line is that far past them, by the same doubles
 * as far_horizon.c's lines did, so on lines of any steps. Per line: the
 * step of its oldest sample not yet pushed (-1: from the step it is first
 * met) and its ring slot, and the push of the current pass.
 */
typedef struct {
    int *next, *slot, *ks;
    double *pd, *pg;
} ts_lane_pushes;

/* For up to `lines` lines (+ a vector's loads beyond); 0 out of memory. */
int ts_lane_pushes_alloc(ts_lane_pushes *p, int lines);
void ts_lane_pushes_free(ts_lane_pushes *p);
/* A new block: every line starts afresh. */
void ts_lane_pushes_reset(ts_lane_pushes *p, int lines);
/* A pass of step s (its k, lines j0..j1, distances d): sets s's pushes to
 * each line's oldest waiting sample where it is ready (none elsewhere) and
 * near_skip to 0; returns 1 where some line has another one ready, which
 * then needs another pass of the hull step before the step's last. */
int ts_lane_delayed_pushes(ts_lane_pushes *p, const double *d_ring, const double *g_ring,
                           size_t slot_stride, int slots, double behind, ts_lane_step *s);
/* The same line by line (any CPU; what the AVX-512 pushes of
 * core/lane_pushes.c must equal). */
int ts_lane_delayed_pushes_scalar(ts_lane_pushes *p, const double *d_ring, const double *g_ring,
                                  size_t slot_stride, int slots, double behind, ts_lane_step *s);

/* The step, vectorised: eight lines per AVX-512 vector (lane_hull.c) where
 * the CPU has AVX-512 and the hulls fit 32-bit offsets, else four per AVX2
 * vector (lane_hull256.c); returns 0, having done nothing, where the CPU
 * (or the build, or TERRASHADE_SIMD) has neither; the caller then runs the
 * scalar code. */
int ts_lane_hull_step(const ts_lane_hulls *h, const ts_lane_step *s, const ts_lane_occluders *occ);
/* The step in scalar code, line by line (any CPU): what the vector steps
 * must equal bit for bit. */
void ts_lane_hull_step_scalar(const ts_lane_hulls *h, const ts_lane_step *s,
                              const ts_lane_occluders *occ);
/* The AVX2 step alone; only where ts_cpu_vector_level() is at least AVX2
 * (0 in builds for other CPUs). */
int ts_lane_hull_step_avx2(const ts_lane_hulls *h, const ts_lane_step *s,
                           const ts_lane_occluders *occ);

#endif
