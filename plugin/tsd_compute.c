/* The products of an instant and of the sky: which core calls, in which
 * order; and the dispatcher. The day products are in tsd_compute_day.c. */
#include "tsd_compute.h"

#include "tsd_compute_env.h"
#include "tsd_compute_sh.h"
#include "tsd_products.h"
#include "tsd_pyramid.h"
#include "tsd_text.h"
#include "terrashade_cl.h"
#include "disk_fraction.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tsd_region_whole(tsd_region *r, const ts_grid *dem)
{
    r->dem = dem;
    r->x0 = r->y0 = 0;
    r->width = dem->width;
    r->height = dem->height;
    r->margin = 0;
}

void tsd_run_init(tsd_run *run, const tsd_options *o, const tsd_sun *sun)
{
    memset(run, 0, sizeof *run);
    run->sun = sun;
    run->sun_azimuth = o->sun_azimuth;
    run->sun_elevation = o->sun_elevation;
    if (sun && isfinite(sun->instant) && !tsd_product_of(o)->daily) {
        /* shade, shadow: the sun at DATETIME */
        run->sun_azimuth = sun->sun.grid_azimuth;
        run->sun_elevation = sun->sun.elevation;
    }
}

static ts_status oom(const tsd_compute_ctx *c, const char *what)
{
    return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM, "out of memory for %s", what);
}

static ts_status core_fail(const tsd_compute_ctx *c, const ts_error *err)
{
    return tsd_fail_core(c->msg, c->msg_size, NULL, err);
}

void tsd_compute_horizon_opts(const tsd_compute_ctx *c, ts_horizon_opts *h)
{
    const tsd_options *o = c->opts;
    ts_horizon_opts_default(h);
    h->directions = o->directions;
    h->start_azimuth = o->start_azimuth;
    h->max_distance = o->max_distance;
    /* a window: the near field within its margin (tsd_window.h) */
    if (c->run->near_distance > 0 &&
        (h->max_distance == 0 || h->max_distance > c->run->near_distance))
        h->max_distance = c->run->near_distance;
    h->curvature = o->curvature;
    h->refraction = o->refraction;
    h->edge = tsd_options_edge(o);
    /* a window's sweep reaches its near field only: the world beyond the
     * DEM's edge joins after the far field (tsd_compute_far) */
    if (h->max_distance != o->max_distance)
        h->edge = TS_EDGE_OPEN;
    h->threads = o->threads;
    h->progress = c->run->progress;
    h->progress_user = c->run->progress_user;
}

ts_status tsd_compute_report(const tsd_compute_ctx *c, double done)
{
    if (c->run->progress && c->run->progress(done, c->run->progress_user))
        return tsd_fail(c->msg, c->msg_size, TS_ERR_CANCELLED, "cancelled by the caller");
    return TS_OK;
}

/* The backend of the options, and the report of a call added to the summary. */
#define BK(c) tsd_backend_to_ts((c)->opts->backend)
#define NOTE(c, call, rep) note((c)->backend, (call), &(rep))

/* After a ts_backend_* call (its status st): add its report, if filled. */
static ts_status note(tsd_backend_summary *bs, ts_status st, const ts_backend_report *r)
{
    if (bs && r->backend[0])
        tsd_backend_summary_add(bs, r);
    return st;
}

void tsd_normals_free(tsd_normals *nm)
{
    free(nm->nx);
    free(nm->ny);
    free(nm->nz);
}

ts_status tsd_normals_make(const tsd_compute_ctx *c, const ts_grid *g, tsd_normals *nm)
{
    size_t cells = (size_t)g->width * g->height;
    ts_error err;
    ts_backend_report rep = {0};
    nm->nx = malloc(cells * sizeof(float));
    nm->ny = malloc(cells * sizeof(float));
    nm->nz = malloc(cells * sizeof(float));
    if (!nm->nx || !nm->ny || !nm->nz)
        return oom(c, "the surface normals");
    if (NOTE(c, ts_backend_normals(BK(c), g, c->opts->threads, nm->nx, nm->ny, nm->nz, &rep,
                                   &err),
             rep) !=
        TS_OK)
        return core_fail(c, &err);
    return TS_OK;
}

