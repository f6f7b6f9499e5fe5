/*
 * tsd_dataset.cpp - a TERRASHADE:<dem> dataset: a thin C++ layer over the
 * C option parser (tsd_options, tsd_connstr), the product table
 * (tsd_products), the geodesy (tsd_geodesy), the sun (tsd_sun), the DEM
 * reader (tsd_dem) and the compute functions (tsd_compute).
 *
 * A dataset computed whole (TILE_SIZE=0, a DEM within one tile, or a method
 * that is not windowed: tsd_window_plan_make) computes its
 * product once, lazily on the first block read (under a mutex; again on the
 * next read if the reading caller's progress callback stopped it), keeps it
 * in memory as float planes (bytes for the products stored as bytes,
 * PRODUCT=farshadow), out of which its bands (tsd_band.cpp) copy 256 x 256
 * blocks; a windowed one computes the chunks around the blocks read
 * (tsd_window_cache.cpp). Its overview levels (tsd_overview.cpp) are datasets
 * of this class too, set up by the same Setup at their size. The memory
 * check is tsd_dataset_memory.cpp's, the warnings tsd_dataset_warnings.cpp's,
 * the DEM's open and read tsd_dataset_dem.cpp's.
 */
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <string>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "gdal_priv.h"

#include "tsd_atlas_check.h"
#include "tsd_caller_progress.h"
#include "tsd_connstr.h"
#include "tsd_dataset.h"
#include "tsd_dem.h"
#include "tsd_gdal.h"
#include "tsd_path_check.h"
#include "tsd_source_stamp.h"
#include "tsd_window.h"
#include "tsd_entry_state.h"

