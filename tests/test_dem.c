/* Test DEMs: the generators and the raw-file reader (see test_dem.h). */
#include "test_dem.h"

#include <math.h>
#include <stdarg.h>
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

uint32_t tdem_xorshift32(uint32_t *state)
{
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    return *state;
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

/* A lattice value in [-0.5, 0.5] from a hash of its corner and the seed. */
static inline float lattice(uint32_t x, uint32_t y, uint32_t seed)
{
    uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return (float)(h & 0xffffff) / (float)0xffffff - 0.5f;
}

void tdem_fbm(ts_grid *g, unsigned seed, double hurst, double relief)
{
    int W = g->width, H = g->height;
    int side = W > H ? W : H;
    double wavelength = side;
    double amp = 1.0;
    tdem_fill(g, 0.0f);
    for (int oct = 0; wavelength >= 2.0; oct++, wavelength /= 2, amp *= pow(2.0, -hurst)) {
        float inv = (float)(1.0 / wavelength), a = (float)amp;
        for (int y = 0; y < H; y++) {
            float fy = y * inv;
            uint32_t iy = (uint32_t)fy;
            float ty = fy - iy;
            for (int x = 0; x < W; x++) {
                float fx = x * inv;
                uint32_t ix = (uint32_t)fx;
                float tx = fx - ix;
                uint32_t s = seed + (uint32_t)oct;
                float v00 = lattice(ix, iy, s), v10 = lattice(ix + 1, iy, s);
                float v01 = lattice(ix, iy + 1, s), v11 = lattice(ix + 1, iy + 1, s);
                float v0 = v00 + tx * (v10 - v00), v1 = v01 + tx * (v11 - v01);
                g->z[(ptrdiff_t)y * g->stride + x] += a * (v0 + ty * (v1 - v0));
            }
        }
    }
    /* in float, unlike rescale(): the benchmarks' surfaces stay as they were */
    float lo = INFINITY, hi = -INFINITY;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float v = g->z[(ptrdiff_t)y * g->stride + x];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    float scale = hi > lo ? (float)(relief / (hi - lo)) : 0.0f;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *p = &g->z[(ptrdiff_t)y * g->stride + x];
            *p = (*p - lo) * scale;
        }
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

/* A per-cell hash in [0, 1]. */
static double hash01(unsigned x, unsigned y, unsigned seed)
{
    unsigned h = x * 374761393u + y * 668265263u + seed * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    h ^= h >> 16;
    return (h & 0xffffff) / (double)0xffffff;
}

void tdem_sines_hash_noise(ts_grid *g, unsigned seed, int holes)
{
    int w = g->width, h = g->height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double X = x, Y = y;
            double v = 300 + 120 * sin(0.11 * X + 0.3) * cos(0.07 * Y) +
                       60 * sin(0.23 * X + 0.19 * Y) + 25 * sin(0.51 * X - 0.43 * Y + 1) +
                       8 * sin(1.3 * X + 0.9 * Y) + 6 * (2 * hash01(x, y, seed) - 1);
            if (holes) {
                if (x >= w / 3 && x < w / 3 + 4 && y >= h / 2 && y < h / 2 + 3)
                    v = NAN;
                if (hash01(x, y, seed + 7) < 0.03)
                    v = NAN;
            }
            g->z[(ptrdiff_t)y * g->stride + x] = (float)v;
        }
}

void tdem_sines_rng_noise(ts_grid *g, uint32_t *state)
{
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++)
            g->z[(ptrdiff_t)y * g->stride + x] =
                (float)(300.0 * sin(x * 0.21) * cos(y * 0.17) +
                        (tdem_xorshift32(state) % 1000) * 0.2);
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

/* ------------------------------------------------------- the raw DEMs */

typedef struct {
    int w, h;
    double cell_y, lon0, lat0, dlon, dlat;
    double *cell_x_row; /* h values */
} raw_header;

static int fail(char *msg, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, n, fmt, ap);
    va_end(ap);
    return -1;
}