/* (tsd_compute.h) By default TSD_OPENCL_BATCH_DEFAULT on a GPU, whose lines
 * of one azimuth fill a few per cent of it, and one on a CPU device, where
 * larger batches measured slower; on C one, as the sweep's threads already
 * fill the CPU and each plane is summed as it comes. */
int tsd_compute_batch(const tsd_compute_ctx *c, size_t cells, int directions)
{
    ts_backend_report rep;
    ts_cl_info info;
    ts_error err;
    char msg[256];
    const double plane = (double)cells * sizeof(float);
    int most = tsd_backend_batch(msg, sizeof msg); /* (checked at open) */
    ts_horizon_opts h;
    tsd_compute_horizon_opts(c, &h);
    /* a capped sweep (MAX_DISTANCE, a window's near field) may run on C
     * (TS_CL_CAPPED_SWEEP_REASON): its planes would wait for nothing */
    if (most == 1 || directions <= 1 || c->run->batch_bytes < plane || h.max_distance > 0 ||
        ts_backend_choose(BK(c), &rep, &err) != TS_OK || rep.used != TS_BACKEND_OPENCL)
        return 1;
    if (most <= 0)
        most = ts_cl_peek(&info, &err) == TS_OK && strcmp(info.type, "CPU")
                   ? TSD_OPENCL_BATCH_DEFAULT
                   : 1;
    const double fit = 1 + c->run->batch_bytes / plane; /* the one plane is counted */
    const int n = most < directions ? most : directions;
    return fit < n ? (int)fit : n;
}

ts_status tsd_compute_stream(const tsd_compute_ctx *c, const ts_grid *g, tsd_plane_fn add,
                             void *user)
{
    size_t cells = (size_t)g->width * g->height;
    ts_horizon_opts h;
    ts_error err;
    ts_status st = TS_OK;
    tsd_compute_horizon_opts(c, &h);
    if (c->opts->horizon_method == TSD_HORIZON_PYRAMID)
        return tsd_pyramid_stream(c, g, add, user);
    const int batch = tsd_compute_batch(c, cells, h.directions);
    float *planes = malloc((size_t)batch * cells * sizeof(float));
    double az[TSD_OPENCL_BATCH_MAX];
    if (!planes)
        return oom(c, "a horizon plane");
    h.progress = NULL; /* reported here, per call */
    for (int k0 = 0; st == TS_OK && k0 < h.directions; k0 += batch) {
        const int n = h.directions - k0 < batch ? h.directions - k0 : batch;
        ts_backend_report rep = {0};
        for (int i = 0; i < n; i++)
            az[i] = ts_horizon_azimuth(&h, k0 + i);
        if ((st = tsd_compute_report(c, (double)k0 / h.directions)) != TS_OK)
            break;
        /* the sweeps on the backend; the accumulation is C only */
        if (NOTE(c, ts_backend_horizon_sweeps(BK(c), g, az, n, &h, planes, &rep, &err), rep) !=
            TS_OK) {
            st = core_fail(c, &err);
            break;
        }
        for (int i = 0; st == TS_OK && i < n; i++) {
            float *plane = planes + (size_t)i * cells;
            if ((st = tsd_compute_far(c, g, az[i], 0, plane)) == TS_OK &&
                add(user, g, k0 + i, az[i], plane, &err) != TS_OK)
                st = core_fail(c, &err);
        }
    }
    free(planes);
    return st;
}

/* The sky products' accumulator of sky_stream. */
typedef struct {
    const tsd_normals *nm;
    int directions;
    ts_svf_model model;
    int threads;
    float *svf, *sky, *open;
} sky_acc;

static ts_status sky_add(void *user, const ts_grid *g, int k, double azimuth,
                         const float *plane, ts_error *err)
{
    (void)k;
    const sky_acc *a = user;
    return ts_sky_accumulate_model(g, a->nm->nx, a->nm->ny, a->nm->nz, plane, azimuth,
                                   a->directions, a->model, a->threads, a->svf, a->sky, a->open,
                                   err);
}

/* Stream the DIRECTIONS horizon planes into one sky accumulator; `which`:
 * 0 = svf (of SVF_MODEL), 1 = sky, 2 = openness (the horizons of g: pass
 * the negated DEM for negative openness). acc must be zeroed. */
