/* Sliding-window upper hull of a sweep line; see window_hull.h. */
#include <stdlib.h>

#include "window_hull.h"

int ts_window_hull_alloc(ts_window_hull *w, int n)
{
    *w = (ts_window_hull){0};
    /* zeroed: a push may save a slot above the hull that was never written */
    w->back = calloc((size_t)n + 1, sizeof *w->back);
    w->front = calloc((size_t)n + 1, sizeof *w->front);
    w->undo_pt = calloc((size_t)n + 1, sizeof *w->undo_pt);
    w->undo_n = calloc((size_t)n + 1, sizeof *w->undo_n);
    return w->back && w->front && w->undo_pt && w->undo_n;
}

void ts_window_hull_free(ts_window_hull *w)
{
    free(w->back);
    free(w->front);
    free(w->undo_pt);
    free(w->undo_n);
    *w = (ts_window_hull){0};
}

void ts_window_hull_refill(ts_window_hull *w, const ts_hull_pt *pts)
{
    ts_hull_pt *F = w->front;
    w->nf = 0;
    for (int i = w->in - 1; i >= w->out; i--) {
        const ts_hull_pt p = pts[i];
        /* mirror of the back's pop: seen forward from p, F[m - 1] is
         * hidden when F[m - 2] is at least as steep */
        int m = w->nf;
        while (m >= 2 && (F[m - 2].g - p.g) * (F[m - 1].d - p.d) >=
                             (F[m - 1].g - p.g) * (F[m - 2].d - p.d))
            m--;
        w->undo_pt[i] = F[m];
        w->undo_n[i] = w->nf;
        F[m] = p;
        w->nf = m + 1;
    }
    w->mid = w->in;
    w->nb = 0;
}
