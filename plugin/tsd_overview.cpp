/*
 * tsd_overview.cpp - the overview levels of a TERRASHADE:<dem> dataset.
 *
 * Level k (1, 2, ...) is the product computed from the DEM read at
 * ceil(W / 2^k) x ceil(H / 2^k) cells through GDAL's RasterIO with average
 * resampling (tsd_dem_load_resampled), with the geotransform scaled as
 * gdal_translate -outsize scales it and everything else (cell sizes, per-row
 * sizes of a geographic DEM, the sun, the memory check) set up as for a DEM
 * of that size: a level is the product of a coarser DEM, not an average of
 * the full-resolution product. Each level is a TSDataset of its own, made on
 * first use and computed lazily on its first block read, then cached like
 * the full level.
 */
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "tsd_dataset.h"
#include "tsd_gdal.h"
#include "tsd_entry_state.h"

namespace tsd
{

int TSDataset::OverviewCount(const tsd_product_def *psProduct, int W, int H)
{
    /* farshadow: its FAR_THRESHOLD is in cells of the full-resolution DEM
     * and its maps exist to be written as an atlas at that resolution,
     * whose near shadows are recomputed from the same DEM; a coarser map
     * would be neither. */
    if (psProduct->byte == TSD_BYTE_ALWAYS)
        return 0;
    int n = 0;
    for (int w = W, h = H; std::max(w, h) > OVERVIEW_MIN_SIDE && std::min(w, h) > 1;)
    {
        w = w / 2 + (w & 1); // (not (w + 1) / 2: a side of 2^31 - 1 overflowed)
        h = h / 2 + (h & 1);
        n++;
    }
    return n;
}

/* Cells a side of level nLevel: n / 2^nLevel rounded up, in 64 bits (a
 * side near 2^31 overflowed an int, an audit's UBSan). */
static int LevelSide(int n, int nLevel)
{
    return static_cast<int>((static_cast<int64_t>(n) + (int64_t{1} << nLevel) - 1) >> nLevel);
}

/* The dataset of level nLevel (>= 1), set up as the product of the DEM
 * resampled to that level; nullptr with the error reported. */
TSDataset *TSDataset::MakeOverview(int nLevel)
{
    const int W = LevelSide(nRasterXSize, nLevel), H = LevelSide(nRasterYSize, nLevel);
    auto poOvr = std::unique_ptr<TSDataset>(new TSDataset());
    poOvr->m_nLevel = nLevel;
    poOvr->m_poBase = this;
    poOvr->m_osDEM = m_osDEM;
    poOvr->m_osDEMPath = m_osDEMPath;
    poOvr->m_sOpts = m_sOpts;
    // measured as the DEM's own cells were (CELL_SIZES=auto decided once)
    poOvr->m_sOpts.cell_sizes = tsd_cells_mode(&m_sCells);
    poOvr->m_psProduct = m_psProduct;
    poOvr->m_bHasGT = m_bHasGT;
    poOvr->m_oSRS = m_oSRS;
    memcpy(poOvr->m_adfGT, m_adfGT, sizeof m_adfGT);
    // as gdal_translate -outsize W H scales it, so that the cells match
    poOvr->m_adfGT[1] *= static_cast<double>(nRasterXSize) / W;
    poOvr->m_adfGT[2] *= static_cast<double>(nRasterYSize) / H;
    poOvr->m_adfGT[4] *= static_cast<double>(nRasterXSize) / W;
    poOvr->m_adfGT[5] *= static_cast<double>(nRasterYSize) / H;
    CPLDebug(DRIVER, "overview level %d of %s: %d x %d", nLevel, m_osDEM.c_str(), W, H);
    if (!poOvr->Setup(CPLSPrintf("%s (overview level %d)", GetDescription(), nLevel), W, H))
        return nullptr;
    return poOvr.release();
}

/* Every level's set-up tried at once, on first use (a set-up reads no
 * heights), and the ones whose set-up fails left out, with one warning: a
 * level is computed whole, and one over MAX_MEMORY (a 65536² DEM's level
 * 1 is 32768² cells) was offered and then gave GDAL a NULL band, on which
 * gdalwarp crashed and -of COG failed. The levels offered are the others,
 * in order, each made again when it is first asked for (kept from here,
 * every level held its own environment light's tables: gdal_translate,
 * which lists the levels, grew by 10-14 MiB under SKY=overcast). Under
 * m_oOvrMutex. */
void TSDataset::MakeOverviews()
{
    if (m_bOverviewsMade)
        return;
    m_bOverviewsMade = true;
    std::string osLeftOut, osWhy;
    /* the caller's last error, which the set-ups' resets would wipe */
    const CPLErr eLastType = CPLGetLastErrorType();
    const CPLErrorNum nLastNo = CPLGetLastErrorNo();
    const std::string osLastMsg = CPLGetLastErrorMsg();
    for (int k = 1; k <= m_nOverviews; k++)
    {
        CPLErrorReset();
        CPLPushErrorHandler(CPLQuietErrorHandler);
        std::unique_ptr<TSDataset> poOvr(MakeOverview(k));
        const std::string osMsg = CPLGetLastErrorMsg();
        CPLPopErrorHandler();
        if (poOvr)
        {
            m_anOffered.push_back(k);
            continue;
        }
        osLeftOut += CPLSPrintf("%s%d (%d x %d)", osLeftOut.empty() ? "" : ", ", k,
                                LevelSide(nRasterXSize, k), LevelSide(nRasterYSize, k));
        if (osWhy.empty()) // (without its "TERRASHADE: ")
            osWhy = osMsg.compare(0, 12, "TERRASHADE: ") == 0 ? osMsg.substr(12) : osMsg;
    }
    m_apoOverviews.resize(m_anOffered.size());
    CPLErrorSetState(eLastType, nLastNo, osLastMsg.c_str());
    if (!osLeftOut.empty())
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: overview level(s) %s of the product of %s not offered, of %d: a "
                 "level is computed whole, and %s. GDAL's tools read the levels offered or the "
                 "full resolution instead; gdal_translate -of COG copies the levels offered "
                 "only (-co OVERVIEWS=IGNORE_EXISTING makes every level from the full "
                 "resolution)",
                 osLeftOut.c_str(), m_osDEM.c_str(), m_nOverviews, osWhy.c_str());
}

