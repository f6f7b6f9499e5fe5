/*
 * Timonen's light table L_p (Timonen & Westerholm 2010, section 6.2,
 * eq. 7) from an environment's texels. For sector k (centred on the horizon
 * sweep's azimuth k, horizontal unit vector u_k), eq. 7 is
 *
 *   L_p(theta_n, h) = 1/pi sum L omega (cos theta_n e_z + sin theta_n e . u_k)
 *
 * over the sector's texels e above both the horizon h and the tangent plane
 * (elevation > -theta_n, the cut taken at the sector's centre as in eq. 4).
 * e . u_k keeps the cos(phi - phi_k) that eq. 5 integrates across the swath,
 * so a constant environment gives eq. 5 itself.
 *
 * The table holds L_p as its two moments, A = 1/pi sum L omega e_z and
 * B = 1/pi sum L omega e . u_k over the same texels, so that L_p =
 * cos theta_n A + sin theta_n B and a cell's |N_p| L_p = nz A + a B (a =
 * N . u_k) exactly: only the cut-offs are interpolated, not the cosine of
 * the normal (a bilinear table of L_p itself, 17 normal steps, was 0.31 %
 * from the brute-force reference of tests/check_env_light.c on average;
 * the moments, 0.21 %).
 * Since a texel is lit when its elevation exceeds max(h, -theta_n), the
 * moments depend on theta_n only through that cut: with normal_steps 0 (the
 * default) the table keeps one row per sector (no cut) and each cell takes
 * its own cut, exactly (core/cellmath/env_light.h): 0.083 % from the
 * reference at 64 directions, against 0.087 % for 65 bilinear normal steps,
 * and well under half the lighting time (bench/env_bench.c).
 *
 * A texel enters every node (i, j) with i from its tangent-plane cut up and
 * j up to its elevation: one addition at its corner, then running sums along
 * both axes, O(texels + directions * max(normal_steps, 1) * horizon_steps),
 * whatever the DEM.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "status_internal.h"
#include "terrashade_env.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)
#define TS_ENV_MAX_DIRECTIONS 65536
#define TS_ENV_MAX_STEPS 16384
#define TS_ENV_MAX_TABLE_FLOATS ((size_t)1 << 28)

void ts_env_table_opts_default(ts_env_table_opts *opts)
{
    opts->directions = 16;
    opts->start_azimuth = 0;
    opts->normal_steps = TS_ENV_DEFAULT_NORMAL_STEPS;
    opts->horizon_steps = TS_ENV_DEFAULT_HORIZON_STEPS;
    opts->ground = 0;
}

void ts_env_table_free(ts_env_table *table)
{
    if (!table)
        return;
    free(table->lp);
    table->lp = NULL;
}

double ts_env_table_azimuth(const ts_env_table *table, int k)
{
    double az = fmod(table->start_azimuth + k * 360.0 / table->directions, 360.0);
    return az < 0 ? az + 360.0 : az;
}

static ts_status check_opts(const ts_env_table_opts *o, ts_error *err)
{
    if (!o)
        return ts_fail(err, TS_ERR_ARG, "table options must not be NULL");
    if (o->directions < 1 || o->directions > TS_ENV_MAX_DIRECTIONS)
        return ts_fail(err, TS_ERR_ARG, "DIRECTIONS must be from 1 to %d, got %d",
                       TS_ENV_MAX_DIRECTIONS, o->directions);
    if (!isfinite(o->start_azimuth))
        return ts_fail(err, TS_ERR_ARG, "the start azimuth must be finite, got %g",
                       o->start_azimuth);
    /* odd counts: a node at 0 degrees, the normal and the horizon of open
     * flat ground, which else reads the mean of two nodes (a uniform sky lit
     * it as 0.5 with 2 horizon steps, 0.875 with 4) */
    if (o->normal_steps < 0 || o->normal_steps > TS_ENV_MAX_STEPS ||
        (o->normal_steps && (o->normal_steps < 3 || o->normal_steps % 2 == 0)))
        return ts_fail(err, TS_ERR_ARG, "the normal-angle steps of the light table must be "
                       "0 (exact) or odd from 3 to %d (a node at 0 degrees), got %d",
                       TS_ENV_MAX_STEPS, o->normal_steps);
    if (o->horizon_steps < 3 || o->horizon_steps > TS_ENV_MAX_STEPS || o->horizon_steps % 2 == 0)
        return ts_fail(err, TS_ERR_ARG, "the horizon-angle steps of the light table must be "
                       "odd from 3 to %d (a node at 0 degrees), got %d", TS_ENV_MAX_STEPS,
                       o->horizon_steps);
    size_t rows = o->normal_steps ? (size_t)o->normal_steps : 1;
    if (rows * o->horizon_steps * 8 > INT32_MAX ||
        (size_t)o->directions * rows * o->horizon_steps * 8 > TS_ENV_MAX_TABLE_FLOATS)
        return ts_fail(err, TS_ERR_ARG, "a light table of %d directions x %d x %d steps is too "
                       "large", o->directions, o->normal_steps, o->horizon_steps);
    if (o->ground != 0 && o->ground != 1)
        return ts_fail(err, TS_ERR_ARG, "ground must be 0 or 1, got %d", o->ground);
    return TS_OK;
}

