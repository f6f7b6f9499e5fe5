/*
 * tsd_dataset_metadata.cpp - the metadata of a TERRASHADE:<dem> dataset:
 * the options used, the cells, the bands (from the product table), where
 * and when the sun was placed, the backend that ran (asked for lazily, so
 * that opening costs no OpenCL initialisation), and PAM next to the DEM.
 */
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cpl_conv.h"
#include "cpl_minixml.h"
#include "cpl_string.h"

#include "tsd_dataset.h"
#include "tsd_gdal.h"
#include "tsd_pam_turn.h"
#include "tsd_entry_state.h"
#include "tsd_source_stamp.h"

namespace tsd
{

/* The BACKEND items asked for before the product is computed (gdalinfo;
 * gdal_translate copies the metadata before reading): the dispatcher's
 * choice, which probes the OpenCL device. Not done at open, so that opening
 * costs no OpenCL initialisation. */
void TSDataset::EnsureBackendMetadata()
{
    // asked for from the progress callback of this dataset's own computation,
    // which holds the mutex: computing says what ran
    if (m_oComputer.load() == std::this_thread::get_id())
        return;
    std::lock_guard<std::mutex> oLock(m_oMutex);
    if (!m_bUsesBackend || m_bBackendKnown || m_bTried)
        return;
    char szMsg[256];
    StartReadAhead(); // the DEM is read meanwhile
    if (tsd_backend_predict(&m_sOpts, &m_sBackend, szMsg, sizeof szMsg) != 0)
        return; // TERRASHADE_BACKEND changed since open: computing will say
    m_bBackendKnown = true;
    SetupBackendMetadata();
}

char **TSDataset::GetMetadata(const char *pszDomain)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    if (!pszDomain || !*pszDomain)
        EnsureBackendMetadata();
    return GDALPamDataset::GetMetadata(pszDomain);
}

const char *TSDataset::GetMetadataItem(const char *pszName, const char *pszDomain)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    if ((!pszDomain || !*pszDomain) && pszName && STARTS_WITH_CI(pszName, "BACKEND"))
        EnsureBackendMetadata();
    return GDALPamDataset::GetMetadataItem(pszName, pszDomain);
}

/* BACKEND, BACKEND_DEVICE, BACKEND_FALLBACK_REASON of m_sBackend. */
void TSDataset::SetupBackendMetadata()
{
    if (!m_bUsesBackend || !m_bBackendKnown)
        return;
    char szBackend[16], szDevice[512];
    tsd_backend_summary_text(&m_sBackend, szBackend, sizeof szBackend, szDevice,
                             sizeof szDevice);
    GDALDataset::SetMetadataItem("BACKEND", szBackend);
    GDALDataset::SetMetadataItem("BACKEND_DEVICE", szDevice);
    GDALDataset::SetMetadataItem("BACKEND_FALLBACK_REASON",
                                 m_sBackend.reason[0] ? m_sBackend.reason : nullptr);
}

/* After computing: say where it ran; a warning when OpenCL was asked for
 * (BACKEND=opencl or TERRASHADE_BACKEND=opencl) and C ran, unless bMayWarn
 * is false (a windowed product warns at its first chunk that ran C only).
 * true when it warned. */
bool TSDataset::ReportBackend(bool bMayWarn)
{
    const tsd_backend_summary &s = m_sBackend;
    char szBackend[16], szDevice[512];
    tsd_backend_summary_text(&s, szBackend, sizeof szBackend, szDevice, sizeof szDevice);
    const bool bWarn = bMayWarn && s.requested == TS_BACKEND_OPENCL && s.c_calls > 0;
    if (bWarn)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: BACKEND=opencl was requested, but %d of %d computation(s) "
                 "ran on the C backend instead: %s",
                 s.c_calls, s.calls, s.reason[0] ? s.reason : "(no reason given)");
    else if (s.c_calls > 0 && s.reason[0])
        CPLDebug(DRIVER, "backend %s (%s) requested, C ran: %s",
                 ts_backend_name(s.requested), szDevice, s.reason);
    CPLDebug(DRIVER, "backend: %s on %s (%d call(s): %d OpenCL, %d C)", szBackend,
             szDevice, s.calls, s.opencl_calls, s.c_calls);
    return bWarn;
}

