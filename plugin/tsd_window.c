/* Windowed computation, C side: the plan of a dataset's chunks and the far
 * field every chunk shares (tsd_window.h, docs/windows.md). */
#include "tsd_window.h"

#include "shadow_atlas.h"
#include "tsd_products.h"
#include "tsd_text.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The two observers of a far plane stand this far below and above the
 * coarse cell's height: the far field between them is close to linear in
 * the height (the slope to one dominant occluder). */
#define TSD_FAR_DZ 25.0

/* 1 if d is product a or b */
static int is(const tsd_product_def *d, const char *a, const char *b)
{
    return strcmp(d->name, a) == 0 || (b && strcmp(d->name, b) == 0);
}

/* (double: a distance of 1e8 m on 1 cm cells, or near a pole's cells of
 * micrometres, is more cells than an int holds) */
static double ceil_cells(double metres, double cell)
{
    return ceil(metres / cell - 1e-9);
}

/* Bytes the far field keeps per cell of its grid: the heights, two float
 * planes per azimuth, and two more while one is swept; where the grid is
 * the DEM itself one 16-bit plane per azimuth, and one float plane while
 * it is swept (tsd_window_peak_bytes). */
static double far_bytes_per_cell(int planes, int own)
{
    if (own)
        return sizeof(float) * 2 + sizeof(uint16_t) * (double)planes;
    return sizeof(float) * (1 + 2.0 * planes + 2);
}

static double far_budget(const tsd_options *o)
{
    double budget = TSD_FAR_BUDGET_MB * 1048576.0;
    if (o->max_memory_mb > 0 && o->max_memory_mb * 1048576.0 / 4 < budget)
        budget = o->max_memory_mb * 1048576.0 / 4;
    return budget;
}

/* The far grid's cell in DEM cells: 1 (the DEM itself) where it fits
 * TSD_FAR_OWN_MAX_CELLS, a grid's sides and the budget, else as fine as they allow;
 * never coarser than near_cells / TSD_FAR_CELLS_PER_NEAR for the budget's
 * sake (the rule before the budget), nor finer than f_mem. */
static int far_factor(const tsd_options *o, int W, int H, int f_mem, double near_cells,
                      int planes)
{
    double budget = far_budget(o);
    if (W <= TS_MAX_SIDE && H <= TS_MAX_SIDE && (double)W * H <= TSD_FAR_OWN_MAX_CELLS &&
        (double)W * H * far_bytes_per_cell(planes, 1) <= budget)
        return 1;
    int f_budget = (int)ceil(sqrt((double)W * H * far_bytes_per_cell(planes, 0) / budget));
    /* in double first: a near field of ~7e10 cells and more (NEAR_DISTANCE
     * on fine cells at a pole) overflowed int, and the budget was lost */
    double q_near = floor(near_cells / TSD_FAR_CELLS_PER_NEAR);
    int f_near = q_near < INT_MAX ? (int)q_near : INT_MAX;
    int f = f_budget < f_near ? f_budget : f_near;
    f = f > f_mem ? f : f_mem;
    return f < 1 ? 1 : f;
}

/* SUN_POSITION=per_cell's lattice thinned to at most THIN x THIN nodes,
 * its corners and edges among them, for counting its sweeps: its thousands
 * of nodes, for every step of a day, would hold up the dataset's opening,
 * and its four corners alone miss a world DEM's spread of azimuths (its
 * east and west edges meet, so their suns agree). */
#define THIN 9
typedef struct {
    double lon[THIN * THIN], lat[THIN * THIN], north[THIN * THIN];
    ts_sun_sites sites;
} thin_lattice;

