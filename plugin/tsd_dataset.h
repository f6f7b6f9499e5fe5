/*
 * tsd_dataset.h - the classes of a TERRASHADE:<dem> dataset, shared by
 * tsd_dataset.cpp (opening, computing), tsd_band.cpp (blocks and reads),
 * tsd_dataset_metadata.cpp (metadata and PAM) and tsd_dataset_warnings.cpp
 * (what a DEM or a sun deserves a word about).
 */
#ifndef TSD_DATASET_H
#define TSD_DATASET_H

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gdal_pam.h"
#include "ogr_spatialref.h"

#include "tsd_backend.h"
#include "tsd_compute.h"
#include "tsd_compute_env.h"
#include "tsd_gdal.h"
#include "tsd_geodesy.h"
#include "tsd_options.h"
#include "tsd_turn_band.h"
#include "tsd_products.h"
#include "tsd_progress.h"
#include "tsd_sun.h"
#include "tsd_window.h"

namespace tsd
{

class TSRasterBand;
struct WindowState; // tsd_window_cache.cpp
struct WindowChunk;
void FreeWindow(WindowState *p);
/* The chunks' plan, or null when the whole DEM is computed at once. */
const tsd_window_plan *WindowPlan(const WindowState *p);
/* tsd_dataset_warnings.cpp: the sentence refusing band nBand of the DEM
 * when its colour interpretation says it is not heights (a colour channel,
 * a palette), else empty; the warning of a DEM without a geotransform
 * (1 m cells), which names its control points or RPCs. */
std::string NotHeights(GDALDataset *poDEM, int nBand, const std::string &osDEM);
/* tsd_dataset_warnings.cpp: the sentence refusing the DEM poDEM (named
 * osDEM) when it is a product of this driver, open through it or written to
 * a file or a VRT that keeps its metadata (PRODUCT and SOURCE_DEM), else
 * empty (the DEM of a product and of an atlas's SHADOWS=all alike). */
std::string ProductAsDEM(GDALDataset *poDEM, const std::string &osDEM);
void WarnNoGeoTransform(GDALDataset *poDEM, const std::string &osDEM);
/* tsd_dataset_warnings.cpp: what to add to "cannot open the DEM": that a
 * relative name is looked for from the working directory (named), or that
 * a file named TERRASHADE:... exists and is reached as ./TERRASHADE:...;
 * else empty. */
std::string DEMNameHint(const std::string &osDEM);
/* The warning of heights taken as metres for want of a unit on a grid in
 * another unit (US state planes in feet), with the Z_FACTOR that would
 * take them in the grid's unit. */
void WarnHeightUnit(const tsd_cells &sCells, const OGRSpatialReference &oSRS,
                    const std::string &osDEM);
/* tsd_dataset_memory.cpp: whether a W x H product of sOpts (whole, or by
 * psPlan's windows) fits MAX_MEMORY; if not, fails with a sentence saying
 * what to do (psSun, sCells and nLevel serve the advice on windows, at
 * level 0). sEnv: the environment's cost, built at open (its peak) and kept
 * while computing; psMap its ENV_MAP's header, or null; dfDEMCopy the bytes
 * of the DEM held in memory beside the product (the standard input's copy).
 * *pdfLimit: the limit (MemoryLimit's), *pdfHeadroom: the bytes left under it. */
bool CheckMemory(const tsd_options &sOpts, int W, int H, const tsd_window_plan *psPlan,
                 const tsd_sun *psSun, const tsd_cells &sCells, int nLevel,
                 const tsd_env_cost &sEnv, const ts_env_map_info *psMap, double dfDEMCopy,
                 double *pdfLimit, double *pdfHeadroom);
/* The limit CheckMemory holds to (bytes), and *ppszWhy where it comes from. */
double MemoryLimit(const tsd_options &sOpts, const char **ppszWhy);

/* What a failure that may pass adds to its sentence: a dataset keeps its
 * failures, its later reads repeating them. */
constexpr const char *KEPT_FAILURE = " (this dataset keeps the failure: open it again to retry)";

/* A failure that a dataset keeps: out of memory may pass, and the sentence
 * says that the dataset must be opened again to retry. */
inline std::string KeptFailure(ts_status eSt, const std::string &osMsg)
{
    return eSt == TS_ERR_NOMEM ? osMsg + KEPT_FAILURE : osMsg;
}

/** A TERRASHADE:<dem> dataset: one product of a DEM. */
class TSDataset final : public GDALPamDataset
{
    friend class TSRasterBand;