void TSDataset::SetupMetadata()
{
    char szValue[TSD_PATH_MAX]; // ENV_MAP's whole path
    const int nBands = GetRasterCount();
    // envlight under ENV_MAP, or a sky without a sun (uniform, overcast):
    // no sun lights it, so its options record none (SUN_AZIMUTH=315 read
    // as the light's direction)
    const bool bSunless =
        m_psProduct->compute == tsd_compute_envlight && tsd_environment_sunless(&m_sOpts);
    for (int i = 0; i < tsd_options_count(); i++)
    {
        const char *pszName = tsd_options_value(&m_sOpts, i, szValue, sizeof szValue);
        if (bSunless && (EQUAL(pszName, "SUN_AZIMUTH") || EQUAL(pszName, "SUN_ELEVATION") ||
                         EQUAL(pszName, "DELTA_T") || EQUAL(pszName, "PRESSURE") ||
                         EQUAL(pszName, "TEMPERATURE")))
            continue;
        // only the options of this product: an atlas copied from it is
        // validated against them (tsd_atlas_check.cpp)
        const bool bApplies = tsd_option_applies(i) == TSD_APPLIES_SELECTOR ||
                              tsd_product_takes(m_psProduct, i);
        // a date range's own settings say nothing of one day
        const bool bRangeOnly =
            EQUAL(pszName, "DAY_INTERVAL") || EQUAL(pszName, "HORIZON_DIRECTIONS");
        if (!bApplies || EQUAL(pszName, "THREADS") || EQUAL(pszName, "MAX_MEMORY") ||
            EQUAL(pszName, "BACKEND") || !szValue[0] ||
            (bRangeOnly && !tsd_options_is_range(&m_sOpts)))
            continue; // BACKEND: what ran (SetupBackendMetadata)
        GDALDataset::SetMetadataItem(pszName, szValue);
    }
    GDALDataset::SetMetadataItem("SOURCE_DEM", m_osDEM.c_str());
    // (a local or engineering CRS is measured as a projected one's grid)
    const char *pszKind = m_sCells.kind == TSD_CRS_GEOGRAPHIC ? "geographic"
                          : m_sCells.kind == TSD_CRS_PROJECTED
                              ? (m_oProductSRS.IsLocal() ? "local" : "projected")
                              : "none";
    GDALDataset::SetMetadataItem("SOURCE_CRS_KIND", pszKind);
    GDALDataset::SetMetadataItem("CELL_SIZE_X", CPLSPrintf("%.6f", m_sCells.cell_x));
    GDALDataset::SetMetadataItem("CELL_SIZE_Y", CPLSPrintf("%.6f", m_sCells.cell_y));
    std::string osSource =
        m_sCells.kind == TSD_CRS_GEOGRAPHIC ? "ground: geodesic on the CRS's ellipsoid"
        : m_sCells.kind == TSD_CRS_NONE     ? "no CRS: the geotransform's units taken as metres"
        : m_sCells.ground ? "ground: geodesic on the CRS's ellipsoid, along the central column"
                          : "grid: the geotransform's pixel size in the CRS's unit";
    if (m_sCells.kind == TSD_CRS_PROJECTED && m_sCells.scale_hi > 0)
        osSource += CPLSPrintf(" (the projection's scale %.4f to %.4f over the DEM)",
                               m_sCells.scale_lo, m_sCells.scale_hi);
    GDALDataset::SetMetadataItem("CELL_SIZE_SOURCE", osSource.c_str());
    if (m_sCells.cell_x_row)
    {
        GDALDataset::SetMetadataItem(
            "CELL_SIZE_X_NORTH", CPLSPrintf("%.6f", m_sCells.cell_x_row[0]));
        GDALDataset::SetMetadataItem(
            "CELL_SIZE_X_SOUTH",
            CPLSPrintf("%.6f", m_sCells.cell_x_row[nRasterYSize - 1]));
    }
    for (int k = 0; m_psProduct->describe_band && k < nBands; k++)
    {
        tsd_band_info sInfo{};
        m_psProduct->describe_band(m_psProduct, &m_sOpts, k, &sInfo);
        GDALRasterBand *poBand = GetRasterBand(k + 1);
        poBand->GDALMajorObject::SetDescription(sInfo.description);
        if (sInfo.key)
            poBand->GDALMajorObject::SetMetadataItem(sInfo.key, sInfo.value);
        if (sInfo.color)
            static_cast<TSRasterBand *>(poBand)->SetColor(
                GDALGetColorInterpretationByName(sInfo.color));
    }
    // chunk by chunk, the far grid's size: MAX_MEMORY (three quarters of the
    // machine's memory by default) can make it coarser, and the far field
    // with it, where the options alone say nothing (docs/windows.md)
    if (const tsd_window_plan *psPlan = WindowPlan(m_poWindow))
        GDALDataset::SetMetadataItem("FAR_GRID",
                                     CPLSPrintf("%d x %d", psPlan->far_w, psPlan->far_h));
    SetupEnvironmentMetadata();
    if (m_bHasSun)
        SetupSunMetadata();
    SetupBackendMetadata();
}