static void thin_lattice_of(const ts_sun_sites *s, thin_lattice *t)
{
    const int mx = s->nx < THIN ? s->nx : THIN, my = s->ny < THIN ? s->ny : THIN;
    for (int b = 0; b < my; b++)
        for (int a = 0; a < mx; a++) {
            int i = mx > 1 ? (int)lround((double)a * (s->nx - 1) / (mx - 1)) : 0;
            int j = my > 1 ? (int)lround((double)b * (s->ny - 1) / (my - 1)) : 0;
            t->lon[b * mx + a] = s->longitude[j * s->nx + i];
            t->lat[b * mx + a] = s->latitude[j * s->nx + i];
            t->north[b * mx + a] = s->north_azimuth ? s->north_azimuth[j * s->nx + i] : 0.0;
        }
    ts_sun_sites thin = {mx, my, s->x0, s->y0,
                         mx > 1 ? s->dx * (s->nx - 1) / (mx - 1) : s->dx,
                         my > 1 ? s->dy * (s->ny - 1) / (my - 1) : s->dy,
                         t->lon, t->lat, t->north};
    t->sites = thin;
}

/* The far planes of a sun at `t`: one sweep, or a lattice's several
 * (SUN_POSITION=per_cell, counted on the thinned lattice); when in doubt,
 * 4. */
static int sun_sweeps(const tsd_sun *sun, double t)
{
    if (!tsd_sun_per_cell(sun))
        return 1;
    thin_lattice thin;
    thin_lattice_of(&sun->sites, &thin);
    int k = ts_sun_visibility_sweeps(&thin.sites, &sun->day, t);
    return k > 0 ? k : 4;
}

/* The far planes of a day product's sun: those of the time steps with the
 * sun up at the centre (its upper limb above the lowest Earth horizon any
 * land can see, TSD_DAY_SUN_UP_DEG), each plane once (a wide lattice's
 * whole degrees serve every step: ts_sun_visibility_planes), or a date
 * range's horizon azimuths. */
static int day_sweeps(const tsd_options *o, const tsd_sun *sun)
{
    if (!sun)
        return 0;
    if (sun->is_range)
        return sun->range.horizon_directions;
    const double step = tsd_options_step_minutes(o) * 60.0;
    const int n = ts_day_step_count(sun->day_length, step);
    double *mid = malloc((size_t)n * sizeof *mid), *dur = malloc((size_t)n * sizeof *dur);
    ts_error err;
    int planes = 4 * n; /* when in doubt, every step */
    if (mid && dur && ts_day_uniform_times(sun->day_start, sun->day_length, step, mid, dur,
                                           &err) == TS_OK) {
        int up = 0;
        for (int k = 0; k < n; k++) {
            ts_sun_sample at;
            if (ts_sun_at_site(&sun->sites, &sun->day, mid[k], &at, &err) != TS_OK ||
                at.elevation + TS_SUN_RADIUS_DEG > TSD_DAY_SUN_UP_DEG)
                mid[up++] = mid[k];
        }
        if (!tsd_sun_per_cell(sun)) {
            planes = up;
        } else {
            thin_lattice thin;
            thin_lattice_of(&sun->sites, &thin);
            int p = ts_sun_visibility_planes(&thin.sites, &sun->day, mid, up);
            if (p >= 0)
                planes = p;
        }
    }
    free(mid);
    free(dur);
    return planes;
}

/* Why the product or method of o needs the whole DEM (NULL: it does
 * not). */
static const char *whole_by_method(const tsd_options *o, const tsd_product_def *d)
{
    if (is(d, "farshadow", NULL))
        return "PRODUCT=farshadow's far shadows are the whole DEM's far field";
    if (o->method == TSD_METHOD_SHM && is(d, "shade", "shadow"))
        return "METHOD=shm carries shadows across the whole DEM";
    if (o->method == TSD_METHOD_SHADOWMAP && is(d, "shade", "shadow"))
        return "METHOD=shadowmap renders one depth map of the whole DEM";
    if (o->horizon_method == TSD_HORIZON_PYRAMID)
        return "HORIZON_METHOD=pyramid reads one pyramid of the whole DEM";
    return NULL;
}