static ts_status sky_stream(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                            int which, float *acc)
{
    ts_error err;
    ts_status st;
    sky_acc a = {nm, c->opts->directions,
                 which == 0 ? (ts_svf_model)c->opts->svf_model : TS_SVF_RADIATIVE,
                 c->opts->threads, which == 0 ? acc : NULL, which == 1 ? acc : NULL,
                 which == 2 ? acc : NULL};
    /* the negated DEM of negative openness is swept without curvature */
    tsd_options flat;
    tsd_compute_ctx cflat;
    if (which == 2 && tsd_sweeps_negated_dem(c->opts)) {
        flat = *c->opts;
        flat.curvature = 0;
        cflat = *c;
        cflat.opts = &flat;
        c = &cflat;
    }
    /* the pyramid sums each row span as it is done (the same sums) */
    ts_pyramid_sky fused = {nm->nx, nm->ny, nm->nz, a.directions, a.model, a.svf, a.sky, a.open};
    st = c->opts->horizon_method == TSD_HORIZON_PYRAMID ? tsd_pyramid_sky(c, g, &fused)
                                                        : tsd_compute_stream(c, g, sky_add, &a);
    if (st != TS_OK)
        return st;
    if (ts_sky_finish(g, a.directions, a.svf, a.sky, a.open, &err) != TS_OK)
        return core_fail(c, &err);
    return TS_OK;
}

/* Shadow height map visibility of the sun into vis. */
static ts_status shm_visibility(const tsd_compute_ctx *c, const ts_grid *g, float *vis)
{
    ts_error err;
    ts_backend_report rep = {0};
    if (NOTE(c, ts_backend_shm_compute(BK(c), g, c->run->sun_azimuth, c->run->sun_elevation,
                                       c->opts->penumbra_depth, c->opts->threads, vis, NULL,
                                       &rep, &err),
             rep) != TS_OK)
        return core_fail(c, &err);
    return TS_OK;
}

/* METHOD=shadowmap: the lit fraction by the shadow map into vis. */
static ts_status shadowmap_visibility(const tsd_compute_ctx *c, const ts_grid *g, float *vis)
{
    ts_error err;
    ts_backend_report rep = {0};
    ts_shadowmap_opts so;
    ts_shadowmap_opts_default(&so);
    so.scale = c->opts->shadowmap_scale;
    so.kernel = isnan(c->opts->pcf_kernel) ? TS_SHADOWMAP_AUTO : c->opts->pcf_kernel;
    so.light_radius = c->opts->light_radius;
    so.threads = c->opts->threads;
    so.progress = c->run->progress;
    so.progress_user = c->run->progress_user;
    /* the map's rows grow with the relief seen from a low sun, which the
     * estimate at open could not know: refused where the real map does
     * not fit what the limit leaves (session 57's audit: 1.10-1.14 times
     * MAX_MEMORY taken) */
    ts_shadowmap_frame f;
    if (c->run->limit_bytes > 0 &&
        ts_shadowmap_frame_make(g, c->run->sun_azimuth, c->run->sun_elevation, &so, &f,
                                &err) == TS_OK) {
        const double plane = (double)g->width * g->height * sizeof(float);
        const double real = 3 * plane + (double)ts_shadowmap_keys(&f) * sizeof(int);
        double map_x, map_y; /* (as counted at open) */
        tsd_shadowmap_aspect(g->cell_x, g->cell_x_row, g->height, g->cell_y, &map_x, &map_y);
        const double over =
            real - tsd_shadowmap_bytes(c->opts, g->width, g->height, map_x, map_y) -
            c->run->headroom_bytes;
        if (over > 0) {
            return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM,
                     "METHOD=shadowmap's depth map for a sun %.1f degrees high over this "
                     "terrain's relief is %d x %d texels: with its buffers about %.0f MiB, "
                     "%.0f MiB more than the memory limit of %.0f MiB leaves (MAX_MEMORY; by default "
                     "three quarters of the physical memory); give "
                     "MAX_MEMORY=%.0f or more, a smaller SHADOWMAP_SCALE (now %g), or "
                     "METHOD=exact",
                     c->run->sun_elevation, f.width, f.height, ceil(real / 1048576.0),
                     ceil(over / 1048576.0), c->run->limit_bytes / 1048576.0,
                     ceil((c->run->limit_bytes + over) / 1048576.0), so.scale);
        }
    }
    if (NOTE(c, ts_backend_shadowmap_compute(BK(c), g, c->run->sun_azimuth,
                                             c->run->sun_elevation, &so, vis, &rep, &err),
             rep) != TS_OK)
        return core_fail(c, &err);
    return TS_OK;
}

