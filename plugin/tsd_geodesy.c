/* Cell sizes in metres from a geotransform and a CRS. */
#include "tsd_geodesy.h"

#include "tsd_text.h"

#include <cpl_error.h>
#include <geodesic.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A grid-registered (node) grid, as ETOPO1's "_g_" ones, has rows centred
 * on a pole, whose cells reach half a cell past it, and, global, a last
 * column that repeats the first meridian. Where that is all that takes a
 * geographic DEM (north-up gt) past the Earth's limits, say so in what and
 * fill the crop (-projwin) that removes them; else 0. */
static int grid_registered(const double gt[6], int width, int height, double crop[4],
                           char *what, size_t n)
{
    double top = gt[3], bottom = gt[3] + height * gt[5], cell = fabs(gt[5]);
    double dlon = fabs(gt[1]), x1 = gt[0] + width * gt[1];
    int north = top > 90 + 1e-9 && top - 0.5 * cell <= 90 + 1e-9;
    int south = bottom < -90 - 1e-9 && bottom + 0.5 * cell >= -90 - 1e-9;
    int meridian = width * dlon > 360 + 1e-9 && (width - 1) * dlon <= 360 + 1e-9;
    crop[0] = fmin(gt[0], x1);
    crop[1] = north ? top - cell : top;
    crop[2] = fmax(gt[0], x1) - (meridian ? dlon : 0);
    crop[3] = south ? bottom + cell : bottom;
    if (!(north || south || meridian) || fabs(crop[1]) > 90 + 1e-9 ||
        fabs(crop[3]) > 90 + 1e-9 || !(crop[1] > crop[3]) || !(crop[2] > crop[0]))
        return 0;
    const char *rows = north && south ? "its northern and southern rows lie on the poles"
                       : north             ? "its northern row lies on the pole"
                       : south             ? "its southern row lies on the pole"
                                           : "";
    snprintf(what, n, "%s%s%s", rows, *rows && meridian ? ", " : "",
             !meridian ? "" : *rows ? "its last column on the first meridian again"
                                    : "its last column lies on the first meridian again");
    return 1;
}

/* Geodesic cell sizes of a geographic DEM; gt in degrees. */
static ts_status geographic(const double gt[6], int width, int height, double a,
                      double invf, tsd_cells *c, char *msg, size_t n)
{
    struct geod_geodesic g;
    double top = gt[3], bottom = gt[3] + height * gt[5];
    double dlon = fabs(gt[1]), crop[4];
    char what[160];
    if (grid_registered(gt, width, height, crop, what, sizeof what))
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM reaches beyond the Earth (latitudes %g to %g, %g degrees of "
                    "longitude): %s, as in a grid-registered grid; crop those cells off, e.g. "
                    "gdal_translate -projwin %.10g %.10g %.10g %.10g dem.tif cropped.tif",
                    bottom, top, width * dlon, what, crop[0], crop[1], crop[2], crop[3]);
    if (fabs(top) > 90 + 1e-9 || fabs(bottom) > 90 + 1e-9)
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM reaches beyond the poles (latitudes %g to %g); its "
                    "geotransform is not in degrees of a geographic CRS",
                    bottom, top);
    if (width * dlon > 360 + 1e-9)
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM spans %g degrees of longitude (cell %g degrees), "
                    "more than the whole Earth", width * dlon, dlon);
    geod_init(&g, a, invf != 0 ? 1.0 / invf : 0.0);
    c->cell_x_row = malloc((size_t)height * sizeof *c->cell_x_row);
    if (!c->cell_x_row)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory for %d rows", height);
    double lon0 = gt[0] + 0.5 * width * gt[1];
    for (int y = 0; y < height; y++) {
        double lat = gt[3] + (y + 0.5) * gt[5];
        double s12 = 0;
        geod_inverse(&g, lat, lon0, lat, lon0 + dlon, &s12, NULL, NULL);
        /* a row at a pole has no width: keep it positive and tiny */
        if (!(s12 > 1e-6 * a * dlon * M_PI / 180))
            s12 = 1e-6 * a * dlon * M_PI / 180;
        c->cell_x_row[y] = s12; /* gt is north-up here: row 0 = north */
    }
    double ns = 0;
    geod_inverse(&g, top, lon0, bottom, lon0, &ns, NULL, NULL);
    c->cell_y = ns / height;
    c->cell_x = c->cell_x_row[height / 2];
    if (!(c->cell_y > 0))
        return tsd_fail(msg, n, TS_ERR_ARG, "cannot compute the north-south cell size "
                    "(latitudes %g to %g)", bottom, top);
    return TS_OK;
}