int tsd_window_plan_make(const tsd_options *o, const tsd_sun *sun, int W, int H,
                         double cells_min_x, double cell_y, tsd_window_plan *p, char *msg,
                         size_t n)
{
    const tsd_product_def *d = tsd_product_of(o);
    memset(p, 0, sizeof *p);
    p->tile = o->tile_size;
    if (o->tile_size == 0)
        p->why_whole = "TILE_SIZE=0";
    else if (W <= o->tile_size && H <= o->tile_size)
        p->why_whole = "the DEM fits in one tile";
    const int fits = p->why_whole != NULL && o->tile_size != 0;
    if (!p->why_whole)
        p->why_whole = whole_by_method(o, d);
    /* a DEM within one tile still has its NEAR_DISTANCE checked, so that
     * whether it is refused does not depend on the DEM's size (a script
     * that ran on a small DEM failed on a larger one) */
    if (p->why_whole && !(fits && o->near_distance > 0 && !whole_by_method(o, d)))
        return 0;
    double cell = cells_min_x < cell_y ? cells_min_x : cell_y;
    /* the far grid's coarsening that keeps it within TSD_FAR_MAX_CELLS,
     * and each of its sides within a grid's (a DEM of 3 x 2^31 - 1 cells
     * opened, then failed at its first read: an audit) */
    int f_mem = (int)ceil(sqrt((double)W * H / TSD_FAR_MAX_CELLS));
    int f_side = (int)(((long long)(W > H ? W : H) + TS_MAX_SIDE - 1) / TS_MAX_SIDE);
    f_mem = f_mem > f_side ? f_mem : f_side;
    double near = o->near_distance;
    if (near == 0) {
        int cells = TSD_NEAR_AUTO_CELLS > TSD_FAR_CELLS_PER_NEAR * f_mem
                        ? TSD_NEAR_AUTO_CELLS
                        : TSD_FAR_CELLS_PER_NEAR * f_mem;
        /* in cells' longer sides: 128 cells every way (at 80 degrees N a
         * degree DEM's east-west cells are a sixth of its north-south
         * ones, and 128 of them were 22 rows, up to 5 degrees off) */
        near = cells * (cells_min_x > cell_y ? cells_min_x : cell_y);
    }
    /* MAX_DISTANCE: the near field is all there is, exact to it */
    p->far = o->max_distance == 0;
    p->near_m = p->far ? near : o->max_distance;
    const int need = TSD_NEAR_MIN_CELLS;
    if (p->far && near < need * cell) {
        /* cells rounded down and metres up, so that the message never says 16.0
         * of 16 nor names a distance that is refused again */
        tsd_fail(msg, n, TS_ERR_ARG,
                 "NEAR_DISTANCE=%g m is %.2f cells of this DEM; the near field needs at "
                 "least %d cells (%.0f m): give a larger NEAR_DISTANCE, or 0 for %d cells",
                 near, floor(near / cell * 100) / 100, need, ceil(need * cell),
                 TSD_NEAR_AUTO_CELLS > TSD_FAR_CELLS_PER_NEAR * f_mem
                     ? TSD_NEAR_AUTO_CELLS
                     : TSD_FAR_CELLS_PER_NEAR * f_mem);
        return -1;
    }
    if (p->why_whole) /* (the check above alone) */
        return 0;
    /* the sweep samples a cell's neighbours too: two cells more */
    double mx = ceil_cells(p->near_m, cells_min_x) + 2.0, my = ceil_cells(p->near_m, cell_y) + 2.0;
    p->margin_x = mx < W ? (int)mx : W;
    p->margin_y = my < H ? (int)my : H;
    p->dem_w = W;
    p->dem_h = H;
    p->windowed = 1;
    /* a cache that holds the chunks a row of blocks spans (GDAL reads
     * blocks row by row, and a copy under a small block cache reads each
     * band's row in turn: a row of 128-cell chunks under 256-cell blocks
     * kept by halves was computed again for every band, 3430 computations
     * of 25 chunks), and at least 4, so that a read that straddles a chunk
     * corner keeps its four */
    const int B = TSD_BLOCK_SIDE, T = p->tile;
    const long long rows = B % T == 0 ? B / T : T % B == 0 ? 1 : B / T + 2;
    const long long row = ((long long)W + T - 1) / T;
    p->cache_chunks = (int)(row * rows + 1 < 4 ? 4 : row * rows + 1);
    if (p->far) {
        /* the sweeps of a chunk: the sun's (METHOD=sh: its swath's; a
         * day's: one per step at most, a date range's HORIZON_DIRECTIONS),
         * DIRECTIONS, or both */
        const int sun_planes = d->daily ? day_sweeps(o, sun)
                        : !is(d, "shade", "shadow")  ? 0
                        : o->method == TSD_METHOD_SH ? o->swath_directions
                        : tsd_sun_per_cell(sun)      ? sun_sweeps(sun, sun->instant)
                                                     : 1;
        p->far_planes = is(d, "shadow", NULL) || is(d, "sunhours", "daycycle") ||
                                (is(d, "shade", NULL) && o->sky_weight == 0) ||
                                /* a range's insolation: the sky term's azimuths
                                 * among the range's (core/sun_range.c) */
                                (sun && sun->is_range && sun_planes % o->directions == 0)
                            ? sun_planes
                            : o->directions + sun_planes;
        int f = far_factor(o, W, H, f_mem, near / cell, p->far_planes);
        p->far_w = (int)(((long long)W + f - 1) / f);
        p->far_h = (int)(((long long)H + f - 1) / f);
        p->far_own = f == 1;
    }
    return 0;
}

