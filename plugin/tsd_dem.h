/*
 * tsd_dem.h - read a DEM band through GDAL's C API into a core grid:
 * float metres, NaN where any validity the DEM declares (nodata, mask
 * band, alpha: tsd_dem_valid.h) says invalid, scale/offset and Z_FACTOR
 * applied, flipped to row 0 = north.
 * Every load refuses what no terrain holds (tsd_dem_check.h: heights beyond
 * the Earth's, cliffs between neighbours, most often an undeclared nodata
 * value) with TS_ERR_ARG and a sentence naming the cell and the remedy.
 */
#ifndef TSD_DEM_H
#define TSD_DEM_H

#include <stddef.h>

#include "gdal.h"
#include "ogr_srs_api.h"
#include "terrashade.h"
#include "tsd_geodesy.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The band's nodata value as a double (*has: whether it has one); an
 * Int64 or UInt64 band's through its own getter, which GDAL's double getter
 * would warn about when the value is not exact as a double. */
double tsd_dem_nodata(GDALRasterBandH band, int *has);

/** Fill `grid` (created here; free with ts_grid_free) from `band`, its
 * heights times z_factor (NAN: AUTO, as tsd_dem_z_factor decides).
 * TS_OK, or the failure's status with a sentence in msg. */
ts_status tsd_dem_load(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                       ts_grid *grid, char *msg, size_t msg_size);

/** The same at w x h cells (an overview level): each coarse cell is the
 * average of the valid cells under it (GDAL's average resampling through
 * RasterIO, which uses the band's own overviews where it has them, but
 * not where tsd_dem_valid_band adds to GDAL's mask); a
 * coarse cell none of whose cells is valid is NaN. `cells` are those of
 * the w x h grid. At the band's own size, tsd_dem_load. */
ts_status tsd_dem_load_resampled(GDALRasterBandH band, const tsd_cells *cells,
                                 double z_factor, int w, int h, ts_grid *grid, char *msg,
                                 size_t msg_size);

/** The window of w x h cells at (x0, y0) of the grid (row 0 north, after
 * the flips of `cells`, whose per-row sizes are the whole DEM's), at full
 * resolution, as tsd_dem_load reads the whole. */
ts_status tsd_dem_load_window(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                              int x0, int y0, int w, int h, ts_grid *grid, char *msg,
                              size_t msg_size);

/**
 * 1 with a sentence in `warning` when more than half of the cells of a
 * sample of up to 256 x 256 cells at the DEM's centre are steeper than 85
 * degrees (by ts_normals, as the shading sees them): not terrain at its
 * cells' scale, as when a DEM in degrees is given a projected CRS (cells of
 * 0.0008 "m") or its heights are in millimetres. 0 otherwise, or when the sample cannot be
 * read. crs_name (may be NULL) names the CRS in the sentence. In
 * tsd_dem_check.c, beside the loads' checks.
 */
int tsd_dem_steepness_warning(GDALRasterBandH band, const tsd_cells *cells, double z_factor,
                              const char *crs_name, char *warning, size_t warning_size);

/**
 * The Z_FACTOR that turns `band`'s heights (after its scale and offset)
 * into metres. A finite `requested` is the user's number and is kept; NAN
 * (AUTO) takes the vertical unit of the dataset's CRS (a compound or
 * vertical CRS), else the band's unit type ("m", "metre", "cm", "mm", "ft",
 * "foot", "US survey foot", "ftUS"...), else 1 (no information: metres).
 * *said (may be NULL) is 1 when the number or the metadata said the unit, 0
 * when the heights are taken as metres for want of one. Writes why to `why`
 * ("vertical unit US survey foot, from the CRS") and returns the factor.
 */
double tsd_dem_z_factor(GDALRasterBandH band, double requested, int *said, char *why,
                        size_t why_size);

/**
 * A sentence for Z_FACTOR=AUTO's users when `band`'s metadata says its
 * heights' unit in a way that may not be what was meant: a band unit type
 * that is not a length terrashade knows ("ft asl" and the like are known;
 * "dam" or "hm" are not), so the heights are taken as metres; or a
 * compound CRS whose vertical unit differs from the band's unit type (the
 * CRS's is used). Returns 1 with the sentence in `note`, else 0.
 */
int tsd_dem_unit_note(GDALRasterBandH band, char *note, size_t note_size);

#ifdef __cplusplus
}
#endif

#endif
