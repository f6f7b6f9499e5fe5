/* Is what a DEM read holds terrain? Heights and steps no terrain has (an
 * undeclared nodata value, heights in another unit), and a DEM too steep
 * at its cells' scale (degrees under a projected CRS). */
#include "tsd_dem_check.h"

#include "tsd_dem.h"
#include "tsd_text.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ogr_srs_api.h"

/* No cliff on Earth drops this far between neighbours (Mount Thor's face,
 * the highest vertical one, is 1.25 km; Nanga Parbat's Rupal face 4.6 km
 * over several km), nor this steeply over larger cells (84 degrees). */
#define CLIFF_M 5000.0
#define CLIFF_SLOPE 10.0

/* A Z_FACTOR beyond the heights' unit is an exaggeration: the limits grow
 * with it (1 otherwise). */
static double stretch_of(const tsd_dem_conversion *c)
{
    double s = c->z_factor / c->unit_factor;
    return s > 1 ? s : 1;
}

/* The heights a grid of the band may hold, in metres: the Earth's, or on
 * another body (a CRS whose ellipsoid is not the Earth's) within its
 * radius; widened by an exaggeration. Names them in `what`; 1 on Earth. */
static int height_limits(GDALRasterBandH band, const tsd_dem_conversion *c, double *low,
                          double *high, char *what, size_t n)
{
    GDALDatasetH ds = GDALGetBandDataset(band);
    OGRSpatialReferenceH srs = ds ? GDALGetSpatialRef(ds) : NULL;
    OGRErr err = OGRERR_FAILURE;
    /* a local CRS, or a vertical one alone, or a compound of either with
     * heights, has no ellipsoid: PROJ said so as an ERROR (four times;
     * twice) */
    OGRSpatialReferenceH ground = srs ? OSRClone(srs) : NULL;
    if (ground && OSRIsCompound(ground))
        OSRStripVertical(ground);
    double a = ground && !OSRIsLocal(ground) && !OSRIsVertical(ground)
                   ? OSRGetSemiMajor(ground, &err)
                   : 0;
    if (ground)
        OSRDestroySpatialReference(ground);
    const int earth = !(err == OGRERR_NONE && a > 0 && fabs(a - TS_EARTH_RADIUS) > 100000.0);
    if (!earth) {
        *low = -a;
        *high = a;
        snprintf(what, n, "the radius of the CRS's body (%.0f m)", a);
    } else {
        *low = TSD_EARTH_LOWEST_M;
        *high = TSD_EARTH_HIGHEST_M;
        snprintf(what, n, "any terrain on Earth (%.0f to %.0f m)", *low, *high);
    }
    const double stretch = stretch_of(c);
    if (stretch > 1) {
        *low *= stretch;
        *high *= stretch;
        size_t len = strlen(what);
        snprintf(what + len, n - len, " times Z_FACTOR's exaggeration %g", stretch);
    }
    return earth;
}

static float raw_metres(double raw, const tsd_dem_conversion *c);

/* " (gdal_edit.py -a_nodata RAW PATH)": the raw value whole and the DEM's
 * name, where it is the file's own cell (full) and finite; else "". */
static void declare_command(const char *path, double raw, int full, char *out, size_t n)
{
    out[0] = '\0';
    if (full && isfinite(raw))
        snprintf(out, n, " (gdal_edit.py -a_nodata %.17g %s)", raw, path);
}

/* The remedies' sentence: declare `z` (a grid height, of the band's cell
 * col, row) as nodata when the grid holds the DEM's own values, or set a
 * unit. The value declared is the band's own, read again: z, a float, holds
 * 24 bits, so that an Int32 void -2147483648 was named -2.14748365e+09,
 * which declared did not match it. */