/* The largest of a few chunk sizes with which options o window a W x H
 * DEM within `limit` bytes, `extra` held beside the windows, with o's
 * near field or else the least of a few wider ones: 1 with *tile, *near
 * (metres; 0: o's own) and *bytes (the windows' peak and extra), else 0. */
static int tile_that_fits(const tsd_options *o, const tsd_sun *sun, int W, int H,
                          double cells_min_x, double cell_y, double limit, double extra,
                          int *tile, double *near, double *bytes)
{
    static const int tiles[] = {4096, 2048, 1024, 512, 256}; /* all >= TSD_TILE_MIN */
    /* then, with the automatic near field, wider ones: a coarser far grid
     * keeps less (a day's far planes on a 16384^2 DEM: 6768 MiB at 256 m,
     * 421 MiB at 2048 m; session 58's large-DEM audit) */
    static const double wider[] = {1, 2, 4, 8, 16};
    double auto_near = 0;
    for (size_t k = 0; k < sizeof wider / sizeof wider[0]; k++) {
        if (k > 0 && !(o->near_distance == 0 && auto_near > 0))
            break;
        for (size_t i = 0; i < sizeof tiles / sizeof tiles[0]; i++) {
            tsd_options t = *o;
            t.tile_size = tiles[i];
            /* (whole metres, as the advice says it: the plan of the value
             * unrounded was up to 1 MiB smaller, the review) */
            t.near_distance = k > 0 ? ceil(auto_near * wider[k]) : o->near_distance;
            if (t.near_distance > TSD_NEAR_MAX_M)
                break;
            tsd_window_plan p;
            char msg[256];
            if ((W <= tiles[i] && H <= tiles[i]) ||
                tsd_window_plan_make(&t, sun, W, H, cells_min_x, cell_y, &p, msg, sizeof msg) !=
                    0 ||
                !p.windowed)
                continue;
            if (k == 0 && auto_near == 0)
                auto_near = p.far ? p.near_m : 0; /* (the first plan's) */
            double steady;
            const double peak = tsd_window_peak_bytes(&t, &p, &steady) + extra;
            if (peak <= limit) {
                *tile = tiles[i];
                *near = k > 0 ? t.near_distance : 0;
                *bytes = peak;
                return 1;
            }
        }
    }
    return 0;
}

