/*
 * tsd_dem_valid.h - the band a DEM's heights and validity are read
 * through. GDAL gives a band one mask: an explicit mask band, else the
 * nodata value, else a Byte or UInt16 alpha band. A DEM may say more than
 * that one: a nodata value beside a mask band, an alpha band beside a
 * nodata value, or an alpha band of another type (gdalwarp -dstalpha on a
 * Float32 DEM), which GDAL's mask leaves out. terrashade counts every one
 * (docs/driver.md, "Nodata").
 */
#ifndef TSD_DEM_VALID_H
#define TSD_DEM_VALID_H

#include "gdal.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The band to read `band`'s heights and mask through: `band` itself where
 * GDAL's mask says all that the DEM says of its validity; else a proxy of
 * the same size and type whose values are the band's and whose mask band
 * (GMF_PER_DATASET) is 0 where GDAL's mask is 0, where a value is the
 * nodata value (as GDAL's nodata mask tests it) or where the alpha band
 * GDAL's mask leaves out is 0 or less (or NaN). Reads at another size go
 * through GDAL's own resampling with that mask. NULL only when out of
 * memory. Release with tsd_dem_valid_release. */
GDALRasterBandH tsd_dem_valid_band(GDALRasterBandH band);

/** Release what tsd_dem_valid_band returned for `band` (nothing where it
 * returned `band` itself). */
void tsd_dem_valid_release(GDALRasterBandH band, GDALRasterBandH valid);

#ifdef __cplusplus
}
#endif

#endif