static void remedies(GDALRasterBandH band, const tsd_dem_conversion *c, int full, float z,
                     int col, int row, char *out, size_t n)
{
    GDALDatasetH ds = GDALGetBandDataset(band);
    const char *path = ds ? GDALGetDescription(ds) : "";
    double raw = ((double)z - c->offset) / c->scale, cell; /* as the band holds it */
    if (full && GDALRasterIO(band, GF_Read, col, row, 1, 1, &cell, 1, 1, GDT_Float64, 0, 0) ==
                    CE_None && raw_metres(cell, c) == z)
        raw = cell;
    char declare[TSD_PATH_MAX + 160];
    declare_command(path, raw, full, declare, sizeof declare);
    snprintf(out, n,
             "A nodata value the DEM does not declare? Declare it%s and those cells are "
             "nodata. Heights in another unit? Set the band's unit (gdal_edit.py -units ft) "
             "or Z_FACTOR",
             declare);
}

static ts_status height_error(GDALRasterBandH band, const tsd_dem_conversion *c,
                              const ts_grid *g, const tsd_dem_placement *p, double low,
                              double high, const char *what, char *msg, size_t n)
{
    int gx = 0, gy = 0;
    float z = NAN;
    for (gy = 0; gy < g->height; gy++) {
        const float *row = g->z + (ptrdiff_t)gy * g->stride;
        for (gx = 0; gx < g->width; gx++)
            if (row[gx] < low || row[gx] > high)
                break;
        if (gx < g->width) {
            z = row[gx];
            break;
        }
    }
    const int full = p->sx == 1 && p->sy == 1; /* else a coarse cell: an average */
    char todo[TSD_PATH_MAX + 320];
    remedies(band, c, full, z, p->x0 + gx, p->y0 + gy, todo, sizeof todo);
    GDALDatasetH ds = GDALGetBandDataset(band);
    return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM '%s' holds a height no terrain has: %.6g m%s in band %d %s "
                    "column %d, row %d, beyond %s. %s",
                    ds ? GDALGetDescription(ds) : "", (double)z, full ? "" : " (averaged)",
                    GDALGetBandNumber(band), full ? "at" : "near",
                    p->x0 + (int)(p->sx * gx), p->y0 + (int)(p->sy * gy), what, todo);
}

/* The first step between neighbours in a row larger than `limit`, named
 * with the side that looks like a void: the one its row repeats beyond
 * the step, else the one farther from zero. */
static ts_status cliff_error(GDALRasterBandH band, const tsd_dem_conversion *c,
                             const ts_grid *g, const tsd_dem_placement *p, double limit,
                             double spacing, char *msg, size_t n)
{
    int gx = 0, gy = 0;
    const float *row = g->z;
    for (gy = 0; gy < g->height; gy++) {
        row = g->z + (ptrdiff_t)gy * g->stride;
        for (gx = 0; gx + 1 < g->width; gx++)
            if (fabsf(row[gx + 1] - row[gx]) > limit)
                break;
        if (gx + 1 < g->width)
            break;
    }
    if (gy == g->height)
        return TS_OK; /* not found again: cannot happen */
    const float a = row[gx], b = row[gx + 1];
    float v = fabsf(a) >= fabsf(b) ? a : b;
    if (gx > 0 && row[gx - 1] == a)
        v = a;
    else if (gx + 2 < g->width && row[gx + 2] == b)
        v = b;
    const int full = p->sx == 1 && p->sy == 1;
    char todo[TSD_PATH_MAX + 320];
    remedies(band, c, full, v, p->x0 + gx + (v == a ? 0 : 1), p->y0 + gy, todo, sizeof todo);
    GDALDatasetH ds = GDALGetBandDataset(band);
    return tsd_fail(msg, n, TS_ERR_ARG,
                    "the DEM '%s' holds a cliff no terrain has: %.6g m beside %.6g m%s in "
                    "band %d %s columns %d and %d of row %d, cells about %.3g m apart, where "
                    "no terrain steps more than %.0f m. %s",
                    ds ? GDALGetDescription(ds) : "", (double)a, (double)b,
                    full ? "" : " (averaged)", GDALGetBandNumber(band), full ? "at" : "near",
                    p->x0 + (int)(p->sx * gx), p->x0 + (int)(p->sx * (gx + 1)),
                    p->y0 + (int)(p->sy * gy), spacing, limit, todo);
}