/* A projected CRS's transform to its own geographic CRS (fwd) and back
 * (inv, where asked), both in longitude-latitude order; 0, with neither
 * left, where PROJ has none. */
static int lonlat_transforms(OGRSpatialReferenceH srs, OGRCoordinateTransformationH *fwd,
                             OGRCoordinateTransformationH *inv)
{
    *fwd = NULL;
    if (inv)
        *inv = NULL;
    OGRSpatialReferenceH geo = OSRCloneGeogCS(srs);
    if (!geo)
        return 0;
    OSRSetAxisMappingStrategy(geo, OAMS_TRADITIONAL_GIS_ORDER);
    OGRSpatialReferenceH src = OSRClone(srs);
    OSRSetAxisMappingStrategy(src, OAMS_TRADITIONAL_GIS_ORDER);
    *fwd = OCTNewCoordinateTransformation(src, geo);
    if (inv)
        *inv = OCTNewCoordinateTransformation(geo, src);
    OSRDestroySpatialReference(src);
    OSRDestroySpatialReference(geo); /* the transforms hold their own */
    if (*fwd && (!inv || *inv))
        return 1;
    if (*fwd)
        OCTDestroyCoordinateTransformation(*fwd);
    if (inv && *inv)
        OCTDestroyCoordinateTransformation(*inv);
    *fwd = NULL;
    if (inv)
        *inv = NULL;
    return 0;
}

/* Lengths on the ground of a projected DEM: its CRS to longitude and
 * latitude and the ellipsoid's geodesics. */
typedef struct {
    OGRCoordinateTransformationH fwd;
    struct geod_geodesic g;
} ground_ctx;

static void ground_close(ground_ctx *t)
{
    if (t->fwd)
        OCTDestroyCoordinateTransformation(t->fwd);
    t->fwd = NULL;
}

static int ground_open(ground_ctx *t, OGRSpatialReferenceH srs)
{
    memset(t, 0, sizeof *t);
    OGRErr e1 = OGRERR_NONE, e2 = OGRERR_NONE;
    double a = OSRGetSemiMajor(srs, &e1), invf = OSRGetInvFlattening(srs, &e2);
    if (e1 != OGRERR_NONE || e2 != OGRERR_NONE || !(a > 0) || !(invf >= 0))
        return 0;
    geod_init(&t->g, a, invf != 0 ? 1.0 / invf : 0.0);
    CPLPushErrorHandler(CPLQuietErrorHandler); /* a failure is ours to word */
    const int ok = lonlat_transforms(srs, &t->fwd, NULL);
    CPLPopErrorHandler();
    return ok;
}

/* The ground lengths of the n segments (x0, y0)-(x1, y1) of the DEM's pixel
 * space (x, y: columns and rows from its top-left corner, as gt maps them)
 * into len; 0 where PROJ cannot place an end. */
