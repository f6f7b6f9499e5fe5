/*
 * The OpenCL backend when the library is built without OpenCL (configure
 * found no CL/cl.h or libOpenCL): every function exists and reports that.
 */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include "status_internal.h"
#include "terrashade_cl.h"

#define NOT_BUILT(err)                                                                         \
    ts_fail(err, TS_ERR_INTERNAL,                                                              \
            "OpenCL support was not built (configure found no OpenCL headers or library)")

int ts_cl_built(void)
{
    return 0;
}

ts_status ts_cl_available(ts_cl_info *info, ts_error *err)
{
    (void)info;
    return NOT_BUILT(err);
}

ts_status ts_cl_peek(ts_cl_info *info, ts_error *err)
{
    (void)info;
    return NOT_BUILT(err);
}

ts_status ts_cl_devices(ts_cl_info *list, int max, int *count, ts_error *err)
{
    (void)list;
    (void)max;
    if (count)
        *count = 0;
    return NOT_BUILT(err);
}

ts_status ts_cl_horizon_sweep(const ts_grid *grid, double azimuth, const ts_horizon_opts *opts,
                              float *out, ts_error *err)
{
    (void)grid, (void)azimuth, (void)opts, (void)out;
    return NOT_BUILT(err);
}

ts_status ts_cl_horizon_sweeps(const ts_grid *grid, const double *azimuths, int n,
                               const ts_horizon_opts *opts, float *out, ts_error *err)
{
    (void)grid, (void)azimuths, (void)n, (void)opts, (void)out;
    return NOT_BUILT(err);
}

ts_status ts_cl_horizon_compute(const ts_grid *grid, const ts_horizon_opts *opts, float *out,
                                ts_error *err)
{
    (void)grid, (void)opts, (void)out;
    return NOT_BUILT(err);
}

ts_status ts_cl_shm_compute(const ts_grid *grid, double azimuth, double elevation,
                            double penumbra_depth, int threads, float *visibility,
                            float *shadow_height, ts_error *err)
{
    (void)grid, (void)azimuth, (void)elevation, (void)penumbra_depth, (void)threads;
    (void)visibility, (void)shadow_height;
    return NOT_BUILT(err);
}

ts_status ts_cl_normals(const ts_grid *grid, float *nx, float *ny, float *nz, ts_error *err)
{
    (void)grid, (void)nx, (void)ny, (void)nz;
    return NOT_BUILT(err);
}

ts_status ts_cl_shade_direct(const ts_direct_request *req, ts_error *err)
{
    (void)req;
    return NOT_BUILT(err);
}

ts_status ts_cl_shadowmap_compute(const ts_grid *grid, double azimuth, double elevation,
                                  const ts_shadowmap_opts *opts, float *visibility,
                                  ts_error *err)
{
    (void)grid, (void)azimuth, (void)elevation, (void)opts, (void)visibility;
    return NOT_BUILT(err);
}

ts_status ts_cl_sky_terms(const ts_sky_request *req, ts_error *err)
{
    (void)req;
    return NOT_BUILT(err);
}

ts_status ts_cl_env_light_accumulate(const ts_env_light_request *req, ts_error *err)
{
    (void)req;
    return NOT_BUILT(err);
}

ts_status ts_cl_env_light_open(const ts_env_light_request *req, ts_cl_env_light **session,
                               ts_error *err)
{
    (void)req;
    if (session)
        *session = NULL;
    return NOT_BUILT(err);
}

int ts_cl_env_light_matches(const ts_cl_env_light *session, const ts_env_light_request *req)
{
    (void)session, (void)req;
    return 0;
}

ts_status ts_cl_env_light_add(ts_cl_env_light *session, const ts_env_light_request *req,
                              ts_error *err)
{
    (void)session, (void)req;
    return NOT_BUILT(err);
}

void ts_cl_env_light_close(ts_cl_env_light *session)
{
    (void)session;
}
