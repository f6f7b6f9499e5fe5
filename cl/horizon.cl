/*
 * Exact horizon sweep: the loops of core/horizon_sweep.c and
 * core/near_field.c, one work-item per line or cell; the per-cell formulas
 * are core/cellmath/cm_near_field.h.
 *
 * Memory layout: both passes index the grid "u-major", element (u, v) of
 * an azimuth at u * V + v, so that neighbouring lines (pass 1) and
 * neighbouring cells (pass 2) touch neighbouring addresses, which a GPU
 * coalesces into one transaction. For azimuths along y (u = y, v = x) that
 * is the DEM's own row-major layout; for azimuths along x (u = x, v = y)
 * the kernels read a transposed copy of the heights (zt, made by
 * ts_transpose), keep their occluder planes transposed and write the
 * horizon plane transposed, which ts_transpose turns back into rows.
 *
 * Pass 1 (ts_sweep_lines): one work-item per sweep line, lines of several
 * azimuths in one launch. Each keeps its convex hull in a stack of (d, g)
 * points (and their step indices k) in global memory, interleaved across
 * work-items (entry j of slot s at j * nslots + s) so that neighbouring
 * work-items touch neighbouring memory (each slot's entries together ran
 * pass 1 2.8 times slower on an H200: docs/performance.md). For every
 * sample k of the line (cell i below it, cell i + 1 above it) it writes the
 * far-field occluder the hull finds (its step index and distance, as int2
 * (k, bits of dd)):
 *   hi[cell i]     from the height of cell i (the C code's `hi`),
 *   lo[cell i + 1] from the height of cell i + 1 (the C code's cur_lo,
 *                  which the next line reads as its `lo`).
 * The C code hands cur_lo from one line to the next in a loop; here it
 * waits in `lo` for pass 2, so the lines are independent.
 *
 * Pass 2 (ts_sweep_fast, then ts_sweep_finish for the cells it leaves;
 * ts_sweep_finish alone under a distance cap): one work-item per cell and
 * azimuth: the far field (the cell's own ray sampled at both occluders and
 * TS_FAR_SPREAD steps beside them; past the distance cap, the exact march of
 * cm_ray_exact), the exact near field (the float fast path of ts_near_row
 * for interior cells without a distance cap, cm_near_exact in `real`
 * elsewhere and for cells whose fast path met nodata), the larger of the
 * two, in degrees.
 */

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
__kernel void ts_sweep_lines(__global const float *zr, __global const float *zt, const int naz,
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
    __global const float *z = xm ? zt : zr; /* u-major heights */
    const long u_stride = (long)V * u_step, v_stride = 1, origin = (long)V * u_start;
    __global const int *fl = fl_all + P[TS_CLI_FLOFF];
    __global const float *fr = fr_all + P[TS_CLI_FLOFF];
    const int sroff = P[TS_CLI_SROFF];
    const real t = Q[TS_CLD_T], step_m = Q[TS_CLD_STEPM], near_skip = Q[TS_CLD_NEARSKIP];
    const long b = (long)P[TS_CLI_BLO] + (item - P[TS_CLI_LINE0]);
    int k0, k1;
    if (!cm_line_k_range(fl, U, V, t >= 0, b, &k0, &k1))
        return;
    __global int2 *oh = hi + P[TS_CLI_PLANE] * plane;
    __global int2 *ol = lo + P[TS_CLI_PLANE] * plane;
    const long ns = nslots;
    __global real2 *S = stack + slot;
    __global int *SK = stack_k + slot;
    const int2 none = (int2)(-1, 0);
    real d = 0;
    int n = 0, far = -1;
    /* the hull's top two points, S[n - 1] and S[n - 2] where they exist,
     * kept in registers: the pops test them at every sample, and each
     * load from the stack waits on global memory */
    real2 top1 = (real2)(0, 0), top2 = (real2)(0, 0);
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
                if (!((top2.y - gs) * (d - top1.x) >= (top1.y - gs) * (d - top2.x)))
                    break;
                n--;
                top1 = top2;
                if (n >= 2)
                    top2 = S[(n - 2) * ns];
            }
            if (far > n - 1)
                far = n - 1;
            while (far + 1 < n && d - S[(far + 1) * ns].x >= near_skip)
                far++;
            top2 = top1;
            top1 = (real2)(d, gs);
            S[n * ns] = top1;
            SK[n * ns] = k;
            n++;
            pushed = 1;
        }
        if (!pushed)
            while (far + 1 < n && d - S[(far + 1) * ns].x >= near_skip)
                far++;
        /* (also off the grid, between the last row and the one beyond:
         * its hull may hold the terrain toward the occluders) */
        oh[p] = !isnan(hc) ? ts_hull_query(S, SK, ns, far, d, hc, c) : none;
        if (has_next)
            ol[p + v_stride] = isnan(hn) ? none : ts_hull_query(S, SK, ns, far, d, hn, c);
    }
    /* A line that leaves the grid across row 0 goes on one row before it,
     * queries only: it answers row 0's cells for the far side, as the C
     * sweep's row_before (core/horizon_sweep.c) */
    const int kl = cm_line_k_leaving(fl, U, t >= 0, b, k1);
    for (int k = k1 + 1; k <= kl; k++) {
        if (sroff >= 0)
            d += sr_all[sroff + (xm ? 0 : u_start + k * u_step)]; /* (row -1: row 0's) */
        else
            d = (real)(k - k0) * step_m;
        while (far + 1 < n && d - S[(far + 1) * ns].x >= near_skip)
            far++;
        const long p0 = origin + (long)k * u_stride; /* row 0 */
        if (fr[k] > 0.0f) /* (on row -1, row 0 is on the next line) */
            ol[p0] = isnan(z[p0]) ? none : ts_hull_query(S, SK, ns, far, d, z[p0], c);
    }
}