/* The visibility of a map method (METHOD=shm or shadowmap), times the
 * fraction of the sun's disk above the edge's horizon (EDGE=horizon or
 * nodata: neither map sees beyond the grid). */
static ts_status approx_visibility(const tsd_compute_ctx *c, const ts_grid *g, float *vis)
{
    ts_status st = c->opts->method == TSD_METHOD_SHADOWMAP ? shadowmap_visibility(c, g, vis)
                                                           : shm_visibility(c, g, vis);
    if (st != TS_OK)
        return st;
    /* neither sees beyond the DEM's edge: EDGE's part of the disk */
    ts_error err;
    ts_horizon_opts h;
    tsd_compute_horizon_opts(c, &h);
    if (ts_horizon_edge_sun(g, c->run->sun_azimuth, c->run->sun_elevation, &h, vis, &err) !=
        TS_OK)
        return core_fail(c, &err);
    return TS_OK;
}

/* Exact horizon at the sun's azimuth into plane; *h describes it. */
static ts_status sun_horizon(const tsd_compute_ctx *c, const ts_grid *g, ts_horizon_opts *h,
                             float *plane)
{
    ts_error err;
    ts_backend_report rep = {0};
    tsd_compute_horizon_opts(c, h);
    h->directions = 1;
    h->start_azimuth = c->run->sun_azimuth;
    h->progress = NULL; /* one sweep */
    /* read only through the sun's disk (the direct term, the shadow) */
    h->nonpositive_moot = ts_light_clears_horizontal(c->run->sun_elevation,
                                                     c->opts->light_radius);
    if (NOTE(c, ts_backend_horizon_sweep(BK(c), g, c->run->sun_azimuth, h, plane, &rep, &err),
             rep) != TS_OK ||
        ts_horizon_earth_floor(g, h, plane, &err) != TS_OK) /* EDGE=horizon */
        return core_fail(c, &err);
    return tsd_compute_far(c, g, c->run->sun_azimuth, 1, plane);
}

/* 1 if the sun is computed per cell (SUN_POSITION=per_cell: a lattice). */
static int sun_lattice(const tsd_compute_ctx *c)
{
    return tsd_sun_per_cell(c->run->sun);
}

/* Per-cell sun (SUN_POSITION=per_cell): visibility of the disk, and the
 * sun's grid azimuth and elevation per cell; the Earth's horizon only with
 * EDGE=horizon, as the exact method's sun_horizon. */
static ts_status sun_per_cell(const tsd_compute_ctx *c, const ts_grid *g, float *vis,
                              float *az, float *el)
{
    ts_error err;
    const tsd_sun *sun = c->run->sun;
    ts_day_opts d = tsd_compute_day_opts(c, sun);
    ts_sun_sites sites = tsd_compute_sun_sites(sun, g);
    d.horizon.progress = NULL; /* a few sweeps */
    d.earth_horizon = tsd_options_edge(c->opts) == TS_EDGE_HORIZON;
    if (ts_sun_visibility(g, &sites, &d, sun->instant, vis, az, el, NULL, &err) !=
        TS_OK)
        return core_fail(c, &err);
    /* (its sweeps are the core's own, not the dispatcher's: said here) */
    tsd_backend_note_c(c->backend, BK(c), TSD_PER_CELL_C_REASON);
    return TS_OK;
}