/* "TILE_SIZE=512" or "TILE_SIZE=512 and NEAR_DISTANCE=2048" */
static const char *tile_words(int tile, double near, char *buf, size_t n)
{
    if (near > 0)
        snprintf(buf, n, "TILE_SIZE=%d and NEAR_DISTANCE=%.0f", tile, near);
    else
        snprintf(buf, n, "TILE_SIZE=%d", tile);
    return buf;
}

void tsd_window_advice(const tsd_options *o, const tsd_sun *sun, int W, int H,
                       double cells_min_x, double cell_y, double limit, double extra,
                       char *out, size_t n)
{
    int tile;
    double bytes, near;
    char words[96];
    const tsd_product_def *d = tsd_product_of(o);
    const char *why = whole_by_method(o, d);
    out[0] = '\0';
    if (!why) {
        if (tile_that_fits(o, sun, W, H, cells_min_x, cell_y, limit, extra, &tile, &near,
                           &bytes))
            snprintf(out, n, "; %s computes it window by window in about %.0f MiB",
                     tile_words(tile, near, words, sizeof words),
                     ceil(bytes / 1048576.0)); /* (up: a MAX_MEMORY that does) */
        return;
    }
    /* the exact methods, windowed (farshadow has none) */
    tsd_options e = *o;
    e.method = o->method == TSD_METHOD_SHM || o->method == TSD_METHOD_SHADOWMAP
                   ? TSD_METHOD_EXACT
                   : o->method;
    e.horizon_method = TSD_HORIZON_EXACT;
    const char *instead = e.method != o->method && o->horizon_method == TSD_HORIZON_PYRAMID
                              ? "METHOD=exact and HORIZON_METHOD=exact"
                          : e.method != o->method ? "METHOD=exact"
                                                  : "HORIZON_METHOD=exact";
    if (!whole_by_method(&e, d) &&
        tile_that_fits(&e, sun, W, H, cells_min_x, cell_y, limit, extra, &tile, &near, &bytes))
        snprintf(out, n,
                 "; it is computed on the whole DEM (%s): %s with %s computes it "
                 "window by window in about %.0f MiB",
                 why, instead, tile_words(tile, near, words, sizeof words),
                 ceil(bytes / 1048576.0));
    else
        snprintf(out, n, "; it is computed on the whole DEM (%s)", why);
}

/* The cells of a chunk's side (at most the tile, at most the DEM's side)
 * and of the window it is computed on (its margins, within the DEM). */
static int chunk_side(int tile, int dem)
{
    return tile < dem ? tile : dem;
}

static int window_side(int tile, int margin, int dem)
{
    const long long w = (long long)chunk_side(tile, dem) + 2LL * margin;
    return w < dem ? (int)w : dem;
}

double tsd_window_peak_bytes(const tsd_options *o, const tsd_window_plan *p, double *steady)
{
    const int W = window_side(p->tile, p->margin_x, p->dem_w);
    const int H = window_side(p->tile, p->margin_y, p->dem_h);
    double kept_one = 0;
    /* (square cells: METHOD=shadowmap, the one method that counts them, is
     * computed whole) */
    double computing = tsd_product_peak_bytes(o, W, H, 1, 1, &kept_one);
    /* the chunk cropped out of it, and the cache */
    double chunk = (double)chunk_side(p->tile, p->dem_w) * chunk_side(p->tile, p->dem_h) *
                   sizeof(float) * tsd_options_band_count(o);
    double far = (double)p->far_w * p->far_h * far_bytes_per_cell(p->far_planes, p->far_own);
    double kept = chunk * p->cache_chunks + far;
    if (steady)
        *steady = kept;
    return computing + chunk + kept;
}