static int ground_lengths(const ground_ctx *t, const double gt[6], int n, const double *x0,
                          const double *y0, const double *x1, const double *y1, double *len)
{
    double *X = malloc((size_t)2 * n * sizeof *X), *Y = malloc((size_t)2 * n * sizeof *Y);
    double *Z = calloc((size_t)2 * n, sizeof *Z);
    int *ok = malloc((size_t)2 * n * sizeof *ok), good = X && Y && Z && ok;
    for (int i = 0; good && i < n; i++) {
        X[2 * i] = gt[0] + x0[i] * gt[1];
        Y[2 * i] = gt[3] + y0[i] * gt[5];
        X[2 * i + 1] = gt[0] + x1[i] * gt[1];
        Y[2 * i + 1] = gt[3] + y1[i] * gt[5];
    }
    if (good) {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        good = OCTTransformEx(t->fwd, 2 * n, X, Y, Z, ok) != 0;
        CPLPopErrorHandler();
    }
    for (int i = 0; good && i < n; i++) {
        const int a = 2 * i, b = 2 * i + 1;
        if (!ok[a] || !ok[b] || !isfinite(X[a] + Y[a] + X[b] + Y[b]) || fabs(Y[a]) > 90 ||
            fabs(Y[b]) > 90) {
            good = 0;
            break;
        }
        len[i] = 0;
        geod_inverse(&t->g, Y[a], X[a], Y[b], X[b], &len[i], NULL, NULL);
        good = len[i] > 0;
    }
    free(X);
    free(Y);
    free(Z);
    free(ok);
    return good;
}

/* The projection's scale (grid length over ground length) at nine cells
 * of the DEM, east-west and north-south: its range into c->scale_lo/hi,
 * how much the east-west length varies across the central row's columns
 * (across) and the north-south length along the central column (along);
 * 0 where PROJ cannot place a point. */
static int ground_scale(const ground_ctx *t, const double gt[6], int width, int height,
                        tsd_cells *c, double *across, double *along)
{
    const double fx[3] = {0.5, 0.5 * width, width - 0.5};
    const double fy[3] = {0.5, 0.5 * height, height - 0.5};
    double x0[18], y0[18], x1[18], y1[18], len[18], grid[18];
    for (int j = 0, i = 0; j < 3; j++)
        for (int k = 0; k < 3; k++, i += 2) {
            x0[i] = fx[k] - 0.5, x1[i] = fx[k] + 0.5, y0[i] = y1[i] = fy[j];
            grid[i] = fabs(gt[1]) * c->unit_to_m;
            x0[i + 1] = x1[i + 1] = fx[k], y0[i + 1] = fy[j] - 0.5, y1[i + 1] = fy[j] + 0.5;
            grid[i + 1] = fabs(gt[5]) * c->unit_to_m;
        }
    if (!ground_lengths(t, gt, 18, x0, y0, x1, y1, len))
        return 0;
    c->scale_lo = INFINITY;
    c->scale_hi = 0;
    for (int i = 0; i < 18; i++) {
        const double k = grid[i] / len[i];
        c->scale_lo = fmin(c->scale_lo, k);
        c->scale_hi = fmax(c->scale_hi, k);
    }
    /* the central row's east-west cells: 6, 8 and 10; the central
     * column's north-south ones: 3, 9 and 15 */
    *across = fmax(len[6], fmax(len[8], len[10])) / fmin(len[6], fmin(len[8], len[10])) - 1;
    *along = fmax(len[3], fmax(len[9], len[15])) / fmin(len[3], fmin(len[9], len[15])) - 1;
    return 1;
}

/* A projected DEM's cells on the ground (CELL_SIZES=ground, or auto where
 * the scale departs from 1 by more than 1 %): east-west per row and the
 * north-south mean, both along the central column, as geographic() does. */
