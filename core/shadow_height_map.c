/*
 * Shadow height map (Lee & Kim): S = max(h, S_prev - step * tan(elevation)),
 * where S_prev is the shadow height one step toward the light, linearly
 * interpolated between two cells. The recurrence walks along the major axis
 * u of the light direction (the same line geometry as the horizon sweep);
 * the whole u-row shares one interpolation offset, so the inner loop over v
 * is a plain vectorisable loop when v is contiguous in memory.
 *
 * Threads split v into bands and run as a wavefront: a band starts step k
 * once its neighbours have finished step k - 1 (a step reads v - 1..v + 1).
 */
#include <math.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>

#include "line_geometry.h"
#include "parallel.h"
#include "status_internal.h"

typedef struct {
    const ts_grid *grid;
    const ts_line_geom *G;
    double tan_el;
    float depth;
    float *vis, *sh;           /* outputs, row stride = width, may be NULL */
    float *ring[2];            /* S of the previous and current u-row */
    int off;                   /* S_prev(v) is interpolated at v + off + F */
    float F;
    int bands;
    atomic_long *progress;     /* per band: last finished step */
    ptrdiff_t o_origin, o_u_stride, o_v_stride;
} shm_ctx;

/* S of one cell from its height and the previous u-row. */
static inline float shm_cell(const float *prev, int v, int V, int off, float F, float h,
                             float drop, int first)
{
    float p = NAN;
    if (!first) {
        int a = v + off, b = a + 1;
        float pa = (a >= 0 && a < V) ? prev[a] : NAN;
        float pb = (F > 0.0f && b >= 0 && b < V) ? prev[b] : NAN;
        if (F == 0.0f || isnan(pb))
            p = pa;
        else if (isnan(pa))
            p = pb;
        else
            p = pa + F * (pb - pa);
        p -= drop;
    }
    if (isnan(h))
        return p;              /* nodata is no occluder: the shadow passes */
    return (isnan(p) || h >= p) ? h : p;
}

static inline float visibility(float s, float h, float depth)
{
    if (isnan(h))
        return NAN;
    float under = s - h;
    if (depth <= 0.0f)
        return under > 0.0f ? 0.0f : 1.0f;
    float a = under / depth;
    return 1.0f - (a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a);
}

static void wait_for(atomic_long *p, long step)
{
    while (atomic_load_explicit(p, memory_order_acquire) < step)
        sched_yield();
}

/* Bands [begin, end) as one contiguous v range; waits only on the bands
 * beside the range. */
static void shm_bands(void *ctx, int worker, long begin, long end)
{
    const shm_ctx *C = ctx;
    const ts_line_geom *G = C->G;
    const ts_grid *grid = C->grid;
    const int V = G->V;
    const float *z = grid->z;
    (void)worker;
    int v0 = (int)((long)V * begin / C->bands), v1 = (int)((long)V * end / C->bands);
    for (int k = 0; k < G->U; k++) {
        if (k > 0) {
            if (begin > 0)
                wait_for(&C->progress[begin - 1], k - 1);
            if (end < C->bands)
                wait_for(&C->progress[end], k - 1);
        }
        const float *prev = C->ring[(k + 1) & 1];
        float *cur = C->ring[k & 1];
        int u = G->u_start + k * G->u_step;
        const float *zrow = z + G->origin + (ptrdiff_t)k * G->u_stride;
        ptrdiff_t orow = C->o_origin + (ptrdiff_t)k * C->o_u_stride;
        if (G->x_major) {
            /* v = y: strided, per-row step length. */
            for (int v = v0; v < v1; v++) {
                double step = G->step_row ? G->step_row[v] : G->step_m;
                float h = zrow[(ptrdiff_t)v * G->v_stride];
                cur[v] = shm_cell(prev, v, V, C->off, C->F, h, (float)(step * C->tan_el), k == 0);
            }
        } else {
            /* v = x: contiguous, one step length per row u. */
            double step = G->step_row ? G->step_row[u] : G->step_m;
            float drop = (float)(step * C->tan_el);
            for (int v = v0; v < v1; v++)
                cur[v] = shm_cell(prev, v, V, C->off, C->F, zrow[v], drop, k == 0);
        }
        for (int v = v0; v < v1; v++) {
            ptrdiff_t o = orow + (ptrdiff_t)v * C->o_v_stride;
            float h = zrow[(ptrdiff_t)v * G->v_stride];
            if (C->sh)
                C->sh[o] = cur[v];
            if (C->vis)
                C->vis[o] = visibility(cur[v], h, C->depth);
        }
        for (long b = begin; b < end; b++)
            atomic_store_explicit(&C->progress[b], k, memory_order_release);
    }
}

ts_status ts_shm_compute(const ts_grid *grid, double azimuth, double elevation,
                         double penumbra_depth, int threads, float *vis,
                         float *shadow_height, ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!isfinite(azimuth))
        return ts_fail(err, TS_ERR_ARG, "sun azimuth must be a finite number of degrees, got %g",
                       azimuth);
    if (!(elevation >= -90 && elevation <= 90))
        return ts_fail(err, TS_ERR_ARG, "sun elevation must be between -90 and 90, got %g",
                       elevation);
    if (!(penumbra_depth >= 0) || isinf(penumbra_depth))
        return ts_fail(err, TS_ERR_ARG,
                       "penumbra depth must be 0 (hard shadows) or a positive number of metres, got %g",
                       penumbra_depth);
    if (threads < 0)
        return ts_fail(err, TS_ERR_ARG, "threads must be 0 (all cores) or more, got %d", threads);
    if (!vis && !shadow_height)
        return ts_fail(err, TS_ERR_ARG, "both outputs are NULL");
    azimuth = fmod(azimuth, 360.0);
    if (azimuth < 0)
        azimuth += 360.0;
    ts_line_geom G;
    if ((st = ts_line_geom_init(&G, grid, azimuth, err)) != TS_OK)
        return st;
    shm_ctx C = {0};
    C.grid = grid;
    C.G = &G;
    C.tan_el = elevation >= 90 ? 1e30 : tan(elevation * M_PI / 180.0);
    C.depth = (float)penumbra_depth;
    C.vis = vis;
    C.sh = shadow_height;
    double q = -G.t, fq = floor(q);
    C.off = (int)fq;
    C.F = (float)(q - fq);
    ptrdiff_t ou = G.x_major ? 1 : grid->width;
    C.o_v_stride = G.x_major ? grid->width : 1;
    C.o_u_stride = ou * G.u_step;
    C.o_origin = ou * G.u_start;
    /* Bands of at least 64 cells, so the wavefront waits stay rare. */
    C.bands = ts_thread_count(threads, G.V / 64 > 0 ? G.V / 64 : 1);
    C.ring[0] = malloc((size_t)G.V * sizeof(float));
    C.ring[1] = malloc((size_t)G.V * sizeof(float));
    C.progress = malloc((size_t)C.bands * sizeof *C.progress);
    if (!C.ring[0] || !C.ring[1] || !C.progress) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate shadow height map rows");
    } else {
        for (int i = 0; i < C.bands; i++)
            atomic_init(&C.progress[i], -1L);
        st = ts_parallel_for(C.bands, C.bands, shm_bands, &C, err);
    }
    free(C.ring[0]);
    free(C.ring[1]);
    free(C.progress);
    ts_line_geom_free(&G);
    return st;
}
