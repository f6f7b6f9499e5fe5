/*
 * gdal_terrashade.cpp - the TERRASHADE GDAL driver: a thin C++ layer over the
 * C option parser (tsd_options, tsd_connstr), the geodesy (tsd_geodesy), the
 * sun (tsd_sun), the DEM reader (tsd_dem) and the product pipeline
 * (tsd_product).
 *
 * A dataset computes its whole product once, lazily on the first block read
 * (under a mutex), keeps it in memory as float planes (bytes for
 * PRODUCT=farshadow) and copies 256 x 256 blocks out of it.
 *
 * The driver also reads and writes far-shadow atlases (*.tsa,
 * docs/atlas-format.md): CreateCopy stores any raster of binary bands
 * (0, 1, nodata), typically PRODUCT=farshadow, and Open recognises the file
 * by its magic and decodes blocks lazily (tsd_atlas_* below).
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
#include <vector>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "gdal_pam.h"
#include "gdal_priv.h"
#include "ogr_spatialref.h"

#include "shadow_atlas.h"
#include "tsd_connstr.h"
#include "tsd_dem.h"
#include "tsd_geodesy.h"
#include "tsd_options.h"
#include "tsd_product.h"
#include "tsd_progress.h"
#include "tsd_sun.h"

namespace
{

constexpr int BLOCK = 256;
constexpr const char *DRIVER = "TERRASHADE";

class TSRasterBand;

class TSDataset final : public GDALPamDataset
{
    friend class TSRasterBand;

    GDALDataset *m_poDEM = nullptr; // open until the product is computed
    std::string m_osDEM;
    tsd_options m_sOpts{};
    tsd_cells m_sCells{};
    double m_adfGT[6] = {0, 1, 0, 0, 0, 1};
    bool m_bHasGT = true;
    OGRSpatialReference m_oSRS{};
    std::mutex m_oMutex{};
    bool m_bTried = false;
    std::string m_osError{};
    float *m_pafProduct = nullptr;
    GByte *m_pabyProduct = nullptr; // PRODUCT=farshadow
    bool m_bHasSun = false;
    tsd_sun m_sSun{};
    bool m_bUsesBackend = false;
    bool m_bBackendKnown = false;     // m_sBackend filled (predicted or ran)
    tsd_backend_summary m_sBackend{}; // predicted, then what ran

    CPLErr EnsureComputed();
    void EnsureBackendMetadata();
    void SetupBackendMetadata();
    void ReportBackend();
    void SetupSunMetadata();
    void SetupMetadata();
    void SetupPam(const char *pszConnection);

  public:
    TSDataset() = default;
    ~TSDataset() override;

    static int Identify(GDALOpenInfo *poOpenInfo);
    static GDALDataset *Open(GDALOpenInfo *poOpenInfo);

    CPLErr GetGeoTransform(double *padfGT) override;
    const OGRSpatialReference *GetSpatialRef() const override;
    char **GetMetadata(const char *pszDomain = "") override;
    const char *GetMetadataItem(const char *pszName, const char *pszDomain = "") override;
};

class TSRasterBand final : public GDALPamRasterBand
{
    int m_nPlane;

  public:
    TSRasterBand(TSDataset *poDSIn, int nBandIn, GDALDataType eType);

    CPLErr IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage) override;
    double GetNoDataValue(int *pbSuccess = nullptr) override;
    GDALColorInterp GetColorInterpretation() override
    {
        return GCI_GrayIndex;
    }
    const char *GetUnitType() override;
};

/* ---------------------------------------------------------------- band */

TSRasterBand::TSRasterBand(TSDataset *poDSIn, int nBandIn, GDALDataType eType)
    : m_nPlane(nBandIn - 1)
{
    poDS = poDSIn;
    nBand = nBandIn;
    eDataType = eType;
    nBlockXSize = std::min(BLOCK, poDSIn->GetRasterXSize());
    nBlockYSize = std::min(BLOCK, poDSIn->GetRasterYSize());
}

double TSRasterBand::GetNoDataValue(int *pbSuccess)
{
    if (pbSuccess)
        *pbSuccess = TRUE;
    if (static_cast<TSDataset *>(poDS)->m_sOpts.product == TSD_PRODUCT_FARSHADOW)
        return TS_ATLAS_NODATA;
    return eDataType == GDT_Byte ? 0.0 : std::numeric_limits<double>::quiet_NaN();
}

const char *TSRasterBand::GetUnitType()
{
    switch (static_cast<TSDataset *>(poDS)->m_sOpts.product)
    {
        case TSD_PRODUCT_HORIZON:
        case TSD_PRODUCT_OPENNESS:
            return "degree";
        case TSD_PRODUCT_SUNHOURS:
            return "hour";
        case TSD_PRODUCT_INSOLATION:
            return "Wh/m2";
        default:
            return "";
    }
}

