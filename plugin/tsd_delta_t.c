/* Delta T for a year (Espenak & Meeus 2006); see tsd_delta_t.h. */
#include "tsd_delta_t.h"

/* The polynomial c0 + c1 x + ... (n terms) at x, by Horner's rule. */
static double poly(double x, const double *c, int n)
{
    double v = 0;
    for (int i = n - 1; i >= 0; i--)
        v = v * x + c[i];
    return v;
}

double tsd_delta_t_estimate(double y)
{
    const double u = (y - 1820) / 100;
    if (y < -500 || y >= 2150)
        return -20 + 32 * u * u;
    if (y < 500) {
        static const double c[] = {10583.6, -1014.41, 33.78311, -5.952053,
                                   -0.1798452, 0.022174192, 0.0090316521};
        return poly(y / 100, c, 7);
    }
    if (y < 1600) {
        static const double c[] = {1574.2, -556.01, 71.23472, 0.319781,
                                   -0.8503463, -0.005050998, 0.0083572073};
        return poly((y - 1000) / 100, c, 7);
    }
    if (y < 1700) {
        static const double c[] = {120, -0.9808, -0.01532, 1 / 7129.0};
        return poly(y - 1600, c, 4);
    }
    if (y < 1800) {
        static const double c[] = {8.83, 0.1603, -0.0059285, 0.00013336, -1 / 1174000.0};
        return poly(y - 1700, c, 5);
    }
    if (y < 1860) {
        static const double c[] = {13.72, -0.332447, 0.0068612, 0.0041116,
                                   -0.00037436, 0.0000121272, -0.0000001699, 0.000000000875};
        return poly(y - 1800, c, 8);
    }
    if (y < 1900) {
        static const double c[] = {7.62, 0.5737, -0.251754, 0.01680668, -0.0004473624,
                                   1 / 233174.0};
        return poly(y - 1860, c, 6);
    }
    if (y < 1920) {
        static const double c[] = {-2.79, 1.494119, -0.0598939, 0.0061966, -0.000197};
        return poly(y - 1900, c, 5);
    }
    if (y < 1941) {
        static const double c[] = {21.20, 0.84493, -0.076100, 0.0020936};
        return poly(y - 1920, c, 4);
    }
    if (y < 1961) {
        static const double c[] = {29.07, 0.407, -1 / 233.0, 1 / 2547.0};
        return poly(y - 1950, c, 4);
    }
    if (y < 1986) {
        static const double c[] = {45.45, 1.067, -1 / 260.0, -1 / 718.0};
        return poly(y - 1975, c, 4);
    }
    if (y < 2005) {
        static const double c[] = {63.86, 0.3345, -0.060374, 0.0017275, 0.000651814,
                                   0.00002373599};
        return poly(y - 2000, c, 6);
    }
    if (y < 2050) {
        static const double c[] = {62.92, 0.32217, 0.005589};
        return poly(y - 2000, c, 3);
    }
    return -20 + 32 * u * u - 0.5628 * (2150 - y);
}