/* The value an integer type's voids hold by custom: the minimum of a
 * signed type (-32768), the maximum of an unsigned one (65535). 0 for the
 * others: a Byte's 255 is as likely a height; the 64-bit ones' lie beyond
 * any terrain at any usual scale; the float types' too. */
static int customary_void(GDALDataType type, double *raw)
{
    switch (type) {
    case GDT_Int16: *raw = -32768.0; return 1;
    case GDT_UInt16: *raw = 65535.0; return 1;
    case GDT_Int32: *raw = -2147483648.0; return 1;
    case GDT_UInt32: *raw = 4294967295.0; return 1;
    default: return 0;
    }
}

/* A raw value in metres as the loads make it (tsd_dem.c's to_metres: the
 * float read times scale plus offset in double, as float). */
static float raw_metres(double raw, const tsd_dem_conversion *c)
{
    return (float)((double)(float)raw * c->scale + c->offset);
}

/* A height the grid holds that is the band's type's customary void, once
 * within the Earth's heights by the band's scale (Int16 centimetres:
 * -327.68 m, UInt16 centimetres: 655.35 m): an error naming it and the
 * first cell; TS_OK where no cell holds it. */
static ts_status void_error(GDALRasterBandH band, const tsd_dem_conversion *c, const ts_grid *g,
                            const tsd_dem_seen *seen, const tsd_dem_placement *p, char *msg,
                            size_t n)
{
    double raw;
    const GDALDataType type = GDALGetRasterDataType(band);
    if (!customary_void(type, &raw))
        return TS_OK;
    const float z = raw_metres(raw, c);
    const double next = raw < 0 ? raw + 1 : raw - 1; /* a height it must differ from */
    if ((z != tsd_key_float(seen->lo_key) && z != tsd_key_float(seen->hi_key)) ||
        raw_metres(next, c) == z)
        return TS_OK;
    for (int gy = 0; gy < g->height; gy++) {
        const float *row = g->z + (ptrdiff_t)gy * g->stride;
        for (int gx = 0; gx < g->width; gx++) {
            if (row[gx] != z)
                continue;
            const int full = p->sx == 1 && p->sy == 1;
            GDALDatasetH ds = GDALGetBandDataset(band);
            const char *path = ds ? GDALGetDescription(ds) : "";
            return tsd_fail(msg, n, TS_ERR_ARG,
                            "the DEM '%s' holds %.0f, the value %s DEMs leave in their voids, "
                            "in band %d %s column %d, row %d (%.6g m after its scale, offset "
                            "and Z_FACTOR), and does not declare it as nodata: those cells "
                            "would be terrain %.6g m %s. Declare it (gdal_edit.py -a_nodata "
                            "%.0f %s) and those cells are nodata; if they are heights, write "
                            "the DEM as Float32 (gdal_translate -ot Float32)",
                            path, raw, GDALGetDataTypeName(type), GDALGetBandNumber(band),
                            full ? "at" : "near", p->x0 + (int)(p->sx * gx),
                            p->y0 + (int)(p->sy * gy), (double)z, fabs((double)z),
                            z < 0 ? "deep" : "high", raw, path);
        }
    }
    return TS_OK;
}