/* ------------------------------------------------------------- far field */

/* Steps on either side of a line's occluder at which the cell's ray is also
 * sampled (FAR_SPREAD of horizon_sweep.c). */
#ifndef TS_FAR_SPREAD
#define TS_FAR_SPREAD 0
#endif

/* The cell's own ray sampled at and beside (TS_FAR_SPREAD steps) a line's
 * occluder cand: the highest slope; *lost: the ray cannot be sampled at the
 * occluder itself (the caller's cm_ray_lost, or ts_sweep_finish). */
float ts_far_at(const cm_ray_grid *r, int k, int i, float h, int2 cand, real step, real c,
                int *lost)
{
    float best = -INFINITY;
    const int dk = k - cand.x;
    *lost = 0;
    for (int e = -TS_FAR_SPREAD; e <= TS_FAR_SPREAD; e++) {
        if (dk + e <= TS_NEAR_STEPS)
            continue;
        float s = cm_ray_slope(r, k, i, h, dk + e, as_float(cand.y) + (float)(e * step),
                               (float)c);
        *lost |= e == 0 && s == -INFINITY;
        best = s > best ? s : best;
    }
    return best;
}

/* far_field: the cell's own ray at and beside the two lines' occluders (at
 * one it cannot be sampled at, the steps up to it: cm_ray_lost); when one
 * lies past the distance cap, the exact ray over the far part of the radius
 * instead (cm_ray_exact). */
float ts_far_field(const cm_ray_grid *r, int k, int i, float h, int2 lo, int2 hi, real step,
                   real c, real cap)
{
    float best = -INFINITY;
    int beyond_cap = 0;
    for (int cc = 0; cc < 2; cc++) {
        int2 cand = cc ? hi : lo;
        if (cand.x < 0 || (cc == 1 && hi.x == lo.x))
            continue;
        beyond_cap |= cap > 0 && as_float(cand.y) > cap;
        int lost;
        float s = ts_far_at(r, k, i, h, cand, step, c, &lost);
        if (lost) { /* the steps up to the occluder instead of the lost sample */
            float sl = cm_ray_lost(r, k, i, h, k - cand.x, TS_NEAR_STEPS, cap / step, step, c);
            s = sl > s ? sl : s;
        }
        best = s > best ? s : best;
    }
    if (!beyond_cap)
        return best;
    return cm_ray_exact(r, k, i, h, TS_NEAR_STEPS, cap / step, step, c);
}

/* ------------------------------------------------------------ near field */

