/* Read a DEM band into a core grid. */
#include "tsd_dem.h"

#include "tsd_dem_check.h"
#include "tsd_dem_valid.h"
#include "tsd_text.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cpl_error.h"

#include "simd_clones.h"

#define STRIP_ROWS 256

static void flip(ts_grid *g, int flip_x, int flip_y)
{
    int w = g->width, h = g->height;
    if (flip_x)
        for (int y = 0; y < h; y++) {
            float *r = g->z + (ptrdiff_t)y * g->stride;
            for (int a = 0, b = w - 1; a < b; a++, b--) {
                float t = r[a];
                r[a] = r[b];
                r[b] = t;
            }
        }
    if (flip_y)
        for (int a = 0, b = h - 1; a < b; a++, b--) {
            float *ra = g->z + (ptrdiff_t)a * g->stride;
            float *rb = g->z + (ptrdiff_t)b * g->stride;
            for (int x = 0; x < w; x++) {
                float t = ra[x];
                ra[x] = rb[x];
                rb[x] = t;
            }
        }
}

/* 1 if the band's validity read at w x h cells is in its values: a nodata
 * band resampled, where GDAL's average leaves the nodata value in a coarse
 * cell none of whose cells is valid (averaging its mask band instead would
 * round a cell with few valid cells to 0 at deep levels). */
static int nodata_in_values(GDALRasterBandH band, int w, int h)
{
    return (GDALGetRasterBandXSize(band) != w || GDALGetRasterBandYSize(band) != h) &&
           GDALGetMaskFlags(band) == GMF_NODATA;
}

double tsd_dem_nodata(GDALRasterBandH band, int *has)
{
#if GDAL_VERSION_NUM >= GDAL_COMPUTE_VERSION(3, 5, 0)
    const GDALDataType type = GDALGetRasterDataType(band);
    if (type == GDT_Int64)
        return (double)GDALGetRasterNoDataValueAsInt64(band, has);
    if (type == GDT_UInt64)
        return (double)GDALGetRasterNoDataValueAsUInt64(band, has);
#endif
    return GDALGetRasterNoDataValue(band, has);
}

/* Rows y0 .. y0 + rows - 1 of the band read at w x h cells: as they are at
 * the band's own size, else averaged over each coarse cell's footprint
 * (GDAL's average resampling, over the valid cells only) through a
 * fractional source window, as a VRT made by gdal_translate -outsize reads
 * it. */
static CPLErr read_rows(GDALRasterBandH band, int y0, int rows, int w, int h, void *buf,
                        size_t stride, GDALDataType type)
{
    const int sw = GDALGetRasterBandXSize(band), sh = GDALGetRasterBandYSize(band);
    const int line = (int)(stride * GDALGetDataTypeSizeBytes(type));
    if (sw == w && sh == h)
        return GDALRasterIO(band, GF_Read, 0, y0, w, rows, buf, w, rows, type, 0, line);
    GDALRasterIOExtraArg extra;
    INIT_RASTERIO_EXTRA_ARG(extra);
    extra.eResampleAlg = GRIORA_Average;
    extra.bFloatingPointWindowValidity = TRUE;
    const double fy = (double)sh / h;
    extra.dfXOff = 0;
    extra.dfXSize = sw;
    extra.dfYOff = y0 * fy;
    extra.dfYSize = rows * fy;
    int yoff = (int)extra.dfYOff;
    int yend = (int)ceil(extra.dfYOff + extra.dfYSize - 1e-10);
    if (yend > sh)
        yend = sh;
    if (GDALRasterIOEx(band, GF_Read, 0, yoff, sw, yend - yoff, buf, w, rows, type, 0,
                       line, &extra) != CE_None)
        return CE_Failure;
    int has_nodata = 0;
    const float nodata = (float)tsd_dem_nodata(band, &has_nodata);
    if (type == GDT_Float32 && has_nodata && nodata_in_values(band, w, h))
        for (int y = 0; y < rows; y++) {
            float *r = (float *)buf + (size_t)y * stride;
            for (int x = 0; x < w; x++)
                if (r[x] == nodata)
                    r[x] = NAN;
        }
    return CE_None;
}