/* The direct sun of shade into out; work is a plane. */
static ts_status shade_direct(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                              float *work, float *out)
{
    size_t cells = (size_t)g->width * g->height;
    ts_status st;
    if (sun_lattice(c)) {
        float *az = malloc(cells * sizeof(float));
        float *el = malloc(cells * sizeof(float));
        st = !az || !el ? oom(c, "a horizon plane") : sun_per_cell(c, g, work, az, el);
        for (size_t i = 0; st == TS_OK && i < cells; i++) {
            double a = az[i] * M_PI / 180, e = el[i] * M_PI / 180;
            double d = nm->nx[i] * sin(a) * cos(e) + nm->ny[i] * cos(a) * cos(e) +
                       nm->nz[i] * sin(e);
            out[i] = (float)((d > 0 ? d : 0) * work[i]); /* NaN stays NaN */
        }
        free(az);
        free(el);
        return st;
    }
    if (c->opts->method == TSD_METHOD_SH)
        return tsd_sh_key_direct(c, g, nm, out);
    if (c->opts->method == TSD_METHOD_EXACT) {
        ts_horizon_opts h;
        ts_backend_report rep = {0};
        ts_error err;
        if ((st = sun_horizon(c, g, &h, work)) != TS_OK)
            return st;
        const ts_direct_request req = {g, nm->nx, nm->ny, nm->nz, work, &h,
                                       c->run->sun_azimuth, c->run->sun_elevation, out,
                                       c->opts->light_radius};
        /* without planes of normals (no sky term): made row by row */
        st = nm->nx ? ts_backend_shade_direct(BK(c), &req, &rep, &err)
                    : ts_backend_shade_direct_horn(BK(c), &req, &rep, &err);
        if (NOTE(c, st, rep) != TS_OK)
            return core_fail(c, &err);
        return TS_OK;
    }
    if ((st = approx_visibility(c, g, work)) != TS_OK)
        return st;
    double az0 = c->run->sun_azimuth * M_PI / 180, el0 = c->run->sun_elevation * M_PI / 180;
    double lx = sin(az0) * cos(el0), ly = cos(az0) * cos(el0), lz = sin(el0);
    for (size_t i = 0; i < cells; i++) {
        double d = nm->nx[i] * lx + nm->ny[i] * ly + nm->nz[i] * lz;
        out[i] = (float)((d > 0 ? d : 0) * work[i]); /* NaN stays NaN */
    }
    return TS_OK;
}

int tsd_shade_without_planes(const tsd_options *o, int sun_lattice)
{
    /* the exact method's direct sun alone makes its normals row by row,
     * and takes the sun's horizons in out (a fresh plane costs page faults);
     * METHOD=sh's alone makes them row by row too, and needs no work plane */
    return (o->method == TSD_METHOD_EXACT || o->method == TSD_METHOD_SH) && !sun_lattice &&
           !(o->sky_weight > 0);
}

TSD_COMPUTE_FN(tsd_compute_shade)
{
    (void)bytes;
    const ts_grid *g = r->dem;
    size_t cells = (size_t)g->width * g->height;
    tsd_normals nm = {0};
    ts_error err;
    ts_status st;
    int planes = !tsd_shade_without_planes(c->opts, sun_lattice(c));
    float *work = planes ? malloc(cells * sizeof(float)) : out;
    if (!work)
        st = oom(c, "a horizon plane");
    else if ((st = planes ? tsd_normals_make(c, g, &nm) : TS_OK) == TS_OK &&
             (st = shade_direct(c, g, &nm, work, out)) == TS_OK && c->opts->sky_weight > 0) {
        memset(work, 0, cells * sizeof(float));
        /* the uniform sky, or that of SKY / ENV_MAP (tsd_compute_env.c) */
        st = c->run->env ? tsd_env_sky_term(c, g, &nm, work) : sky_stream(c, g, &nm, 1, work);
        if (st == TS_OK &&
            ts_shade_combine(g, out, work, c->opts->sky_weight, out, &err) != TS_OK)
            st = core_fail(c, &err);
    }
    if (work != out)
        free(work);
    tsd_normals_free(&nm);
    return st;
}

