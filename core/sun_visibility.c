/*
 * The sun seen from every cell at an instant: the visible fraction of its
 * disk above each cell's horizon, with one sun or a lattice of suns (the
 * horizon planes of a lattice kept from one instant to the next). See
 * day_cycle.h; ts_sun_hours and ts_insolation (day_cycle.c) step it
 * through a day.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "day_cycle_internal.h"
#include "disk_fraction.h"
#include "simd_clones.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)
/* Largest azimuth gap between the sweeps of a lattice, degrees. */
#define LATTICE_AZ_STEP 1.0

/* ---------------------------------------------------- sun on the grid */

ts_status ts_day_sweep(const ts_grid *g, double azimuth, const ts_horizon_opts *h,
                       const ts_day_opts *o, double sun_elevation, float *plane,
                       ts_error *err)
{
    ts_status st = ts_horizon_sweep(g, azimuth, h, plane, err);
    if (st == TS_OK && o->plane_hook)
        st = o->plane_hook(o->plane_hook_user, g, azimuth, sun_elevation, plane, err);
    return st;
}


/* Slots of the lattice's kept planes: one a whole LATTICE_AZ_STEP. */
#define LATTICE_SLOTS ((int)(360.0 / LATTICE_AZ_STEP + 0.5))

void ts_vis_free(ts_vis_ctx *c)
{
    if (c->kept)
        for (int s = 0; s < LATTICE_SLOTS; s++)
            free(c->kept[s]);
    free(c->kept);
    free(c->floor);
    free(c->pa);
    free(c->pb);
    free(c->cel);
    free(c->caz);
    free(c->ns);
    free(c->noff);
    memset(c, 0, sizeof *c);
}

ts_status ts_vis_init(ts_vis_ctx *c, const ts_grid *g, const ts_sun_sites *s,
                          const ts_day_opts *o, int keep, ts_error *err)
{
    memset(c, 0, sizeof *c);
    ts_status st = ts_grid_validate(g, err);
    if (st != TS_OK)
        return st;
    if ((st = ts_sun_sites_validate(s, err)) != TS_OK)
        return st;
    if ((st = ts_day_opts_check(o, err)) != TS_OK)
        return st;
    c->g = g;
    c->s = s;
    c->o = o;
    c->W = g->width;
    c->H = g->height;
    c->cells = (size_t)g->width * g->height;
    c->nodes = s->nx * s->ny;
    int lattice = c->nodes > 1;
    c->pa = malloc(c->cells * sizeof(float));
    c->pb = lattice ? malloc(c->cells * sizeof(float)) : NULL;
    c->cel = lattice ? malloc(c->cells * sizeof(float)) : NULL;
    c->caz = lattice ? malloc(c->cells * sizeof(float)) : NULL;
    c->ns = malloc((size_t)c->nodes * sizeof *c->ns);
    c->noff = malloc((size_t)c->nodes * sizeof *c->noff);
    c->floor = o->earth_horizon ? malloc(c->cells * sizeof(float)) : NULL;
    c->kept = lattice ? calloc(LATTICE_SLOTS, sizeof *c->kept) : NULL;
    if (keep && lattice) {
        size_t planes = o->plane_cache_bytes / (c->cells * sizeof(float));
        c->room = planes < (size_t)LATTICE_SLOTS ? (int)planes : LATTICE_SLOTS;
    }
    if (!c->pa || !c->ns || !c->noff || (lattice && (!c->pb || !c->cel || !c->caz || !c->kept)) ||
        (o->earth_horizon && !c->floor)) {
        ts_vis_free(c);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the sun's work planes");
    }
    c->floor_min = c->floor ? ts_day_earth_floor(g, &o->horizon, c->floor) : -90.0;
    return TS_OK;
}

/* Bilinear weights of pixel coordinate p on a lattice axis. */
static void axis_weight(double p, double p0, double dp, int n, int *i, double *f)
{
    if (n < 2) {
        *i = 0;
        *f = 0;
        return;
    }
    double u = (p - p0) / dp;
    if (u <= 0) {
        *i = 0;
        *f = 0;
    } else if (u >= n - 1) {
        *i = n - 2;
        *f = 1;
    } else {
        *i = (int)u;
        if (*i > n - 2)
            *i = n - 2;
        *f = u - *i;
    }
}

static inline float cell_vis(double e, float h, float fl)
{
    if (isnan(h))
        return NAN;
    if (!isnan(fl) && fl > h)
        h = fl;
    return (float)ts_sun_disk_fraction_inl(e, h);
}

