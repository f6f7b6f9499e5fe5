/*
 * Exact horizon sweep: a port of core/horizon_sweep.c and core/near_field.c.
 *
 * Pass 1 (ts_sweep_lines): one work-item per sweep line, lines of several
 * azimuths in one launch. Each keeps its convex hull in a stack of (d, g)
 * points (and their step indices k) in global memory, interleaved across
 * work-items (entry j of slot s at j * nslots + s) so that neighbouring
 * work-items touch neighbouring memory. For every sample k of the line
 * (cell i below it, cell i + 1 above it) it writes the far-field occluder
 * the hull finds (its step index and distance, as int2 (k, bits of dd)):
 *   hi[cell i]     from the height of cell i (the C code's `hi`),
 *   lo[cell i + 1] from the height of cell i + 1 (the C code's cur_lo,
 *                  which the next line reads as its `lo`).
 * The C code hands cur_lo from one line to the next in a loop; here it
 * waits in `lo` for pass 2, so the lines are independent.
 *
 * Pass 2 (ts_sweep_finish): one work-item per cell and azimuth: the far
 * field (the cell's own ray sampled at both occluders and TS_FAR_SPREAD
 * steps beside them; past the distance cap, the exact march of
 * ts_ray_exact), the exact near field (the float fast path of ts_near_row
 * for interior cells without a distance cap, ts_near_field in `real`
 * elsewhere and for cells whose fast path met nodata), the larger of the
 * two, in degrees.
 */

/* ---------------------------------------------------------- line geometry */

