/*
 * Shadow height map, normals, direct sun and sky terms on the OpenCL
 * device; kernels in cl/shm.cl and cl/shading.cl. Each function checks its
 * arguments exactly as its C counterpart does, then runs one job.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cl_internal.h"
#include "line_geometry.h"
#include "arg_checks.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

/* The grid's heights with stride = width: grid->z itself when already
 * packed, else a copy in *copy (freed by the caller). NULL on NOMEM. */
static const float *packed_heights(const ts_grid *grid, float **copy)
{
    *copy = NULL;
    if (grid->stride == grid->width)
        return grid->z;
    size_t W = (size_t)grid->width;
    float *p = malloc(W * (size_t)grid->height * sizeof *p);
    if (!p)
        return NULL;
    for (int y = 0; y < grid->height; y++)
        memcpy(p + (size_t)y * W, grid->z + (ptrdiff_t)y * grid->stride, W * sizeof *p);
    *copy = p;
    return p;
}

/* ------------------------------------------------------------------ SHM */

ts_status ts_cl_shm_compute(const ts_grid *grid, double azimuth, double elevation,
                            double penumbra_depth, int threads, float *vis, float *shadow_height,
                            ts_error *err)
{
    ts_status st = ts_check_shm_args(grid, &azimuth, elevation, penumbra_depth, threads, vis,
                                     shadow_height, err);
    if (st != TS_OK)
        return st;

    const int W = grid->width, H = grid->height;
    const size_t cells = (size_t)W * H;
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK)
        return J.st;
    float *copy;
    const float *z = packed_heights(grid, &copy);
    ts_grid pg = *grid;
    pg.stride = W;
    pg.z = (float *)z;
    ts_line_geom G;
    memset(&G, 0, sizeof G);
    float *drop = malloc((size_t)H * sizeof *drop);
    if (!z || !drop) {
        ts_cl_job_fail(&J, TS_ERR_NOMEM, "cannot allocate the shadow height map tables");
    } else if ((st = ts_line_geom_init(&G, &pg, azimuth, err)) != TS_OK) {
        J.st = st;
    }
    if (J.st != TS_OK) {
        free(copy);
        free(drop);
        return ts_cl_job_end(&J);
    }
    const double tan_el = elevation >= 90 ? 1e30 : tan(elevation * M_PI / 180.0);
    for (int y = 0; y < H; y++)
        drop[y] = (float)((G.step_row ? G.step_row[y] : G.step_m) * tan_el);
    const double q = -G.t, fq = floor(q);
    const cl_int off = (cl_int)fq;
    const cl_float F = (cl_float)(q - fq);
    const int halo = off != 0 || F > 0.0f;

    cl_kernel k = ts_cl_job_kernel(&J, "ts_shm_rows");
    size_t L = ts_cl_job_wg(&J, k, 256);
    /* Rows per launch = halo width: a quarter of the band keeps the
     * recomputed halo at 25 %. Local memory: two rows of B + halo. */
    size_t K = halo ? (L / 4 > 0 ? L / 4 : 1) : (size_t)G.U;
    while (L > 1 && 2 * (L + (halo ? K : 0)) * sizeof(float) > J.d->local_mem) {
        L /= 2;
        if (halo)
            K = L / 4 > 0 ? L / 4 : 1;
    }
    const cl_int hlo = halo && off < 0 ? (cl_int)K : 0;
    const cl_int hhi = halo && off >= 0 ? (cl_int)K : 0;
    const size_t E = L + (size_t)hlo + (size_t)hhi;
    const size_t groups = ((size_t)G.V + L - 1) / L;

    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, cells * sizeof(float), z, "heights");
    cl_mem db = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, (size_t)H * sizeof(float), drop,
                                 "drop table");
    cl_mem s0 = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, (size_t)G.V * sizeof(float), NULL,
                                 "shadow height rows");
    cl_mem s1 = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, (size_t)G.V * sizeof(float), NULL,
                                 "shadow height rows");
    cl_mem vb = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, vis ? cells * sizeof(float) : 16, NULL,
                                 "visibility");
    cl_mem hb = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY,
                                 shadow_height ? cells * sizeof(float) : 16, NULL,
                                 "shadow heights");
    const cl_int cW = W, xm = G.x_major, V = G.V, us = G.u_start, ustep = G.u_step;
    const cl_int want_vis = vis != NULL, want_sh = shadow_height != NULL;
    const cl_float depth = (cl_float)penumbra_depth;
    ts_cl_job_args(&J, k, 0,
                   TS_CL_ARGS(TS_CL_ARG(zb), TS_CL_ARG(cW), TS_CL_ARG(xm), TS_CL_ARG(V),
                              TS_CL_ARG(us), TS_CL_ARG(ustep), TS_CL_ARG(off), TS_CL_ARG(F),
                              TS_CL_ARG(db), TS_CL_ARG(depth)));
    ts_cl_job_args(&J, k, 12, TS_CL_ARGS(TS_CL_ARG(hlo), TS_CL_ARG(hhi)));
    ts_cl_job_args(&J, k, 16,
                   TS_CL_ARGS(TS_CL_ARG(vb), TS_CL_ARG(hb), TS_CL_ARG(want_vis),
                              TS_CL_ARG(want_sh)));
    ts_cl_job_arg(&J, k, 20, 2 * E * sizeof(float), NULL);
    cl_mem in = s0, outm = s1;
    for (int k0 = 0; k0 < G.U && J.st == TS_OK; k0 += (int)K) {
        const cl_int ck0 = k0, nrows = G.U - k0 < (int)K ? G.U - k0 : (int)K;
        ts_cl_job_args(&J, k, 10, TS_CL_ARGS(TS_CL_ARG(ck0), TS_CL_ARG(nrows)));
        ts_cl_job_args(&J, k, 14, TS_CL_ARGS(TS_CL_ARG(in), TS_CL_ARG(outm)));
        size_t global = groups * L;
        ts_cl_job_run(&J, k, 1, &global, &L, "ts_shm_rows");
        cl_mem t = in;
        in = outm;
        outm = t;
    }
    if (vis)
        ts_cl_job_read(&J, vb, 0, cells * sizeof(float), vis, "visibility");
    if (shadow_height)
        ts_cl_job_read(&J, hb, 0, cells * sizeof(float), shadow_height, "shadow heights");
    st = ts_cl_job_end(&J);
    ts_line_geom_free(&G);
    free(copy);
    free(drop);
    return st;
}