static ts_status projected(const double gt[6], int width, int height,
                           OGRSpatialReferenceH srs, tsd_cell_sizes mode, tsd_cells *c,
                           char *msg, size_t n)
{
    c->cell_x = fabs(gt[1]) * c->unit_to_m;
    c->cell_y = fabs(gt[5]) * c->unit_to_m;
    if (mode == TSD_CELLS_GRID || OSRIsLocal(srs))
        return TS_OK;
    ground_ctx t;
    double across = 0, along = 0;
    if (!ground_open(&t, srs) || !ground_scale(&t, gt, width, height, c, &across, &along)) {
        ground_close(&t);
        c->scale_lo = c->scale_hi = 0;
        if (mode == TSD_CELLS_AUTO)
            return TS_OK; /* nothing known against the grid's sizes */
        return tsd_fail(msg, n, TS_ERR_ARG, "CELL_SIZES=ground: PROJ cannot take the DEM's "
                        "cells to longitude and latitude; use CELL_SIZES=grid");
    }
    if (mode == TSD_CELLS_AUTO && fabs(c->scale_lo - 1) <= 0.01 && fabs(c->scale_hi - 1) <= 0.01) {
        ground_close(&t);
        return TS_OK;
    }
    c->ground = 1;
    double *x0 = malloc((size_t)(height + 1) * sizeof *x0);
    double *y0 = malloc((size_t)(height + 1) * sizeof *y0);
    double *x1 = malloc((size_t)(height + 1) * sizeof *x1);
    double *y1 = malloc((size_t)(height + 1) * sizeof *y1);
    c->cell_x_row = malloc((size_t)(height + 1) * sizeof *c->cell_x_row);
    ts_status st = TS_OK;
    if (!x0 || !y0 || !x1 || !y1 || !c->cell_x_row) {
        st = tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory for %d rows", height);
        goto done;
    }
    const double xc = 0.5 * width;
    for (int y = 0; y < height; y++) {
        /* row y of the core's grid (row 0 = north) */
        double py = c->flip_y ? height - (y + 0.5) : y + 0.5;
        x0[y] = xc - 0.5, x1[y] = xc + 0.5, y0[y] = y1[y] = py;
    }
    x0[height] = x1[height] = xc, y0[height] = 0, y1[height] = height;
    if (!ground_lengths(&t, gt, height + 1, x0, y0, x1, y1, c->cell_x_row)) {
        if (mode == TSD_CELLS_GROUND) {
            st = tsd_fail(msg, n, TS_ERR_ARG, "CELL_SIZES=ground: PROJ cannot take every "
                          "row of the DEM's central column to longitude and latitude; use "
                          "CELL_SIZES=grid");
            goto done;
        }
        /* auto: what the DEM opened with before CELL_SIZES, said */
        free(c->cell_x_row);
        c->cell_x_row = NULL;
        c->ground = 0;
        snprintf(c->warning, sizeof c->warning,
                 "the projection's scale is %.4f to %.4f over the DEM, but PROJ cannot take "
                 "every row of its central column to longitude and latitude, so its cells "
                 "are the grid's, not the ground's", c->scale_lo, c->scale_hi);
        goto done;
    }
    c->cell_y = c->cell_x_row[height] / height;
    c->cell_x = c->cell_x_row[height / 2];
    /* what one length per row (east-west) and one for the whole DEM
     * (north-south) cannot hold */
    if (across > 0.01 || along > 0.05)
        snprintf(c->warning, sizeof c->warning,
                 "the projection's scale varies by %.1f %% across the DEM's columns and its "
                 "cells' north-south length by %.1f %% along its rows; they are measured "
                 "along the central column, north-south as their mean: crop the DEM or "
                 "warp it to a local projection (e.g. UTM) for exact slopes at its edges",
                 100 * across, 100 * along);
done:
    free(x0);
    free(y0);
    free(x1);
    free(y1);
    ground_close(&t);
    return st;
}

