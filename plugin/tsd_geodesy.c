/* Cell sizes in metres from a geotransform and a CRS. */
#include "tsd_geodesy.h"

#include "tsd_text.h"

#include <cpl_error.h>
#include <geodesic.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdarg.h>
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
    /* a row centred on a pole reaches half a cell past it; a hair past is
     * rounding (geographic() takes it), a few tenths of a cell something else */
    int north = top - 90 >= 0.25 * cell && top - 0.5 * cell <= 90 + 1e-9;
    int south = -90 - bottom >= 0.25 * cell && bottom + 0.5 * cell >= -90 - 1e-9;
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
    /* past a pole by a thousandth of a cell or less: rounding of the
     * geotransform (90 + 1e-13), taken as the pole */
    const double hair = fmax(1e-9, 1e-3 * fabs(gt[5]));
    if (fabs(top) > 90 + hair || fabs(bottom) > 90 + hair) {
        const double past = fmax(fabs(top), fabs(bottom)) - 90;
        if (past < fabs(gt[5]))
            return tsd_fail(msg, n, TS_ERR_ARG,
                            "the DEM reaches %.6g degrees (%.2f of a cell) past the pole "
                            "(latitudes %.10g to %.10g): its geotransform's origin or pixel "
                            "size is off; set them right (gdal_edit.py -a_ullr or -tr)",
                            past, past / fabs(gt[5]), bottom, top);
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM reaches beyond the poles (latitudes %g to %g); its "
                    "geotransform is not in degrees of a geographic CRS",
                    bottom, top);
    }
    top = fmin(top, 90);
    bottom = fmax(bottom, -90);
    if (width * dlon > 360 + 1e-9)
        return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM spans %g degrees of longitude (cell %g degrees), "
                    "more than the whole Earth", width * dlon, dlon);
    geod_init(&g, a, invf != 0 ? 1.0 / invf : 0.0);
    c->cell_x_row = malloc((size_t)height * sizeof *c->cell_x_row);
    if (!c->cell_x_row)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory for %d rows", height);
    double lon0 = gt[0] + 0.5 * width * gt[1];
    /* an origin many turns round (lon 1e13 and beyond): lon0 + dlon would
     * round to lon0, the parallels' widths to nothing (an svf of cliffs);
     * the same meridian within a turn, exactly (remainder is exact) */
    if (fabs(lon0) > 360)
        lon0 = remainder(lon0, 360.0);
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

/* tsd_geodesy.h */
void tsd_geographic_units(OGRSpatialReferenceH srs, double *unit_deg, double *pm_deg)
{
    const double rad = OSRGetAngularUnits(srs, NULL); /* radians per unit */
    *unit_deg = rad > 0 ? rad * 180.0 / M_PI : 1.0;
    const double pm = OSRGetPrimeMeridian(srs, NULL); /* degrees */
    *pm_deg = isfinite(pm) ? pm : 0.0;
}

/* tsd_geodesy.h */
int tsd_lonlat_open(OGRSpatialReferenceH srs, int with_inv, tsd_lonlat *t)
{
    memset(t, 0, sizeof *t);
    OGRSpatialReferenceH geo = NULL;
    if (OSRIsDerivedGeographic(srs)) {
        /* a rotated pole: OSRCloneGeogCS keeps the rotation, so its base is
         * built here, on its ellipsoid, in degrees from Greenwich */
        OGRErr e1 = OGRERR_NONE, e2 = OGRERR_NONE;
        const double a = OSRGetSemiMajor(srs, &e1), invf = OSRGetInvFlattening(srs, &e2);
        geo = OSRNewSpatialReference(NULL);
        if (geo && (e1 != OGRERR_NONE || e2 != OGRERR_NONE ||
                    OSRSetGeogCS(geo, "base of a rotated pole", "unknown", "unknown", a, invf,
                                 "Greenwich", 0.0, "degree", M_PI / 180) != OGRERR_NONE)) {
            OSRDestroySpatialReference(geo);
            geo = NULL;
        }
    } else {
        geo = OSRCloneGeogCS(srs);
    }
    if (!geo)
        return 0;
    tsd_geographic_units(geo, &t->unit_deg, &t->pm_deg);
    OSRSetAxisMappingStrategy(geo, OAMS_TRADITIONAL_GIS_ORDER);
    OGRSpatialReferenceH src = OSRClone(srs);
    OSRSetAxisMappingStrategy(src, OAMS_TRADITIONAL_GIS_ORDER);
    t->fwd = OCTNewCoordinateTransformation(src, geo);
    if (with_inv)
        t->inv = OCTNewCoordinateTransformation(geo, src);
    OSRDestroySpatialReference(src);
    OSRDestroySpatialReference(geo); /* the transforms hold their own */
    if (t->fwd && (!with_inv || t->inv))
        return 1;
    tsd_lonlat_close(t);
    return 0;
}

