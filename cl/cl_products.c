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
    ts_cl_job_arg(&J, k, 0, sizeof zb, &zb);
    ts_cl_job_arg(&J, k, 1, sizeof cW, &cW);
    ts_cl_job_arg(&J, k, 2, sizeof xm, &xm);
    ts_cl_job_arg(&J, k, 3, sizeof V, &V);
    ts_cl_job_arg(&J, k, 4, sizeof us, &us);
    ts_cl_job_arg(&J, k, 5, sizeof ustep, &ustep);
    ts_cl_job_arg(&J, k, 6, sizeof off, &off);
    ts_cl_job_arg(&J, k, 7, sizeof F, &F);
    ts_cl_job_arg(&J, k, 8, sizeof db, &db);
    ts_cl_job_arg(&J, k, 9, sizeof depth, &depth);
    ts_cl_job_arg(&J, k, 12, sizeof hlo, &hlo);
    ts_cl_job_arg(&J, k, 13, sizeof hhi, &hhi);
    ts_cl_job_arg(&J, k, 16, sizeof vb, &vb);
    ts_cl_job_arg(&J, k, 17, sizeof hb, &hb);
    ts_cl_job_arg(&J, k, 18, sizeof want_vis, &want_vis);
    ts_cl_job_arg(&J, k, 19, sizeof want_sh, &want_sh);
    ts_cl_job_arg(&J, k, 20, 2 * E * sizeof(float), NULL);
    cl_mem in = s0, outm = s1;
    for (int k0 = 0; k0 < G.U && J.st == TS_OK; k0 += (int)K) {
        const cl_int ck0 = k0, nrows = G.U - k0 < (int)K ? G.U - k0 : (int)K;
        ts_cl_job_arg(&J, k, 10, sizeof ck0, &ck0);
        ts_cl_job_arg(&J, k, 11, sizeof nrows, &nrows);
        ts_cl_job_arg(&J, k, 14, sizeof in, &in);
        ts_cl_job_arg(&J, k, 15, sizeof outm, &outm);
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
    ts_cl_job_arg(&J, k, 0, sizeof zb, &zb);
    ts_cl_job_arg(&J, k, 1, sizeof cW, &cW);
    ts_cl_job_arg(&J, k, 2, sizeof cH, &cH);
    ts_cl_job_arg(&J, k, 3, sizeof cb, &cb);
    ts_cl_job_arg(&J, k, 4, sizeof has, &has);
    ts_cl_job_arg_real(&J, k, 5, grid->cell_x);
    ts_cl_job_arg_real(&J, k, 6, grid->cell_y);
    ts_cl_job_arg(&J, k, 7, sizeof xb, &xb);
    ts_cl_job_arg(&J, k, 8, sizeof yb, &yb);
    ts_cl_job_arg(&J, k, 9, sizeof zzb, &zzb);
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

ts_status ts_cl_shade_direct(const ts_grid *grid, const float *nx, const float *ny,
                             const float *nz, const float *horizons, const ts_horizon_opts *opts,
                             double sun_azimuth, double sun_elevation, float *out, ts_error *err)
{
    return ts_cl_shade_direct_disk(grid, nx, ny, nz, horizons, opts, sun_azimuth, sun_elevation,
                                   TS_SUN_RADIUS_DEG, out, err);
}

ts_status ts_cl_shade_direct_disk(const ts_grid *grid, const float *nx, const float *ny,
                                  const float *nz, const float *horizons,
                                  const ts_horizon_opts *opts, double sun_azimuth,
                                  double sun_elevation, double light_radius, float *out,
                                  ts_error *err)
{
    int k0, k1;
    double w;
    cl_float light[3];
    ts_status st = ts_check_light_radius(light_radius, err);
    if (st != TS_OK)
        return st;
    st = ts_direct_setup(grid, nx, ny, nz, horizons, opts, sun_azimuth, sun_elevation,
                                   out, &k0, &k1, &w, light, err);
    if (st != TS_OK)
        return st;
    const size_t cells = (size_t)grid->width * grid->height, bytes = cells * sizeof(float);
    ts_cl_job J;
    if (ts_cl_job_begin(&J, err) != TS_OK)
        return J.st;
    cl_mem xb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, nx, "normals");
    cl_mem yb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, ny, "normals");
    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, nz, "normals");
    cl_mem h0 = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, horizons + cells * k0,
                                 "horizon plane");
    cl_mem h1 = k1 == k0 ? h0
                         : ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, horizons + cells * k1,
                                            "horizon plane");
    cl_mem ob = ts_cl_job_buffer(&J, CL_MEM_WRITE_ONLY, bytes, NULL, "direct light");
    cl_kernel k = ts_cl_job_kernel(&J, "ts_direct");
    const cl_long ccells = (cl_long)cells;
    ts_cl_job_arg(&J, k, 0, sizeof xb, &xb);
    ts_cl_job_arg(&J, k, 1, sizeof yb, &yb);
    ts_cl_job_arg(&J, k, 2, sizeof zb, &zb);
    ts_cl_job_arg(&J, k, 3, sizeof h0, &h0);
    ts_cl_job_arg(&J, k, 4, sizeof h1, &h1);
    ts_cl_job_arg(&J, k, 5, sizeof ccells, &ccells);
    const cl_float fw = (float)w;
    ts_cl_job_arg(&J, k, 6, sizeof fw, &fw);
    for (int j = 0; j < 3; j++)
        ts_cl_job_arg(&J, k, 7 + j, sizeof light[j], &light[j]);
    /* as core/shading.c */
    const cl_float el_deg = (float)sun_elevation, inv_r = (float)(1.0 / light_radius);
    ts_cl_job_arg(&J, k, 10, sizeof el_deg, &el_deg);
    ts_cl_job_arg(&J, k, 11, sizeof inv_r, &inv_r);
    ts_cl_job_arg(&J, k, 12, sizeof ob, &ob);
    size_t L = ts_cl_job_wg(&J, k, 256), global = ts_cl_round_up(cells, L);
    ts_cl_job_run(&J, k, 1, &global, &L, "ts_direct");
    ts_cl_job_read(&J, ob, 0, bytes, out, "direct light");
    return ts_cl_job_end(&J);
}

