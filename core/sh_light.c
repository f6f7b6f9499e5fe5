/*
 * Shading from SH visibility (Snyder & Nowrouzezahrai 2008, section 5): the
 * triple product of the light, the cell's visibility vector and the clamped
 * cosine around its normal (the light's product matrix folded with the
 * clamped cosine's zonal coefficients once, so a cell costs the 16 basis
 * values of its normal and 272 multiply-adds); the double product of light
 * and visibility for a key light's visible share; a key light's
 * normalisers (a swath's light in one pass: core/sh_swath_light.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "parallel.h"
#include "sh_internal.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)

void ts_sh_swath_visibility_flat(const ts_sh_swath *s, double omega_deg,
                                 double out[TS_SH_COEFFS])
{
    double v[TS_SH_COEFFS];
    memset(out, 0, sizeof(double) * TS_SH_COEFFS);
    /* canonical starts (terrashade_sh.h, core/sh_visibility.c): each wedge at
     * the later of its two azimuths, clockwise */
    for (int k = 0; k < s->n; k++) {
        if (k == 0 && !s->complete)
            continue;
        ts_sh_wedge_project(s->step, omega_deg, omega_deg, v);
        ts_sh_rotate_z(v, (90.0 - ts_sh_swath_azimuth(s, k)) * DEG2RAD, v);
        for (int i = 0; i < TS_SH_COEFFS; i++)
            out[i] += v[i];
    }
    if (s->complete)
        return;
    ts_sh_wedge_project(s->step / 2, omega_deg, 90, v);
    ts_sh_rotate_z(v, (90.0 - ts_sh_swath_azimuth(s, 0)) * DEG2RAD, v);
    for (int i = 0; i < TS_SH_COEFFS; i++)
        out[i] += v[i];
    ts_sh_wedge_project(s->step / 2, 90, omega_deg, v);
    ts_sh_rotate_z(v, (90.0 - ts_sh_swath_azimuth(s, s->n - 1) - s->step / 2) * DEG2RAD, v);
    for (int i = 0; i < TS_SH_COEFFS; i++)
        out[i] += v[i];
}

void ts_sh_fold_cosine(const double m[TS_SH_COEFFS][TS_SH_COEFFS],
                        float mh[TS_SH_COEFFS][TS_SH_COEFFS])
{
    for (int k = 0; k < TS_SH_COEFFS; k++) {
        int l = k < 1 ? 0 : k < 4 ? 1 : k < 9 ? 2 : 3;
        double f = sqrt(4 * M_PI / (2 * l + 1)) * TS_SH_CLAMPED_COS_ZH[l];
        for (int j = 0; j < TS_SH_COEFFS; j++)
            mh[j][k] = (float)(m[j][k] * f);
    }
}

/* The triple product of visibility v (16 floats) with the folded matrix and
 * the normal (x, y, z), in float (ts_sh_triple_folded). */
static inline double cell_triple(const float mh[TS_SH_COEFFS][TS_SH_COEFFS], const float *v,
                                 float x, float y, float z)
{
    float yn[TS_SH_COEFFS];
    TS_SH_BASIS(float, x, y, z, yn);
    return ts_sh_triple_folded(mh, v, yn);
}

typedef struct {
    const ts_grid *g;
    float mh[TS_SH_COEFFS][TS_SH_COEFFS]; /* m with the clamped cosine's zonal factors */
    const float *nx, *ny, *nz, *vis;
    const double *l;
    double scale;
    float *out;
} shade_ctx;

static void shade_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const shade_ctx *C = ctx;
    const size_t W = (size_t)C->g->width;
    for (size_t c = (size_t)y0 * W; c < (size_t)y1 * W; c++) {
        double s = C->scale * cell_triple(C->mh, C->vis + c * TS_SH_COEFFS, C->nx[c],
                                          C->ny[c], C->nz[c]);
        C->out[c] = s == s ? (float)(s > 0 ? s : 0) : NAN;
    }
}

static ts_status check_planes(const ts_grid *grid, const float *vis, const float *out,
                              ts_error *err)
{
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!vis || !out)
        return ts_fail(err, TS_ERR_ARG, "the visibility and the output must not be NULL");
    return TS_OK;
}

ts_status ts_sh_shade(const ts_grid *grid, const double m[TS_SH_COEFFS][TS_SH_COEFFS],
                      const float *nx, const float *ny, const float *nz, const float *vis,
                      double scale, int threads, float *out, ts_error *err)
{
    ts_status st = check_planes(grid, vis, out, err);
    if (st != TS_OK)
        return st;
    if (!m || !nx || !ny || !nz)
        return ts_fail(err, TS_ERR_ARG, "the light and the normals must not be NULL");
    shade_ctx C = {grid, {{0}}, nx, ny, nz, vis, NULL, scale, out};
    ts_sh_fold_cosine(m, C.mh);
    return ts_parallel_for_ranges(ts_thread_count(threads, grid->height), grid->height,
                                  TS_ROWS_GRAIN, shade_rows, &C, err);
}

static void share_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const shade_ctx *C = ctx;
    const size_t W = (size_t)C->g->width;
    for (size_t c = (size_t)y0 * W; c < (size_t)y1 * W; c++) {
        double s = 0;
        for (int i = 0; i < TS_SH_COEFFS; i++)
            s += C->l[i] * C->vis[c * TS_SH_COEFFS + i];
        s *= C->scale;
        C->out[c] = s == s ? (float)(s < 0 ? 0 : s > 1 ? 1 : s) : NAN;
    }
}

ts_status ts_sh_visible_share(const ts_grid *grid, const double l[TS_SH_COEFFS],
                              const float *vis, double scale, int threads, float *out,
                              ts_error *err)
{
    ts_status st = check_planes(grid, vis, out, err);
    if (st != TS_OK)
        return st;
    if (!l)
        return ts_fail(err, TS_ERR_ARG, "the light must not be NULL");
    shade_ctx C = {grid, {{0}}, NULL, NULL, NULL, vis, l, scale, out};
    return ts_parallel_for_ranges(ts_thread_count(threads, grid->height), grid->height,
                                  TS_ROWS_GRAIN, share_rows, &C, err);
}

void ts_sh_key_reference(const ts_sh_wedges *w, const double l[TS_SH_COEFFS],
                         double azimuth, double elevation, double *shade_ref,
                         double *share_ref)
{
    double v[TS_SH_COEFFS], h[TS_SH_COEFFS], m[TS_SH_COEFFS][TS_SH_COEFFS];
    (void)azimuth; /* the swath and the light hold it */
    double e = elevation * DEG2RAD, up[3] = {0, 0, 1};
    ts_sh_swath_visibility_flat(&w->swath, 0, v);
    ts_sh_clamped_cosine(up, h);
    ts_sh_product_matrix(l, m);
    /* open flat ground's SH value over its exact max(0, N . L) = sin e */
    *shade_ref = sin(e) > 0 ? ts_sh_triple(m, v, h) / sin(e) : 0;
    double s = 0;
    for (int i = 0; i < TS_SH_COEFFS; i++)
        s += l[i] * v[i];
    *share_ref = s;
}
