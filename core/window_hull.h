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
    /* Lazy mode (ts_window_hull_track): the hulls lag behind the indices */
    ts_hull_pt *all;     /* hull of every sample that entered, [0, in) */
    int nall;
    int bin;             /* the back holds samples [mid, bin) */
    int fmid;            /* the front was last refilled up to fmid */
    int fout;            /* and its undos applied up to fout */
    int rlo;             /* the latest refill takes samples [rlo, mid) */
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
    w->nall = w->bin = w->fmid = w->fout = w->rlo = 0;
}

/* Rebuild the front from samples [lo, hi), newest first, recording the
 * undo of each push. */
void ts_window_hull_refill_range(ts_window_hull *w, const ts_hull_pt *pts, int lo, int hi);

/* Rebuild the front from samples [out, in), newest first; the back empties. */
static inline void ts_window_hull_refill(ts_window_hull *w, const ts_hull_pt *pts)
{
    ts_window_hull_refill_range(w, pts, w->out, w->in);
    w->mid = w->in;
    w->nb = 0;
}

/* Push p onto the upper hull S[0, m) (oldest first), popping the points it
 * hides; returns the new size. */
static inline int ts_hull_push(ts_hull_pt *S, int m, ts_hull_pt p)
{
    while (m >= 2 && (S[m - 2].g - p.g) * (p.d - S[m - 1].d) >=
                         (S[m - 1].g - p.g) * (p.d - S[m - 2].d))
        m--;
    S[m] = p;
    return m + 1;
}

/*
 * Slide the window to query distance d over the line's samples pts[0, n):
 * those at least `near` metres behind d enter, those more than `cap`
 * metres behind leave. d never decreases between resets.
 */
static inline void ts_window_hull_slide(ts_window_hull *w, const ts_hull_pt *pts, int n,
                                        double d, double near, double cap)
{
    while (w->in < n && d - pts[w->in].d >= near)
        w->nb = ts_hull_push(w->back, w->nb, pts[w->in++]);
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
 * query from the next sample's point has its tangent nearby). If tie is
 * not NULL, *tie says whether P[j - 1] is as steep as the answer (the climb
 * stops on a strictly less steep P[j + 1], so only P[j - 1] can tie). */
static inline __attribute__((always_inline)) int ts_hull_climb_tie(const ts_hull_pt *P, int n,
                                                                   int j, double d, double g,
                                                                   int *tie)
{
    j = j < n ? j : n - 1;
    while (j + 1 < n && (P[j + 1].g - g) * (d - P[j].d) >= (P[j].g - g) * (d - P[j + 1].d))
        j++;
    for (;;) {
        if (j == 0) {
            if (tie)
                *tie = 0;
            return 0;
        }
        double up = (P[j - 1].g - g) * (d - P[j].d), here = (P[j].g - g) * (d - P[j - 1].d);
        if (!(up > here)) {
            if (tie)
                *tie = up == here;
            return j;
        }
        j--;
    }
}

static inline int ts_hull_climb(const ts_hull_pt *P, int n, int j, double d, double g)
{
    return ts_hull_climb_tie(P, n, j, d, g, NULL);
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

/*
 * Lazy mode: ts_window_hull_track moves the window's bounds as
 * ts_window_hull_slide would, but only pushes the entering samples onto
 * `all`, the hull of every sample that entered (the unbounded hull, less
 * the near field). Where the tangent to `all` lies in the window, it is the
 * window's answer; only elsewhere do the two hulls catch up, replaying the
 * pushes, refill and undos that the slides would have done, in order.
 */
static inline void ts_window_hull_track(ts_window_hull *w, const ts_hull_pt *pts, int n,
                                        double d, double near, double cap)
{
    while (w->in < n && d - pts[w->in].d >= near)
        w->nall = ts_hull_push(w->all, w->nall, pts[w->in++]);
    while (w->out < w->in && d - pts[w->out].d > cap) {
        if (w->out == w->mid) { /* ts_window_hull_slide refills here */
            w->rlo = w->out;
            w->mid = w->in;
        }
        w->out++;
    }
}

/* Bring the two hulls to the state the slides would have left them in. */
static inline void ts_window_hull_catch_up(ts_window_hull *w, const ts_hull_pt *pts)
{
    if (w->fmid != w->mid) { /* refilled since: only the latest refill counts */
        ts_window_hull_refill_range(w, pts, w->rlo, w->mid);
        w->fmid = w->mid;
        w->fout = w->rlo;
        w->nb = 0;
        w->bin = w->mid;
    }
    for (; w->fout < w->out; w->fout++) {
        w->front[w->nf - 1] = w->undo_pt[w->fout];
        w->nf = w->undo_n[w->fout];
    }
    while (w->bin < w->in)
        w->nb = ts_hull_push(w->back, w->nb, pts[w->bin++]);
}

/* ts_window_hull_query for a window moved by ts_window_hull_track. The
 * tangent to `all` answers when it lies in the window and no other point
 * of `all` is as steep (the climbs break ties their own way). finger[2]
 * is where the last such query ended on `all`. */
static inline __attribute__((always_inline)) const ts_hull_pt *ts_window_hull_query_lazy(ts_window_hull *w,
                                                          const ts_hull_pt *pts, double d,
                                                          double g, int finger[3])
{
    const ts_hull_pt *S = w->all;
    const int n = w->nall;
    if (n > 0 && w->out < w->in) {
        int tie;
        int j = finger[2] = ts_hull_climb_tie(S, n, finger[2], d, g, &tie);
        if (!tie && S[j].d >= pts[w->out].d)
            return &S[j];
    }
    ts_window_hull_catch_up(w, pts);
    return ts_window_hull_query(w, d, g, finger);
}

#endif
