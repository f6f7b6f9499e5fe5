/* Row-wide upper bound of a capped sweep's ray stretches; see
 * cap_tail_bound.h. */
#include <math.h>

#include "cap_tail_bound.h"
#include "simd_clones.h"

/* Corner weights of the point (a, b) of a patch, clamped into it. */
static void corner_weights(double a, double b, float w[4])
{
    a = a < 0 ? 0 : a > 1 ? 1 : a;
    b = b < 0 ? 0 : b > 1 ? 1 : b;
    w[0] = (float)((1 - a) * (1 - b));
    w[1] = (float)(a * (1 - b));
    w[2] = (float)((1 - a) * b);
    w[3] = (float)(a * b);
}

/* How far x is from the nearest integer. */
static double off_integer(double x)
{
    return fabs(x - floor(x + 0.5));
}

/* ts_ray_exact's pieces of stretch [sa, sb] relative to the cell (its loop,
 * with v = i - t s taken at i = 0), checked against the stencil's; sets
 * s->exact only if they match and every floor and ceil of that loop is at
 * least 5e-10 from a jump, so that the cell's own index (rounding of
 * i - t s up to ~1e-10 for a row of 2^20 cells) cannot change them. */
static void exact_pieces(ts_cap_stencil *s, double sa, double sb, const int rr[2])
{
    const double t = s->t, gap = 5e-10;
    const int use_r1 = t != 0;
    int np = 0, ok = 1;
    double x = sa;
    while (ok && x < sb - 1e-12) {
        double nxt = floor(x + 1e-9) + 1;
        if (use_r1) {
            double v = -t * x;
            double w = t > 0 ? v - 1e-9 : v + 1e-9;
            ok &= off_integer(w) > gap;
            double vb = t > 0 ? ceil(w) - 1 : floor(w) + 1;
            double sv = -vb / t; /* (i - vb) / t, i - vb an integer */
            if (sv > x + 1e-9 && sv < nxt)
                nxt = sv;
        }
        double se = nxt < sb ? nxt : sb, mid = 0.5 * (x + se);
        ok &= off_integer(mid) > gap && (!use_r1 || off_integer(-t * mid) > gap);
        ok &= np < s->npieces && ceil(mid) == s->a0 && (!use_r1 || floor(-t * mid) == rr[np]);
        if (ok) {
            s->s[np][0] = x;
            s->s[np][1] = se;
            np++;
        }
        x = se;
    }
    s->exact = ok && np == s->npieces;
}

void ts_cap_stencil_init(ts_cap_stencil *s, const ts_line_geom *G, double sa, double sb,
                         double step, double c)
{
    *s = (ts_cap_stencil){0};
    if (!(sb > sa) || sa < 1)
        return;
    const int j = (int)floor(sa);
    const double t = fabs(G->t) <= 1e-12 ? 0.0 : G->t;
    /* where v (relative to the cell's) crosses a whole row inside (sa, sb) */
    double cut[3] = {sa, sb, sb};
    int ncut = 2;
    if (t != 0) {
        double va = -t * sa, vb = -t * sb, lo = va < vb ? va : vb, hi = va < vb ? vb : va;
        double r = floor(hi);
        if (r > lo && r < hi) {
            double sv = -r / t;
            if (sv > sa && sv < sb) {
                cut[1] = sv;
                cut[2] = sb;
                ncut = 3;
            }
        }
    }
    s->npieces = ncut - 1;
    int rr[2] = {0, 0};
    s->vlo = 1 << 30;
    s->vhi = -(1 << 30);
    for (int p = 0; p < s->npieces; p++) {
        double pa = cut[p], pb = cut[p + 1], mid = 0.5 * (pa + pb);
        int r = t != 0 ? (int)floor(-t * mid) : 0;
        int r1 = t != 0 ? r + 1 : r; /* along a row the second row weighs nothing */
        ptrdiff_t o = -(ptrdiff_t)(j + 1) * G->u_stride;
        s->off[p][0] = o + r * G->v_stride;
        s->off[p][1] = o + G->u_stride + r * G->v_stride;
        s->off[p][2] = o + r1 * G->v_stride;
        s->off[p][3] = o + G->u_stride + r1 * G->v_stride;
        for (int e = 0; e < 2; e++) {
            double se = e ? pb : pa;
            corner_weights(j + 1 - se, t != 0 ? -t * se - r : 0.0, s->w[p][e]);
        }
        s->bulge[p] = (float)(t * (pb - pa) * (pb - pa) * 0.25);
        s->b0[p] = -r;
        rr[p] = r;
        s->inv[p][0] = (float)(1.0 / (pa * step));
        s->inv[p][1] = (float)(1.0 / (pb * step));
        s->vlo = r < s->vlo ? r : s->vlo;
        s->vhi = r1 > s->vhi ? r1 : s->vhi;
    }
    s->jback = j + 1;
    s->drop = (float)(c * sa * step);
    s->a0 = j + 1;
    s->t = t;
    s->step = step;
    s->c = c;
    exact_pieces(s, sa, sb, rr);
}

