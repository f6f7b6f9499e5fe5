/* The world beyond the DEM edge (ts_edge_mode): the sea-level horizon
 * against its closed form and a brute-force maximum, the sweep's planes in
 * each mode, the Earth's floor of the direct sun, bad modes. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "day_cycle.h"
#include "terrashade.h"
#include "test_grid.h"
#include "test_run.h"

#define RAD2DEG (180.0 / M_PI)

static ts_horizon_opts opts_edge(ts_edge_mode edge, int curvature, double max_distance)
{
    ts_horizon_opts o;
    ts_horizon_opts_default(&o);
    o.edge = edge;
    o.curvature = curvature;
    o.max_distance = max_distance;
    o.threads = 2;
    return o;
}

/* The highest sea-level point over s in [s0, s1], by a fine scan. */
static double brute_edge(double h, double s0, double s1, double c)
{
    double best = -INFINITY;
    for (int i = 0; i <= 200000; i++) {
        double s = s0 * pow(s1 / s0, i / 200000.0);
        double f = (-h - c * s * s) / s;
        best = f > best ? f : best;
    }
    return atan(best) * RAD2DEG;
}

/* The dip at 1000 m: -atan(2 sqrt(h c)), c = (1 - k) / 2R, about -0.947 deg,
 * and the Earth's horizon of the day products (-acos(R'/(R'+h))) within
 * 1e-4 deg; a scan over the sea level beyond the edge agrees. */
START_TEST(test_dip_at_1000m)
{
    ts_horizon_opts o = opts_edge(TS_EDGE_HORIZON, 1, 0);
    const double c = (1.0 - TS_DEFAULT_REFRACTION) / (2.0 * TS_EARTH_RADIUS);
    const double analytic = -atan(2.0 * sqrt(1000.0 * c)) * RAD2DEG;
    double dip = ts_edge_horizon(1000.0, 15.0, &o);
    printf("  dip at 1000 m: %.6f deg (closed form %.6f, Earth horizon %.6f)\n", dip, analytic,
           ts_earth_horizon(1000.0, &o));
    ck_assert_double_eq_tol(dip, analytic, 1e-12);
    ck_assert_double_eq_tol(dip, -0.9469, 1e-3);
    ck_assert_double_eq_tol(dip, ts_earth_horizon(1000.0, &o), 1e-4);
    ck_assert_double_eq_tol(dip, brute_edge(1000.0, 15.0, 1e7, c), 1e-6);
    /* the tangent point is sqrt(h / c) = 121 km away: an edge farther than
     * that sees the sea level at the edge itself, lower than the dip */
    double far = ts_edge_horizon(1000.0, 300e3, &o);
    ck_assert_double_eq_tol(far, atan((-1000.0 - c * 9e10) / 300e3) * RAD2DEG, 1e-12);
    ck_assert_double_eq_tol(far, brute_edge(1000.0, 300e3, 1e7, c), 1e-6);
    ck_assert(far < dip);
}
END_TEST

/* A search radius keeps only the sea level within it; past it, nothing. */
START_TEST(test_max_distance)
{
    const double c = (1.0 - TS_DEFAULT_REFRACTION) / (2.0 * TS_EARTH_RADIUS);
    ts_horizon_opts o = opts_edge(TS_EDGE_HORIZON, 1, 50e3);
    /* the tangent point (121 km) is beyond the radius: the radius's end */
    ck_assert_double_eq_tol(ts_edge_horizon(1000.0, 100.0, &o),
                            atan((-1000.0 - c * 2.5e9) / 50e3) * RAD2DEG, 1e-12);
    ck_assert_double_eq_tol(ts_edge_horizon(1000.0, 100.0, &o),
                            brute_edge(1000.0, 100.0, 50e3, c), 1e-6);
    ck_assert_double_eq(ts_edge_horizon(1000.0, 50001.0, &o), -90.0);
    ck_assert(isnan(ts_edge_horizon(NAN, 10.0, &o)));
}
END_TEST

/* At or below sea level the sea level falls away from the edge: its
 * nearest point is the highest; without curvature the sea-level plane
 * rises toward the horizontal from below. */