static ts_status check_env(const ts_env *env, ts_error *err)
{
    if (!env || (env->count && !env->texels))
        return ts_fail(err, TS_ERR_ARG, "the environment must not be NULL");
    for (size_t i = 0; i < env->count; i++) {
        const ts_env_texel *t = &env->texels[i];
        double len2 = (double)t->dir[0] * t->dir[0] + (double)t->dir[1] * t->dir[1] +
                      (double)t->dir[2] * t->dir[2];
        if (!(fabs(len2 - 1) < 1e-3))
            return ts_fail(err, TS_ERR_ARG, "environment texel %zu has no unit direction", i);
        if (!(t->solid_angle >= 0 && t->solid_angle <= 4 * M_PI))
            return ts_fail(err, TS_ERR_ARG, "environment texel %zu has a solid angle of %g sr",
                           i, (double)t->solid_angle);
        for (int c = 0; c < 3; c++)
            if (!(t->rgb[c] >= 0 && isfinite(t->rgb[c])))
                return ts_fail(err, TS_ERR_ARG, "environment texel %zu has radiance %g: it must "
                               "be finite and >= 0", i, (double)t->rgb[c]);
    }
    return TS_OK;
}

/* Adds every lit texel's moments at its corner hist[k][i0][jtop]: jtop the
 * highest horizon node strictly below it, i0 the lowest normal node whose
 * tangent plane lets it through (0 in the exact form, with one row: there
 * the cut is the cell's). */
static void bin_texels(const ts_env *env, const ts_env_table_opts *o, double *hist)
{
    const int D = o->directions, NH = o->horizon_steps;
    const int NN = o->normal_steps ? o->normal_steps : 1;
    const double sector = 360.0 / D, dh = 180.0 / (NH - 1);
    const double dn = o->normal_steps ? 180.0 / (NN - 1) : INFINITY;
    for (size_t t = 0; t < env->count; t++) {
        const ts_env_texel *x = &env->texels[t];
        if ((x->rgb[0] == 0 && x->rgb[1] == 0 && x->rgb[2] == 0) || x->solid_angle == 0)
            continue;
        double ex = x->dir[0], ey = x->dir[1], ez = x->dir[2];
        double len = sqrt(ex * ex + ey * ey + ez * ez);
        ex /= len, ey /= len, ez /= len;
        if (!o->ground && ez <= 0)
            continue;
        double elev = asin(ez > 1 ? 1 : ez) * RAD2DEG;
        double az = atan2(ex, ey) * RAD2DEG; /* clockwise from north */
        long k = lround(floor((az - o->start_azimuth) / sector + 0.5));
        k %= D;
        k = k < 0 ? k + D : k;
        double azk = (o->start_azimuth + k * sector) * DEG2RAD;
        double horiz = ex * sin(azk) + ey * cos(azk); /* e . u_k */
        int jtop = (int)ceil((elev + 90) / dh) - 1;
        jtop = jtop > NH - 1 ? NH - 1 : jtop;
        int i0 = o->normal_steps ? (int)floor((90 - elev) / dn) + 1 : 0;
        i0 = i0 < 0 ? 0 : i0;
        if (jtop < 0 || i0 > NN - 1)
            continue; /* below every horizon node, or behind every tangent plane */
        double w = x->solid_angle / M_PI;
        double *h = hist + (((size_t)k * NN + i0) * NH + jtop) * 8;
        for (int c = 0; c < 3; c++) {
            h[c] += w * ez * x->rgb[c];
            h[4 + c] += w * horiz * x->rgb[c];
        }
    }
}

ts_status ts_env_table_build(const ts_env *env, const ts_env_table_opts *opts,
                             ts_env_table *table, ts_error *err)
{
    if (!table)
        return ts_fail(err, TS_ERR_ARG, "the light table must not be NULL");
    table->lp = NULL;
    ts_status st = check_opts(opts, err);
    if (st == TS_OK)
        st = check_env(env, err);
    if (st != TS_OK)
        return st;
    const int NN = opts->normal_steps ? opts->normal_steps : 1, NH = opts->horizon_steps;
    const size_t n = (size_t)opts->directions * NN * NH * 8;
    double *hist = calloc(n, sizeof *hist);
    float *lp = malloc(n * sizeof *lp);
    if (!hist || !lp) {
        free(hist), free(lp);
        return ts_fail(err, TS_ERR_NOMEM, "no memory for a light table of %zu floats", n);
    }
    bin_texels(env, opts, hist);
    /* Node j holds every texel above it: running sums from the zenith down;
     * node i every texel its tangent plane lets through: running sums up. */
    for (int k = 0; k < opts->directions; k++)
        for (int i = 0; i < NN; i++) {
            double *row = hist + ((size_t)k * NN + i) * NH * 8;
            for (int j = NH - 2; j >= 0; j--)
                for (int c = 0; c < 8; c++)
                    row[j * 8 + c] += row[(j + 1) * 8 + c];
            if (i > 0)
                for (size_t m = 0; m < (size_t)NH * 8; m++)
                    row[m] += row[m - (size_t)NH * 8];
        }
    for (size_t m = 0; m < n; m++)
        lp[m] = (float)hist[m];
    free(hist);
    table->directions = opts->directions;
    table->start_azimuth = opts->start_azimuth;
    table->normal_steps = opts->normal_steps;
    table->horizon_steps = NH;
    table->lp = lp;
    return ts_ok(err);
}
