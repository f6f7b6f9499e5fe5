/*
 * terrashade_sh.h - order-4 spherical-harmonic (SH) light and visibility
 * (Snyder & Nowrouzezahrai 2008, section 5): a light (an environment or a
 * circular key light) projected to 16 SH coefficients, a per-cell
 * visibility vector summed over wedges between consecutive horizon angles
 * (a precomputed 256 x 256 wedge table, boundary wedges for a partial
 * swath, z-rotation in the SH basis), and the SH triple product of light,
 * visibility and the clamped cosine around the cell's normal.
 *
 * Basis: the real SH of bands l = 0..3, orthonormal over the sphere
 * (integral of y_i y_j = delta_ij), index i = l (l + 1) + m, m = -l..l;
 * m > 0 holds cos(m phi), m < 0 sin(|m| phi), without the Condon-Shortley
 * phase (y_1,1 = sqrt(3 / 4 pi) x, y_1,-1 = sqrt(3 / 4 pi) y,
 * y_1,0 = sqrt(3 / 4 pi) z), the polynomial forms of Sloan's "Stupid SH
 * tricks". Directions are in the terrain frame (x east, y north, z up); phi
 * is the mathematical angle from east, counter-clockwise seen from above,
 * i.e. phi = 90 deg - azimuth.
 *
 * Below the horizontal: the sky ends there (as the `sky` product's and the
 * L_p table's), so horizon angles are clamped at 0 (the paper's omega >= 0)
 * and the visibility is 0 below the horizontal; a light's values there are
 * then free, and they are the mirror image of the light above (L(x, y, -z) =
 * L(x, y, z)) so that the band-limited light has no step at the horizon
 * (a constant sky becomes one coefficient, exactly).
 *
 * Reentrant, no global state.
 */
#ifndef TERRASHADE_SH_H
#define TERRASHADE_SH_H

#include <stddef.h>

#include "terrashade.h"
#include "terrashade_env.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Coefficients of order-4 SH (bands 0..3). */
#define TS_SH_COEFFS 16
/** Nodes of each horizon-angle axis of a wedge table, over 0..90 degrees. */
#define TS_SH_WEDGE_STEPS 256

/* ----------------------------------------------------------- the basis */

/** The 16 basis functions at unit direction d (terrain frame). */
void ts_sh_eval(const double d[3], double y[TS_SH_COEFFS]);

/** Rotate a function about z by `angle` radians (counter-clockwise seen
 *  from above): out(d) = in(R^-1 d). in and out may be the same array. */
void ts_sh_rotate_z(const double in[TS_SH_COEFFS], double angle, double out[TS_SH_COEFFS]);

/** The clamped cosine max(0, n . s) around unit normal n (zonal harmonics
 *  pi/2 / sqrt(pi), sqrt(pi/3), sqrt(5 pi)/8, 0, rotated to n). */
void ts_sh_clamped_cosine(const double n[3], double h[TS_SH_COEFFS]);

/** A spherical cap of angular radius `radius_deg` (0 < r <= 180) around
 *  unit direction d, constant radiance, normalised to unit power
 *  (integral over the sphere = 1). */
void ts_sh_cap(const double d[3], double radius_deg, double out[TS_SH_COEFFS]);

/**
 * The product matrix of light `l`: m[j][k] = integral of l y_j y_k over the
 * sphere (exact: a product Gauss quadrature of degree 9), so that the triple
 * product of l, v and h (the integral of the product of the three
 * band-limited functions) is sum_jk v_j m[j][k] h_k (ts_sh_triple).
 */
void ts_sh_product_matrix(const double l[TS_SH_COEFFS],
                          double m[TS_SH_COEFFS][TS_SH_COEFFS]);

/** sum_jk v_j m[j][k] h_k. */
double ts_sh_triple(const double m[TS_SH_COEFFS][TS_SH_COEFFS], const double v[TS_SH_COEFFS],
                    const double h[TS_SH_COEFFS]);

/* --------------------------------------------------------- projection */

/**
 * Project an environment's texels (terrain frame) to SH per colour:
 * out[c][i] = sum over the texels above the horizontal (z > 0) of
 * rgb[c] omega (y_i(d) + y_i(mirror d)), the mirror being (x, y, -z) (the
 * file comment says why); texels at or below the horizontal are ignored,
 * as by the L_p table. TS_ERR_ARG for a NULL or empty environment.
 */
ts_status ts_sh_project_env(const ts_env *env, double out[3][TS_SH_COEFFS], ts_error *err);

/**
 * A key light: a disk of angular radius `radius_deg` (0 < r < 45) at the
 * sun's azimuth (degrees from north) and elevation, unit power, plus its
 * mirror image below the horizontal (the file comment). The visibility
 * clips it at the horizontal; ts_sh_disk_above says how much of the disk
 * itself lies above it.
 */
void ts_sh_key_light(double azimuth, double elevation, double radius_deg,
                     double out[TS_SH_COEFFS]);

