/* One sun site for the day tests (core/day_cycle.h): a ts_sun_sites of a
 * single node whose arrays point into the struct itself, so keep it where
 * it was initialised (do not copy it). */
#ifndef TEST_SITE_H
#define TEST_SITE_H

#include <string.h>

#include "day_cycle.h"

typedef struct {
    double lon, lat, north;
    ts_sun_sites s;
} test_site;

/* A single site at (lat, lon) degrees, grid north = true north. */
static inline void test_site_init(test_site *p, double lat, double lon)
{
    memset(p, 0, sizeof *p);
    p->lon = lon;
    p->lat = lat;
    p->s.nx = p->s.ny = 1;
    p->s.longitude = &p->lon;
    p->s.latitude = &p->lat;
    p->s.north_azimuth = &p->north;
}

#endif