namespace tsd
{

TSDataset::~TSDataset()
{
    m_apoOverviews.clear(); // first: a level may light with this dataset's ENV_MAP
    if (m_oReadAhead.joinable()) // before the DEM closes
        m_oReadAhead.join();
    ts_grid_free(&m_sReadGrid);
    TSDataset::FlushCache(true);
    FreeWindow(m_poWindow);
    if (m_poDEM)
        GDALClose(m_poDEM);
    if (!m_osStdinCopy.empty())
        VSIUnlink(m_osStdinCopy.c_str());
    tsd_cells_free(&m_sCells);
    tsd_sun_free(&m_sSun);
    tsd_environment_free(&m_sEnv);
    VSIFree(m_pafProduct);
    VSIFree(m_pabyProduct);
}

/* GDALDestroyDriverManager (QGIS's exit, a C host's end) closes every
 * dataset still open in any order, after asking each to let go of those it
 * holds: the DEM and each overview level's DEM are closed here, where this
 * dataset's destructor closed them again after GDAL had (SIGSEGV). A read
 * after this fails with DEMReleasedError. */
int TSDataset::CloseDependentDatasets()
{
    int bDropped = GDALPamDataset::CloseDependentDatasets();
    if (m_oReadAhead.joinable())
        m_oReadAhead.join();
    {
        std::lock_guard<std::mutex> oLock(m_oOvrMutex);
        for (std::unique_ptr<TSDataset> &poLevel : m_apoOverviews)
            if (poLevel)
            {
                poLevel.reset();
                bDropped = TRUE;
            }
        m_bDEMReleased = true; // (before a level could be made again)
    }
    if (m_poDEM)
    {
        GDALClose(m_poDEM);
        m_poDEM = nullptr;
        bDropped = TRUE;
    }
    return bDropped;
}

std::string TSDataset::DEMReleasedError() const
{
    return CPLSPrintf("the DEM '%s' was closed by GDAL's driver manager "
                      "(GDALDestroyDriverManager) before the product was read",
                      m_osDEM.c_str());
}

CPLErr TSDataset::GetGeoTransform(double *padfGT)
{
    if (!m_bHasGT)
        return GDALPamDataset::GetGeoTransform(padfGT);
    memcpy(padfGT, m_adfGT, sizeof m_adfGT);
    return CE_None;
}

const OGRSpatialReference *TSDataset::GetSpatialRef() const
{
    return m_oProductSRS.IsEmpty() ? nullptr : &m_oProductSRS;
}

/* Start the progress line of a computation run by psRun (PROGRESS, after
 * TERRASHADE_PROGRESS_AFTER seconds under auto) and hook it to the run,
 * with the progress callback of the read that started it, if it has one
 * (panCells: the raster cells a chunk covers; NULL: the whole read). */
void TSDataset::StartProgress(tsd_progress *psProgress, const char *pszLabel,
                              tsd_run *psRun, const int *panCells) const
{
    tsd_progress_begin(psProgress, m_sOpts.progress_mode, nullptr, pszLabel,
                       CPLAtof(CPLGetConfigOption("TERRASHADE_PROGRESS_AFTER", "1")));
    CallerProgress::Hook(psProgress, panCells);
    psRun->progress = tsd_progress_report;
    psRun->progress_user = psProgress;
}

/* Report a computation the caller's progress callback stopped (nothing
 * of it is kept, so that the next read computes it again) with its error
 * number, CPLE_UserInterrupt, as GDAL reports a read its callback stops. */
void TSDataset::FailCancelled() const
{
    CallerProgress::NoteCancelled();
    Fail(TS_ERR_CANCELLED, CPLSPrintf("computing PRODUCT=%s was cancelled by the caller's "
                                      "progress callback; a later read computes it again",
                                      m_psProduct->name));
}

bool TSDataset::ReadInsideOwnComputation() const
{
    if (m_oComputer.load() != std::this_thread::get_id())
        return false;
    CPLError(CE_Failure, CPLE_AppDefined,
             "TERRASHADE: '%s' was read from inside its own computation (from its progress "
             "callback, on the thread computing it), which would wait for itself: read it "
             "once the read that computes it has returned",
             GetDescription());
    return true;
}

bool TSDataset::TakeReadTurn(std::unique_lock<std::recursive_mutex> &oTurn)
{
    if (ReadInsideOwnComputation())
        return false;
    oTurn = std::unique_lock<std::recursive_mutex>(m_oReadMutex);
    return true;
}

CPLErr TSDataset::IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize, int nYSize,
                            void *pData, int nBufXSize, int nBufYSize, GDALDataType eBufType,
                            int nBandCount, int *panBandMap, GSpacing nPixelSpace,
                            GSpacing nLineSpace, GSpacing nBandSpace,
                            GDALRasterIOExtraArg *psExtraArg)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    std::unique_lock<std::recursive_mutex> oTurn;
    if (!TakeReadTurn(oTurn))
        return CE_Failure;
    CallerProgress oCaller(psExtraArg, nXOff, nYOff, nXSize, nYSize);
    psExtraArg = oCaller.Arg(psExtraArg);
    const CPLErr eErr = GDALPamDataset::IRasterIO(
        eRWFlag, nXOff, nYOff, nXSize, nYSize, pData, nBufXSize, nBufYSize, eBufType,
        nBandCount, panBandMap, nPixelSpace, nLineSpace, nBandSpace, psExtraArg);
    if (eErr != CE_None && oCaller.CancelledUnsaid())
        FailCancelled();
    return eErr;
}

/* Compute the product once; later calls return the same outcome, except
 * after the caller's progress callback stopped it. */