/* The near-field tables of an azimuth's parameter rows (cm_near_field.h). */
cm_near_tables ts_near_tables(__global const int *P, __global const real *Q)
{
    cm_near_tables q = {P[TS_CLI_NPIECES], P + TS_CLI_PDU, P + TS_CLI_PDV, Q + TS_CLD_PSA,
                        Q + TS_CLD_PSB};
    return q;
}

/* The piece constants of an azimuth (cm_fast_piece_init) for step L. */
cm_fast_piece ts_near_piece(__global const int *P, __global const real *Q, int n, float L,
                            float c)
{
    const real pt = Q[TS_CLD_T];
    return cm_fast_piece_init(P[TS_CLI_PDU + n], P[TS_CLI_PDV + n], fabs(pt) <= RC(1e-12),
                              Q[TS_CLD_PSA + n], Q[TS_CLD_PSB + n], pt, L, c);
}

/* The float fast path of near_run (near_field.c) for one interior cell zc
 * at height h, piece by piece as there (cm_fast_piece's slopes), +0 for a
 * -0 as near_merge. The pieces come from `lp` when `shared` (the work-group
 * made them once, the same bits), else are made here for step L. *flag: a
 * corner was nodata or infinite (the cell is then redone by cm_near_exact). */
float ts_near_fast(__global const float *zc, __global const int *P, __global const real *Q,
                   __local const cm_fast_piece *lp, int shared, long u_stride, long v_stride,
                   float h, float L, float c, int *flag)
{
    float best = -INFINITY, prev = 0.0f;
    int bad = 0;
    const float t = (float)Q[TS_CLD_T];
    for (int n = 0; n < P[TS_CLI_NPIECES]; n++) {
        __global const float *q0 =
            zc + (long)P[TS_CLI_PDU + n] * u_stride + (long)P[TS_CLI_PDV + n] * v_stride;
        const cm_fast_piece q = shared ? lp[n] : ts_near_piece(P, Q, n, L, c);
        const float k[4] = {q0[0], q0[u_stride], q0[v_stride], q0[u_stride + v_stride]};
        const float X = cm_fast_twist(k[0], k[1], k[2], k[3]);
        const float f = cm_fast_cross(q, k[q.e0], k[q.e1], h);
        float m = f;
        if (!q.has_sa) {
            const float s0 = cm_fast_start(q, t, k[0], k[1], k[2], k[3]);
            m = s0 > m ? s0 : m;
        } else if (cm_fast_peak_test(q, t, X, prev, f)) {
            const float fs = cm_fast_peak(q, t, k[0], k[1], k[2], k[3], h, L, c);
            m = fs > m ? fs : m;
        }
        best = m > best ? m : best;
        prev = f;
        bad |= !(X - X == 0.0f);
    }
    *flag = bad;
    return best + 0.0f;
}

/* One cell of pass 2: where it lies in its azimuth's u-major layout and
 * what its ray and near field need. */
typedef struct {
    long po;         /* its element in the output plane */
    int v, x, y, k;  /* v across the lines, x and y in the DEM, k the step */
    float hc;        /* its height */
    int2 olo;        /* the occluder of the line below it ((-1, 0): none) */
    real step;       /* metres a step on its row */
    cm_ray_grid r;
} ts_finish_cell;

ts_finish_cell ts_finish_setup(__global const float *zr, __global const float *zt,
                               __global const int *P, __global const real *Q,
                               __global const int *fl_all, __global const float *fr_all,
                               __global const real *sr_all, __global const int2 *lo, long cell,
                               long plane)
{
    ts_finish_cell f;
    const int xm = P[TS_CLI_XMAJOR], V = P[TS_CLI_V];
    __global const float *z = xm ? zt : zr; /* u-major heights */
    f.po = P[TS_CLI_PLANE] * plane + cell;
    f.hc = z[cell];
    const int u = (int)(cell / V);
    f.v = (int)(cell - (long)u * V);
    f.x = xm ? u : f.v;
    f.y = xm ? f.v : u;
    const int u_start = P[TS_CLI_USTART], u_step = P[TS_CLI_USTEP];
    f.k = (u - u_start) * u_step;
    const float F = fr_all[P[TS_CLI_FLOFF] + f.k];
    /* row 0's far side: the line one row before it, where it has left
     * the grid (ts_sweep_lines' last steps; none elsewhere, unwritten) */
    int below = f.v >= 1;
    if (!below && Q[TS_CLD_T] < 0) {
        __global const int *fl = fl_all + P[TS_CLI_FLOFF];
        int k0, k1;
        below = cm_line_k_range(fl, P[TS_CLI_U], V, 0, -1 - (long)fl[f.k], &k0, &k1);
    }
    f.olo = (F > 0.0f && below && !isnan(f.hc)) ? lo[f.po] : (int2)(-1, 0);
    const int sroff = P[TS_CLI_SROFF];
    f.step = sroff >= 0 ? sr_all[sroff + f.y] : Q[TS_CLD_STEPM];
    const cm_ray_grid r = {z, V, Q[TS_CLD_T], (long)V * u_start, (long)V * u_step, 1};
    f.r = r;
    return f;
}

