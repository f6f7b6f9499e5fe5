/*
 * tsd_atlas_dataset.cpp - far-shadow atlases (*.tsa, docs/atlas-format.md):
 * CreateCopy stores any raster of binary bands (0, 1, nodata), typically
 * PRODUCT=farshadow, and Open recognises the file by its magic and decodes
 * blocks lazily. Its open options (SHADOWS, DEM, THREADS) are rows of the
 * driver's option table (tsd_options.h).
 */
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "gdal_pam.h"
#include "gdal_priv.h"
#include "ogr_spatialref.h"

#include "shadow_atlas.h"
#include "tsd_atlas_check.h"
#include "tsd_atlas_dataset.h"
#include "tsd_dataset.h"
#include "tsd_dem.h"
#include "tsd_gdal.h"
#include "tsd_geodesy.h"
#include "tsd_options.h"
#include "tsd_path_check.h"
#include "tsd_pam_band.h"
#include "tsd_source_stamp.h"
#include "tsd_entry_state.h"

namespace tsd
{
namespace
{

/* KEY=VALUE lines of an atlas's metadata text. */
static CPLStringList AtlasMetadata(const char *pszText)
{
    CPLStringList aosOut;
    const CPLStringList aosLines(CSLTokenizeStringComplex(pszText, "\n", FALSE, FALSE));
    for (int i = 0; i < aosLines.size(); i++)
        if (strchr(aosLines[i], '='))
            aosOut.AddString(aosLines[i]);
    return aosOut;
}

} // namespace

TSAtlasDataset::~TSAtlasDataset()
{
    TSAtlasDataset::FlushCache(true);
    ts_atlas_free(m_psAtlas);
    VSIFree(m_pabyNear);
    if (m_poDEM)
        GDALClose(m_poDEM);
}

int TSAtlasDataset::CloseDependentDatasets()
{
    int bDropped = GDALPamDataset::CloseDependentDatasets();
    if (m_poDEM)
    {
        GDALClose(m_poDEM);
        m_poDEM = nullptr;
        m_bDEMReleased = true;
        bDropped = TRUE;
    }
    return bDropped;
}

/* SHADOWS=all: near shadows (occluders within the far threshold) of every
 * map, from the DEM, with the exact horizon sweep capped at the
 * threshold. */
CPLErr TSAtlasDataset::EnsureNear()
{
    std::lock_guard<std::mutex> oLock(m_oMutex);
    if (!m_bTried)
    {
        m_bTried = true;
        const ts_atlas_info *psInfo = ts_atlas_get_info(m_psAtlas);
        const int W = psInfo->width, H = psInfo->height;
        char szMsg[1024] = "";
        GDALDataset *poDEM = m_poDEM; // (opened, its size and ground checked, at open)
        tsd_cells sCells{};
        ts_grid sGrid{};
        bool bGrid = false;
        float *pafPlane = nullptr;
        const int nBandDEM = m_sMetaOpts.band;
        ts_horizon_opts sH;
        ts_horizon_opts_default(&sH);
        sH.curvature = m_sMetaOpts.curvature;
        sH.refraction = m_sMetaOpts.refraction;
        sH.threads = m_nThreads;
        sH.directions = 1;
        sH.max_distance = psInfo->threshold_m;
        double adfGT[6];
        std::string osNotHeights;
        if (m_bDEMReleased)
            m_osError = CPLSPrintf("SHADOWS=all: the DEM '%s' was closed by GDAL's driver "
                                   "manager (GDALDestroyDriverManager) before the atlas was "
                                   "read",
                                   m_osDEM.c_str());
        else if (!(std::isfinite(psInfo->threshold_m) && psInfo->threshold_m > 0))
            m_osError = "SHADOWS=all needs the atlas's far threshold in "
                        "metres, which this atlas does not record";
        else if (dynamic_cast<TSAtlasDataset *>(poDEM))
            m_osError = AtlasAsDEM(m_osDEM, m_bDEMGiven);
        else if (nBandDEM > poDEM->GetRasterCount())
            m_osError = CPLSPrintf("SHADOWS=all: the atlas's metadata says BAND=%d, but the "
                                   "DEM '%s' has %d band(s)", nBandDEM, m_osDEM.c_str(),
                                   poDEM->GetRasterCount());
        else if (!(osNotHeights = NotHeights(poDEM, nBandDEM, m_osDEM)).empty())
            m_osError = "SHADOWS=all: " + osNotHeights; /* as a product's open says */
        else if (poDEM->GetGeoTransform(adfGT) != CE_None)
            m_osError = "SHADOWS=all: the DEM has no geotransform";
        else
        {
            const OGRSpatialReference *poSRS = poDEM->GetSpatialRef();
            OGRSpatialReferenceH hSRS =
                poSRS ? OGRSpatialReference::ToHandle(const_cast<OGRSpatialReference *>(poSRS))
                      : nullptr;
            ts_status eSt = tsd_cells_compute(adfGT, W, H, hSRS, m_sMetaOpts.cell_sizes, &sCells,
                                              szMsg, sizeof szMsg);
            if (eSt == TS_OK)
                eSt = tsd_dem_load(GDALRasterBand::ToHandle(poDEM->GetRasterBand(nBandDEM)),
                                   &sCells, m_sMetaOpts.z_factor, &sGrid, szMsg, sizeof szMsg);
            if (eSt != TS_OK)
            {
                m_nErr = ErrorNum(eSt);
                m_osError = std::string("SHADOWS=all: ") + szMsg;
            }
            else
                bGrid = true;
        }
        const size_t nCells = static_cast<size_t>(W) * H;
        if (bGrid)
        {
            m_pabyNear = static_cast<GByte *>(VSI_MALLOC2_VERBOSE(nCells, psInfo->steps));
            pafPlane = static_cast<float *>(VSI_MALLOC2_VERBOSE(nCells, sizeof(float)));
            if (!m_pabyNear || !pafPlane)
            {
                m_nErr = ErrorNum(TS_ERR_NOMEM);
                m_osError = "out of memory for the near shadows";
            }
        }
        for (int k = 0; bGrid && m_osError.empty() && k < psInfo->steps; k++)
        {
            const ts_atlas_step *psStep = ts_atlas_get_step(m_psAtlas, k);
            ts_error sErr;
            GByte *pabyOut = m_pabyNear + static_cast<size_t>(k) * nCells;
            if (!std::isfinite(psStep->grid_azimuth) || !std::isfinite(psStep->elevation))
            {
                m_osError = CPLSPrintf("SHADOWS=all: map %d of the atlas "
                                       "records no sun position", k + 1);
                break;
            }
            if (ts_horizon_sweep(&sGrid, psStep->grid_azimuth, &sH, pafPlane, &sErr) != TS_OK)
            {
                m_nErr = ErrorNum(sErr.code);
                m_osError = sErr.message;
                break;
            }
            const float fEl = static_cast<float>(psStep->elevation);
            for (int y = 0; y < H; y++)
            {
                const int gy = sCells.flip_y ? H - 1 - y : y;
                for (int x = 0; x < W; x++)
                {
                    const int gx = sCells.flip_x ? W - 1 - x : x;
                    const float v = pafPlane[static_cast<size_t>(gy) * W + gx];
                    pabyOut[static_cast<size_t>(y) * W + x] = v > fEl ? 1 : 0;
                }
            }
        }
        VSIFree(pafPlane);
        if (bGrid)
            ts_grid_free(&sGrid);
        tsd_cells_free(&sCells);
        if (m_poDEM) // read: its handle is not kept
            GDALClose(m_poDEM);
        m_poDEM = nullptr;
        if (!m_osError.empty())
        {
            VSIFree(m_pabyNear);
            m_pabyNear = nullptr;
        }
    }
    if (!m_osError.empty())
    {
        Fail(m_nErr, m_osError.c_str());
        return CE_Failure;
    }
    return CE_None;
}

GDALDataset *TSAtlasDataset::Open(GDALOpenInfo *poOpenInfo)
{
    if (poOpenInfo->eAccess == GA_Update)
        return FailOpen(CPLE_NotSupported,
                        "far-shadow atlases are read-only; write a new one with "
                        "gdal_translate -of TERRASHADE");
    tsd_options sOpts;
    char szMsg[1024];
    tsd_options_defaults(&sOpts);
    if (tsd_options_apply_atlas(&sOpts, poOpenInfo->papszOpenOptions, szMsg,
                                sizeof szMsg) != 0)
        return FailOpen(TS_ERR_ARG, szMsg);
    const bool bAll = sOpts.shadows_all != 0;
    const std::string osDEM = sOpts.dem;
    const int nThreads = sOpts.threads;
    VSILFILE *fp = VSIFOpenL(poOpenInfo->pszFilename, "rb");
    if (!fp)
        return FailOpen(CPLE_OpenFailed, CPLSPrintf("cannot open the atlas '%s'",
                                                      poOpenInfo->pszFilename));
    VSIFSeekL(fp, 0, SEEK_END);
    const vsi_l_offset nSize = VSIFTellL(fp);
    VSIFSeekL(fp, 0, SEEK_SET);
    // the header first, checked against the file's size: the file was read
    // whole (up to 1 TiB; a /vsicurl/ one downloaded) before its header
    // said that it ends much earlier (an audit); now a file longer or
    // shorter than its header says is refused before the rest is read
    GByte abyHead[TS_ATLAS_HEADER_SIZE];
    const size_t nHead = static_cast<size_t>(
        std::min(nSize, static_cast<vsi_l_offset>(sizeof abyHead)));
    ts_error sErr;
    bool bRead = VSIFReadL(abyHead, 1, nHead, fp) == nHead;
    ts_status eSt = bRead ? ts_atlas_check_header(abyHead, nHead, nSize, &sErr) : TS_OK;
    GByte *pabyFile = nullptr;
    if (bRead && eSt == TS_OK)
    {
        pabyFile = nSize < (static_cast<vsi_l_offset>(1) << 40)
                       ? static_cast<GByte *>(VSI_MALLOC_VERBOSE(static_cast<size_t>(nSize)))
                       : nullptr;
        bRead = pabyFile != nullptr;
        if (bRead)
        {
            memcpy(pabyFile, abyHead, nHead);
            const size_t nRest = static_cast<size_t>(nSize) - nHead;
            bRead = VSIFReadL(pabyFile + nHead, 1, nRest, fp) == nRest;
        }
    }
    VSIFCloseL(fp);
    ts_atlas *psAtlas = nullptr;
    if (!bRead)
    {
        VSIFree(pabyFile);
        return FailOpen(CPLE_FileIO, CPLSPrintf("cannot read the atlas '%s'",
                                                  poOpenInfo->pszFilename));
    }
    if (eSt == TS_OK)
        eSt = ts_atlas_open(pabyFile, static_cast<size_t>(nSize), &psAtlas, &sErr);
    VSIFree(pabyFile);
    // a file that does not read as an atlas: FileIO, as docs/driver.md's
    // errors say (the core's argument error read as a bad option, 5)
    if (eSt != TS_OK)
    {
        const char *pszMsg = CPLSPrintf("'%s': %s", poOpenInfo->pszFilename, sErr.message);
        return eSt == TS_ERR_NOMEM ? FailOpen(eSt, pszMsg) : FailOpen(CPLE_FileIO, pszMsg);
    }
    auto poDS = std::unique_ptr<TSAtlasDataset>(new TSAtlasDataset());
    poDS->m_psAtlas = psAtlas;
    const ts_atlas_info *psInfo = ts_atlas_get_info(psAtlas);
    poDS->nRasterXSize = psInfo->width;
    poDS->nRasterYSize = psInfo->height;
    poDS->m_bHasGT = psInfo->has_geotransform;
    memcpy(poDS->m_adfGT, psInfo->geotransform, sizeof poDS->m_adfGT);
    poDS->m_aosMeta = AtlasMetadata(psInfo->metadata);
    const std::string osCause =
        CheckAtlasMetadata(poDS->m_aosMeta, psInfo->steps, &poDS->m_sMetaOpts);
    if (!osCause.empty())
        return FailOpen(TS_ERR_ARG, CPLSPrintf("'%s': atlas metadata: %s",
                                                 poOpenInfo->pszFilename, osCause.c_str()));
    for (int k = 0; k < psInfo->steps; k++)
        if (!std::isfinite(ts_atlas_get_step(psAtlas, k)->unix_time))
            return FailOpen(TS_ERR_ARG,
                            CPLSPrintf("'%s': atlas step table: map %d has no time, but "
                                       "every map of PRODUCT=farshadow has one",
                                       poOpenInfo->pszFilename, k + 1));
    poDS->m_bAll = bAll;
    poDS->m_nThreads = nThreads;
    poDS->m_bDEMGiven = !osDEM.empty();
    if (poDS->m_bDEMGiven && !bAll) // (it was taken without a word)
        return FailOpen(TS_ERR_ARG, "DEM applies with SHADOWS=all only, which recomputes the "
                                    "near shadows from it; SHADOWS=far reads the atlas alone");
    poDS->m_osDEM = !osDEM.empty() ? osDEM
                                   : AtlasSourceDEM(poOpenInfo->pszFilename,
                                                    poDS->m_aosMeta.FetchNameValueDef(
                                                        "SOURCE_DEM", ""));
    if (bAll && poDS->m_osDEM.empty())
        return FailOpen(TS_ERR_ARG,
                          "SHADOWS=all recomputes the near shadows from the DEM, but the "
                          "atlas names none: give it with the open option DEM=...");
    // a pipe's open (also an atlas's SOURCE_DEM, which anyone who sends
    // the file writes) would wait for ever, and a MEM::: name reads memory
    const std::string osRefused =
        bAll ? RefusedDEMName(poDS->m_osDEM.c_str(),
                              poDS->m_bDEMGiven ? "the DEM" : "the atlas's SOURCE_DEM",
                              !poDS->m_bDEMGiven)
             : std::string();
    if (!osRefused.empty())
        return FailOpen(TS_ERR_ARG, osRefused.c_str());
    if (bAll && IsAtlasFile(poDS->m_osDEM.c_str()))
        return FailOpen(TS_ERR_ARG, AtlasAsDEM(poDS->m_osDEM, poDS->m_bDEMGiven).c_str());
    int nOffset = atoi(poDS->m_aosMeta.FetchNameValueDef("UTC_OFFSET_MINUTES", "0"));
    for (int i = 0; i < poDS->m_aosMeta.size(); i++)
    {
        char *pszKey = nullptr;
        const char *pszValue = CPLParseNameValue(poDS->m_aosMeta[i], &pszKey);
        if (pszKey && pszValue)
        {
            if (EQUAL(pszKey, "SRS_WKT"))
            {
                poDS->m_oSRS.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
                if (poDS->m_oSRS.importFromWkt(pszValue) != OGRERR_NONE)
                {
                    CPLFree(pszKey);
                    return FailOpen(TS_ERR_ARG,
                                    CPLSPrintf("'%s': atlas metadata: SRS_WKT is not a CRS "
                                               "GDAL can read", poOpenInfo->pszFilename));
                }
            }
            else
                poDS->GDALDataset::SetMetadataItem(pszKey, pszValue);
        }
        CPLFree(pszKey);
    }
    // a relative SOURCE_DEM found beside the atlas: its path from here, so
    // that a copy of the atlas written elsewhere names the same file
    if (!poDS->m_bDEMGiven && !poDS->m_osDEM.empty())
        poDS->GDALDataset::SetMetadataItem("SOURCE_DEM", poDS->m_osDEM.c_str());
    if (bAll)
    {
        // the DEM at open, not at the first read (a QGIS layer opened and
        // then failed block by block), and the same ground as the atlas (a
        // copy moved or reprojected, of the same size, was taken)
        poDS->m_poDEM =
            GDALDataset::Open(poDS->m_osDEM.c_str(), GDAL_OF_RASTER | GDAL_OF_VERBOSE_ERROR);
        if (!poDS->m_poDEM)
            return FailOpen(CPLE_OpenFailed,
                            CPLSPrintf("SHADOWS=all cannot open the DEM '%s'%s (give it with "
                                       "the open option DEM=...)", poDS->m_osDEM.c_str(),
                                       poDS->m_bDEMGiven ? "" : " (the atlas's SOURCE_DEM)"));
        // a product as the DEM: its shading was taken as the near field's heights
        const std::string osProduct = ProductAsDEM(poDS->m_poDEM, poDS->m_osDEM);
        if (!osProduct.empty())
            return FailOpen(TS_ERR_ARG, osProduct.c_str());
        const std::string osWhy = CheckAtlasDEM(
            poDS->m_poDEM, poDS->m_osDEM, poDS->m_bDEMGiven, psInfo->width, psInfo->height,
            poDS->m_bHasGT, poDS->m_adfGT, poDS->m_oSRS.IsEmpty() ? nullptr : &poDS->m_oSRS);
        if (!osWhy.empty())
            return FailOpen(TS_ERR_ARG, osWhy.c_str());
        // what a copy holds: far and near shadows (CheckAtlasSource refuses it)
        poDS->GDALDataset::SetMetadataItem("SHADOWS", "all");
    }
    for (int k = 0; k < psInfo->steps; k++)
    {
        auto poBand = new TSAtlasBand(poDS.get(), k + 1);
        poDS->SetBand(k + 1, poBand);
        const ts_atlas_step *r = ts_atlas_get_step(psAtlas, k);
        SetStepMetadata(poBand, r->unix_time, std::isfinite(r->unix_time)
                                                  ? r->utc_offset_minutes : nOffset,
                        r->azimuth, r->grid_azimuth, r->elevation,
                        std::numeric_limits<double>::quiet_NaN());
        if (!std::isfinite(r->unix_time))
            poBand->GDALMajorObject::SetDescription(CPLSPrintf("map %d", k + 1));
    }
    poDS->SetDescription(poOpenInfo->pszFilename);
    // SHADOWS=all is other pixels than the atlas's own (and another DEM's
    // near shadows are others again): each view has an entry of its own in
    // the atlas's .aux.xml, where the two reported each other's statistics
    // and histograms and the far view took SHADOWS=all from the saved
    // metadata (and GDAL rewrites the file whole for a view without one)
    // (DEM= by its absolute path: a relative one is read from the working
    // directory, and two DEMs of one name shared an entry: the review)
    const std::string osView =
        bAll ? "SHADOWS=all" +
                   (poDS->m_bDEMGiven ? ":DEM=" + AbsolutePath(poDS->m_osDEM.c_str()) : "")
             : std::string("SHADOWS=far");
    if (bAll && IsStdinName(poDS->m_osDEM))
        poDS->nPamFlags |= GPF_DISABLED; // the next run's standard input is another DEM
    const char *pszPam = poDS->BuildPamFilename();
    const bool bHasView = pszPam && HasPamEntry(pszPam, osView.c_str(), nullptr);
    if (!bAll && pszPam && !bHasView)
    {
        // the file's top level, where the atlas's entries were before
        // session 57: what the user set is saved as the view's; its
        // statistics and histograms may be the other view's (one entry
        // served both), and are computed again
        poDS->TryLoadXML();
        for (int i = 1; i <= poDS->nBands; i++)
            static_cast<TSAtlasBand *>(poDS->GetRasterBand(i))->DropSavedStatistics();
    }
    poDS->SetSubdatasetName(osView.c_str());
    if (!pszPam || bHasView)
        poDS->TryLoadXML();
    // the driver's own items over what the entry holds (one saved by an
    // earlier version for the other view)
    poDS->GDALDataset::SetMetadataItem("SHADOWS", bAll ? "all" : nullptr);
    if (!poDS->m_bDEMGiven && !poDS->m_osDEM.empty())
        poDS->GDALDataset::SetMetadataItem("SOURCE_DEM", poDS->m_osDEM.c_str());
    poDS->nPamFlags &= ~GPF_DIRTY;
    // statistics saved for other contents of the atlas's file or, with
    // SHADOWS=all, of the DEM's (regenerated under the same name: the
    // view's entry reported the former DEM's near shadows' statistics): dropped,
    // and the entry saved without them at close
    // (the atlas's file passed as SourceFiles' one other file)
    std::vector<std::string> aosFiles = SourceFiles(nullptr, poOpenInfo->pszFilename);
    if (bAll && !(poDS->nPamFlags & GPF_DISABLED)) // (none for a standard input's DEM)
    {
        char **papszDEMFiles = poDS->m_poDEM->GetFileList();
        const std::vector<std::string> aosDEM = SourceFiles(papszDEMFiles, nullptr);
        CSLDestroy(papszDEMFiles);
        aosFiles.insert(aosFiles.end(), aosDEM.begin(), aosDEM.end());
    }
    poDS->m_osPamStamp = SourceStamp(aosFiles);
    DropStaleStatistics(poDS.get(), poDS->m_osPamStamp);
    return poDS.release();
}

/* Store the bands of any raster whose values are 0, 1 or nodata. */
GDALDataset *TSAtlasDataset::CreateCopy(const char *pszFilename, GDALDataset *poSrcDS,
                                        int /*bStrict*/, char ** /*papszOptions*/,
                                        GDALProgressFunc pfnProgress, void *pProgressData)
{
    const int W = poSrcDS->GetRasterXSize(), H = poSrcDS->GetRasterYSize();
    const int nBands = poSrcDS->GetRasterCount();
    if (nBands < 1)
        return FailOpen(CPLE_NotSupported, "an atlas needs at least one band");
    const std::string osNotShadow = CheckAtlasSource(poSrcDS);
    if (!osNotShadow.empty())
        return FailOpen(CPLE_NotSupported, osNotShadow.c_str());
    if (!pfnProgress)
        pfnProgress = GDALDummyProgress;
    ts_error sErr;
    ts_atlas_writer *psW = nullptr;
    if (ts_atlas_writer_new(W, H, &psW, &sErr) != TS_OK)
        return FailOpen(sErr.code, sErr.message);
    std::unique_ptr<ts_atlas_writer, void (*)(ts_atlas_writer *)> oW(psW, ts_atlas_writer_free);
    const size_t nCells = static_cast<size_t>(W) * H;
    std::vector<GByte> abyPlane;
    std::vector<double> adfRow;
    try
    {
        abyPlane.resize(nCells);
        adfRow.resize(static_cast<size_t>(W));
    }
    catch (const std::bad_alloc &)
    {
        return FailOpen(TS_ERR_NOMEM, "out of memory for one map of the atlas");
    }
    const int nOffset =
        atoi(CSLFetchNameValueDef(poSrcDS->GetMetadata(), "UTC_OFFSET_MINUTES", "0"));
    for (int b = 1; b <= nBands; b++)
    {
        GDALRasterBand *poBand = poSrcDS->GetRasterBand(b);
        int bHasNoData = FALSE;
        const double dfNoData = poBand->GetNoDataValue(&bHasNoData);
        for (int y = 0; y < H; y++)
        {
            if (poBand->RasterIO(GF_Read, 0, y, W, 1, adfRow.data(), W, 1, GDT_Float64, 0, 0,
                                 nullptr) != CE_None)
                return nullptr; // GDAL has said why
            GByte *row = abyPlane.data() + static_cast<size_t>(y) * W;
            for (int x = 0; x < W; x++)
            {
                const double v = adfRow[x];
                if (std::isnan(v) || (bHasNoData && v == dfNoData))
                    row[x] = TS_ATLAS_NODATA;
                else if (v == 0 || v == 1)
                    row[x] = static_cast<GByte>(v);
                else
                    return FailOpen(
                        CPLE_NotSupported,
                        CPLSPrintf("band %d holds the value %g at column %d, row %d: an "
                                   "atlas stores binary maps (0, 1 and nodata), such as "
                                   "PRODUCT=farshadow", b, v, x, y));
            }
        }
        auto fetch = [poBand](const char *pszKey) {
            const char *v = poBand->GetMetadataItem(pszKey);
            return v ? CPLAtof(v) : std::numeric_limits<double>::quiet_NaN();
        };
        ts_atlas_step sStep{fetch("UNIX_TIME"), fetch("SUN_AZIMUTH_TRUE"),
                            fetch("SUN_AZIMUTH"), fetch("SUN_ELEVATION"), nOffset};
        if (ts_atlas_writer_add(psW, abyPlane.data(), W, &sStep, &sErr) != TS_OK)
            return FailOpen(sErr.code, CPLSPrintf("band %d: %s", b, sErr.message));
        if (!pfnProgress(0.95 * b / nBands, nullptr, pProgressData))
        {
            Fail(TS_ERR_CANCELLED, "interrupted");
            return nullptr;
        }
    }
    /* metadata text: the source's metadata, its CRS, its threshold */
    std::string osText;
    for (char **p = poSrcDS->GetMetadata(); p && *p; p++)
    {
        std::string osLine = *p;
        if (STARTS_WITH_CI(osLine.c_str(), "SOURCE_DEM=")) // as the atlas's folder names it
            osLine = "SOURCE_DEM=" + AtlasSourceDEMToWrite(pszFilename, osLine.substr(11));
        std::replace(osLine.begin(), osLine.end(), '\n', ' ');
        std::replace(osLine.begin(), osLine.end(), '\r', ' ');
        if (!STARTS_WITH_CI(osLine.c_str(), "SRS_WKT="))
            osText += osLine + "\n";
    }
    if (const OGRSpatialReference *poSRS = poSrcDS->GetSpatialRef())
    {
        char *pszWKT = nullptr;
        const char *apszOpts[] = {"FORMAT=WKT2_2019", "MULTILINE=NO", nullptr};
        if (poSRS->exportToWkt(&pszWKT, apszOpts) == OGRERR_NONE && pszWKT)
            osText += std::string("SRS_WKT=") + pszWKT + "\n";
        CPLFree(pszWKT);
    }
    ts_atlas_info sInfo{};
    sInfo.has_geotransform = poSrcDS->GetGeoTransform(sInfo.geotransform) == CE_None;
    const char *pszT = poSrcDS->GetMetadataItem("FAR_THRESHOLD");
    const char *pszTm = poSrcDS->GetMetadataItem("FAR_THRESHOLD_M");
    sInfo.threshold_cells = pszT ? atoi(pszT) : 0;
    sInfo.threshold_m = pszTm ? CPLAtof(pszTm) : std::numeric_limits<double>::quiet_NaN();
    sInfo.metadata = osText.c_str();
    uint8_t *pabyFile = nullptr;
    size_t nSize = 0;
    if (ts_atlas_writer_finish(psW, &sInfo, &pabyFile, &nSize, &sErr) != TS_OK)
        return FailOpen(sErr.code, sErr.message);
    // Only a regular file (or a new one) is written, and only what this
    // call opened is removed on failure: it unlinked whatever the path named
    // when the write failed, so that /dev/full itself, a symlink, or another
    // user's write-protected file in an unwritable folder went (an audit)
    VSIStatBufL sStat;
    if (VSIStatL(pszFilename, &sStat) == 0 && !VSI_ISREG(sStat.st_mode))
    {
        free(pabyFile);
        return FailOpen(CPLE_FileIO,
                        CPLSPrintf("cannot write the atlas '%s': it exists and is not a "
                                   "regular file (a folder, a device, a pipe); an atlas is "
                                   "a file of its own",
                                   pszFilename));
    }
    errno = 0;
    VSILFILE *fp = VSIFOpenL(pszFilename, "wb");
    int nErrno = errno;
    bool bOK = fp && VSIFWriteL(pabyFile, 1, nSize, fp) == nSize;
    if (fp && !bOK)
        nErrno = errno;
    if (fp && VSIFCloseL(fp) != 0 && bOK)
    {
        bOK = false;
        nErrno = errno;
    }
    free(pabyFile);
    if (!bOK)
    {
        if (fp) // its contents are this call's, cut short
            VSIUnlink(pszFilename);
        return FailOpen(CPLE_FileIO,
                        CPLSPrintf("cannot write the atlas '%s'%s%s", pszFilename,
                                   nErrno ? ": " : "", nErrno ? VSIStrerror(nErrno) : ""));
    }
    CPLDebug(DRIVER, "wrote the atlas %s: %d maps of %d x %d, %zu bytes (%.4f bits per cell)",
             pszFilename, nBands, W, H, nSize, nSize * 8.0 / nCells);
    pfnProgress(1.0, nullptr, pProgressData);
    GDALOpenInfo oOpenInfo(pszFilename, GA_ReadOnly);
    return TSAtlasDataset::Open(&oOpenInfo);
}

int IdentifyAtlas(GDALOpenInfo *poOpenInfo)
{
    return poOpenInfo->nHeaderBytes >= 8 &&
           ts_atlas_identify(poOpenInfo->pabyHeader,
                             static_cast<size_t>(poOpenInfo->nHeaderBytes));
}

GDALDataset *OpenAtlas(GDALOpenInfo *poOpenInfo)
{
    return TSAtlasDataset::Open(poOpenInfo);
}

GDALDataset *CreateAtlasCopy(const char *pszFilename, GDALDataset *poSrcDS, int bStrict,
                             char **papszOptions, GDALProgressFunc pfnProgress,
                             void *pProgressData)
{
    return TSAtlasDataset::CreateCopy(pszFilename, poSrcDS, bStrict, papszOptions,
                                      pfnProgress, pProgressData);
}

} // namespace tsd
