/* Environment light in the driver; see tsd_compute_env.h. */
#include "tsd_compute_env.h"

#include "tsd_backend.h"
#include "tsd_compute_sh.h"
#include "tsd_products.h"
#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Rec. 709 / sRGB luminance of linear RGB. */
#define LUMA(r, g, b) (0.2126 * (r) + 0.7152 * (g) + 0.0722 * (b))

/* The unshadowed surfaces sampled for the automatic exposure: every
 * PEAK_STEP degrees of aspect, and of slope from 0 (flat) to below 90. */
#define PEAK_STEP 5
#define PEAK_ASPECTS (360 / PEAK_STEP)
#define PEAK_SLOPES (90 / PEAK_STEP)

int tsd_options_env(const tsd_options *o)
{
    return o->env_map[0] || o->sky[0];
}

int tsd_environment_sunless(const tsd_options *o)
{
    ts_sky_kind kind;
    int cie = 0;
    return o->env_map[0] || (o->sky[0] && ts_sky_parse(o->sky, &kind, &cie, NULL) == TS_OK &&
                             !ts_sky_follows_sun(kind, cie));
}

int tsd_exposure_parse(const char *text, double *stops)
{
    if (!text[0] || strcasecmp(text, "auto") == 0)
        return 1;
    double x;
    if (tsd_parse_decimal(text, &x) != 0 || fabs(x) > TSD_EXPOSURE_MAX)
        return -1;
    *stops = x;
    return 0;
}

const char *tsd_environment_layout(const tsd_environment *e)
{
    return e->map.cube ? "cube" : "lat-long";
}

void tsd_environment_free(tsd_environment *e)
{
    if (!e)
        return;
    ts_env_free(&e->env);
    ts_env_table_free(&e->table);
    memset(e, 0, sizeof *e);
}

/* The light table's nodes: DIRECTIONS x ENV_NORMAL_STEPS (1 when exact) x
 * ENV_HORIZON_STEPS (one count for its limit and its memory estimate). */
static double table_nodes(const tsd_options *o)
{
    return (double)o->directions * (o->env_normal_steps ? o->env_normal_steps : 1) *
           o->env_horizon_steps;
}

/* OpenEXRCore's buffers for one chunk, packed and unpacked, per pixel of
 * the map's width: up to 32 lines (PIZ, B44) of 4 float channels, twice
 * (DWA's 256-line chunks are of half channels: the same order). */
#define DECODE_BYTES_PER_COLUMN (2.0 * 32 * 4 * sizeof(float))

void tsd_environment_cost(const tsd_options *o, const ts_env_map_info *map, double map_bytes,
                          tsd_env_cost *c)
{
    memset(c, 0, sizeof *c);
    if (!tsd_options_env(o))
        return;
    c->texels = map ? (double)ts_env_map_texels(map, TSD_ENV_MAX_TEXELS)
                    : (double)TS_SKY_DEFAULT_WIDTH * TS_SKY_DEFAULT_HEIGHT;
    const double texels = c->texels * sizeof(ts_env_texel);
    const double nodes = table_nodes(o);
    /* ts_env_table_build sums in doubles, then copies to the kept floats:
     * 8 doubles and 8 floats a node at once, three times the table */
    const double table = nodes * 8 * sizeof(float);
    c->table_peak = map_bytes + texels + nodes * 8 * (sizeof(double) + sizeof(float));
    if (map) /* the pixels as three floats beside the texels made from them */
        c->map_peak = map_bytes + (double)map->width * map->height * 3 * sizeof(float) +
                      map->width * DECODE_BYTES_PER_COLUMN + texels;
    else
        c->map_peak = texels;
    c->peak = c->map_peak > c->table_peak ? c->map_peak : c->table_peak;
    c->kept = texels + table;
}

int tsd_environment_same(const tsd_options *a, const tsd_run *ra, const tsd_options *b,
                         const tsd_run *rb)
{
    if (strcmp(a->env_map, b->env_map) != 0 || strcmp(a->sky, b->sky) != 0 ||
        strcmp(a->exposure, b->exposure) != 0 || a->env_rotation != b->env_rotation ||
        a->directions != b->directions || a->start_azimuth != b->start_azimuth ||
        a->env_normal_steps != b->env_normal_steps ||
        a->env_horizon_steps != b->env_horizon_steps)
        return 0;
    if (tsd_environment_sunless(a))
        return 1;
    /* a sky placed by the sun: the same sun, up to rounding (a level's sun
     * is the same instant at the same centre, through a scaled
     * geotransform); a sun in another place makes another sky */
    return fabs(remainder(ra->sun_azimuth - rb->sun_azimuth, 360.0)) <= 1e-9 &&
           fabs(ra->sun_elevation - rb->sun_elevation) <= 1e-9;
}