/* vis[i] = cell_vis(e, pa[i], floor[i]) for the cells i < n (floor NULL: no
 * floor; cel: each cell's own e): the whole disk's cases in a loop that
 * vectorises, by cell_vis' double arithmetic, then the cells of a partly
 * hidden disk (and nodata) by cell_vis itself (one division a cell, where
 * a loop calling out could not vectorise: ~15 % of a day's sunhours). */
TS_SIMD_CLONES
static void vis_cells(double e, const float *restrict cel, const float *restrict pa,
                      const float *restrict floor, size_t n, float *restrict vis)
{
    int partial = 0;
    for (size_t i = 0; i < n; i++) {
        const float h = pa[i], fl = floor ? floor[i] : NAN;
        const float hf = fl > h ? fl : h; /* a NaN h stays NaN */
        const double u = ts_disk_u(cel ? (double)cel[i] : e, hf, TS_SUN_RADIUS_DEG);
        const int whole = (u >= 1.0) | (u <= -1.0);
        vis[i] = whole ? (u >= 1.0 ? 1.0f : 0.0f) : NAN;
        partial |= !whole;
    }
    if (partial)
        for (size_t i = 0; i < n; i++)
            if (vis[i] != vis[i])
                vis[i] = cell_vis(cel ? cel[i] : e, pa[i], floor ? floor[i] : NAN);
}

/* Cell i's horizon the fraction f (clamped to 0..1) of the way from plane
 * pa to plane pb. */
static inline float plane_between(const float *pa, const float *pb, size_t i, double f)
{
    float ff = (float)f;
    if (ff < 0) ff = 0;
    if (ff > 1) ff = 1;
    return pa[i] + ff * (pb[i] - pa[i]);
}

/* The azimuths of a lattice's suns, as offsets lo..hi from a_ref, and
 * their highest elevation. */
static void lattice_span(const ts_sun_sample *ns, int nx, int ny, double a_ref, double *off,
                         double *lo, double *hi, double *emax)
{
    *lo = INFINITY;
    *hi = *emax = -INFINITY;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            /* from a_ref, but as its neighbour (left, or above for a row's
             * first) continues: wrapped each from a_ref alone, two nodes on
             * either side of a_ref + 180 were averaged the long way round,
             * and a band of cells took a sun from the opposite side */
            const int k = j * nx + i, p = i > 0 ? k - 1 : j > 0 ? k - nx : -1;
            double d = ts_wrap180(ns[k].grid_azimuth - a_ref);
            if (p >= 0)
                d += 360.0 * round((off[p] + ts_wrap180(ns[k].grid_azimuth -
                                                        ns[p].grid_azimuth) - d) / 360.0);
            off[k] = d;
            *lo = fmin(*lo, d);
            *hi = fmax(*hi, d);
            *emax = fmax(*emax, ns[k].elevation);
        }
}

/* The brackets b0..b1 of whole LATTICE_AZ_STEPs (bracket b: between the
 * planes at b and b + 1 steps of azimuth) that hold azimuths alo..ahi. */
static void lattice_brackets(double alo, double ahi, long *b0, long *b1)
{
    *b0 = (long)floor(alo / LATTICE_AZ_STEP);
    *b1 = (long)ceil(ahi / LATTICE_AZ_STEP) - 1;
    if (*b1 < *b0)
        *b1 = *b0;
}

/* A lattice's suns within this many degrees of azimuth (a DEM of a few
 * degrees of longitude) are swept at their span's ends and evenly between,
 * at most LATTICE_AZ_STEP apart: planes closer than whole degrees, which
 * the steps of a day could not share anyway. Wider spans are swept at the
 * whole degrees, which the steps share. */
#define LATTICE_NARROW 2.0

/* Sweeps across a lattice's azimuths lo..hi from a_ref. */
static int lattice_sweeps(double a_ref, double lo, double hi)
{
    long b0, b1;
    double span = hi - lo;
    if (span <= LATTICE_NARROW)
        return span < 1e-9 ? 1 : (int)ceil(span / LATTICE_AZ_STEP) + 1;
    lattice_brackets(a_ref + lo, a_ref + hi, &b0, &b1);
    return (int)(b1 - b0 + 2);
}

/* A narrow lattice (LATTICE_NARROW): K sweeps from a_ref + lo to a_ref + hi
 * through the two work planes, each cell interpolated between the two
 * around its azimuth. */
