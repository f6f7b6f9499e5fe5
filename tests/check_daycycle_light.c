/* Light over a day on terrain (core/day_cycle.h): shadows that cut the
 * hours of sun, the grid azimuth of true north turning the sweeps, the
 * clear-sky model (ESRA) and the insolation of flat ground, of a lattice
 * of sites and of slopes. The dates, sampling times and day lengths are in
 * check_daycycle.c. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "test_daycycle.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"
#include "test_site.h"

/* ------------------------------------------------------------ shadows */


/* A north-south ridge 150 m above the plain: cells just west of it lose
 * the morning sun, cells just east the evening sun, cells far from it
 * little; a deep pit gets none. */
START_TEST(test_shadows_cut_sun_hours)
{
    ts_error err;
    const int n = 64;
    ts_grid g;
    flat(&g, n, 30.0, 500.0f);
    for (int y = 0; y < n; y++)
        for (int x = 40; x < 44; x++)
            g.z[y * n + x] = 650.0f; /* ridge, columns 40..43 */
    for (int y = 10; y < 14; y++)
        for (int x = 10; x < 14; x++)
            g.z[y * n + x] = -2000.0f; /* deep 4 x 4 pit, 120 m wide */
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    float *h = malloc(n * n * sizeof *h);
    double start = ts_local_midnight(2026, 6, 21, 120);
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, h, &err) == TS_OK);
    double far = h[32 * n + 2], west = h[32 * n + 38], east = h[32 * n + 45],
           crest = h[32 * n + 41], pit = h[11 * n + 11];
    printf("ridge: 1140 m west %.3f h, just west %.3f h, crest %.3f h, just east %.3f h, "
           "pit %.3f h\n", far, west, crest, east, pit);
    ck_assert(far > 14.5);
    ck_assert(west < far - 5.0 && east < far - 5.0);
    ck_assert(crest >= far);
    ck_assert(pit == 0.0f);
    /* Weighting by the disk fraction never gives more, and gives less
     * where the disk is cut by the ridge or the plane's own horizon. */
    float *f = malloc(n * n * sizeof *f);
    o.sun_hours_rule = TS_SUN_HOURS_DISK_FRACTION;
    ck_assert(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, f, &err) == TS_OK);
    double less = 0;
    for (int i = 0; i < n * n; i++) {
        ck_assert_msg(f[i] <= h[i] + 1e-5f, "cell %d: fraction %g h > visible %g h", i,
                      f[i], h[i]);
        less = fmax(less, h[i] - f[i]);
    }
    printf("ridge: disk-fraction hours at most %.3f h below visible hours\n", less);
    ck_assert(f[32 * n + 2] < far);
    ck_assert(f[11 * n + 11] == 0.0f);
    o.sun_hours_rule = (ts_sun_hours_rule)7;
    EXPECT_ARG(ts_sun_hours(&g, &p.s, &o, start, 86400, 300, f, &err), &err);
    ck_assert(strstr(err.message, "sun-hours rule"));
    free(f);
    free(h);
    ts_grid_free(&g);
}
END_TEST

/* The grid azimuth of true north turns the sweeps: a short wall due (grid)
 * north of a cell leaves it in the 07:00 sun (azimuth ~68) when grid north
 * is true north, and shades it when true north lies at grid azimuth -90
 * (the sun then comes from grid azimuth ~338). */