static FILE *open_data(const char *name, const char *ext, const char *mode, char *msg,
                       size_t n)
{
    const char *dir = getenv("TS_TEST_DATA");
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.%s", dir && *dir ? dir : TS_TEST_DATA, name, ext);
    FILE *f = fopen(path, mode);
    if (!f)
        fail(msg, n, "cannot open test data %s (tests/data/make_raw.py writes it)", path);
    return f;
}

/* "key value" lines, '#' comments, then cell_x_row and its h values. */
static int read_header(FILE *f, const char *name, raw_header *r, char *msg, size_t n)
{
    char line[256], key[64];
    double v;
    memset(r, 0, sizeof *r);
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#')
            continue;
        if (strncmp(line, "cell_x_row", 10) == 0) {
            if (r->w <= 0 || r->h <= 0 || !(r->cell_y > 0))
                return fail(msg, n, "%s.hdr: bad header", name);
            r->cell_x_row = malloc((size_t)r->h * sizeof *r->cell_x_row);
            if (!r->cell_x_row)
                return fail(msg, n, "%s.hdr: out of memory", name);
            for (int y = 0; y < r->h; y++)
                if (fscanf(f, "%lf", &r->cell_x_row[y]) != 1)
                    return fail(msg, n, "%s.hdr: missing cell_x_row[%d]", name, y);
            return 0;
        }
        if (sscanf(line, "%63s %lf", key, &v) != 2)
            continue;
        if (strcmp(key, "width") == 0) r->w = (int)v;
        else if (strcmp(key, "height") == 0) r->h = (int)v;
        else if (strcmp(key, "cell_y") == 0) r->cell_y = v;
        else if (strcmp(key, "lon0") == 0) r->lon0 = v;
        else if (strcmp(key, "lat0") == 0) r->lat0 = v;
        else if (strcmp(key, "dlon_deg") == 0) r->dlon = v;
        else if (strcmp(key, "dlat_deg") == 0) r->dlat = v;
    }
    return fail(msg, n, "%s.hdr: no cell_x_row", name);
}

/* Little-endian float32, assembled bytewise so the host order is moot. */
static int read_heights(FILE *f, const char *name, ts_grid *g, char *msg, size_t n)
{
    unsigned char b[4];
    for (ptrdiff_t i = 0; i < (ptrdiff_t)g->width * g->height; i++) {
        if (fread(b, 1, 4, f) != 4)
            return fail(msg, n, "%s.f32 is short", name);
        uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                     (uint32_t)b[3] << 24;
        memcpy(&g->z[i], &u, 4);
    }
    return 0;
}

int tdem_read(ts_grid *g, const char *name, double *lon, double *lat, char *msg,
              size_t msg_size)
{
    raw_header r;
    FILE *f = open_data(name, "hdr", "r", msg, msg_size);
    if (!f)
        return -1;
    int bad = read_header(f, name, &r, msg, msg_size);
    fclose(f);
    ts_error err;
    if (!bad && ts_grid_create(g, r.w, r.h, r.cell_x_row[r.h / 2], r.cell_y, &err) != TS_OK) {
        bad = fail(msg, msg_size, "%s: %s", name, err.message);
    } else if (!bad && ts_grid_set_row_spacing(g, r.cell_x_row, &err) != TS_OK) {
        ts_grid_free(g);
        bad = fail(msg, msg_size, "%s: %s", name, err.message);
    }
    free(r.cell_x_row);
    if (bad)
        return -1;
    f = open_data(name, "f32", "rb", msg, msg_size);
    if (!f || read_heights(f, name, g, msg, msg_size) != 0) {
        if (f)
            fclose(f);
        ts_grid_free(g);
        return -1;
    }
    fclose(f);
    if (lon)
        *lon = r.lon0 + r.dlon * (r.w - 1) / 2.0;
    if (lat)
        *lat = r.lat0 - r.dlat * (r.h - 1) / 2.0;
    return 0;
}
