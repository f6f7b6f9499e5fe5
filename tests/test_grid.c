/* Grids and buffers for the check programs (see test_grid.h). */
#include "test_grid.h"

#include <check.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef TS_TEST_DATA
#define TS_TEST_DATA "tests/data"
#endif

void tdem_create(ts_grid *g, int width, int height, double cell_x,
                 double cell_y)
{
    ts_error err;
    ts_status st = ts_grid_create(g, width, height, cell_x, cell_y, &err);
    ck_assert_msg(st == TS_OK, "ts_grid_create(%d, %d): %s", width, height,
                  err.message);
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