/* Whether the cell is far enough from the DEM's sides for the float near
 * field (without a distance cap). */
int ts_finish_interior(const ts_finish_cell *f, int W, int H, real cap)
{
    const int m = TS_NEAR_MARGIN;
    return cap == 0 && f->y >= m && f->y < H - m && W > 2 * m && f->x >= m && f->x < W - m;
}

/* A cell that ts_sweep_fast leaves to ts_sweep_finish keeps its occluder
 * hi as (TS_REST_MARK - hi.x, hi.y), below every step index and -1. */
#define TS_REST_MARK (-3)

/*
 * Pass 2 in full: global size (cells rounded up, azimuths in the batch);
 * work-item `cell` is the cell u * V + v of its azimuth's u-major layout.
 * marked_only: only the cells ts_sweep_fast marked (the others are done).
 */
__kernel void ts_sweep_finish(__global const float *zr, __global const float *zt, const int W,
                              const int H,
                              __global const int *ip, __global const real *dp,
                              __global const int *fl_all, __global const float *fr_all,
                              __global const real *sr_all, const real c, const real cap,
                              __global float *out,
                              __global const int2 *hi, __global const int2 *lo, const long plane,
                              const int marked_only)
{
    const long cell = get_global_id(0);
    const int a = (int)get_global_id(1);
    if (cell >= (long)W * H)
        return;
    __global const int *P = ip + a * TS_CLI_N;
    __global const real *Q = dp + a * TS_CLD_N;
    const long po = P[TS_CLI_PLANE] * plane + cell;
    int2 ohi = hi[po];
    if (marked_only) {
        if (ohi.x > TS_REST_MARK + 1)
            return;
        ohi.x = TS_REST_MARK - ohi.x;
    }
    const ts_finish_cell f = ts_finish_setup(zr, zt, P, Q, fl_all, fr_all, sr_all, lo, cell, plane);
    if (isnan(f.hc)) {
        out[po] = NAN;
        return;
    }
    const cm_near_tables nt = ts_near_tables(P, Q);
    const float farf = ts_far_field(&f.r, f.k, f.v, f.hc, f.olo, ohi, f.step, c, cap);
    float res;
    int left;
    if (ts_finish_interior(&f, W, H, cap)) {
        int flagged;
        float nf = ts_near_fast(f.r.z + cell, P, Q, 0, 0, f.r.u_stride, f.r.v_stride, f.hc,
                                (float)f.step, (float)c, &flagged);
        if (flagged)
            nf = cm_near_exact(&f.r, &nt, f.k, f.v, f.hc, f.step, c, 0, &left);
        res = nf > farf ? nf : farf;
    } else {
        float nf = cm_near_exact(&f.r, &nt, f.k, f.v, f.hc, f.step, c, cap, &left);
        res = left ? nf : fmax(nf, farf);
    }
    out[po] = ts_atan_deg(res);
}

/*
 * Pass 2's common case, without a distance cap: the interior cells whose
 * near field the float fast path answers and whose far field has its ray
 * at both occluders; the others it marks (TS_REST_MARK) for
 * ts_sweep_finish (marked_only), the same computation as one kernel did.
 * Without the exact near field and the lost ray in it, the kernel holds
 * fewer registers, so more of it runs at once. Local size (n, 1), one
 * azimuth a work-group: where the step is the azimuth's own (projected
 * DEMs) the work-group makes the near-field pieces once in local memory
 * (made per cell, their double-precision setup took a fifth of pass 2's
 * time on an H200).
 */
