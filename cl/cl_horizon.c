/*
 * Horizon sweep on the OpenCL device; the kernels are in cl/horizon.cl.
 *
 * The line geometry (ts_line_geom_init) and the near-field plan
 * (ts_near_plan_init) are computed here, on the host, by the C core's own
 * functions, and handed to the kernels as tables, so that both backends
 * walk exactly the same lines. Azimuths go in batches: as many horizon
 * planes as fit the device (per azimuth the output plane and two planes of
 * far-field occluders, the one handed from each line to the next), and the
 * lines of a batch in launches of as many hull stacks as fit.
 *
 * The kernels see each azimuth's grid u-major (cl/horizon.cl): azimuths
 * along x read a transposed copy of the heights, made once per call on the
 * device, and their horizon planes are transposed back on the device
 * (into the then unused occluder buffer) before they are read.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cl_internal.h"
#include "line_geometry.h"
#include "near_field.h"
#include "arg_checks.h"
#include "status_internal.h"
#include "ts_cl_params.h"

/* Hull stacks on a CPU device are host memory: keep them modest. */
#define CPU_STACK_BUDGET (256ull << 20)
/* Azimuths per batch, at most. */
#define MAX_BATCH 32

/* Transpose the R x C matrix of 32-bit values at element soff of src into
 * dst at element doff (ts_transpose); wg: the work-group size, >= 32. */
static void transpose(ts_cl_job *J, cl_kernel k, size_t wg, cl_mem src, cl_long soff, int R,
                      int C, cl_mem dst, cl_long doff)
{
    const cl_int cR = R, cC = C;
    ts_cl_job_args(J, k, 0,
                   TS_CL_ARGS(TS_CL_ARG(src), TS_CL_ARG(soff), TS_CL_ARG(cR), TS_CL_ARG(cC),
                              TS_CL_ARG(dst), TS_CL_ARG(doff)));
    size_t local[2] = {32, wg / 32};
    size_t global[2] = {ts_cl_round_up((size_t)C, 32), ((size_t)R + 31) / 32 * local[1]};
    ts_cl_job_run(J, k, 2, global, local, "ts_transpose");
}

/* Fill the table rows of azimuth `a` of a batch; returns 0 on NOMEM. */
static int fill_azimuth(const ts_grid *pg, double azimuth, int a, int line0, int floff,
                        int *ip, double *dp, int *fl, float *fr, double *sr, int *lines,
                        ts_error *err)
{
    ts_line_geom G;
    if (ts_line_geom_init(&G, pg, azimuth, err) != TS_OK)
        return 0;
    ts_near_plan NP;
    ts_near_plan_init(&NP, &G);
    int *I = ip + (size_t)a * TS_CLI_N;
    double *Dp = dp + (size_t)a * TS_CLD_N;
    memset(I, 0, TS_CLI_N * sizeof *I);
    memset(Dp, 0, TS_CLD_N * sizeof *Dp);
    I[TS_CLI_XMAJOR] = G.x_major;
    I[TS_CLI_U] = G.U;
    I[TS_CLI_V] = G.V;
    I[TS_CLI_USTART] = G.u_start;
    I[TS_CLI_USTEP] = G.u_step;
    I[TS_CLI_BLO] = (int)G.b_lo;
    I[TS_CLI_LINE0] = line0;
    I[TS_CLI_FLOFF] = floff;
    I[TS_CLI_SROFF] = G.step_row ? a * pg->height : -1;
    I[TS_CLI_PLANE] = a;
    I[TS_CLI_NPIECES] = NP.npieces;
    for (int n = 0; n < NP.npieces; n++) {
        I[TS_CLI_PDU + n] = NP.piece_du[n];
        I[TS_CLI_PDV + n] = NP.piece_dv[n];
        Dp[TS_CLD_PSA + n] = NP.piece_sa[n];
        Dp[TS_CLD_PSB + n] = NP.piece_sb[n];
    }
    Dp[TS_CLD_T] = G.t;
    Dp[TS_CLD_STEPM] = G.step_m;
    Dp[TS_CLD_NEARSKIP] = (TS_NEAR_STEPS + 0.5) * G.step_m;
    memcpy(fl + floff, G.fl, (size_t)G.U * sizeof *fl);
    memcpy(fr + floff, G.fr, (size_t)G.U * sizeof *fr);
    if (G.step_row)
        memcpy(sr + (size_t)a * pg->height, G.step_row, (size_t)pg->height * sizeof *sr);
    *lines = (int)(G.b_hi - G.b_lo + 1);
    ts_line_geom_free(&G);
    return 1;
}