static ts_status vis_narrow(ts_vis_ctx *c, const ts_horizon_opts *ho, double a_ref,
                           double lo, double hi, float *vis, ts_error *err)
{
    const int K = lattice_sweeps(a_ref, lo, hi);
    double step = K > 1 ? (hi - lo) / (K - 1) : 0.0;
    ts_status st;
    if ((st = ts_day_sweep(c->g, a_ref + lo, ho, c->o, NAN, c->pa, err)) != TS_OK)
        return st;
    if (K == 1) {
        vis_cells(0.0, c->cel, c->pa, c->floor, c->cells, vis);
        return TS_OK;
    }
    for (int j = 1; j < K; j++) {
        if ((st = ts_day_sweep(c->g, a_ref + lo + j * step, ho, c->o, NAN, c->pb, err)) !=
            TS_OK)
            return st;
        for (size_t i = 0; i < c->cells; i++) {
            double u = (c->caz[i] - lo) / step;
            int b = (int)floor(u);
            if (b < 0) b = 0;
            if (b > K - 2) b = K - 2;
            if (b != j - 1)
                continue;
            float h = plane_between(c->pa, c->pb, i, u - b);
            vis[i] = cell_vis(c->cel[i], h, c->floor ? c->floor[i] : NAN);
        }
        float *t = c->pa;
        c->pa = c->pb;
        c->pb = t;
    }
    return TS_OK;
}

/* The span of a lattice's suns at unix_time (lattice_span), from a_ref,
 * its reference node's azimuth; ns and off: room for every node. */
static ts_status lattice_at(const ts_sun_sites *sites, const ts_day_opts *o, double unix_time,
                            ts_sun_sample *ns, double *off, double *a_ref, double *lo,
                            double *hi)
{
    ts_error err;
    double emax;
    ts_status st = ts_day_nodes_sun(sites, o, unix_time, ns, &err);
    if (st != TS_OK)
        return st;
    *a_ref = ns[ts_day_ref_node(sites)].grid_azimuth;
    lattice_span(ns, sites->nx, sites->ny, *a_ref, off, lo, hi, &emax);
    return TS_OK;
}

int ts_sun_visibility_sweeps(const ts_sun_sites *sites, const ts_day_opts *o,
                             double unix_time)
{
    int nodes = sites->nx * sites->ny;
    if (nodes == 1)
        return 1;
    ts_sun_sample *ns = malloc((size_t)nodes * sizeof *ns);
    double *off = malloc((size_t)nodes * sizeof *off);
    int K = -1;
    double a_ref, lo, hi;
    if (ns && off && lattice_at(sites, o, unix_time, ns, off, &a_ref, &lo, &hi) == TS_OK)
        K = lattice_sweeps(a_ref, lo, hi);
    free(ns);
    free(off);
    return K;
}

/* Slot of the plane at b whole LATTICE_AZ_STEPs of azimuth (b any integer). */
static int lattice_slot(long b)
{
    long s = b % LATTICE_SLOTS;
    return (int)(s < 0 ? s + LATTICE_SLOTS : s);
}

int ts_sun_visibility_planes(const ts_sun_sites *sites, const ts_day_opts *o,
                             const double *unix_times, int n)
{
    int nodes = sites->nx * sites->ny;
    if (nodes == 1)
        return n;
    ts_sun_sample *ns = malloc((size_t)nodes * sizeof *ns);
    double *off = malloc((size_t)nodes * sizeof *off);
    unsigned char *seen = calloc(LATTICE_SLOTS, 1);
    int planes = ns && off && seen ? 0 : -1;
    for (int k = 0; k < n && planes >= 0; k++) {
        double a_ref, lo, hi;
        long b0, b1;
        if (lattice_at(sites, o, unix_times[k], ns, off, &a_ref, &lo, &hi) != TS_OK) {
            planes = -1;
        } else if (hi - lo <= LATTICE_NARROW) { /* its own azimuths: not shared */
            planes += lattice_sweeps(a_ref, lo, hi);
        } else { /* whole steps of azimuth, each swept once a day */
            lattice_brackets(a_ref + lo, a_ref + hi, &b0, &b1);
            for (long b = b0; b <= b1 + 1; b++)
                if (!seen[lattice_slot(b)]) {
                    seen[lattice_slot(b)] = 1;
                    planes++;
                }
        }
    }
    free(seen);
    free(ns);
    free(off);
    return planes;
}

/* The plane at b steps of azimuth if kept, else NULL. */
static const float *kept_plane(const ts_vis_ctx *c, long b)
{
    return c->kept[lattice_slot(b)];
}

/* The plane at b steps of azimuth: kept from an earlier step, or swept now
 * and kept while there is room, else swept into a work plane (pa or pb by
 * the slot's parity, so that two neighbours never share one). */
