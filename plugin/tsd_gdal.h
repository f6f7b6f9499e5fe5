/*
 * tsd_gdal.h - what the driver's C++ files share (GDAL side): the block
 * size, the driver's name, the one mapping from ts_status to GDAL error
 * numbers, the entry points of the two kinds of datasets (a product of a
 * DEM, TERRASHADE:<dem>, in tsd_dataset.cpp; a far-shadow atlas, *.tsa, in
 * tsd_atlas_dataset.cpp) and the metadata of one time step.
 */
#ifndef TSD_GDAL_H
#define TSD_GDAL_H

#include "cpl_error.h"
#include "gdal_priv.h"

#include "terrashade.h"
#include "tsd_window.h"

namespace tsd
{

constexpr int BLOCK = TSD_BLOCK_SIDE;
/** Overview levels stop at the first one whose longer side is at most
 * this many cells (as gdaladdo's default). */
constexpr int OVERVIEW_MIN_SIDE = 256;
constexpr const char *DRIVER = "TERRASHADE";

/** The GDAL error number of a status: out of memory, cancelled by the
 * caller, a bad argument, anything else. */
inline CPLErrorNum ErrorNum(ts_status eStatus)
{
    switch (eStatus)
    {
        case TS_ERR_NOMEM:
            return CPLE_OutOfMemory;
        case TS_ERR_CANCELLED:
            return CPLE_UserInterrupt;
        case TS_ERR_ARG:
            return CPLE_IllegalArg;
        default:
            return CPLE_AppDefined;
    }
}

/** Report a failure, "TERRASHADE: <sentence>", with the status's number. */
inline void Fail(ts_status eStatus, const char *pszMsg)
{
    CPLError(CE_Failure, ErrorNum(eStatus), "TERRASHADE: %s", pszMsg);
}

/** Report a failure that no status describes (a file that cannot be read,
 * an access mode not supported) with its own number. */
inline void Fail(CPLErrorNum nErr, const char *pszMsg)
{
    CPLError(CE_Failure, nErr, "TERRASHADE: %s", pszMsg);
}

/** The same; returns nullptr for Open. */
inline GDALDataset *FailOpen(CPLErrorNum nErr, const char *pszMsg)
{
    Fail(nErr, pszMsg);
    return nullptr;
}

/** Report a status's failure; returns nullptr for Open. */
inline GDALDataset *FailOpen(ts_status eStatus, const char *pszMsg)
{
    Fail(eStatus, pszMsg);
    return nullptr;
}

/** Whether the .aux.xml file pszPath holds an entry <Subdataset
 * name="pszName"> (read in the products' turn of the DEM pszDEM where it is
 * not null; tsd_dataset_metadata.cpp). GDAL's TryLoadXML does not say. */
bool HasPamEntry(const char *pszPath, const char *pszName, const char *pszDEM);

/** Refuse SetGeoTransform/SetSpatialRef on a dataset whose georeferencing
 * is fixed (a product's is its DEM's, an atlas's what it stores): GDAL's
 * PAM took them, saved them and reported nothing of them. */
inline CPLErr RefuseGeoreferencing(const GDALDataset *poDS, const char *pszWhat)
{
    Fail(CPLE_NotSupported,
         CPLSPrintf("%s: the %s cannot be changed: a product's georeferencing is its "
                    "DEM's, an atlas's the one it stores; set it on the DEM (gdal_edit.py "
                    "-a_srs / -a_ullr dem.tif) or on a copy (gdal_translate -a_srs / -a_ullr)",
                    poDS->GetDescription(), pszWhat));
    return CE_Failure;
}

/** The horizontal part of a CRS: a compound one's without its vertical
 * CRS, its data axes as they were (a VRT's "1,2,3" made "1,2"; GDAL's
 * StripVertical left three on two axes, and the CRS then differed from the
 * same CRS read elsewhere); any other as it is (tsd_dataset_dem.cpp). */
OGRSpatialReference GroundSRS(const OGRSpatialReference &oSRS);

/* TERRASHADE:<dem> datasets (tsd_dataset.cpp). */
int IdentifyProduct(GDALOpenInfo *poOpenInfo);
GDALDataset *OpenProduct(GDALOpenInfo *poOpenInfo);

/* Far-shadow atlases (tsd_atlas_dataset.cpp). */
int IdentifyAtlas(GDALOpenInfo *poOpenInfo);
GDALDataset *OpenAtlas(GDALOpenInfo *poOpenInfo);
GDALDataset *CreateAtlasCopy(const char *pszFilename, GDALDataset *poSrcDS, int bStrict,
                             char **papszOptions, GDALProgressFunc pfnProgress,
                             void *pProgressData);

/** The metadata of one time step: its instant (as the description, TIME
 * and UNIX_TIME) and the sun there; NaN values are left out. */
void SetStepMetadata(GDALMajorObject *poObj, double dfTime, int nOffset, double dfAzTrue,
                     double dfAzGrid, double dfEl, double dfDuration);

} // namespace tsd

#endif