ts_status tsd_cells_compute(const double gt[6], int width, int height,
                      OGRSpatialReferenceH srs, tsd_cell_sizes mode, tsd_cells *c,
                      char *msg, size_t n)
{
    memset(c, 0, sizeof *c);
    if (width < 1 || height < 1)
        return tsd_fail(msg, n, TS_ERR_ARG, "the DEM has no cells (%d x %d)", width, height);
    for (int i = 0; i < 6; i++)
        if (!isfinite(gt[i]))
            return tsd_fail(msg, n, TS_ERR_ARG, "the DEM's geotransform is not finite");
    double scale = fmax(fabs(gt[1]), fabs(gt[5]));
    if (fabs(gt[2]) > 1e-9 * scale || fabs(gt[4]) > 1e-9 * scale)
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM's geotransform is rotated or sheared (GT[2] = %g, "
                    "GT[4] = %g); terrashade needs a north-up grid: warp it first, "
                    "e.g. gdalwarp dem.tif north_up.tif", gt[2], gt[4]);
    if (gt[1] == 0 || gt[5] == 0)
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM's pixel size is zero (GT[1] = %g, GT[5] = %g)",
                    gt[1], gt[5]);
    c->flip_x = gt[1] < 0;
    c->flip_y = gt[5] > 0;
    c->unit_to_m = 1;
    if (srs && OSRIsGeographic(srs)) {
        if (mode == TSD_CELLS_GRID)
            return tsd_fail(msg, n, TS_ERR_ARG, "CELL_SIZES=grid: the DEM's CRS is "
                            "geographic, whose cells (degrees) are not lengths; use "
                            "CELL_SIZES=auto");
        OGRErr e1 = OGRERR_NONE, e2 = OGRERR_NONE;
        double a = OSRGetSemiMajor(srs, &e1);
        double invf = OSRGetInvFlattening(srs, &e2);
        double rad = OSRGetAngularUnits(srs, NULL); /* radians per unit */
        if (e1 != OGRERR_NONE || e2 != OGRERR_NONE || !(a > 0) || !(rad > 0))
            return tsd_fail(msg, n, TS_ERR_ARG, "cannot read the ellipsoid of the DEM's "
                        "geographic CRS (a = %g, 1/f = %g)", a, invf);
        double deg = rad * 180.0 / M_PI, g[6];
        for (int i = 0; i < 6; i++)
            g[i] = gt[i] * deg;
        /* the geotransform of a north-up geographic raster: x = longitude */
        if (c->flip_y) {
            g[3] = g[3] + height * g[5];
            g[5] = -g[5];
        }
        c->kind = TSD_CRS_GEOGRAPHIC;
        return geographic(g, width, height, a, invf, c, msg, n);
    }
    if (srs && (OSRIsProjected(srs) || OSRIsLocal(srs))) {
        c->kind = TSD_CRS_PROJECTED;
        c->unit_to_m = OSRGetLinearUnits(srs, NULL);
        if (!(c->unit_to_m > 0))
            return tsd_fail(msg, n, TS_ERR_ARG, "the DEM's CRS has an invalid linear unit "
                        "(%g metres)", c->unit_to_m);
        if (mode == TSD_CELLS_GROUND && OSRIsLocal(srs))
            return tsd_fail(msg, n, TS_ERR_ARG, "CELL_SIZES=ground: the DEM's CRS is a "
                            "local one, without longitudes and latitudes; use "
                            "CELL_SIZES=grid");
        return projected(gt, width, height, srs, mode, c, msg, n);
    }
    if (srs && OSRIsGeocentric(srs))
        return tsd_fail(msg, n, TS_ERR_ARG, "the DEM's CRS is neither projected nor geographic "
                    "(it is geocentric); warp it to a projected CRS first");
    if (mode == TSD_CELLS_GROUND)
        return tsd_fail(msg, n, TS_ERR_ARG, "CELL_SIZES=ground: the DEM has no CRS, so its "
                        "cells cannot be measured on the ground; give it one "
                        "(gdal_edit.py -a_srs)");
    c->kind = TSD_CRS_NONE;
    snprintf(c->warning, sizeof c->warning,
             "the DEM has no CRS: its cell size (%g x %g) is taken as metres",
             fabs(gt[1]), fabs(gt[5]));
    c->cell_x = fabs(gt[1]) * c->unit_to_m;
    c->cell_y = fabs(gt[5]) * c->unit_to_m;
    return TS_OK;
}