/* Horizons for the n azimuths az[] (already in [0, 360)), plane k of out
 * for az[k]. Arguments are checked by the callers. */
static ts_status horizon_run(const ts_grid *grid, const ts_horizon_opts *opts, const double *az,
                             int n, float *out, ts_error *err)
{
    const int W = grid->width, H = grid->height;
    const size_t cells = (size_t)W * H, plane_bytes = cells * sizeof(float);
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK)
        return J.st;
    ts_cl_dev *D = J.d;
    const size_t rs = ts_cl_real_size(D);
    const int Umax = W > H ? W : H;
    const double c = opts->curvature ? (1.0 - opts->refraction) / (2.0 * TS_EARTH_RADIUS) : 0.0;
    const double cap = opts->max_distance;

    /* Packed heights (stride = width): the geometry's strides then index
     * the device copy directly. */
    float *packed = NULL;
    const float *zsrc = grid->z;
    if (grid->stride != W) {
        packed = malloc(plane_bytes);
        if (!packed) {
            ts_cl_job_fail(&J, TS_ERR_NOMEM, "cannot allocate a packed copy of the grid");
            return ts_cl_job_end(&J);
        }
        for (int y = 0; y < H; y++)
            memcpy(packed + (size_t)y * W, grid->z + (ptrdiff_t)y * grid->stride,
                   (size_t)W * sizeof(float));
        zsrc = packed;
    }
    ts_grid pg = *grid;
    pg.stride = W;
    pg.z = (float *)zsrc;

    /* Batch size: the output planes (float) and the two occluder planes
     * (int2) each within one buffer, all within half the budget. */
    const size_t occ_bytes = cells * 2 * sizeof(cl_int);
    size_t A = (size_t)n < MAX_BATCH ? (size_t)n : MAX_BATCH;
    if (A > J.max_alloc / occ_bytes)
        A = J.max_alloc / occ_bytes;
    if (A > J.budget / 2 / (plane_bytes + 2 * occ_bytes))
        A = J.budget / 2 / (plane_bytes + 2 * occ_bytes);
    if (A < 1)
        A = 1; /* the buffers below then fail with a clean error */

    /* Lines per batch, for the hull stacks; whether an azimuth runs along x
     * (and needs the transposed heights). */
    int max_items = 0, any_xm = 0;
    {
        ts_line_geom G;
        int items = 0;
        for (int k = 0; k < n && J.st == TS_OK; k++) {
            if (k % A == 0)
                items = 0;
            if (ts_line_geom_init(&G, &pg, az[k], err) != TS_OK) {
                J.st = err ? err->code : TS_ERR_NOMEM;
                break;
            }
            items += (int)(G.b_hi - G.b_lo + 1);
            any_xm |= G.x_major;
            ts_line_geom_free(&G);
            if (items > max_items)
                max_items = items;
        }
    }
    const size_t slot_entries = (size_t)(Umax + 1);
    const size_t slot_bytes = slot_entries * (2 * rs + sizeof(cl_int));
    unsigned long long sbud = J.budget / 2;
    if (sbud > J.max_alloc)
        sbud = J.max_alloc;
    if (D->is_cpu && sbud > CPU_STACK_BUDGET)
        sbud = CPU_STACK_BUDGET;
    size_t nslots = sbud / slot_bytes;
    if (nslots > (size_t)max_items)
        nslots = (size_t)max_items;
    if (nslots < 1)
        nslots = 1;

    int *ip = malloc(A * TS_CLI_N * sizeof *ip);
    double *dp = malloc(A * TS_CLD_N * sizeof *dp);
    void *dpr = malloc(A * TS_CLD_N * rs);
    int *fl = malloc(A * (size_t)Umax * sizeof *fl);
    float *fr = malloc(A * (size_t)Umax * sizeof *fr);
    double *sr = grid->cell_x_row ? malloc(A * (size_t)H * sizeof *sr) : NULL;
    void *srr = grid->cell_x_row ? malloc(A * (size_t)H * rs) : NULL;
    if (J.st == TS_OK &&
        (!ip || !dp || !dpr || !fl || !fr || (grid->cell_x_row && (!sr || !srr))))
        ts_cl_job_fail(&J, TS_ERR_NOMEM, "cannot allocate the horizon sweep tables");

    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, plane_bytes, zsrc, "heights");
    /* The heights u-major for azimuths along x (else unused: zb stands in). */
    cl_mem ztb = any_xm ? ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, plane_bytes, NULL,
                                           "transposed heights")
                        : zb;
    cl_mem ob = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, A * plane_bytes, NULL, "horizon planes");
    cl_mem hib = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, A * occ_bytes, NULL,
                                  "far-field occluders");
    cl_mem lob = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, A * occ_bytes, NULL,
                                  "far-field occluders");
    cl_mem sb = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, nslots * slot_entries * 2 * rs, NULL,
                                 "hull stacks");
    cl_mem skb = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, nslots * slot_entries * sizeof(cl_int),
                                  NULL, "hull stacks");
    cl_mem ipb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, A * TS_CLI_N * sizeof *ip, NULL,
                                  "azimuth table");
    cl_mem dpb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, A * TS_CLD_N * rs, NULL, "azimuth table");
    cl_mem flb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, A * Umax * sizeof *fl, NULL, "line table");
    cl_mem frb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, A * Umax * sizeof *fr, NULL, "line table");
    cl_mem srb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, sr ? A * H * rs : 16, NULL, "step table");
    cl_kernel k1 = ts_cl_job_kernel(&J, "ts_sweep_lines");
    cl_kernel k2 = ts_cl_job_kernel(&J, "ts_sweep_finish");
    cl_kernel k3 = ts_cl_job_kernel(&J, "ts_transpose");
    /* without a cap, the common case first (ts_sweep_fast), the cells it
     * leaves after it */
    cl_kernel kf = cap == 0 ? ts_cl_job_kernel(&J, "ts_sweep_fast") : NULL;
    size_t wg1 = ts_cl_job_wg(&J, k1, 64);
    size_t wg2 = ts_cl_job_wg(&J, k2, D->is_cpu ? 256 : 128);
    size_t wgf = kf ? ts_cl_job_wg(&J, kf, D->is_cpu ? 256 : 128) : 0;
    size_t wg3 = ts_cl_job_wg(&J, k3, 256);
    if (J.st == TS_OK && wg3 < 32)
        ts_cl_job_fail(&J, TS_ERR_INTERNAL,
                       "OpenCL device %.60s runs work-groups of %zu work-items, fewer than "
                       "the 32 the horizon kernels need",
                       D->info.device, wg3);
    if (any_xm)
        transpose(&J, k3, wg3, zb, 0, H, W, ztb, 0);
    const cl_int cW = W, cH = H, cslots = (cl_int)nslots;
    const cl_long cplane = (cl_long)cells;

    for (int first = 0; first < n && J.st == TS_OK; first += (int)A) {
        if (ts_progress(opts, (double)first / n, err) != TS_OK) {
            ts_cl_job_fail(&J, TS_ERR_CANCELLED, "cancelled by the caller");
            break;
        }
        int nb = n - first < (int)A ? n - first : (int)A;
        int items = 0, floff = 0;
        for (int a = 0; a < nb; a++) {
            int lines;
            if (!fill_azimuth(&pg, az[first + a], a, items, floff, ip, dp, fl, fr, sr, &lines,
                              err)) {
                J.st = err ? err->code : TS_ERR_NOMEM;
                break;
            }
            items += lines;
            floff += ip[(size_t)a * TS_CLI_N + TS_CLI_U];
        }
        if (J.st != TS_OK)
            break;
        ts_cl_to_real(D, dpr, dp, (size_t)nb * TS_CLD_N);
        ts_cl_job_write(&J, ipb, 0, (size_t)nb * TS_CLI_N * sizeof *ip, ip, "azimuth table");
        ts_cl_job_write(&J, dpb, 0, (size_t)nb * TS_CLD_N * rs, dpr, "azimuth table");
        ts_cl_job_write(&J, flb, 0, (size_t)floff * sizeof *fl, fl, "line table");
        ts_cl_job_write(&J, frb, 0, (size_t)floff * sizeof *fr, fr, "line table");
        if (sr) {
            ts_cl_to_real(D, srr, sr, (size_t)nb * H);
            ts_cl_job_write(&J, srb, 0, (size_t)nb * H * rs, srr, "step table");
        }
        const cl_int cnaz = nb, citems = items;
        /* pass 1: lines */
        ts_cl_job_args(&J, k1, 0,
                       TS_CL_ARGS(TS_CL_ARG(zb), TS_CL_ARG(ztb), TS_CL_ARG(cnaz), TS_CL_ARG(ipb),
                                  TS_CL_ARG(dpb), TS_CL_ARG(flb), TS_CL_ARG(frb),
                                  TS_CL_ARG(srb)));
        ts_cl_job_arg(&J, k1, 9, sizeof citems, &citems);
        ts_cl_job_arg_real(&J, k1, 10, c);
        ts_cl_job_args(&J, k1, 11,
                       TS_CL_ARGS(TS_CL_ARG(hib), TS_CL_ARG(lob), TS_CL_ARG(cplane),
                                  TS_CL_ARG(sb), TS_CL_ARG(skb), TS_CL_ARG(cslots)));
        for (int item0 = 0; item0 < items && J.st == TS_OK; item0 += (int)nslots) {
            const cl_int citem0 = item0;
            size_t active = (size_t)(items - item0) < nslots ? (size_t)(items - item0) : nslots;
            size_t global = ts_cl_round_up(active, wg1);
            ts_cl_job_arg(&J, k1, 8, sizeof citem0, &citem0);
            ts_cl_job_run(&J, k1, 1, &global, &wg1, "ts_sweep_lines");
        }
        /* pass 2: cells */
        size_t global2[2] = {ts_cl_round_up(cells, wg2), (size_t)nb}, local2[2] = {wg2, 1};
        const cl_int marked_only = kf != NULL;
        if (kf) {
            ts_cl_job_args(&J, kf, 0,
                           TS_CL_ARGS(TS_CL_ARG(zb), TS_CL_ARG(ztb), TS_CL_ARG(cW),
                                      TS_CL_ARG(cH), TS_CL_ARG(ipb), TS_CL_ARG(dpb),
                                      TS_CL_ARG(flb), TS_CL_ARG(frb), TS_CL_ARG(srb)));
            ts_cl_job_arg_real(&J, kf, 9, c);
            ts_cl_job_args(&J, kf, 10,
                           TS_CL_ARGS(TS_CL_ARG(ob), TS_CL_ARG(hib), TS_CL_ARG(lob),
                                      TS_CL_ARG(cplane)));
            size_t globalf[2] = {ts_cl_round_up(cells, wgf), (size_t)nb}, localf[2] = {wgf, 1};
            ts_cl_job_run(&J, kf, 2, globalf, localf, "ts_sweep_fast");
        }
        ts_cl_job_args(&J, k2, 0,
                       TS_CL_ARGS(TS_CL_ARG(zb), TS_CL_ARG(ztb), TS_CL_ARG(cW), TS_CL_ARG(cH),
                                  TS_CL_ARG(ipb), TS_CL_ARG(dpb), TS_CL_ARG(flb),
                                  TS_CL_ARG(frb), TS_CL_ARG(srb)));
        ts_cl_job_arg_real(&J, k2, 9, c);
        ts_cl_job_arg_real(&J, k2, 10, cap);
        ts_cl_job_args(&J, k2, 11,
                       TS_CL_ARGS(TS_CL_ARG(ob), TS_CL_ARG(hib), TS_CL_ARG(lob),
                                  TS_CL_ARG(cplane), TS_CL_ARG(marked_only)));
        ts_cl_job_run(&J, k2, 2, global2, local2, "ts_sweep_finish");
        /* Planes along x back into rows, into the occluder buffer (free
         * now, and twice a plane's size); then read each run of planes
         * that lie in one buffer at once. */
        for (int a = 0; a < nb; a++)
            if (ip[(size_t)a * TS_CLI_N + TS_CLI_XMAJOR])
                transpose(&J, k3, wg3, ob, (cl_long)(a * cells), W, H, hib,
                          (cl_long)(a * cells));
        for (int a = 0; a < nb;) {
            const int xm = ip[(size_t)a * TS_CLI_N + TS_CLI_XMAJOR];
            int e = a + 1;
            while (e < nb && ip[(size_t)e * TS_CLI_N + TS_CLI_XMAJOR] == xm)
                e++;
            ts_cl_job_read(&J, xm ? hib : ob, a * plane_bytes, (size_t)(e - a) * plane_bytes,
                           out + ((size_t)first + a) * cells, "horizon planes");
            a = e;
        }
    }
    ts_status st = ts_cl_job_end(&J);
    if (st == TS_OK)
        st = ts_progress(opts, 1.0, err);
    free(packed);
    free(ip);
    free(dp);
    free(dpr);
    free(fl);
    free(fr);
    free(sr);
    free(srr);
    return st;
}