START_TEST(test_low_cells_and_flat_earth)
{
    const double c = (1.0 - TS_DEFAULT_REFRACTION) / (2.0 * TS_EARTH_RADIUS);
    ts_horizon_opts o = opts_edge(TS_EDGE_HORIZON, 1, 0);
    ck_assert_double_eq_tol(ts_edge_horizon(-50.0, 200.0, &o),
                            atan((50.0 - c * 4e4) / 200.0) * RAD2DEG, 1e-12);
    ck_assert(ts_edge_horizon(-50.0, 200.0, &o) > 14.0);
    ck_assert(ts_edge_horizon(0.0, 200.0, &o) < 0 && ts_edge_horizon(0.0, 200.0, &o) > -1e-3);
    ts_horizon_opts flat = opts_edge(TS_EDGE_HORIZON, 0, 0);
    ck_assert_double_eq(ts_edge_horizon(1000.0, 15.0, &flat), 0.0);
    flat.max_distance = 10e3;
    ck_assert_double_eq_tol(ts_edge_horizon(1000.0, 15.0, &flat), atan(-0.1) * RAD2DEG, 1e-12);
    ck_assert_double_eq_tol(ts_edge_horizon(-10.0, 20.0, &flat), atan(0.5) * RAD2DEG, 1e-12);
}
END_TEST

/* Distances to the edge from cell centres, along the axes and a diagonal. */
START_TEST(test_edge_distance)
{
    ts_grid g;
    tdem_create(&g, 10, 6, 30.0, 20.0);
    ck_assert_double_eq_tol(ts_edge_distance(&g, 0, 0, 270.0), 15.0, 1e-9);
    ck_assert_double_eq_tol(ts_edge_distance(&g, 0, 0, 90.0), 285.0, 1e-9);
    ck_assert_double_eq_tol(ts_edge_distance(&g, 3, 2, 0.0), 50.0, 1e-9);
    ck_assert_double_eq_tol(ts_edge_distance(&g, 3, 2, 180.0), 70.0, 1e-9);
    /* north-east from (9, 5): the east edge after 15 m of easting */
    ck_assert_double_eq_tol(ts_edge_distance(&g, 9, 5, 45.0), 15.0 * sqrt(2.0), 1e-9);
    ts_grid_free(&g);
}
END_TEST

/* The sweep's planes: open keeps -90 where nothing lies beyond a cell;
 * horizon raises every angle to the sea-level horizon beyond the edge and
 * is otherwise the open sweep; nodata is NaN within the radius. */
START_TEST(test_sweep_modes)
{
    ts_grid g;
    ts_error e;
    tdem_create(&g, 60, 45, 30.0, 30.0);
    tdem_fractal(&g, 5, 400.0);
    for (int i = 0; i < 60 * 45; i++)
        g.z[i] += 600.0f;
    g.z[7 * 60 + 9] = NAN;
    const size_t n = 60 * 45;
    float *open = tdem_floats(n), *hor = tdem_floats(n), *nod = tdem_floats(n);
    float *capped = tdem_floats(n);
    const double az[] = {0, 33.7, 90, 137, 222.2, 300};
    for (int k = 0; k < 6; k++) {
        ts_horizon_opts oo = opts_edge(TS_EDGE_OPEN, 1, 0);
        ts_horizon_opts oh = opts_edge(TS_EDGE_HORIZON, 1, 0);
        ts_horizon_opts on = opts_edge(TS_EDGE_NODATA, 1, 200.0);
        ts_horizon_opts oc = opts_edge(TS_EDGE_OPEN, 1, 200.0);
        ck_assert_int_eq(ts_horizon_sweep(&g, az[k], &oo, open, &e), TS_OK);
        ck_assert_int_eq(ts_horizon_sweep(&g, az[k], &oh, hor, &e), TS_OK);
        ck_assert_int_eq(ts_horizon_sweep(&g, az[k], &on, nod, &e), TS_OK);
        ck_assert_int_eq(ts_horizon_sweep(&g, az[k], &oc, capped, &e), TS_OK);
        int minus90 = 0, raised = 0, blank = 0;
        for (int y = 0; y < 45; y++)
            for (int x = 0; x < 60; x++) {
                size_t i = (size_t)y * 60 + x;
                float h = g.z[i];
                if (isnan(h)) {
                    ck_assert(isnan(open[i]) && isnan(hor[i]) && isnan(nod[i]));
                    continue;
                }
                double s = ts_edge_distance(&g, x, y, az[k]);
                float want = fmaxf(open[i], (float)ts_edge_horizon(h, s, &oh));
                ck_assert_float_eq(hor[i], want);
                ck_assert(hor[i] >= (float)ts_earth_horizon(h, &oh) - 1e-3f);
                minus90 += open[i] == -90.0f;
                raised += hor[i] > open[i];
                ck_assert_int_eq(isnan(nod[i]), s <= 200.0);
                if (!isnan(nod[i]))
                    ck_assert_float_eq(nod[i], capped[i]);
                blank += isnan(nod[i]);
            }
        ck_assert_int_gt(minus90, 0); /* the outward edge, open */
        ck_assert_int_ge(raised, minus90);
        ck_assert_int_gt(blank, 0);
    }
    free(open);
    free(hor);
    free(nod);
    free(capped);
    ts_grid_free(&g);
}
END_TEST

