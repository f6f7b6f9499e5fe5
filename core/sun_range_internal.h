/*
 * Internal to the date-range products: sun_range.c gathers the sun's
 * positions and streams the horizon planes, sun_range_eval.c evaluates the
 * positions of one azimuth bucket on every cell.
 */
#ifndef TS_SUN_RANGE_INTERNAL_H
#define TS_SUN_RANGE_INTERNAL_H

#include <stddef.h>

#include "day_cycle.h"
#include "parallel.h"

/* Entries of a sun position's beam-transmittance table over the grid's
 * range of pressure factors exp(-z / 8434.5), interpolated linearly. */
#define TS_RANGE_TABLE 256

/* What a bucket adds to each cell. */
typedef enum { TS_RANGE_VISIBLE, TS_RANGE_FRACTION, TS_RANGE_BEAM } ts_range_mode;

/* One sun position of the range. */
typedef struct {
    double az;       /* grid azimuth, degrees */
    double el;       /* apparent elevation of the centre, degrees */
    float w;         /* weight of the bucket's right-hand plane */
    double hours;    /* step length in hours times the day's weight */
    double g0_hours; /* beam: extraterrestrial irradiance times hours */
    float lx, ly, lz; /* beam: unit vector to the sun (east, north, up) */
    const float *table; /* beam: TS_RANGE_TABLE transmittances */
} ts_range_sun;

/* The positions between two horizon planes, and where they go. */
typedef struct {
    size_t cells;
    const float *pa, *pb; /* horizons at the bucket's two azimuths */
    const float *floor;   /* Earth horizon per cell, or NULL */
    ts_range_mode mode;
    const ts_range_sun *sun;
    int count;
    const float *nx, *ny, *nz, *pc; /* beam: normals, pressure factors */
    float pc_min, pc_inv;           /* beam: table axis */
    double *acc;                    /* width*height sums */
} ts_range_bucket;

/* acc += the bucket's contributions, on `threads` threads (0 = all). */
ts_status ts_range_evaluate(const ts_range_bucket *b, int threads, ts_error *err);

#endif
