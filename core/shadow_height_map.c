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

#include "arg_checks.h"
#include "cellmath/cm_shm.h"
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
    int *failed;               /* set when a band cannot get its buffers */
    ptrdiff_t o_origin, o_u_stride, o_v_stride;
} shm_ctx;

/* S of one cell from its height and the previous u-row, where the
 * interpolation may reach past the grid's edge. */
static inline float shm_cell(const float *prev, int v, int V, int off, float F, float h,
                             float drop, int first)
{
    float pa = NAN, pb = NAN;
    int a = v + off, b = a + 1;
    /* Off the grid toward the light there is nothing to cast a shadow. */
    int off_grid = a < 0 || a >= V || (F > 0.0f && (b < 0 || b >= V));
    if (!first && !off_grid) {
        pa = prev[a];
        pb = F > 0.0f ? prev[b] : NAN;
    }
    return cm_shm_step(pa, pb, F, drop, h);
}

static void wait_for(atomic_long *p, long step)
{
    while (atomic_load_explicit(p, memory_order_acquire) < step)
        sched_yield();
}

/*
 * One u-row of the recurrence for v0 <= v < v1: cur[v] from prev, heights
 * h[v] (contiguous), the drop per v (dropv, or the constant drop), then the
 * outputs vis[v] / sh[v] (contiguous, may be NULL). Cells whose
 * interpolation reaches past the grid edge go through shm_cell; the rest is
 * a branch-free loop the compiler vectorises.
 */
static void shm_row(const float *restrict prev, float *restrict cur, const float *restrict h,
                    const float *restrict dropv, float drop, int v0, int v1, int V, int off,
                    float F, int first, float depth, float *restrict vis, float *restrict sh)
{
    /* interior: both v + off and v + off + 1 inside [0, V - 1] */
    int lo = -off > v0 ? -off : v0, hi = V - 1 - off < v1 ? V - 1 - off : v1;
    if (first || lo > hi) {
        lo = v1;
        hi = v1;
    }
    for (int v = v0; v < lo; v++)
        cur[v] = shm_cell(prev, v, V, off, F, h[v], dropv ? dropv[v] : drop, first);
    for (int v = hi; v < v1; v++)
        cur[v] = shm_cell(prev, v, V, off, F, h[v], dropv ? dropv[v] : drop, first);
    const float *restrict pa_ = prev + off, *restrict pb_ = prev + off + 1;
    for (int v = lo; v < hi; v++)
        cur[v] = cm_shm_step(pa_[v], F > 0.0f ? pb_[v] : pa_[v], F,
                             dropv ? dropv[v] : drop, h[v]);
    for (int v = v0; v < v1; v++) {
        if (vis)
            vis[v] = cm_shm_lit(cur[v], h[v], depth);
        if (sh)
            sh[v] = cur[v];
    }
}

/* Columns of x-major light are handled TILE u-rows at a time through
 * transposed copies, so that the recurrence runs on contiguous memory. */
#define TILE 32

/* Bands [begin, end) as one contiguous v range; waits only on the bands
 * beside the range. */