void tsd_far_field_init(tsd_far_field *f, ts_grid *coarse, int fine_w, int fine_h,
                        double threshold, const tsd_options *o)
{
    memset(f, 0, sizeof *f);
    f->coarse = *coarse;
    memset(coarse, 0, sizeof *coarse);
    f->fine_w = fine_w;
    f->fine_h = fine_h;
    f->own = f->coarse.width == fine_w && f->coarse.height == fine_h;
    f->threshold = threshold;
    ts_horizon_opts_default(&f->hopts);
    f->hopts.directions = 1;
    f->hopts.curvature = o->curvature;
    f->hopts.refraction = o->refraction;
    f->hopts.threads = o->threads;
    if (tsd_sweeps_negated_dem(o)) {
        /* its far grid is the negated coarse grid's, swept flat */
        f->hopts.curvature = 0;
        tsd_negate_heights(&f->coarse, &f->coarse);
    }
    f->zmax = -INFINITY;
    for (int y = 0; y < f->coarse.height; y++)
        for (int x = 0; x < f->coarse.width; x++) {
            float z = ts_grid_at(&f->coarse, x, y);
            f->zmax = z > f->zmax ? z : f->zmax; /* NaN is never larger */
        }
}

void tsd_far_field_free(tsd_far_field *f)
{
    for (int i = 0; i < f->n; i++) {
        free(f->planes[i].base);
        free(f->planes[i].per_m);
        free(f->planes[i].angle);
    }
    free(f->planes);
    ts_grid_free(&f->coarse);
    memset(f, 0, sizeof *f);
}

/* The far plane of a grid that is the DEM itself: each cell's far horizon
 * from its own height, in degrees, rounded to 1/TSD_FAR_STEPS_PER_DEGREE
 * (0.0014 degrees at most) to keep a plane per azimuth in 16 bits. */
static const struct tsd_far_plane *own_plane(tsd_far_field *f, double azimuth,
                                             const tsd_compute_ctx *c)
{
    size_t cells = (size_t)f->coarse.width * f->coarse.height;
    float *deg = malloc(cells * sizeof *deg);
    uint16_t *q = malloc(cells * sizeof *q);
    ts_error err;
    ts_status st = !deg || !q ? TS_ERR_NOMEM : TS_OK;
    if (st != TS_OK)
        tsd_fail(c->msg, c->msg_size, st, "out of memory for the far field");
    else if ((st = ts_far_horizon(&f->coarse, azimuth, f->threshold, &f->hopts, deg, &err)) !=
             TS_OK)
        tsd_fail_core(c->msg, c->msg_size, "the far field", &err);
    if (st != TS_OK) {
        free(deg);
        free(q);
        return NULL;
    }
    for (size_t i = 0; i < cells; i++) /* NaN, or -90: no far terrain */
        q[i] = !(deg[i] > -90.0f)
                   ? 0
                   : (uint16_t)(1 + lrint((deg[i] + 90.0) * TSD_FAR_STEPS_PER_DEGREE));
    free(deg);
    f->planes[f->n] = (struct tsd_far_plane){azimuth, NULL, NULL, q};
    return &f->planes[f->n++];
}

/* The far plane of `azimuth`, swept on first use; NULL with msg. */
static const struct tsd_far_plane *far_plane(tsd_far_field *f, double azimuth,
                                            const tsd_compute_ctx *c)
{
    for (int i = 0; i < f->n; i++)
        if (f->planes[i].azimuth == azimuth)
            return &f->planes[i];
    if (f->n == f->cap) {
        int cap = f->cap ? 2 * f->cap : 16;
        struct tsd_far_plane *p = realloc(f->planes, (size_t)cap * sizeof *p);
        if (!p)
            return tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM, "out of memory for the far "
                            "field"), NULL;
        f->planes = p;
        f->cap = cap;
    }
    if (f->own)
        return own_plane(f, azimuth, c);
    size_t cells = (size_t)f->coarse.width * f->coarse.height;
    float *lo = malloc(cells * sizeof *lo), *hi = malloc(cells * sizeof *hi);
    ts_error err;
    ts_status st = !lo || !hi ? TS_ERR_NOMEM : TS_OK;
    if (st != TS_OK)
        tsd_fail(c->msg, c->msg_size, st, "out of memory for the far field");
    else if ((st = ts_far_slope_raised(&f->coarse, azimuth, f->threshold, -TSD_FAR_DZ,
                                       &f->hopts, lo, &err)) != TS_OK ||
             (st = ts_far_slope_raised(&f->coarse, azimuth, f->threshold, TSD_FAR_DZ,
                                       &f->hopts, hi, &err)) != TS_OK)
        tsd_fail_core(c->msg, c->msg_size, "the far field", &err);
    if (st != TS_OK) {
        free(lo);
        free(hi);
        return NULL;
    }
    /* The far-only sweep does not sample a cell's ray at an occluder it
     * cannot reach (off the grid, or nodata: core/lane_passes.c far_lost),
     * so one observer may find no far terrain (-inf) where the other finds
     * some: a line through -inf would put the horizon at +-90 degrees.
     * There, the slope the other observer found, whatever the height. */
    for (size_t i = 0; i < cells; i++) {
        if (isinf(lo[i]) || isinf(hi[i])) {
            lo[i] = isinf(lo[i]) ? hi[i] : lo[i]; /* -inf both: no far terrain */
            hi[i] = 0.0f;
        } else
            hi[i] = (float)((hi[i] - lo[i]) / (2 * TSD_FAR_DZ));
    }
    f->planes[f->n] = (struct tsd_far_plane){azimuth, lo, hi, NULL};
    return &f->planes[f->n++];
}