CPLErr TSRasterBand::IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage)
{
    TSDataset *ds = static_cast<TSDataset *>(poDS);
    if (ds->EnsureComputed() != CE_None)
        return CE_Failure;
    const int W = nRasterXSize, H = nRasterYSize;
    const int x0 = nBlockXOff * nBlockXSize, y0 = nBlockYOff * nBlockYSize;
    const bool bByte = eDataType == GDT_Byte;
    GByte *pabyOut = static_cast<GByte *>(pImage);
    if (ds->m_pabyProduct)
    {
        const GByte *bplane = ds->m_pabyProduct + static_cast<size_t>(m_nPlane) * W * H;
        for (int by = 0; by < nBlockYSize; by++)
        {
            const int y = y0 + by;
            const int gy = ds->m_sCells.flip_y ? H - 1 - y : y;
            for (int bx = 0; bx < nBlockXSize; bx++)
            {
                const int x = x0 + bx;
                const int gx = ds->m_sCells.flip_x ? W - 1 - x : x;
                pabyOut[static_cast<size_t>(by) * nBlockXSize + bx] =
                    y < H && x < W ? bplane[static_cast<size_t>(gy) * W + gx]
                                   : static_cast<GByte>(TS_ATLAS_NODATA);
            }
        }
        return CE_None;
    }
    const float *plane = ds->m_pafProduct + static_cast<size_t>(m_nPlane) * W * H;
    float *pafOut = static_cast<float *>(pImage);
    const float fNaN = std::numeric_limits<float>::quiet_NaN();
    for (int by = 0; by < nBlockYSize; by++)
    {
        const int y = y0 + by;
        const int gy = ds->m_sCells.flip_y ? H - 1 - y : y;
        const float *row = y < H ? plane + static_cast<size_t>(gy) * W : nullptr;
        for (int bx = 0; bx < nBlockXSize; bx++)
        {
            const int x = x0 + bx;
            const int gx = ds->m_sCells.flip_x ? W - 1 - x : x;
            const float v = row && x < W ? row[gx] : fNaN;
            const size_t i = static_cast<size_t>(by) * nBlockXSize + bx;
            if (bByte)
                pabyOut[i] = tsd_to_byte(v);
            else
                pafOut[i] = v;
        }
    }
    return CE_None;
}

/* ------------------------------------------------------------- dataset */

TSDataset::~TSDataset()
{
    TSDataset::FlushCache(true);
    if (m_poDEM)
        GDALClose(m_poDEM);
    tsd_cells_free(&m_sCells);
    tsd_sun_free(&m_sSun);
    VSIFree(m_pafProduct);
    VSIFree(m_pabyProduct);
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
    return m_oSRS.IsEmpty() ? nullptr : &m_oSRS;
}

int TSDataset::Identify(GDALOpenInfo *poOpenInfo)
{
    return tsd_connstr_matches(poOpenInfo->pszFilename);
}