ts_status tsd_dem_beyond_float(GDALRasterBandH band, const float *z, ptrdiff_t stride,
                               const unsigned char *m, int w, int rows,
                               tsd_dem_reread_fn reread, void *ctx, int x0, int y0, double sx,
                               double sy, char *msg, size_t n)
{
    if (GDALGetRasterDataType(band) != GDT_Float64)
        return TS_OK;
    int any = 0; /* an infinity where the mask says valid: voids (-DBL_MAX
                  * declared nodata reads as -inf) cost no second read */
    for (int y = 0; y < rows && !any; y++)
        for (int x = 0; x < w; x++)
            any |= isinf(z[(ptrdiff_t)y * stride + x]) && !(m && !m[(size_t)y * w + x]);
    if (!any)
        return TS_OK;
    double *d = malloc((size_t)w * rows * sizeof *d);
    if (!d)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory reading the DEM's heights");
    ts_status st = TS_OK;
    if (reread(ctx, d) != CE_None) {
        free(d);
        return TS_OK; /* as read first: the infinities stay nodata */
    }
    int has_nodata = 0;
    const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
    for (size_t i = 0; i < (size_t)w * rows; i++)
        if (isfinite(d[i]) && fabs(d[i]) > FLT_MAX && !(m && !m[i]) &&
            !(has_nodata && d[i] == nodata)) {
            GDALDatasetH ds = GDALGetBandDataset(band);
            const int full = sx == 1 && sy == 1;
            const char *path = ds ? GDALGetDescription(ds) : "";
            char declare[TSD_PATH_MAX + 160];
            declare_command(path, d[i], full, declare, sizeof declare);
            st = tsd_fail(msg, n, TS_ERR_ARG,
                          "the DEM '%s' holds a value no terrain's height is: %.6g%s in band "
                          "%d %s column %d, row %d, beyond the range of 32-bit floats "
                          "(%.6g). A nodata value the DEM does not declare? Declare it%s and "
                          "those cells are nodata",
                          path, d[i], full ? "" : " (averaged)", GDALGetBandNumber(band),
                          full ? "at" : "near", x0 + (int)(sx * (double)(i % (size_t)w)),
                          y0 + (int)(sy * (double)(i / (size_t)w)), (double)FLT_MAX, declare);
            break;
        }
    free(d);
    return st;
}

ts_status tsd_dem_check(GDALRasterBandH band, const tsd_dem_conversion *c, const ts_grid *g,
                        const tsd_dem_seen *seen, double spacing, const tsd_dem_placement *p,
                        char *msg, size_t n)
{
    /* before the heights: a NaN scale leaves none to test */
    const double scale = GDALGetRasterScale(band, NULL), offset = GDALGetRasterOffset(band, NULL);
    if (!isfinite(scale) || scale == 0 || !isfinite(offset)) {
        GDALDatasetH ds = GDALGetBandDataset(band);
        const char *path = ds ? GDALGetDescription(ds) : "";
        return tsd_fail(msg, n, TS_ERR_ARG,
                        "the DEM '%s' gives band %d a scale of %g and an offset of %g: %s. "
                        "Set them to what the values mean (gdal_edit.py -scale 1 -offset 0 "
                        "%s, if they are metres)",
                        path, GDALGetBandNumber(band), scale, offset,
                        isfinite(scale) && isfinite(offset)
                            ? "every height would be the offset, a flat plane"
                            : "no height would be a number",
                        path);
    }
    if (seen->lo_key > seen->hi_key)
        return TS_OK; /* no valid height */
    double low, high;
    char what[160];
    const int earth = height_limits(band, c, &low, &high, what, sizeof what);
    if (!(tsd_key_float(seen->lo_key) >= low && tsd_key_float(seen->hi_key) <= high))
        return height_error(band, c, g, p, low, high, what, msg, n);
    if (!earth)
        return TS_OK; /* a smaller body's cliffs are taller (Verona Rupes on Miranda) */
    float step;
    memcpy(&step, &seen->step_bits, sizeof step);
    const double cliff = fmax(CLIFF_M, CLIFF_SLOPE * spacing) * stretch_of(c);
    if (step > cliff)
        return cliff_error(band, c, g, p, cliff, spacing, msg, n);
    return void_error(band, c, g, seen, p, msg, n);
}

/* Steeper than this nearly everywhere is not terrain at the DEM's scale. */
#define STEEP_DEGREES 85.0
#define STEEP_SAMPLE 256

