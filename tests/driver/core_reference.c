/*
 * core_reference - compute a terrashade product with the core library
 * alone, for the driver tests to compare gdal_translate's output against.
 * No GDAL. It reaches the products by a different path from the driver
 * where the core offers one (all horizon planes at once with
 * ts_horizon_compute and ts_sky_terms, rather than the driver's streaming
 * ts_horizon_sweep + ts_sky_accumulate).
 *
 * usage: core_reference PRODUCT WIDTH HEIGHT CELL_X CELL_Y in.f32 out.f32
 *                       [KEY=VALUE...]
 *   PRODUCT: shade shadow horizon svf sky openness
 *   in.f32:  WIDTH*HEIGHT native floats, metres, NaN = nodata, row 0 north
 *   out.f32: the product, float planes (DIRECTIONS planes for horizon)
 *   keys: SUN_AZIMUTH SUN_ELEVATION DIRECTIONS START_AZIMUTH METHOD
 *         (exact|shm) PENUMBRA_DEPTH MAX_DISTANCE CURVATURE (YES|NO)
 *         REFRACTION SKY_WEIGHT THREADS EDGE (horizon|open|nodata, default
 *         horizon as the driver's) ROWS (file of HEIGHT native doubles:
 *         east-west cell size of each row)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade.h"

typedef struct {
    double sun_az, sun_el, penumbra, sky_weight;
    int shm;
    ts_horizon_opts h;
    const char *rows;
} params;

static void die(const char *what, const ts_error *err)
{
    fprintf(stderr, "core_reference: %s%s%s\n", what, err ? ": " : "",
            err ? err->message : "");
    exit(1);
}

static void *xalloc(size_t n)
{
    void *p = calloc(n, 1);
    if (!p)
        die("out of memory", NULL);
    return p;
}

static void read_file(const char *path, void *buf, size_t bytes)
{
    FILE *f = fopen(path, "rb");
    if (!f || fread(buf, 1, bytes, f) != bytes)
        die(path, NULL);
    fclose(f);
}

static void parse_key(params *p, const char *kv)
{
    const char *eq = strchr(kv, '=');
    if (!eq)
        die("arguments after out.f32 must be KEY=VALUE", NULL);
    size_t k = (size_t)(eq - kv);
    const char *v = eq + 1;
#define KEY(name) (k == strlen(name) && strncmp(kv, name, k) == 0)
    if (KEY("SUN_AZIMUTH")) p->sun_az = atof(v);
    else if (KEY("SUN_ELEVATION")) p->sun_el = atof(v);
    else if (KEY("DIRECTIONS")) p->h.directions = atoi(v);
    else if (KEY("START_AZIMUTH")) p->h.start_azimuth = atof(v);
    else if (KEY("METHOD")) p->shm = strcmp(v, "shm") == 0;
    else if (KEY("PENUMBRA_DEPTH")) p->penumbra = atof(v);
    else if (KEY("MAX_DISTANCE")) p->h.max_distance = atof(v);
    else if (KEY("CURVATURE")) p->h.curvature = strcmp(v, "YES") == 0;
    else if (KEY("REFRACTION")) p->h.refraction = atof(v);
    else if (KEY("SKY_WEIGHT")) p->sky_weight = atof(v);
    else if (KEY("THREADS")) p->h.threads = atoi(v);
    else if (KEY("EDGE"))
        p->h.edge = strcmp(v, "open") == 0     ? TS_EDGE_OPEN
                    : strcmp(v, "nodata") == 0 ? TS_EDGE_NODATA
                                               : TS_EDGE_HORIZON;
    else if (KEY("ROWS")) p->rows = v;
    else die(kv, NULL);
#undef KEY
}

/* All horizon planes for p->h, then the sky terms. */
static void sky_terms(const ts_grid *g, const float *nx, const float *ny,
                      const float *nz, const params *p, float *svf, float *sky,
                      float *open)
{
    ts_error err;
    size_t cells = (size_t)g->width * g->height;
    float *hz = xalloc(cells * p->h.directions * sizeof(float));
    if (ts_horizon_compute(g, &p->h, hz, &err) != TS_OK)
        die("ts_horizon_compute", &err);
    const ts_sky_request req = {g, nx, ny, nz, hz, &p->h, TS_SVF_RADIATIVE, svf, sky, open};
    if (ts_sky_terms(&req, &err) != TS_OK)
        die("ts_sky_terms", &err);
    free(hz);
}

/* Visible fraction of the sun into vis (exact horizon or SHM). */
static void sun_visibility(const ts_grid *g, const params *p, float *vis,
                           float *horizon)
{
    ts_error err;
    size_t cells = (size_t)g->width * g->height;
    if (p->shm) {
        if (ts_shm_compute(g, p->sun_az, p->sun_el, p->penumbra, p->h.threads,
                           vis, NULL, &err) != TS_OK)
            die("ts_shm_compute", &err);
        if (p->h.edge == TS_EDGE_OPEN)
            return;
        /* the shadow height map sees no edge: times the disk above the
         * edge's and the Earth's horizon alone */
        for (size_t i = 0; i < cells; i++)
            horizon[i] = -90.0f;
        if (ts_horizon_edge_apply(g, p->sun_az, &p->h, horizon, &err) != TS_OK)
            die("ts_horizon_edge_apply", &err);
    } else if (ts_horizon_sweep(g, p->sun_az, &p->h, horizon, &err) != TS_OK) {
        die("ts_horizon_sweep", &err);
    }
    if (ts_horizon_earth_floor(g, &p->h, horizon, &err) != TS_OK)
        die("ts_horizon_earth_floor", &err);
    for (size_t i = 0; i < cells; i++) {
        float f = isnan(horizon[i]) ? NAN : (float)ts_sun_disk_fraction(p->sun_el, horizon[i]);
        vis[i] = p->shm ? vis[i] * f : f;
    }
}