static ts_status lattice_plane(ts_vis_ctx *c, const ts_horizon_opts *ho, long b,
                               const float **out, ts_error *err)
{
    int s = lattice_slot(b);
    if (c->kept[s]) {
        *out = c->kept[s];
        return TS_OK;
    }
    float *p = c->room > 0 ? malloc(c->cells * sizeof(float)) : NULL;
    int keep = p != NULL;
    if (!keep)
        p = s & 1 ? c->pb : c->pa;
    ts_status st = ts_day_sweep(c->g, s * LATTICE_AZ_STEP, ho, c->o, NAN, p, err);
    if (st != TS_OK) {
        if (keep)
            free(p);
        return st;
    }
    if (keep) {
        c->kept[s] = p;
        c->room--;
    }
    *out = p;
    return TS_OK;
}

ts_status ts_vis_step(ts_vis_ctx *c, double t, float *vis, float *az, float *el,
                          ts_sun_sample *ref, int *dark, ts_error *err)
{
    const ts_grid *g = c->g;
    const ts_sun_sites *s = c->s;
    ts_status st;
    if ((st = ts_day_nodes_sun(s, c->o, t, c->ns, err)) != TS_OK)
        return st;
    const ts_sun_sample *r = &c->ns[ts_day_ref_node(s)];
    if (ref)
        *ref = *r;
    const double rad = TS_SUN_RADIUS_DEG;
    const int W = c->W, H = c->H;
    ts_horizon_opts ho = c->o->horizon;
    ho.directions = 1;
    *dark = 0;

    if (c->nodes == 1) {
        double e = r->elevation, a = r->grid_azimuth;
        if (az || el)
            for (size_t i = 0; i < c->cells; i++) {
                if (az) az[i] = (float)a;
                if (el) el[i] = (float)e;
            }
        if (e + rad <= c->floor_min) {
            *dark = 1;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++)
                    vis[(size_t)y * W + x] = isnan(ts_grid_at(g, x, y)) ? NAN : 0.0f;
            return TS_OK;
        }
        if ((st = ts_day_sweep(g, a, &ho, c->o, e, c->pa, err)) != TS_OK)
            return st;
        vis_cells(e, NULL, c->pa, c->floor, c->cells, vis);
        return TS_OK;
    }

    /* Lattice: azimuths as offsets from the reference node's. */
    double a_ref = r->grid_azimuth, lo, hi, emax, clo = INFINITY, chi = -INFINITY;
    lattice_span(c->ns, s->nx, s->ny, a_ref, c->noff, &lo, &hi, &emax);
    for (int y = 0; y < H; y++) {
        int j;
        double fy;
        axis_weight(y + 0.5, s->y0, s->dy, s->ny, &j, &fy);
        for (int x = 0; x < W; x++) {
            int i;
            double fx;
            axis_weight(x + 0.5, s->x0, s->dx, s->nx, &i, &fx);
            int i1 = s->nx > 1 ? i + 1 : i, j1 = s->ny > 1 ? j + 1 : j;
            const ts_sun_sample *n00 = &c->ns[j * s->nx + i], *n10 = &c->ns[j * s->nx + i1],
                                *n01 = &c->ns[j1 * s->nx + i], *n11 = &c->ns[j1 * s->nx + i1];
            double w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy,
                   w11 = fx * fy;
            /* the nodes' sun vectors, not their angles, interpolated: the
             * vector is smooth everywhere, while around the subsolar point
             * the elevation is a cone and the azimuth turns a whole circle
             * (angles interpolated there put the sun up to 3 deg off, and
             * on the far side of the zenith). The azimuths as offsets from
             * a_ref, each as its quad's first continues (the lattice's
             * unwrapping leaves a seam around the subsolar point). */
            const ts_sun_sample *nq[4] = {n00, n10, n01, n11};
            const double wq[4] = {w00, w10, w01, w11};
            const double o00 = c->noff[j * s->nx + i];
            const double oq[4] = {o00, c->noff[j * s->nx + i1], c->noff[j1 * s->nx + i],
                                  c->noff[j1 * s->nx + i1]};
            double ve = 0, vn = 0, vu = 0;
            for (int q = 0; q < 4; q++) {
                const double e0q = nq[q]->true_elevation * DEG2RAD, aq = oq[q] * DEG2RAD;
                ve += wq[q] * cos(e0q) * sin(aq);
                vn += wq[q] * cos(e0q) * cos(aq);
                vu += wq[q] * sin(e0q);
            }
            /* refracted after: the refraction jumps at its cut-off, which
             * a lattice of sunrise and sunset straddles */
            double e0 = atan2(vu, hypot(ve, vn)) / DEG2RAD;
            double e = e0 + ts_sun_refraction(e0, &c->o->sun);
            double d = o00 + ts_wrap180(atan2(ve, vn) / DEG2RAD - o00);
            emax = fmax(emax, e);
            clo = fmin(clo, d);
            chi = fmax(chi, d);
            size_t k = (size_t)y * W + x;
            c->cel[k] = (float)e;
            c->caz[k] = (float)d;
            if (el) el[k] = (float)e;
            if (az) az[k] = (float)ts_wrap360(a_ref + d);
        }
    }
    lo = fmin(lo, clo); /* (the cells' own span: wider only across a seam) */
    hi = fmax(hi, chi);
    if (emax + rad <= c->floor_min) {
        *dark = 1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                vis[(size_t)y * W + x] = isnan(ts_grid_at(g, x, y)) ? NAN : 0.0f;
        return TS_OK;
    }
    if (hi - lo <= LATTICE_NARROW)
        return vis_narrow(c, &ho, a_ref, lo, hi, vis, err);
    long b0, b1;
    lattice_brackets(a_ref + lo, a_ref + hi, &b0, &b1);
    /* Every plane kept (or keepable): one pass over the cells. Else bracket
     * by bracket through the two work planes, the planes beyond the room
     * swept again at each step. */
    int all_kept = 1;
    for (long b = b0; b <= b1 + 1; b++) {
        const float *p;
        if (!kept_plane(c, b) && c->room == 0) {
            all_kept = 0;
            break;
        }
        if ((st = lattice_plane(c, &ho, b, &p, err)) != TS_OK)
            return st;
        if (!kept_plane(c, b)) { /* no memory to keep it */
            all_kept = 0;
            break;
        }
    }
    const float *pa = NULL, *pb;
    if (!all_kept && (st = lattice_plane(c, &ho, b0, &pa, err)) != TS_OK)
        return st;
    for (long j = all_kept ? b1 : b0; j <= b1; j++) {
        if (!all_kept && (st = lattice_plane(c, &ho, j + 1, &pb, err)) != TS_OK)
            return st;
        for (size_t i = 0; i < c->cells; i++) {
            double u = (a_ref + c->caz[i]) / LATTICE_AZ_STEP;
            long b = (long)floor(u);
            if (b < b0) b = b0;
            if (b > b1) b = b1;
            if (!all_kept && b != j)
                continue;
            float h = all_kept ? plane_between(kept_plane(c, b), kept_plane(c, b + 1), i, u - b)
                               : plane_between(pa, pb, i, u - b);
            vis[i] = cell_vis(c->cel[i], h, c->floor ? c->floor[i] : NAN);
        }
        pa = pb;
    }
    return TS_OK;
}

