/*
 * The window hulls of a lockstep block of capped sweep lines (the capped
 * sweep's sweep_block, core/horizon_sweep.c): each line keeps its samples
 * and the sliding-window hull of those beyond the near field and within
 * the maximum distance (window_hull.h), and per step answers the same
 * queries, with the same search fingers, in the same order as the
 * line-by-line process_line, so the occluders are the same bit for bit.
 * Sampling and the far field around it are the block's vectorised passes
 * (lane_passes.h); the hulls run here, eight lines per AVX-512 vector
 * where the CPU has it (window_lanes_vec.c), else line by line.
 */
#ifndef TS_WINDOW_LANES_H
#define TS_WINDOW_LANES_H

#include <stddef.h>

#include "lane_hull.h"
#include "window_hull.h"

typedef struct {
    int lanes, n;           /* lines, samples a line may hold + 1 */
    double cap;             /* the maximum distance, metres */
    ts_hull_pt *pts;        /* line j's samples, back, front and undo points at
                               pts + j * lane_pts + {0, 1, 2, 3} * n, its undo
                               sizes (ints) after them */
    size_t lane_pts, bytes; /* points per line, the mapping's size */
    /* by line: its window's state (ts_window_hull's fields), its samples */
    int *in, *mid, *out, *nb, *nf, *raw_n;
    int *finger;            /* line j's search fingers at j + {0, 1, 2, 3} lanes:
                               (cell below, cell above) x (front, back) */
} ts_window_lanes;

/* Buffers for `lanes` lines of up to `samples` samples each; 0 if out of
 * memory (then ts_window_lanes_free still applies). */
int ts_window_lanes_alloc(ts_window_lanes *L, int lanes, int samples, double cap);
void ts_window_lanes_free(ts_window_lanes *L);

/* Empty line j's samples and window for a new line. */
void ts_window_lanes_reset(ts_window_lanes *L, int j);

/* Line j's window as a ts_window_hull, and back. */
ts_window_hull ts_window_lanes_get(const ts_window_lanes *L, int j);
void ts_window_lanes_put(const ts_window_lanes *L, int j, const ts_window_hull *w);

/* Step s->k of lines s->j0..s->j1 (as ts_lane_hull_step, with the same
 * meaning of s and occ): each line keeps its sample (NaN: none), slides
 * its window to its distance and asks it for the occluders of the cells
 * below (hi, where asked) and above (lo entry j + 1). */
void ts_window_lanes_step(const ts_window_lanes *L, const ts_lane_step *s,
                          const ts_lane_occluders *occ);

/* The step, vectorised (window_lanes_vec.c): returns 0, having done
 * nothing, where the CPU (or the build) has no AVX-512 or the buffers are
 * too large for 32-bit offsets. */
int ts_window_lanes_step_vec(const ts_window_lanes *L, const ts_lane_step *s,
                             const ts_lane_occluders *occ);

#endif
