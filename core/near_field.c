/* Exact near-field horizon on the bilinear surface; see near_field.h. */
#include <math.h>
#include <stdlib.h>

#include "near_field.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

void ts_near_plan_init(ts_near_plan *p, const ts_line_geom *g)
{
    p->t = g->t;
    /* Break points: whole steps (new column) and v crossing an integer. */
    double br[4 * TS_NEAR_EXACT + 4];
    int nb = 0;
    br[nb++] = 0.0;
    for (int j = 1; j <= TS_NEAR_EXACT; j++)
        br[nb++] = j;
    double at = fabs(g->t);
    if (at > 1e-12)
        for (int m = 1; m / at < TS_NEAR_EXACT - 1e-9 && nb < (int)(sizeof br / sizeof *br); m++)
            br[nb++] = m / at;
    qsort(br, nb, sizeof *br, cmp_double);
    p->npieces = 0;
    for (int j = 0; j + 1 < nb && p->npieces < TS_NEAR_MAX_PIECES; j++) {
        if (br[j + 1] - br[j] < 1e-9)
            continue;
        double mid = 0.5 * (br[j] + br[j + 1]);
        ts_near_piece *q = &p->piece[p->npieces++];
        q->sa = br[j];
        q->sb = br[j + 1];
        q->du = (int)floor(-mid);
        q->dv = at > 1e-12 ? (int)floor(-g->t * mid) : 0;
    }
    for (int n = 0; n < p->npieces; n++) {
        ptrdiff_t o = p->piece[n].du * g->u_stride + p->piece[n].dv * g->v_stride;
        p->piece_off[n][0] = o;
        p->piece_off[n][1] = o + g->u_stride;
        p->piece_off[n][2] = o + g->v_stride;
        p->piece_off[n][3] = o + g->u_stride + g->v_stride;
    }
    for (int j = 0; j <= TS_NEAR_STEPS; j++) {
        double v = -g->t * j, f = floor(v);
        p->sample_dv[j] = (int)f;
        p->sample_fv[j] = (float)(v - f);
        if (p->sample_fv[j] >= 1.0f) {
            p->sample_dv[j]++;
            p->sample_fv[j] = 0.0f;
        }
        p->sample_off[j][0] = -j * g->u_stride + p->sample_dv[j] * g->v_stride;
        p->sample_off[j][1] = p->sample_off[j][0] + g->v_stride;
    }
}

/* Max over s in [sa, sb] (sa > 0) of the slope to a patch's quadratic
 * h(s) = h0 + P + beta s + gamma s^2 along the ray. */
static double piece_max(double P, double beta, double gamma, double sa, double sb, double L,
                        double c);

/* Bilinear height at (a, b) of a patch from the corners that weigh
 * something there; NaN if one of those is nodata. */
