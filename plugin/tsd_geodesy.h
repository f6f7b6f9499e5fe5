/*
 * tsd_geodesy.h - cell sizes in metres of a north-up DEM from its
 * geotransform and CRS (OSR + PROJ's geodesic routines).
 *
 *  - projected (or local) CRS: linear units converted to metres (metre,
 *    foot, US survey foot... anything OSR knows): the grid's sizes; or,
 *    with CELL_SIZES=ground (and auto where the projection's scale departs
 *    from 1 by more than 1 %, as Web Mercator's does away from the equator),
 *    geodesic distances on the ellipsoid as for a geographic CRS, measured
 *    along the DEM's central column;
 *  - geographic CRS: geodesic distances on the CRS's ellipsoid, per row
 *    for east-west (it shrinks with latitude) and the mean over the DEM for
 *    north-south;
 *  - no CRS: the geotransform's units are taken as metres (a warning);
 *  - rotated or sheared geotransform: an error.
 * A south-up (GT[5] > 0) or east-to-west (GT[1] < 0) DEM is flipped on the
 * way in and out so that the core always sees row 0 = north.
 */
#ifndef TSD_GEODESY_H
#define TSD_GEODESY_H

#include <stddef.h>

#include "ogr_srs_api.h"
#include "terrashade.h"
#include "tsd_options.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { TSD_CRS_NONE = 0, TSD_CRS_PROJECTED, TSD_CRS_GEOGRAPHIC } tsd_crs_kind;

/* The most a projected DEM's grid axes may be from a right angle on the
 * ground: beyond the first, a warning; beyond the second, a refusal (its
 * slopes, aspects and shadows would turn by as much). */
#define TSD_SKEW_WARN_DEG 1.0
#define TSD_SKEW_MAX_DEG 10.0

typedef struct {
    tsd_crs_kind kind;
    double cell_x;      /* metres; geographic: at the central row */
    double cell_y;      /* metres */
    double *cell_x_row; /* geographic only: height values in grid order
                           (row 0 = north), malloc'd; else NULL */
    int flip_x;         /* DEM column 0 is the eastern edge */
    int flip_y;         /* DEM row 0 is the southern edge */
    double unit_to_m;   /* projected: metres per CRS unit */
    int ground;         /* projected: measured on the ground (CELL_SIZES) */
    double scale_lo, scale_hi; /* projected: the projection's scale (grid length
                                  over ground length) seen over the DEM; 0: not
                                  measured (CELL_SIZES=grid, a local CRS) */
    double skew_deg;    /* projected: how far the grid's axes are from a right
                           angle on the ground, at most, over a 5 x 5 lattice
                           of cells (chords of at least 100 m); 0:
                           not measured (a local CRS) */
    char warning[1024]; /* non-empty: something the user should know */
} tsd_cells;

/**
 * Compute the cell sizes of a width x height DEM. srs may be NULL (no CRS).
 * mode (CELL_SIZES) says how a projected DEM's cells are measured; auto
 * decides from the projection's scale at nine cells of the DEM (its
 * corners, edges' midpoints and centre). grid with a
 * geographic CRS, or ground without a CRS or through a CRS PROJ cannot take
 * to longitude and latitude, is an error. TS_OK, or the failure's status
 * with a sentence in msg. Free with tsd_cells_free.
 */
ts_status tsd_cells_compute(const double gt[6], int width, int height,
                      OGRSpatialReferenceH srs, tsd_cell_sizes mode, tsd_cells *out,
                      char *msg, size_t msg_size);

/** The mode that measures another grid of the same DEM (an overview level,
 * the far field's coarse grid) as c measured it: grid or ground for a
 * projected DEM, auto (moot) otherwise. */
tsd_cell_sizes tsd_cells_mode(const tsd_cells *c);

void tsd_cells_free(tsd_cells *c);

/** The smallest east-west cell size over the rows of a DEM of `height`
 * rows (cell_x where the rows do not differ), metres. */
double tsd_cells_min_x(const tsd_cells *c, int height);