/* -------------------------------------------------------------- normals */

ts_status ts_cl_normals(const ts_grid *grid, float *nx, float *ny, float *nz, ts_error *err)
{
    ts_status st = ts_check_normals_args(grid, nx, ny, nz, err);
    if (st != TS_OK)
        return st;
    const int W = grid->width, H = grid->height;
    const size_t cells = (size_t)W * H, bytes = cells * sizeof(float);
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK)
        return J.st;
    const size_t rs = ts_cl_real_size(J.d);
    float *copy;
    const float *z = packed_heights(grid, &copy);
    void *cxr = grid->cell_x_row ? malloc((size_t)H * rs) : NULL;
    if (!z || (grid->cell_x_row && !cxr))
        ts_cl_job_fail(&J, TS_ERR_NOMEM, "cannot allocate a packed copy of the grid");
    else if (cxr)
        ts_cl_to_real(J.d, cxr, grid->cell_x_row, (size_t)H);
    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, z, "heights");
    cl_mem cb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, cxr ? (size_t)H * rs : 16, cxr,
                                 "row spacing");
    cl_mem xb = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, bytes, NULL, "normals");
    cl_mem yb = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, bytes, NULL, "normals");
    cl_mem zzb = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, bytes, NULL, "normals");
    cl_kernel k = ts_cl_job_kernel(&J, "ts_normals");
    const cl_int cW = W, cH = H, has = cxr != NULL;
    ts_cl_job_args(&J, k, 0,
                   TS_CL_ARGS(TS_CL_ARG(zb), TS_CL_ARG(cW), TS_CL_ARG(cH), TS_CL_ARG(cb),
                              TS_CL_ARG(has)));
    ts_cl_job_arg_real(&J, k, 5, grid->cell_x);
    ts_cl_job_arg_real(&J, k, 6, grid->cell_y);
    ts_cl_job_args(&J, k, 7, TS_CL_ARGS(TS_CL_ARG(xb), TS_CL_ARG(yb), TS_CL_ARG(zzb)));
    size_t L = ts_cl_job_wg(&J, k, 256), global = ts_cl_round_up(cells, L);
    ts_cl_job_run(&J, k, 1, &global, &L, "ts_normals");
    ts_cl_job_read(&J, xb, 0, bytes, nx, "normals");
    ts_cl_job_read(&J, yb, 0, bytes, ny, "normals");
    ts_cl_job_read(&J, zzb, 0, bytes, nz, "normals");
    st = ts_cl_job_end(&J);
    free(copy);
    free(cxr);
    return st;
}