/* ------------------------------------------------------------------ sky */

ts_status ts_cl_sky_terms(const ts_grid *grid, const float *nx, const float *ny, const float *nz,
                          const float *horizons, const ts_horizon_opts *opts, float *svf,
                          float *sky, float *openness, ts_error *err)
{
    return ts_cl_sky_terms_model(grid, nx, ny, nz, horizons, opts, TS_SVF_RADIATIVE, svf, sky,
                                 openness, err);
}

ts_status ts_cl_sky_terms_model(const ts_grid *grid, const float *nx, const float *ny,
                                const float *nz, const float *horizons,
                                const ts_horizon_opts *opts, ts_svf_model svf_model, float *svf,
                                float *sky, float *openness, ts_error *err)
{
    ts_status st = ts_check_sky_terms_args(grid, nx, ny, nz, horizons, opts, err);
    if (st == TS_OK)
        st = ts_check_svf_model(svf_model, err);
    if (st != TS_OK)
        return st;
    const int n = opts->directions;
    const cl_int want = (svf ? 1 : 0) | (sky ? 2 : 0) | (openness ? 4 : 0) |
                        (svf && svf_model == TS_SVF_SOLID_ANGLE ? 8 : 0);
    if (!want)
        return ts_ok(err);
    const size_t cells = (size_t)grid->width * grid->height, bytes = cells * sizeof(float);
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
    cl_mem xb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, nx, "normals");
    cl_mem yb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, ny, "normals");
    cl_mem zb = ts_cl_job_buffer(&J, CL_MEM_READ_ONLY, bytes, nz, "normals");
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
    ts_cl_job_arg(&J, k, 0, sizeof xb, &xb);
    ts_cl_job_arg(&J, k, 1, sizeof yb, &yb);
    ts_cl_job_arg(&J, k, 2, sizeof zb, &zb);
    ts_cl_job_arg(&J, k, 3, sizeof pb, &pb);
    ts_cl_job_arg(&J, k, 5, sizeof ccells, &ccells);
    ts_cl_job_arg(&J, k, 8, sizeof w1, &w1);
    ts_cl_job_arg(&J, k, 9, sizeof w2, &w2);
    ts_cl_job_arg(&J, k, 10, sizeof want, &want);
    ts_cl_job_arg(&J, k, 12, sizeof fn, &fn);
    ts_cl_job_arg(&J, k, 13, sizeof acc[0], &acc[0]);
    ts_cl_job_arg(&J, k, 14, sizeof acc[1], &acc[1]);
    ts_cl_job_arg(&J, k, 15, sizeof acc[2], &acc[2]);
    size_t L = ts_cl_job_wg(&J, k, 256), global = ts_cl_round_up(cells, L);
    for (int first = 0; first < n && J.st == TS_OK; first += (int)A) {
        const cl_int nb = n - first < (int)A ? n - first : (int)A;
        const cl_int finish = first + nb >= n;
        ts_cl_job_write(&J, pb, 0, (size_t)nb * bytes, horizons + cells * first,
                        "horizon planes");
        /* sa/ca of this batch: sub-buffers would need alignment; offset
         * copies are simpler. */
        ts_cl_job_write(&J, sab, 0, (size_t)nb * sizeof *sa, sa + first, "azimuths");
        ts_cl_job_write(&J, cab, 0, (size_t)nb * sizeof *ca, ca + first, "azimuths");
        ts_cl_job_arg(&J, k, 4, sizeof nb, &nb);
        ts_cl_job_arg(&J, k, 6, sizeof sab, &sab);
        ts_cl_job_arg(&J, k, 7, sizeof cab, &cab);
        ts_cl_job_arg(&J, k, 11, sizeof finish, &finish);
        ts_cl_job_run(&J, k, 1, &global, &L, "ts_sky");
    }
    float *outs[3] = {svf, sky, openness};
    for (int i = 0; i < 3; i++)
        if (outs[i])
            ts_cl_job_read(&J, acc[i], 0, bytes, outs[i], "sky terms");
    st = ts_cl_job_end(&J);
    free(sa);
    free(ca);
    return st;
}