static double edge_height(const float hc[4], double a, double b)
{
    const double eps = 1e-9;
    a = a < eps ? 0.0 : a > 1.0 - eps ? 1.0 : a;
    b = b < eps ? 0.0 : b > 1.0 - eps ? 1.0 : b;
    double w[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
    double sum = 0.0;
    for (int q = 0; q < 4; q++)
        if (w[q] > 0.0)
            sum += w[q] * hc[q]; /* a NaN corner makes the sum NaN */
    return sum;
}

static inline double slope_at(double P, double beta, double gamma, double s, double L, double c)
{
    return (P + beta * s + gamma * s * s) / (s * L) - c * s * L;
}

float ts_near_field(const ts_near_plan *p, const ts_line_geom *g, const float *z, int k,
                    int i, float h, double step, double c, double cap, int *left)
{
    double smax = cap > 0 ? cap / step : INFINITY; /* in steps */
    double best = -INFINITY;
    *left = 0;
    const int V = g->V;
    for (int n = 0; n < p->npieces; n++) {
        const ts_near_piece *q = &p->piece[n];
        int k0 = k + q->du, r0 = i + q->dv;
        int flat_v = fabs(p->t) <= 1e-12; /* b == 0 along the whole ray */
        if (k0 < 0 || r0 < 0 || r0 > V - 1 || (!flat_v && r0 + 1 > V - 1)) {
            *left = 1;
            break;
        }
        ptrdiff_t o = g->origin + (ptrdiff_t)k0 * g->u_stride + (ptrdiff_t)r0 * g->v_stride;
        if (q->sa >= smax)
            break;
        /* corners: 00 = (k0, r0), 10 = (k0 + 1, r0), 01 = (k0, r0 + 1), 11;
         * along a grid line (t = 0) the 01 and 11 corners weigh nothing. */
        int use_r1 = !flat_v && r0 + 1 <= V - 1;
        float hc[4] = {z[o], z[o + g->u_stride], use_r1 ? z[o + g->v_stride] : z[o],
                       use_r1 ? z[o + g->u_stride + g->v_stride] : z[o + g->u_stride]};
        double sb = q->sb < smax ? q->sb : smax;
        /* local coordinates in the patch: a = a0 - s, b = b0 - t s */
        double a0 = -q->du, b0 = flat_v ? 0.0 : -q->dv;
        /* The surface exists only on patches with four valid corners:
         * nodata is no terrain, so a patch touching it is skipped, but for
         * its end points on a grid line, whose only corners may be valid. */
        if (isnan(hc[0]) || isnan(hc[1]) || isnan(hc[2]) || isnan(hc[3])) {
            double ends[2] = {q->sa, sb};
            for (int e = 0; e < 2; e++) {
                double se = ends[e];
                if (se <= 0)
                    continue;
                double he = edge_height(hc, a0 - se, b0 - (flat_v ? 0.0 : p->t) * se);
                if (!isnan(he)) {
                    double sl = (he - h) / (se * step) - c * se * step;
                    best = sl > best ? sl : best;
                }
            }
            continue;
        }
        double A = hc[1] - hc[0], B = hc[2] - hc[0], X = hc[3] - hc[1] - hc[2] + hc[0];
        double t = flat_v ? 0.0 : p->t;
        double alpha = hc[0] + A * a0 + B * b0 + X * a0 * b0;
        double beta = -(A + B * t + X * (a0 * t + b0));
        double gamma = X * t;
        double P = alpha - h;
        double L = step;
        double fb = slope_at(P, beta, gamma, sb, L, c);
        double fa = q->sa > 0 ? slope_at(P, beta, gamma, q->sa, L, c) : beta / L;
        double m = fa > fb ? fa : fb;
        double g2 = gamma - c * L * L;
        if (q->sa > 0 && P < 0 && g2 < 0) {
            double ss = sqrt(P / g2);
            if (ss > q->sa && ss < sb) {
                double fs = slope_at(P, beta, gamma, ss, L, c);
                m = fs > m ? fs : m;
            }
        }
        best = m > best ? m : best;
    }
    if (*left)
        return (float)best;
    /* Whole steps beyond the exact cells: linear along the column. */
    for (int j = TS_NEAR_EXACT + 1; j <= TS_NEAR_STEPS && j <= smax; j++) {
        int kk = k - j, r0 = i + p->sample_dv[j];
        float f = p->sample_fv[j];
        if (kk < 0 || r0 < 0 || r0 > V - 1 || (f > 0.0f && r0 + 1 > V - 1)) {
            *left = 1;
            break;
        }
        ptrdiff_t o = g->origin + (ptrdiff_t)kk * g->u_stride + (ptrdiff_t)r0 * g->v_stride;
        float va = z[o], vb = f > 0.0f ? z[o + g->v_stride] : va;
        float hj = va + f * (vb - va); /* NaN if either cell is nodata */
        if (isnan(hj))
            continue;
        double d = j * step;
        double s = (hj - h) / d - c * d;
        best = s > best ? s : best;
    }
    return (float)best;
}

/* One piece over a run of cells: plain float arithmetic in a loop the
 * compiler vectorises. NaN corners make the slope NaN, which the
 * comparison ignores; such cells are flagged and redone in scalar code. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
static void near_run(const ts_near_plan *p, const float *restrict zrow, int x0, int x1,
                     float L, float c, float *restrict best, float *restrict flag)
{
    for (int x = x0; x < x1; x++) {
        best[x] = -INFINITY;
        flag[x] = 0.0f;
    }
    const float t = (float)p->t;
    for (int n = 0; n < p->npieces; n++) {
        const ts_near_piece *q = &p->piece[n];
        const float *restrict c00 = zrow + p->piece_off[n][0];
        const float *restrict c10 = zrow + p->piece_off[n][1];
        const float *restrict c01 = zrow + p->piece_off[n][2];
        const float *restrict c11 = zrow + p->piece_off[n][3];
        const float a0 = (float)-q->du, b0 = fabs(p->t) <= 1e-12 ? 0.0f : (float)-q->dv;
        const float sa = (float)q->sa, sb = (float)q->sb;
        const float inv_b = 1.0f / (sb * L), cb = c * sb * L, cLL = c * L * L, invL = 1.0f / L;
        /* fa = P * ka + beta * kb + gamma * kc - ca; at s = 0 it is the limit
         * beta / L, since P is 0 there. */
        const int has_sa = sa > 0;
        const float ka = has_sa ? 1.0f / (sa * L) : 0.0f;
        const float kb = has_sa ? sa * ka : invL, kc = has_sa ? sa * sa * ka : 0.0f;
        const float ca = has_sa ? c * sa * L : 0.0f;
        for (int x = x0; x < x1; x++) {
            float h = zrow[x];
            float A = c10[x] - c00[x], B = c01[x] - c00[x];
            float X = c11[x] - c10[x] - c01[x] + c00[x];
            float alpha = c00[x] + A * a0 + B * b0 + X * a0 * b0;
            float beta = -(A + B * t + X * (a0 * t + b0));
            float gamma = X * t;
            float P = alpha - h;
            float fb = (P + beta * sb + gamma * sb * sb) * inv_b - cb;
            float fa = P * ka + beta * kb + gamma * kc - ca;
            float m = fa > fb ? fa : fb;
            float g2 = gamma - cLL;
            float r = P / g2;
            float ss = sqrtf(r > 0.0f ? r : 0.0f);
            float sd = ss > 0.0f ? ss : 1.0f;
            float fs = (P / sd + beta + gamma * ss) * invL - c * ss * L;
            int inner = has_sa & (P < 0.0f) & (g2 < 0.0f) & (ss > sa) & (ss < sb) & (fs > m);
            m = inner ? fs : m;
            best[x] = m > best[x] ? m : best[x];
            flag[x] += (m != m) ? 1.0f : 0.0f;
        }
    }
    for (int j = TS_NEAR_EXACT + 1; j <= TS_NEAR_STEPS; j++) {
        const float *restrict sa_ = zrow + p->sample_off[j][0];
        const float *restrict sb_ = zrow + p->sample_off[j][1];
        const float f = p->sample_fv[j], d = (float)j * L, invd = 1.0f / d, cd = c * d;
        for (int x = x0; x < x1; x++) {
            float hj = sa_[x] + f * (sb_[x] - sa_[x]);
            float s = (hj - zrow[x]) * invd - cd;
            best[x] = s > best[x] ? s : best[x];
            flag[x] += (s != s) ? 1.0f : 0.0f;
        }
    }
}

