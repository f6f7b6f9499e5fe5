/*
 * The ESRA clear-sky model (Rigollier, Bauer & Wald 2000). Split from
 * day_cycle.c unchanged. See day_cycle.h and docs/day-cycle.md.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "day_cycle_internal.h"
#include "status_internal.h"

#define DEG2RAD (M_PI / 180.0)
#define RAD2DEG (180.0 / M_PI)

/* ------------------------------------------------------------ clear sky */

/* Kasten & Young (1989) relative optical air mass at sea level, apparent
 * elevation h in degrees (> 0). */
double ts_esra_air_mass(double h)
{
    return 1.0 / (sin(h * DEG2RAD) + 0.50572 * pow(h + 6.07995, -1.6364));
}

/* Rayleigh optical thickness at air mass m (Kasten 1996, as in ESRA). */
static double rayleigh(double m)
{
    if (m <= 20.0)
        return 1.0 / (6.6296 + m * (1.7513 + m * (-0.1202 + m * (0.0065 - m * 0.00013))));
    return 1.0 / (10.4 + 0.718 * m);
}

/* Diffuse transmission at zenith and its angular function (ESRA). */
double ts_esra_diffuse_factor(double linke, double sin_h)
{
    double tl = linke;
    double trd = -1.5843e-2 + tl * (3.0543e-2 + tl * 3.797e-4);
    double a0 = 2.6463e-1 + tl * (-6.1581e-2 + tl * 3.1408e-3);
    double a1 = 2.0402 + tl * (1.8945e-2 - tl * 1.1161e-2);
    double a2 = -1.3025 + tl * (3.9231e-2 + tl * 8.5079e-3);
    if (a0 * trd < 2e-3)
        a0 = 2e-3 / trd;
    double fd = a0 + sin_h * (a1 + sin_h * a2);
    double d = trd * fd;
    return d > 0 ? d : 0;
}

double ts_esra_beam_transmittance(double m, double linke)
{
    return exp(-0.8662 * linke * m * rayleigh(m));
}

void ts_clear_sky_esra(double elevation, double height_m, double linke,
                       double distance_au, ts_clear_sky *out)
{
    memset(out, 0, sizeof *out);
    if (!(elevation > 0) || !(distance_au > 0) || !(linke > 0))
        return;
    double eps = 1.0 / (distance_au * distance_au);
    double g0 = TS_SOLAR_CONSTANT * eps;
    double pc = exp(-(isfinite(height_m) ? height_m : 0.0) / 8434.5);
    double m = pc * ts_esra_air_mass(elevation);
    double sh = sin(elevation * DEG2RAD);
    out->beam_normal = g0 * ts_esra_beam_transmittance(m, linke);
    out->beam_horizontal = out->beam_normal * sh;
    out->diffuse_horizontal = g0 * ts_esra_diffuse_factor(linke, sh);
}