int tsd_lonlat_to(const tsd_lonlat *t, int n, double *x, double *y, int *ok)
{
    double *z = calloc(n > 0 ? (size_t)n : 1, sizeof *z);
    if (!z)
        return 0;
    const int all = OCTTransformEx(t->fwd, n, x, y, z, ok) != 0;
    free(z);
    for (int i = 0; i < n; i++) {
        x[i] = x[i] * t->unit_deg + t->pm_deg;
        y[i] *= t->unit_deg;
    }
    return all;
}

int tsd_lonlat_from(const tsd_lonlat *t, int n, double *x, double *y, int *ok)
{
    double *z = calloc(n > 0 ? (size_t)n : 1, sizeof *z);
    if (!z)
        return 0;
    for (int i = 0; i < n; i++) {
        x[i] = (x[i] - t->pm_deg) / t->unit_deg;
        y[i] /= t->unit_deg;
    }
    const int all = OCTTransformEx(t->inv, n, x, y, z, ok) != 0;
    free(z);
    return all;
}

void tsd_lonlat_close(tsd_lonlat *t)
{
    if (t->fwd)
        OCTDestroyCoordinateTransformation(t->fwd);
    if (t->inv)
        OCTDestroyCoordinateTransformation(t->inv);
    t->fwd = t->inv = NULL;
}

/* Lengths on the ground of a projected DEM: its CRS to longitude and
 * latitude and the ellipsoid's geodesics. */
typedef struct {
    tsd_lonlat ll;
    struct geod_geodesic g;
} ground_ctx;

static void ground_close(ground_ctx *t)
{
    tsd_lonlat_close(&t->ll);
}

static int ground_open(ground_ctx *t, OGRSpatialReferenceH srs)
{
    memset(t, 0, sizeof *t);
    if (OSRIsLocal(srs)) /* no ellipsoid (PROJ said so as an ERROR) */
        return 0;
    OGRErr e1 = OGRERR_NONE, e2 = OGRERR_NONE;
    double a = OSRGetSemiMajor(srs, &e1), invf = OSRGetInvFlattening(srs, &e2);
    if (e1 != OGRERR_NONE || e2 != OGRERR_NONE || !(a > 0) || !(invf >= 0))
        return 0;
    geod_init(&t->g, a, invf != 0 ? 1.0 / invf : 0.0);
    CPLPushErrorHandler(CPLQuietErrorHandler); /* a failure is ours to word */
    const int ok = tsd_lonlat_open(srs, 0, &t->ll);
    CPLPopErrorHandler();
    return ok;
}

/* The ends of the n segments (x0, y0)-(x1, y1) of the DEM's pixel space,
 * as longitude X and latitude Y (2n each: segment i's at 2i and 2i + 1),
 * and which of them PROJ could place (ok); 0 unless it placed them all. */