/* Compute the product once; later calls return the same outcome. */
CPLErr TSDataset::EnsureComputed()
{
    std::lock_guard<std::mutex> oLock(m_oMutex);
    if (!m_bTried)
    {
        m_bTried = true;
        char szMsg[1024] = "";
        const int W = nRasterXSize, H = nRasterYSize;
        const size_t nCells = static_cast<size_t>(W) * H;
        const int nBands = tsd_options_band_count(&m_sOpts);
        CPLDebug(DRIVER, "computing PRODUCT=%s of %s (%d x %d, %d band(s))",
                 tsd_product_name(m_sOpts.product), m_osDEM.c_str(), W, H,
                 nBands);
        const auto tStart = std::chrono::steady_clock::now();
        // The whole product is computed here, inside the first block read,
        // where GDAL passes no progress callback: report on stderr.
        tsd_progress sProgress;
        const std::string osLabel = CPLSPrintf(
            "computing %s of %d x %d cells", tsd_product_name(m_sOpts.product), W, H);
        tsd_progress_begin(&sProgress, m_sOpts.progress_mode, nullptr, osLabel.c_str(),
                           CPLAtof(CPLGetConfigOption("TERRASHADE_PROGRESS_AFTER", "1")));
        tsd_options sRun = m_sOpts;
        sRun.progress = tsd_progress_report;
        sRun.progress_user = &sProgress;
        ts_grid sGrid;
        GDALRasterBandH hBand = GDALGetRasterBand(m_poDEM, m_sOpts.band);
        if (tsd_dem_load(hBand, &m_sCells, m_sOpts.z_factor, &sGrid, szMsg,
                         sizeof szMsg) != 0)
        {
            m_osError = std::string("TERRASHADE: ") + szMsg;
        }
        else
        {
            const std::chrono::duration<double> dfRead =
                std::chrono::steady_clock::now() - tStart;
            CPLDebug(DRIVER, "read the DEM in %.3f s", dfRead.count());
            if (m_sOpts.product == TSD_PRODUCT_FARSHADOW)
                m_pabyProduct = static_cast<GByte *>(VSI_MALLOC2_VERBOSE(nCells, nBands));
            else
                m_pafProduct = static_cast<float *>(
                    VSI_MALLOC3_VERBOSE(nCells, nBands, sizeof(float)));
            if (!m_pafProduct && !m_pabyProduct)
                m_osError = "TERRASHADE: out of memory for the product";
            else
            {
                tsd_backend_summary sRan{};
                if (tsd_product_compute(&sGrid, &sRun, m_bHasSun ? &m_sSun : nullptr,
                                        m_pafProduct, m_pabyProduct, &sRan, szMsg,
                                        sizeof szMsg) != 0)
                    m_osError = std::string("TERRASHADE: ") + szMsg;
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
        GDALClose(m_poDEM);
        m_poDEM = nullptr;
        const std::chrono::duration<double> dfSec =
            std::chrono::steady_clock::now() - tStart;
        CPLDebug(DRIVER, "computed PRODUCT=%s in %.3f s%s",
                 tsd_product_name(m_sOpts.product), dfSec.count(),
                 m_osError.empty() ? "" : " (failed)");
    }
    if (!m_osError.empty())
    {
        CPLError(CE_Failure, CPLE_AppDefined, "%s", m_osError.c_str());
        return CE_Failure;
    }
    return CE_None;
}

/* The BACKEND items asked for before the product is computed (gdalinfo;
 * gdal_translate copies the metadata before reading): the dispatcher's
 * choice, which probes the OpenCL device. Not done at open, so that opening
 * costs no OpenCL initialisation. */
void TSDataset::EnsureBackendMetadata()
{
    std::lock_guard<std::mutex> oLock(m_oMutex);
    if (!m_bUsesBackend || m_bBackendKnown || m_bTried)
        return;
    char szMsg[256];
    if (tsd_backend_predict(&m_sOpts, &m_sBackend, szMsg, sizeof szMsg) != 0)
        return; // TERRASHADE_BACKEND changed since open: computing will say
    m_bBackendKnown = true;
    SetupBackendMetadata();
}

char **TSDataset::GetMetadata(const char *pszDomain)
{
    if (!pszDomain || !*pszDomain)
        EnsureBackendMetadata();
    return GDALPamDataset::GetMetadata(pszDomain);
}

const char *TSDataset::GetMetadataItem(const char *pszName, const char *pszDomain)
{
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
 * (BACKEND=opencl or TERRASHADE_BACKEND=opencl) and C ran. */
void TSDataset::ReportBackend()
{
    const tsd_backend_summary &s = m_sBackend;
    char szBackend[16], szDevice[512];
    tsd_backend_summary_text(&s, szBackend, sizeof szBackend, szDevice, sizeof szDevice);
    if (s.requested == TS_BACKEND_OPENCL && s.c_calls > 0)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: BACKEND=opencl was requested, but %d of %d computation(s) "
                 "ran on the C backend instead: %s",
                 s.c_calls, s.calls, s.reason[0] ? s.reason : "(no reason given)");
    else if (s.c_calls > 0 && s.reason[0])
        CPLDebug(DRIVER, "backend %s (%s) requested, C ran: %s",
                 ts_backend_name(s.requested), szDevice, s.reason);
    CPLDebug(DRIVER, "backend: %s on %s (%d call(s): %d OpenCL, %d C)", szBackend,
             szDevice, s.calls, s.opencl_calls, s.c_calls);
}

void TSDataset::SetupMetadata()
{
    char szValue[128];
    for (int i = 0; i < tsd_options_count(); i++)
    {
        const char *pszName = tsd_options_value(&m_sOpts, i, szValue, sizeof szValue);
        if (EQUAL(pszName, "THREADS") || EQUAL(pszName, "MAX_MEMORY") ||
            EQUAL(pszName, "BACKEND") || !szValue[0])
            continue; // BACKEND: what ran (SetupBackendMetadata)
        GDALDataset::SetMetadataItem(pszName, szValue);
    }
    GDALDataset::SetMetadataItem("SOURCE_DEM", m_osDEM.c_str());
    const char *pszKind = m_sCells.kind == TSD_CRS_GEOGRAPHIC  ? "geographic"
                          : m_sCells.kind == TSD_CRS_PROJECTED ? "projected"
                                                               : "none";
    GDALDataset::SetMetadataItem("SOURCE_CRS_KIND", pszKind);
    GDALDataset::SetMetadataItem("CELL_SIZE_X", CPLSPrintf("%.6f", m_sCells.cell_x));
    GDALDataset::SetMetadataItem("CELL_SIZE_Y", CPLSPrintf("%.6f", m_sCells.cell_y));
    if (m_sCells.cell_x_row)
    {
        GDALDataset::SetMetadataItem(
            "CELL_SIZE_X_NORTH", CPLSPrintf("%.6f", m_sCells.cell_x_row[0]));
        GDALDataset::SetMetadataItem(
            "CELL_SIZE_X_SOUTH",
            CPLSPrintf("%.6f", m_sCells.cell_x_row[nRasterYSize - 1]));
    }
    if (m_sOpts.product == TSD_PRODUCT_HORIZON)
    {
        const int nBands = tsd_options_band_count(&m_sOpts);
        ts_horizon_opts sH;
        ts_horizon_opts_default(&sH);
        sH.directions = m_sOpts.directions;
        sH.start_azimuth = m_sOpts.start_azimuth;
        for (int k = 0; k < nBands; k++)
        {
            const char *pszAz = CPLSPrintf("%.10g", ts_horizon_azimuth(&sH, k));
            GDALRasterBand *poBand = GetRasterBand(k + 1);
            poBand->GDALMajorObject::SetDescription(CPLSPrintf("azimuth %s", pszAz));
            poBand->GDALMajorObject::SetMetadataItem("AZIMUTH", pszAz);
        }
    }
    else if (m_sOpts.product == TSD_PRODUCT_INSOLATION)
    {
        const char *apszNames[3] = {"global", "beam", "diffuse"};
        for (int k = 0; k < 3; k++)
            GetRasterBand(k + 1)->GDALMajorObject::SetDescription(
                CPLSPrintf("insolation %s", apszNames[k]));
    }
    else if (m_sOpts.product != TSD_PRODUCT_DAYCYCLE &&
             m_sOpts.product != TSD_PRODUCT_FARSHADOW)
    {
        GetRasterBand(1)->GDALMajorObject::SetDescription(
            tsd_product_name(m_sOpts.product));
    }
    if (m_bHasSun)
        SetupSunMetadata();
    SetupBackendMetadata();
}

/* The metadata of one time step: its instant and the sun there. */
static void SetStepMetadata(GDALMajorObject *poObj, double dfTime, int nOffset,
                            double dfAzTrue, double dfAzGrid, double dfEl,
                            double dfDuration)
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
    GDALDataset::SetMetadataItem("MERIDIAN_CONVERGENCE", CPLSPrintf("%.6f", -dfNorth));
    GDALDataset::SetMetadataItem("SUN_MODEL", "SPA (Reda & Andreas 2004), apparent "
                                              "elevation with refraction");
    char szTime[64];
    if (!tsd_product_is_daily(m_sOpts.product))
    {
        tsd_format_time(s.instant, s.offset_minutes, szTime, sizeof szTime);
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
    if (m_sOpts.product == TSD_PRODUCT_INSOLATION)
        GDALDataset::SetMetadataItem(
            "CLEAR_SKY_MODEL",
            "ESRA (Rigollier et al. 2000): beam on the tilted surface x visible "
            "fraction of the sun + diffuse horizontal x sky-view factor (sky term)");
    if (m_sOpts.product == TSD_PRODUCT_FARSHADOW)
        GDALDataset::SetMetadataItem("FAR_THRESHOLD_M", CPLSPrintf("%.6f", s.threshold_m));
    for (int k = 0; k < s.steps; k++)
        SetStepMetadata(GetRasterBand(k + 1), s.times[k], s.offset_minutes,
                        s.samples[k].azimuth, s.samples[k].grid_azimuth,
                        s.samples[k].elevation, s.durations[k]);
}

/* Auxiliary metadata (statistics...) goes next to the DEM's file, in a
 * subdataset entry per set of options, never into the current directory. */
void TSDataset::SetupPam(const char *pszConnection)
{
    SetDescription(pszConnection);
    char **papszFiles = m_poDEM->GetFileList();
    char szCanon[1024];
    if (papszFiles && papszFiles[0] &&
        tsd_options_canonical(&m_sOpts, szCanon, sizeof szCanon) == 0)
    {
        std::string osSub = std::string(DRIVER) + ":" + szCanon;
        if (m_osDEM != papszFiles[0])
            osSub += ":" + m_osDEM;
        SetPhysicalFilename(papszFiles[0]);
        SetSubdatasetName(osSub.c_str());
        TryLoadXML();
    }
    else
    {
        nPamFlags |= GPF_DISABLED; // no file to put it next to
    }
    CSLDestroy(papszFiles);
    nPamFlags &= ~GPF_DIRTY;
}

static GDALDataset *OpenFailed(CPLErrorNum nErr, const char *pszMsg)
{
    CPLError(CE_Failure, nErr, "TERRASHADE: %s", pszMsg);
    return nullptr;
}

/* Refuse products that cannot fit, with a sentence saying what to do. */
static bool CheckMemory(const tsd_options &sOpts, int W, int H)
{
    double dfSteady = 0;
    const double dfPeak = tsd_product_peak_bytes(&sOpts, W, H, &dfSteady);
    double dfLimit = 0;
    const char *pszWhy = "MAX_MEMORY";
    if (sOpts.max_memory_mb > 0)
        dfLimit = sOpts.max_memory_mb * 1048576.0;
    else
    {
        dfLimit = 0.75 * static_cast<double>(CPLGetUsablePhysicalRAM());
        pszWhy = "three quarters of the physical memory; set MAX_MEMORY to change";
        if (dfLimit <= 0)
            dfLimit = static_cast<double>(std::numeric_limits<size_t>::max()) / 2;
    }
    if (dfPeak <= dfLimit && dfPeak < static_cast<double>(std::numeric_limits<size_t>::max()) / 2)
        return true;
    CPLError(CE_Failure, CPLE_OutOfMemory,
             "TERRASHADE: PRODUCT=%s with %d band(s) on this %d x %d DEM needs "
             "about %.0f MiB while computing (%.0f MiB kept), more than the "
             "limit of %.0f MiB (%s); crop or downsample the DEM, use fewer "
             "DIRECTIONS, or raise MAX_MEMORY",
             tsd_product_name(sOpts.product), tsd_options_band_count(&sOpts), W,
             H, dfPeak / 1048576.0, dfSteady / 1048576.0, dfLimit / 1048576.0,
             pszWhy);
    return false;
}

GDALDataset *TSDataset::Open(GDALOpenInfo *poOpenInfo)
{
    if (!Identify(poOpenInfo))
        return nullptr;
    if (poOpenInfo->eAccess == GA_Update)
        return OpenFailed(CPLE_NotSupported,
                          "TERRASHADE datasets are read-only; write the product "
                          "with gdal_translate instead");
    char szMsg[1024] = "";
    tsd_connstr sConn;
    if (tsd_connstr_parse(poOpenInfo->pszFilename, &sConn, szMsg, sizeof szMsg) != 0)
    {
        tsd_connstr_free(&sConn);
        return OpenFailed(CPLE_IllegalArg, szMsg);
    }
    CPLStringList aosOptions;
    for (char **p = sConn.options; p && *p; p++)
        aosOptions.AddString(*p);
    for (char **p = poOpenInfo->papszOpenOptions; p && *p; p++)
        aosOptions.AddString(*p);
    const std::string osDEM = sConn.dem;
    tsd_connstr_free(&sConn);

    tsd_options sOpts;
    tsd_options_defaults(&sOpts);
    if (tsd_options_apply(&sOpts, aosOptions.List(), szMsg, sizeof szMsg) != 0)
        return OpenFailed(CPLE_IllegalArg, szMsg);

    GDALDataset *poDEM = GDALDataset::Open(
        osDEM.c_str(), GDAL_OF_RASTER | GDAL_OF_VERBOSE_ERROR, nullptr, nullptr,
        nullptr);
    if (!poDEM)
        return OpenFailed(CPLE_OpenFailed,
                          CPLSPrintf("cannot open the DEM '%s' as a raster",
                                     osDEM.c_str()));
    auto poDS = std::unique_ptr<TSDataset>(new TSDataset());
    poDS->m_poDEM = poDEM;
    poDS->m_osDEM = osDEM;
    poDS->m_sOpts = sOpts;
    if (sOpts.band > poDEM->GetRasterCount())
        return OpenFailed(CPLE_IllegalArg,
                          CPLSPrintf("BAND=%d, but the DEM '%s' has %d band(s)",
                                     sOpts.band, osDEM.c_str(),
                                     poDEM->GetRasterCount()));
    const int W = poDEM->GetRasterXSize(), H = poDEM->GetRasterYSize();
    if (poDEM->GetGeoTransform(poDS->m_adfGT) != CE_None)
    {
        // no georeferencing: row 0 is the top (north), cells 1 x 1 metre
        poDS->m_bHasGT = false;
        const double adfTopDown[6] = {0, 1, 0, 0, 0, -1};
        memcpy(poDS->m_adfGT, adfTopDown, sizeof adfTopDown);
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: the DEM '%s' has no geotransform: its cells are "
                 "taken as 1 x 1 metre, row 0 north", osDEM.c_str());
    }
    if (const OGRSpatialReference *poSRS = poDEM->GetSpatialRef())
        poDS->m_oSRS = *poSRS;
    OGRSpatialReferenceH hSRS =
        poDS->m_oSRS.IsEmpty() ? nullptr : OGRSpatialReference::ToHandle(&poDS->m_oSRS);
    if (tsd_cells_compute(poDS->m_adfGT, W, H, hSRS, &poDS->m_sCells, szMsg,
                          sizeof szMsg) != 0)
        return OpenFailed(CPLE_AppDefined, szMsg);
    if (tsd_options_sun_from_time(&sOpts))
    {
        const char *pszWhat = sOpts.datetime[0] ? "DATETIME" : "DATE";
        if (!poDS->m_bHasGT || !hSRS)
            return OpenFailed(
                CPLE_AppDefined,
                CPLSPrintf("%s needs a georeferenced DEM, but '%s' has no %s: the sun's "
                           "position over it is unknown. Give it one (gdal_edit.py "
                           "-a_srs / -a_ullr) or use SUN_AZIMUTH and SUN_ELEVATION",
                           pszWhat, osDEM.c_str(),
                           !poDS->m_bHasGT ? "geotransform" : "CRS"));
        tsd_sites sSites;
        if (tsd_sites_compute(poDS->m_adfGT, W, H, hSRS, &poDS->m_sCells,
                              sOpts.sun_position == TSD_SUN_PER_CELL, &sSites, szMsg,
                              sizeof szMsg) != 0)
            return OpenFailed(CPLE_AppDefined, CPLSPrintf("%s: %s", pszWhat, szMsg));
        double dfMinCell = poDS->m_sCells.cell_y;
        for (int y = 0; y < H; y++)
            dfMinCell = std::min(dfMinCell, poDS->m_sCells.cell_x_row
                                                ? poDS->m_sCells.cell_x_row[y]
                                                : poDS->m_sCells.cell_x);
        if (tsd_sun_setup(&poDS->m_sOpts, &sSites, dfMinCell, &poDS->m_sSun, szMsg,
                          sizeof szMsg) != 0)
            return OpenFailed(CPLE_AppDefined, szMsg);
        poDS->m_bHasSun = true;
    }
    if (poDS->m_sCells.warning[0])
        CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s",
                 poDS->m_sCells.warning);
    if (!CheckMemory(sOpts, W, H))
        return nullptr;
    /* a bad TERRASHADE_BACKEND is an error here (without probing OpenCL) */
    poDS->m_bUsesBackend =
        tsd_product_uses_backend(&sOpts, poDS->m_bHasSun ? &poDS->m_sSun : nullptr) != 0;
    if (poDS->m_bUsesBackend &&
        tsd_backend_check_env(&sOpts, szMsg, sizeof szMsg) != 0)
        return OpenFailed(CPLE_IllegalArg, szMsg);

    poDS->nRasterXSize = W;
    poDS->nRasterYSize = H;
    const GDALDataType eType = tsd_options_output_byte(&sOpts) ? GDT_Byte : GDT_Float32;
    sOpts = poDS->m_sOpts; // with the sun placed
    for (int i = 1; i <= tsd_options_band_count(&sOpts); i++)
        poDS->SetBand(i, new TSRasterBand(poDS.get(), i, eType));
    poDS->SetupMetadata();
    poDS->SetupPam(poOpenInfo->pszFilename);
    return poDS.release();
}

