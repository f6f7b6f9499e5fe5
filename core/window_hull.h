/*
 * Upper convex hull of a sliding window of a sweep line's samples: the
 * dominant occluder within a maximum distance in amortised O(1).
 *
 * The samples of one line come in order of distance d along it. The window
 * holds those at distance near..cap behind the query point: a sample enters
 * when it is `near` metres behind, and leaves when it is more than `cap`
 * metres behind, so it is a FIFO queue. A queue is two stacks; here each
 * stack is an upper hull:
 *  - the back hull: the newer part of the window, built as the unbounded
 *    sweep builds its hull (pops on push, Timonen & Westerholm eq. 1);
 *  - the front hull: the older part, built newest first, so that its oldest
 *    sample is on top; each push records the one slot and the size it
 *    overwrote, so that removing the oldest sample undoes it in O(1).
 * When a sample must leave and the front is empty, the whole back becomes
 * the front (rebuilt from the samples: every sample enters each hull once).
 * A query from a point beyond the window takes the higher of the two
 * hulls' tangents; on each hull the slopes are unimodal, so it walks from
 * the end nearest the point.
 *
 * Heights are g = h - c d^2 as in the sweep (horizon_sweep.c), so the hull
 * stays exact with Earth curvature.
 */
#ifndef TS_WINDOW_HULL_H
#define TS_WINDOW_HULL_H

typedef struct {
    double d, g;
    int k;              /* step index of the sample on its line */
} ts_hull_pt;

typedef struct {
    int in, mid, out;   /* samples [out, mid) are in the front, [mid, in) in the back */
    ts_hull_pt *back;   /* oldest at 0 */
    int nb;
    ts_hull_pt *front;  /* newest at 0, oldest on top */
    int nf;
    ts_hull_pt *undo_pt; /* by sample index: what its front push overwrote */
    int *undo_n;         /* by sample index: front size before its push */
} ts_window_hull;

/* Buffers for lines of up to n samples; 0 if out of memory (then
 * ts_window_hull_free still applies). */
int ts_window_hull_alloc(ts_window_hull *w, int n);
void ts_window_hull_free(ts_window_hull *w);

/* Empty the window for a new line. */
static inline void ts_window_hull_reset(ts_window_hull *w)
{
    w->in = w->mid = w->out = 0;
    w->nb = w->nf = 0;
}

/* Rebuild the front from samples [out, in), newest first; the back empties. */
void ts_window_hull_refill(ts_window_hull *w, const ts_hull_pt *pts);

/*
 * Slide the window to query distance d over the line's samples pts[0, n):
 * those at least `near` metres behind d enter, those more than `cap`
 * metres behind leave. d never decreases between resets.
 */
static inline void ts_window_hull_slide(ts_window_hull *w, const ts_hull_pt *pts, int n,
                                        double d, double near, double cap)
{
    while (w->in < n && d - pts[w->in].d >= near) {
        const ts_hull_pt p = pts[w->in++];
        ts_hull_pt *S = w->back;
        int m = w->nb;
        while (m >= 2 && (S[m - 2].g - p.g) * (p.d - S[m - 1].d) >=
                             (S[m - 1].g - p.g) * (p.d - S[m - 2].d))
            m--;
        S[m] = p;
        w->nb = m + 1;
    }
    while (w->out < w->in && d - pts[w->out].d > cap) {
        if (w->out == w->mid)
            ts_window_hull_refill(w, pts);
        /* the oldest sample was the front's last push: undo it */
        int o = w->out++;
        int pos = w->nf - 1;
        w->front[pos] = w->undo_pt[o];
        w->nf = w->undo_n[o];
    }
}

/* The hull point of largest slope seen from (d, g) among P[0, n), n > 0,
 * found by climbing from P[j] (the slopes along a hull are unimodal, and a
 * query from the next sample's point has its tangent nearby). */
static inline int ts_hull_climb(const ts_hull_pt *P, int n, int j, double d, double g)
{
    j = j < n ? j : n - 1;
    while (j + 1 < n && (P[j + 1].g - g) * (d - P[j].d) >= (P[j].g - g) * (d - P[j + 1].d))
        j++;
    while (j > 0 && (P[j - 1].g - g) * (d - P[j].d) > (P[j].g - g) * (d - P[j - 1].d))
        j--;
    return j;
}

/* The window's sample of largest slope (g_p - g) / (d - d_p) seen from the
 * point (d, g), or NULL if the window is empty. finger[2] holds where the
 * last query of the same kind ended on each hull (any values will do: they
 * only make the search shorter). */
static inline const ts_hull_pt *ts_window_hull_query(const ts_window_hull *w, double d, double g,
                                                     int finger[2])
{
    const ts_hull_pt *best = NULL;
    if (w->nf > 0) {
        finger[0] = ts_hull_climb(w->front, w->nf, finger[0], d, g);
        best = &w->front[finger[0]];
    }
    if (w->nb > 0) {
        finger[1] = ts_hull_climb(w->back, w->nb, finger[1], d, g);
        const ts_hull_pt *b = &w->back[finger[1]];
        if (!best || (b->g - g) * (d - best->d) > (best->g - g) * (d - b->d))
            best = b;
    }
    return best;
}

#endif
