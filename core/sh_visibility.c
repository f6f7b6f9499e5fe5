/*
 * SH visibility from horizons (Snyder & Nowrouzezahrai 2008, section 5,
 * eq. 6-8): between consecutive sampled azimuths the horizon is linear in
 * azimuth; each such wedge's visibility is read from a table precomputed in
 * canonical position (256 x 256 horizon pairs, bilinear), turned to its
 * azimuth about z and summed; a partial swath adds a boundary wedge at each
 * end (a 1D table) whose horizon rises to fully blocked at the swath's edge.
 */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "parallel.h"
#include "sh_internal.h"
#include "simd_clones.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define NQ 12            /* Gauss nodes per axis and piece */
#define PIECE_DEG 90.0   /* the azimuth axis is cut in pieces at most this wide */
#define N_STEPS TS_SH_WEDGE_STEPS

static double clamp_omega(double w)
{
    return w < 0 ? 0 : w > 90 ? 90 : w;
}

/*
 * A basis function is A_i(theta) B_i(phi), B_i = 1, cos(m phi) or sin(|m| phi),
 * so a wedge's coefficient is the integral over phi of B_i(phi) Q_i(omega(phi)),
 * Q_i(omega) = integral from omega to pi/2 of A_i(theta) cos(theta) d theta: Q
 * is tabulated once (Gauss, exact for these trigonometric polynomials to
 * rounding) with its derivative -A_i(omega) cos(omega), and read by cubic
 * Hermite interpolation (error below 1e-8 at QN nodes). The table (66 KB)
 * depends on nothing, so it is built once per process and shared: on the
 * stack it took METHOD=sh past a 96 KB stack (ulimit -s, a host's thread).
 */
#define QN 257

typedef struct {
    double q[QN][TS_SH_COEFFS], dq[QN][TS_SH_COEFFS];
} q_table;

/* m of coefficient i. */
static int coeff_m(int i)
{
    int l = i < 1 ? 0 : i < 4 ? 1 : i < 9 ? 2 : 3;
    return i - l * (l + 1);
}

/* A_i(theta) for every i: y_i where its B_i is 1 (phi = 0 for m >= 0,
 * pi / 2|m| for m < 0). */
static void theta_part(double theta, double a[TS_SH_COEFFS])
{
    double y[TS_SH_COEFFS], ct = cos(theta), st = sin(theta);
    for (int m = 0; m <= 3; m++) {
        double phi = m == 0 ? 0 : M_PI / (2 * m), d[3] = {cos(phi) * ct, sin(phi) * ct, st};
        ts_sh_eval(d, y);
        for (int i = 0; i < TS_SH_COEFFS; i++)
            if ((m == 0 && coeff_m(i) >= 0) || coeff_m(i) == -m)
                a[i] = y[i];
    }
}

static q_table q_shared;
static pthread_once_t q_once = PTHREAD_ONCE_INIT;

static void q_build(void)
{
    q_table *t = &q_shared;
    double gx[NQ], gw[NQ], a[TS_SH_COEFFS];
    ts_sh_gauss(NQ, gx, gw);
    for (int n = 0; n < QN; n++) {
        double omega = M_PI / 2 * n / (QN - 1), half = (M_PI / 2 - omega) / 2;
        memset(t->q[n], 0, sizeof t->q[n]);
        for (int j = 0; j < NQ; j++) {
            double theta = omega + half * (gx[j] + 1);
            theta_part(theta, a);
            for (int i = 0; i < TS_SH_COEFFS; i++)
                t->q[n][i] += gw[j] * half * cos(theta) * a[i];
        }
        theta_part(omega, a);
        for (int i = 0; i < TS_SH_COEFFS; i++)
            t->dq[n][i] = -a[i] * cos(omega);
    }
}

static const q_table *q_get(void)
{
    pthread_once(&q_once, q_build);
    return &q_shared;
}

static void q_eval(const q_table *t, double omega, double out[TS_SH_COEFFS])
{
    const double h = M_PI / 2 / (QN - 1);
    double x = omega / h;
    int n = (int)x;
    if (n >= QN - 1)
        n = QN - 2;
    if (n < 0)
        n = 0;
    double u = x - n, u2 = u * u, u3 = u2 * u;
    double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2,
           h11 = u3 - u2;
    for (int i = 0; i < TS_SH_COEFFS; i++)
        out[i] = h00 * t->q[n][i] + h10 * h * t->dq[n][i] + h01 * t->q[n + 1][i] +
                 h11 * h * t->dq[n + 1][i];
}

/* The azimuth axis's nodes of one extent: phi / extent, weight, B_i(phi). */
#define MAX_PHI_NODES (NQ * 4) /* at most 4 pieces of PIECE_DEG */

typedef struct {
    int count;
    double t[MAX_PHI_NODES], w[MAX_PHI_NODES], b[MAX_PHI_NODES][TS_SH_COEFFS];
} phi_nodes;