int tsd_dem_steepness_warning(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                              const char *crs_name, char *warning, size_t n)
{
    const int W = GDALGetRasterBandXSize(band), H = GDALGetRasterBandYSize(band);
    const int w = W < STEEP_SAMPLE ? W : STEEP_SAMPLE, h = H < STEEP_SAMPLE ? H : STEEP_SAMPLE;
    if (w < 3 || h < 3)
        return 0;
    const int x0 = (W - w) / 2, y0 = (H - h) / 2;
    ts_grid g;
    char msg[16];
    /* a sample that cannot be read (or holds no terrain) says nothing
     * here: the reads will */
    if (tsd_dem_load_window(band, cells, z_factor, x0, y0, w, h, &g, msg, sizeof msg) != TS_OK)
        return 0;
    /* the shading's own normals (Horn's method, the grid's row spacing) */
    const size_t cells_n = (size_t)w * h;
    float *nz = malloc(3 * cells_n * sizeof *nz);
    ts_error err;
    if (!nz || ts_normals_threads(&g, 1, nz + cells_n, nz + 2 * cells_n, nz, &err) != TS_OK) {
        free(nz);
        ts_grid_free(&g);
        return 0;
    }
    const float limit = (float)cos(STEEP_DEGREES * M_PI / 180.0);
    long steep = 0, counted = 0;
    for (size_t i = 0; i < cells_n; i++)
        if (!isnan(nz[i])) {
            counted++;
            steep += nz[i] < limit;
        }
    free(nz);
    ts_grid_free(&g);
    if (counted == 0 || steep * 2 <= counted)
        return 0;
    /* what is likely wrong, by where the cells' sizes came from */
    char question[256];
    if (cells->kind == TSD_CRS_PROJECTED)
        snprintf(question, sizeof question,
                 "Is it georeferenced in degrees under a projected CRS%s%s%s, or are its "
                 "heights in another unit (Z_FACTOR)?",
                 crs_name && *crs_name ? " (" : "", crs_name ? crs_name : "",
                 crs_name && *crs_name ? ")" : "");
    else if (cells->kind == TSD_CRS_NONE)
        snprintf(question, sizeof question,
                 "Without a CRS its cells are taken as metres: are they? Or are its heights "
                 "in another unit (Z_FACTOR)?");
    else
        snprintf(question, sizeof question, "Are its heights in another unit (Z_FACTOR)?");
    GDALDatasetH ds = GDALGetBandDataset(band);
    snprintf(warning, n,
             "the DEM '%s' is steeper than %.0f degrees at %.0f %% of the %d x %d cells at its "
             "centre: its cells (%.6g x %.6g m) are small for its heights' changes, and its "
             "shading will be black and white. %s",
             ds ? GDALGetDescription(ds) : "", STEEP_DEGREES, 100.0 * steep / counted, w, h,
             cells->cell_x, cells->cell_y, question);
    return 1;
}

/* Below this lowest height EDGE=horizon's sea level at the DEM's edges
 * stands as a wall worth a word: -1 m is a few degrees of horizon within
 * ten metres of the edge, and keeps coastal DEMs whose sea reads a few
 * decimetres below 0 quiet. */
#define BELOW_SEA_WARN_M (-1.0)

int tsd_grid_below_sea_warning(const ts_grid *g, char *warning, size_t n)
{
    float lowest = INFINITY;
    for (int y = 0; y < g->height; y++) {
        const float *row = g->z + (ptrdiff_t)y * g->stride;
        for (int x = 0; x < g->width; x++)
            lowest = row[x] < lowest ? row[x] : lowest; /* NaN fails the compare */
    }
    if (!(lowest < BELOW_SEA_WARN_M))
        return 0;
    snprintf(warning, n,
             "the DEM's heights reach %.1f m, below sea level: with EDGE=horizon (the "
             "default) the ground beyond the DEM's edges is the sea-level sphere, which "
             "stands as a wall above them, so that they are shaded and their sky closed as "
             "in a pit (sea floor, depressions such as the Dead Sea, ellipsoidal heights "
             "where the geoid lies below the ellipsoid). Give EDGE=open (nothing beyond the "
             "edges) or EDGE=nodata",
             lowest);
    return 1;
}