/**
 * A CRS's points as longitude and latitude in degrees east of Greenwich,
 * and back. PROJ transforms to the CRS's own geographic CRS, which may
 * count in grads or from another prime meridian (NTF (Paris), EPSG:27572
 * and 4807, in grads from Paris; MGI (Ferro)); the conversion to degrees
 * from Greenwich is applied here (once missing: the Lambert II DEMs' cells
 * were 10 % off and their sun 5 degrees away).
 */
typedef struct {
    OGRCoordinateTransformationH fwd, inv; /* to the geographic CRS and back */
    double unit_deg;                       /* degrees per angular unit of it */
    double pm_deg;                         /* its prime meridian east of Greenwich */
} tsd_lonlat;

/** Open t for srs (a projected or derived geographic CRS), inv only where
 * asked; 1, or 0 with nothing to close where PROJ has no transform. */
int tsd_lonlat_open(OGRSpatialReferenceH srs, int with_inv, tsd_lonlat *t);

/** n points in place, the CRS to degrees (tsd_lonlat_to) or back
 * (tsd_lonlat_from, t opened with_inv), longitude first; ok[i] (may be
 * NULL) whether point i went; returns whether they all did. */
int tsd_lonlat_to(const tsd_lonlat *t, int n, double *x, double *y, int *ok);
int tsd_lonlat_from(const tsd_lonlat *t, int n, double *x, double *y, int *ok);

void tsd_lonlat_close(tsd_lonlat *t);

/** A geographic CRS's angular unit in degrees and its prime meridian in
 * degrees east of Greenwich. */
void tsd_geographic_units(OGRSpatialReferenceH srs, double *unit_deg, double *pm_deg);

/**
 * Where the sun is seen from, in the core grid's frame (row 0 north, after
 * the flips of tsd_cells): one site at the DEM's centre, or (per_cell) a
 * lattice of nx x ny sites, node (i, j) at pixel (x0 + i dx, y0 + j dy)
 * (cell (c, r) has its centre at (c + 0.5, r + 0.5)). Longitude and
 * latitude in degrees on the CRS's own datum (geodetic); `north` is the
 * grid azimuth of true north (0 for a geographic CRS; in a projected CRS
 * minus the meridian convergence), found through PROJ by stepping 1e-4
 * degrees north. Arrays are malloc'd; free with tsd_sites_free.
 */
typedef struct {
    int nx, ny;
    double x0, y0, dx, dy;
    double *lon, *lat, *north;
} tsd_sites;

/**
 * Compute the sites of a width x height DEM with geotransform gt and CRS
 * srs (not NULL). TS_OK, or the failure's status with a sentence in msg: no CRS usable
 * for geographic coordinates, a transformation PROJ cannot do, a latitude
 * beyond +/-90.
 */
ts_status tsd_sites_compute(const double gt[6], int width, int height,
                      OGRSpatialReferenceH srs, const tsd_cells *cells,
                      int per_cell, tsd_sites *out, char *msg, size_t msg_size);

/**
 * How far, in degrees of arc, the farthest node of the DEM's per-cell lattice
 * of sites (tsd_sites_compute with per_cell) lies from (lon0, lat0), the
 * site of SUN_POSITION=center: about how far off the sun computed there is
 * at the DEM's edges. *turn (may be NULL) receives the most the sun's grid
 * azimuth turns between the centre and a node from the frames alone: the
 * meridians' convergence (longitude difference x sin latitude) less the
 * change of the grid azimuth of true north. About 0 on a conformal grid; on
 * a geographic grid near a pole it can far exceed the arc (4 degrees of
 * longitude at 85 N: 2 degrees at the edges, 0.17 of arc). 0 where the
 * lattice cannot be computed.
 */
double tsd_sites_reach(const double gt[6], int width, int height, OGRSpatialReferenceH srs,
                       const tsd_cells *cells, double lon0, double lat0, double *turn);

void tsd_sites_free(tsd_sites *s);

#ifdef __cplusplus
}
#endif

#endif
