/* Test DEMs: synthetic generators and the raw-file loader. */
#include "test_dem.h"

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef TS_TEST_DATA
#define TS_TEST_DATA "tests/data"
#endif

static const double PI = 3.14159265358979323846;

double tdem_uniform(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

void tdem_create(ts_grid *g, int width, int height, double cell_x,
                 double cell_y)
{
    ts_error err;
    ts_status st = ts_grid_create(g, width, height, cell_x, cell_y, &err);
    ck_assert_msg(st == TS_OK, "ts_grid_create(%d, %d): %s", width, height,
                  err.message);
}

void tdem_fill(ts_grid *g, float z)
{
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++)
            g->z[(ptrdiff_t)y * g->stride + x] = z;
}

/* Rescale the valid heights linearly onto [0, relief]. */
static void rescale(ts_grid *g, double relief)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            double v = g->z[(ptrdiff_t)y * g->stride + x];
            if (v < lo) lo = v;
            if (v > hi) hi = v;
        }
    double s = hi > lo ? relief / (hi - lo) : 0.0;
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            float *p = &g->z[(ptrdiff_t)y * g->stride + x];
            *p = (float)((*p - lo) * s);
        }
}

void tdem_fractal(ts_grid *g, uint64_t seed, double relief)
{
    enum { WAVES = 160 };
    double kx[WAVES], ky[WAVES], amp[WAVES], phase[WAVES];
    double side = g->width > g->height ? g->width : g->height;
    for (int i = 0; i < WAVES; i++) {
        /* wavelengths log-uniform from 2 * side down to 2.5 cells */
        double lambda = 2.0 * side * pow(2.5 / (2.0 * side), tdem_uniform(&seed));
        double dir = 2.0 * PI * tdem_uniform(&seed);
        kx[i] = 2.0 * PI / lambda * cos(dir);
        ky[i] = 2.0 * PI / lambda * sin(dir);
        amp[i] = lambda; /* amplitude ~ 1/f */
        phase[i] = 2.0 * PI * tdem_uniform(&seed);
    }
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            double z = 0;
            for (int i = 0; i < WAVES; i++)
                z += amp[i] * sin(kx[i] * x + ky[i] * y + phase[i]);
            g->z[(ptrdiff_t)y * g->stride + x] = (float)z;
        }
    rescale(g, relief);
}

void tdem_sines(ts_grid *g, double relief)
{
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            double z = sin(x * 0.071) * cos(y * 0.053) +
                       0.5 * sin(0.037 * x + 0.091 * y + 1.0) +
                       0.25 * cos(0.13 * x - 0.17 * y);
            g->z[(ptrdiff_t)y * g->stride + x] = (float)z;
        }
    rescale(g, relief);
}

void tdem_hills(ts_grid *g, uint64_t seed, int count, double relief)
{
    tdem_fill(g, 0.0f);
    for (int i = 0; i < count; i++) {
        double cx = g->width * tdem_uniform(&seed);
        double cy = g->height * tdem_uniform(&seed);
        double r = 3.0 + 20.0 * tdem_uniform(&seed);
        double h = relief * (0.2 + 0.8 * tdem_uniform(&seed));
        for (int y = 0; y < g->height; y++)
            for (int x = 0; x < g->width; x++) {
                double q = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (r * r);
                g->z[(ptrdiff_t)y * g->stride + x] += (float)(h * exp(-0.5 * q));
            }
    }
}

void tdem_sharp(ts_grid *g, uint64_t seed)
{
    tdem_fractal(g, seed, 50.0);
    double sx = g->width * (0.3 + 0.4 * tdem_uniform(&seed));
    double sy = g->height * (0.3 + 0.4 * tdem_uniform(&seed));
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++) {
            float *p = &g->z[(ptrdiff_t)y * g->stride + x];
            if (x > sx) *p += 40.0f;                  /* cliff facing west */
            if (x - 0.5 * y > sy) *p -= 25.0f;        /* oblique step */
            *p += (float)(4.0 * tdem_uniform(&seed) - 2.0); /* noise */
            if (tdem_uniform(&seed) < 0.01)           /* spikes */
                *p += (float)(20.0 + 130.0 * tdem_uniform(&seed));
        }
}

float *tdem_floats(size_t n)
{
    float *p = malloc((n ? n : 1) * sizeof *p);
    ck_assert_msg(p != NULL, "cannot allocate %zu floats", n);
    return p;
}

static FILE *open_data(const char *name, const char *ext, const char *mode)
{
    const char *dir = getenv("TS_TEST_DATA");
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.%s", dir && *dir ? dir : TS_TEST_DATA,
             name, ext);
    FILE *f = fopen(path, mode);
    ck_assert_msg(f != NULL, "cannot open test data %s", path);
    return f;
}

void tdem_load(ts_grid *g, const char *name)
{
    FILE *f = open_data(name, "hdr", "r");
    char line[256], key[64];
    int w = 0, h = 0;
    double cell_y = 0, v;
    double *cx = NULL;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#')
            continue;
        if (strncmp(line, "cell_x_row", 10) == 0) {
            ck_assert_msg(w > 0 && h > 0 && cell_y > 0, "%s.hdr: bad header", name);
            cx = malloc((size_t)h * sizeof *cx);
            ck_assert(cx != NULL);
            for (int y = 0; y < h; y++)
                ck_assert_msg(fscanf(f, "%lf", &cx[y]) == 1,
                              "%s.hdr: missing cell_x_row[%d]", name, y);
            break;
        }
        if (sscanf(line, "%63s %lf", key, &v) != 2)
            continue;
        if (strcmp(key, "width") == 0) w = (int)v;
        else if (strcmp(key, "height") == 0) h = (int)v;
        else if (strcmp(key, "cell_y") == 0) cell_y = v;
    }
    fclose(f);
    ck_assert_msg(cx != NULL, "%s.hdr: no cell_x_row", name);

    tdem_create(g, w, h, cx[h / 2], cell_y);
    ts_error err;
    ck_assert_msg(ts_grid_set_row_spacing(g, cx, &err) == TS_OK, "%s", err.message);
    free(cx);

    /* little-endian float32, assembled bytewise so the host order is moot */
    f = open_data(name, "f32", "rb");
    unsigned char b[4];
    for (ptrdiff_t i = 0; i < (ptrdiff_t)w * h; i++) {
        ck_assert_msg(fread(b, 1, 4, f) == 4, "%s.f32 is short", name);
        uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 |
                     (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
        memcpy(&g->z[i], &u, 4);
    }
    fclose(f);
}
