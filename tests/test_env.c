/* Helpers for the environment-map tests (test_env.h). */
#include "test_env.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

double tenv_total_solid_angle(const ts_env *e)
{
    double s = 0.0;
    for (size_t i = 0; i < e->count; i++)
        s += e->texels[i].solid_angle;
    return s;
}

void tenv_irradiance(const ts_env *e, const double n[3], double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (size_t i = 0; i < e->count; i++) {
        const ts_env_texel *t = &e->texels[i];
        double c = n[0] * t->dir[0] + n[1] * t->dir[1] + n[2] * t->dir[2];
        if (c > 0.0)
            for (int k = 0; k < 3; k++)
                out[k] += t->rgb[k] * c * t->solid_angle;
    }
}

void tenv_power(const ts_env *e, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (size_t i = 0; i < e->count; i++)
        for (int k = 0; k < 3; k++)
            out[k] += (double)e->texels[i].rgb[k] * e->texels[i].solid_angle;
}

size_t tenv_brightest(const ts_env *e)
{
    size_t best = 0;
    double v = -1.0;
    for (size_t i = 0; i < e->count; i++) {
        const float *c = e->texels[i].rgb;
        if (c[0] + c[1] + c[2] > v)
            v = c[0] + c[1] + c[2], best = i;
    }
    return best;
}

float *tenv_constant(size_t n_pixels, float v)
{
    float *p = malloc(n_pixels * 3 * sizeof *p);
    for (size_t i = 0; i < n_pixels * 3; i++)
        p[i] = v;
    return p;
}

static double uniform(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return ((*seed >> 8) & 0xffffff) / 16777216.0;
}

float *tenv_random_image(int w, int h, unsigned seed)
{
    float *p = malloc((size_t)w * h * 3 * sizeof *p);
    for (size_t i = 0; i < (size_t)w * h * 3; i++)
        p[i] = (float)floor(uniform(&seed) * 640.0) / 64.0f;
    return p;
}

void tenv_random_direction(unsigned *seed, double d[3])
{
    double z = 2.0 * uniform(seed) - 1.0, a = 2.0 * M_PI * uniform(seed);
    double r = sqrt(1.0 - z * z);
    d[0] = r * cos(a), d[1] = r * sin(a), d[2] = z;
}

void tenv_fibonacci_direction(int k, int n, double d[3])
{
    double z = 1.0 - (2.0 * k + 1.0) / n, a = k * M_PI * (3.0 - sqrt(5.0));
    double r = sqrt(1.0 - z * z);
    d[0] = r * cos(a), d[1] = r * sin(a), d[2] = z;
}

void tenv_cube_pixel_of(const double d[3], int sof, int *x, int *y)
{
    double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]), px, py;
    int face;
    double m = sof - 1;
    if (ax >= ay && ax >= az) {
        px = (d[1] / ax + 1) / 2 * m, py = (d[2] / ax + 1) / 2 * m;
        face = d[0] > 0 ? 0 : 1;
    } else if (ay >= az) {
        px = (d[0] / ay + 1) / 2 * m, py = (d[2] / ay + 1) / 2 * m;
        face = d[1] > 0 ? 2 : 3;
    } else {
        px = (d[0] / az + 1) / 2 * m, py = (d[1] / az + 1) / 2 * m;
        face = d[2] > 0 ? 4 : 5;
    }
    double minx = 0, maxx = m, miny = face * sof, maxy = miny + m, fx, fy;
    switch (face) {
    case 0: fx = minx + py, fy = maxy - px; break;
    case 1: fx = maxx - py, fy = maxy - px; break;
    case 2: fx = minx + px, fy = maxy - py; break;
    case 3: fx = minx + px, fy = miny + py; break;
    case 4: fx = maxx - px, fy = maxy - py; break;
    default: fx = minx + px, fy = maxy - py; break;
    }
    *x = (int)floor(fx + 0.5);
    *y = (int)floor(fy + 0.5);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double tenv_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static char tmp_dir[64];

void tenv_tmp_begin(void)
{
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/check_env_map_XXXXXX");
    if (!mkdtemp(tmp_dir)) {
        perror("mkdtemp");
        exit(EXIT_FAILURE);
    }
}

const char *tenv_tmp(const char *name)
{
    static char paths[8][256];
    static int next;
    char *p = paths[next++ % 8];
    if (snprintf(p, 256, "%s/%s", tmp_dir, name) >= 256) {
        fprintf(stderr, "tenv_tmp: name too long: %s\n", name);
        abort();
    }
    return p;
}

void tenv_tmp_end(void)
{
    DIR *d = opendir(tmp_dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            unlink(tenv_tmp(e->d_name));
    if (d)
        closedir(d);
    rmdir(tmp_dir);
}