ts_status tsd_dem_load(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                       ts_grid *grid, char *msg, size_t n)
{
    return tsd_dem_load_resampled(band, cells, z_factor, GDALGetRasterBandXSize(band),
                                  GDALGetRasterBandYSize(band), grid, msg, n);
}

static tsd_dem_conversion conversion_of(GDALRasterBandH band, double z_factor)
{
    tsd_dem_conversion c;
    int has_scale = 0, has_offset = 0;
    c.scale = GDALGetRasterScale(band, &has_scale);
    c.offset = GDALGetRasterOffset(band, &has_offset);
    if (!has_scale)
        c.scale = 1;
    if (!has_offset)
        c.offset = 0;
    c.unit_factor = tsd_dem_z_factor(band, NAN, NULL, NULL, 0);
    c.z_factor = isnan(z_factor) ? c.unit_factor : z_factor;
    c.scale *= c.z_factor;
    c.offset *= c.z_factor;
    return c;
}

/* Heights in metres, NaN where the mask row says invalid or not finite:
 * r * scale + offset in double, as (float), selected on the bits (a float
 * or double compare would keep gcc from vectorising under trapping math;
 * the read ahead of the whole DEM waits on this loop). What tsd_dem_check
 * needs of the row is folded into *seen: its lowest and highest valid
 * heights' order keys, its largest step between neighbours. */
TS_SIMD_CLONES
static void to_metres(float *restrict r, const unsigned char *restrict mr, int w, double scale,
                      double offset, tsd_dem_seen *restrict seen)
{
    const uint32_t nan_bits = 0x7fc00000u; /* NAN */
    uint32_t lo = seen->lo_key, hi = seen->hi_key;
    for (int x = 0; x < w; x++) {
        double v = r[x] * scale + offset;
        float f = (float)v;
        uint64_t vb;
        uint32_t fb;
        memcpy(&vb, &v, sizeof vb);
        memcpy(&fb, &f, sizeof fb);
        uint32_t finite = (uint32_t)((vb & 0x7ff0000000000000u) != 0x7ff0000000000000u);
        uint32_t keep = -(finite & (uint32_t)(!mr || mr[x]));
        uint32_t key = tsd_order_key(fb);
        uint32_t key_lo = key | ~keep, key_hi = key & keep; /* invalid: no bound */
        lo = key_lo < lo ? key_lo : lo;
        hi = key_hi > hi ? key_hi : hi;
        fb = (fb & keep) | (nan_bits & ~keep);
        memcpy(&r[x], &fb, sizeof fb);
    }
    /* |r[x] - r[x - 1]| as bits, 0 where either is NaN or it overflows */
    uint32_t step = seen->step_bits;
    for (int x = 1; x < w; x++) {
        float d = r[x] - r[x - 1];
        uint32_t db;
        memcpy(&db, &d, sizeof db);
        db &= 0x7fffffffu;
        db &= -(uint32_t)(db < 0x7f800000u);
        step = db > step ? db : step;
    }
    seen->lo_key = lo;
    seen->hi_key = hi;
    seen->step_bits = step;
}

/* The cells a read took, read again as doubles (tsd_dem_beyond_float). */
typedef struct {
    GDALRasterBandH band;
    int x, y, w, rows, h; /* h > 0: rows y .. of the band resampled to h rows */
} reread_ctx;

static CPLErr reread_doubles(void *ctx, double *buf)
{
    const reread_ctx *r = ctx;
    if (r->h > 0)
        return read_rows(r->band, r->y, r->rows, r->w, r->h, buf, (size_t)r->w, GDT_Float64);
    return GDALRasterIO(r->band, GF_Read, r->x, r->y, r->w, r->rows, buf, r->w, r->rows,
                        GDT_Float64, 0, 0);
}