/* The options the kernels run with: TS_ERR_ARG when the maximum distance
 * caps a line toward one of the azimuths (the C sweep's own test, so that
 * the C backend takes exactly the capped sweeps), else a copy without the
 * distance, which then caps nothing. */
static ts_status uncapped_opts(const ts_grid *grid, const ts_horizon_opts *opts,
                               const double *az, int n, ts_horizon_opts *run, ts_error *err)
{
    *run = *opts;
    if (!(opts->max_distance > 0))
        return TS_OK;
    for (int a = 0; a < n; a++) {
        ts_line_geom G;
        ts_status st = ts_line_geom_init(&G, grid, az[a], err);
        if (st != TS_OK)
            return st;
        double shortest, longest;
        ts_line_geom_step_range(&G, grid->height, &shortest, &longest);
        int caps = !(opts->max_distance > longest * G.U);
        ts_line_geom_free(&G);
        if (caps)
            return ts_fail(err, TS_ERR_ARG, "%s", TS_CL_CAPPED_SWEEP_REASON);
    }
    run->max_distance = 0.0;
    return TS_OK;
}

/* The world beyond the edge (opts->edge) on the n planes read back, by the
 * core's own function: both backends clamp alike before any sum or test. */
static ts_status edge_apply(const ts_grid *grid, const ts_horizon_opts *opts, const double *az,
                            int n, float *out, ts_error *err)
{
    size_t cells = (size_t)grid->width * grid->height;
    ts_status st = TS_OK;
    for (int a = 0; st == TS_OK && a < n; a++)
        st = ts_horizon_edge_apply(grid, az[a], opts, out + (size_t)a * cells, err);
    return st;
}