/* ============================================================== atlases */

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
    CPLStringList m_aosMeta{};
    std::mutex m_oMutex{};
    bool m_bTried = false;
    std::string m_osError{};
    GByte *m_pabyNear = nullptr; // near-shadow bits, raster order, one plane per map

    CPLErr EnsureNear();

  public:
    TSAtlasDataset() = default;
    ~TSAtlasDataset() override;

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
};

class TSAtlasBand final : public GDALPamRasterBand
{
    int m_nStep;

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
    double GetNoDataValue(int *pbSuccess = nullptr) override
    {
        // as PRODUCT=farshadow, whether or not the maps have nodata cells
        if (pbSuccess)
            *pbSuccess = TRUE;
        return TS_ATLAS_NODATA;
    }
    GDALColorInterp GetColorInterpretation() override
    {
        return GCI_GrayIndex;
    }
};

TSAtlasDataset::~TSAtlasDataset()
{
    TSAtlasDataset::FlushCache(true);
    ts_atlas_free(m_psAtlas);
    VSIFree(m_pabyNear);
}

CPLErr TSAtlasBand::IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage)
{
    TSAtlasDataset *ds = static_cast<TSAtlasDataset *>(poDS);
    if (ds->m_bAll && ds->EnsureNear() != CE_None)
        return CE_Failure;
    const int W = nRasterXSize, H = nRasterYSize;
    const int x0 = nBlockXOff * nBlockXSize, y0 = nBlockYOff * nBlockYSize;
    const int w = std::min(nBlockXSize, W - x0), h = std::min(nBlockYSize, H - y0);
    GByte *pabyOut = static_cast<GByte *>(pImage);
    memset(pabyOut, TS_ATLAS_NODATA, static_cast<size_t>(nBlockXSize) * nBlockYSize);
    ts_error sErr;
    if (ts_atlas_read(ds->m_psAtlas, m_nStep, x0, y0, w, h, pabyOut, nBlockXSize, &sErr) !=
        TS_OK)
    {
        CPLError(CE_Failure, CPLE_AppDefined, "TERRASHADE: %s", sErr.message);
        return CE_Failure;
    }
    if (ds->m_bAll)
    {
        const GByte *near = ds->m_pabyNear + static_cast<size_t>(m_nStep) * W * H;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
            {
                GByte &v = pabyOut[static_cast<size_t>(y) * nBlockXSize + x];
                if (v != TS_ATLAS_NODATA)
                    v |= near[static_cast<size_t>(y0 + y) * W + x0 + x];
            }
    }
    return CE_None;
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
        GDALDataset *poDEM = nullptr;
        tsd_cells sCells{};
        ts_grid sGrid{};
        bool bGrid = false;
        float *pafPlane = nullptr;
        const char *pszZ = m_aosMeta.FetchNameValueDef("Z_FACTOR", "1");
        const int nBandDEM = atoi(m_aosMeta.FetchNameValueDef("BAND", "1"));
        ts_horizon_opts sH;
        ts_horizon_opts_default(&sH);
        sH.curvature = CPLTestBool(m_aosMeta.FetchNameValueDef("CURVATURE", "YES"));
        sH.refraction = CPLAtof(m_aosMeta.FetchNameValueDef("REFRACTION", "0.13"));
        sH.threads = m_nThreads;
        sH.directions = 1;
        sH.max_distance = psInfo->threshold_m;
        double adfGT[6];
        if (!(std::isfinite(psInfo->threshold_m) && psInfo->threshold_m > 0))
            m_osError = "TERRASHADE: SHADOWS=all needs the atlas's far threshold in "
                        "metres, which this atlas does not record";
        else if (!(poDEM = GDALDataset::Open(m_osDEM.c_str(),
                                             GDAL_OF_RASTER | GDAL_OF_VERBOSE_ERROR)))
            m_osError = CPLSPrintf("TERRASHADE: SHADOWS=all cannot open the DEM '%s' "
                                   "(give it with the open option DEM=...)",
                                   m_osDEM.c_str());
        else if (poDEM->GetRasterXSize() != W || poDEM->GetRasterYSize() != H ||
                 nBandDEM < 1 || nBandDEM > poDEM->GetRasterCount())
            m_osError = CPLSPrintf("TERRASHADE: SHADOWS=all: the DEM '%s' (%d x %d) does "
                                   "not match the %d x %d atlas", m_osDEM.c_str(),
                                   poDEM->GetRasterXSize(), poDEM->GetRasterYSize(), W, H);
        else if (poDEM->GetGeoTransform(adfGT) != CE_None)
            m_osError = "TERRASHADE: SHADOWS=all: the DEM has no geotransform";
        else
        {
            const OGRSpatialReference *poSRS = poDEM->GetSpatialRef();
            OGRSpatialReferenceH hSRS =
                poSRS ? OGRSpatialReference::ToHandle(const_cast<OGRSpatialReference *>(poSRS))
                      : nullptr;
            if (tsd_cells_compute(adfGT, W, H, hSRS, &sCells, szMsg, sizeof szMsg) != 0 ||
                tsd_dem_load(GDALRasterBand::ToHandle(poDEM->GetRasterBand(nBandDEM)),
                             &sCells, CPLAtof(pszZ), &sGrid, szMsg, sizeof szMsg) != 0)
                m_osError = std::string("TERRASHADE: SHADOWS=all: ") + szMsg;
            else
                bGrid = true;
        }
        const size_t nCells = static_cast<size_t>(W) * H;
        if (bGrid)
        {
            m_pabyNear = static_cast<GByte *>(VSI_MALLOC2_VERBOSE(nCells, psInfo->steps));
            pafPlane = static_cast<float *>(VSI_MALLOC2_VERBOSE(nCells, sizeof(float)));
            if (!m_pabyNear || !pafPlane)
                m_osError = "TERRASHADE: out of memory for the near shadows";
        }
        for (int k = 0; bGrid && m_osError.empty() && k < psInfo->steps; k++)
        {
            const ts_atlas_step *psStep = ts_atlas_get_step(m_psAtlas, k);
            ts_error sErr;
            GByte *pabyOut = m_pabyNear + static_cast<size_t>(k) * nCells;
            if (!std::isfinite(psStep->grid_azimuth) || !std::isfinite(psStep->elevation))
            {
                m_osError = CPLSPrintf("TERRASHADE: SHADOWS=all: map %d of the atlas "
                                       "records no sun position", k + 1);
                break;
            }
            if (ts_horizon_sweep(&sGrid, psStep->grid_azimuth, &sH, pafPlane, &sErr) != TS_OK)
            {
                m_osError = std::string("TERRASHADE: ") + sErr.message;
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
        if (poDEM)
            GDALClose(poDEM);
        if (!m_osError.empty())
        {
            VSIFree(m_pabyNear);
            m_pabyNear = nullptr;
        }
    }
    if (!m_osError.empty())
    {
        CPLError(CE_Failure, CPLE_AppDefined, "%s", m_osError.c_str());
        return CE_Failure;
    }
    return CE_None;
}

GDALDataset *TSAtlasDataset::Open(GDALOpenInfo *poOpenInfo)
{
    if (poOpenInfo->eAccess == GA_Update)
        return OpenFailed(CPLE_NotSupported,
                          "far-shadow atlases are read-only; write a new one with "
                          "gdal_translate -of TERRASHADE");
    bool bAll = false;
    std::string osDEM;
    int nThreads = 0;
    for (char **p = poOpenInfo->papszOpenOptions; p && *p; p++)
    {
        char *pszKey = nullptr;
        const char *pszValue = CPLParseNameValue(*p, &pszKey);
        const std::string osKey = pszKey ? pszKey : "";
        CPLFree(pszKey);
        if (!pszValue)
            return OpenFailed(CPLE_IllegalArg,
                              CPLSPrintf("open option '%s' is not of the form KEY=VALUE", *p));
        if (EQUAL(osKey.c_str(), "SHADOWS"))
        {
            if (!EQUAL(pszValue, "far") && !EQUAL(pszValue, "all"))
                return OpenFailed(CPLE_IllegalArg,
                                  CPLSPrintf("SHADOWS must be one of far, all, got '%s'",
                                             pszValue));
            bAll = EQUAL(pszValue, "all");
        }
        else if (EQUAL(osKey.c_str(), "DEM"))
            osDEM = pszValue;
        else if (EQUAL(osKey.c_str(), "THREADS"))
            nThreads = std::max(0, atoi(pszValue));
        else
            return OpenFailed(CPLE_IllegalArg,
                              CPLSPrintf("an atlas takes the open options SHADOWS, DEM and "
                                         "THREADS, not '%s'", osKey.c_str()));
    }
    VSILFILE *fp = VSIFOpenL(poOpenInfo->pszFilename, "rb");
    if (!fp)
        return OpenFailed(CPLE_OpenFailed, CPLSPrintf("cannot open the atlas '%s'",
                                                      poOpenInfo->pszFilename));
    VSIFSeekL(fp, 0, SEEK_END);
    const vsi_l_offset nSize = VSIFTellL(fp);
    VSIFSeekL(fp, 0, SEEK_SET);
    GByte *pabyFile = nSize < (static_cast<vsi_l_offset>(1) << 40)
                          ? static_cast<GByte *>(VSI_MALLOC_VERBOSE(static_cast<size_t>(nSize)))
                          : nullptr;
    const bool bRead = pabyFile && VSIFReadL(pabyFile, 1, static_cast<size_t>(nSize), fp) ==
                                       static_cast<size_t>(nSize);
    VSIFCloseL(fp);
    ts_atlas *psAtlas = nullptr;
    ts_error sErr;
    if (!bRead)
    {
        VSIFree(pabyFile);
        return OpenFailed(CPLE_FileIO, CPLSPrintf("cannot read the atlas '%s'",
                                                  poOpenInfo->pszFilename));
    }
    const ts_status eSt = ts_atlas_open(pabyFile, static_cast<size_t>(nSize), &psAtlas, &sErr);
    VSIFree(pabyFile);
    if (eSt != TS_OK)
        return OpenFailed(CPLE_AppDefined, CPLSPrintf("'%s': %s", poOpenInfo->pszFilename,
                                                      sErr.message));
    auto poDS = std::unique_ptr<TSAtlasDataset>(new TSAtlasDataset());
    poDS->m_psAtlas = psAtlas;
    const ts_atlas_info *psInfo = ts_atlas_get_info(psAtlas);
    poDS->nRasterXSize = psInfo->width;
    poDS->nRasterYSize = psInfo->height;
    poDS->m_bHasGT = psInfo->has_geotransform;
    memcpy(poDS->m_adfGT, psInfo->geotransform, sizeof poDS->m_adfGT);
    poDS->m_aosMeta = AtlasMetadata(psInfo->metadata);
    poDS->m_bAll = bAll;
    poDS->m_nThreads = nThreads;
    poDS->m_osDEM = !osDEM.empty() ? osDEM
                                   : poDS->m_aosMeta.FetchNameValueDef("SOURCE_DEM", "");
    if (bAll && poDS->m_osDEM.empty())
        return OpenFailed(CPLE_IllegalArg,
                          "SHADOWS=all recomputes the near shadows from the DEM, but the "
                          "atlas names none: give it with the open option DEM=...");
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
                poDS->m_oSRS.importFromWkt(pszValue);
            }
            else
                poDS->GDALDataset::SetMetadataItem(pszKey, pszValue);
        }
        CPLFree(pszKey);
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
    poDS->TryLoadXML();
    poDS->nPamFlags &= ~GPF_DIRTY;
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
        return OpenFailed(CPLE_NotSupported, "an atlas needs at least one band");
    if (!pfnProgress)
        pfnProgress = GDALDummyProgress;
    ts_error sErr;
    ts_atlas_writer *psW = nullptr;
    if (ts_atlas_writer_new(W, H, &psW, &sErr) != TS_OK)
        return OpenFailed(CPLE_AppDefined, sErr.message);
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
        return OpenFailed(CPLE_OutOfMemory, "out of memory for one map of the atlas");
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
                    return OpenFailed(
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
            return OpenFailed(CPLE_AppDefined, CPLSPrintf("band %d: %s", b, sErr.message));
        if (!pfnProgress(0.95 * b / nBands, nullptr, pProgressData))
        {
            CPLError(CE_Failure, CPLE_UserInterrupt, "TERRASHADE: interrupted");
            return nullptr;
        }
    }
    /* metadata text: the source's metadata, its CRS, its threshold */
    std::string osText;
    for (char **p = poSrcDS->GetMetadata(); p && *p; p++)
    {
        std::string osLine = *p;
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
        return OpenFailed(CPLE_AppDefined, sErr.message);
    VSILFILE *fp = VSIFOpenL(pszFilename, "wb");
    bool bOK = fp && VSIFWriteL(pabyFile, 1, nSize, fp) == nSize;
    if (fp && VSIFCloseL(fp) != 0)
        bOK = false;
    free(pabyFile);
    if (!bOK)
    {
        VSIUnlink(pszFilename);
        return OpenFailed(CPLE_FileIO, CPLSPrintf("cannot write the atlas '%s'", pszFilename));
    }
    CPLDebug(DRIVER, "wrote the atlas %s: %d maps of %d x %d, %zu bytes (%.4f bits per cell)",
             pszFilename, nBands, W, H, nSize, nSize * 8.0 / nCells);
    pfnProgress(1.0, nullptr, pProgressData);
    GDALOpenInfo oOpenInfo(pszFilename, GA_ReadOnly);
    return TSAtlasDataset::Open(&oOpenInfo);
}