__kernel void ts_sweep_fast(__global const float *zr, __global const float *zt, const int W,
                            const int H,
                            __global const int *ip, __global const real *dp,
                            __global const int *fl_all, __global const float *fr_all,
                            __global const real *sr_all, const real c, __global float *out,
                            __global int2 *hi,
                            __global const int2 *lo, const long plane)
{
    __local cm_fast_piece lp[TS_NEAR_MAX_PIECES];
    const long cell = get_global_id(0);
    const int a = (int)get_global_id(1);
    __global const int *P = ip + a * TS_CLI_N;
    __global const real *Q = dp + a * TS_CLD_N;
    /* the same for the whole work-group: all of it meets the barrier or none */
    const int shared = P[TS_CLI_SROFF] < 0;
    if (shared) {
        for (int n = (int)get_local_id(0); n < P[TS_CLI_NPIECES]; n += (int)get_local_size(0))
            lp[n] = ts_near_piece(P, Q, n, (float)Q[TS_CLD_STEPM], (float)c);
        barrier(CLK_LOCAL_MEM_FENCE);
    }
    if (cell >= (long)W * H)
        return;
    const ts_finish_cell f = ts_finish_setup(zr, zt, P, Q, fl_all, fr_all, sr_all, lo, cell, plane);
    if (isnan(f.hc)) {
        out[f.po] = NAN;
        return;
    }
    const int2 ohi = hi[f.po];
    int rest = !ts_finish_interior(&f, W, H, 0);
    float farf = -INFINITY;
    for (int cc = 0; cc < 2 && !rest; cc++) {
        const int2 cand = cc ? ohi : f.olo;
        if (cand.x < 0 || (cc == 1 && ohi.x == f.olo.x))
            continue;
        int lost; /* ts_far_field's cm_ray_lost: left to ts_sweep_finish */
        const float s = ts_far_at(&f.r, f.k, f.v, f.hc, cand, f.step, c, &lost);
        rest |= lost;
        farf = s > farf ? s : farf;
    }
    int flagged = 0;
    float nf = -INFINITY;
    if (!rest)
        nf = ts_near_fast(f.r.z + cell, P, Q, lp, shared, f.r.u_stride, f.r.v_stride, f.hc,
                          (float)f.step, (float)c, &flagged);
    if (rest || flagged)
        hi[f.po] = (int2)(TS_REST_MARK - ohi.x, ohi.y);
    else
        out[f.po] = ts_atan_deg(nf > farf ? nf : farf);
}

/* ------------------------------------------------------------- transpose */

#define TS_TR_TILE 32

/* dst[c * R + r] = src[r * C + c] for the R x C matrix at src + soff, into
 * dst + doff, as bits (a NaN's payload is kept). One work-group of 32 x n
 * work-items (n = 1 .. 32) per 32 x 32 tile, global size (C rounded up to
 * 32) x (tiles along R times n): the tile goes through local memory so that
 * both the reads and the writes run along rows. */
__kernel void ts_transpose(__global const uint *src, const long soff, const int R, const int C,
                           __global uint *dst, const long doff)
{
    __local uint tile[TS_TR_TILE][TS_TR_TILE + 1]; /* +1: no bank conflicts */
    const int lx = (int)get_local_id(0), ly0 = (int)get_local_id(1);
    const int ny = (int)get_local_size(1);
    const int c0 = (int)get_group_id(0) * TS_TR_TILE, r0 = (int)get_group_id(1) * TS_TR_TILE;
    for (int ly = ly0; ly < TS_TR_TILE; ly += ny) {
        const int r = r0 + ly, c = c0 + lx;
        if (r < R && c < C)
            tile[ly][lx] = src[soff + (long)r * C + c];
    }
    barrier(CLK_LOCAL_MEM_FENCE);
    for (int ly = ly0; ly < TS_TR_TILE; ly += ny) {
        const int c = c0 + ly, r = r0 + lx;
        if (r < R && c < C)
            dst[doff + (long)c * R + r] = tile[lx][ly];
    }
}
