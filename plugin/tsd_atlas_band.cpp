/*
 * tsd_atlas_band.cpp - the reads of an atlas: blocks decoded from the file
 * (with SHADOWS=all, joined with the near shadows), and reads of one
 * dataset from several threads taking turns, as a product's do
 * (docs/driver.md, "Threads").
 */
#include <algorithm>
#include <cstring>
#include <mutex>

#include "tsd_atlas_dataset.h"
#include "tsd_entry_state.h"

namespace tsd
{

CPLErr TSAtlasBand::IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
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
        Fail(sErr.code, sErr.message);
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

CPLErr TSAtlasDataset::IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize,
                                 int nYSize, void *pData, int nBufXSize, int nBufYSize,
                                 GDALDataType eBufType, int nBandCount, int *panBandMap,
                                 GSpacing nPixelSpace, GSpacing nLineSpace, GSpacing nBandSpace,
                                 GDALRasterIOExtraArg *psExtraArg)
{
    const std::lock_guard<std::recursive_mutex> oTurn(m_oReadTurns);
    return GDALPamDataset::IRasterIO(eRWFlag, nXOff, nYOff, nXSize, nYSize, pData, nBufXSize,
                                     nBufYSize, eBufType, nBandCount, panBandMap, nPixelSpace,
                                     nLineSpace, nBandSpace, psExtraArg);
}

CPLErr TSAtlasBand::IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize, int nYSize,
                              void *pData, int nBufXSize, int nBufYSize, GDALDataType eBufType,
                              GSpacing nPixelSpace, GSpacing nLineSpace,
                              GDALRasterIOExtraArg *psExtraArg)
{
    std::unique_lock<std::recursive_mutex> oTurn;
    TakeReadTurn(oTurn);
    return GDALPamRasterBand::IRasterIO(eRWFlag, nXOff, nYOff, nXSize, nYSize, pData, nBufXSize,
                                        nBufYSize, eBufType, nPixelSpace, nLineSpace,
                                        psExtraArg);
}

} // namespace tsd