/* The levels offered (MakeOverviews). */
int TSDataset::OverviewsOffered()
{
    std::lock_guard<std::mutex> oLock(m_oOvrMutex);
    MakeOverviews();
    return static_cast<int>(m_anOffered.size());
}

/* Overview i: the i-th level offered, made on first use. */
TSDataset *TSDataset::Overview(int i)
{
    std::lock_guard<std::mutex> oLock(m_oOvrMutex);
    MakeOverviews();
    if (i < 0 || i >= static_cast<int>(m_anOffered.size()))
        return nullptr;
    if (!m_apoOverviews[i] && m_bDEMReleased) // (CloseDependentDatasets: no new level)
        return nullptr;
    if (!m_apoOverviews[i])
        m_apoOverviews[i].reset(MakeOverview(m_anOffered[i]));
    return m_apoOverviews[i].get();
}

/* gdaladdo on a TERRASHADE:<dem> source: its levels are its own (each the
 * product of the DEM at the level's size), and a read-only dataset has no
 * file to add others to; GDAL's own refusal named neither. */
CPLErr TSDataset::IBuildOverviews(const char *, int, const int *, int, const int *,
                                  GDALProgressFunc, void *, CSLConstList)
{
    Fail(CPLE_NotSupported,
         CPLSPrintf("%s: a product makes overview levels of its own (each the product of "
                    "the DEM read at the level's size: docs/driver.md, \"Overviews\") when "
                    "they are read, and gdaladdo can neither add nor remove them. Write the "
                    "product with gdal_translate (-of COG copies these levels) and run gdaladdo "
                    "on the file written",
                    GetDescription()));
    return CE_Failure;
}

int TSRasterBand::GetOverviewCount()
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    return static_cast<TSDataset *>(poDS)->OverviewsOffered();
}

GDALRasterBand *TSRasterBand::GetOverview(int i)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    TSDataset *poOvr = static_cast<TSDataset *>(poDS)->Overview(i);
    return poOvr ? poOvr->GetRasterBand(nBand) : nullptr;
}

} // namespace tsd