/* GDAL's reason, or, where it gave none (GDAL 3.6's direct reads of a
 * truncated GeoTIFF fail without one), what to try: the DEM named. */
static ts_status read_failed(GDALRasterBandH band, ts_grid *grid, unsigned char *m, char *msg,
                             size_t n)
{
    const char *last = CPLGetLastErrorMsg();
    GDALDatasetH ds = GDALGetBandDataset(band);
    const char *name = ds ? GDALGetDescription(ds) : "";
    free(m);
    ts_grid_free(grid);
    if (last && *last)
        return tsd_fail(msg, n, TS_ERR_INTERNAL, "cannot read the DEM '%s': %s", name, last);
    return tsd_fail(msg, n, TS_ERR_INTERNAL,
                    "cannot read the DEM '%s' (GDAL gave no reason: is the file truncated or "
                    "damaged? `gdalinfo -checksum` reads it whole)",
                    name);
}

/* A w x h grid of the cells' sizes, row spacing from row `row0` on. */
static ts_status grid_of(const tsd_cells *cells, int w, int h, int row0, ts_grid *grid,
                         char *msg, size_t n)
{
    ts_error err;
    if (ts_grid_create(grid, w, h, cells->cell_x, cells->cell_y, &err) != TS_OK)
        return tsd_fail_core(msg, n, NULL, &err);
    if (cells->cell_x_row &&
        ts_grid_set_row_spacing(grid, cells->cell_x_row + row0, &err) != TS_OK) {
        ts_grid_free(grid);
        return tsd_fail_core(msg, n, NULL, &err);
    }
    return TS_OK;
}

/* The largest east-west cell size of a grid's rows. */
static double largest_spacing(const ts_grid *g)
{
    if (!g->cell_x_row)
        return g->cell_x;
    double m = 0;
    for (int y = 0; y < g->height; y++)
        m = g->cell_x_row[y] > m ? g->cell_x_row[y] : m;
    return m;
}

/* The loads' end: the grid checked (tsd_dem_check; on failure it is
 * freed), then turned to row 0 = north. */
static ts_status checked_and_flipped(GDALRasterBandH band, const tsd_dem_conversion *c,
                                     const tsd_cells *cells, ts_grid *grid,
                                     const tsd_dem_seen *seen, const tsd_dem_placement *p,
                                     char *msg, size_t n)
{
    ts_status st = tsd_dem_check(band, c, grid, seen, largest_spacing(grid), p, msg, n);
    if (st != TS_OK) {
        ts_grid_free(grid);
        return st;
    }
    flip(grid, cells->flip_x, cells->flip_y);
    return TS_OK;
}

/* The loads read heights and mask from `src` (tsd_dem_valid_band of
 * `band`), and take everything else from `band`. */
static ts_status load_window(GDALRasterBandH band, GDALRasterBandH src, const tsd_cells *cells,
                             double z_factor, int x0, int y0, int w, int h, ts_grid *grid,
                             char *msg, size_t n)
{
    const int W = GDALGetRasterBandXSize(band), H = GDALGetRasterBandYSize(band);
    ts_status st = grid_of(cells, w, h, y0, grid, msg, n);
    if (st != TS_OK)
        return st;
    const tsd_dem_conversion c = conversion_of(band, z_factor);
    /* the grid's window in the band's own orientation */
    const int rx = cells->flip_x ? W - x0 - w : x0, ry = cells->flip_y ? H - y0 - h : y0;
    GDALRasterBandH mask = GDALGetMaskFlags(src) == GMF_ALL_VALID ? NULL : GDALGetMaskBand(src);
    unsigned char *m = mask ? malloc((size_t)w * h) : NULL;
    if (mask && !m) {
        ts_grid_free(grid);
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory reading the DEM's mask");
    }
    if (GDALRasterIO(src, GF_Read, rx, ry, w, h, grid->z, w, h, GDT_Float32, 0,
                     (int)(grid->stride * sizeof(float))) != CE_None ||
        (mask && GDALRasterIO(mask, GF_Read, rx, ry, w, h, m, w, h, GDT_Byte, 0, w) != CE_None))
        return read_failed(src, grid, m, msg, n);
    reread_ctx again = {src, rx, ry, w, h, 0};
    if ((st = tsd_dem_beyond_float(band, grid->z, grid->stride, m, w, h, reread_doubles,
                                   &again, rx, ry, 1, 1, msg, n)) != TS_OK) {
        free(m);
        ts_grid_free(grid);
        return st;
    }
    tsd_dem_seen seen = TSD_DEM_SEEN_NONE;
    for (int y = 0; y < h; y++)
        to_metres(grid->z + (ptrdiff_t)y * grid->stride, m ? m + (size_t)y * w : NULL, w,
                  c.scale, c.offset, &seen);
    free(m);
    const tsd_dem_placement p = {rx, ry, 1, 1};
    return checked_and_flipped(band, &c, cells, grid, &seen, &p, msg, n);
}