void SetStepMetadata(GDALMajorObject *poObj, double dfTime, int nOffset,
                          double dfAzTrue, double dfAzGrid, double dfEl, double dfDuration)
{
    if (std::isfinite(dfTime))
    {
        char szTime[64];
        tsd_format_time(dfTime, nOffset, szTime, sizeof szTime);
        poObj->SetDescription(szTime);
        poObj->SetMetadataItem("TIME", szTime);
        poObj->SetMetadataItem("UNIX_TIME", CPLSPrintf("%.3f", dfTime));
    }
    if (std::isfinite(dfDuration))
        poObj->SetMetadataItem("DURATION_MINUTES", CPLSPrintf("%.10g", dfDuration / 60));
    if (std::isfinite(dfAzGrid))
        poObj->SetMetadataItem("SUN_AZIMUTH", CPLSPrintf("%.6f", dfAzGrid));
    if (std::isfinite(dfAzTrue))
        poObj->SetMetadataItem("SUN_AZIMUTH_TRUE", CPLSPrintf("%.6f", dfAzTrue));
    if (std::isfinite(dfEl))
        poObj->SetMetadataItem("SUN_ELEVATION", CPLSPrintf("%.6f", dfEl));
}

/* Where and when the sun was placed, with the names of the values used. */
void TSDataset::SetupSunMetadata()
{
    const tsd_sun &s = m_sSun;
    const int nRef = (s.sites.ny / 2) * s.sites.nx + s.sites.nx / 2;
    const double dfNorth = s.sites.north_azimuth[nRef];
    GDALDataset::SetMetadataItem("SUN_SITE_LONGITUDE",
                                 CPLSPrintf("%.8f", s.sites.longitude[nRef]));
    GDALDataset::SetMetadataItem("SUN_SITE_LATITUDE",
                                 CPLSPrintf("%.8f", s.sites.latitude[nRef]));
    // (a geographic grid's 0 was written -0.000000)
    std::string osConvergence = CPLSPrintf("%.6f", -dfNorth);
    if (osConvergence == "-0.000000")
        osConvergence.erase(0, 1);
    GDALDataset::SetMetadataItem("MERIDIAN_CONVERGENCE", osConvergence.c_str());
    GDALDataset::SetMetadataItem("SUN_MODEL", "SPA (Reda & Andreas 2004), apparent "
                                              "elevation with refraction");
    char szTime[64];
    if (!m_psProduct->daily)
    {
        tsd_format_instant(s.instant, s.offset_minutes, szTime, sizeof szTime);
        GDALDataset::SetMetadataItem("SUN_TIME", szTime);
        GDALDataset::SetMetadataItem("SUN_AZIMUTH", CPLSPrintf("%.6f", s.sun.grid_azimuth));
        GDALDataset::SetMetadataItem("SUN_AZIMUTH_TRUE", CPLSPrintf("%.6f", s.sun.azimuth));
        GDALDataset::SetMetadataItem("SUN_ELEVATION", CPLSPrintf("%.6f", s.sun.elevation));
        return;
    }
    /* a day: the sun's azimuth and elevation change; SUN_AZIMUTH and
     * SUN_ELEVATION of the options do not apply */
    GDALDataset::SetMetadataItem("SUN_AZIMUTH", nullptr);
    GDALDataset::SetMetadataItem("SUN_ELEVATION", nullptr);
    tsd_format_time(s.day_start, s.offset_minutes, szTime, sizeof szTime);
    GDALDataset::SetMetadataItem("DAY_START", szTime);
    tsd_format_time(s.day_start + s.day_length, s.offset_minutes, szTime, sizeof szTime);
    GDALDataset::SetMetadataItem("DAY_END", szTime);
    GDALDataset::SetMetadataItem("UTC_OFFSET_MINUTES", CPLSPrintf("%d", s.offset_minutes));
    if (s.is_range)
    {
        /* the range used: its last day, length, days computed, and the step
         * (30 minutes when STEP_MINUTES is not given) */
        const ts_date_range &r = s.range;
        GDALDataset::SetMetadataItem(
            "END_DATE", CPLSPrintf("%04d-%02d-%02d", r.last_year, r.last_month, r.last_day));
        GDALDataset::SetMetadataItem("STEP_MINUTES", CPLSPrintf("%.10g", r.step_minutes));
        GDALDataset::SetMetadataItem("RANGE_DAYS", CPLSPrintf("%d", s.range_days));
        GDALDataset::SetMetadataItem("RANGE_SAMPLED_DAYS", CPLSPrintf("%d", s.range_sampled));
        GDALDataset::SetMetadataItem("RANGE_DAY_WEIGHT",
                                     "the range is cut into blocks of DAY_INTERVAL days "
                                     "from START_DATE (the last one shorter); each block's "
                                     "middle day is computed and counts for its days");
    }
    if (m_psProduct->model_key)
        GDALDataset::SetMetadataItem(m_psProduct->model_key, m_psProduct->model);
    if (m_psProduct->steps == TSD_STEPS_ATLAS)
        GDALDataset::SetMetadataItem("FAR_THRESHOLD_M", CPLSPrintf("%.6f", s.threshold_m));
    for (int k = 0; k < s.steps; k++)
        SetStepMetadata(GetRasterBand(k + 1), s.times[k], s.offset_minutes,
                        s.samples[k].azimuth, s.samples[k].grid_azimuth,
                        s.samples[k].elevation, s.durations[k]);
}