int main(int argc, char **argv)
{
    if (argc < 8) {
        fprintf(stderr, "usage: core_reference PRODUCT WIDTH HEIGHT CELL_X "
                        "CELL_Y in.f32 out.f32 [KEY=VALUE...]\n");
        return 2;
    }
    params p = {315, 45, 0, 0, 0, {0}, NULL};
    ts_horizon_opts_default(&p.h);
    p.h.edge = TS_EDGE_HORIZON; /* the driver's default */
    for (int i = 8; i < argc; i++)
        parse_key(&p, argv[i]);
    const char *product = argv[1];
    ts_grid g;
    ts_error err;
    if (ts_grid_create(&g, atoi(argv[2]), atoi(argv[3]), atof(argv[4]),
                       atof(argv[5]), &err) != TS_OK)
        die("ts_grid_create", &err);
    size_t cells = (size_t)g.width * g.height;
    read_file(argv[6], g.z, cells * sizeof(float));
    if (p.rows) {
        double *rows = xalloc((size_t)g.height * sizeof(double));
        read_file(p.rows, rows, (size_t)g.height * sizeof(double));
        if (ts_grid_set_row_spacing(&g, rows, &err) != TS_OK)
            die("ts_grid_set_row_spacing", &err);
        free(rows);
    }
    int planes = strcmp(product, "horizon") == 0 ? p.h.directions : 1;
    float *out = xalloc(cells * planes * sizeof(float));
    float *nx = xalloc(cells * 4), *ny = xalloc(cells * 4), *nz = xalloc(cells * 4);
    if (ts_normals(&g, nx, ny, nz, &err) != TS_OK)
        die("ts_normals", &err);

    if (strcmp(product, "horizon") == 0) {
        if (ts_horizon_compute(&g, &p.h, out, &err) != TS_OK)
            die("ts_horizon_compute", &err);
    } else if (strcmp(product, "svf") == 0) {
        sky_terms(&g, nx, ny, nz, &p, out, NULL, NULL);
    } else if (strcmp(product, "sky") == 0) {
        sky_terms(&g, nx, ny, nz, &p, NULL, out, NULL);
    } else if (strcmp(product, "openness") == 0) {
        sky_terms(&g, nx, ny, nz, &p, NULL, NULL, out);
    } else if (strcmp(product, "shadow") == 0) {
        float *hz = xalloc(cells * sizeof(float));
        sun_visibility(&g, &p, out, hz);
        free(hz);
    } else if (strcmp(product, "shade") == 0) {
        float *hz = xalloc(cells * sizeof(float));
        if (p.shm) {
            float *vis = xalloc(cells * sizeof(float));
            sun_visibility(&g, &p, vis, hz);
            double az = p.sun_az * M_PI / 180, el = p.sun_el * M_PI / 180;
            double lx = sin(az) * cos(el), ly = cos(az) * cos(el), lz = sin(el);
            for (size_t i = 0; i < cells; i++) {
                double d = nx[i] * lx + ny[i] * ly + nz[i] * lz;
                out[i] = (float)((d > 0 ? d : 0) * vis[i]);
            }
            free(vis);
        } else {
            ts_horizon_opts one = p.h;
            one.directions = 1;
            one.start_azimuth = p.sun_az;
            if (ts_horizon_sweep(&g, p.sun_az, &one, hz, &err) != TS_OK ||
                ts_horizon_earth_floor(&g, &one, hz, &err) != TS_OK)
                die("ts_horizon_sweep", &err);
            const ts_direct_request req = {&g, nx, ny, nz, hz, &one, p.sun_az, p.sun_el, out,
                                           TS_SUN_RADIUS_DEG};
            if (ts_shade_direct(&req, &err) != TS_OK)
                die("ts_shade_direct", &err);
        }
        if (p.sky_weight > 0) {
            float *sky = xalloc(cells * sizeof(float));
            sky_terms(&g, nx, ny, nz, &p, NULL, sky, NULL);
            if (ts_shade_combine(&g, out, sky, p.sky_weight, out, &err) != TS_OK)
                die("ts_shade_combine", &err);
            free(sky);
        }
        free(hz);
    } else {
        die("unknown product", NULL);
    }
    FILE *f = fopen(argv[7], "wb");
    if (!f || fwrite(out, sizeof(float), cells * planes, f) != cells * planes ||
        fclose(f) != 0)
        die(argv[7], NULL);
    free(out);
    free(nx);
    free(ny);
    free(nz);
    ts_grid_free(&g);
    return 0;
}
