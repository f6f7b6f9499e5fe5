/*
 * cm_line.h - which samples of a sweep line lie on the grid (see
 * core/line_geometry.h): line b crosses row b + fl[k] at step k, and fl is
 * monotone in k (non-decreasing for t >= 0, non-increasing for t < 0), so
 * the k range is found by binary search.
 */
#ifndef TS_CM_LINE_H
#define TS_CM_LINE_H

#include "cm_prelude.h"

/* Smallest k in [0, U] with the predicate true (U: none); the predicate,
 * fl[k] >= lim (want_ge) or > lim, with <= / < when descending, goes from
 * false to true once. */
CM_FN int cm_first_k(const CM_GLOBAL int *fl, int U, int ascending, long lim, int want_ge)
{
    int lo = 0, hi = U;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        long v = fl[mid];
        int p = want_ge ? (ascending ? v >= lim : v <= lim) : (ascending ? v > lim : v < lim);
        if (p)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Steps k0..k1 of line b whose rows b + fl[k] lie in [0, V - 1], for U
 * steps, ascending: t >= 0. Returns 0 if there are none. */
CM_FN int cm_line_k_range(const CM_GLOBAL int *fl, int U, int V, int ascending, long b, int *k0,
                          int *k1)
{
    /* Rows b + fl[k] in [0, V-1]  <=>  fl[k] in [-b, V-1-b]. */
    long lo = -b, hi = (long)V - 1 - b;
    int a, z;
    if (ascending) {
        a = cm_first_k(fl, U, 1, lo, 1);     /* first fl >= lo */
        z = cm_first_k(fl, U, 1, hi, 0) - 1; /* last fl <= hi */
    } else {
        a = cm_first_k(fl, U, 0, hi, 1);     /* first fl <= hi */
        z = cm_first_k(fl, U, 0, lo, 0) - 1; /* last fl >= lo */
    }
    if (a > z || a >= U || z < 0)
        return 0;
    *k0 = a;
    *k1 = z;
    return 1;
}

/* The last step of line b (its steps on the grid ending at k1) whose row
 * b + fl[k] is at least -1: a descending line (t < 0) goes on one row
 * before the grid's first after it leaves, where its cell on row 0 asks
 * it for the far side's occluder (it holds the terrain the line crossed
 * on the grid, toward the occluders); k1 for an ascending line, whose row
 * -1 comes before its samples. */
CM_FN int cm_line_k_leaving(const CM_GLOBAL int *fl, int U, int ascending, long b, int k1)
{
    if (ascending)
        return k1;
    const int z = cm_first_k(fl, U, 0, -b - 1, 0) - 1; /* last fl >= -b - 1 */
    return z > k1 ? z : k1;
}

#endif
