/* The window hulls of a lockstep block of capped sweep lines; see
 * window_lanes.h. */
#include <math.h>
#include <stdlib.h>
#include <sys/mman.h>

#include "window_lanes.h"

/* Every line's arrays in one mapping, in huge pages where the system has
 * them (a hint): the lines of a block touch their hulls at once, hundreds
 * of spots a step. */
int ts_window_lanes_alloc(ts_window_lanes *L, int lanes, int samples, double cap)
{
    *L = (ts_window_lanes){0};
    const size_t n = (size_t)samples + 1;
    L->lanes = lanes;
    L->n = (int)n;
    L->cap = cap;
    L->lane_pts = 4 * n + (n * sizeof(int) + sizeof(ts_hull_pt) - 1) / sizeof(ts_hull_pt);
    L->bytes = (size_t)lanes * L->lane_pts * sizeof(ts_hull_pt);
    /* anonymous pages come zeroed: a front push may save a slot never written */
    void *m = mmap(NULL, L->bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED)
        return 0;
#ifdef MADV_HUGEPAGE
    madvise(m, L->bytes, MADV_HUGEPAGE);
#endif
    L->pts = m;
    L->in = calloc(10 * (size_t)lanes, sizeof *L->in);
    if (!L->in)
        return 0;
    L->mid = L->in + lanes;
    L->out = L->in + 2 * lanes;
    L->nb = L->in + 3 * lanes;
    L->nf = L->in + 4 * lanes;
    L->raw_n = L->in + 5 * lanes;
    L->finger = L->in + 6 * lanes;
    return 1;
}

void ts_window_lanes_free(ts_window_lanes *L)
{
    if (L->pts)
        munmap(L->pts, L->bytes);
    free(L->in);
    *L = (ts_window_lanes){0};
}

void ts_window_lanes_reset(ts_window_lanes *L, int j)
{
    L->raw_n[j] = L->in[j] = L->mid[j] = L->out[j] = L->nb[j] = L->nf[j] = 0;
}

ts_window_hull ts_window_lanes_get(const ts_window_lanes *L, int j)
{
    ts_hull_pt *p = L->pts + (size_t)j * L->lane_pts;
    const size_t n = (size_t)L->n;
    return (ts_window_hull){L->in[j], L->mid[j], L->out[j], p + n, L->nb[j], p + 2 * n,
                            L->nf[j], p + 3 * n, (int *)(p + 4 * n)};
}

void ts_window_lanes_put(const ts_window_lanes *L, int j, const ts_window_hull *w)
{
    L->in[j] = w->in;
    L->mid[j] = w->mid;
    L->out[j] = w->out;
    L->nb[j] = w->nb;
    L->nf[j] = w->nf;
}

/* The occluder of a point at distance d, height h among line j's window
 * w, with the fingers of queries of its kind: its step and its distance
 * from the point; step -1 when none. */
static inline void window_query(const ts_window_hull *w, const ts_window_lanes *L, int j,
                                int kind, double d, float h, double c, int *k_out, float *dd_out)
{
    int *ff = L->finger + 2 * kind * L->lanes + j, *fb = ff + L->lanes;
    int finger[2] = {*ff, *fb};
    const ts_hull_pt *p = ts_window_hull_query(w, d, h - c * d * d, finger);
    *ff = finger[0];
    *fb = finger[1];
    *k_out = p ? p->k : -1;
    *dd_out = p ? (float)(d - p->d) : 0.0f;
}

void ts_window_lanes_step(const ts_window_lanes *L, const ts_lane_step *s,
                          const ts_lane_occluders *occ)
{
    if (ts_window_lanes_step_vec(L, s, occ))
        return;
    const double c = s->c;
    for (int j = s->j0; j <= s->j1; j++) {
        ts_hull_pt *raw = L->pts + (size_t)j * L->lane_pts;
        ts_window_hull w = ts_window_lanes_get(L, j);
        const double d = s->d[j];
        const float hs = s->hs[j], hc = s->hc[j], hn = s->hn[j];
        if (!isnan(hs))
            raw[L->raw_n[j]++] = (ts_hull_pt){d, hs - c * d * d, s->k};
        ts_window_hull_slide(&w, raw, L->raw_n[j], d, s->near_skip, L->cap);
        occ->hi_k[j] = -1;
        occ->hi_dd[j] = 0.0f;
        if (!isnan(hc) && j >= s->hi_from && j <= s->hi_to)
            window_query(&w, L, j, 0, d, hc, c, &occ->hi_k[j], &occ->hi_dd[j]);
        occ->lo_k[j + 1] = -1;
        occ->lo_dd[j + 1] = 0.0f;
        if (!isnan(hn))
            window_query(&w, L, j, 1, d, hn, c, &occ->lo_k[j + 1], &occ->lo_dd[j + 1]);
        ts_window_lanes_put(L, j, &w);
    }
}