/* The light of unshadowed surfaces of every sampled slope and aspect (no
 * horizon above the tangent plane) through the table: e->flat from the flat
 * one, e->peak the largest channel of any. */
static ts_status sample_surfaces(tsd_environment *e, ts_error *err)
{
    ts_grid g;
    ts_status st = ts_grid_create(&g, PEAK_ASPECTS, PEAK_SLOPES, 1.0, 1.0, err);
    if (st != TS_OK)
        return st;
    size_t n = (size_t)PEAK_ASPECTS * PEAK_SLOPES;
    float *buf = calloc(n * 7, sizeof *buf);
    if (!buf) {
        ts_grid_free(&g);
        return TS_ERR_NOMEM;
    }
    float *nx = buf, *ny = buf + n, *nz = buf + 2 * n, *plane = buf + 3 * n;
    float *r = buf + 4 * n, *gr = buf + 5 * n, *b = buf + 6 * n;
    for (int s = 0; s < PEAK_SLOPES; s++)
        for (int a = 0; a < PEAK_ASPECTS; a++) {
            size_t i = (size_t)s * PEAK_ASPECTS + a;
            double t = s * PEAK_STEP * M_PI / 180, az = a * PEAK_STEP * M_PI / 180;
            nx[i] = (float)(sin(t) * sin(az));
            ny[i] = (float)(sin(t) * cos(az));
            nz[i] = (float)cos(t);
            plane[i] = -90.0f; /* nothing above the tangent plane */
        }
    ts_env_light_request req = {&g, &e->table, 0, nx, ny, nz, plane, r, gr, b, 0};
    for (req.k = 0; st == TS_OK && req.k < e->table.directions; req.k++)
        st = ts_env_light_accumulate(&req, err);
    if (st == TS_OK)
        st = ts_env_light_finish(&g, r, gr, b, err);
    if (st == TS_OK) {
        e->flat[0] = r[0], e->flat[1] = gr[0], e->flat[2] = b[0];
        e->peak = 0;
        for (size_t i = 0; i < n; i++) {
            double m = fmax(r[i], fmax(gr[i], b[i]));
            e->peak = m > e->peak ? m : e->peak;
        }
    }
    free(buf);
    ts_grid_free(&g);
    return st;
}

/* The texels of ENV_MAP, or of SKY with the run's sun. */
static ts_status load_environment(const tsd_options *o, const tsd_run *run, const void *map,
                                  size_t map_size, tsd_environment *e, char *msg, size_t n)
{
    ts_error err;
    if (o->env_map[0]) {
        e->has_map = 1;
        if (ts_env_exr_info(map, map_size, o->env_map, &e->map, &err) != TS_OK ||
            ts_env_load_exr_memory(map, map_size, o->env_map, o->env_rotation,
                                   TSD_ENV_MAX_TEXELS, &e->env, &err) != TS_OK)
            return tsd_fail_core(msg, n, "ENV_MAP", &err);
        return TS_OK;
    }
    ts_sky_kind kind;
    int type;
    if (ts_sky_parse(o->sky, &kind, &type, &err) != TS_OK ||
        ts_env_sky(&e->env, kind, type, run->sun_azimuth, run->sun_elevation, 0, 0, &err) !=
            TS_OK)
        return tsd_fail_core(msg, n, "SKY", &err);
    return TS_OK;
}

ts_status tsd_environment_check_table(const tsd_options *o, char *msg, size_t n)
{
    double table_bytes = table_nodes(o) * 8 * sizeof(float);
    if (table_bytes > TSD_ENV_MAX_TABLE_BYTES)
        return tsd_fail(msg, n, TS_ERR_ARG,
                        "the light table of DIRECTIONS=%d, ENV_NORMAL_STEPS=%d and "
                        "ENV_HORIZON_STEPS=%d would take %.0f MiB, more than %.0f MiB: use "
                        "ENV_NORMAL_STEPS=0 (exact) or fewer steps",
                        o->directions, o->env_normal_steps, o->env_horizon_steps,
                        table_bytes / 1048576, TSD_ENV_MAX_TABLE_BYTES / 1048576);
    return TS_OK;
}

ts_status tsd_environment_setup(const tsd_options *o, const tsd_run *run, const void *map,
                                size_t map_size, tsd_environment *e, char *msg, size_t n)
{
    ts_error err;
    ts_status st;
    memset(e, 0, sizeof *e);
    if ((st = tsd_environment_check_table(o, msg, n)) != TS_OK)
        return st;
    if ((st = load_environment(o, run, map, map_size, e, msg, n)) != TS_OK) {
        tsd_environment_free(e);
        return st;
    }
    ts_env_table_opts to;
    ts_env_table_opts_default(&to);
    to.directions = o->directions;
    to.start_azimuth = o->start_azimuth;
    to.normal_steps = o->env_normal_steps;
    to.horizon_steps = o->env_horizon_steps;
    to.ground = 0; /* the sky ends at the horizontal, as the sky product's */
    if ((st = ts_env_table_build(&e->env, &to, &e->table, &err)) != TS_OK ||
        (st = sample_surfaces(e, &err)) != TS_OK) {
        tsd_environment_free(e);
        return st == TS_ERR_NOMEM ? tsd_fail(msg, n, st, "out of memory for the light table")
                                  : tsd_fail_core(msg, n, NULL, &err);
    }
    e->exposure_auto = tsd_exposure_parse(o->exposure, &e->exposure) == 1;
    if (e->exposure_auto)
        e->exposure = e->peak > 0 ? -log2(e->peak) : 0.0;
    return TS_OK;
}

