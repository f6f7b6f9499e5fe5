/*
 * tsd_atlas_check.h - what a far-shadow atlas (*.tsa) must be, beyond its
 * file format (the core checks that): the metadata of PRODUCT=farshadow,
 * validated through the option table as a dataset's options are; a source
 * that is such a product; a DEM that is not an atlas.
 */
#ifndef TSD_ATLAS_CHECK_H
#define TSD_ATLAS_CHECK_H

#include <string>

#include "cpl_string.h"
#include "gdal_priv.h"

#include "tsd_options.h"

namespace tsd
{

/**
 * The metadata of an atlas (its KEY=VALUE lines, or a source's metadata)
 * as the options of the PRODUCT=farshadow dataset it was written from:
 * PRODUCT=farshadow, every item that is an option through the option table
 * (its range, the combination; BACKEND says what ran and is skipped),
 * ATLAS_STEPS = nMaps, UTC_OFFSET_MINUTES and FAR_THRESHOLD_M what they
 * say. Fills *psOpts; returns "" or the cause, a sentence.
 */
std::string CheckAtlasMetadata(const CPLStringList &aosMeta, int nMaps, tsd_options *psOpts);

/** "" if poSrcDS can be written as an atlas (no complex band, the metadata
 * of PRODUCT=farshadow, a UNIX_TIME on every band), else why not. */
std::string CheckAtlasSource(GDALDataset *poSrcDS);

/** true if the file pszName starts with the atlas magic. */
bool IsAtlasFile(const char *pszName);

/** The sentence refusing an atlas named as its own DEM (bGiven: by the
 * open option DEM, else the atlas's SOURCE_DEM). */
std::string AtlasAsDEM(const std::string &osDEM, bool bGiven);

/** The atlas's SOURCE_DEM as the atlas at pszAtlas names it: a relative
 * path is the atlas's folder's (as a VRT's sources are), given back as the
 * physical absolute path of the file there, else as it is. */
std::string AtlasSourceDEM(const char *pszAtlas, const std::string &osDEM);

/** The SOURCE_DEM to write into the atlas at pszAtlas: a relative path of
 * a file (the writer's working directory's) made relative to the atlas's
 * folder (physical paths both), so that the two can move together, or
 * absolute where the atlas is on a GDAL virtual file system; anything else
 * as it is. */
std::string AtlasSourceDEMToWrite(const char *pszAtlas, const std::string &osDEM);

/** "" if poDEM (named osDEM, bGiven: by DEM=) can be the DEM of a W x H
 * atlas with that geotransform (if bHasGT) and CRS (if not null): the
 * same size, the same geotransform (within a millionth of a cell) and the
 * same CRS; else why not, a sentence. */
std::string CheckAtlasDEM(GDALDataset *poDEM, const std::string &osDEM, bool bGiven, int W,
                          int H, bool bHasGT, const double *padfGT,
                          const OGRSpatialReference *poSRS);

} // namespace tsd

#endif