static int segments_lonlat(const ground_ctx *t, const double gt[6], int n, const double *x0,
                           const double *y0, const double *x1, const double *y1, double *X,
                           double *Y, int *ok)
{
    for (int i = 0; i < n; i++) {
        X[2 * i] = gt[0] + x0[i] * gt[1];
        Y[2 * i] = gt[3] + y0[i] * gt[5];
        X[2 * i + 1] = gt[0] + x1[i] * gt[1];
        Y[2 * i + 1] = gt[3] + y1[i] * gt[5];
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    const int good = tsd_lonlat_to(&t->ll, 2 * n, X, Y, ok);
    CPLPopErrorHandler();
    return good;
}

/* The ground lengths of the n segments (x0, y0)-(x1, y1) of the DEM's pixel
 * space (x, y: columns and rows from its top-left corner, as gt maps them)
 * into len; 0 where PROJ cannot place an end. */
static int ground_lengths(const ground_ctx *t, const double gt[6], int n, const double *x0,
                          const double *y0, const double *x1, const double *y1, double *len)
{
    double *X = malloc((size_t)2 * n * sizeof *X), *Y = malloc((size_t)2 * n * sizeof *Y);
    int *ok = malloc((size_t)2 * n * sizeof *ok), good = X && Y && ok;
    good = good && segments_lonlat(t, gt, n, x0, y0, x1, y1, X, Y, ok);
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
    free(ok);
    return good;
}

/* A point on the ellipsoid's surface in Earth-centred Cartesian metres. */
static void ecef(const struct geod_geodesic *g, double lon, double lat, double out[3])
{
    const double f = lon * M_PI / 180, p = lat * M_PI / 180, e2 = g->f * (2 - g->f);
    const double N = g->a / sqrt(1 - e2 * sin(p) * sin(p));
    out[0] = N * cos(p) * cos(f);
    out[1] = N * cos(p) * sin(f);
    out[2] = N * (1 - e2) * sin(p);
}

/* side x side cells of the DEM, from corner to corner (3: its corners,
 * its edges' middles, its centre): the segments of each one's east-west
 * side (2i) and north-south side (2i + 1) in pixel space, hx and hy cells
 * either side of its centre (0.5: the cell's own sides). */
static void lattice_cells(int width, int height, int side, double hx, double hy, double *x0,
                          double *y0, double *x1, double *y1)
{
    for (int j = 0, i = 0; j < side; j++)
        for (int k = 0; k < side; k++, i += 2) {
            const double fx = 0.5 + (width - 1.0) * k / (side - 1);
            const double fy = 0.5 + (height - 1.0) * j / (side - 1);
            x0[i] = fx - hx, x1[i] = fx + hx, y0[i] = y1[i] = fy;
            x0[i + 1] = x1[i + 1] = fx, y0[i + 1] = fy - hy, y1[i + 1] = fy + hy;
        }
}

/* Cells a side of the lattice the shear is measured on: a world
 * Mollweide's shear lies off its axes, its corners outside its domain. */
#define SKEW_SIDE 5
/* The shortest chord on the ground the shear is measured along, metres. */
#define SKEW_CHORD_M 100.0

/* How far the grid's axes are from a right angle on the ground, at most,
 * over the cells of a SKEW_SIDE^2 lattice that PROJ can place, as the
 * angle between the chords of a cell's two sides in space, which, unlike
 * azimuths, holds at a pole; the number of cells measured. */
static int ground_skew(const ground_ctx *t, const double gt[6], int width, int height,
                       double unit_to_m, double *skew)
{
    enum { CELLS = SKEW_SIDE * SKEW_SIDE };
    double x0[2 * CELLS], y0[2 * CELLS], x1[2 * CELLS], y1[2 * CELLS], X[4 * CELLS],
        Y[4 * CELLS];
    int ok[4 * CELLS], measured = 0;
    /* chords of at least SKEW_CHORD_M: on cells of a nanometre the
     * points' own rounding read 28 degrees of shear */
    const double hx = fmax(0.5, 0.5 * SKEW_CHORD_M / (fabs(gt[1]) * unit_to_m));
    const double hy = fmax(0.5, 0.5 * SKEW_CHORD_M / (fabs(gt[5]) * unit_to_m));
    lattice_cells(width, height, SKEW_SIDE, hx, hy, x0, y0, x1, y1);
    *skew = 0;
    for (int i = 0; i < 4 * CELLS; i++)
        ok[i] = 0;
    segments_lonlat(t, gt, 2 * CELLS, x0, y0, x1, y1, X, Y, ok); /* (the points placed: ok) */
    for (int i = 0; i < CELLS; i++) {
        double v[2][3];
        int placed = 1;
        for (int k = 0; k < 2; k++) {
            const int a = 4 * i + 2 * k, b = a + 1;
            double pa[3], pb[3];
            placed = placed && ok[a] && ok[b] && isfinite(X[a] + Y[a] + X[b] + Y[b]) &&
                     fabs(Y[a]) <= 90 && fabs(Y[b]) <= 90;
            if (!placed)
                break;
            ecef(&t->g, X[a], Y[a], pa);
            ecef(&t->g, X[b], Y[b], pb);
            for (int j = 0; j < 3; j++)
                v[k][j] = pb[j] - pa[j];
        }
        if (!placed)
            continue;
        const double dot = v[0][0] * v[1][0] + v[0][1] * v[1][1] + v[0][2] * v[1][2];
        const double n0 = sqrt(v[0][0] * v[0][0] + v[0][1] * v[0][1] + v[0][2] * v[0][2]);
        const double n1 = sqrt(v[1][0] * v[1][0] + v[1][1] * v[1][1] + v[1][2] * v[1][2]);
        if (!(n0 > 0 && n1 > 0))
            continue;
        const double c = fmax(-1.0, fmin(1.0, dot / (n0 * n1)));
        *skew = fmax(*skew, fabs(acos(c) * 180 / M_PI - 90.0));
        measured++;
    }
    return measured;
}

/* The projection's scale (grid length over ground length) at nine cells
 * of the DEM, east-west and north-south: its range into c->scale_lo/hi,
 * how much the east-west length varies across the central row's columns
 * (across) and the north-south length along the central column (along);
 * 0 where PROJ cannot place a point. */
static int ground_scale(const ground_ctx *t, const double gt[6], int width, int height,
                        tsd_cells *c, double *across, double *along)
{
    double x0[18], y0[18], x1[18], y1[18], len[18], grid[18];
    lattice_cells(width, height, 3, 0.5, 0.5, x0, y0, x1, y1);
    for (int i = 0; i < 18; i += 2) {
        grid[i] = fabs(gt[1]) * c->unit_to_m;
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

/* Add a sentence to the cells' warning: after the one there, where there
 * is one (the shear's hid the scale's: session 58's review). */
static void add_warning(tsd_cells *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void add_warning(tsd_cells *c, const char *fmt, ...)
{
    const size_t used = strlen(c->warning);
    if (used)
        snprintf(c->warning + used, sizeof c->warning - used, "; and ");
    const size_t at = strlen(c->warning);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->warning + at, sizeof c->warning - at, fmt, ap);
    va_end(ap);
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
    if (OSRIsLocal(srs))
        return TS_OK;
    ground_ctx t;
    double across = 0, along = 0;
    const int opened = ground_open(&t, srs);
    if (opened)
        ground_skew(&t, gt, width, height, c->unit_to_m, &c->skew_deg);
    /* one cell size a row and a north-south one cannot hold axes that are
     * not at right angles on the ground: slopes, aspects and shadows turn
     * by as much (Sinusoidal at 84 W 37 N: 41 degrees, a peak's shadow 31
     * degrees off the sun; session 58's CRS audit) */
    if (c->skew_deg > TSD_SKEW_MAX_DEG) {
        ground_close(&t);
        return tsd_fail(msg, n, TS_ERR_ARG,
                        "the DEM's grid axes are up to %.1f degrees from a right angle on "
                        "the ground (its projection shears it there, as Sinusoidal or "
                        "Mollweide do away from their central meridian), which would turn "
                        "slopes, aspects and shadows by as much: warp it to a conformal "
                        "projection first (UTM, e.g. gdalwarp -t_srs EPSG:326NN dem.tif "
                        "utm.tif; for a continent a Lambert conformal conic, for a pole a "
                        "polar stereographic one)", c->skew_deg);
    }
    if (c->skew_deg > TSD_SKEW_WARN_DEG)
        add_warning(c,
                    "the DEM's grid axes are up to %.1f degrees from a right angle on the "
                    "ground (its projection shears it there): slopes, aspects and shadows "
                    "turn by up to as much; warp it to a conformal projection (e.g. UTM) "
                    "for exact directions", c->skew_deg);
    if (!opened || mode == TSD_CELLS_GRID ||
        !ground_scale(&t, gt, width, height, c, &across, &along)) {
        /* (CELL_SIZES=grid: measured for the shear only, grid sizes and no
         * scale, as asked) */
        ground_close(&t);
        c->scale_lo = c->scale_hi = 0;
        if (mode != TSD_CELLS_GROUND)
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
        add_warning(c,
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
        add_warning(c,
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

/* A projected DEM's corners farther than this from its CRS's origin (m),
 * more than twice around the Earth, took GDAL 3.6's Web Mercator inverse
 * seconds a point (1e17 m: an open that never ended; session 57's fuzzing). */
#define TSD_CORNER_MAX_M 1e8

/* Whether the DEM's columns (x) run along the axis that GIS order puts
 * second (latitude, northing): a CRS whose data axes keep its authority's
 * order (EPSG:4326's latitude first: a VRT's dataAxisToSRSAxisMapping="1,2")
 * with the geotransform in that order. Read as longitude, such a DEM's site
 * landed in Antarctica (session 58's CRS audit). (Not the axes' names: a
 * polar stereographic CRS's first axis points "south along 45 E".) */
static int columns_run_north(OGRSpatialReferenceH srs)
{
    OGRSpatialReferenceH gis = OSRClone(srs);
    if (!gis)
        return 0;
    OSRSetAxisMappingStrategy(gis, OAMS_TRADITIONAL_GIS_ORDER);
    int n_data = 0, n_gis = 0;
    const int *data = OSRGetDataAxisToSRSAxisMapping(srs, &n_data);
    const int *order = OSRGetDataAxisToSRSAxisMapping(gis, &n_gis);
    const int swapped = data && order && n_data >= 2 && n_gis >= 2 &&
                        abs(data[0]) != abs(order[0]);
    OSRDestroySpatialReference(gis);
    return swapped;
}

static ts_status cells_compute(const double gt[6], int width, int height,
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
    if (srs && (OSRIsGeographic(srs) || OSRIsProjected(srs)) && columns_run_north(srs))
        return tsd_fail(msg, n, TS_ERR_ARG,
                        "the DEM's columns run north-south: its CRS's first axis is "
                        "latitude or northing, and its geotransform is in that order (a "
                        "VRT's dataAxisToSRSAxisMapping=\"1,2\", say); terrashade needs "
                        "x east-west: warp it first, e.g. gdalwarp dem.vrt north_up.tif");
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
        const double far = c->unit_to_m *
                           fmax(fmax(fabs(gt[0]), fabs(gt[0] + width * gt[1])),
                                fmax(fabs(gt[3]), fabs(gt[3] + height * gt[5])));
        if (!(far <= TSD_CORNER_MAX_M))
            return tsd_fail(msg, n, TS_ERR_ARG,
                            "the DEM's corners lie up to %g m from its CRS's origin, more "
                            "than twice around the Earth: its geotransform is not one of "
                            "this CRS (coordinates in another unit, or another CRS?)", far);
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

ts_status tsd_cells_compute(const double gt[6], int width, int height,
                            OGRSpatialReferenceH srs, tsd_cell_sizes mode, tsd_cells *c,
                            char *msg, size_t n)
{
    ts_status st = cells_compute(gt, width, height, srs, mode, c, msg, n);
    if (st != TS_OK)
        return st;
    double lo = fmin(c->cell_x, c->cell_y), hi = fmax(c->cell_x, c->cell_y);
    for (int y = 0; c->cell_x_row && y < height; y++) {
        lo = fmin(lo, c->cell_x_row[y]);
        hi = fmax(hi, c->cell_x_row[y]);
    }
    /* (the core's bounds, said here with the DEM's own words: cells of
     * 1e-320 m read NaN or nodata everywhere, and a NaN reached an int) */
    if (lo >= TS_CELL_MIN_M && hi <= TS_CELL_MAX_M)
        return TS_OK;
    tsd_cells_free(c);
    return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM's cells measure %g to %g m, outside the %g to %g m that "
                    "terrashade computes with: a geotransform in another unit?",
                    lo, hi, TS_CELL_MIN_M, TS_CELL_MAX_M);
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
