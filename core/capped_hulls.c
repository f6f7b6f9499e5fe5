/* Lockstep blocks of capped lines through per-line window hulls; see
 * capped_hulls.h. */
#include <math.h>
#include <stdlib.h>

#include "capped_hulls.h"

int ts_cap_window_span(const int lags[4], int U)
{
    /* lags 0..lag_hi + 1 (the oldest leaves only when the step's window
     * slides), one more for rounding; no line has more than U samples */
    return (lags[1] < U ? lags[1] : U) + 3;
}

/* Slots per line at most: with ~100 bytes a slot (the sample, both hulls'
 * points and the undo record), ~27 MB per worker for a block of 65 lines;
 * longer windows stay line by line (process_line), which needs one. */
#ifndef CAP_HULLS_MAX_RING
#define CAP_HULLS_MAX_RING 4096
#endif

int ts_cap_hulls_fit(const int lags[4], int U)
{
    return ts_window_hull_ring(ts_cap_window_span(lags, U)) <= CAP_HULLS_MAX_RING;
}

int ts_cap_hulls_alloc(ts_cap_hulls *r, int lines, const int lags[4], int U, double cap)
{
    *r = (ts_cap_hulls){0};
    const int span = ts_cap_window_span(lags, U);
    r->ring = ts_window_hull_ring(span);
    r->cap = cap;
    r->win = calloc((size_t)lines, sizeof *r->win);
    r->raw = malloc((size_t)lines * r->ring * sizeof *r->raw);
    r->raw_n = calloc((size_t)lines, sizeof *r->raw_n);
    r->finger = calloc((size_t)lines, sizeof *r->finger);
    if (!r->win || !r->raw || !r->raw_n || !r->finger)
        return 0;
    r->lines = lines;
    int ok = 1;
    for (int j = 0; j < lines; j++)
        ok = ts_window_hull_alloc(&r->win[j], span) && ok;
    return ok;
}

void ts_cap_hulls_free(ts_cap_hulls *r)
{
    for (int j = 0; j < r->lines; j++)
        ts_window_hull_free(&r->win[j]);
    free(r->win);
    free(r->raw);
    free(r->raw_n);
    free(r->finger);
    *r = (ts_cap_hulls){0};
}

void ts_cap_hulls_clear(ts_cap_hulls *r)
{
    for (int j = 0; j < r->lines; j++) {
        ts_window_hull_reset(&r->win[j]);
        r->raw_n[j] = 0;
        r->finger[j][0][0] = r->finger[j][0][1] = r->finger[j][1][0] = r->finger[j][1][1] = 0;
    }
}

/* Line j at step s, as process_line does it. */
static inline void line_step(ts_cap_hulls *r, int j, const ts_lane_step *s,
                             const ts_lane_occluders *occ)
{
    const double c = s->c;
    const int mask = r->ring - 1;
    ts_window_hull *w = &r->win[j];
    ts_hull_pt *raw = r->raw + (size_t)j * r->ring;
    const double d = s->d[j];
    const float hs = s->hs[j], hc = s->hc[j], hn = s->hn[j];
    /* the sample enters the ring, then the window slides (the sample
     * itself is nearer than near_skip) */
    if (!isnan(hs))
        raw[r->raw_n[j]++ & mask] = (ts_hull_pt){d, hs - c * d * d, s->k};
    ts_window_hull_slide(w, raw, r->raw_n[j], d, s->near_skip, r->cap);
    const ts_hull_pt *hi = NULL, *lo = NULL;
    if (!isnan(hc) && j >= s->hi_from && j <= s->hi_to)
        hi = ts_window_hull_query(w, d, hc - c * d * d, r->finger[j][0]);
    if (!isnan(hn))
        lo = ts_window_hull_query(w, d, hn - c * d * d, r->finger[j][1]);
    occ->hi_k[j] = hi ? hi->k : -1;
    occ->hi_dd[j] = hi ? (float)(d - hi->d) : 0.0f;
    occ->lo_k[j + 1] = lo ? lo->k : -1;
    occ->lo_dd[j + 1] = lo ? (float)(d - lo->d) : 0.0f;
}

void ts_cap_hulls_run(ts_cap_hulls *r, const ts_lane_step *steps, const ts_lane_occluders *occ,
                      int n, int nl)
{
    /* line by line: a line's window stays in cache over the steps */
    for (int j = 0; j < nl; j++)
        for (int t = 0; t < n; t++)
            if (j >= steps[t].j0 && j <= steps[t].j1)
                line_step(r, j, &steps[t], &occ[t]);
}
