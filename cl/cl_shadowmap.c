/*
 * Shadow map with percentage-closer filtering on the device
 * (cl/shadowmap.cl): the frame of core/shadowmap_frame.c, then project,
 * clear, render and filter, each a kernel over cells, texels or quads.
 */
#include <stdlib.h>

#include "cl_internal.h"
#include "status_internal.h"

ts_status ts_cl_shadowmap_compute(const ts_grid *grid, double azimuth, double elevation,
                                  const ts_shadowmap_opts *opts, float *visibility,
                                  ts_error *err)
{
    ts_shadowmap_frame f;
    ts_status st = ts_shadowmap_prepare(grid, azimuth, elevation, opts, visibility, &f, err);
    if (st != TS_OK)
        return st;
    const int W = grid->width, H = grid->height;
    const size_t cells = (size_t)W * H, bytes = cells * sizeof(float);
    const size_t texels = ts_shadowmap_keys(&f); /* and the tiles' */
    const size_t zbytes = ((size_t)grid->stride * (H - 1) + W) * sizeof(float);
    float *cxr = malloc((size_t)H * sizeof(float));
    if (!cxr)
        return ts_fail(err, TS_ERR_NOMEM, "out of memory for the row spacing");
    for (int y = 0; y < H; y++)
        cxr[y] = (float)ts_grid_cell_x(grid, y); /* as core/shadowmap.c */
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK) {
        free(cxr);
        return J.st;
    }
    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, zbytes, grid->z, "heights");
    cl_mem cb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, (size_t)H * sizeof(float), cxr,
                                 "row spacing");
    cl_mem pb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, sizeof f.params, f.params,
                                 "shadow map frame");
    cl_mem ub = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, bytes, NULL, "projected vertices");
    cl_mem vb = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, bytes, NULL, "projected vertices");
    cl_mem db = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, bytes, NULL, "projected vertices");
    cl_mem mb = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, texels * sizeof(cl_int), NULL,
                                 "shadow map");
    cl_mem ob = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, bytes, NULL, "visibility");
    const cl_int cW = W, cH = H, mw = f.width, mh = f.height;
    const cl_long stride = (cl_long)grid->stride, n = (cl_long)texels;

    cl_kernel kp = ts_cl_job_kernel(&J, "ts_shadowmap_project");
    const cl_mem pargs[] = {ub, vb, db};
    ts_cl_job_arg(&J, kp, 0, sizeof zb, &zb);
    ts_cl_job_arg(&J, kp, 1, sizeof stride, &stride);
    ts_cl_job_arg(&J, kp, 2, sizeof cW, &cW);
    ts_cl_job_arg(&J, kp, 3, sizeof cH, &cH);
    ts_cl_job_arg(&J, kp, 4, sizeof cb, &cb);
    ts_cl_job_arg(&J, kp, 5, sizeof pb, &pb);
    for (int a = 0; a < 3; a++)
        ts_cl_job_arg(&J, kp, 6 + a, sizeof pargs[a], &pargs[a]);
    size_t L = ts_cl_job_wg(&J, kp, 256), global = ts_cl_round_up(cells, L);
    ts_cl_job_run(&J, kp, 1, &global, &L, "ts_shadowmap_project");

    cl_kernel kc = ts_cl_job_kernel(&J, "ts_shadowmap_clear");
    ts_cl_job_arg(&J, kc, 0, sizeof mb, &mb);
    ts_cl_job_arg(&J, kc, 1, sizeof n, &n);
    L = ts_cl_job_wg(&J, kc, 256);
    global = ts_cl_round_up(texels, L);
    ts_cl_job_run(&J, kc, 1, &global, &L, "ts_shadowmap_clear");

    /* render and filter share their first arguments */
    cl_kernel kr = ts_cl_job_kernel(&J, "ts_shadowmap_render");
    cl_kernel kf = ts_cl_job_kernel(&J, "ts_shadowmap_filter");
    const cl_kernel both[] = {kr, kf};
    for (int b = 0; b < 2; b++) {
        cl_kernel k = both[b];
        ts_cl_job_arg(&J, k, 0, sizeof pb, &pb);
        ts_cl_job_arg(&J, k, 1, sizeof mb, &mb);
        ts_cl_job_arg(&J, k, 2, sizeof mw, &mw);
        ts_cl_job_arg(&J, k, 3, sizeof mh, &mh);
        for (int a = 0; a < 3; a++)
            ts_cl_job_arg(&J, k, 4 + a, sizeof pargs[a], &pargs[a]);
        ts_cl_job_arg(&J, k, 7, sizeof cW, &cW);
        ts_cl_job_arg(&J, k, 8, sizeof cH, &cH);
    }
    const size_t quads = (size_t)(W > 1 ? W - 1 : 0) * (H > 1 ? H - 1 : 0);
    if (quads > 0) {
        L = ts_cl_job_wg(&J, kr, 256);
        global = ts_cl_round_up(quads, L);
        ts_cl_job_run(&J, kr, 1, &global, &L, "ts_shadowmap_render");
    }
    ts_cl_job_arg(&J, kf, 9, sizeof ob, &ob);
    L = ts_cl_job_wg(&J, kf, 256);
    global = ts_cl_round_up(cells, L);
    ts_cl_job_run(&J, kf, 1, &global, &L, "ts_shadowmap_filter");
    ts_cl_job_read(&J, ob, 0, bytes, visibility, "visibility");
    st = ts_cl_job_end(&J);
    free(cxr);
    return st;
}