/* --------------------------------------------------------------- direct */

ts_status ts_cl_shade_direct(const ts_direct_request *req, ts_error *err)
{
    ts_direct_plan p;
    ts_status st = ts_direct_setup(req, &p, err);
    if (st != TS_OK)
        return st;
    const float *horizons = req->horizons;
    const size_t cells = (size_t)req->grid->width * req->grid->height;
    const size_t bytes = cells * sizeof(float);
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK)
        return J.st;
    cl_mem xb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, req->nx, "normals");
    cl_mem yb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, req->ny, "normals");
    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, req->nz, "normals");
    cl_mem h0 = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, horizons + cells * p.k0,
                                 "horizon plane");
    cl_mem h1 = p.k1 == p.k0 ? h0
                             : ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes,
                                                horizons + cells * p.k1, "horizon plane");
    cl_mem ob = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, bytes, NULL, "direct light");
    cl_kernel k = ts_cl_job_kernel(&J, "ts_direct");
    const cl_long ccells = (cl_long)cells;
    const cl_float fw = (float)p.w;
    /* as core/shading.c */
    const cl_float el_deg = (float)req->sun_elevation, inv_r = (float)(1.0 / p.radius);
    ts_cl_job_args(&J, k, 0,
                   TS_CL_ARGS(TS_CL_ARG(xb), TS_CL_ARG(yb), TS_CL_ARG(zb), TS_CL_ARG(h0),
                              TS_CL_ARG(h1), TS_CL_ARG(ccells), TS_CL_ARG(fw),
                              TS_CL_ARG(p.light[0]), TS_CL_ARG(p.light[1]),
                              TS_CL_ARG(p.light[2]), TS_CL_ARG(el_deg), TS_CL_ARG(inv_r),
                              TS_CL_ARG(ob)));
    size_t L = ts_cl_job_wg(&J, k, 256), global = ts_cl_round_up(cells, L);
    ts_cl_job_run(&J, k, 1, &global, &L, "ts_direct");
    ts_cl_job_read(&J, ob, 0, bytes, req->out, "direct light");
    return ts_cl_job_end(&J);
}

/* ------------------------------------------------------------------ sky */