void ts_cap_stencil_range(const ts_cap_stencil *s, const ts_line_geom *G, int width, int y,
                          int *xa, int *xb)
{
    *xa = *xb = 0;
    if (s->npieces == 0)
        return;
    int a = 0, b = width;
    if (G->x_major) { /* u = x, i = y */
        if (y + s->vlo < 0 || y + s->vhi > G->V - 1)
            return;
        if (G->u_step > 0)
            a = G->u_start + s->jback;
        else
            b = G->u_start - s->jback + 1;
    } else { /* u = y, i = x */
        if ((y - G->u_start) * G->u_step < s->jback)
            return;
        a = -s->vlo;
        b = width - s->vhi;
    }
    a = a < 0 ? 0 : a;
    b = b > width ? width : b;
    if (a < b) {
        *xa = a;
        *xb = b;
    }
}

/* The bound of one piece over a run of cells, merged into bound[] and
 * the nodata count into flag[]: plain float loops the compiler vectorises.
 * Along the chord, (h(s) - h) / s is monotonic, so its ends bound it; the
 * concave bulge and the rounding margin count at the nearer end. */
TS_SIMD_CLONES
static void piece_run(const float *restrict zrow, const ptrdiff_t off[4], const float wa[4],
                      const float wb[4], float tb, float inv_a, float inv_b, int xa, int xb,
                      float *restrict bound, float *restrict flag)
{
    const float *c00 = zrow + off[0], *c10 = zrow + off[1];
    const float *c01 = zrow + off[2], *c11 = zrow + off[3];
    const float a0 = wa[0], a1 = wa[1], a2 = wa[2], a3 = wa[3];
    const float b0 = wb[0], b1 = wb[1], b2 = wb[2], b3 = wb[3];
    for (int x = xa; x < xb; x++) {
        float h0 = c00[x], h1 = c10[x], h2 = c01[x], h3 = c11[x], h = zrow[x];
        float ea = a0 * h0 + a1 * h1 + a2 * h2 + a3 * h3;
        float eb = b0 * h0 + b1 * h1 + b2 * h2 + b3 * h3;
        float sa = (ea - h) * inv_a, sb = (eb - h) * inv_b;
        float bulge = -(h3 - h1 - h2 + h0) * tb;
        bulge = bulge > 0.0f ? bulge : 0.0f;
        /* float rounding of the heights here is a few ulp of them */
        float margin = 1e-2f + 1e-5f * (fabsf(ea) + fabsf(eb) + 2.0f * fabsf(h));
        float v = (sa > sb ? sa : sb) + (bulge + margin) * inv_a;
        float cur = bound[x];
        bound[x] = v > cur ? v : cur;
        flag[x] += (v != v) ? 1.0f : 0.0f;
    }
}

void ts_cap_stencil_row(const ts_cap_stencil *s, const float *zrow, int xa, int xb,
                        float *bound, float *flag)
{
    for (int x = xa; x < xb; x++) {
        bound[x] = -INFINITY;
        flag[x] = 0.0f;
    }
    for (int p = 0; p < s->npieces; p++)
        piece_run(zrow, s->off[p], s->w[p][0], s->w[p][1], s->bulge[p], s->inv[p][0],
                  s->inv[p][1], xa, xb, bound, flag);
    const float drop = s->drop;
    for (int x = xa; x < xb; x++) {
        float m = bound[x] - drop;
        m += 1e-5f * fabsf(m) + 1e-6f;
        bound[x] = flag[x] != 0.0f ? NAN : m;
    }
}