/* Auxiliary metadata (statistics...) goes next to the DEM's file, in a
 * subdataset entry per set of options, never into the current directory. */
/* The products of a DEM keep their entries (statistics, the user's nodata,
 * unit and colour) in a file of their own beside it, <DEM>.terrashade.aux.xml,
 * not in the DEM's own .aux.xml, which they once shared: GDAL rewrites such
 * a file whole (it reads it, then truncates and writes it), so processes
 * saving statistics of several products at once lost each other's entries
 * and the DEM's own, georeferencing included (a PNG's, kept there). Saves
 * and loads take turns, between threads and between processes
 * (PamFileTurn; docs/driver.md, PAM). */
const char *TSDataset::BuildPamFilename()
{
    if (!psPam)
        return nullptr;
    if (psPam->pszPamFilename)
        return psPam->pszPamFilename;
    const char *pszBase = GDALPamDataset::BuildPamFilename(); // <DEM>.aux.xml, or a proxy's
    if (!pszBase || m_bLegacyPam)
        return pszBase;
    std::string os(pszBase);
    const std::string osAux = ".aux.xml";
    if (os.size() > osAux.size() && EQUAL(os.c_str() + os.size() - osAux.size(), osAux.c_str()))
    {
        os.insert(os.size() - osAux.size(), ".terrashade");
        CPLFree(psPam->pszPamFilename);
        psPam->pszPamFilename = CPLStrdup(os.c_str());
    }
    return psPam->pszPamFilename;
}


/* The bytes of the file at osPath, for RestoreAfterFailedSave: false where
 * there is none (or it cannot be read, quietly: GDAL's save says why). */
static bool ReadForRestore(const std::string &osPath, std::vector<GByte> &oBytes)
{
    VSIStatBufL sStat;
    if (VSIStatL(osPath.c_str(), &sStat) != 0)
        return false;
    GByte *pabyOld = nullptr;
    vsi_l_offset nOld = 0;
    CPLPushErrorHandler(CPLQuietErrorHandler);
    const bool bRead = VSIIngestFile(nullptr, osPath.c_str(), &pabyOld, &nOld, 64 << 20) != 0;
    CPLPopErrorHandler();
    if (bRead)
        oBytes.assign(pabyOld, pabyOld + nOld);
    VSIFree(pabyOld);
    return bRead;
}

/* Put the bytes back in the file at osPath, in place (the same file: a
 * link, its owner and mode kept). */
static bool RestoreAfterFailedSave(const std::string &osPath, const std::vector<GByte> &oBytes)
{
    VSILFILE *fp = VSIFOpenL(osPath.c_str(), "wb");
    if (!fp)
        return false;
    const bool bOk = VSIFWriteL(oBytes.data(), 1, oBytes.size(), fp) == oBytes.size();
    return VSIFCloseL(fp) == 0 && bOk;
}