tsd_cell_sizes tsd_cells_mode(const tsd_cells *c)
{
    if (c->kind != TSD_CRS_PROJECTED)
        return TSD_CELLS_AUTO;
    return c->ground ? TSD_CELLS_GROUND : TSD_CELLS_GRID;
}

double tsd_cells_min_x(const tsd_cells *c, int height)
{
    double m = c->cell_x;
    for (int y = 0; c->cell_x_row && y < height; y++)
        m = c->cell_x_row[y] < m ? c->cell_x_row[y] : m;
    return m;
}

void tsd_cells_free(tsd_cells *c)
{
    if (c) {
        free(c->cell_x_row);
        c->cell_x_row = NULL;
    }
}

/* ------------------------------------------------------------- sites */

/* Longitude into [-180, 180]. */
static double wrap_lon(double lon)
{
    lon = fmod(lon + 180.0, 360.0);
    if (lon < 0)
        lon += 360.0;
    return lon - 180.0;
}

/* The lattice's nodes a side: every 32 cells or so, at most 65, unless
 * grow_sites asks for more; odd, so that the middle node, whose sun the
 * metadata reports, is the DEM's centre (with 2 nodes it was a corner). */
static int site_nodes(int cells, int at_least)
{
    if (cells < 2)
        return 1;
    int k = cells / 32 + 2;
    k = k > 65 ? 65 : k;
    k = k < at_least ? at_least : k;
    return k + (k % 2 == 0);
}

static void site_grid(tsd_sites *s, int width, int height)
{
    s->x0 = s->nx > 1 ? 0.5 : 0.5 * width;
    s->y0 = s->ny > 1 ? 0.5 : 0.5 * height;
    s->dx = s->nx > 1 ? (width - 1.0) / (s->nx - 1) : 1.0;
    s->dy = s->ny > 1 ? (height - 1.0) / (s->ny - 1) : 1.0;
}

/* Degrees of arc, about, between sites a and b: the sun's elevation and
 * azimuth curve with the hour angle and the latitude, so the bilinear
 * interpolation's error grows as the square of this. */
static double site_step(const tsd_sites *s, size_t a, size_t b)
{
    double lat = fabs(s->lat[b] - s->lat[a]);
    double lon = fabs(remainder(s->lon[b] - s->lon[a], 360.0)) *
                 cos(0.5 * (s->lat[a] + s->lat[b]) * M_PI / 180.0);
    return lat > lon ? lat : lon;
}

/* Nodes a side so that neighbours lie at most SITE_MAX_STEP_DEG apart
 * (one per cell at most, SITE_MAX_NODES a side): on a DEM of coarse cells
 * or a continent, 32 cells can span tens of degrees, where interpolating
 * the sun across them put it below the horizon for hours at noon.
 * Returns 1 if nx or ny grew. */
#define SITE_MAX_STEP_DEG 2.0
#define SITE_MAX_NODES 181
static int finer_nodes(int nodes, double step, int cells)
{
    int cap = cells < SITE_MAX_NODES ? cells : SITE_MAX_NODES;
    if (step <= SITE_MAX_STEP_DEG || nodes >= cap)
        return nodes;
    int k = (nodes - 1) * (int)ceil(step / SITE_MAX_STEP_DEG) + 1;
    return k < cap ? k : cap;
}

static int grow_sites(const tsd_sites *s, int width, int height, int *nx, int *ny)
{
    double sx = 0, sy = 0;
    for (int j = 0; j < s->ny; j++)
        for (int i = 0; i < s->nx; i++) {
            size_t k = (size_t)j * s->nx + i;
            if (i + 1 < s->nx)
                sx = fmax(sx, site_step(s, k, k + 1));
            if (j + 1 < s->ny)
                sy = fmax(sy, site_step(s, k, k + s->nx));
        }
    *nx = site_nodes(width, finer_nodes(s->nx, sx, width));
    *ny = site_nodes(height, finer_nodes(s->ny, sy, height));
    return *nx != s->nx || *ny != s->ny;
}