/* The longest run of voids among n cells step apart that has valid cells
 * on one side at least (all voids: none), in cells; its first index. */
static int longest_voids(const float *z, ptrdiff_t step, int n, int *first)
{
    int best = 0, run = 0, seen_valid = 0;
    for (int k = 0; k <= n; k++) {
        if (k < n && isnan(z[k * step])) {
            run++;
            continue;
        }
        /* a run ended by a valid cell, or by the edge after valid ones */
        if (run > best && (k < n || seen_valid))
            best = run, *first = k - run;
        seen_valid |= k < n;
        run = 0;
    }
    return best;
}

int tsd_grid_voids_warning(const ts_grid *g, double max_distance, double per_x, double per_y,
                           char *warning, size_t n)
{
    if (!(max_distance > 0)) /* unbounded rays cross every void: no pass over the grid */
        return 0;
    const int W = g->width, H = g->height;
    double widest = 0;
    int row = 0, line = 0, from = 0, len = 0;
    for (int y = 0; y < H; y++) {
        int first = 0;
        const int k = longest_voids(g->z + (ptrdiff_t)y * g->stride, 1, W, &first);
        if (k * ts_grid_cell_x(g, y) > widest)
            widest = k * ts_grid_cell_x(g, y), row = 1, line = y, from = first, len = k;
    }
    for (int x = 0; x < W; x++) {
        int first = 0;
        const int k = longest_voids(g->z + x, g->stride, H, &first);
        if (k * g->cell_y > widest)
            widest = k * g->cell_y, row = 0, line = x, from = first, len = k;
    }
    if (!(widest > max_distance))
        return 0;
    /* in the whole DEM's cells where g is a window of it, where a run cut
     * by the window's edge is at least as wide as it shows */
    const ts_grid_origin *o = g->origin;
    const int ox = o ? o->x0 : 0, oy = o ? o->y0 : 0;
    const int full = row ? (o ? o->full_width : W) : (o ? o->full_height : H);
    const int cut = (from == 0 && (row ? ox : oy) > 0) ||
                    (from + len == (row ? W : H) && from + len + (row ? ox : oy) < full);
    line += row ? oy : ox;
    from += row ? ox : oy;
    const int edge = from == 0 || from + len == full;
    /* an overview level's cells, in the DEM's */
    const double along = row ? per_x : per_y, across = row ? per_y : per_x;
    line = (int)(line * across);
    const int last = (int)((from + len) * along) - 1;
    from = (int)(from * along);
    len = last - from + 1;
    snprintf(warning, n,
             "the DEM has nodata %s %s%.0f m across (%s %d, cells %d to %d), wider than "
             "MAX_DISTANCE=%g m: a ray that meets no valid cell within MAX_DISTANCE has no "
             "horizon (-90 degrees), so the cells along such voids look down into them: "
             "openness up to 150 degrees, svf and sky a little higher there%s. Fill the "
             "voids (gdal_fillnodata.py)%s, or give no MAX_DISTANCE (rays then cross the "
             "voids to the terrain beyond)",
             edge ? "along its edge (a collar, as from gdalwarp)" : "voids",
             cut ? "at least " : "", widest,
             row ? "row" : "column", line, from, from + len - 1, max_distance,
             edge ? "; EDGE applies at the grid's edge, not at the data's, so EDGE=horizon "
                    "does not raise them and EDGE=nodata leaves them valid"
                  : "",
             edge ? ", crop the collar (gdalwarp -crop_to_cutline, gdal_translate -projwin)"
                  : "");
    return 1;
}