START_TEST(test_grid_north)
{
    ts_error err;
    const int n = 32;
    ts_grid g;
    flat(&g, n, 30.0, 0.0f);
    for (int x = 12; x <= 20; x++)
        g.z[3 * n + x] = 300.0f; /* a wall on row 3, north of cell (16, 8) */
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    double t;
    ck_assert(ts_parse_iso8601("2026-06-21T07:00:00+02:00", &t, NULL, &err) == TS_OK);
    float vis[n * n], az[n * n], el[n * n];
    ts_sun_sample ref;
    ck_assert(ts_sun_visibility(&g, &p.s, &o, t, vis, az, el, &ref, &err) == TS_OK);
    printf("07:00 at Bern: sun at azimuth %.2f, elevation %.2f\n", ref.azimuth,
           ref.elevation);
    ck_assert(ref.azimuth > 60 && ref.azimuth < 80 && ref.elevation > 10);
    ck_assert(vis[8 * n + 16] == 1.0f); /* the wall is north: lit */
    p.north = -90.0;                    /* true east is grid north */
    ck_assert(ts_sun_visibility(&g, &p.s, &o, t, vis, az, el, &ref, &err) == TS_OK);
    CK_NEAR(ref.grid_azimuth, ref.azimuth - 90.0 + (ref.azimuth < 90 ? 360 : 0), 1e-9,
            "grid azimuth");
    CK_NEAR(az[0], ref.grid_azimuth, 1e-4, "cell azimuth");
    ck_assert(vis[8 * n + 16] == 0.0f); /* the sun now comes over the wall */
    ts_grid_free(&g);
}
END_TEST

/* ------------------------------------------------------------ clear sky */

START_TEST(test_esra)
{
    ts_clear_sky c;
    /* Sun at the zenith, sea level, TL = 3, mean distance: m ~ 1,
     * 1/dR = 6.6296 + 1.7513 - 0.1202 + 0.0065 - 0.00013 = 8.26717 */
    ts_clear_sky_esra(90.0, 0.0, 3.0, 1.0, &c);
    double m = 1.0 / (1.0 + 0.50572 * pow(96.07995, -1.6364));
    double dr = 1.0 / (6.6296 + 1.7513 * m - 0.1202 * m * m + 0.0065 * pow(m, 3) -
                       0.00013 * pow(m, 4));
    double bn = 1367.0 * exp(-0.8662 * 3.0 * m * dr);
    printf("ESRA, zenith sun, TL 3: beam %.2f W/m2, diffuse %.2f W/m2\n", c.beam_normal,
           c.diffuse_horizontal);
    CK_NEAR(c.beam_normal, bn, 1e-9, "beam normal");
    CK_NEAR(c.beam_horizontal, bn, 1e-9, "beam horizontal");
    CK_NEAR(c.beam_normal, 998.36, 0.05, "beam normal (hand value)");
    /* Trd(3) = 0.079203, Fd(90) = A0 + A1 + A2 = 0.996504 */
    CK_NEAR(c.diffuse_horizontal, 1367.0 * 0.0792027 * 0.996504, 0.01, "diffuse");
    /* higher site: less air, more beam */
    ts_clear_sky hi;
    ts_clear_sky_esra(30.0, 3000.0, 3.0, 1.0, &hi);
    ts_clear_sky_esra(30.0, 0.0, 3.0, 1.0, &c);
    ck_assert(hi.beam_normal > c.beam_normal);
    /* more turbidity: less beam, more diffuse */
    ts_clear_sky turbid;
    ts_clear_sky_esra(30.0, 0.0, 6.0, 1.0, &turbid);
    ck_assert(turbid.beam_normal < c.beam_normal);
    ck_assert(turbid.diffuse_horizontal > c.diffuse_horizontal);
    /* sun at or below the horizon: nothing */
    ts_clear_sky_esra(0.0, 0.0, 3.0, 1.0, &c);
    ck_assert(c.beam_normal == 0 && c.diffuse_horizontal == 0);
    /* closer sun, more light: 1 / R^2 */
    ts_clear_sky_esra(90.0, 0.0, 3.0, 0.5, &c);
    CK_NEAR(c.beam_normal, 4 * bn, 1e-6, "1/R^2");
}
END_TEST

/* ESRA off the zenith, worked by hand from Rigollier et al. (2000): the
 * diffuse angular function Fd(h) = A0 + A1 sin h + A2 sin^2 h at two
 * elevations, and the beam at 1 deg, where air mass > 20 takes Kasten's
 * (1996) Rayleigh thickness 1 / (10.4 + 0.718 m). Sea level, TL = 3, 1 AU. */
