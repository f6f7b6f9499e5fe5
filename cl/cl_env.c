/*
 * Environment light on the OpenCL device (kernel cl/envlight.cl): a session
 * per product holds the light table and the normals on the device, uploaded
 * once; each horizon plane is one upload and one launch. The accumulators
 * live on the device too and are read back after every plane, so that the
 * caller's r, g, b always hold the sum so far (a later failure can go on in
 * C from there).
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <stdlib.h>
#include <string.h>

#include "arg_checks.h"
#include "cl_internal.h"
#include "status_internal.h"

struct ts_cl_env_light {
    ts_cl_job J;
    int W, H;
    size_t cells;
    const ts_env_table *table;
    const float *lp, *nx, *ny, *nz;
    const float *acc_host[3]; /* the host arrays the device accumulators mirror */
    cl_mem plane, acc[3];
    cl_kernel k;
    size_t L, global;
};

ts_status ts_cl_env_light_open(const ts_env_light_request *req, ts_cl_env_light **out,
                               ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "the session pointer must not be NULL");
    *out = NULL;
    ts_status st = ts_check_env_light_request(req, err);
    if (st != TS_OK)
        return st;
    const ts_grid *grid = req->grid;
    const ts_env_table *table = req->table;
    ts_cl_env_light *s = calloc(1, sizeof *s);
    if (!s)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the OpenCL environment light");
    ts_cl_job *J = &s->J;
    if ((st = ts_cl_job_begin(J, err)) != TS_OK) {
        free(s);
        return st;
    }
    s->W = grid->width, s->H = grid->height;
    s->cells = (size_t)grid->width * grid->height;
    s->table = table, s->lp = table->lp, s->nx = req->nx, s->ny = req->ny, s->nz = req->nz;
    const size_t bytes = s->cells * sizeof(float);
    const size_t lp_bytes = ts_env_table_sector_floats(table) * table->directions * sizeof(float);
    cl_mem lpb = ts_cl_job_buffer(J, CL_MEM_READ_ONLY, lp_bytes, table->lp, "light table");
    cl_mem xb = ts_cl_job_buffer(J, CL_MEM_READ_ONLY, bytes, req->nx, "normals");
    cl_mem yb = ts_cl_job_buffer(J, CL_MEM_READ_ONLY, bytes, req->ny, "normals");
    cl_mem zb = ts_cl_job_buffer(J, CL_MEM_READ_ONLY, bytes, req->nz, "normals");
    s->plane = ts_cl_job_buffer(J, CL_MEM_READ_ONLY, bytes, NULL, "horizon plane");
    for (int c = 0; c < 3; c++)
        s->acc[c] = ts_cl_job_buffer(J, CL_MEM_READ_WRITE, bytes, NULL, "light accumulators");
    s->k = ts_cl_job_kernel(J, "ts_env_light");
    const cl_long ccells = (cl_long)s->cells;
    const cl_int nn = table->normal_steps, nh = table->horizon_steps;
    ts_cl_job_args(J, s->k, 0,
                   TS_CL_ARGS(TS_CL_ARG(xb), TS_CL_ARG(yb), TS_CL_ARG(zb), TS_CL_ARG(s->plane),
                              TS_CL_ARG(ccells), TS_CL_ARG(lpb)));
    ts_cl_job_args(J, s->k, 7, TS_CL_ARGS(TS_CL_ARG(nn), TS_CL_ARG(nh)));
    ts_cl_job_args(J, s->k, 11,
                   TS_CL_ARGS(TS_CL_ARG(s->acc[0]), TS_CL_ARG(s->acc[1]), TS_CL_ARG(s->acc[2])));
    s->L = ts_cl_job_wg(J, s->k, 256);
    s->global = ts_cl_round_up(s->cells, s->L);
    if (J->st != TS_OK) {
        st = ts_cl_job_end(J);
        free(s);
        return st;
    }
    *out = s;
    return ts_ok(err);
}

int ts_cl_env_light_matches(const ts_cl_env_light *s, const ts_env_light_request *req)
{
    return s && req && req->grid && req->table && s->W == req->grid->width &&
           s->H == req->grid->height && s->table == req->table && s->lp == req->table->lp &&
           s->nx == req->nx && s->ny == req->ny && s->nz == req->nz;
}

ts_status ts_cl_env_light_add(ts_cl_env_light *s, const ts_env_light_request *req, ts_error *err)
{
    ts_status st = ts_check_env_light_request(req, err);
    if (st != TS_OK)
        return st;
    if (!s || !ts_cl_env_light_matches(s, req))
        return ts_fail(err, TS_ERR_ARG, "the OpenCL environment light was opened for another "
                                        "grid, light table or normals");
    ts_cl_job *J = &s->J;
    if (J->st != TS_OK) /* an earlier failure is final */
        return ts_fail(err, J->st, "the OpenCL environment light failed before");
    J->err = err;
    const size_t bytes = s->cells * sizeof(float);
    float *host[3] = {req->r, req->g, req->b};
    for (int c = 0; c < 3; c++)
        if (s->acc_host[c] != host[c]) { /* new accumulators: start from their sums */
            ts_cl_job_write(J, s->acc[c], 0, bytes, host[c], "light accumulators");
            s->acc_host[c] = host[c];
        }
    float sa, ca;
    ts_env_sector_sincos(req->table, req->k, &sa, &ca);
    const cl_long off = (cl_long)(ts_env_table_sector_floats(req->table) * (size_t)req->k);
    ts_cl_job_write(J, s->plane, 0, bytes, req->plane, "horizon plane");
    ts_cl_job_arg(J, s->k, 6, sizeof off, &off);
    ts_cl_job_args(J, s->k, 9, TS_CL_ARGS(TS_CL_ARG(sa), TS_CL_ARG(ca)));
    ts_cl_job_run(J, s->k, 1, &s->global, &s->L, "ts_env_light");
    for (int c = 0; c < 3; c++)
        ts_cl_job_read(J, s->acc[c], 0, bytes, host[c], "light accumulators");
    if (J->st != TS_OK) {
        memset(s->acc_host, 0, sizeof s->acc_host); /* the host sums are suspect now */
        return J->st;
    }
    return ts_ok(err);
}

void ts_cl_env_light_close(ts_cl_env_light *s)
{
    if (!s)
        return;
    ts_error e;
    s->J.err = &e;
    s->J.st = TS_OK; /* release everything, whatever happened before */
    ts_cl_job_end(&s->J);
    free(s);
}

/* One plane: a session for it alone (open checks the request). */
ts_status ts_cl_env_light_accumulate(const ts_env_light_request *req, ts_error *err)
{
    ts_cl_env_light *s;
    ts_status st = ts_cl_env_light_open(req, &s, err);
    if (st != TS_OK)
        return st;
    st = ts_cl_env_light_add(s, req, err);
    ts_cl_env_light_close(s);
    return st;
}
