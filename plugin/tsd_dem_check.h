/*
 * tsd_dem_check.h - is what a DEM read holds terrain? Inside the plugin:
 * tsd_dem.c folds what it needs into its conversion loop (the lowest and
 * highest height, the largest step between neighbours in a row) and asks
 * tsd_dem_check before it hands the grid on.
 */
#ifndef TSD_DEM_CHECK_H
#define TSD_DEM_CHECK_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "gdal.h"
#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Beyond any terrain on Earth: the deepest ocean floor (the Challenger
 * Deep, -10.9 km) and Everest (8.85 km), with room for ellipsoidal heights.
 * Undeclared nodata values (-32768, 32767, 65535, -3.4e38...) lie beyond;
 * no cell's horizon dips below the sea-level one seen from the highest. */
#define TSD_EARTH_LOWEST_M (-12000.0)
#define TSD_EARTH_HIGHEST_M 9000.0

/** A Float64 band's heights beyond the float range read as +-inf in a
 * Float32 read, which the conversion takes for nodata, as an infinite
 * height in the file: where `rows` rows of w cells so read (z, stride)
 * hold an infinity, the same cells read as doubles by `reread` (into a
 * w x rows buffer; CE_None on success) tell them apart. TS_OK, or the
 * first finite height beyond the float range refused as no terrain's, at
 * band cell (x0 + sx * gx, y0 + sy * gy). Cells the mask m (w a row; NULL:
 * none) says invalid, and the band's nodata value (-DBL_MAX is common),
 * are voids, not heights. */
typedef CPLErr (*tsd_dem_reread_fn)(void *ctx, double *buf);
ts_status tsd_dem_beyond_float(GDALRasterBandH band, const float *z, ptrdiff_t stride,
                               const unsigned char *m, int w, int rows,
                               tsd_dem_reread_fn reread, void *ctx, int x0, int y0, double sx,
                               double sy, char *msg, size_t n);

/** How a band's values become the grid's heights. */
typedef struct {
    double scale, offset; /**< value * scale + offset: the band's own, times z_factor */
    double z_factor;      /**< Z_FACTOR as applied (AUTO resolved) */
    double unit_factor;   /**< metres per unit of the heights as the DEM's metadata says */
} tsd_dem_conversion;

/** Where a grid loaded (not yet flipped) lies in the band: its cell
 * (gx, gy) is about band cell (x0 + sx * gx, y0 + sy * gy). */
typedef struct {
    int x0, y0;
    double sx, sy;
} tsd_dem_placement;

/** What a load saw of its valid heights, folded row by row: the order
 * keys (tsd_order_key) of the lowest and highest, and the bits of the
 * largest absolute step between neighbours in a row (a finite float's). */
typedef struct {
    uint32_t lo_key, hi_key;
    uint32_t step_bits;
} tsd_dem_seen;

/** Nothing seen yet. */
#define TSD_DEM_SEEN_NONE {UINT32_MAX, 0, 0}

/** An unsigned int per float bit pattern that orders as the floats do (NaN
 * aside), so that the lowest and highest heights reduce in integer lanes. */
static inline uint32_t tsd_order_key(uint32_t bits)
{
    return bits ^ ((0u - (bits >> 31)) | 0x80000000u);
}

static inline float tsd_key_float(uint32_t key)
{
    uint32_t bits = key & 0x80000000u ? key ^ 0x80000000u : ~key;
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/**
 * TS_OK if the grid `g` just loaded from `band` (`seen` folded over it,
 * `spacing` its largest east-west cell size in metres) holds terrain: no
 * height beyond the Earth's (-12 000 to 9 000 m; on another body, its
 * radius) and, on Earth, no cliff of more than 5 000 m, and steeper than 84
 * degrees, between neighbours in a row; both widened by a Z_FACTOR that
 * exaggerates; on Earth, no integer band's customary void (Int16 -32768,
 * UInt16 65535...) that its scale brings within those heights. Else
 * TS_ERR_ARG with a sentence naming the first cell at fault and what to do
 * (declare the nodata value, the unit).
 */
ts_status tsd_dem_check(GDALRasterBandH band, const tsd_dem_conversion *c, const ts_grid *g,
                        const tsd_dem_seen *seen, double spacing, const tsd_dem_placement *p,
                        char *msg, size_t msg_size);

/**
 * A sentence for EDGE=horizon's users when the grid `g` holds valid heights
 * more than a metre below sea level: that mode puts the sea-level sphere
 * beyond the DEM's edges, a wall above them. Returns 1 with the sentence in
 * `warning`, else 0. (A pass over the grid's heights.)
 */
int tsd_grid_below_sea_warning(const ts_grid *g, char *warning, size_t warning_size);

/**
 * A sentence for a MAX_DISTANCE of `max_distance` metres shorter than the
 * widest run of nodata cells along a row or column of the grid `g` (the
 * DEM's or a window of it) that has valid cells beside it: a
 * collar from the grid's edge (a reprojected or clipped DEM) or an inner
 * void (lidar's water). A ray that meets no valid cell within the distance
 * has no horizon (-90 degrees), so cells along such voids look down into
 * them. The sentence names the void's row or column in the DEM's cells,
 * per_x and per_y of them to a cell of g (an overview level's: 2, 4...).
 * Returns 1 with the sentence, else 0.
 */
int tsd_grid_voids_warning(const ts_grid *g, double max_distance, double per_x, double per_y,
                           char *warning, size_t warning_size);

#ifdef __cplusplus
}
#endif

#endif