static void phi_nodes_build(double extent_deg, phi_nodes *n)
{
    double gx[NQ], gw[NQ];
    ts_sh_gauss(NQ, gx, gw);
    const double ext = extent_deg * DEG2RAD;
    const int pieces = (int)ceil(extent_deg / PIECE_DEG);
    const double plen = ext / pieces;
    n->count = 0;
    for (int p = 0; p < pieces; p++)
        for (int j = 0; j < NQ; j++, n->count++) {
            double phi = plen * (p + (gx[j] + 1) / 2);
            n->t[n->count] = phi / ext;
            n->w[n->count] = gw[j] * plen / 2;
            for (int i = 0; i < TS_SH_COEFFS; i++) {
                int m = coeff_m(i);
                n->b[n->count][i] = m == 0 ? 1 : m > 0 ? cos(m * phi) : sin(-m * phi);
            }
        }
}

static void wedge_from_q(const q_table *t, const phi_nodes *n, double omega_a, double omega_b,
                         double out[TS_SH_COEFFS])
{
    double q[TS_SH_COEFFS];
    memset(out, 0, sizeof(double) * TS_SH_COEFFS);
    const double wa = clamp_omega(omega_a) * DEG2RAD, wb = clamp_omega(omega_b) * DEG2RAD;
    for (int j = 0; j < n->count; j++) {
        q_eval(t, wa + (wb - wa) * n->t[j], q);
        for (int i = 0; i < TS_SH_COEFFS; i++)
            out[i] += n->w[j] * q[i] * n->b[j][i];
    }
}

void ts_sh_wedge_project(double extent_deg, double omega_a, double omega_b,
                         double out[TS_SH_COEFFS])
{
    phi_nodes n;
    phi_nodes_build(extent_deg, &n);
    wedge_from_q(q_get(), &n, omega_a, omega_b, out);
}

static double node_omega(int a)
{
    return 90.0 * a / (N_STEPS - 1);
}

typedef struct {
    const ts_sh_swath *s;
    ts_sh_wedges *w;
} build_ctx;

static void build_rows(void *ctx, int worker, long a0, long a1)
{
    (void)worker;
    const build_ctx *C = ctx;
    double v[TS_SH_COEFFS];
    const q_table *t = q_get();
    phi_nodes whole, half;
    phi_nodes_build(C->s->step, &whole);
    phi_nodes_build(C->s->step / 2, &half);
    for (long a = a0; a < a1; a++) {
        for (int b = 0; b < N_STEPS; b++) {
            wedge_from_q(t, &whole, node_omega((int)a), node_omega(b), v);
            for (int k = 0; k < TS_SH_COEFFS; k++)
                C->w->interior[((size_t)a * N_STEPS + b) * TS_SH_COEFFS + k] = (float)v[k];
        }
        if (!C->w->rise)
            continue;
        wedge_from_q(t, &half, node_omega((int)a), 90, v);
        for (int k = 0; k < TS_SH_COEFFS; k++)
            C->w->rise[a * TS_SH_COEFFS + k] = (float)v[k];
        wedge_from_q(t, &half, 90, node_omega((int)a), v);
        for (int k = 0; k < TS_SH_COEFFS; k++)
            C->w->fall[a * TS_SH_COEFFS + k] = (float)v[k];
    }
}

ts_status ts_sh_wedges_build(const ts_sh_swath *s, int threads, ts_sh_wedges *w,
                             ts_error *err)
{
    if (!w)
        return ts_fail(err, TS_ERR_ARG, "the wedge tables must not be NULL");
    memset(w, 0, sizeof *w);
    if (!s || s->n < 1 || !(s->step > 0) || !(s->span <= 360))
        return ts_fail(err, TS_ERR_ARG, "the swath must have at least one azimuth and an "
                       "extent of at most 360 degrees");
    w->swath = *s;
    w->threads = threads;
    /* each node's 16 floats on one 64-byte cache line, as the folded tables
     * (core/sh_swath_light.c): malloc's 16-byte alignment splits every read */
    w->interior = aligned_alloc(64, sizeof(float) * N_STEPS * N_STEPS * TS_SH_COEFFS);
    if (!s->complete) {
        w->rise = aligned_alloc(64, sizeof(float) * N_STEPS * TS_SH_COEFFS);
        w->fall = aligned_alloc(64, sizeof(float) * N_STEPS * TS_SH_COEFFS);
    }
    if (!w->interior || (!s->complete && (!w->rise || !w->fall))) {
        ts_sh_wedges_free(w);
        return ts_fail(err, TS_ERR_NOMEM, "out of memory for the SH wedge tables");
    }
    build_ctx C = {s, w};
    ts_status st = ts_parallel_for(ts_thread_count(threads, N_STEPS), N_STEPS, build_rows, &C,
                                   err);
    if (st != TS_OK)
        ts_sh_wedges_free(w);
    return st;
}

void ts_sh_wedges_free(ts_sh_wedges *w)
{
    if (!w)
        return;
    free(w->interior);
    free(w->rise);
    free(w->fall);
    w->interior = w->rise = w->fall = NULL;
}

/* One wedge added to every cell: horizons from plane a (NULL = 90 deg) to
 * plane b (NULL = 90), canonical start turned by `angle`. */