CPLErr TSDataset::TrySaveXML()
{
    const PamFileTurn oTurn(GetPhysicalFilename(), true);
    // the contents the entry's statistics are of (DropStaleStatistics)
    StampPamEntry(this, m_osPamStamp);
    const char *pszPam = psPam && !(nPamFlags & GPF_DISABLED) ? BuildPamFilename() : nullptr;
    if (m_bSavingOver || !pszPam)
        return GDALPamDataset::TrySaveXML(); // (GDAL's retry in its proxy folder, nested)
    // GDAL rewrites the file in place: reads it, truncates it, writes it. A
    // write cut short (a full disk) left it truncated, every product's
    // entries lost, the nodata and units users set among them: the former
    // bytes are put back, and the dataset is marked clean, so that its close
    // does not try again (GDAL's destructor saves in place, unguarded).
    const std::string osPam = pszPam;
    VSIStatBufL sStatBefore;
    std::vector<GByte> oOld;
    const bool bOld = ReadForRestore(osPam, oOld);
    // a file (or a link, even dangling) there that could not be read whole is
    // never removed below: only a file this save began is
    struct stat sLink;
    const bool bThere = bOld || VSIStatL(osPam.c_str(), &sStatBefore) == 0 ||
                        (!STARTS_WITH(pszPam, "/vsi") && lstat(pszPam, &sLink) == 0);
    m_bSavingOver = true;
    const CPLErr eErr = GDALPamDataset::TrySaveXML();
    m_bSavingOver = false;
    // failed, or moved to GDAL's proxy folder after a failed write here
    const bool bMoved = !psPam->pszPamFilename || osPam != psPam->pszPamFilename;
    if (eErr == CE_None && !bMoved)
        return eErr;
    std::vector<GByte> oNow;
    if (bOld && (!ReadForRestore(osPam, oNow) || oNow != oOld) &&
        !RestoreAfterFailedSave(osPam, oOld))
        CPLError(CE_Warning, CPLE_FileIO,
                 "TERRASHADE: %s could not be written back as it was after the failed save: "
                 "its entries may be lost",
                 osPam.c_str());
    else if (!bThere && VSIStatL(osPam.c_str(), &sStatBefore) == 0)
        VSIUnlink(osPam.c_str()); // (a file begun, cut short)
    if (eErr != CE_None)
        nPamFlags &= ~GPF_DIRTY;
    return eErr;
}

CPLErr TSDataset::TryLoadXML(char **papszSiblingFiles)
{
    const PamFileTurn oTurn(GetPhysicalFilename(), false);
    return GDALPamDataset::TryLoadXML(papszSiblingFiles);
}

/* Whether the .aux.xml at pszPath holds a <Subdataset> named pszName (in
 * a turn on DEM pszDEM's auxiliary file: a save may be under way in another
 * thread or process). */
bool HasPamEntry(const char *pszPath, const char *pszName, const char *pszDEM)
{
    VSIStatBufL sStat;
    if (!*pszPath || VSIStatL(pszPath, &sStat) != 0)
        return false;
    std::optional<PamFileTurn> oTurn;
    if (pszDEM)
        oTurn.emplace(pszDEM, false);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLXMLNode *psTree = CPLParseXMLFile(pszPath);
    CPLPopErrorHandler();
    bool bFound = false;
    for (CPLXMLNode *ps = psTree ? psTree->psChild : nullptr; ps && !bFound; ps = ps->psNext)
        bFound = ps->eType == CXT_Element && EQUAL(ps->pszValue, "Subdataset") &&
                 EQUAL(CPLGetXMLValue(ps, "name", ""), pszName);
    CPLDestroyXMLNode(psTree);
    return bFound;
}

bool TSDataset::DEMUnchanged() const
{
    const TSDataset *poLevel0 = m_poBase ? m_poBase : this;
    return SourceStamp(poLevel0->m_aosDEMFiles) == poLevel0->m_osDEMStamp;
}

