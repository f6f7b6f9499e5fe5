/* Grids and buffers for the check programs (see test_grid.h). */
#include "test_grid.h"

#include <check.h>
#include <stdlib.h>

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

void tdem_load(ts_grid *g, const char *name)
{
    char msg[4200];
    ck_assert_msg(tdem_read(g, name, NULL, NULL, msg, sizeof msg) == 0, "%s", msg);
}

int tprog_log(double done, void *user)
{
    tprog *l = user;
    if (l->calls == 0)
        l->first = done;
    ck_assert_msg(done >= l->last && done <= 1.0, "progress %g after %g", done, l->last);
    l->last = done;
    return ++l->calls == l->stop_at;
}
