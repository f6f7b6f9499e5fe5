/*
 * ts_disk_fraction for per-cell loops: its two common cases inline, a disk
 * wholly above the horizon (1) or wholly below it (0), by the same double
 * arithmetic as ts_disk_fraction (so the same results), and only the partly
 * hidden disk by the call (asin). Most cells of a sunlit grid take the
 * first case, and their loops no longer call out per cell.
 */
#ifndef TS_DISK_FRACTION_H
#define TS_DISK_FRACTION_H

#include "terrashade.h"

/* ts_disk_fraction's u: the light's centre above the horizon, in radii
 * (one subtraction and one division, rounded as every user of it must). */
static inline double ts_disk_u(double light_elevation, double horizon, double radius)
{
    return (light_elevation - horizon) / radius;
}

static inline double ts_disk_fraction_inl(double light_elevation, double horizon, double radius)
{
    if (radius > 0) { /* else NaN, by the call */
        const double u = ts_disk_u(light_elevation, horizon, radius);
        if (u >= 1.0)
            return 1.0;
        if (u <= -1.0)
            return 0.0;
    }
    return ts_disk_fraction(light_elevation, horizon, radius); /* NaN, or partly hidden */
}

static inline double ts_sun_disk_fraction_inl(double sun_elevation, double horizon)
{
    return ts_disk_fraction_inl(sun_elevation, horizon, TS_SUN_RADIUS_DEG);
}

/* Whether the sun clears horizon h: ts_disk_fraction's u >= 1, where its
 * fraction is 1 (and for every lower horizon: u only grows as h falls,
 * rounding included). A NaN gives 0. */
static inline int ts_sun_disk_clears(double sun_elevation, double horizon)
{
    return ts_disk_u(sun_elevation, horizon, TS_SUN_RADIUS_DEG) >= 1.0;
}

#endif