void TSDataset::SetupPam(const char *pszConnection)
{
    SetDescription(pszConnection);
    char **papszFiles = m_poDEM->GetFileList();
    std::vector<char> achCanon(4 * TSD_PATH_MAX); // ENV_MAP's whole path and the rest
    // The key names the sun used (placed by DATETIME, if given), as it
    // always has, so that earlier .aux.xml entries are found again.
    tsd_options sKey = m_sOpts;
    sKey.sun_azimuth = m_sRun.sun_azimuth;
    sKey.sun_elevation = m_sRun.sun_elevation;
    sKey.step_minutes = tsd_options_step_minutes(&m_sOpts); // a range's 30 when not given
    if (papszFiles && papszFiles[0] &&
        tsd_options_canonical(&sKey, achCanon.data(), achCanon.size()) == 0)
    {
        std::string osSub = std::string(DRIVER) + ":" + achCanon.data();
        // chunks and the far grid change pixels where the options alone do
        // not say (TILE_SIZE=256 against the whole DEM, a MAX_MEMORY that
        // coarsens the far grid): they shared one entry's statistics
        const std::string osDEMPart = m_osDEM != papszFiles[0] ? ":" + m_osDEM : "";
        const std::string osUnwindowed = osSub + osDEMPart; // the key until session 51
        if (const tsd_window_plan *psPlan = WindowPlan(m_poWindow))
            osSub += CPLSPrintf(",WINDOWS=%d/%.17g/%dx%d", psPlan->tile, psPlan->near_m,
                                psPlan->far_w, psPlan->far_h);
        osSub += osDEMPart;
        // (absolute: a chdir before the save put the file in the new directory)
        SetPhysicalFilename(AbsolutePath(papszFiles[0]).c_str());
        SetSubdatasetName(osSub.c_str());
        bool bLegacy = false;
        const char *pszOwn = BuildPamFilename();
        const std::string osOwn = pszOwn ? pszOwn : "";
        TryLoadXML();
        // a windowed product's entry saved under the key without its chunks
        // (before session 51): what the user set comes over; its statistics,
        // maybe of other pixels (the whole DEM's), do not
        if (osUnwindowed != osSub && !HasPamEntry(osOwn.c_str(), osSub.c_str(), papszFiles[0]) &&
            HasPamEntry(osOwn.c_str(), osUnwindowed.c_str(), papszFiles[0]))
        {
            SetSubdatasetName(osUnwindowed.c_str());
            bLegacy = TryLoadXML() == CE_None;
            SetSubdatasetName(osSub.c_str());
            for (int i = 1; i <= nBands; i++)
                static_cast<TSRasterBand *>(GetRasterBand(i))->DropSavedStatistics();
        }
        else if (!HasPamEntry(osOwn.c_str(), osSub.c_str(), papszFiles[0])) // before session 48?
        {
            CPLFree(psPam->pszPamFilename);
            psPam->pszPamFilename = nullptr;
            m_bLegacyPam = true;
            const char *pszOld = BuildPamFilename(); // the DEM's own
            if (pszOld && HasPamEntry(pszOld, osSub.c_str(), papszFiles[0]))
            {
                CPLPushErrorHandler(CPLQuietErrorHandler);
                bLegacy = TryLoadXML() == CE_None;
                CPLPopErrorHandler();
            }
            m_bLegacyPam = false;
            CPLFree(psPam->pszPamFilename);
            psPam->pszPamFilename = nullptr; // the next save: the products' own file
        }
        // what the entry holds of the driver's own descriptions and metadata
        // (saved beside the statistics, GDAL's PAM keeps them all) is of the
        // DEM and options when it was saved: computed again over it, so that
        // a regenerated DEM's day does not keep the old site's times and sun
        // (an atlas then stored them, and its near shadows took that sun),
        // nor SOURCE_DEM another directory's name; what the user set stays
        SetupMetadata();
        // a legacy entry moves to the products' file when the dataset closes,
        // so that another product's first save there does not hide it
        nPamFlags = bLegacy ? nPamFlags | GPF_DIRTY : nPamFlags & ~GPF_DIRTY;
        m_aosDEMFiles = SourceFiles(papszFiles, nullptr);
        m_osDEMStamp = SourceStamp(m_aosDEMFiles);
        // the DEM's stamp, and ENV_MAP's beside it (the DEM's files stated once)
        m_osPamStamp = m_sOpts.env_map[0] ? m_osDEMStamp + "; ENV_MAP: " +
                                                SourceStamp(SourceFiles(nullptr, m_sOpts.env_map))
                                          : m_osDEMStamp;
        // statistics and histograms saved for other contents of the DEM or
        // ENV_MAP (regenerated under the same name: GDAL drops the DEM's
        // own .aux.xml then, not the products'), or by a version that kept
        // no stamp, were reported, and copied into gdal_translate's output
        // and QGIS's stretch, as this product's: dropped (what the user set
        // stays), and the entry saved without them at close
        DropStaleStatistics(this, m_osPamStamp);
    }
    else
    {
        SetupMetadata();
        nPamFlags |= GPF_DISABLED; // no file to put it next to
        nPamFlags &= ~GPF_DIRTY;
    }
    CSLDestroy(papszFiles);
}

} // namespace tsd