static ts_status sites_fill(const double gt[6], int width, int height, int geographic,
                            double deg, OGRCoordinateTransformationH fwd,
                            OGRCoordinateTransformationH inv, const tsd_cells *cells,
                            tsd_sites *s, char *msg, size_t n);

ts_status tsd_sites_compute(const double gt[6], int width, int height,
                      OGRSpatialReferenceH srs, const tsd_cells *cells, int per_cell,
                      tsd_sites *s, char *msg, size_t n)
{
    memset(s, 0, sizeof *s);
    if (!srs)
        return tsd_fail(msg, n, TS_ERR_ARG, "the DEM has no CRS, so the sun's position over it is "
                    "unknown: give it a CRS (gdal_edit.py -a_srs) or use "
                    "SUN_AZIMUTH and SUN_ELEVATION");
    int geographic = OSRIsGeographic(srs);
    if (!geographic && !OSRIsProjected(srs))
        return tsd_fail(msg, n, TS_ERR_ARG, "the DEM's CRS is neither geographic nor projected (a "
                    "local or engineering CRS), so its longitudes and latitudes are "
                    "unknown; use SUN_AZIMUTH and SUN_ELEVATION instead");
    OGRCoordinateTransformationH fwd = NULL, inv = NULL;
    if (!geographic && !lonlat_transforms(srs, &fwd, &inv))
        return tsd_fail(msg, n, TS_ERR_ARG, "PROJ cannot transform the DEM's CRS to longitude and "
                    "latitude, so the sun's position over it is unknown");
    double deg = geographic ? OSRGetAngularUnits(srs, NULL) * 180.0 / M_PI : 1.0;
    int nx = per_cell ? site_nodes(width, 1) : 1, ny = per_cell ? site_nodes(height, 1) : 1;
    ts_status rc;
    /* a finer lattice where the first one's nodes lie too far apart (the
     * second pass's spacing follows the first's, so it rarely grows again) */
    for (int pass = 0;; pass++) {
        s->nx = nx;
        s->ny = ny;
        site_grid(s, width, height);
        rc = sites_fill(gt, width, height, geographic, deg, fwd, inv, cells, s, msg, n);
        if (rc != TS_OK || !per_cell || pass == 3 || !grow_sites(s, width, height, &nx, &ny))
            break;
        tsd_sites_free(s);
    }
    if (fwd) OCTDestroyCoordinateTransformation(fwd);
    if (inv) OCTDestroyCoordinateTransformation(inv);
    if (rc != TS_OK)
        tsd_sites_free(s);
    return rc;
}

