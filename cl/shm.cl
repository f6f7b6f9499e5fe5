/*
 * Shadow height map (Lee & Kim): the recurrence of
 * core/shadow_height_map.c, its step and light in core/cellmath/cm_shm.h.
 *
 * S(k, v) = max(h, S(k - 1, v + off + F) - drop) walks along the light's
 * major axis u (k = step index); a u-row depends on the previous one at v +
 * off and v + off + 1 only, i.e. on one side of v (off = -1: below; off = 0
 * with F > 0, or off = 1: above; off = 0, F = 0: v itself).
 *
 * Barrier-free across work-groups, by overlapped tiles: one launch covers
 * `nrows` u-rows; work-group g owns the band [g B, g B + B) of v (B = the
 * work-group size) and recomputes, in local memory, a halo of nrows cells on
 * the side the light comes from, so that after nrows rows its own band is
 * exact without reading anything another group writes during the launch.
 * The launch starts from the full previous u-row (state_in) and leaves its
 * last u-row in state_out (ping-pong between launches). With no halo (light
 * along an axis) one launch does every row. Only local barriers are used.
 */
__kernel void ts_shm_rows(__global const float *z, const int W, const int xm, const int V,
                          const int u_start, const int u_step, const int off, const float F,
                          __global const float *drop_row, const float depth, const int k0,
                          const int nrows, const int halo_lo, const int halo_hi,
                          __global const float *state_in, __global float *state_out,
                          __global float *vis, __global float *sh, const int want_vis,
                          const int want_sh, __local float *buf)
{
    const int L = (int)get_local_size(0), lid = (int)get_local_id(0);
    const int B = L;
    const int v0 = (int)get_group_id(0) * B;
    const int e_lo = v0 - halo_lo;            /* v of local cell 0 */
    const int E = B + halo_lo + halo_hi;      /* local cells */
    const long su = xm ? 1 : W;
    const long u_stride = su * u_step, v_stride = xm ? W : 1, origin = su * u_start;
    for (int j = 0; j < nrows; j++) {
        const int k = k0 + j;
        __local float *prev = buf + ((j + 1) & 1) * E;
        __local float *cur = buf + (j & 1) * E;
        const long rowoff = origin + (long)k * u_stride;
        const int u = u_start + k * u_step;
        for (int e = lid; e < E; e += L) {
            const int v = e_lo + e;
            if (v < 0 || v >= V) {
                cur[e] = NAN;
                continue;
            }
            const long p = rowoff + (long)v * v_stride;
            const float h = z[p];
            float pa = NAN, pb = NAN; /* NaN: nothing toward the light */
            if (k > 0) {
                const int a = v + off, b = a + 1;
                /* off the grid toward the light nothing casts a shadow */
                const int off_grid = a < 0 || a >= V || (F > 0.0f && (b < 0 || b >= V));
                if (!off_grid && j == 0) {
                    pa = state_in[a];
                    pb = F > 0.0f ? state_in[b] : NAN;
                } else if (!off_grid) {
                    /* outside the local cells only in the stale part of
                     * the halo, which the band never reads */
                    const int ea = a - e_lo, eb = ea + 1;
                    pa = (ea >= 0 && ea < E) ? prev[ea] : NAN;
                    pb = (F > 0.0f && eb >= 0 && eb < E) ? prev[eb] : NAN;
                }
            }
            const float s = cm_shm_step(pa, pb, F, k > 0 ? drop_row[xm ? v : u] : 0.0f, h);
            cur[e] = s;
            if (e >= halo_lo && e < halo_lo + B) {
                if (want_vis)
                    vis[p] = cm_shm_lit(s, h, depth);
                if (want_sh)
                    sh[p] = s;
                if (j == nrows - 1)
                    state_out[v] = s;
            }
        }
        barrier(CLK_LOCAL_MEM_FENCE);
    }
}