void ts_near_row(const ts_near_plan *p, const ts_line_geom *g, const float *z,
                 const float *zrow, int y, int x0, int x1, double step, double c,
                 float *out, float *scratch)
{
    float *best = scratch, *flag = scratch + x1;
    near_run(p, zrow, x0, x1, (float)step, (float)c, best, flag);
    for (int x = x0; x < x1; x++) {
        if (isnan(zrow[x]))
            continue;
        float nf = best[x];
        if (flag[x] != 0.0f) {
            int u = g->x_major ? x : y, v = g->x_major ? y : x;
            int left;
            nf = ts_near_field(p, g, z, (u - g->u_start) * g->u_step, v, zrow[x], step, c, 0.0,
                               &left);
        }
        out[x] = nf > out[x] ? nf : out[x];
    }
}

static inline double slope_of(double P, double beta, double gamma, double s, double L, double c)
{
    return (P + beta * s + gamma * s * s) / (s * L) - c * s * L;
}

static double piece_max(double P, double beta, double gamma, double sa, double sb, double L,
                        double c)
{
    double fa = slope_of(P, beta, gamma, sa, L, c), fb = slope_of(P, beta, gamma, sb, L, c);
    double m = fa > fb ? fa : fb;
    double g2 = gamma - c * L * L;
    if (P < 0 && g2 < 0) {
        double ss = sqrt(P / g2);
        if (ss > sa && ss < sb) {
            double fs = slope_of(P, beta, gamma, ss, L, c);
            m = fs > m ? fs : m;
        }
    }
    return m;
}