CPLErr TSDataset::EnsureComputed()
{
    if (ReadInsideOwnComputation())
        return CE_Failure;
    std::lock_guard<std::mutex> oLock(m_oMutex);
    const ComputingHere oHere(m_oComputer);
    if (!m_bTried)
    {
        m_bTried = true;
        char szMsg[1024] = "";
        ts_status eStatus = TS_OK;
        const char *pszName = m_psProduct->name;
        const int W = nRasterXSize, H = nRasterYSize;
        const size_t nCells = static_cast<size_t>(W) * H;
        const int nBands = tsd_options_band_count(&m_sOpts);
        CPLDebug(DRIVER, "computing PRODUCT=%s of %s (%d x %d, %d band(s), level %d)",
                 pszName, m_osDEM.c_str(), W, H, nBands, m_nLevel);
        const auto tStart = std::chrono::steady_clock::now();
        // The whole product is computed here, inside the first block read,
        // where GDAL passes no progress callback: report on stderr.
        tsd_progress sProgress;
        tsd_run sRun = m_sRun;
        StartProgress(&sProgress, CPLSPrintf("computing %s of %d x %d cells", pszName, W, H),
                      &sRun);
        ts_grid sGrid;
        const bool bAhead = m_oReadAhead.joinable();
        eStatus = ReadDEM(&sGrid, szMsg, sizeof szMsg);
        if (eStatus == TS_OK && !DEMUnchanged()) // (read, maybe, half before, half after)
        {
            ts_grid_free(&sGrid);
            eStatus = TS_ERR_ARG;
            snprintf(szMsg, sizeof szMsg, "%s", SourcesChangedError(m_osDEM, m_nLevel,
                                         (m_poBase ? m_poBase : this)->m_aosDEMFiles)
                         .c_str());
        }
        if (eStatus != TS_OK)
        {
            m_osError = KeptFailure(eStatus, szMsg);
        }
        else
        {
            const std::chrono::duration<double> dfRead =
                std::chrono::steady_clock::now() - tStart;
            CPLDebug(DRIVER, "read the DEM in %.3f s%s", dfRead.count(),
                     bAhead ? " (waited for the read ahead)" : "");
            WarnBelowSea(&sGrid);
            WarnVoids(&sGrid);
            if (m_psProduct->byte == TSD_BYTE_ALWAYS)
                m_pabyProduct = static_cast<GByte *>(VSI_MALLOC2_VERBOSE(nCells, nBands));
            else
                m_pafProduct = static_cast<float *>(
                    VSI_MALLOC3_VERBOSE(nCells, nBands, sizeof(float)));
            if (!m_pafProduct && !m_pabyProduct)
            {
                eStatus = TS_ERR_NOMEM;
                m_osError = KeptFailure(eStatus, "out of memory for the product");
            }
            else
            {
                tsd_backend_summary sRan{};
                tsd_region sRegion;
                tsd_region_whole(&sRegion, &sGrid);
                const tsd_compute_ctx sCtx{&m_sOpts, &sRun, &sRan, szMsg, sizeof szMsg};
                eStatus = tsd_product_compute(&sCtx, &sRegion, m_pafProduct, m_pabyProduct);
                if (eStatus != TS_OK)
                    m_osError = KeptFailure(eStatus, szMsg);
                else if (sRan.calls > 0)
                {
                    m_sBackend = sRan;
                    m_bBackendKnown = true;
                    SetupBackendMetadata();
                    ReportBackend();
                }
            }
            ts_grid_free(&sGrid);
        }
        tsd_progress_end(&sProgress, m_osError.empty());
        if (!m_osError.empty())
        {
            VSIFree(m_pafProduct);
            m_pafProduct = nullptr;
            VSIFree(m_pabyProduct);
            m_pabyProduct = nullptr;
        }
        if (eStatus == TS_ERR_CANCELLED && sProgress.cancelled)
        {
            // not tried: the DEM stays open for the next read, which computes
            m_bTried = false;
            m_osError.clear();
            CPLDebug(DRIVER, "computing the whole product: cancelled by the caller");
            FailCancelled();
            return CE_Failure;
        }
        if (m_poDEM)
            GDALClose(m_poDEM);
        m_poDEM = nullptr;
        const std::chrono::duration<double> dfSec =
            std::chrono::steady_clock::now() - tStart;
        CPLDebug(DRIVER, "computed PRODUCT=%s in %.3f s%s", pszName, dfSec.count(),
                 m_osError.empty() ? "" : " (failed)");
        m_eStatus = eStatus;
    }
    if (!m_osError.empty())
    {
        Fail(m_eStatus, m_osError.c_str());
        return CE_Failure;
    }
    return CE_None;
}

