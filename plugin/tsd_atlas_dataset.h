/*
 * tsd_atlas_dataset.h - a far-shadow atlas (*.tsa, docs/atlas-format.md)
 * opened as a dataset: its classes, shared by tsd_atlas_dataset.cpp (open,
 * create, the near shadows of SHADOWS=all) and tsd_atlas_band.cpp (the
 * reads). Internal to the plugin.
 */
#ifndef TSD_ATLAS_DATASET_H
#define TSD_ATLAS_DATASET_H

#include <algorithm>
#include <mutex>
#include <string>

#include "cpl_string.h"
#include "gdal_pam.h"
#include "ogr_spatialref.h"

#include "shadow_atlas.h"
#include "tsd_gdal.h"
#include "tsd_options.h"
#include "tsd_turn_band.h"

namespace tsd
{

class TSAtlasBand;

class TSAtlasDataset final : public GDALPamDataset
{
    friend class TSAtlasBand;

    ts_atlas *m_psAtlas = nullptr;
    OGRSpatialReference m_oSRS{};
    double m_adfGT[6] = {0, 1, 0, 0, 0, 1};
    bool m_bHasGT = false;
    bool m_bAll = false; // SHADOWS=all: far | near, near recomputed from the DEM
    std::string m_osDEM{};
    int m_nThreads = 0;
    bool m_bDEMGiven = false;           // DEM= given, not the SOURCE_DEM
    CPLStringList m_aosMeta{};
    tsd_options m_sMetaOpts{};          // the metadata, validated as options
    std::mutex m_oMutex{};
    /* reads take turns (IRasterIO, the statistics): GDAL 3.6's block cache
     * files a block before IReadBlock fills it, so that a second thread
     * reading this dataset took blocks unfilled (nodata, 2, 4, 7...) */
    std::recursive_mutex m_oReadTurns{};
    bool m_bTried = false;
    std::string m_osError{};            // why SHADOWS=all failed
    CPLErrorNum m_nErr = CPLE_AppDefined; // and its error number
    GByte *m_pabyNear = nullptr; // near-shadow bits, raster order, one plane per map
    GDALDataset *m_poDEM = nullptr; // SHADOWS=all: the DEM, opened and checked at open,
                                    // until EnsureNear has read it

    bool m_bDEMReleased = false; // closed by CloseDependentDatasets before EnsureNear
    /* the stamp (tsd_source_stamp.h) of the atlas's file, and SHADOWS=all's
     * DEM's files, when it opened: the statistics its entry holds are of
     * those contents (StampPamEntry) */
    std::string m_osPamStamp{};

    CPLErr EnsureNear();

  public:
    TSAtlasDataset() = default;
    ~TSAtlasDataset() override;

    /* GDALDestroyDriverManager: SHADOWS=all's DEM closed here, as a
     * product's (TSDataset::CloseDependentDatasets) */
    int CloseDependentDatasets() override;
    /* GDAL's, with the stamp of the contents the statistics are of */
    CPLErr TrySaveXML() override
    {
        StampPamEntry(this, m_osPamStamp);
        return GDALPamDataset::TrySaveXML();
    }

    CPLErr IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize, int nYSize,
                     void *pData, int nBufXSize, int nBufYSize, GDALDataType eBufType,
                     int nBandCount, int *panBandMap, GSpacing nPixelSpace, GSpacing nLineSpace,
                     GSpacing nBandSpace, GDALRasterIOExtraArg *psExtraArg) override;

    static GDALDataset *Open(GDALOpenInfo *poOpenInfo);
    static GDALDataset *CreateCopy(const char *pszFilename, GDALDataset *poSrcDS,
                                   int bStrict, char **papszOptions,
                                   GDALProgressFunc pfnProgress, void *pProgressData);

    CPLErr GetGeoTransform(double *padfGT) override
    {
        if (!m_bHasGT)
            return GDALPamDataset::GetGeoTransform(padfGT);
        memcpy(padfGT, m_adfGT, sizeof m_adfGT);
        return CE_None;
    }
    const OGRSpatialReference *GetSpatialRef() const override
    {
        return m_oSRS.IsEmpty() ? nullptr : &m_oSRS;
    }
    CPLErr SetGeoTransform(double *) override
    {
        return RefuseGeoreferencing(this, "geotransform");
    }
    CPLErr SetSpatialRef(const OGRSpatialReference *) override
    {
        return RefuseGeoreferencing(this, "spatial reference");
    }
    /* gdaladdo: GDAL's own refusal ("BuildOverviews() not supported") was
     * no TERRASHADE sentence and said nothing of what to do */
    CPLErr IBuildOverviews(const char *, int, const int *, int, const int *, GDALProgressFunc,
                           void *, CSLConstList) override
    {
        Fail(CPLE_NotSupported,
             CPLSPrintf("%s: a far-shadow atlas is read-only and holds no overviews; copy it "
                        "(gdal_translate day.tsa day.tif) and run gdaladdo on the copy",
                        GetDescription()));
        return CE_Failure;
    }
};

/* Its nodata value and colour are the atlas's unless the user set them
 * (tsd_pam_band.h). */
class TSAtlasBand final : public TSTurnBand
{
    int m_nStep;

  protected:
    double OwnNoData() const override
    {
        // as PRODUCT=farshadow, whether or not the maps have nodata cells
        return TS_ATLAS_NODATA;
    }
    bool TakeReadTurn(std::unique_lock<std::recursive_mutex> &oTurn) override
    {
        oTurn = std::unique_lock<std::recursive_mutex>(
            static_cast<TSAtlasDataset *>(poDS)->m_oReadTurns);
        return true;
    }

  public:
    TSAtlasBand(TSAtlasDataset *poDSIn, int nBandIn) : m_nStep(nBandIn - 1)
    {
        poDS = poDSIn;
        nBand = nBandIn;
        eDataType = GDT_Byte;
        nBlockXSize = std::min(BLOCK, poDSIn->GetRasterXSize());
        nBlockYSize = std::min(BLOCK, poDSIn->GetRasterYSize());
    }

    CPLErr IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage) override;
    /* in the dataset's read turn, as the statistics (TSTurnBand) */
    CPLErr IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize, int nYSize,
                     void *pData, int nBufXSize, int nBufYSize, GDALDataType eBufType,
                     GSpacing nPixelSpace, GSpacing nLineSpace,
                     GDALRasterIOExtraArg *psExtraArg) override;
};

} // namespace tsd

#endif