START_TEST(test_esra_low_sun)
{
    ts_clear_sky c;
    /* Trd = -0.015843 + 0.030543*3 + 0.0003797*9 = 0.0792033
     * A0 = 0.26463 - 0.061581*3 + 0.0031408*9 = 0.1081542 (A0 Trd > 0.002)
     * A1 = 2.0402 + 0.018945*3 - 0.011161*9 = 1.996586
     * A2 = -1.3025 + 0.039231*3 + 0.0085079*9 = -1.1082359
     * sin h = 0.5 (h = 30): Fd = 0.1081542 + 0.998293 - 0.2770590 = 0.8293882,
     *   D = 1367 * 0.0792033 * 0.8293882 = 89.7986 W/m2
     * sin h = 0.2 (h = 11.536959): Fd = 0.1081542 + 0.3993172 - 0.0443294
     *   = 0.4631420, D = 1367 * 0.0792033 * 0.4631420 = 50.1448 W/m2 */
    ts_clear_sky_esra(30.0, 0.0, 3.0, 1.0, &c);
    printf("ESRA, TL 3: diffuse %.4f W/m2 at sin h 0.5", c.diffuse_horizontal);
    CK_NEAR(c.diffuse_horizontal, 89.7986, 0.001, "diffuse, sin h 0.5");
    ts_clear_sky_esra(asin(0.2) * 180 / M_PI, 0.0, 3.0, 1.0, &c);
    printf(", %.4f W/m2 at sin h 0.2", c.diffuse_horizontal);
    CK_NEAR(c.diffuse_horizontal, 50.1448, 0.001, "diffuse, sin h 0.2");
    /* h = 1: m = 1 / (sin 1 + 0.50572 * 7.07995^-1.6364)
     *        = 1 / (0.0174524 + 0.0205551) = 26.3106 (> 20),
     * dR = 1 / (10.4 + 0.718 * 26.3106) = 1 / 29.2910 = 0.0341402,
     * Bn = 1367 exp(-0.8662 * 3 * 26.3106 * 0.0341402) = 1367 exp(-2.334187)
     *    = 132.448 W/m2 */
    ts_clear_sky_esra(1.0, 0.0, 3.0, 1.0, &c);
    printf("; beam normal %.3f W/m2 at 1 deg\n", c.beam_normal);
    CK_NEAR(c.beam_normal, 132.448, 0.005, "beam normal, 1 deg");
}
END_TEST

/* The insolation of a flat open plane is the clear-sky global horizontal
 * irradiation, summed step by step here independently. */
START_TEST(test_insolation_flat)
{
    ts_error err;
    ts_grid g;
    flat(&g, 16, 30.0, 400.0f);
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 8;
    double start = ts_local_midnight(2026, 6, 21, 120);
    float tot[256], beam[256], dif[256];
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 300, tot, beam, dif, &err) ==
              TS_OK);
    double want_b = 0, want_d = 0;
    for (int k = 0; k < 288; k++) {
        ts_sun_sample s;
        ck_assert(ts_sun_at_site(&p.s, &o, start + 300 * k + 150, &s, &err) == TS_OK);
        ts_clear_sky c;
        ts_clear_sky_esra(s.elevation, 400.0, 3.0, s.distance_au, &c);
        double f = ts_sun_disk_fraction(s.elevation, 0.0);
        want_b += c.beam_horizontal * f * 300 / 3600.0;
        want_d += c.diffuse_horizontal * 300 / 3600.0;
    }
    int mid = 8 * 16 + 8;
    printf("insolation, Bern 400 m, 2026-06-21, TL 3: %.1f Wh/m2 (beam %.1f, diffuse "
           "%.1f); independent sum %.1f\n",
           tot[mid], beam[mid], dif[mid], want_b + want_d);
    CK_NEAR(beam[mid], want_b, 1e-3 * want_b, "beam");
    CK_NEAR(dif[mid], want_d, 1e-3 * want_d, "diffuse");
    CK_NEAR(tot[mid], beam[mid] + dif[mid], 0.1, "total");
    ck_assert(tot[mid] > 7000 && tot[mid] < 9000); /* clear June day, mid latitudes */
    /* a south-facing 30-degree slope gets more in December, less direct
     * light faces north */
    ts_grid_free(&g);
}
END_TEST