/**
 * The least radius (degrees) of a key light's disk: a smaller LIGHT_RADIUS
 * is taken as this. Order 4 cannot tell a disk of 0.01 degrees from a point
 * (its bands differ by ~1e-7), and a swath 1e-38 degrees wide made wedge
 * tables of float zeros and denormals: shades of 1 or NaN.
 */
#define TS_SH_KEY_RADIUS_MIN 0.01

/** Fraction (0..1) of a disk of angular radius r centred at elevation e
 *  above the horizontal (the planar-disk chord area, as the exact shade's). */
double ts_sh_disk_above(double elevation, double radius_deg);

/* ------------------------------------------------------------- swaths */

/**
 * The azimuths whose horizons the visibility is built from: a complete
 * swath (n samples every 360/n degrees from `first`, n interior wedges
 * around the circle) or a partial one (the swath from `start` clockwise over
 * `span` degrees, n samples at the centres of its n equal parts, n - 1
 * interior wedges between them and a boundary wedge of half a part at each
 * end whose horizon rises linearly to 90 degrees, fully blocked, at the
 * swath's edge).
 */
typedef struct {
    int complete;  /**< 1: the whole circle */
    int n;         /**< samples, >= 1 */
    double start;  /**< partial: the swath's first edge, degrees from north */
    double span;   /**< degrees (360 when complete) */
    double step;   /**< between samples: span / n */
    double first;  /**< azimuth of sample 0 */
} ts_sh_swath;

/** A complete swath of n samples from azimuth `first`. */
void ts_sh_swath_complete(ts_sh_swath *s, int n, double first);

/**
 * The partial swath of a key light: the azimuths that a disk of radius r at
 * (azimuth, elevation) covers, 2 asin(sin r / cos e) wide and centred on its
 * azimuth; a complete swath when the disk holds the zenith (e + r >= 90).
 */
void ts_sh_swath_key(ts_sh_swath *s, int n, double azimuth, double elevation,
                     double radius_deg);

/** Azimuth of sample k, degrees in [0, 360). */
double ts_sh_swath_azimuth(const ts_sh_swath *s, int k);

/* -------------------------------------------------------- wedge tables */

/**
 * Wedge tables of a swath (eq. 8 of the paper): the SH projection of the
 * visibility of one wedge in canonical position (phi from 0 to its extent,
 * the horizon linear from omega_a at 0 to omega_b at the end; visible above
 * it, 0 below and outside the wedge), by Gauss quadrature in azimuth of a
 * tabulated integral over elevation (core/sh_visibility.c; within 3e-5 of a
 * sum over a 0.09-degree grid of the sphere, tests/check_sh.c). interior[(a * 256 + b) * 16 + i]
 * at omega_a = 90 a / 255, omega_b = 90 b / 255 degrees, extent s->step;
 * for a partial swath rise[a * 16 + i] = the wedge of extent step / 2 from
 * omega_a to 90 degrees and fall[b * 16 + i] from 90 degrees to omega_b.
 */
typedef struct {
    ts_sh_swath swath;
    float *interior;
    float *rise, *fall; /**< NULL for a complete swath */
    int threads;        /**< what ts_sh_wedges_build was given: the passes
                             that take these tables use as many */
} ts_sh_wedges;

/** Build the tables of swath s (threads: 0 = all cores; the visibility and
 *  swath-light passes over these tables use the same count). Free with
 *  ts_sh_wedges_free. */
ts_status ts_sh_wedges_build(const ts_sh_swath *s, int threads, ts_sh_wedges *w,
                             ts_error *err);
/** Free the tables (zeroed: freeing twice is harmless). */
void ts_sh_wedges_free(ts_sh_wedges *w);

/** The visibility of swath s with the same horizon, omega_deg, in every
 *  azimuth (wedge by wedge, without the tables). */
void ts_sh_swath_visibility_flat(const ts_sh_swath *s, double omega_deg,
                                 double out[TS_SH_COEFFS]);

/** The SH projection of one wedge of `extent_deg`, horizons omega_a to
 *  omega_b degrees (clamped to 0..90), by the quadrature of the tables. */
void ts_sh_wedge_project(double extent_deg, double omega_a, double omega_b,
                         double out[TS_SH_COEFFS]);

/**
 * Visibility of every cell, summed wedge by wedge as the swath's horizon
 * planes arrive in order k = 0 .. n - 1 (ts_sh_visibility_add), then
 * finished (ts_sh_visibility_finish adds the wedges that need the last
 * plane: the closing one of a complete swath, the end boundary of a
 * partial one). vis: 16 floats a cell, width * height cells (coefficient i of
 * cell c at vis[c * 16 + i]); it keeps copies of the first and the last
 * plane. NaN horizons (nodata) give NaN.
 */
typedef struct {
    const ts_sh_wedges *w;
    const ts_grid *grid;
    int next;        /**< the plane expected next */
    float *vis;      /**< 16 floats a cell, zeroed by init */
    float *first;    /**< plane 0 (complete swath) */
    float *prev;     /**< the last plane */
} ts_sh_visibility;