float ts_ray_exact(const ts_line_geom *g, const float *z, int k, int i, float h, double s_from,
                   double s_to, double step, double c)
{
    const double t = g->t, at = fabs(t);
    double best = -INFINITY;
    double s = s_from;
    while (s < s_to - 1e-12) {
        /* next break point: a whole step, or v crossing an integer */
        double nxt = floor(s + 1e-9) + 1.0;
        if (at > 1e-12) {
            double v = i - t * s;
            double vb = t > 0 ? ceil(v - 1e-9) - 1.0 : floor(v + 1e-9) + 1.0;
            double sv = (i - vb) / t;
            if (sv > s + 1e-9 && sv < nxt)
                nxt = sv;
        }
        double se = nxt < s_to ? nxt : s_to, mid = 0.5 * (s + se);
        int k0 = (int)floor(k - mid), r0 = at > 1e-12 ? (int)floor(i - t * mid) : i;
        int use_r1 = at > 1e-12;
        if (k0 < 0 || r0 < 0 || r0 > g->V - 1 || (use_r1 && r0 + 1 > g->V - 1))
            break; /* the ray leaves the grid */
        ptrdiff_t o = g->origin + (ptrdiff_t)k0 * g->u_stride + (ptrdiff_t)r0 * g->v_stride;
        double h00 = z[o], h10 = z[o + g->u_stride];
        double h01 = use_r1 ? z[o + g->v_stride] : h00;
        double h11 = use_r1 ? z[o + g->u_stride + g->v_stride] : h10;
        if (!isnan(h00 + h10 + h01 + h11)) {
            double a0 = k - k0, b0 = use_r1 ? i - r0 : 0.0, tt = use_r1 ? t : 0.0;
            double A = h10 - h00, B = h01 - h00, X = h11 - h10 - h01 + h00;
            double alpha = h00 + A * a0 + B * b0 + X * a0 * b0;
            double beta = -(A + B * tt + X * (a0 * tt + b0)), gamma = X * tt;
            double m = piece_max(alpha - h, beta, gamma, s > 0 ? s : 1e-9, se, step, c);
            best = m > best ? m : best;
        } else {
            /* nodata patch: only its valid end points on grid lines */
            double ends[2] = {s, se};
            double hc[4] = {h00, h10, h01, h11};
            for (int e = 0; e < 2; e++) {
                if (ends[e] <= 0)
                    continue;
                float hf[4] = {(float)hc[0], (float)hc[1], (float)hc[2], (float)hc[3]};
                double he = edge_height(hf, (k - ends[e]) - k0,
                                        use_r1 ? (i - t * ends[e]) - r0 : 0.0);
                if (!isnan(he)) {
                    double sl = (he - h) / (ends[e] * step) - c * ends[e] * step;
                    best = sl > best ? sl : best;
                }
            }
        }
        s = se;
    }
    return (float)best;
}