ts_status ts_cl_sky_terms(const ts_sky_request *req, ts_error *err)
{
    ts_status st = ts_check_sky_request(req, err);
    if (st != TS_OK)
        return st;
    const ts_horizon_opts *opts = req->opts;
    const int n = opts->directions;
    float *outs[3] = {req->svf, req->sky, req->openness};
    const cl_int want = (outs[0] ? 1 : 0) | (outs[1] ? 2 : 0) | (outs[2] ? 4 : 0) |
                        (outs[0] && req->svf_model == TS_SVF_SOLID_ANGLE ? 8 : 0);
    if (!want)
        return ts_ok(err);
    const size_t cells = (size_t)req->grid->width * req->grid->height;
    const size_t bytes = cells * sizeof(float);
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK)
        return J.st;
    /* Planes per launch: what one buffer and half the budget hold. */
    size_t A = (size_t)n;
    if (A > J.max_alloc / bytes)
        A = J.max_alloc / bytes;
    if (A > J.budget / 2 / bytes)
        A = J.budget / 2 / bytes;
    if (A < 1)
        A = 1;
    float *sa = malloc((size_t)n * sizeof *sa), *ca = malloc((size_t)n * sizeof *ca);
    if (!sa || !ca)
        ts_cl_job_fail(&J, TS_ERR_NOMEM, "cannot allocate the azimuth tables");
    else
        for (int k = 0; k < n; k++) {
            double a = ts_horizon_azimuth(opts, k);
            sa[k] = (float)sin(a * DEG2RAD);
            ca[k] = (float)cos(a * DEG2RAD);
        }
    cl_mem xb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, req->nx, "normals");
    cl_mem yb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, req->ny, "normals");
    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, req->nz, "normals");
    cl_mem pb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, A * bytes, NULL, "horizon planes");
    cl_mem sab = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, (size_t)n * sizeof *sa, sa, "azimuths");
    cl_mem cab = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, (size_t)n * sizeof *ca, ca, "azimuths");
    cl_mem acc[3];
    for (int i = 0; i < 3; i++) {
        acc[i] = ts_cl_job_buffer(&J, CL_MEM_READ_WRITE, (want >> i & 1) ? bytes : 16, NULL,
                                  "sky accumulators");
        ts_cl_job_fill0(&J, acc[i], (want >> i & 1) ? bytes : 16, "sky accumulators");
    }
    cl_kernel k = ts_cl_job_kernel(&J, "ts_sky");
    const cl_long ccells = (cl_long)cells;
    const cl_float w1 = (float)(1.0 / n), w2 = (float)(sin(M_PI / n) / M_PI), fn = (float)n;
    ts_cl_job_args(&J, k, 0,
                   TS_CL_ARGS(TS_CL_ARG(xb), TS_CL_ARG(yb), TS_CL_ARG(zb), TS_CL_ARG(pb)));
    ts_cl_job_arg(&J, k, 5, sizeof ccells, &ccells);
    ts_cl_job_args(&J, k, 8, TS_CL_ARGS(TS_CL_ARG(w1), TS_CL_ARG(w2), TS_CL_ARG(want)));
    ts_cl_job_args(&J, k, 12,
                   TS_CL_ARGS(TS_CL_ARG(fn), TS_CL_ARG(acc[0]), TS_CL_ARG(acc[1]),
                              TS_CL_ARG(acc[2])));
    size_t L = ts_cl_job_wg(&J, k, 256), global = ts_cl_round_up(cells, L);
    for (int first = 0; first < n && J.st == TS_OK; first += (int)A) {
        const cl_int nb = n - first < (int)A ? n - first : (int)A;
        const cl_int finish = first + nb >= n;
        ts_cl_job_write(&J, pb, 0, (size_t)nb * bytes, req->horizons + cells * first,
                        "horizon planes");
        /* sa/ca of this batch: sub-buffers would need alignment; offset
         * copies are simpler. */
        ts_cl_job_write(&J, sab, 0, (size_t)nb * sizeof *sa, sa + first, "azimuths");
        ts_cl_job_write(&J, cab, 0, (size_t)nb * sizeof *ca, ca + first, "azimuths");
        ts_cl_job_arg(&J, k, 4, sizeof nb, &nb);
        ts_cl_job_args(&J, k, 6, TS_CL_ARGS(TS_CL_ARG(sab), TS_CL_ARG(cab)));
        ts_cl_job_arg(&J, k, 11, sizeof finish, &finish);
        ts_cl_job_run(&J, k, 1, &global, &L, "ts_sky");
    }
    for (int i = 0; i < 3; i++)
        if (outs[i])
            ts_cl_job_read(&J, acc[i], 0, bytes, outs[i], "sky terms");
    st = ts_cl_job_end(&J);
    free(sa);
    free(ca);
    return st;
}
