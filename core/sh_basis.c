/*
 * The order-4 real SH basis (terrashade_sh.h states the convention): its
 * values, rotation about z, the clamped cosine (Ramamoorthi & Hanrahan
 * 2001, rotated by the zonal-harmonic rule), a spherical cap, and the
 * product matrix of the triple product, by exact quadrature.
 */
#include <math.h>
#include <string.h>

#include "sh_internal.h"

void ts_sh_eval(const double d[3], double y[TS_SH_COEFFS])
{
    TS_SH_BASIS(double, d[0], d[1], d[2], y);
}

void ts_sh_rotate_z(const double in[TS_SH_COEFFS], double angle, double out[TS_SH_COEFFS])
{
    double tmp[TS_SH_COEFFS];
    memcpy(tmp, in, sizeof tmp);
    out[0] = tmp[0];
    for (int l = 1; l <= 3; l++) {
        int c0 = l * (l + 1);
        out[c0] = tmp[c0];
        for (int m = 1; m <= l; m++) {
            /* f(phi - angle): c cos(m phi) + s sin(m phi) turned */
            double c = tmp[c0 + m], s = tmp[c0 - m], cm = cos(m * angle), sm = sin(m * angle);
            out[c0 + m] = c * cm - s * sm;
            out[c0 - m] = c * sm + s * cm;
        }
    }
}

void ts_sh_rotation_set(ts_sh_rotation *r, double az_start)
{
    double angle = (90.0 - az_start) * M_PI / 180;
    for (int l = 0; l <= 3; l++)
        for (int m = -l; m <= l; m++) {
            /* c' = c cos - s sin, s' = c sin + s cos (ts_sh_rotate_z) */
            int k = l * (l + 1) + m, am = m < 0 ? -m : m;
            r->p[k] = (float)cos(am * angle);
            r->q[k] = (float)(m > 0 ? -sin(am * angle) : m < 0 ? sin(am * angle) : 0);
        }
}

/* A zonal function with coefficients zh[l] (of y_l0) rotated to unit
 * direction d: sqrt(4 pi / (2l + 1)) zh[l] y_lm(d). */
static void zonal_to(const double zh[4], const double d[3], double out[TS_SH_COEFFS])
{
    double y[TS_SH_COEFFS];
    ts_sh_eval(d, y);
    for (int l = 0; l <= 3; l++)
        for (int m = -l; m <= l; m++)
            out[l * (l + 1) + m] = sqrt(4 * M_PI / (2 * l + 1)) * zh[l] * y[l * (l + 1) + m];
}

void ts_sh_clamped_cosine(const double n[3], double h[TS_SH_COEFFS])
{
    zonal_to(TS_SH_CLAMPED_COS_ZH, n, h);
}

void ts_sh_cap(const double d[3], double radius_deg, double out[TS_SH_COEFFS])
{
    /* unit power: radiance 1 / (2 pi (1 - c)); the zonal coefficient of band l,
     * rotated, is then y_lm(d) times the mean of P_l over the cap, in closed
     * form (no cancellation for small caps) */
    double c = cos(radius_deg * M_PI / 180);
    double mean[4] = {1, (1 + c) / 2, c * (1 + c) / 2, (5 * c * c - 1) * (1 + c) / 8}, zh[4];
    for (int l = 0; l <= 3; l++)
        zh[l] = mean[l] / sqrt(4 * M_PI / (2 * l + 1));
    zonal_to(zh, d, out);
}

void ts_sh_gauss(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double t = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = t;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (t * p1 - p0) / (t * t - 1);
            double dt = p1 / dp;
            t -= dt;
            if (fabs(dt) < 1e-15)
                break;
        }
        x[i] = t;
        w[i] = 2 / ((1 - t * t) * dp * dp);
    }
}

/* Quadrature of the product matrix: exact for polynomials of degree 9 on
 * the sphere (3 bands each): Gauss in z, equal steps in phi. */
#define PM_Z 8
#define PM_PHI 20

void ts_sh_product_matrix(const double l[TS_SH_COEFFS],
                          double m[TS_SH_COEFFS][TS_SH_COEFFS])
{
    double zx[PM_Z], zw[PM_Z];
    ts_sh_gauss(PM_Z, zx, zw);
    memset(m, 0, sizeof(double) * TS_SH_COEFFS * TS_SH_COEFFS);
    for (int a = 0; a < PM_Z; a++)
        for (int b = 0; b < PM_PHI; b++) {
            double phi = 2 * M_PI * b / PM_PHI, r = sqrt(1 - zx[a] * zx[a]);
            double d[3] = {r * cos(phi), r * sin(phi), zx[a]}, y[TS_SH_COEFFS];
            ts_sh_eval(d, y);
            double lv = 0;
            for (int i = 0; i < TS_SH_COEFFS; i++)
                lv += l[i] * y[i];
            double wgt = zw[a] * 2 * M_PI / PM_PHI * lv;
            for (int j = 0; j < TS_SH_COEFFS; j++)
                for (int k = 0; k < TS_SH_COEFFS; k++)
                    m[j][k] += wgt * y[j] * y[k];
        }
}

double ts_sh_triple(const double m[TS_SH_COEFFS][TS_SH_COEFFS], const double v[TS_SH_COEFFS],
                    const double h[TS_SH_COEFFS])
{
    double s = 0;
    for (int j = 0; j < TS_SH_COEFFS; j++) {
        double t = 0;
        for (int k = 0; k < TS_SH_COEFFS; k++)
            t += m[j][k] * h[k];
        s += v[j] * t;
    }
    return s;
}