static ts_status load_resampled(GDALRasterBandH band, GDALRasterBandH src,
                                const tsd_cells *cells, double z_factor, int w, int h,
                                ts_grid *grid, char *msg, size_t n)
{
    ts_status st = grid_of(cells, w, h, 0, grid, msg, n);
    if (st != TS_OK)
        return st;
    const tsd_dem_conversion c = conversion_of(band, z_factor);

    int all_valid = GDALGetMaskFlags(src) == GMF_ALL_VALID || nodata_in_values(src, w, h);
    GDALRasterBandH mask = all_valid ? NULL : GDALGetMaskBand(src);
    unsigned char *m = NULL;
    /* resampled: one request for the whole grid, as gdal_translate -outsize
     * makes for a level of this size (where a request's edge falls changes
     * GDAL's average next to nodata) */
    const int strip =
        w == GDALGetRasterBandXSize(band) && h == GDALGetRasterBandYSize(band) ? STRIP_ROWS : h;
    if (mask && !(m = malloc((size_t)w * strip))) {
        ts_grid_free(grid);
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory reading the DEM's mask");
    }
    tsd_dem_seen seen = TSD_DEM_SEEN_NONE;
    for (int y0 = 0; y0 < h; y0 += strip) {
        int rows = h - y0 < strip ? h - y0 : strip;
        float *z = grid->z + (ptrdiff_t)y0 * grid->stride;
        if (read_rows(src, y0, rows, w, h, z, grid->stride, GDT_Float32) != CE_None ||
            (mask && read_rows(mask, y0, rows, w, h, m, w, GDT_Byte) != CE_None))
            return read_failed(src, grid, m, msg, n);
        const double sx = (double)GDALGetRasterBandXSize(band) / w,
                     sy = (double)GDALGetRasterBandYSize(band) / h;
        reread_ctx again = {src, 0, y0, w, rows, h};
        if ((st = tsd_dem_beyond_float(band, z, grid->stride, m, w, rows, reread_doubles,
                                       &again, 0, (int)(sy * y0), sx, sy, msg, n)) != TS_OK) {
            free(m);
            ts_grid_free(grid);
            return st;
        }
        for (int y = 0; y < rows; y++)
            to_metres(z + (ptrdiff_t)y * grid->stride, m ? m + (size_t)y * w : NULL, w,
                      c.scale, c.offset, &seen);
    }
    free(m);
    const tsd_dem_placement p = {0, 0, (double)GDALGetRasterBandXSize(band) / w,
                                 (double)GDALGetRasterBandYSize(band) / h};
    return checked_and_flipped(band, &c, cells, grid, &seen, &p, msg, n);
}

ts_status tsd_dem_load_window(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                              int x0, int y0, int w, int h, ts_grid *grid, char *msg,
                              size_t n)
{
    GDALRasterBandH src = tsd_dem_valid_band(band);
    if (!src)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory reading the DEM's mask");
    ts_status st = load_window(band, src, cells, z_factor, x0, y0, w, h, grid, msg, n);
    tsd_dem_valid_release(band, src);
    return st;
}