/* The n planes of azimuths az (checked, in [0, 360)): the kernels, with
 * the options uncapped where nothing caps, then the world beyond the edge;
 * the one tail of the three entry points below. */
static ts_status sweep_azimuths(const ts_grid *grid, const ts_horizon_opts *opts,
                                const double *az, int n, float *out, ts_error *err)
{
    ts_horizon_opts run;
    ts_status st = uncapped_opts(grid, opts, az, n, &run, err);
    if (st == TS_OK)
        st = horizon_run(grid, &run, az, n, out, err);
    return st == TS_OK ? edge_apply(grid, opts, az, n, out, err) : st;
}

ts_status ts_cl_horizon_sweep(const ts_grid *grid, double azimuth, const ts_horizon_opts *opts,
                              float *out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "output buffer is NULL");
    ts_status st = ts_check_sweep_args(grid, &azimuth, opts, err);
    return st == TS_OK ? sweep_azimuths(grid, opts, &azimuth, 1, out, err) : st;
}

ts_status ts_cl_horizon_sweeps(const ts_grid *grid, const double *azimuths, int n,
                               const ts_horizon_opts *opts, float *out, ts_error *err)
{
    double *az = n > 0 ? malloc((size_t)n * sizeof *az) : NULL;
    if (n > 0 && !az)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the azimuth list");
    ts_status st = ts_check_sweeps_args(grid, azimuths, n, opts, out, az, err);
    if (st == TS_OK)
        st = sweep_azimuths(grid, opts, az, n, out, err);
    free(az);
    return st;
}

ts_status ts_cl_horizon_compute(const ts_grid *grid, const ts_horizon_opts *opts, float *out,
                                ts_error *err)
{
    ts_status st = ts_check_horizon_compute_args(grid, opts, out, err);
    if (st != TS_OK)
        return st;
    double *az = malloc((size_t)opts->directions * sizeof *az);
    if (!az)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the azimuth list");
    for (int k = 0; k < opts->directions; k++)
        az[k] = ts_horizon_azimuth(opts, k); /* in [0, 360) */
    st = sweep_azimuths(grid, opts, az, opts->directions, out, err);
    free(az);
    return st;
}