GDALDataset *TSDataset::Open(GDALOpenInfo *poOpenInfo)
{
    if (!tsd_connstr_matches(poOpenInfo->pszFilename))
        return nullptr;
    if (poOpenInfo->eAccess == GA_Update)
        return FailOpen(CPLE_NotSupported,
                             "TERRASHADE datasets are read-only; write the product "
                             "with gdal_translate instead (gdal_edit.py -ro sets a "
                             "product's nodata value, unit or statistics in "
                             "<DEM>.terrashade.aux.xml)");
    char szMsg[4096] = ""; // the option list, and hints that quote the name
    tsd_connstr sConn;
    const ts_status eParsed =
        tsd_connstr_parse(poOpenInfo->pszFilename, &sConn, szMsg, sizeof szMsg);
    if (eParsed != TS_OK)
    {
        tsd_connstr_free(&sConn);
        return FailOpen(eParsed, szMsg);
    }
    CPLStringList aosOptions;
    for (char **p = sConn.options; p && *p; p++)
        aosOptions.AddString(*p);
    for (char **p = poOpenInfo->papszOpenOptions; p && *p; p++)
        aosOptions.AddString(*p);
    const std::string osDEM = sConn.dem;
    char szCut[512]; /* "" unless an inline value was cut at its ':' */
    tsd_connstr_cut_colon_hint(&sConn, szCut, sizeof szCut);
    char szSegment[512]; /* "" unless the DEM's name looks like inline options */
    tsd_connstr_segment_hint(&sConn, szSegment, sizeof szSegment);
    /* "" unless the whole name after the prefix is a file: a DEM whose
     * name starts like KEY=VALUE:, not quoted, read as inline options */
    char szWhole[2048] = "";
    const char *pszWhole = poOpenInfo->pszFilename + strlen(TSD_PREFIX);
    VSIStatBufL sStat;
    if (sConn.options && sConn.options[0] && VSIStatL(pszWhole, &sStat) == 0)
        snprintf(szWhole, sizeof szWhole,
                 "; '%s' is a file: if it is the DEM, quote its name (TERRASHADE:\"%s\"), "
                 "as a DEM's name that starts like KEY=VALUE: must be",
                 pszWhole, pszWhole);
    tsd_connstr_free(&sConn);

    auto poDS = std::unique_ptr<TSDataset>(new TSDataset());
    tsd_options &sOpts = poDS->m_sOpts;
    tsd_options_defaults(&sOpts);
    if (tsd_options_apply(&sOpts, aosOptions.List(), szMsg, sizeof szMsg) != 0)
    {
        tsd_connstr_add_hint(szMsg, sizeof szMsg, szCut);
        return FailOpen(TS_ERR_ARG, tsd_connstr_add_hint(szMsg, sizeof szMsg, szWhole));
    }
    poDS->m_psProduct = tsd_product_of(&sOpts);

    const std::string osRefused = RefusedDEMName(osDEM.c_str(), "the DEM", false);
    if (!osRefused.empty())
        return FailOpen(TS_ERR_ARG, osRefused.c_str());
    // (GDAL's names for the stream, with its options or behind a handler
    // that streams, /vsigzip/: IsStdinName)
    const bool bStdin = IsStdinName(osDEM);
    if (bStdin && (poDS->m_osStdinCopy = CopyStdin(sOpts, osDEM)).empty())
        return nullptr;
    GDALDataset *poDEM = OpenDEM(bStdin ? poDS->m_osStdinCopy.c_str() : osDEM.c_str());
    if (!poDEM)
    {
        snprintf(szMsg, sizeof szMsg, "cannot open the DEM '%s' as a raster%s", osDEM.c_str(),
                 DEMNameHint(osDEM).c_str());
        tsd_connstr_add_hint(szMsg, sizeof szMsg, szCut);
        return FailOpen(CPLE_OpenFailed, tsd_connstr_add_hint(szMsg, sizeof szMsg, szSegment));
    }
    poDS->m_poDEM = poDEM;
    poDS->m_osDEM = osDEM;
    poDS->m_osDEMPath = bStdin ? poDS->m_osStdinCopy
                               : AbsolutePath(osDEM.c_str()); // (a chdir before a level's read)
    // an atlas, which this driver opens (its 0/1 maps were taken as heights);
    // its file read only then, not for every DEM
    const bool bOurs = poDEM->GetDriver() && EQUAL(poDEM->GetDriver()->GetDescription(), DRIVER);
    if (bOurs && IsAtlasFile(osDEM.c_str()))
        return FailOpen(TS_ERR_ARG,
                        CPLSPrintf("the DEM '%s' is a far-shadow atlas (.tsa), not a DEM: open "
                                   "it as it is (%s, its far shadows; -oo SHADOWS=all with "
                                   "the near ones), or name the DEM it was made from",
                                   osDEM.c_str(), osDEM.c_str()));
    const std::string osProduct = ProductAsDEM(poDEM, osDEM);
    if (!osProduct.empty())
        return FailOpen(TS_ERR_ARG, osProduct.c_str());
    if (sOpts.band > poDEM->GetRasterCount())
        return FailOpen(TS_ERR_ARG,
                             CPLSPrintf("BAND=%d, but the DEM '%s' has %d band(s)",
                                        sOpts.band, osDEM.c_str(),
                                        poDEM->GetRasterCount()));
    const std::string osNotHeights = NotHeights(poDEM, sOpts.band, osDEM);
    if (!osNotHeights.empty())
        return FailOpen(TS_ERR_ARG, osNotHeights.c_str());
    // Z_FACTOR=AUTO becomes the factor of the DEM's vertical unit here, so
    // that the metadata and the auxiliary-file key say the number used
    char szZWhy[256], szUnitNote[512];
    int bUnitSaid = 0;
    GDALRasterBandH hHeights = GDALRasterBand::ToHandle(poDEM->GetRasterBand(sOpts.band));
    const bool bUnitNote = std::isnan(sOpts.z_factor) &&
                           tsd_dem_unit_note(hHeights, szUnitNote, sizeof szUnitNote);
    sOpts.z_factor = tsd_dem_z_factor(hHeights, sOpts.z_factor, &bUnitSaid, szZWhy,
                                      sizeof szZWhy);
    const int W = poDEM->GetRasterXSize(), H = poDEM->GetRasterYSize();
    if (poDEM->GetGeoTransform(poDS->m_adfGT) != CE_None)
    {
        // no georeferencing: row 0 is the top (north), cells 1 x 1 metre
        poDS->m_bHasGT = false;
        const double adfTopDown[6] = {0, 1, 0, 0, 0, -1};
        memcpy(poDS->m_adfGT, adfTopDown, sizeof adfTopDown);
        WarnNoGeoTransform(poDEM, osDEM);
    }
    if (const OGRSpatialReference *poSRS = poDEM->GetSpatialRef())
        poDS->m_oSRS = *poSRS;
    poDS->m_bShared = (poOpenInfo->nOpenFlags & GDAL_OF_SHARED) != 0;
    if (!poDS->Setup(poOpenInfo->pszFilename, W, H))
        return nullptr;
    if (bUnitNote)
        CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szUnitNote);
    else if (!bUnitSaid)
        WarnHeightUnit(poDS->m_sCells, poDS->m_oSRS, osDEM);
    // not through PAM: it is derived, like the rest of the metadata
    poDS->GDALDataset::SetMetadataItem("Z_FACTOR_SOURCE", szZWhy);
    poDS->m_nOverviews = OverviewCount(poDS->m_psProduct, W, H);
    return poDS.release();
}