/* The longitude, latitude and grid azimuth of true north of s's nodes. */
static ts_status sites_fill(const double gt[6], int width, int height, int geographic,
                            double deg, OGRCoordinateTransformationH fwd,
                            OGRCoordinateTransformationH inv, const tsd_cells *cells,
                            tsd_sites *s, char *msg, size_t n)
{
    size_t nodes = (size_t)s->nx * s->ny;
    s->lon = malloc(nodes * sizeof *s->lon);
    s->lat = malloc(nodes * sizeof *s->lat);
    s->north = malloc(nodes * sizeof *s->north);
    if (!s->lon || !s->lat || !s->north)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory for %zu sun sites", nodes);
    ts_status rc = TS_OK;
    for (int j = 0; j < s->ny && rc == 0; j++)
        for (int i = 0; i < s->nx && rc == 0; i++) {
            /* core pixel -> DEM pixel -> georeferenced */
            double cx = s->x0 + i * s->dx, cy = s->y0 + j * s->dy;
            double px = cells->flip_x ? width - cx : cx;
            double py = cells->flip_y ? height - cy : cy;
            double X = gt[0] + px * gt[1] + py * gt[2];
            double Y = gt[3] + px * gt[4] + py * gt[5];
            double lon, lat, north = 0.0;
            if (geographic) {
                lon = X * deg;
                lat = Y * deg;
            } else {
                double x = X, y = Y, z = 0;
                if (!OCTTransform(fwd, 1, &x, &y, &z) || !isfinite(x) || !isfinite(y)) {
                    rc = tsd_fail(msg, n, TS_ERR_ARG,
                                  "PROJ cannot find the longitude and latitude of "
                                  "the DEM's point (%.10g, %.10g), so the sun's position "
                                  "over it is unknown", X, Y);
                    break;
                }
                lon = x;
                lat = y;
                /* grid azimuth of true north: a small step north, back */
                double step = lat + 1e-4 <= 90.0 ? 1e-4 : -1e-4;
                double x2 = lon, y2 = lat + step, z2 = 0;
                if (!OCTTransform(inv, 1, &x2, &y2, &z2) || !isfinite(x2) || !isfinite(y2)) {
                    rc = tsd_fail(msg, n, TS_ERR_ARG,
                                  "PROJ cannot transform a point north of (%.8g, "
                                  "%.8g) back into the DEM's CRS", lon, lat);
                    break;
                }
                double dx = (x2 - X) * (step > 0 ? 1 : -1), dy = (y2 - Y) * (step > 0 ? 1 : -1);
                north = atan2(dx, dy) * 180.0 / M_PI;
            }
            if (!isfinite(lat) || lat < -90.0 - 1e-9 || lat > 90.0 + 1e-9) {
                rc = tsd_fail(msg, n, TS_ERR_ARG,
                              "the DEM's georeferencing puts a point at latitude %g, "
                              "beyond +/-90 degrees: the geotransform or the CRS is wrong",
                              lat);
                break;
            }
            lat = lat > 90.0 ? 90.0 : lat < -90.0 ? -90.0 : lat;
            size_t k = (size_t)j * s->nx + i;
            s->lon[k] = wrap_lon(lon);
            s->lat[k] = lat;
            s->north[k] = north;
        }
    return rc;
}

double tsd_sites_reach(const double gt[6], int width, int height, OGRSpatialReferenceH srs,
                       const tsd_cells *cells, double lon0, double lat0, double *turn)
{
    tsd_sites s;
    char msg[256];
    if (turn)
        *turn = 0;
    if (tsd_sites_compute(gt, width, height, srs, cells, 1, &s, msg, sizeof msg) != TS_OK)
        return 0;
    const double rad = M_PI / 180;
    const double north0 = s.north[(size_t)(s.ny / 2) * s.nx + s.nx / 2]; /* the centre's */
    double reach = 0, most = 0;
    for (size_t k = 0; k < (size_t)s.nx * s.ny; k++) {
        /* the central angle, by the haversine (well conditioned when small) */
        double sp = sin((s.lat[k] - lat0) * rad / 2), sl = sin((s.lon[k] - lon0) * rad / 2);
        double a = sp * sp + cos(s.lat[k] * rad) * cos(lat0 * rad) * sl * sl;
        double angle = 2 * asin(sqrt(a < 1 ? a : 1)) / rad;
        reach = angle > reach ? angle : reach;
        /* a distant sun's true azimuth turns with the meridians, its grid
         * azimuth by that plus the turn of grid north (they cancel on a
         * conformal grid, not on a geographic one near a pole) */
        double dlon = remainder(s.lon[k] - lon0, 360.0);
        double t = fabs(remainder(dlon * sin(0.5 * (s.lat[k] + lat0) * rad) + s.north[k] -
                                  north0, 360.0));
        most = t > most ? t : most;
    }
    tsd_sites_free(&s);
    if (turn)
        *turn = most;
    return reach;
}

void tsd_sites_free(tsd_sites *s)
{
    if (!s)
        return;
    free(s->lon);
    free(s->lat);
    free(s->north);
    s->lon = s->lat = s->north = NULL;
}