/* The direct sun's floor: the Earth's horizon of each height, only with
 * TS_EDGE_HORIZON; NaN stays NaN. */
START_TEST(test_earth_floor)
{
    ts_grid g;
    ts_error e;
    tdem_create(&g, 3, 1, 30.0, 30.0);
    g.z[0] = 1000.0f;
    g.z[1] = -20.0f;
    g.z[2] = NAN;
    float plane[3] = {-30.0f, -30.0f, NAN}, kept[3] = {-30.0f, 5.0f, NAN};
    ts_horizon_opts o = opts_edge(TS_EDGE_OPEN, 1, 0);
    ck_assert_int_eq(ts_horizon_earth_floor(&g, &o, kept, &e), TS_OK);
    ck_assert_float_eq(kept[0], -30.0f);
    o.edge = TS_EDGE_HORIZON;
    ck_assert_int_eq(ts_horizon_earth_floor(&g, &o, plane, &e), TS_OK);
    ck_assert_float_eq(plane[0], (float)ts_earth_horizon(1000.0, &o));
    ck_assert_float_eq(plane[1], 0.0f);
    ck_assert(isnan(plane[2]));
    ck_assert_int_eq(ts_horizon_earth_floor(&g, &o, kept, &e), TS_OK);
    ck_assert_float_eq(kept[1], 5.0f); /* a higher horizon stays */
    ts_grid_free(&g);
}
END_TEST

/* The sun of the shadow height map: its visibility times the disk above
 * the edge's and the Earth's horizon, as a plane of -90 raised by both. */
START_TEST(test_edge_sun)
{
    ts_grid g;
    ts_error e;
    tdem_create(&g, 30, 20, 30.0, 30.0);
    tdem_fractal(&g, 9, 300.0);
    g.z[45] = NAN;
    /* cells near sea level and below it, whose Earth's floor is within a
     * sun radius of 0 deg: suns there keep a part of the disk hidden */
    g.z[200] = 0.5f, g.z[201] = 2.0f, g.z[202] = -3.0f, g.z[203] = 0.0f;
    const size_t n = 30 * 20;
    float *vis = tdem_floats(n), *plane = tdem_floats(n);
    const ts_edge_mode modes[] = {TS_EDGE_OPEN, TS_EDGE_HORIZON, TS_EDGE_NODATA};
    /* suns below, within and above a radius (0.2666 deg) of the horizontal */
    const double suns[] = {-0.2, 0.1, 0.2, 0.25, 0.3, 1.0};
    for (int m = 0; m < 3; m++)
        for (int k = 0; k < (int)(sizeof suns / sizeof *suns); k++) {
            ts_horizon_opts o = opts_edge(modes[m], 1, m == 2 ? 100.0 : 0.0);
            for (size_t i = 0; i < n; i++) {
                vis[i] = isnan(g.z[i]) ? NAN : 0.75f;
                plane[i] = isnan(g.z[i]) ? NAN : -90.0f;
            }
            ck_assert_int_eq(ts_horizon_edge_sun(&g, 250.0, suns[k], &o, vis, &e), TS_OK);
            ck_assert_int_eq(ts_horizon_edge_apply(&g, 250.0, &o, plane, &e), TS_OK);
            ck_assert_int_eq(ts_horizon_earth_floor(&g, &o, plane, &e), TS_OK);
            int lit = 0, part = 0;
            for (size_t i = 0; i < n; i++) {
                if (isnan(plane[i])) {
                    ck_assert(isnan(vis[i]));
                    continue;
                }
                float want = modes[m] == TS_EDGE_OPEN
                                 ? 0.75f
                                 : 0.75f * (float)ts_sun_disk_fraction(suns[k], plane[i]);
                ck_assert_float_eq(vis[i], want);
                lit += vis[i] > 0;
                part += vis[i] > 0 && vis[i] < 0.75f;
            }
            /* a sun at -0.2 deg: above the dip of cells 100..400 m high */
            ck_assert_int_gt(lit, 0);
            /* at 0.1-0.25 deg the low cells see a part of the disk */
            if (modes[m] == TS_EDGE_HORIZON && suns[k] > 0 && suns[k] < 0.26)
                ck_assert_int_gt(part, 0);
        }
    ts_horizon_opts o = opts_edge(TS_EDGE_HORIZON, 1, 0);
    ck_assert_int_eq(ts_horizon_edge_sun(&g, 250.0, 91.0, &o, vis, &e), TS_ERR_ARG);
    free(vis);
    free(plane);
    ts_grid_free(&g);
}
END_TEST