/* Everything that follows from the georeferencing (m_adfGT, m_bHasGT,
 * m_oSRS) of a W x H grid and the options: the cells, the sun, the memory
 * check, the bands, the metadata and (level 0) PAM. Shared by the DEM's
 * own resolution and its overview levels, so that a level is set up as a
 * DEM of its size would be. false with the error reported. */
bool TSDataset::Setup(const char *pszConnection, int W, int H)
{
    char szMsg[1024] = "";
    const tsd_options &sOpts = m_sOpts;
    // The cells and the sun are the ground's: a compound CRS's horizontal
    // part (an engineering one with heights was measured as no CRS at all,
    // its unit ignored: the review), none for a vertical CRS alone, which
    // places nothing (PROJ's errors on asking it for an ellipsoid, and "the
    // DEM has no CRS", misled: the CRS audit). The heights' unit is the
    // DEM's whole CRS's (Z_FACTOR=AUTO, tsd_dem.c).
    const bool bVerticalOnly = m_oSRS.IsVertical() && !m_oSRS.IsCompound();
    m_oProductSRS = bVerticalOnly ? OGRSpatialReference() : GroundSRS(m_oSRS);
    OGRSpatialReferenceH hSRS = m_oProductSRS.IsEmpty()
                                    ? nullptr
                                    : OGRSpatialReference::ToHandle(&m_oProductSRS);
    const std::string osVertical =
        bVerticalOnly ? CPLSPrintf("a vertical CRS only (%s), which places nothing on the ground",
                                   m_oSRS.GetName())
                      : std::string();
    if (bVerticalOnly && sOpts.cell_sizes == TSD_CELLS_GROUND)
        return Fail(TS_ERR_ARG, CPLSPrintf("CELL_SIZES=ground: the DEM has %s, so its cells "
                                           "cannot be measured on the ground; give it a "
                                           "horizontal CRS too (gdal_edit.py -a_srs)",
                                           osVertical.c_str())),
               false;
    ts_status eSt = tsd_cells_compute(m_adfGT, W, H, hSRS, sOpts.cell_sizes, &m_sCells, szMsg,
                                      sizeof szMsg);
    if (eSt != TS_OK)
        return Fail(eSt, szMsg), false;
    if (bVerticalOnly)
        snprintf(m_sCells.warning, sizeof m_sCells.warning,
                 "the DEM has %s: its cell size (%g x %g) is taken as metres",
                 osVertical.c_str(), std::fabs(m_adfGT[1]), std::fabs(m_adfGT[5]));
    const double dfMinCell = std::min(m_sCells.cell_y, tsd_cells_min_x(&m_sCells, H));
    if (m_nLevel == 0 && sOpts.max_distance > 0 &&
        sOpts.max_distance < std::min(TSD_MAX_DISTANCE_MIN, dfMinCell) &&
        tsd_product_takes(m_psProduct, tsd_option_find("MAX_DISTANCE")))
        return Fail(TS_ERR_ARG,
                    CPLSPrintf("MAX_DISTANCE=%g m is shorter than both %g m and the DEM's "
                               "cells (%.4g m): within a cell's own surface a horizon is a "
                               "height difference over the distance, which the rounding of "
                               "the heights (32-bit floats) swamps. Give 0 (unbounded) or at "
                               "least %g m; it is in metres (RVT's radius is in cells: times "
                               "the cell size)",
                               sOpts.max_distance, TSD_MAX_DISTANCE_MIN, dfMinCell,
                               std::min(TSD_MAX_DISTANCE_MIN, dfMinCell))),
               false;
    if (tsd_options_sun_from_time(&sOpts))
    {
        const char *pszWhat = sOpts.datetime[0]     ? "DATETIME"
                              : sOpts.start_date[0] ? "START_DATE"
                                                    : "DATE";
        if (!m_bHasGT || !hSRS)
            return Fail(
                       CPLE_AppDefined,
                       CPLSPrintf("%s needs a georeferenced DEM, but '%s' has %s: the "
                                  "sun's position over it is unknown. Give it one "
                                  "(gdal_edit.py -a_srs / -a_ullr)%s",
                                  pszWhat, m_osDEM.c_str(),
                                  !m_bHasGT       ? "no geotransform"
                                  : bVerticalOnly ? osVertical.c_str()
                                                  : "no CRS",
                                  m_psProduct->daily ? ""
                                                     : " or use SUN_AZIMUTH and SUN_ELEVATION")),
                   false;
        tsd_sites sSites;
        eSt = tsd_sites_compute(m_adfGT, W, H, hSRS, &m_sCells,
                                sOpts.sun_position == TSD_SUN_PER_CELL, &sSites, szMsg,
                                sizeof szMsg);
        if (eSt != TS_OK)
            return Fail(eSt, CPLSPrintf("%s: %s", pszWhat, szMsg)), false;
        if (sOpts.sun_position != TSD_SUN_PER_CELL && m_nLevel == 0)
            WarnSunReach(W, H, hSRS, sSites.lon[0], sSites.lat[0]);
        else if (m_nLevel == 0)
            CPLDebug(DRIVER, "the sun: a lattice of %d x %d sites (SUN_POSITION=per_cell)",
                     sSites.nx, sSites.ny);
        eSt = tsd_sun_setup(&sOpts, &sSites, dfMinCell, &m_sSun, szMsg, sizeof szMsg);
        if (eSt != TS_OK)
            return Fail(eSt, szMsg), false;
        m_bHasSun = true;
        if (m_nLevel == 0 && (tsd_sun_night_warning(&m_sSun, &sOpts, szMsg, sizeof szMsg) ||
                              tsd_sun_zone_warning(&m_sSun, &sOpts, szMsg, sizeof szMsg)))
            CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szMsg);
        if (m_nLevel == 0 && tsd_sun_range_warning(&m_sSun, &sOpts, szMsg, sizeof szMsg))
            CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szMsg);
        if (m_nLevel == 0 && tsd_sun_delta_t_warning(&m_sSun, &sOpts, szMsg, sizeof szMsg))
            CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szMsg);
    }
    const tsd_sun *psSun = m_bHasSun ? &m_sSun : nullptr;
    tsd_run_init(&m_sRun, &sOpts, psSun);
    std::vector<GByte> oEnvMap; // ENV_MAP's bytes, until the environment is built
    if (!PlanEnvironment(oEnvMap))
        return false;
    if (m_sCells.warning[0] && m_nLevel == 0) // said once, for the DEM itself
        CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", m_sCells.warning);
    if (m_nLevel == 0 &&
        tsd_dem_steepness_warning(GDALGetRasterBand(m_poDEM, sOpts.band), &m_sCells,
                                  sOpts.z_factor, hSRS ? m_oSRS.GetName() : nullptr, szMsg,
                                  sizeof szMsg))
        CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szMsg);
    if (m_nLevel == 0)
    {
        WarnUnusedOptions();
        WarnDistances(dfMinCell, W, H);
        WarnSweepTurn(H);
    }
    double dfLimit = 0, dfHeadroom = 0;
    if (!SetupWindow(W, H) ||
        !CheckMemory(sOpts, W, H, WindowPlan(m_poWindow), m_bHasSun ? &m_sSun : nullptr,
                     m_sCells, m_nLevel, m_sEnvCost,
                     m_sEnvMapInfo.width ? &m_sEnvMapInfo : nullptr, StdinCopyBytes(),
                     &dfLimit, &dfHeadroom) ||
        !BuildEnvironment(oEnvMap))
        return false;
    // a lattice's day keeps horizon planes across its steps: in at most
    // half of what the limit leaves (docs/day-cycle.md)
    if (m_bHasSun)
        m_sSun.day.plane_cache_bytes = static_cast<size_t>(
            std::min(static_cast<double>(m_sSun.day.plane_cache_bytes), dfHeadroom / 2));
    // OpenCL sweeps of a horizon stream in batches: in the other half
    // (docs/opencl.md, "Through the driver")
    m_sRun.batch_bytes = dfHeadroom / 2;
    // and what is known only when computing, against the whole headroom
    m_sRun.limit_bytes = dfLimit;
    m_sRun.headroom_bytes = dfHeadroom;
    /* a bad TERRASHADE_BACKEND or _SIMD is an error here (without probing OpenCL) */
    m_bUsesBackend = m_psProduct->uses_backend && m_psProduct->uses_backend(&sOpts, psSun);
    if (tsd_backend_check_env(&sOpts, m_bUsesBackend, szMsg, sizeof szMsg) != 0)
        return Fail(TS_ERR_ARG, szMsg), false;
    /* asked for where nothing could run on it (the day products): said at
     * open, as the C steps of the others are said when they run (shadow's
     * per-cell sun among them) */
    if (!m_bUsesBackend && sOpts.backend == TSD_BACKEND_OPENCL && m_nLevel == 0 &&
        sOpts.sun_position != TSD_SUN_PER_CELL)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: BACKEND=opencl was requested, but PRODUCT=%s runs on the C "
                 "backend only",
                 m_psProduct->name);

    nRasterXSize = W;
    nRasterYSize = H;
    const GDALDataType eType = tsd_options_output_byte(&sOpts) ? GDT_Byte : GDT_Float32;
    for (int i = 1; i <= tsd_options_band_count(&sOpts); i++)
        SetBand(i, new TSRasterBand(this, i, eType));
    if (m_nLevel == 0)
        SetupPam(AbsoluteConnection(pszConnection).c_str()); // the metadata too, over what a
                                                             // saved entry holds
    else
    {
        SetupMetadata();
        SetDescription(pszConnection);
        nPamFlags |= GPF_DISABLED; // a level's statistics are its parent's business
    }
    if (!m_osStdinCopy.empty())
        nPamFlags |= GPF_DISABLED; // (the next run's standard input is another DEM)
    return true;
}