/* The environment light of sector k added to three accumulators, on the
 * backend (the device state carried from plane to plane in `state`). */
typedef struct {
    const tsd_compute_ctx *c;
    const tsd_environment *e;
    const tsd_normals *nm;
    ts_backend_env_light state;
    float *r, *g, *b;
} env_acc;

static ts_status env_add(void *user, const ts_grid *g, int k, double azimuth,
                         const float *plane, ts_error *err)
{
    (void)azimuth; /* the table's sector k is the sweep's azimuth k */
    env_acc *a = user;
    ts_backend_report rep = {0};
    const ts_env_light_request req = {g, &a->e->table, k, a->nm->nx, a->nm->ny, a->nm->nz,
                                      plane, a->r, a->g, a->b, a->c->opts->threads};
    ts_status st = ts_backend_env_light_accumulate(tsd_backend_to_ts(a->c->opts->backend),
                                                   &a->state, &req, &rep, err);
    if (a->c->backend && rep.backend[0])
        tsd_backend_summary_add(a->c->backend, &rep);
    return st;
}

/* E/pi per colour into the zeroed planes r, g, b. */
static ts_status env_light(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                           float *r, float *gr, float *b)
{
    ts_error err;
    env_acc a = {c, c->run->env, nm, {0}, r, gr, b};
    ts_status st = tsd_compute_stream(c, g, env_add, &a);
    ts_backend_env_light_release(&a.state);
    if (st != TS_OK)
        return st;
    if (ts_env_light_finish(g, r, gr, b, &err) != TS_OK)
        return tsd_fail_core(c->msg, c->msg_size, NULL, &err);
    return TS_OK;
}

/* The sRGB transfer curve (IEC 61966-2-1) of a linear value in 0..1. */
static float srgb_encode(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return (float)(x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055);
}

TSD_COMPUTE_FN(tsd_compute_envlight)
{
    (void)bytes;
    const ts_grid *g = r->dem;
    size_t cells = (size_t)g->width * g->height;
    tsd_normals nm = {0};
    ts_status st;
    if (!c->run->env)
        return tsd_fail(c->msg, c->msg_size, TS_ERR_ARG,
                        "PRODUCT=envlight has no environment (ENV_MAP or SKY)");
    memset(out, 0, 3 * cells * sizeof(float));
    if ((st = tsd_normals_make(c, g, &nm)) == TS_OK)
        st = c->opts->env_method == TSD_ENV_SH
                 ? tsd_sh_env_light(c, g, &nm, out, out + cells, out + 2 * cells)
                 : env_light(c, g, &nm, out, out + cells, out + 2 * cells);
    tsd_normals_free(&nm);
    if (st != TS_OK || !tsd_options_output_byte(c->opts))
        return st;
    /* Byte: exposure, then the sRGB curve; tsd_to_byte maps 0..1 to 1..255 */
    const double scale = exp2(c->run->env->exposure);
    for (size_t i = 0; i < 3 * cells; i++)
        if (out[i] == out[i])
            out[i] = srgb_encode(out[i] * scale);
    return TS_OK;
}

ts_status tsd_env_sky_term(const tsd_compute_ctx *c, const ts_grid *g, const tsd_normals *nm,
                           float *sky)
{
    const tsd_environment *e = c->run->env;
    size_t cells = (size_t)g->width * g->height;
    double flat = LUMA(e->flat[0], e->flat[1], e->flat[2]);
    if (!(flat > 0))
        return tsd_fail(c->msg, c->msg_size, TS_ERR_ARG,
                        "the environment has no light above the horizontal, so it cannot "
                        "be the sky term of shade (normalised by an open flat plane's light)");
    float *gr = calloc(cells, sizeof *gr), *b = calloc(cells, sizeof *b);
    ts_status st = !gr || !b ? tsd_fail(c->msg, c->msg_size, TS_ERR_NOMEM,
                                        "out of memory for the environment light")
                             : env_light(c, g, nm, sky, gr, b);
    for (size_t i = 0; st == TS_OK && i < cells; i++)
        sky[i] = (float)(LUMA(sky[i], gr[i], b[i]) / flat); /* NaN stays NaN */
    free(gr);
    free(b);
    return st;
}