/* nonpositive_moot: under a sun that clears the horizontal, the sweep's
 * plane with its EDGE raises and Earth's floor skipped where they stay
 * <= 0 deg lights every cell as the exact plane does; cells below sea
 * level keep their exact horizons; a grazing sun does not clear. */
START_TEST(test_nonpositive_moot)
{
    ts_grid g;
    tdem_create(&g, 48, 40, 30.0, 30.0);
    tdem_fractal(&g, 9, 400.0);
    ck_assert(g.stride == g.width); /* cell i is z[i] */
    size_t n = (size_t)g.width * g.height;
    float lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        lo = g.z[i] < lo ? g.z[i] : lo;
        hi = g.z[i] > hi ? g.z[i] : hi;
    }
    for (size_t i = 0; i < n; i++) /* 0 m at 30 % of the relief: some cells below */
        g.z[i] -= lo + 0.3f * (hi - lo);
    float *exact = tdem_floats(n), *moot = tdem_floats(n);
    ts_horizon_opts o = opts_edge(TS_EDGE_HORIZON, 1, 0), m = o;
    m.nonpositive_moot = 1;
    const double az = 250.0, el = 5.0;
    ck_assert(ts_light_clears_horizontal(el, 0) && ts_light_clears_horizontal(0.27, 0.2666));
    ck_assert(!ts_light_clears_horizontal(0.2, 0) && !ts_light_clears_horizontal(-3, 0));
    ts_error err;
    ck_assert_msg(ts_horizon_sweep(&g, az, &o, exact, &err) == TS_OK, "%s", err.message);
    ck_assert(ts_horizon_earth_floor(&g, &o, exact, &err) == TS_OK);
    ck_assert_msg(ts_horizon_sweep(&g, az, &m, moot, &err) == TS_OK, "%s", err.message);
    ck_assert(ts_horizon_earth_floor(&g, &m, moot, &err) == TS_OK);
    int below = 0, skipped = 0;
    for (size_t i = 0; i < n; i++) {
        ck_assert(ts_sun_disk_fraction(el, exact[i]) == ts_sun_disk_fraction(el, moot[i]));
        ck_assert(moot[i] <= exact[i] && (moot[i] == exact[i] || exact[i] <= 0));
        skipped += moot[i] != exact[i];
        if (g.z[i] < 0) {
            below++;
            ck_assert(moot[i] == exact[i] || exact[i] == 0); /* only the floor of 0 */
        }
    }
    printf("  moot: %d of %zu cells below sea level, %d horizons left lower\n", below, n,
           skipped);
    ck_assert(below > 0 && skipped > 0);
    free(exact);
    free(moot);
    ts_grid_free(&g);
}
END_TEST

START_TEST(test_bad_mode)
{
    ts_grid g;
    ts_error e;
    tdem_create(&g, 4, 4, 30.0, 30.0);
    float out[16];
    ts_horizon_opts o = opts_edge((ts_edge_mode)7, 1, 0);
    ck_assert_int_eq(ts_horizon_sweep(&g, 10.0, &o, out, &e), TS_ERR_ARG);
    ck_assert_str_eq(e.message, "the edge mode must be open, horizon or nodata, got 7");
    o.edge = TS_EDGE_HORIZON;
    ck_assert_int_eq(ts_horizon_edge_apply(&g, NAN, &o, out, &e), TS_ERR_ARG);
    ck_assert_int_eq(ts_horizon_edge_apply(&g, 10.0, &o, NULL, &e), TS_ERR_ARG);
    ts_grid_free(&g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("edge");
    TCase *t = tcase_create("edge");
    tcase_add_test(t, test_dip_at_1000m);
    tcase_add_test(t, test_max_distance);
    tcase_add_test(t, test_low_cells_and_flat_earth);
    tcase_add_test(t, test_edge_distance);
    tcase_add_test(t, test_sweep_modes);
    tcase_add_test(t, test_earth_floor);
    tcase_add_test(t, test_edge_sun);
    tcase_add_test(t, test_nonpositive_moot);
    tcase_add_test(t, test_bad_mode);
    suite_add_tcase(s, t);
    return test_run_suite_mode(s, CK_VERBOSE);
}