/* 1 if no far horizon can reach the lower limb of the light (of angular
 * radius `radius`) from any cell of g: the far field is the coarse grid's,
 * no higher than its highest cell. */
static int sun_clears_far(const tsd_far_field *f, const ts_grid *g, double elevation,
                          double radius)
{
    double limb = elevation - radius;
    if (!(limb > 0) || !isfinite(f->zmax))
        return !isfinite(f->zmax); /* no far terrain at all */
    float zmin = INFINITY;
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            float z = ts_grid_at(g, x, y);
            zmin = z < zmin ? z : zmin;
        }
    return !isfinite(zmin) ||
           (double)f->zmax - zmin < f->threshold * tan(limb * (M_PI / 180.0));
}

static ts_status far_raise(const tsd_compute_ctx *c, const ts_grid *g, double azimuth,
                           float *plane);
static ts_status far_edge(const tsd_compute_ctx *c, const ts_grid *g, double azimuth,
                          double elevation, double radius, float *plane);

ts_status tsd_compute_far(const tsd_compute_ctx *c, const ts_grid *g, double azimuth, int sun,
                          float *plane)
{
    return tsd_compute_far_light(c, g, azimuth, sun ? c->run->sun_elevation : NAN,
                                 c->opts->light_radius, plane);
}

ts_status tsd_compute_far_light(const tsd_compute_ctx *c, const ts_grid *g, double azimuth,
                                double elevation, double radius, float *plane)
{
    tsd_far_field *f = c->run->far;
    if (!f || !g->origin)
        return TS_OK;
    if (!(!isnan(elevation) && sun_clears_far(f, g, elevation, radius))) {
        ts_status st = far_raise(c, g, azimuth, plane);
        if (st != TS_OK)
            return st;
    }
    return far_edge(c, g, azimuth, elevation, radius, plane);
}

/* The world beyond the DEM's edge over the whole reach (EDGE), and the
 * Earth's horizon under a light (elevation not NaN), which the near field's
 * sweep left out (tsd_compute_horizon_opts): the DEM's edges, not the
 * window's. */
static ts_status far_edge(const tsd_compute_ctx *c, const ts_grid *g, double azimuth,
                          double elevation, double radius, float *plane)
{
    ts_horizon_opts h;
    ts_error err;
    const int sun = !isnan(elevation);
    tsd_compute_horizon_opts(c, &h);
    h.max_distance = c->opts->max_distance;
    h.edge = tsd_options_edge(c->opts);
    /* under the sun, read only through its disk (sun_horizon) */
    h.nonpositive_moot = sun && ts_light_clears_horizontal(elevation, radius);
    if (ts_horizon_edge_apply(g, azimuth, &h, plane, &err) != TS_OK ||
        (sun && ts_horizon_earth_floor(g, &h, plane, &err) != TS_OK))
        return tsd_fail_core(c->msg, c->msg_size, NULL, &err);
    return TS_OK;
}