static void shm_bands(void *ctx, int worker, long begin, long end)
{
    const shm_ctx *C = ctx;
    const ts_line_geom *G = C->G;
    const ts_grid *grid = C->grid;
    const int V = G->V;
    (void)worker;
    int v0 = (int)((long)V * begin / C->bands), v1 = (int)((long)V * end / C->bands);
    int tile = G->x_major ? TILE : 1;
    /* transposed tiles (x-major only): heights, visibility, shadow height */
    float *th = NULL, *tv = NULL, *ts = NULL, *dropv = NULL;
    if (G->x_major) {
        size_t n = (size_t)TILE * V;
        th = malloc(n * sizeof *th);
        tv = C->vis ? malloc(n * sizeof *tv) : NULL;
        ts = C->sh ? malloc(n * sizeof *ts) : NULL;
        dropv = malloc((size_t)V * sizeof *dropv);
        if (!th || (C->vis && !tv) || (C->sh && !ts) || !dropv) {
            free(th), free(tv), free(ts), free(dropv);
            th = tv = ts = dropv = NULL;
            tile = 1; /* fall back to strided access, same arithmetic */
        } else {
            for (int v = 0; v < V; v++)
                dropv[v] = (float)((G->step_row ? G->step_row[v] : G->step_m) * C->tan_el);
        }
    }
    float *hrow = NULL, *vrow = NULL, *srow = NULL;
    if (G->x_major && !th) {
        hrow = malloc((size_t)V * sizeof *hrow);
        vrow = malloc((size_t)V * sizeof *vrow);
        srow = malloc((size_t)V * sizeof *srow);
        dropv = malloc((size_t)V * sizeof *dropv);
        if (!hrow || !vrow || !srow || !dropv) {
            /* Nothing left to try: mark the outputs as failed. */
            __atomic_store_n(C->failed, 1, __ATOMIC_RELAXED);
        } else {
            for (int v = 0; v < V; v++)
                dropv[v] = (float)((G->step_row ? G->step_row[v] : G->step_m) * C->tan_el);
        }
    }
    for (int k0 = 0; k0 < G->U; k0 += tile) {
        int kn = G->U - k0 < tile ? G->U - k0 : tile;
        if (th) /* gather: row v of the grid holds the tile's u-rows side by side */
            for (int v = v0; v < v1; v++) {
                const float *zr = grid->z + G->origin + (ptrdiff_t)v * G->v_stride;
                for (int j = 0; j < kn; j++)
                    th[(size_t)j * V + v] = zr[(ptrdiff_t)(k0 + j) * G->u_stride];
            }
        for (int j = 0; j < kn; j++) {
            int k = k0 + j;
            if (k > 0) {
                if (begin > 0)
                    wait_for(&C->progress[begin - 1], k - 1);
                if (end < C->bands)
                    wait_for(&C->progress[end], k - 1);
            }
            const float *prev = C->ring[(k + 1) & 1];
            float *cur = C->ring[k & 1];
            const float *zrow = grid->z + G->origin + (ptrdiff_t)k * G->u_stride;
            ptrdiff_t orow = C->o_origin + (ptrdiff_t)k * C->o_u_stride;
            if (th) {
                shm_row(prev, cur, th + (size_t)j * V, dropv, 0.0f, v0, v1, V, C->off, C->F,
                        k == 0, C->depth, tv ? tv + (size_t)j * V : NULL,
                        ts ? ts + (size_t)j * V : NULL);
            } else if (G->x_major) {
                if (hrow && vrow && srow && dropv) {
                    for (int v = v0; v < v1; v++)
                        hrow[v] = zrow[(ptrdiff_t)v * G->v_stride];
                    shm_row(prev, cur, hrow, dropv, 0.0f, v0, v1, V, C->off, C->F, k == 0,
                            C->depth, vrow, srow);
                    for (int v = v0; v < v1; v++) {
                        ptrdiff_t o = orow + (ptrdiff_t)v * C->o_v_stride;
                        if (C->vis)
                            C->vis[o] = vrow[v];
                        if (C->sh)
                            C->sh[o] = srow[v];
                    }
                }
            } else {
                int u = G->u_start + k * G->u_step;
                double step = G->step_row ? G->step_row[u] : G->step_m;
                shm_row(prev, cur, zrow, NULL, (float)(step * C->tan_el), v0, v1, V, C->off,
                        C->F, k == 0, C->depth, C->vis ? C->vis + orow : NULL,
                        C->sh ? C->sh + orow : NULL);
            }
            for (long b = begin; b < end; b++)
                atomic_store_explicit(&C->progress[b], k, memory_order_release);
        }
        if (th) /* scatter the tile's outputs back to grid rows */
            for (int v = v0; v < v1; v++) {
                ptrdiff_t o = C->o_origin + (ptrdiff_t)k0 * C->o_u_stride +
                              (ptrdiff_t)v * C->o_v_stride;
                for (int j = 0; j < kn; j++) {
                    if (tv)
                        C->vis[o + (ptrdiff_t)j * C->o_u_stride] = tv[(size_t)j * V + v];
                    if (ts)
                        C->sh[o + (ptrdiff_t)j * C->o_u_stride] = ts[(size_t)j * V + v];
                }
            }
    }
    free(th), free(tv), free(ts), free(dropv);
    free(hrow), free(vrow), free(srow);
}

ts_status ts_shm_compute(const ts_grid *grid, double azimuth, double elevation,
                         double penumbra_depth, int threads, float *vis,
                         float *shadow_height, ts_error *err)
{
    ts_status st = ts_check_shm_args(grid, &azimuth, elevation, penumbra_depth, threads, vis,
                                     shadow_height, err);
    if (st != TS_OK)
        return st;
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
        int failed = 0;
        C.failed = &failed;
        for (int i = 0; i < C.bands; i++)
            atomic_init(&C.progress[i], -1L);
        st = ts_parallel_for(C.bands, C.bands, shm_bands, &C, err);
        if (st == TS_OK && failed)
            st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate shadow height map buffers");
    }
    free(C.ring[0]);
    free(C.ring[1]);
    free(C.progress);
    ts_line_geom_free(&G);
    return st;
}