/* Smallest k with the predicate true (port of first_k, line_geometry.c). */
int ts_first_k(__global const int *fl, int U, int asc, long lim, int want_ge)
{
    int lo = 0, hi = U;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        long v = fl[mid];
        int p = want_ge ? (asc ? v >= lim : v <= lim) : (asc ? v > lim : v < lim);
        if (p)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* ts_line_k_range. */
int ts_k_range(__global const int *fl, int U, int V, real t, long b, int *k0, int *k1)
{
    int asc = t >= 0;
    long lo = -b, hi = (long)V - 1 - b;
    int a, z;
    if (asc) {
        a = ts_first_k(fl, U, 1, lo, 1);
        z = ts_first_k(fl, U, 1, hi, 0) - 1;
    } else {
        a = ts_first_k(fl, U, 0, hi, 1);
        z = ts_first_k(fl, U, 0, lo, 0) - 1;
    }
    if (a > z || a >= U || z < 0)
        return 0;
    *k0 = a;
    *k1 = z;
    return 1;
}

/* ------------------------------------------------------------------ hull */

/* hull_query: the far-field occluder of (d, h) among hull points 0..far:
 * (its step index, bits of its distance); k = -1 when there is none. */
int2 ts_hull_query(__global const real2 *S, __global const int *SK, long ns, int far, real d,
                   float h, real c)
{
    if (far < 0)
        return (int2)(-1, 0);
    real g = h - c * d * d;
    int j = far;
    real2 sj = S[j * ns];
    while (j > 0) {
        real2 sp = S[(j - 1) * ns];
        if (!((sp.y - g) * (d - sj.x) >= (sj.y - g) * (d - sp.x)))
            break;
        j--;
        sj = sp;
    }
    return (int2)(SK[j * ns], as_int((float)(d - sj.x)));
}

/*
 * Pass 1. Work-item `slot` processes line item0 + slot of the batch; the
 * lines of azimuth a are items ip[a][LINE0] .. (next azimuth's LINE0) - 1.
 * stack / stack_k hold nslots interleaved stacks of (longest line + 1)
 * entries.
 */
__kernel void ts_sweep_lines(__global const float *z, const int W, const int naz,
                             __global const int *ip, __global const real *dp,
                             __global const int *fl_all, __global const float *fr_all,
                             __global const real *sr_all, const int item0, const int nitems,
                             const real c, __global int2 *hi, __global int2 *lo,
                             const long plane, __global real2 *stack, __global int *stack_k,
                             const int nslots)
{
    const int slot = (int)get_global_id(0);
    const int item = item0 + slot;
    if (slot >= nslots || item >= nitems)
        return;
    int a = 0;
    while (a + 1 < naz && ip[(a + 1) * TS_CLI_N + TS_CLI_LINE0] <= item)
        a++;
    __global const int *P = ip + a * TS_CLI_N;
    __global const real *Q = dp + a * TS_CLD_N;
    const int xm = P[TS_CLI_XMAJOR], U = P[TS_CLI_U], V = P[TS_CLI_V];
    const int u_start = P[TS_CLI_USTART], u_step = P[TS_CLI_USTEP];
    const long su = xm ? 1 : W;
    const long u_stride = su * u_step, v_stride = xm ? W : 1, origin = su * u_start;
    __global const int *fl = fl_all + P[TS_CLI_FLOFF];
    __global const float *fr = fr_all + P[TS_CLI_FLOFF];
    const int sroff = P[TS_CLI_SROFF];
    const real t = Q[TS_CLD_T], step_m = Q[TS_CLD_STEPM], near_skip = Q[TS_CLD_NEARSKIP];
    const long b = (long)P[TS_CLI_BLO] + (item - P[TS_CLI_LINE0]);
    int k0, k1;
    if (!ts_k_range(fl, U, V, t, b, &k0, &k1))
        return;
    __global int2 *oh = hi + P[TS_CLI_PLANE] * plane;
    __global int2 *ol = lo + P[TS_CLI_PLANE] * plane;
    const long ns = nslots;
    __global real2 *S = stack + slot;
    __global int *SK = stack_k + slot;
    const int2 none = (int2)(-1, 0);
    real d = 0;
    int n = 0, far = -1;
    for (int k = k0; k <= k1; k++) {
        int i = (int)(b + fl[k]);
        float F = fr[k];
        long p = origin + (long)k * u_stride + (long)i * v_stride;
        int has_next = F > 0.0f && i + 1 < V;
        float hc = z[p];
        float hn = has_next ? z[p + v_stride] : NAN;
        if (sroff >= 0) {
            if (k > k0) {
                int row = xm ? i : u_start + k * u_step;
                d += sr_all[sroff + row];
            }
        } else {
            d = (real)(k - k0) * step_m;
        }
        int inside = F == 0.0f || has_next;
        float hs; /* NaN when either cell is nodata: no occluder */
        if (!inside)
            hs = NAN;
        else if (F == 0.0f)
            hs = hc;
        else
            hs = hc + F * (hn - hc);

        int pushed = 0;
        if (!isnan(hs)) {
            real gs = hs - c * d * d;
            while (n >= 2) {
                real2 s2 = S[(n - 2) * ns], s1 = S[(n - 1) * ns];
                if (!((s2.y - gs) * (d - s1.x) >= (s1.y - gs) * (d - s2.x)))
                    break;
                n--;
            }
            if (far > n - 1)
                far = n - 1;
            while (far + 1 < n && d - S[(far + 1) * ns].x >= near_skip)
                far++;
            S[n * ns] = (real2)(d, gs);
            SK[n * ns] = k;
            n++;
            pushed = 1;
        }
        if (!pushed)
            while (far + 1 < n && d - S[(far + 1) * ns].x >= near_skip)
                far++;
        oh[p] = (!isnan(hc) && inside) ? ts_hull_query(S, SK, ns, far, d, hc, c) : none;
        if (has_next)
            ol[p + v_stride] = isnan(hn) ? none : ts_hull_query(S, SK, ns, far, d, hn, c);
    }
}

/* ------------------------------------------------------------- far field */

/* Steps on either side of a line's occluder at which the cell's ray is also
 * sampled (FAR_SPREAD of horizon_sweep.c). */
#ifndef TS_FAR_SPREAD
#define TS_FAR_SPREAD 0
#endif

float ts_ray_exact(__global const float *z, int V, real t, long origin, long u_stride,
                   long v_stride, int k, int i, float h, real s_from, real s_to, real step,
                   real c);

/* ray_slope: slope from cell (k, i) at height h to its own ray dk steps
 * back (distance dd); -inf off the grid or on nodata. */
float ts_ray_slope(__global const float *z, int V, real t, long origin, long u_stride,
                   long v_stride, int k, int i, float h, int dk, float dd, float cf)
{
    int kk = k - dk;
    if (dk <= 0 || kk < 0 || dd <= 0.0f)
        return -INFINITY;
    real pv = -t * dk, o = floor(pv);
    int r0 = i + (int)o;
    float f = (float)(pv - o);
    if (r0 < 0 || r0 > V - 1 || (f > 0.0f && r0 + 1 > V - 1))
        return -INFINITY;
    __global const float *zz = z + origin + (long)kk * u_stride + (long)r0 * v_stride;
    float a = zz[0], b = f > 0.0f ? zz[v_stride] : a;
    float hz = a + f * (b - a);
    if (isnan(hz))
        return -INFINITY;
    return (hz - h) / dd - cf * dd;
}

/* far_field: the cell's own ray at and beside the two lines' occluders;
 * when one lies past the distance cap, the exact ray over the far part of
 * the radius instead (ts_ray_exact). */
float ts_far_field(__global const float *z, int V, real t, long origin, long u_stride,
                   long v_stride, int k, int i, float h, int2 lo, int2 hi, real step, real c,
                   real cap)
{
    float best = -INFINITY;
    int beyond_cap = 0;
    const float cf = (float)c;
    for (int cc = 0; cc < 2; cc++) {
        int2 cand = cc ? hi : lo;
        if (cand.x < 0 || (cc == 1 && hi.x == lo.x))
            continue;
        int dk = k - cand.x;
        beyond_cap |= cap > 0 && as_float(cand.y) > cap;
        for (int e = -TS_FAR_SPREAD; e <= TS_FAR_SPREAD; e++) {
            if (dk + e <= TS_NEAR_STEPS)
                continue;
            float s = ts_ray_slope(z, V, t, origin, u_stride, v_stride, k, i, h, dk + e,
                                   as_float(cand.y) + (float)(e * step), cf);
            best = s > best ? s : best;
        }
    }
    if (!beyond_cap)
        return best;
    return ts_ray_exact(z, V, t, origin, u_stride, v_stride, k, i, h, TS_NEAR_EXACT,
                        cap / step, step, c);
}

/* ------------------------------------------------------------ near field */

/* edge_height of near_field.c: bilinear height at (a, b) from the corners
 * that weigh something there; NaN if one of those is nodata. */
real ts_edge_height(float h0, float h1, float h2, float h3, real a, real b)
{
    const real eps = RC(1e-9);
    a = a < eps ? (real)0 : a > 1 - eps ? (real)1 : a;
    b = b < eps ? (real)0 : b > 1 - eps ? (real)1 : b;
    const real w0 = (1 - a) * (1 - b), w1 = a * (1 - b), w2 = (1 - a) * b, w3 = a * b;
    real sum = 0;
    if (w0 > 0)
        sum += w0 * h0; /* a NaN corner makes the sum NaN */
    if (w1 > 0)
        sum += w1 * h1;
    if (w2 > 0)
        sum += w2 * h2;
    if (w3 > 0)
        sum += w3 * h3;
    return sum;
}

real ts_slope_at(real P, real beta, real gamma, real s, real L, real c)
{
    return (P + beta * s + gamma * s * s) / (s * L) - c * s * L;
}

/* ts_near_field: exact near field of cell (k, i) at height h, within the
 * distance cap (0 = none). */
float ts_near_exact(__global const float *z, __global const int *P, __global const real *Q,
                    long origin, long u_stride, long v_stride, int k, int i, float h,
                    real step, real c, real cap, int *left)
{
    const real smax = cap > 0 ? cap / step : (real)INFINITY; /* in steps */
    real best = -INFINITY;
    *left = 0;
    const int V = P[TS_CLI_V];
    const real pt = Q[TS_CLD_T];
    const int npieces = P[TS_CLI_NPIECES];
    for (int n = 0; n < npieces; n++) {
        const int du = P[TS_CLI_PDU + n], dv = P[TS_CLI_PDV + n];
        const real sa = Q[TS_CLD_PSA + n], sb = Q[TS_CLD_PSB + n];
        int k0 = k + du, r0 = i + dv;
        int flat_v = fabs(pt) <= RC(1e-12);
        if (k0 < 0 || r0 < 0 || r0 > V - 1 || (!flat_v && r0 + 1 > V - 1)) {
            *left = 1;
            break;
        }
        long o = origin + (long)k0 * u_stride + (long)r0 * v_stride;
        if (sa >= smax)
            break;
        /* along a grid line (t = 0) the 01 and 11 corners weigh nothing */
        int use_r1 = !flat_v && r0 + 1 <= V - 1;
        float hc0 = z[o], hc1 = z[o + u_stride];
        float hc2 = use_r1 ? z[o + v_stride] : z[o];
        float hc3 = use_r1 ? z[o + u_stride + v_stride] : z[o + u_stride];
        const real sbc = sb < smax ? sb : smax;
        real a0 = -du, b0 = flat_v ? (real)0 : (real)-dv;
        /* nodata is no terrain: a patch touching it is skipped, but for its
         * end points on a grid line, whose only corners may be valid */
        if (isnan(hc0) || isnan(hc1) || isnan(hc2) || isnan(hc3)) {
            for (int e = 0; e < 2; e++) {
                const real se = e ? sbc : sa;
                if (se <= 0)
                    continue;
                real he = ts_edge_height(hc0, hc1, hc2, hc3, a0 - se,
                                         b0 - (flat_v ? (real)0 : pt) * se);
                if (!isnan(he)) {
                    real sl = (he - h) / (se * step) - c * se * step;
                    best = sl > best ? sl : best;
                }
            }
            continue;
        }
        real A = hc1 - hc0, B = hc2 - hc0, X = hc3 - hc1 - hc2 + hc0;
        real t = flat_v ? (real)0 : pt;
        real alpha = hc0 + A * a0 + B * b0 + X * a0 * b0;
        real beta = -(A + B * t + X * (a0 * t + b0));
        real gamma = X * t;
        real Pp = alpha - h;
        real L = step;
        real fb = ts_slope_at(Pp, beta, gamma, sbc, L, c);
        real fa = sa > 0 ? ts_slope_at(Pp, beta, gamma, sa, L, c) : beta / L;
        real m = fa > fb ? fa : fb;
        real g2 = gamma - c * L * L;
        if (sa > 0 && Pp < 0 && g2 < 0) {
            real ss = sqrt(Pp / g2);
            if (ss > sa && ss < sbc) {
                real fs = ts_slope_at(Pp, beta, gamma, ss, L, c);
                m = fs > m ? fs : m;
            }
        }
        best = m > best ? m : best;
    }
    if (*left)
        return (float)best;
    for (int j = TS_NEAR_EXACT + 1; j <= TS_NEAR_STEPS && j <= smax; j++) {
        int kk = k - j, r0 = i + P[TS_CLI_SDV + j];
        float f = (float)Q[TS_CLD_SFV + j];
        if (kk < 0 || r0 < 0 || r0 > V - 1 || (f > 0.0f && r0 + 1 > V - 1)) {
            *left = 1;
            break;
        }
        long o = origin + (long)kk * u_stride + (long)r0 * v_stride;
        float va = z[o], vb = f > 0.0f ? z[o + v_stride] : va;
        float hj = va + f * (vb - va); /* NaN if either cell is nodata */
        if (isnan(hj))
            continue;
        real d = j * step;
        real s = (hj - h) / d - c * d;
        best = s > best ? s : best;
    }
    return (float)best;
}

/* piece_max of near_field.c: max over s in [sa, sb] of the slope to a
 * patch's quadratic along the ray. */
real ts_piece_max(real P, real beta, real gamma, real sa, real sb, real L, real c)
{
    real fa = ts_slope_at(P, beta, gamma, sa, L, c), fb = ts_slope_at(P, beta, gamma, sb, L, c);
    real m = fa > fb ? fa : fb;
    real g2 = gamma - c * L * L;
    if (P < 0 && g2 < 0) {
        real ss = sqrt(P / g2);
        if (ss > sa && ss < sb) {
            real fs = ts_slope_at(P, beta, gamma, ss, L, c);
            m = fs > m ? fs : m;
        }
    }
    return m;
}

/* ts_ray_exact: the largest slope from cell (k, i) at height h over its ray
 * between s_from and s_to steps, on the exact bilinear surface, patch by
 * patch; -inf if nothing there. */
float ts_ray_exact(__global const float *z, int V, real t, long origin, long u_stride,
                   long v_stride, int k, int i, float h, real s_from, real s_to, real step,
                   real c)
{
    const real at = fabs(t);
    real best = -INFINITY;
    real s = s_from;
    while (s < s_to - RC(1e-12)) {
        real nxt = floor(s + RC(1e-9)) + 1;
        if (at > RC(1e-12)) {
            real v = i - t * s;
            real vb = t > 0 ? ceil(v - RC(1e-9)) - 1 : floor(v + RC(1e-9)) + 1;
            real sv = (i - vb) / t;
            if (sv > s + RC(1e-9) && sv < nxt)
                nxt = sv;
        }
        real se = nxt < s_to ? nxt : s_to, mid = RC(0.5) * (s + se);
        int k0 = (int)floor(k - mid), r0 = at > RC(1e-12) ? (int)floor(i - t * mid) : i;
        int use_r1 = at > RC(1e-12);
        if (k0 < 0 || r0 < 0 || r0 > V - 1 || (use_r1 && r0 + 1 > V - 1))
            break; /* the ray leaves the grid */
        long o = origin + (long)k0 * u_stride + (long)r0 * v_stride;
        real h00 = z[o], h10 = z[o + u_stride];
        real h01 = use_r1 ? (real)z[o + v_stride] : h00;
        real h11 = use_r1 ? (real)z[o + u_stride + v_stride] : h10;
        if (!isnan(h00 + h10 + h01 + h11)) {
            real a0 = k - k0, b0 = use_r1 ? (real)(i - r0) : (real)0, tt = use_r1 ? t : (real)0;
            real A = h10 - h00, B = h01 - h00, X = h11 - h10 - h01 + h00;
            real alpha = h00 + A * a0 + B * b0 + X * a0 * b0;
            real beta = -(A + B * tt + X * (a0 * tt + b0)), gamma = X * tt;
            real m = ts_piece_max(alpha - h, beta, gamma, s > 0 ? s : RC(1e-9), se, step, c);
            best = m > best ? m : best;
        } else {
            /* nodata patch: only its valid end points on grid lines */
            for (int e = 0; e < 2; e++) {
                real end = e ? se : s;
                if (end <= 0)
                    continue;
                real he = ts_edge_height((float)h00, (float)h10, (float)h01, (float)h11,
                                         (k - end) - k0, use_r1 ? (i - t * end) - r0 : (real)0);
                if (!isnan(he)) {
                    real sl = (he - h) / (end * step) - c * end * step;
                    best = sl > best ? sl : best;
                }
            }
        }
        s = se;
    }
    return (float)best;
}

/* The float fast path of near_run (near_field.c) for one interior cell:
 * same expressions in the same order. *flag: a NaN was met. */
float ts_near_fast(__global const float *zc, __global const int *P, __global const real *Q,
                   long u_stride, long v_stride, float h, float L, float c, int *flag)
{
    float best = -INFINITY, nans = 0.0f;
    const real pt = Q[TS_CLD_T];
    const float t = (float)pt;
    const int npieces = P[TS_CLI_NPIECES];
    for (int n = 0; n < npieces; n++) {
        const int du = P[TS_CLI_PDU + n], dv = P[TS_CLI_PDV + n];
        long o = (long)du * u_stride + (long)dv * v_stride;
        float c00 = zc[o], c10 = zc[o + u_stride], c01 = zc[o + v_stride];
        float c11 = zc[o + u_stride + v_stride];
        const float a0 = (float)-du, b0 = fabs(pt) <= RC(1e-12) ? 0.0f : (float)-dv;
        const float sa = (float)Q[TS_CLD_PSA + n], sb = (float)Q[TS_CLD_PSB + n];
        const float inv_b = 1.0f / (sb * L), cb = c * sb * L, cLL = c * L * L, invL = 1.0f / L;
        const int has_sa = sa > 0;
        const float ka = has_sa ? 1.0f / (sa * L) : 0.0f;
        const float kb = has_sa ? sa * ka : invL, kc = has_sa ? sa * sa * ka : 0.0f;
        const float ca = has_sa ? c * sa * L : 0.0f;
        float A = c10 - c00, B = c01 - c00;
        float X = c11 - c10 - c01 + c00;
        float alpha = c00 + A * a0 + B * b0 + X * a0 * b0;
        float beta = -(A + B * t + X * (a0 * t + b0));
        float gamma = X * t;
        float Pp = alpha - h;
        float fb = (Pp + beta * sb + gamma * sb * sb) * inv_b - cb;
        float fa = Pp * ka + beta * kb + gamma * kc - ca;
        float m = fa > fb ? fa : fb;
        float g2 = gamma - cLL;
        float r = Pp / g2;
        float ss = sqrt(r > 0.0f ? r : 0.0f);
        float sd = ss > 0.0f ? ss : 1.0f;
        float fs = (Pp / sd + beta + gamma * ss) * invL - c * ss * L;
        int inner = has_sa & (Pp < 0.0f) & (g2 < 0.0f) & (ss > sa) & (ss < sb) & (fs > m);
        m = inner ? fs : m;
        best = m > best ? m : best;
        nans += (m != m) ? 1.0f : 0.0f;
    }
    for (int j = TS_NEAR_EXACT + 1; j <= TS_NEAR_STEPS; j++) {
        long o0 = -(long)j * u_stride + (long)P[TS_CLI_SDV + j] * v_stride;
        const float f = (float)Q[TS_CLD_SFV + j], d = (float)j * L, invd = 1.0f / d, cd = c * d;
        float va = zc[o0], vb = zc[o0 + v_stride];
        float hj = va + f * (vb - va);
        float s = (hj - h) * invd - cd;
        best = s > best ? s : best;
        nans += (s != s) ? 1.0f : 0.0f;
    }
    *flag = nans != 0.0f;
    return best;
}

/* Pass 2: global size (cells rounded up, azimuths in the batch). */
__kernel void ts_sweep_finish(__global const float *z, const int W, const int H,
                              __global const int *ip, __global const real *dp,
                              __global const float *fr_all, __global const real *sr_all,
                              const real c, const real cap, __global float *out,
                              __global const int2 *hi, __global const int2 *lo, const long plane)
{
    const long cell = get_global_id(0);
    const int a = (int)get_global_id(1);
    if (cell >= (long)W * H)
        return;
    __global const int *P = ip + a * TS_CLI_N;
    __global const real *Q = dp + a * TS_CLD_N;
    const long po = P[TS_CLI_PLANE] * plane + cell;
    const float hc = z[cell];
    if (isnan(hc)) {
        out[po] = NAN;
        return;
    }
    const int y = (int)(cell / W), x = (int)(cell - (long)y * W);
    const int xm = P[TS_CLI_XMAJOR], V = P[TS_CLI_V];
    const int u_start = P[TS_CLI_USTART], u_step = P[TS_CLI_USTEP];
    const long su = xm ? 1 : W;
    const long u_stride = su * u_step, v_stride = xm ? W : 1, origin = su * u_start;
    const int u = xm ? x : y, v = xm ? y : x;
    const int k = (u - u_start) * u_step;
    const float F = fr_all[P[TS_CLI_FLOFF] + k];
    const int2 none = (int2)(-1, 0);
    const int2 ohi = hi[po];
    const int2 olo = (F > 0.0f && v >= 1) ? lo[po] : none;
    const int sroff = P[TS_CLI_SROFF];
    const real step = sroff >= 0 ? sr_all[sroff + y] : Q[TS_CLD_STEPM];
    const float farf = ts_far_field(z, V, Q[TS_CLD_T], origin, u_stride, v_stride, k, v, hc,
                                    olo, ohi, step, c, cap);
    const int m = TS_NEAR_MARGIN;
    const int interior =
        cap == 0 && y >= m && y < H - m && W > 2 * m && x >= m && x < W - m;
    float res;
    int left;
    if (interior) {
        int flagged;
        float nf = ts_near_fast(z + cell, P, Q, u_stride, v_stride, hc, (float)step, (float)c,
                                &flagged);
        if (flagged)
            nf = ts_near_exact(z, P, Q, origin, u_stride, v_stride, k, v, hc, step, c, 0,
                               &left);
        res = nf > farf ? nf : farf;
    } else {
        float nf =
            ts_near_exact(z, P, Q, origin, u_stride, v_stride, k, v, hc, step, c, cap, &left);
        res = left ? nf : fmax(nf, farf);
    }
    out[po] = ts_atan_deg(res);
}
