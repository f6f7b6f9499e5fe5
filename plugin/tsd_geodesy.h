/*
 * tsd_geodesy.h - cell sizes in metres of a north-up DEM from its
 * geotransform and CRS (OSR + PROJ's geodesic routines).
 *
 *  - projected (or local) CRS: linear units converted to metres (metre,
 *    foot, US survey foot... anything OSR knows);
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

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { TSD_CRS_NONE = 0, TSD_CRS_PROJECTED, TSD_CRS_GEOGRAPHIC } tsd_crs_kind;

typedef struct {
    tsd_crs_kind kind;
    double cell_x;      /* metres; geographic: at the central row */
    double cell_y;      /* metres */
    double *cell_x_row; /* geographic only: height values in grid order
                           (row 0 = north), malloc'd; else NULL */
    int flip_x;         /* DEM column 0 is the eastern edge */
    int flip_y;         /* DEM row 0 is the southern edge */
    double unit_to_m;   /* projected: metres per CRS unit */
    char warning[256];  /* non-empty: something the user should know */
} tsd_cells;

/**
 * Compute the cell sizes of a width x height DEM. srs may be NULL (no CRS).
 * 0 on success; -1 with a sentence in msg. Free with tsd_cells_free.
 */
int tsd_cells_compute(const double gt[6], int width, int height,
                      OGRSpatialReferenceH srs, tsd_cells *out, char *msg,
                      size_t msg_size);

void tsd_cells_free(tsd_cells *c);

#ifdef __cplusplus
}
#endif

#endif