/** Start the visibility of `grid` for the swath of `w` (both kept by
 * pointer: they must outlive v): vis zeroed, plane 0 expected next. Free
 * with ts_sh_visibility_free. */
ts_status ts_sh_visibility_init(ts_sh_visibility *v, const ts_grid *grid,
                                const ts_sh_wedges *w, ts_error *err);
/** Add plane k (horizon angles in degrees at ts_sh_swath_azimuth(k)). */
ts_status ts_sh_visibility_add(ts_sh_visibility *v, int k, const float *plane, ts_error *err);
/** After every plane: the wedges that need the last one; vis then holds
 * each cell's visibility. An error if a plane is missing. */
ts_status ts_sh_visibility_finish(ts_sh_visibility *v, ts_error *err);
/** Free vis and the plane copies (zeroed: freeing twice is harmless). */
void ts_sh_visibility_free(ts_sh_visibility *v);

/* ------------------------------------------------------------ shading */

/**
 * The SH triple product per cell: out[c] = scale * sum_jk vis_j m[j][k]
 * h_k(N), h the clamped cosine around the cell's normal (ts_normals), m the
 * light's product matrix; negative results (ringing) become 0; NaN normal or
 * visibility give NaN. threads: 0 = all cores.
 */
ts_status ts_sh_shade(const ts_grid *grid, const double m[TS_SH_COEFFS][TS_SH_COEFFS],
                      const float *nx, const float *ny, const float *nz, const float *vis,
                      double scale, int threads, float *out, ts_error *err);

/** out[c] = clamp(scale * sum_i l_i vis_i, 0, 1): the visible share of a
 *  light (ts_sh_shadow's double product); NaN stays NaN. threads: 0 = all
 *  cores (as ts_sh_shade). */
ts_status ts_sh_visible_share(const ts_grid *grid, const double l[TS_SH_COEFFS],
                              const float *vis, double scale, int threads, float *out,
                              ts_error *err);

/**
 * A swath's light in one pass over the cells from all its horizon planes at
 * once (planes[k] at ts_sh_swath_azimuth(k), n of them), without storing the
 * visibility (the cheaper form when the swath has few samples, as a key
 * light's): each cell's visibility summed from the same wedges as
 * ts_sh_visibility, then, where the output is not NULL,
 * shade = max(0, scale_shade * triple(l, V, clamped cosine of N)) and
 * share = clamp(scale_share * l . V, 0, 1); NaN stays NaN. The normals N:
 * the planes nx, ny, nz (ts_normals), or, all three NULL, each row's made
 * from the grid as ts_normals makes it (the same values, without 3 planes).
 * A large grid takes a faster path (the tables folded with the light) that
 * differs from the other by float rounding; a window of a larger DEM (the
 * grid's `origin`) takes the path the whole DEM would, so that its cells
 * are the whole's bit for bit. shade or share may be the same array as a
 * plane: each cell's horizons are read before its outputs are written.
 */
ts_status ts_sh_swath_light(const ts_grid *grid, const ts_sh_wedges *w,
                            const float *const *planes, const double l[TS_SH_COEFFS],
                            const float *nx, const float *ny, const float *nz,
                            double scale_shade, float *shade, double scale_share, float *share,
                            ts_error *err);

/**
 * ts_sh_swath_light reporting its progress through report's callback
 * (report->progress, may be NULL: none) from `from` to `to`, about 32
 * times, and stopping with TS_ERR_CANCELLED where the callback asks; the
 * same cells.
 */
ts_status ts_sh_swath_light_reported(const ts_grid *grid, const ts_sh_wedges *w,
                                     const float *const *planes, const double l[TS_SH_COEFFS],
                                     const float *nx, const float *ny, const float *nz,
                                     double scale_shade, float *shade, double scale_share,
                                     float *share, const ts_horizon_opts *report, double from,
                                     double to, ts_error *err);

/* ---------------------------------------------------------- key light */

/**
 * A key light's normalisers, from its swath with every horizon at 0 (open
 * flat ground): `shade_ref` = the triple product with the upward clamped
 * cosine divided by sin(elevation) (0 for a sun at or below the horizontal),
 * so that shade divided by it gives open flat ground exactly the exact
 * method's max(0, N . L) = sin e (of the normalisations tried, the one
 * closest to the exact shade on jacksboro: mean |difference| 0.024 against
 * 0.082 for "a surface facing the light gets 1", sun at 315/45 degrees);
 * `share_ref` = the double product (light . visibility), so that open flat
 * ground sees all of the light. Multiply both results by ts_sh_disk_above.
 */
void ts_sh_key_reference(const ts_sh_wedges *w, const double l[TS_SH_COEFFS],
                         double azimuth, double elevation, double *shade_ref,
                         double *share_ref);

#ifdef __cplusplus
}
#endif

#endif