    GDALDataset *m_poDEM = nullptr; // open until the product is computed
    std::string m_osDEM;
    std::string m_osDEMPath; // m_osDEM made absolute at open: what an overview level reopens
    std::string m_osStdinCopy; // /vsimem/ copy of the standard input (the DEM), unlinked at close
    bool m_bShared = false;    // opened by GDALOpenShared: described by the name it was given
    tsd_options m_sOpts{};                  // what the user said
    const tsd_product_def *m_psProduct = nullptr; // its row of the product table
    tsd_run m_sRun{};                       // the sun used (progress: while computing)
    tsd_cells m_sCells{};
    double m_adfGT[6] = {0, 1, 0, 0, 0, 1};
    bool m_bHasGT = true;
    OGRSpatialReference m_oSRS{};
    /* what the product reports: m_oSRS without a compound CRS's vertical
     * part (shading is no height: gdalwarp scaled an svf of a DEM in
     * NAVD88 feet by 0.3048, session 58's CRS audit); set by Setup */
    OGRSpatialReference m_oProductSRS{};
    std::mutex m_oMutex{};
    /* one reader at a time through GDAL's block cache (IRasterIO, the
     * statistics): GDAL 3.6 files a block in the band's cache before
     * IReadBlock fills it, so that a second thread reading the same block
     * took it unfilled (zeros, garbage) while the first computed it */
    std::recursive_mutex m_oReadMutex{};
    /* the thread computing under m_oMutex (EnsureComputed, WindowBlock):
     * a read of the dataset from its own progress callback, on that thread,
     * would wait for itself (or take a block GDAL's cache holds unfilled) */
    std::atomic<std::thread::id> m_oComputer{};
    bool ReadInsideOwnComputation() const;

  public:
    /* A read's turn (IRasterIO, the statistics; of the dataset or its
     * bands): false, with the error said, from inside the dataset's own
     * computation; else true with oTurn holding the read lock */
    bool TakeReadTurn(std::unique_lock<std::recursive_mutex> &oTurn);

  private:
    /* the calling thread marked as m_oComputer while it holds m_oMutex */
    class ComputingHere
    {
        std::atomic<std::thread::id> &m_roComputer;

      public:
        explicit ComputingHere(std::atomic<std::thread::id> &roComputer)
            : m_roComputer(roComputer)
        {
            m_roComputer.store(std::this_thread::get_id());
        }
        ~ComputingHere()
        {
            m_roComputer.store(std::thread::id());
        }
        ComputingHere(const ComputingHere &) = delete;
        ComputingHere &operator=(const ComputingHere &) = delete;
    };
    bool m_bTried = false;
    bool m_bDEMReleased = false; // CloseDependentDatasets closed the DEM
    bool m_bSavingOver = false; // in TrySaveXML's call of GDAL's (tsd_dataset_metadata.cpp)
    std::string m_osError{};      // why computing failed
    ts_status m_eStatus = TS_OK;  // and its status
    float *m_pafProduct = nullptr;
    GByte *m_pabyProduct = nullptr; // products stored as bytes (TSD_BYTE_ALWAYS)
    bool m_bHasSun = false;
    tsd_sun m_sSun{};
    /* overviews (tsd_overview.cpp): level 0 is the DEM's own resolution; a
     * level k > 0 dataset is the product of the DEM read at its size (the
     * DEM reopened by name when it computes) */
    int m_nLevel = 0;
    TSDataset *m_poBase = nullptr; // level 0, which owns a level k > 0 (its PAM is level 0's)
    int m_nOverviews = 0;   // levels by size (level 0 only), before MakeOverviews
    std::mutex m_oOvrMutex{};
    bool m_bOverviewsMade = false; // MakeOverviews ran
    std::vector<int> m_anOffered{};   // the levels offered (their set-up succeeds)
    std::vector<std::unique_ptr<TSDataset>> m_apoOverviews{}; // each made on first use
    bool m_bUsesBackend = false;
    bool m_bBackendKnown = false;     // m_sBackend filled (predicted or ran)
    tsd_backend_summary m_sBackend{}; // predicted, then what ran
    tsd_environment m_sEnv{};         // ENV_MAP or SKY (tsd_dataset_env.cpp); a level's: its dataset's
    tsd_env_cost m_sEnvCost{};        // what it takes (a level sharing it: kept only)
    ts_env_map_info m_sEnvMapInfo{};  // ENV_MAP's header, when it is built here
    WindowState *m_poWindow = nullptr; // computed chunk by chunk (tsd_window_cache.cpp), or null
    std::thread m_oReadAhead{};  // the DEM read while OpenCL is probed (StartReadAhead)
    ts_grid m_sReadGrid{};       // what it read, for ReadDEM
    ts_status m_eReadStatus = TS_OK;
    std::string m_osReadMsg{};
    /* GDAL's messages on that thread, said again on the reader's (ReadDEM):
     * a host's error handler is its thread's */
    struct HeldMessage
    {
        CPLErr eClass;
        CPLErrorNum nNum;
        std::string osMsg;
    };
    std::vector<HeldMessage> m_aoReadMessages{};
    static void CPL_STDCALL HoldMessage(CPLErr eClass, CPLErrorNum nNum, const char *pszMsg);