std::string TSDataset::AbsoluteConnection(const char *pszConnection) const
{
    // a VRT of a product whose DEM was relative read another directory's
    // DEM of that name, silently, where it was read from (session 59's audit)
    // (GDALOpenShared finds a dataset again by its description, and warns
    // where it is not the name opened: the first review)
    const std::string osConn = pszConnection;
    const size_t n = m_osDEM.size();
    if (m_bShared || !m_osStdinCopy.empty() || m_osDEMPath == m_osDEM || osConn.size() < n ||
        osConn.compare(osConn.size() - n, n, m_osDEM) != 0)
        return osConn;
    const std::string osAbs = osConn.substr(0, osConn.size() - n) + m_osDEMPath;
    // (where it reads back as another DEM, as given)
    tsd_connstr sConn;
    char szMsg[256];
    const bool bSame = tsd_connstr_parse(osAbs.c_str(), &sConn, szMsg, sizeof szMsg) == TS_OK &&
                       m_osDEMPath == sConn.dem;
    tsd_connstr_free(&sConn);
    return bSame ? osAbs : osConn;
}

int IdentifyProduct(GDALOpenInfo *poOpenInfo)
{
    return tsd_connstr_matches(poOpenInfo->pszFilename);
}

GDALDataset *OpenProduct(GDALOpenInfo *poOpenInfo)
{
    return TSDataset::Open(poOpenInfo);
}

} // namespace tsd