TSD_COMPUTE_FN(tsd_compute_shadow)
{
    (void)bytes;
    const ts_grid *g = r->dem;
    size_t cells = (size_t)g->width * g->height;
    ts_status st;
    if (sun_lattice(c) && c->opts->method == TSD_METHOD_EXACT)
        return sun_per_cell(c, g, out, NULL, NULL);
    if (c->opts->method == TSD_METHOD_SH)
        return tsd_sh_key_shadow(c, g, out);
    if (c->opts->method != TSD_METHOD_EXACT)
        return approx_visibility(c, g, out);
    ts_horizon_opts h;
    if ((st = sun_horizon(c, g, &h, out)) != TS_OK)
        return st;
    for (size_t i = 0; i < cells; i++)
        if (out[i] == out[i])
            out[i] = (float)ts_disk_fraction_inl(c->run->sun_elevation, out[i],
                                                 c->opts->light_radius);
    return TS_OK;
}

TSD_COMPUTE_FN(tsd_compute_horizon)
{
    (void)bytes;
    ts_horizon_opts h;
    ts_error err;
    ts_backend_report rep = {0};
    if (c->opts->horizon_method == TSD_HORIZON_PYRAMID)
        return tsd_pyramid_planes(c, r->dem, out);
    tsd_compute_horizon_opts(c, &h);
    if (NOTE(c, ts_backend_horizon_compute(BK(c), r->dem, &h, out, &rep, &err), rep) != TS_OK)
        return core_fail(c, &err);
    size_t cells = (size_t)r->dem->width * r->dem->height;
    ts_status st = TS_OK;
    for (int k = 0; st == TS_OK && k < h.directions; k++)
        st = tsd_compute_far(c, r->dem, ts_horizon_azimuth(&h, k), 0, out + k * cells);
    return st;
}

/* A copy of `dem` with its heights negated (tsd_negate_heights), the
 * surface negative openness sweeps; free its z. */
static ts_status negated_dem(const tsd_compute_ctx *c, const ts_grid *dem, ts_grid *neg)
{
    *neg = *dem;
    neg->stride = dem->width;
    neg->owns_memory = 0;
    neg->z = malloc((size_t)dem->width * dem->height * sizeof(float));
    if (!neg->z)
        return oom(c, "the negated DEM of negative openness");
    tsd_negate_heights(dem, neg);
    return TS_OK;
}

static ts_status sky_product(const tsd_compute_ctx *c, const tsd_region *r, int which,
                             float *out)
{
    tsd_normals nm = {0};
    ts_grid neg = {0};
    ts_status st;
    const int negative = which == 2 && tsd_sweeps_negated_dem(c->opts);
    memset(out, 0, (size_t)r->width * r->height * sizeof(float));
    if ((st = tsd_normals_make(c, r->dem, &nm)) == TS_OK && negative)
        st = negated_dem(c, r->dem, &neg);
    if (st == TS_OK)
        st = sky_stream(c, negative ? &neg : r->dem, &nm, which, out);
    free(neg.z);
    tsd_normals_free(&nm);
    return st;
}

TSD_COMPUTE_FN(tsd_compute_svf)
{
    (void)bytes;
    return sky_product(c, r, 0, out);
}

TSD_COMPUTE_FN(tsd_compute_sky)
{
    (void)bytes;
    return sky_product(c, r, 1, out);
}

TSD_COMPUTE_FN(tsd_compute_openness)
{
    (void)bytes;
    return sky_product(c, r, 2, out);
}

ts_status tsd_product_compute(const tsd_compute_ctx *c, const tsd_region *r, float *out,
                              uint8_t *bytes)
{
    ts_error err;
    ts_horizon_opts h;
    if (c->backend)
        memset(c->backend, 0, sizeof *c->backend);
    if (ts_grid_validate(r->dem, &err) != TS_OK)
        return core_fail(c, &err);
    /* windows come later: today the region is the whole DEM */
    if (r->x0 != 0 || r->y0 != 0 || r->margin != 0 || r->width != r->dem->width ||
        r->height != r->dem->height)
        return tsd_fail(c->msg, c->msg_size, TS_ERR_ARG,
                        "a product is computed over the whole DEM, not over a %d x %d "
                        "window at (%d, %d) with a margin of %d cells",
                        r->width, r->height, r->x0, r->y0, r->margin);
    tsd_compute_horizon_opts(c, &h);
    if (ts_horizon_opts_validate(&h, &err) != TS_OK)
        return core_fail(c, &err);
    return tsd_product_of(c->opts)->compute(c, r, out, bytes);
}