    CPLErr EnsureComputed();
    void StartProgress(tsd_progress *psProgress, const char *pszLabel, tsd_run *psRun,
                       const int *panCells = nullptr) const;
    void FailCancelled() const;
    bool SetupWindow(int W, int H);
    bool EnsureFarField();
    bool ComputeChunk(int cx, int cy, WindowChunk &c);
    const WindowChunk *Chunk(int cx, int cy);
    // the block at (x0, y0) of nPlanes planes (piPlane[k] into ppImage[k])
    CPLErr WindowBlock(int nPlanes, const int *piPlane, void *const *ppImage, int x0, int y0,
                       int nBW, int nBH, bool bByte);
    bool Setup(const char *pszConnection, int W, int H);
    // the connection string with the DEM's absolute path where it named a
    // relative one (what gdal_translate -of VRT writes as the source), else
    // (and where opened shared) as given
    std::string AbsoluteConnection(const char *pszConnection) const;
    void WarnSunReach(int W, int H, OGRSpatialReferenceH hSRS, double dfLon, double dfLat);
    void WarnDistances(double dfMinCell, int W, int H);
    void WarnSweepTurn(int H);
    void WarnUnusedOptions();
    void WarnBelowSea(const ts_grid *g);
    void WarnVoids(const ts_grid *g);
    void WarnSkyAtNight() const;
    std::atomic<bool> m_bBelowSeaWarned{false}; // WarnBelowSea: once per dataset
    std::atomic<bool> m_bVoidsWarned{false};   // WarnVoids: once per dataset
    static GDALDataset *OpenDEM(const char *pszDEM);
    /* The standard input read whole into a /vsimem/ file, through what
     * the DEM's name chains before it (osDEM, IsStdinName's:
     * /vsigzip//vsistdin/ decompressed), which is what the DEM is read
     * from: its stream reads forward only, but
     * a DEM is read more than once (the steepness sample at open, the grid,
     * each overview level's open). Its name, or "" with the error said. */
    static std::string CopyStdin(const tsd_options &sOpts, const std::string &osDEM);
    /* the bytes of that copy (level 0's, which a level reads too), or 0 */
    double StdinCopyBytes() const;
    /* why a read after CloseDependentDatasets fails */
    std::string DEMReleasedError() const;
    ts_status LoadDEM(ts_grid *psGrid, char *pszMsg, size_t nMsg);
    void StartReadAhead();
    ts_status ReadDEM(ts_grid *psGrid, char *pszMsg, size_t nMsg);
    TSDataset *Overview(int i);
    int OverviewsOffered();
    void MakeOverviews();
    TSDataset *MakeOverview(int nLevel);
    void EnsureBackendMetadata();
    void SetupBackendMetadata();
    bool ReportBackend(bool bMayWarn = true);
    void SetupSunMetadata();
    void SetupMetadata();
    void SetupPam(const char *pszConnection); // level 0: PAM, then SetupMetadata over it
    bool m_bLegacyPam = false; // BuildPamFilename: the DEM's own .aux.xml (SetupPam)
    /* the DEM's files (level 0; none: a MEM DEM) and the stamps of their
     * contents, and of ENV_MAP's with them, when the dataset opened
     * (tsd_source_stamp.h): a product is not computed from a DEM changed
     * since, and PAM's statistics of other contents are dropped */
    std::vector<std::string> m_aosDEMFiles{};
    std::string m_osDEMStamp{}, m_osPamStamp{};
    bool DEMUnchanged() const;
    bool PlanEnvironment(std::vector<GByte> &oMap);
    bool BuildEnvironment(const std::vector<GByte> &oMap);
    void SetupEnvironmentMetadata();

  public:
    TSDataset() = default;
    ~TSDataset() override;