ts_status tsd_dem_load_resampled(GDALRasterBandH band, const tsd_cells *cells,
                                 double z_factor, int w, int h, ts_grid *grid, char *msg,
                                 size_t n)
{
    GDALRasterBandH src = tsd_dem_valid_band(band);
    if (!src)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory reading the DEM's mask");
    ts_status st = load_resampled(band, src, cells, z_factor, w, h, grid, msg, n);
    tsd_dem_valid_release(band, src);
    return st;
}

/* A unit's name as metres_per_unit compares it: lower case, '_', '-' and
 * runs of spaces as one space, '.' and parentheses dropped, and a trailing
 * datum word (asl, amsl, msl, navd88, ...: "ft asl", "m (NAVD88)") cut. */
static void unit_key(const char *unit, char *key, size_t n)
{
    static const char *const datum_words[] = {"asl",    "amsl",    "msl",   "above sea level",
                                              "navd88", "ngvd29",  "egm96", "egm2008",
                                              "height", "elevation"};
    size_t k = 0;
    for (const char *c = unit; *c && k + 1 < n; c++) {
        char ch = (char)tolower((unsigned char)*c);
        if (ch == '.' || ch == '(' || ch == ')')
            continue;
        if (ch == '_' || ch == '-' || isspace((unsigned char)ch))
            ch = ' ';
        if (ch == ' ' && (k == 0 || key[k - 1] == ' '))
            continue;
        key[k++] = ch;
    }
    while (k > 0 && key[k - 1] == ' ')
        k--;
    key[k] = '\0';
    for (size_t i = 0; i < sizeof datum_words / sizeof datum_words[0]; i++) {
        const size_t w = strlen(datum_words[i]);
        if (k > w + 1 && key[k - w - 1] == ' ' && strcmp(key + k - w, datum_words[i]) == 0) {
            key[k - w - 1] = '\0';
            return;
        }
    }
}

/* Metres per unit of a unit's name (GDAL's band unit types, PROJ's and
 * GeoTIFF's names, and their common spellings), or 0 if not known. */
static double metres_per_unit(const char *unit)
{
    static const struct {
        const char *name; /* as unit_key writes it */
        double metres;
    } units[] = {
        {"m", 1.0}, {"metre", 1.0}, {"meter", 1.0},
        {"dm", 0.1}, {"decimetre", 0.1}, {"decimeter", 0.1},
        {"cm", 0.01}, {"centimetre", 0.01}, {"centimeter", 0.01},
        {"mm", 0.001}, {"millimetre", 0.001}, {"millimeter", 0.001},
        {"km", 1000.0}, {"kilometre", 1000.0}, {"kilometer", 1000.0},
        {"ft", 0.3048}, {"foot", 0.3048}, {"feet", 0.3048}, {"international foot", 0.3048},
        {"international feet", 0.3048}, {"intl ft", 0.3048}, {"ft intl", 0.3048},
        {"us survey foot", 1200.0 / 3937.0}, {"us survey feet", 1200.0 / 3937.0},
        {"survey foot", 1200.0 / 3937.0}, {"survey feet", 1200.0 / 3937.0},
        {"us foot", 1200.0 / 3937.0}, {"us feet", 1200.0 / 3937.0},
        {"ftus", 1200.0 / 3937.0}, {"ft us", 1200.0 / 3937.0}, {"us ft", 1200.0 / 3937.0},
        {"usft", 1200.0 / 3937.0}, {"foot us", 1200.0 / 3937.0}, {"feet us", 1200.0 / 3937.0},
        {"foot us survey", 1200.0 / 3937.0}, {"feet us survey", 1200.0 / 3937.0},
        {"masl", 1.0}, {"mamsl", 1.0}, {"ftasl", 0.3048}, {"ftamsl", 0.3048},
    };
    char key[64];
    unit_key(unit, key, sizeof key);
    /* a plural's trailing s aside (metres, centimeters; not "ms" or "cms") */
    size_t len = strlen(key);
    for (int plural = 0; plural < 2; plural++)
        for (size_t i = 0; i < sizeof units / sizeof units[0]; i++) {
            size_t k = strlen(units[i].name);
            if (plural ? k > 2 && len == k + 1 && key[k] == 's' &&
                             strncmp(key, units[i].name, k) == 0
                       : strcmp(key, units[i].name) == 0)
                return units[i].metres;
        }
    return 0.0;
}