/* TERRASHADE:... connection strings, and atlas files by their magic. */
static int IdentifyAny(GDALOpenInfo *poOpenInfo)
{
    if (tsd_connstr_matches(poOpenInfo->pszFilename))
        return TRUE;
    return poOpenInfo->nHeaderBytes >= 8 &&
           ts_atlas_identify(poOpenInfo->pabyHeader,
                             static_cast<size_t>(poOpenInfo->nHeaderBytes));
}

static GDALDataset *OpenAny(GDALOpenInfo *poOpenInfo)
{
    if (tsd_connstr_matches(poOpenInfo->pszFilename))
        return TSDataset::Open(poOpenInfo);
    if (!IdentifyAny(poOpenInfo))
        return nullptr;
    return TSAtlasDataset::Open(poOpenInfo);
}

} // namespace

extern "C" void __attribute__((visibility("default"))) GDALRegister_TERRASHADE();

void GDALRegister_TERRASHADE()
{
    if (!GDAL_CHECK_VERSION("TERRASHADE driver"))
        return;
    if (GDALGetDriverByName(DRIVER) != nullptr)
        return;
    GDALDriver *poDriver = new GDALDriver();
    poDriver->SetDescription(DRIVER);
    poDriver->SetMetadataItem(GDAL_DCAP_RASTER, "YES");
    poDriver->SetMetadataItem(GDAL_DMD_LONGNAME,
                              "terrashade: shaded relief with cast shadows, "
                              "horizons, sky-view factor");
    poDriver->SetMetadataItem(GDAL_DMD_HELPTOPIC,
                              "https://example.invalid/terrashade/docs/driver.md");
    poDriver->SetMetadataItem(GDAL_DCAP_VIRTUALIO, "YES");
    poDriver->SetMetadataItem(GDAL_DCAP_CREATECOPY, "YES");
    poDriver->SetMetadataItem(GDAL_DMD_EXTENSION, "tsa");
    poDriver->SetMetadataItem(GDAL_DMD_CREATIONDATATYPES, "Byte");
    poDriver->SetMetadataItem(GDAL_DMD_CONNECTION_PREFIX, TSD_PREFIX);
    if (char *pszXML = tsd_options_xml())
    {
        poDriver->SetMetadataItem(GDAL_DMD_OPENOPTIONLIST, pszXML);
        free(pszXML);
    }
    poDriver->pfnIdentify = IdentifyAny;
    poDriver->pfnOpen = OpenAny;
    poDriver->pfnCreateCopy = TSAtlasDataset::CreateCopy;
    GetGDALDriverManager()->RegisterDriver(poDriver);
}
