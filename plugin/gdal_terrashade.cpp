/*
 * gdal_terrashade.cpp - the TERRASHADE GDAL driver: a thin C++ layer over the
 * C option parser (tsd_options, tsd_connstr), the geodesy (tsd_geodesy), the
 * DEM reader (tsd_dem) and the product pipeline (tsd_product).
 *
 * A dataset computes its whole product once, lazily on the first block read
 * (under a mutex), keeps it in memory as float planes and copies 256 x 256
 * blocks out of it.
 */
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <string>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "gdal_pam.h"
#include "gdal_priv.h"
#include "ogr_spatialref.h"

#include "tsd_connstr.h"
#include "tsd_dem.h"
#include "tsd_geodesy.h"
#include "tsd_options.h"
#include "tsd_product.h"

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

    CPLErr EnsureComputed();
    void SetupMetadata();
    void SetupPam(const char *pszConnection);

  public:
    TSDataset() = default;
    ~TSDataset() override;

    static int Identify(GDALOpenInfo *poOpenInfo);
    static GDALDataset *Open(GDALOpenInfo *poOpenInfo);

    CPLErr GetGeoTransform(double *padfGT) override;
    const OGRSpatialReference *GetSpatialRef() const override;
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
    return eDataType == GDT_Byte ? 0.0 : std::numeric_limits<double>::quiet_NaN();
}

const char *TSRasterBand::GetUnitType()
{
    const tsd_product p = static_cast<TSDataset *>(poDS)->m_sOpts.product;
    return p == TSD_PRODUCT_HORIZON || p == TSD_PRODUCT_OPENNESS ? "degree" : "";
}

CPLErr TSRasterBand::IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage)
{
    TSDataset *ds = static_cast<TSDataset *>(poDS);
    if (ds->EnsureComputed() != CE_None)
        return CE_Failure;
    const int W = nRasterXSize, H = nRasterYSize;
    const int x0 = nBlockXOff * nBlockXSize, y0 = nBlockYOff * nBlockYSize;
    const bool bByte = eDataType == GDT_Byte;
    const float *plane = ds->m_pafProduct + static_cast<size_t>(m_nPlane) * W * H;
    GByte *pabyOut = static_cast<GByte *>(pImage);
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
    VSIFree(m_pafProduct);
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
            m_pafProduct = static_cast<float *>(
                VSI_MALLOC3_VERBOSE(nCells, nBands, sizeof(float)));
            if (!m_pafProduct)
                m_osError = "TERRASHADE: out of memory for the product";
            else if (tsd_product_compute(&sGrid, &m_sOpts, m_pafProduct, szMsg,
                                         sizeof szMsg) != 0)
                m_osError = std::string("TERRASHADE: ") + szMsg;
            ts_grid_free(&sGrid);
        }
        if (!m_osError.empty())
        {
            VSIFree(m_pafProduct);
            m_pafProduct = nullptr;
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

void TSDataset::SetupMetadata()
{
    char szValue[128];
    for (int i = 0; i < tsd_options_count(); i++)
    {
        const char *pszName = tsd_options_value(&m_sOpts, i, szValue, sizeof szValue);
        if (EQUAL(pszName, "THREADS") || EQUAL(pszName, "MAX_MEMORY"))
            continue;
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
    else
    {
        GetRasterBand(1)->GDALMajorObject::SetDescription(
            tsd_product_name(m_sOpts.product));
    }
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
    if (poDS->m_sCells.warning[0])
        CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s",
                 poDS->m_sCells.warning);
    if (!CheckMemory(sOpts, W, H))
        return nullptr;

    poDS->nRasterXSize = W;
    poDS->nRasterYSize = H;
    const GDALDataType eType = tsd_options_output_byte(&sOpts) ? GDT_Byte : GDT_Float32;
    for (int i = 1; i <= tsd_options_band_count(&sOpts); i++)
        poDS->SetBand(i, new TSRasterBand(poDS.get(), i, eType));
    poDS->SetupMetadata();
    poDS->SetupPam(poOpenInfo->pszFilename);
    return poDS.release();
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
    poDriver->SetMetadataItem(GDAL_DMD_CONNECTION_PREFIX, TSD_PREFIX);
    if (char *pszXML = tsd_options_xml())
    {
        poDriver->SetMetadataItem(GDAL_DMD_OPENOPTIONLIST, pszXML);
        free(pszXML);
    }
    poDriver->pfnIdentify = TSDataset::Identify;
    poDriver->pfnOpen = TSDataset::Open;
    GetGDALDriverManager()->RegisterDriver(poDriver);
}
