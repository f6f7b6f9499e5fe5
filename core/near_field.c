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
    for (int j = 0; j <= TS_NEAR_STEPS; j++) {
        double v = -g->t * j, f = floor(v);
        p->sample_dv[j] = (int)f;
        p->sample_fv[j] = (float)(v - f);
        if (p->sample_fv[j] >= 1.0f) {
            p->sample_dv[j]++;
            p->sample_fv[j] = 0.0f;
        }
    }
}

static inline double slope_at(double P, double beta, double gamma, double s, double L, double c)
{
    return (P + beta * s + gamma * s * s) / (s * L) - c * s * L;
}

/* Height at s on a patch with NaN corners: bilinear over valid corners. */
static double patch_height_nan(const float hc[4], double a, double b)
{
    double w[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
    double sum = 0, ws = 0;
    for (int q = 0; q < 4; q++)
        if (w[q] > 0 && !isnan(hc[q])) {
            sum += w[q] * hc[q];
            ws += w[q];
        }
    return ws > 0 ? sum / ws : NAN;
}

float ts_near_field(const ts_near_plan *p, const ts_line_geom *g, const float *z, int k,
                    int i, float h, double step, double c, int *left)
{
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
        int has_r1 = r0 + 1 <= V - 1;
        /* corners: 00 = (k0, r0), 10 = (k0 + 1, r0), 01 = (k0, r0 + 1), 11 */
        float hc[4] = {z[o], z[o + g->u_stride], has_r1 ? z[o + g->v_stride] : z[o],
                       has_r1 ? z[o + g->u_stride + g->v_stride] : z[o + g->u_stride]};
        /* local coordinates in the patch: a = a0 - s, b = b0 - t s */
        double a0 = -q->du, b0 = flat_v ? 0.0 : -q->dv;
        if (isnan(hc[0]) || isnan(hc[1]) || isnan(hc[2]) || isnan(hc[3])) {
            double hb = patch_height_nan(hc, a0 - q->sb, b0 - p->t * q->sb);
            if (!isnan(hb)) {
                double s = (hb - h) / (q->sb * step) - c * q->sb * step;
                best = s > best ? s : best;
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
        double fb = slope_at(P, beta, gamma, q->sb, L, c);
        double fa = q->sa > 0 ? slope_at(P, beta, gamma, q->sa, L, c) : beta / L;
        double m = fa > fb ? fa : fb;
        double g2 = gamma - c * L * L;
        if (q->sa > 0 && P < 0 && g2 < 0) {
            double ss = sqrt(P / g2);
            if (ss > q->sa && ss < q->sb) {
                double fs = slope_at(P, beta, gamma, ss, L, c);
                m = fs > m ? fs : m;
            }
        }
        best = m > best ? m : best;
    }
    if (*left)
        return (float)best;
    /* Whole steps beyond the exact cells: linear along the column. */
    for (int j = TS_NEAR_EXACT + 1; j <= TS_NEAR_STEPS; j++) {
        int kk = k - j, r0 = i + p->sample_dv[j];
        float f = p->sample_fv[j];
        if (kk < 0 || r0 < 0 || r0 > V - 1 || (f > 0.0f && r0 + 1 > V - 1)) {
            *left = 1;
            break;
        }
        ptrdiff_t o = g->origin + (ptrdiff_t)kk * g->u_stride + (ptrdiff_t)r0 * g->v_stride;
        float va = z[o], vb = f > 0.0f ? z[o + g->v_stride] : NAN;
        float hj = isnan(vb) ? va : isnan(va) ? vb : va + f * (vb - va);
        if (isnan(hj))
            continue;
        double d = j * step;
        double s = (hj - h) / d - c * d;
        best = s > best ? s : best;
    }
    return (float)best;
}
