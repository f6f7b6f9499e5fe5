/* Read a DEM band into a core grid. */
#include "tsd_dem.h"

#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cpl_error.h"

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

ts_status tsd_dem_load(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                       ts_grid *grid, char *msg, size_t n)
{
    ts_error err;
    int w = GDALGetRasterBandXSize(band), h = GDALGetRasterBandYSize(band);
    if (ts_grid_create(grid, w, h, cells->cell_x, cells->cell_y, &err) != TS_OK)
        return tsd_fail_core(msg, n, NULL, &err);
    if (cells->cell_x_row &&
        ts_grid_set_row_spacing(grid, cells->cell_x_row, &err) != TS_OK) {
        ts_grid_free(grid);
        return tsd_fail_core(msg, n, NULL, &err);
    }
    int has_scale = 0, has_offset = 0;
    double scale = GDALGetRasterScale(band, &has_scale);
    double offset = GDALGetRasterOffset(band, &has_offset);
    if (!has_scale)
        scale = 1;
    if (!has_offset)
        offset = 0;
    if (isnan(z_factor))
        z_factor = tsd_dem_z_factor(band, z_factor, NULL, 0);
    scale *= z_factor;
    offset *= z_factor;

    int all_valid = GDALGetMaskFlags(band) == GMF_ALL_VALID;
    GDALRasterBandH mask = all_valid ? NULL : GDALGetMaskBand(band);
    unsigned char *m = NULL;
    if (mask && !(m = malloc((size_t)w * STRIP_ROWS))) {
        ts_grid_free(grid);
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory reading the DEM's mask");
    }
    for (int y0 = 0; y0 < h; y0 += STRIP_ROWS) {
        int rows = h - y0 < STRIP_ROWS ? h - y0 : STRIP_ROWS;
        float *z = grid->z + (ptrdiff_t)y0 * grid->stride;
        if (GDALRasterIO(band, GF_Read, 0, y0, w, rows, z, w, rows, GDT_Float32,
                         0, (int)(grid->stride * sizeof(float))) != CE_None ||
            (mask && GDALRasterIO(mask, GF_Read, 0, y0, w, rows, m, w, rows,
                                  GDT_Byte, 0, w) != CE_None)) {
            const char *last = CPLGetLastErrorMsg();
            free(m);
            ts_grid_free(grid);
            return tsd_fail(msg, n, TS_ERR_INTERNAL, "cannot read the DEM%s%s",
                            last && *last ? ": " : "", last ? last : "");
        }
        for (int y = 0; y < rows; y++) {
            float *r = z + (ptrdiff_t)y * grid->stride;
            const unsigned char *mr = m ? m + (size_t)y * w : NULL;
            for (int x = 0; x < w; x++) {
                double v = r[x] * scale + offset;
                r[x] = (mr && !mr[x]) || !isfinite(v) ? NAN : (float)v;
            }
        }
    }
    free(m);
    flip(grid, cells->flip_x, cells->flip_y);
    return TS_OK;
}

/* Metres per unit of a unit's name (GDAL's band unit types, PROJ's and
 * GeoTIFF's names), or 0 if not known. */
static double metres_per_unit(const char *unit)
{
    static const struct {
        const char *name;
        double metres;
    } units[] = {
        {"m", 1.0}, {"metre", 1.0}, {"meter", 1.0}, {"metres", 1.0}, {"meters", 1.0},
        {"ft", 0.3048}, {"foot", 0.3048}, {"feet", 0.3048}, {"international foot", 0.3048},
        {"US survey foot", 1200.0 / 3937.0}, {"US survey feet", 1200.0 / 3937.0},
        {"ftUS", 1200.0 / 3937.0}, {"us-ft", 1200.0 / 3937.0},
        {"foot_us", 1200.0 / 3937.0}, {"Foot_US", 1200.0 / 3937.0},
    };
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (strcasecmp(unit, units[i].name) == 0)
            return units[i].metres;
    return 0.0;
}

double tsd_dem_z_factor(GDALRasterBandH band, double requested, char *why, size_t n)
{
    char scratch[8];
    if (!why) {
        why = scratch;
        n = sizeof scratch;
    }
    if (!isnan(requested)) {
        snprintf(why, n, "given as Z_FACTOR");
        return requested;
    }
    /* the vertical CRS of a compound (or vertical) CRS: its axis unit */
    GDALDatasetH ds = GDALGetBandDataset(band);
    OGRSpatialReferenceH srs = ds ? GDALGetSpatialRef(ds) : NULL;
    if (srs && (OSRIsCompound(srs) || OSRIsVertical(srs))) {
        char *name = NULL;
        double metres = OSRGetTargetLinearUnits(srs, "VERT_CS", &name);
        if (metres > 0 && isfinite(metres)) {
            snprintf(why, n, "vertical unit %s, from the CRS", name ? name : "?");
            return metres;
        }
    }
    const char *unit = GDALGetRasterUnitType(band);
    if (unit && unit[0]) {
        double metres = metres_per_unit(unit);
        if (metres > 0) {
            snprintf(why, n, "band unit %s", unit);
            return metres;
        }
        snprintf(why, n, "band unit '%s' not a length terrashade knows: heights taken "
                         "as metres", unit);
        return 1.0;
    }
    snprintf(why, n, "no vertical unit in the CRS or the band: heights taken as metres");
    return 1.0;
}