/* The lattice path of the insolation (per-cell sun) gives the single
 * site's result when every node is that site. */
START_TEST(test_insolation_lattice)
{
    ts_error err;
    const int n = 24;
    ts_grid g;
    tdem_create(&g, n, n, 30.0, 30.0);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++)
            g.z[y * n + x] = (float)(800 + 60 * sin(x * 0.4) * cos(y * 0.3) + 4 * y);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 8;
    double start = ts_local_midnight(2026, 3, 1, 60);
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    p.north = 1.5;
    double lon[4] = {7.9, 7.9, 7.9, 7.9}, lat[4] = {46.5, 46.5, 46.5, 46.5},
           north[4] = {1.5, 1.5, 1.5, 1.5};
    ts_sun_sites s = {2, 2, 0.5, 0.5, n - 1.0, n - 1.0, lon, lat, north};
    float a[3][24 * 24], b[3][24 * 24];
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 900, a[0], a[1], a[2], &err) == TS_OK);
    ck_assert(ts_insolation(&g, &s, &o, start, 86400, 900, b[0], b[1], b[2], &err) == TS_OK);
    double worst = 0;
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < n * n; i++)
            worst = fmax(worst, fabs(a[k][i] - b[k][i]) / fmax(1.0, fabs(a[k][i])));
    printf("insolation, one site vs a lattice of the same site: max relative diff %.2g\n",
           worst);
    ck_assert(worst < 1e-4);
    ts_grid_free(&g);
}
END_TEST

/* Slopes: in December at 46.5 N a south-facing slope gets more than the
 * plain, a north-facing one less; a pit's floor gets little beam. */
START_TEST(test_insolation_slopes)
{
    ts_error err;
    const int n = 48;
    ts_grid g;
    tdem_create(&g, n, n, 30.0, 30.0);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            double yy = y < n / 2 ? y : n - 1 - y; /* a roof: ridge at the middle */
            g.z[y * n + x] = (float)(1000.0 + 30.0 * yy * tan(30 * M_PI / 180));
        }
    test_site p;
    test_site_init(&p, 46.5, 7.9);
    ts_day_opts o;
    ts_day_opts_default(&o);
    o.horizon.directions = 16;
    double start = ts_local_midnight(2026, 12, 21, 60);
    float *tot = malloc(n * n * sizeof *tot);
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 600, tot, NULL, NULL, &err) == TS_OK);
    double north = tot[(n / 4) * n + n / 2], south = tot[(3 * n / 4) * n + n / 2];
    ts_grid_free(&g);
    flat(&g, n, 30.0, 1000.0f);
    ck_assert(ts_insolation(&g, &p.s, &o, start, 86400, 600, tot, NULL, NULL, &err) == TS_OK);
    double plain = tot[(n / 2) * n + n / 2];
    printf("December: north slope %.0f, plain %.0f, south slope %.0f Wh/m2\n", north, plain,
           south);
    ck_assert(south > 1.5 * plain);
    ck_assert(north < 0.6 * plain);
    free(tot);
    ts_grid_free(&g);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("daycycle_light");
    TCase *tc = tcase_create("light");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_shadows_cut_sun_hours);
    tcase_add_test(tc, test_grid_north);
    tcase_add_test(tc, test_esra);
    tcase_add_test(tc, test_esra_low_sun);
    tcase_add_test(tc, test_insolation_flat);
    tcase_add_test(tc, test_insolation_slopes);
    tcase_add_test(tc, test_insolation_lattice);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return test_run_suite(suite());
}