    static GDALDataset *Open(GDALOpenInfo *poOpenInfo);

    /** The number of overview levels of a W x H product: 2x, 4x, ... while
     * the previous level's longer side exceeds OVERVIEW_MIN_SIDE, and never
     * for PRODUCT=farshadow. */
    static int OverviewCount(const tsd_product_def *psProduct, int W, int H);

    /* gdaladdo: refused with what to do (tsd_overview.cpp) */
    CPLErr IBuildOverviews(const char *pszResampling, int nOverviews, const int *panOverviewList,
                           int nListBands, const int *panBandList, GDALProgressFunc pfnProgress,
                           void *pProgressData, CSLConstList papszOptions) override;
    /* sets the caller's progress callback for the computation a read starts */
    CPLErr IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize, int nYSize,
                     void *pData, int nBufXSize, int nBufYSize, GDALDataType eBufType,
                     int nBandCount, int *panBandMap, GSpacing nPixelSpace, GSpacing nLineSpace,
                     GSpacing nBandSpace, GDALRasterIOExtraArg *psExtraArg) override;
    CPLErr GetGeoTransform(double *padfGT) override;
    const OGRSpatialReference *GetSpatialRef() const override;
    /* refused: the DEM's georeferencing is the product's */
    CPLErr SetGeoTransform(double *) override
    {
        return RefuseGeoreferencing(this, "geotransform");
    }
    CPLErr SetSpatialRef(const OGRSpatialReference *) override
    {
        return RefuseGeoreferencing(this, "spatial reference");
    }
    /* none: a product has no file of its own, and GDAL's generic Delete
     * (gdalmanage delete -f GTiff TERRASHADE:dem.tif) unlinked what PAM
     * listed, the DEM among them */
    char **GetFileList() override
    {
        return nullptr;
    }
    /* GDALDestroyDriverManager: the DEM closed here (tsd_dataset.cpp) */
    int CloseDependentDatasets() override;
    char **GetMetadata(const char *pszDomain = "") override;
    const char *GetMetadataItem(const char *pszName, const char *pszDomain = "") override;

  protected:
    /* the products' own .aux.xml, <DEM>.terrashade.aux.xml, one save or load
     * at a time in the process (tsd_dataset_metadata.cpp, SetupPam) */
    const char *BuildPamFilename() override;
    CPLErr TrySaveXML() override;
    CPLErr TryLoadXML(char **papszSiblingFiles = nullptr) override;
};

/** A band of it: one plane of the product. Its nodata value, unit and
 * colour are the product's unless the user set them (tsd_pam_band.h). */
class TSRasterBand final : public TSTurnBand
{
    int m_nPlane;
    GDALColorInterp m_eColor = GCI_GrayIndex;
    CPLErr WindowReadBlock(int nBlockXOff, int nBlockYOff, void *pImage); // tsd_window_cache.cpp
    void CopyRow(int n, const float *row, int x0, int W, bool flip_x, bool bByte, GByte *pabyOut,
                 float *pafOut) const;
    static void CopyCells(int n, const float *row, int x0, int W, bool flip_x, bool bByte,
                          GByte *pabyOut, float *pafOut);
    bool DirectRead(int nXOff, int nYOff, int nXSize, int nYSize, void *pData,
                    GSpacing nLineSpace, GDALRasterIOExtraArg *psExtraArg, CPLErr *peErr);

  protected:
    double OwnNoData() const override;
    const char *OwnUnit() const override;
    GDALColorInterp OwnColor() const override
    {
        return m_eColor;
    }
    const GDALRasterBandPamInfo *UserPam() override;
    const char *NotHere() const override;
    /* the dataset's (TSDataset::TakeReadTurn): refused from the computation's
     * own progress callback, where GDAL's cache holds the block being
     * computed unfilled */
    bool TakeReadTurn(std::unique_lock<std::recursive_mutex> &oTurn) override;

  public:
    TSRasterBand(TSDataset *poDSIn, int nBandIn, GDALDataType eType);
    CPLErr IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage) override;
    CPLErr IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize, int nYSize,
                     void *pData, int nBufXSize, int nBufYSize, GDALDataType eBufType,
                     GSpacing nPixelSpace, GSpacing nLineSpace,
                     GDALRasterIOExtraArg *psExtraArg) override;
    void SetColor(GDALColorInterp eColor)
    {
        m_eColor = eColor;
    }
    int GetOverviewCount() override;
    GDALRasterBand *GetOverview(int i) override;
};

} // namespace tsd

#endif