/* The heights' unit as the DEM's metadata says it: the vertical axis of a
 * compound (or vertical) CRS, else the band's unit type. 1 with *metres and
 * why when it says one terrashade knows; 0 with why otherwise. */
static int metadata_unit(GDALRasterBandH band, double *metres, char *why, size_t n)
{
    GDALDatasetH ds = GDALGetBandDataset(band);
    OGRSpatialReferenceH srs = ds ? GDALGetSpatialRef(ds) : NULL;
    if (srs && (OSRIsCompound(srs) || OSRIsVertical(srs))) {
        char *name = NULL;
        double m = OSRGetTargetLinearUnits(srs, "VERT_CS", &name);
        if (m > 0 && isfinite(m)) {
            snprintf(why, n, "vertical unit %s, from the CRS", name ? name : "?");
            *metres = m;
            return 1;
        }
    }
    const char *unit = GDALGetRasterUnitType(band);
    if (unit && unit[0]) {
        double m = metres_per_unit(unit);
        if (m > 0) {
            snprintf(why, n, "band unit %s", unit);
            *metres = m;
            return 1;
        }
        snprintf(why, n, "band unit '%s' not a length terrashade knows: heights taken "
                         "as metres", unit);
        return 0;
    }
    snprintf(why, n, "no vertical unit in the CRS or the band: heights taken as metres");
    return 0;
}

int tsd_dem_unit_note(GDALRasterBandH band, char *note, size_t n)
{
    const char *unit = GDALGetRasterUnitType(band);
    if (!unit || !unit[0])
        return 0;
    const double band_m = metres_per_unit(unit);
    double crs_m = 0;
    char crs_name[96] = "";
    GDALDatasetH ds = GDALGetBandDataset(band);
    OGRSpatialReferenceH srs = ds ? GDALGetSpatialRef(ds) : NULL;
    if (srs && (OSRIsCompound(srs) || OSRIsVertical(srs))) {
        char *name = NULL;
        const double m = OSRGetTargetLinearUnits(srs, "VERT_CS", &name);
        if (m > 0 && isfinite(m)) {
            crs_m = m;
            snprintf(crs_name, sizeof crs_name, "%s", name ? name : "?");
        }
    }
    if (crs_m > 0 && band_m > 0 && fabs(band_m / crs_m - 1) > 1e-9) {
        snprintf(note, n, "the DEM's CRS gives its heights in %s, its band in '%.60s': the "
                          "CRS's unit is used (Z_FACTOR=%.10g). If the heights are in %.60s, "
                          "give Z_FACTOR=%.10g",
                 crs_name, unit, crs_m, unit, band_m);
        return 1;
    }
    if (crs_m > 0 || band_m > 0)
        return 0;
    snprintf(note, n, "the DEM's band gives its heights' unit as '%.60s', which is not a length "
                      "terrashade knows: they are taken as metres. Give Z_FACTOR, the metres "
                      "of one unit (0.3048 for feet, 0.3048006096 for US survey feet), or "
                      "1 if they are metres",
             unit);
    return 1;
}

double tsd_dem_z_factor(GDALRasterBandH band, double requested, int *said, char *why,
                        size_t n)
{
    char scratch[8];
    if (!why) {
        why = scratch;
        n = sizeof scratch;
    }
    double metres = requested;
    int known = 1;
    if (!isnan(requested))
        snprintf(why, n, "given as Z_FACTOR");
    else if (!(known = metadata_unit(band, &metres, why, n)))
        metres = 1.0;
    if (said)
        *said = known;
    return metres;
}