ts_status ts_sun_visibility(const ts_grid *grid, const ts_sun_sites *sites,
                            const ts_day_opts *o, double unix_time, float *vis,
                            float *az, float *el, ts_sun_sample *ref, ts_error *err)
{
    if (!vis)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_visibility: the output is NULL");
    if (!isfinite(unix_time))
        return ts_fail(err, TS_ERR_ARG, "the instant must be finite");
    ts_vis_ctx c;
    ts_status st = ts_vis_init(&c, grid, sites, o, 0, err);
    if (st != TS_OK)
        return st;
    int dark;
    st = ts_vis_step(&c, unix_time, vis, az, el, ref, &dark, err);
    ts_vis_free(&c);
    return st == TS_OK ? ts_ok(err) : st;
}

/* Uniform steps of a day, allocated. */

ts_status ts_sun_visibility_steps(const ts_grid *grid, const ts_sun_sites *sites,
                                  const ts_day_opts *o, const double *unix_times, int n,
                                  float *vis, ts_error *err)
{
    if (!vis || !unix_times || n < 1)
        return ts_fail(err, TS_ERR_ARG, "ts_sun_visibility_steps: no instants or no output");
    for (int k = 0; k < n; k++)
        if (!isfinite(unix_times[k]))
            return ts_fail(err, TS_ERR_ARG, "instant %d is not finite", k);
    ts_vis_ctx c;
    ts_status st = ts_vis_init(&c, grid, sites, o, n > 1, err);
    if (st != TS_OK)
        return st;
    for (int k = 0; k < n && st == TS_OK; k++) {
        int dark;
        if ((st = ts_progress(&o->horizon, (double)k / n, err)) == TS_OK)
            st = ts_vis_step(&c, unix_times[k], vis + (size_t)k * c.cells, NULL, NULL, NULL,
                             &dark, err);
    }
    if (st == TS_OK)
        st = ts_progress(&o->horizon, 1.0, err);
    ts_vis_free(&c);
    return st == TS_OK ? ts_ok(err) : st;
}
