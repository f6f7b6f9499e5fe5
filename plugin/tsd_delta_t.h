/*
 * tsd_delta_t.h - an estimate of TT - UT (delta T) for a year, to tell a
 * user whose date is far from the 2020s that DELTA_T's default (69 s) is
 * not that year's.
 */
#ifndef TSD_DELTA_T_H
#define TSD_DELTA_T_H

#ifdef __cplusplus
extern "C" {
#endif

/** Delta T in seconds for a (fractional) year, from the polynomials of
 * Espenak & Meeus (2006, NASA's Five Millennium Canon of Solar Eclipses):
 * fits of the observed values from -500 to 2005, a prediction after, and
 * the long-term parabola -20 + 32 ((year - 1820) / 100)^2 outside
 * -500..2150. */
double tsd_delta_t_estimate(double year);

#ifdef __cplusplus
}
#endif

#endif