/* One coarse cell's far slope seen from a fine cell at height z: the
 * plane's linear function of the observer's height; NAN where it has none
 * (nodata, or no far terrain). */
static inline double far_slope_at(const struct tsd_far_plane *p, size_t i, const float *zc,
                                  double z)
{
    float b = p->base[i];
    if (isnan(zc[0]) || isnan(b) || isinf(b))
        return NAN;
    return b + (z - zc[0] + TSD_FAR_DZ) * p->per_m[i];
}

/* Where fine cell g (global index, of n) lies between the centres of the
 * coarse cells (of m): the lower one and the weight of the upper. */
static inline int far_lerp_at(long g, int n, int m, float *w)
{
    double c = (g + 0.5) * m / n - 0.5;
    int i = (int)floor(c);
    if (i < 0) {
        *w = 0.0f;
        return 0;
    }
    if (i >= m - 1) {
        *w = 0.0f;
        return m - 1;
    }
    *w = (float)(c - i);
    return i;
}

/* The far field: each cell's horizon raised to the coarse grid's beyond the
 * near field, interpolated bilinearly between the four coarse cells around
 * it (each evaluated at the cell's own height): a coarse cell's far field
 * is the one seen from its centre, which is up to half a coarse cell nearer
 * or farther along the ray than the cell. */
static ts_status far_raise(const tsd_compute_ctx *c, const ts_grid *g, double azimuth,
                           float *plane)
{
    tsd_far_field *f = c->run->far;
    const struct tsd_far_plane *p = far_plane(f, azimuth, c);
    if (!p)
        return TS_ERR_NOMEM;
    const int cw = f->coarse.width, ch = f->coarse.height;
    if (f->own) {
        for (int y = 0; y < g->height; y++) {
            float *row = plane + (size_t)y * g->width;
            const uint16_t *q = p->angle + (size_t)(g->origin->y0 + y) * cw + g->origin->x0;
            for (int x = 0; x < g->width; x++) {
                if (q[x] == 0 || isnan(row[x]))
                    continue;
                float deg = (float)((q[x] - 1) * (1.0 / TSD_FAR_STEPS_PER_DEGREE) - 90.0);
                row[x] = deg > row[x] ? deg : row[x];
            }
        }
        return TS_OK;
    }
    for (int y = 0; y < g->height; y++) {
        float wy;
        int cy = far_lerp_at(g->origin->y0 + y, f->fine_h, ch, &wy);
        int cy1 = cy + 1 < ch ? cy + 1 : cy;
        float *row = plane + (size_t)y * g->width;
        const float *zrow = g->z + (ptrdiff_t)y * g->stride;
        for (int x = 0; x < g->width; x++) {
            if (isnan(row[x]))
                continue;
            float wx;
            int cx = far_lerp_at(g->origin->x0 + x, f->fine_w, cw, &wx);
            int cx1 = cx + 1 < cw ? cx + 1 : cx;
            const int xs[4] = {cx, cx1, cx, cx1}, ys[4] = {cy, cy, cy1, cy1};
            const float ws[4] = {(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy};
            double sum = 0, wsum = 0;
            for (int k = 0; k < 4; k++) {
                if (ws[k] <= 0)
                    continue;
                size_t i = (size_t)ys[k] * cw + xs[k];
                double s = far_slope_at(
                    p, i, f->coarse.z + (ptrdiff_t)ys[k] * f->coarse.stride + xs[k], zrow[x]);
                if (isnan(s))
                    continue;
                sum += ws[k] * s;
                wsum += ws[k];
            }
            if (!(wsum > 0))
                continue;
            float deg = (float)(atan(sum / wsum) * (180.0 / M_PI));
            row[x] = deg > row[x] ? deg : row[x];
        }
    }
    return TS_OK;
}
