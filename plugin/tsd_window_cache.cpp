/*
 * tsd_window_cache.cpp - windowed computation, GDAL side (tsd_window.h,
 * docs/windows.md): a block read computes the chunk of TILE_SIZE x
 * TILE_SIZE cells around it from the DEM read with its margin and the
 * dataset's one far-field grid, and keeps the most recent chunks (LRU) so
 * that GDAL's row-by-row reads compute each chunk once.
 */
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <list>
#include <memory>
#include <string>
#include <vector>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "gdal_priv.h"

#include "terrashade_cl.h"
#include "tsd_dataset.h"
#include "tsd_source_stamp.h"
#include "tsd_dem.h"
#include "tsd_gdal.h"
#include "tsd_window.h"

namespace tsd
{

/* A computed chunk: all bands, w x h cells each, grid orientation. */
struct WindowChunk
{
    int cx = 0, cy = 0, w = 0, h = 0;
    std::vector<float> data{};
};

struct WindowState
{
    tsd_window_plan plan{};
    double refCellX = 0; // the whole DEM's central row: the sweeps' direction
    bool farTried = false;
    std::string error{};  // the first failure, repeated to later reads
    ts_status status = TS_OK;
    tsd_far_field far{};
    bool farReady = false;
    std::list<WindowChunk> lru{}; // most recent first
    tsd_backend_summary ran{};    // what the chunks computed so far ran
    bool warned = false;          // BACKEND=opencl ran C: warned once
    ~WindowState()
    {
        if (farReady)
            tsd_far_field_free(&far);
    }
};

void FreeWindow(WindowState *p)
{
    delete p;
}

const tsd_window_plan *WindowPlan(const WindowState *p)
{
    return p ? &p->plan : nullptr;
}

/* How far the n x n overview cells from (ox, oy) of poOvr lie from the
 * full-resolution cells of poBand under them: the mean |difference| from
 * their average and from the cell -r nearest takes (what -r average and -r
 * nearest build), and the tolerance (2 % of the averages' range, at least
 * 0.5). false where nothing could be compared (or read: the reads that
 * follow will say). */
struct OverviewSample
{
    double dfAverage, dfNearest, dfTol;
    int nHoles;      // overview cells with a height over full-resolution nodata only
    double dfHole;   // the first such height
};

/* Whether every cell of the full-resolution block afFull (fw x fh, from
 * column fx, row fy) under overview cell (i, j) and the overview cells
 * around it is nodata; false where those reach beyond the block (the
 * sample's border cells, which its neighbours' interiors cover). */
template <class Valid>
static bool IsHole(const std::vector<float> &afFull, int fw, int fh, int i, int j, int fx, int fy,
                   double rx, double ry, const Valid &valid)
{
    const int x0 = static_cast<int>(std::floor((i - 1) * rx)) - fx;
    const int y0 = static_cast<int>(std::floor((j - 1) * ry)) - fy;
    const int x1 = static_cast<int>(std::ceil((i + 2) * rx)) - fx;
    const int y1 = static_cast<int>(std::ceil((j + 2) * ry)) - fy;
    if (x0 < 0 || y0 < 0 || x1 > fw || y1 > fh)
        return false;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            if (valid(afFull[static_cast<size_t>(y) * fw + x]))
                return false;
    return true;
}

static bool SampleOverview(GDALRasterBand *poBand, GDALRasterBand *poOvr, int ox, int oy, int n,
                           OverviewSample *psOut)
{
    const int W = poBand->GetXSize(), H = poBand->GetYSize();
    const double rx = static_cast<double>(W) / poOvr->GetXSize();
    const double ry = static_cast<double>(H) / poOvr->GetYSize();
    const int fx = static_cast<int>(ox * rx), fy = static_cast<int>(oy * ry);
    const int fw = std::min(W - fx, static_cast<int>(std::ceil(n * rx)));
    const int fh = std::min(H - fy, static_cast<int>(std::ceil(n * ry)));
    std::vector<float> afOvr(static_cast<size_t>(n) * n), afFull(static_cast<size_t>(fw) * fh);
    if (poOvr->RasterIO(GF_Read, ox, oy, n, n, afOvr.data(), n, n, GDT_Float32, 0, 0,
                        nullptr) != CE_None ||
        poBand->RasterIO(GF_Read, fx, fy, fw, fh, afFull.data(), fw, fh, GDT_Float32, 0, 0,
                         nullptr) != CE_None)
        return false;
    int bHasNoData = FALSE;
    const double dfNoData = tsd_dem_nodata(GDALRasterBand::ToHandle(poBand), &bHasNoData);
    auto valid = [&](double v) { return std::isfinite(v) && !(bHasNoData && v == dfNoData); };
    double dfAvg = 0, dfNear = 0, dfMin = INFINITY, dfMax = -INFINITY, dfHole = 0, dfSpread = 0;
    int nCompared = 0, nHoles = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
        {
            const float o = afOvr[static_cast<size_t>(j) * n + i];
            double s = 0;
            int c = 0;
            const int x0 = static_cast<int>((ox + i) * rx) - fx,
                      y0 = static_cast<int>((oy + j) * ry) - fy;
            const int x1 = std::min(fw, static_cast<int>((ox + i + 1) * rx) - fx);
            const int y1 = std::min(fh, static_cast<int>((oy + j + 1) * ry) - fy);
            for (int y = y0; y < y1; y++)
                for (int x = x0; x < x1; x++)
                {
                    const float v = afFull[static_cast<size_t>(y) * fw + x];
                    if (valid(v))
                        s += v, c++;
                }
            double dev = 0; // the cells' mean |deviation| from their average
            for (int y = y0; y < y1 && c > 0; y++)
                for (int x = x0; x < x1; x++)
                {
                    const float v = afFull[static_cast<size_t>(y) * fw + x];
                    if (valid(v))
                        dev += std::fabs(v - s / c);
                }
            // (the cell -r nearest takes: GDAL 3.6's round((i) r), the first)
            const int cx = std::min(fw - 1, static_cast<int>((ox + i) * rx + 0.5) - fx);
            const int cy = std::min(fh - 1, static_cast<int>((oy + j) * ry + 0.5) - fy);
            const float fCentre = afFull[static_cast<size_t>(cy) * fw + cx];
            // a height where every cell under it and around it is nodata: no
            // resampling makes one (an overview of a former nodata value:
            // session 59's audit, whose heights were then called cliffs). The
            // cells around: GDAL's average weighs the cells an overview cell
            // only partly covers, and bilinear, cubic and gauss reach further
            // (their overviews of a DEM with nodata edges were refused)
            if (c == 0 && valid(o) && IsHole(afFull, fw, fh, ox + i, oy + j, fx, fy, rx, ry,
                                             valid) &&
                nHoles++ == 0)
                dfHole = o;
            if (c == 0 || !valid(o))
                continue;
            dfAvg += std::fabs(o - s / c);
            dfNear += valid(fCentre) ? std::fabs(o - fCentre) : std::fabs(o - s / c);
            dfSpread += dev / c;
            dfMin = std::min(dfMin, s / c);
            dfMax = std::max(dfMax, s / c);
            nCompared++;
        }
    if (nCompared == 0 && nHoles == 0)
        return false;
    // within 6 times the cells' own spread about their average: what GDAL's
    // resamplings differ by on rough terrain (gauss 3.2 times it, the others
    // 1.6 where the overview's cells do not fall on whole cells, 2048 to
    // 683; a stale edit of session 59's audit 38 times)
    const double dfSpreadMean = nCompared ? dfSpread / nCompared : 0;
    *psOut = {nCompared ? dfAvg / nCompared : 0, nCompared ? dfNear / nCompared : 0,
              std::max({0.5, 0.02 * (dfMax - dfMin), 6 * dfSpreadMean}), nHoles, dfHole};
    return true;
}

/* The overview of `hBand` that GDAL would read for a W' = w grid (the
 * smallest not smaller), compared with the full-resolution cells under it
 * over a 16 x 16 lattice of samples across the DEM, so that a stale part
 * (a tile of a mosaic, an edit since gdaladdo) a sixteenth of the DEM wide
 * and high is seen: nine samples of 32 x 32 overview cells, 3.5 % of a
 * 2048^2 DEM, missed an edited tile of an 8 x 8 mosaic (session 59's
 * audit). A sampled check, not a proof. false with the error set. */
static bool OverviewsAgree(GDALRasterBand *poBand, int w, const std::string &osDEM)
{
    GDALRasterBand *poOvr = nullptr;
    for (int i = 0; i < poBand->GetOverviewCount(); i++)
    {
        GDALRasterBand *p = poBand->GetOverview(i);
        if (p && p->GetXSize() >= w && (!poOvr || p->GetXSize() < poOvr->GetXSize()))
            poOvr = p;
    }
    if (!poOvr)
        return true;
    const int ow = poOvr->GetXSize(), oh = poOvr->GetYSize();
    const double r = std::max(static_cast<double>(poBand->GetXSize()) / ow,
                              static_cast<double>(poBand->GetYSize()) / oh);
    // samples of at most 8 x 8 overview cells and 256 x 256 DEM cells
    const int n = std::max(1, std::min({8, ow, oh, static_cast<int>(256 / r)}));
    const int nx = std::min(16, ow / n), ny = std::min(16, oh / n);
    for (int sy = 0; sy < ny; sy++)
        for (int sx = 0; sx < nx; sx++)
        {
            const int ox = nx > 1 ? (ow - n) * sx / (nx - 1) : 0;
            const int oy = ny > 1 ? (oh - n) * sy / (ny - 1) : 0;
            OverviewSample sS;
            if (!SampleOverview(poBand, poOvr, ox, oy, n, &sS))
                continue;
            if (sS.nHoles > 0)
            {
                Fail(TS_ERR_ARG,
                     CPLSPrintf("the DEM '%s' has overviews that disagree with it: its %d x %d "
                                "overview holds heights (%.6g, and %d cells in all) over the "
                                "%d x %d overview cells from column %d, row %d where every "
                                "full-resolution cell under and around them is nodata (an overview made "
                                "before the nodata value or the cells changed?); the far "
                                "field of TILE_SIZE would come from it. Rebuild the overviews "
                                "(gdaladdo -r average) or remove them (gdaladdo -clean), or "
                                "set TILE_SIZE=0",
                                osDEM.c_str(), ow, oh, sS.dfHole, sS.nHoles, n, n, ox, oy));
                return false;
            }
            if (std::min(sS.dfAverage, sS.dfNearest) <= sS.dfTol)
                continue;
            Fail(TS_ERR_ARG,
                 CPLSPrintf("the DEM '%s' has overviews that disagree with it: its %d x %d "
                            "overview differs from the full-resolution cells under it by %.3g "
                            "on average (from their average; %.3g from the cells -r nearest takes) "
                            "over the %d x %d overview cells from column %d, row %d "
                            "(tolerance %.3g); the far field of TILE_SIZE would come from "
                            "it. Rebuild the overviews (gdaladdo -r average) or remove them "
                            "(gdaladdo -clean), or set TILE_SIZE=0",
                            osDEM.c_str(), ow, oh, sS.dfAverage, sS.dfNearest, n, n, ox, oy,
                            sS.dfTol));
            return false;
        }
    return true;
}

/* Plan the chunks of a W x H product (level 0 only); false with the
 * error reported. */
bool TSDataset::SetupWindow(int W, int H)
{
    auto poState = std::unique_ptr<WindowState>(new WindowState());
    const double dfMinX = tsd_cells_min_x(&m_sCells, H);
    poState->refCellX = m_sCells.cell_x_row ? m_sCells.cell_x_row[H / 2] : m_sCells.cell_x;
    char szMsg[512];
    // an overview level is computed whole (below): NEAR_DISTANCE, checked
    // against the DEM's cells at level 0, is none of its business (its
    // coarser cells made a valid one "too few cells" when zoomed out)
    tsd_options sOpts = m_sOpts;
    if (m_nLevel > 0)
        sOpts.near_distance = 0;
    if (tsd_window_plan_make(&sOpts, m_bHasSun ? &m_sSun : nullptr, W, H, dfMinX, m_sCells.cell_y,
                             &poState->plan, szMsg, sizeof szMsg) != 0)
        return Fail(TS_ERR_ARG, szMsg), false;
    if (m_nLevel > 0 && poState->plan.windowed)
    {
        // an overview level is the product of the DEM read at its size
        poState->plan.windowed = 0;
        poState->plan.why_whole = "an overview level";
    }
    if (!poState->plan.windowed)
    {
        CPLDebug(DRIVER, "whole-DEM path (no chunks): %s", poState->plan.why_whole);
        return true;
    }
    const tsd_window_plan &p = poState->plan;
    CPLDebug(DRIVER, "windowed: chunks of %d cells, near field %.0f m (margin %d x %d "
             "cells), far grid %d x %d, cache of %d chunks",
             p.tile, p.near_m, p.margin_x, p.margin_y, p.far_w, p.far_h, p.cache_chunks);
    if (p.far && m_poDEM &&
        !OverviewsAgree(m_poDEM->GetRasterBand(m_sOpts.band), p.far_w, m_osDEM))
        return false;
    m_poWindow = poState.release();
    return true;
}

/* The far grid, read once: the DEM averaged to the plan's size (GDAL takes
 * it from the DEM's overviews where they are fine enough). */
bool TSDataset::EnsureFarField()
{
    WindowState &s = *m_poWindow;
    if (!s.plan.far || s.farTried)
        return s.error.empty();
    s.farTried = true;
    const int W = nRasterXSize, H = nRasterYSize, fw = s.plan.far_w, fh = s.plan.far_h;
    double adfGT[6];
    memcpy(adfGT, m_adfGT, sizeof adfGT);
    // as gdal_translate -outsize fw fh scales it, so that the cells match
    for (int i : {1, 4})
        adfGT[i] *= static_cast<double>(W) / fw;
    for (int i : {2, 5})
        adfGT[i] *= static_cast<double>(H) / fh;
    // (the ground's CRS, as Setup measured the DEM's own cells with)
    OGRSpatialReferenceH hSRS =
        m_oProductSRS.IsEmpty() ? nullptr : OGRSpatialReference::ToHandle(&m_oProductSRS);
    if (!m_poDEM)
    {
        s.status = TS_ERR_INTERNAL;
        s.error = DEMReleasedError();
        return false;
    }
    char szMsg[1024] = "";
    tsd_cells sCells{};
    ts_grid sCoarse{};
    // measured as the DEM's own cells were (CELL_SIZES decided once)
    ts_status eSt = tsd_cells_compute(adfGT, fw, fh, hSRS, tsd_cells_mode(&m_sCells), &sCells,
                                      szMsg, sizeof szMsg);
    if (eSt == TS_OK)
        eSt = tsd_dem_load_resampled(GDALRasterBand::ToHandle(m_poDEM->GetRasterBand(m_sOpts.band)),
                                     &sCells, m_sOpts.z_factor, fw, fh, &sCoarse, szMsg,
                                     sizeof szMsg);
    tsd_cells_free(&sCells);
    if (eSt != TS_OK)
    {
        s.status = eSt;
        s.error = KeptFailure(eSt, std::string("the far-field grid: ") + szMsg);
        return false;
    }
    WarnBelowSea(&sCoarse);
    tsd_far_field_init(&s.far, &sCoarse, W, H, s.plan.near_m, &m_sOpts);
    s.farReady = true;
    return true;
}

/* Compute chunk (cx, cy) into c; false with s.error, or cancelled by the
 * caller's progress callback (s.error empty). */
bool TSDataset::ComputeChunk(int cx, int cy, WindowChunk &c)
{
    WindowState &s = *m_poWindow;
    const tsd_window_plan &p = s.plan;
    const int W = nRasterXSize, H = nRasterYSize;
    c.cx = cx;
    c.cy = cy;
    const int gx0 = cx * p.tile, gy0 = cy * p.tile;
    c.w = std::min(p.tile, W - gx0);
    c.h = std::min(p.tile, H - gy0);
    const int ax0 = std::max(0, gx0 - p.margin_x), ay0 = std::max(0, gy0 - p.margin_y);
    const int aw = std::min(W, gx0 + c.w + p.margin_x) - ax0;
    const int ah = std::min(H, gy0 + c.h + p.margin_y) - ay0;
    char szMsg[1024] = "";
    bool bCancelled = false; // by the caller's progress callback
    ts_grid sGrid{};
    if (!m_poDEM)
    {
        s.status = TS_ERR_INTERNAL;
        s.error = DEMReleasedError();
        return false;
    }
    ts_status eSt =
        tsd_dem_load_window(GDALRasterBand::ToHandle(m_poDEM->GetRasterBand(m_sOpts.band)),
                            &m_sCells, m_sOpts.z_factor, ax0, ay0, aw, ah, &sGrid,
                            szMsg, sizeof szMsg);
    const ts_grid_origin sOrigin{ax0, ay0, s.refCellX, W, H};
    sGrid.origin = &sOrigin;
    if (eSt == TS_OK)
    {
        WarnBelowSea(&sGrid);
        WarnVoids(&sGrid); // (in the DEM's cells: not from the coarse far grid)
    }
    const int nBands = tsd_options_band_count(&m_sOpts);
    const size_t nCells = static_cast<size_t>(aw) * ah;
    float *pafOut = nullptr;
    if (eSt == TS_OK &&
        !(pafOut = static_cast<float *>(VSI_MALLOC3_VERBOSE(nCells, nBands, sizeof(float)))))
    {
        eSt = TS_ERR_NOMEM;
        snprintf(szMsg, sizeof szMsg, "out of memory for a chunk of %d x %d cells", aw, ah);
    }
    if (eSt == TS_OK)
    {
        // Each chunk is computed inside a block read, where GDAL passes no
        // progress callback (the RasterIO's caller's, if any, is told too):
        // a line of its own on stderr, as the whole DEM's (the first chunk
        // also sweeps the far field); numbered in the grid's order, placed
        // in the raster's columns and rows
        const int nx = (W + p.tile - 1) / p.tile, ny = (H + p.tile - 1) / p.tile;
        const int rx0 = m_sCells.flip_x ? W - gx0 - c.w : gx0;
        const int ry0 = m_sCells.flip_y ? H - gy0 - c.h : gy0;
        tsd_progress sProgress;
        tsd_run sRun = m_sRun;
        const int anCells[4] = {rx0, ry0, c.w, c.h};
        StartProgress(&sProgress,
                      CPLSPrintf("computing %s of chunk %d of %d (%d x %d cells from column "
                                 "%d, row %d)",
                                 m_psProduct->name, cy * nx + cx + 1, nx * ny, c.w, c.h, rx0,
                                 ry0),
                      &sRun, anCells);
        sRun.near_distance = p.near_m;
        sRun.far = p.far ? &s.far : nullptr;
        tsd_backend_summary sRan{};
        tsd_region sRegion;
        tsd_region_whole(&sRegion, &sGrid);
        const tsd_compute_ctx sCtx{&m_sOpts, &sRun, &sRan, szMsg, sizeof szMsg};
        eSt = tsd_product_compute(&sCtx, &sRegion, pafOut, nullptr);
        tsd_progress_end(&sProgress, eSt == TS_OK);
        bCancelled = eSt == TS_ERR_CANCELLED && sProgress.cancelled;
        if (eSt == TS_OK && sRan.calls > 0)
        {
            // a chunk's sweep is bounded by its near field, not MAX_DISTANCE
            if (p.far && strcmp(sRan.reason, TS_CL_CAPPED_SWEEP_REASON) == 0)
                snprintf(sRan.reason, sizeof sRan.reason,
                         "a chunk's sweep, bounded by its near field of %.0f m (TILE_SIZE=%d, "
                         "NEAR_DISTANCE), runs on the C backend (the OpenCL kernel has no "
                         "bounded sweep yet)",
                         p.near_m, p.tile);
            // what the chunks computed so far ran (replacing the prediction
            // gdal_translate asks for first), and one warning per dataset
            tsd_backend_summary_merge(&s.ran, &sRan);
            m_sBackend = s.ran;
            m_bBackendKnown = true;
            SetupBackendMetadata();
            s.warned = ReportBackend(!s.warned) || s.warned;
        }
    }
    if (eSt == TS_OK)
    {
        // the chunk out of the chunk with its margin
        c.data.resize(static_cast<size_t>(nBands) * c.w * c.h);
        for (int b = 0; b < nBands; b++)
            for (int y = 0; y < c.h; y++)
                memcpy(&c.data[(static_cast<size_t>(b) * c.h + y) * c.w],
                       pafOut + b * nCells + static_cast<size_t>(gy0 - ay0 + y) * aw +
                           (gx0 - ax0),
                       c.w * sizeof(float));
    }
    VSIFree(pafOut);
    ts_grid_free(&sGrid);
    if (eSt != TS_OK && !bCancelled) // a cancelled chunk is computed again when read
    {
        s.status = eSt;
        s.error = KeptFailure(eSt, szMsg);
    }
    return eSt == TS_OK;
}

/* Chunk (cx, cy), from the cache or computed; nullptr with s.error, or
 * cancelled (s.error empty). */
const WindowChunk *TSDataset::Chunk(int cx, int cy)
{
    WindowState &s = *m_poWindow;
    for (auto it = s.lru.begin(); it != s.lru.end(); ++it)
        if (it->cx == cx && it->cy == cy)
        {
            s.lru.splice(s.lru.begin(), s.lru, it);
            return &s.lru.front();
        }
    if (!EnsureFarField())
        return nullptr;
    while (static_cast<int>(s.lru.size()) >= s.plan.cache_chunks)
        s.lru.pop_back();
    WindowChunk c;
    const auto tStart = std::chrono::steady_clock::now();
    if (!ComputeChunk(cx, cy, c))
        return nullptr;
    if (!DEMUnchanged()) // (its chunks and far grid would mix two DEMs)
    {
        s.status = TS_ERR_ARG;
        s.error = SourcesChangedError(m_osDEM, m_nLevel,
                                      (m_poBase ? m_poBase : this)->m_aosDEMFiles);
        return nullptr;
    }
    const std::chrono::duration<double> dfSec = std::chrono::steady_clock::now() - tStart;
    CPLDebug(DRIVER, "computed chunk (%d, %d) of %d x %d cells in %.3f s", cx, cy, c.w, c.h,
             dfSec.count());
    s.lru.push_front(std::move(c));
    return &s.lru.front();
}

/* Block (x0, y0) of nBW x nBH cells of band plane iPlane, assembled from
 * the chunks it overlaps. */
CPLErr TSDataset::WindowBlock(int nPlanes, const int *piPlane, void *const *ppImage, int x0,
                              int y0, int nBW, int nBH, bool bByte)
{
    if (ReadInsideOwnComputation())
        return CE_Failure;
    std::lock_guard<std::mutex> oLock(m_oMutex);
    const ComputingHere oHere(m_oComputer);
    WindowState &s = *m_poWindow;
    const int W = nRasterXSize, H = nRasterYSize, T = s.plan.tile;
    const float fNaN = std::numeric_limits<float>::quiet_NaN();
    bool bCancelled = false;
    for (int by = 0; by < nBH && s.error.empty() && !bCancelled; by++)
    {
        const int y = y0 + by;
        const int gy = m_sCells.flip_y ? H - 1 - y : y;
        const WindowChunk *c = nullptr;
        for (int bx = 0; bx < nBW; bx++)
        {
            const int x = x0 + bx;
            const int gx = m_sCells.flip_x ? W - 1 - x : x;
            const bool bIn = y < H && x < W;
            if (bIn && (!c || c->cx != gx / T))
                c = Chunk(gx / T, gy / T);
            if (bIn && !c)
            {
                bCancelled = s.error.empty();
                break;
            }
            const size_t i = static_cast<size_t>(by) * nBW + bx;
            for (int k = 0; k < nPlanes; k++)
            {
                const float v =
                    bIn ? c->data[(static_cast<size_t>(piPlane[k]) * c->h + (gy - c->cy * T)) *
                                      c->w +
                                  (gx - c->cx * T)]
                        : fNaN;
                if (bByte)
                    static_cast<GByte *>(ppImage[k])[i] = tsd_to_byte(v);
                else
                    static_cast<float *>(ppImage[k])[i] = v;
            }
        }
    }
    if (!s.error.empty())
    {
        Fail(s.status, s.error.c_str());
        return CE_Failure;
    }
    if (bCancelled)
    {
        CPLDebug(DRIVER, "computing a chunk: cancelled by the caller");
        FailCancelled();
        return CE_Failure;
    }
    return CE_None;
}

/* A block, and the same block of the other bands into GDAL's block cache,
 * all in one pass over the block's chunks: a chunk holds every band, and a
 * reader that takes the bands one after the other over the whole raster
 * would otherwise compute it again for each. (Band by band, a block that
 * spans more chunks than the cache keeps, TILE_SIZE=64 under 256-cell
 * blocks, computed them all again for every band: 265 chunk computations
 * for the 25 chunks of a 16-band horizon of 300 x 300 cells.) */
CPLErr TSRasterBand::WindowReadBlock(int nBlockXOff, int nBlockYOff, void *pImage)
{
    TSDataset *ds = static_cast<TSDataset *>(poDS);
    const int x0 = nBlockXOff * nBlockXSize, y0 = nBlockYOff * nBlockYSize;
    const bool bByte = eDataType == GDT_Byte;
    std::vector<int> aiPlane{m_nPlane};
    std::vector<void *> apImage{pImage};
    std::vector<GDALRasterBand *> apoOther;
    std::vector<GDALRasterBlock *> apoBlock;
    // Only into room the cache has: a block of another band pushed out
    // to make room for this one's siblings is filled again when that band
    // is read, and a product of many bands under a small cache (64 bands,
    // GDAL_CACHEMAX=16) spent 40x its time copying blocks in and out.
    const GIntBig nBlockBytes = static_cast<GIntBig>(nBlockXSize) * nBlockYSize *
                                GDALGetDataTypeSizeBytes(eDataType);
    GIntBig nRoom = GDALGetCacheMax64() - GDALGetCacheUsed64() - nBlockBytes;
    for (int i = 1; i <= ds->GetRasterCount() && nRoom >= nBlockBytes; i++)
    {
        if (i == nBand)
            continue;
        GDALRasterBand *poOther = ds->GetRasterBand(i);
        GDALRasterBlock *poBlock = poOther->TryGetLockedBlockRef(nBlockXOff, nBlockYOff);
        if (poBlock)
        {
            poBlock->DropLock();
            continue;
        }
        poBlock = poOther->GetLockedBlockRef(nBlockXOff, nBlockYOff, TRUE);
        if (!poBlock)
            continue; // no room in the block cache: read again when asked
        nRoom -= nBlockBytes;
        aiPlane.push_back(i - 1);
        apImage.push_back(poBlock->GetDataRef());
        apoOther.push_back(poOther);
        apoBlock.push_back(poBlock);
    }
    const CPLErr eErr = ds->WindowBlock(static_cast<int>(aiPlane.size()), aiPlane.data(),
                                        apImage.data(), x0, y0, nBlockXSize, nBlockYSize, bByte);
    for (size_t k = 0; k < apoBlock.size(); k++)
    {
        apoBlock[k]->DropLock();
        if (eErr != CE_None) // out of the cache, not left there unfilled as if read
            apoOther[k]->FlushBlock(nBlockXOff, nBlockYOff, FALSE);
    }
    return eErr;
}

} // namespace tsd