typedef struct {
    const ts_sh_visibility *v;
    const float *a, *b;
    const float *table; /* interior, rise (b NULL) or fall (a NULL) */
    ts_sh_rotation rot;
} wedge_ctx;

/* Cells c0..c1 of one wedge (cloned for wider vectors where the CPU has
 * them). */
TS_SIMD_CLONES
static void wedge_cells(const wedge_ctx *C, size_t c0, size_t c1)
{
    const int kind = C->a && C->b ? 2 : C->a ? 0 : 1;
    for (size_t c = c0; c < c1; c++)
        ts_sh_cell_wedge(C->table, kind, C->a ? C->a[c] : 90.0f, C->b ? C->b[c] : 90.0f,
                         &C->rot, C->v->vis + c * TS_SH_COEFFS);
}

static void wedge_rows(void *ctx, int worker, long y0, long y1)
{
    (void)worker;
    const wedge_ctx *C = ctx;
    const size_t W = (size_t)C->v->grid->width;
    wedge_cells(C, (size_t)y0 * W, (size_t)y1 * W);
}

/* Add the wedge whose canonical start lies at azimuth `az_start` (its
 * phi = 90 - az_start), horizons a (at the start) and b. */
static ts_status add_wedge(const ts_sh_visibility *v, const float *table, double az_start,
                           const float *a, const float *b, ts_error *err)
{
    wedge_ctx C = {v, a, b, table, {{0}, {0}}};
    ts_sh_rotation_set(&C.rot, az_start);
    return ts_parallel_for_ranges(ts_thread_count(v->w->threads, v->grid->height),
                                  v->grid->height, TS_ROWS_GRAIN, wedge_rows, &C, err);
}

ts_status ts_sh_visibility_init(ts_sh_visibility *v, const ts_grid *grid,
                                const ts_sh_wedges *w, ts_error *err)
{
    if (!v)
        return ts_fail(err, TS_ERR_ARG, "the visibility must not be NULL");
    memset(v, 0, sizeof *v);
    ts_status st = ts_grid_validate(grid, err);
    if (st != TS_OK)
        return st;
    if (!w || !w->interior)
        return ts_fail(err, TS_ERR_ARG, "the wedge tables were not built");
    size_t cells = (size_t)grid->width * grid->height;
    v->w = w;
    v->grid = grid;
    v->vis = calloc(cells * TS_SH_COEFFS, sizeof(float));
    v->first = malloc(cells * sizeof(float));
    v->prev = malloc(cells * sizeof(float));
    if (!v->vis || !v->first || !v->prev) {
        ts_sh_visibility_free(v);
        return ts_fail(err, TS_ERR_NOMEM, "out of memory for the SH visibility (%zu floats "
                       "a cell)", (size_t)TS_SH_COEFFS + 2);
    }
    return ts_ok(err);
}

ts_status ts_sh_visibility_add(ts_sh_visibility *v, int k, const float *plane, ts_error *err)
{
    if (!v || !v->vis || !plane)
        return ts_fail(err, TS_ERR_ARG, "the visibility and the horizon plane must not be NULL");
    const ts_sh_swath *s = &v->w->swath;
    if (k != v->next || k >= s->n)
        return ts_fail(err, TS_ERR_ARG, "horizon plane %d given, plane %d of %d expected", k,
                       v->next, s->n);
    size_t cells = (size_t)v->grid->width * v->grid->height;
    ts_status st = TS_OK;
    double az = ts_sh_swath_azimuth(s, k);
    if (k > 0) /* from sample k - 1 clockwise to k: canonical start at k */
        st = add_wedge(v, v->w->interior, az, plane, v->prev, err);
    else if (!s->complete) /* the swath's edge, blocked, to sample 0 */
        st = add_wedge(v, v->w->rise, az, plane, NULL, err);
    if (k == 0 && s->complete)
        memcpy(v->first, plane, cells * sizeof(float));
    memcpy(v->prev, plane, cells * sizeof(float));
    v->next = k + 1;
    return st == TS_OK ? ts_ok(err) : st;
}

ts_status ts_sh_visibility_finish(ts_sh_visibility *v, ts_error *err)
{
    if (!v || !v->vis)
        return ts_fail(err, TS_ERR_ARG, "the visibility must not be NULL");
    const ts_sh_swath *s = &v->w->swath;
    if (v->next != s->n)
        return ts_fail(err, TS_ERR_ARG, "%d of the swath's %d horizon planes were added",
                       v->next, s->n);
    if (s->complete) /* the last sample clockwise to the first */
        return add_wedge(v, v->w->interior, ts_sh_swath_azimuth(s, 0), v->first, v->prev,
                         err);
    /* the last sample to the swath's edge, blocked */
    double edge = ts_sh_swath_azimuth(s, s->n - 1) + s->step / 2;
    return add_wedge(v, v->w->fall, edge, NULL, v->prev, err);
}

void ts_sh_visibility_free(ts_sh_visibility *v)
{
    if (!v)
        return;
    free(v->vis);
    free(v->first);
    free(v->prev);
    v->vis = v->first = v->prev = NULL;
}
