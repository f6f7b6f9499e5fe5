/*
 * tsd_band.cpp - a band of a TERRASHADE:<dem> dataset: its blocks and
 * reads out of the computed product (tsd_dataset.cpp computes it; chunk by
 * chunk, tsd_window_cache.cpp), and its own nodata value and unit, after
 * what the user set (tsd_pam_band.h).
 */
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>

#include "cpl_conv.h"
#include "gdal_priv.h"

#include "tsd_caller_progress.h"
#include "tsd_dataset.h"
#include "tsd_gdal.h"
#include "tsd_entry_state.h"

namespace tsd
{

TSRasterBand::TSRasterBand(TSDataset *poDSIn, int nBandIn, GDALDataType eType)
    : m_nPlane(nBandIn - 1)
{
    poDS = poDSIn;
    nBand = nBandIn;
    eDataType = eType;
    nBlockXSize = std::min(BLOCK, poDSIn->GetRasterXSize());
    nBlockYSize = std::min(BLOCK, poDSIn->GetRasterYSize());
}

double TSRasterBand::OwnNoData() const
{
    if (eDataType != GDT_Byte)
        return std::numeric_limits<double>::quiet_NaN();
    return static_cast<TSDataset *>(poDS)->m_psProduct->byte_nodata;
}

const char *TSRasterBand::OwnUnit() const
{
    return static_cast<TSDataset *>(poDS)->m_psProduct->unit;
}

/* An overview level has no PAM of its own: it reports what the user set
 * on the full resolution, as a GeoTIFF's overviews share its nodata. */
const GDALRasterBandPamInfo *TSRasterBand::UserPam()
{
    const TSDataset *ds = static_cast<TSDataset *>(poDS);
    if (!ds->m_poBase)
        return GetPamInfo();
    return static_cast<TSRasterBand *>(ds->m_poBase->GetRasterBand(nBand))->GetPamInfo();
}

const char *TSRasterBand::NotHere() const
{
    if (!static_cast<TSDataset *>(poDS)->m_poBase)
        return nullptr;
    return "it is an overview level, which reports what is set on the full-resolution band: "
           "set it there";
}

CPLErr TSRasterBand::IReadBlock(int nBlockXOff, int nBlockYOff, void *pImage)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    TSDataset *ds = static_cast<TSDataset *>(poDS);
    if (ds->m_poWindow) // chunk by chunk (tsd_window_cache.cpp)
        return WindowReadBlock(nBlockXOff, nBlockYOff, pImage);
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
                                   : static_cast<GByte>(ds->m_psProduct->byte_nodata);
            }
        }
        return CE_None;
    }
    const float *plane = ds->m_pafProduct + static_cast<size_t>(m_nPlane) * W * H;
    const int n = x0 < W ? std::min(nBlockXSize, W - x0) : 0; // cells on the grid per row
    for (int by = 0; by < nBlockYSize; by++)
    {
        const int y = y0 + by;
        const int gy = ds->m_sCells.flip_y ? H - 1 - y : y;
        const float *row = y < H ? plane + static_cast<size_t>(gy) * W : nullptr;
        const size_t i0 = static_cast<size_t>(by) * nBlockXSize;
        CopyRow(row ? n : 0, row, x0, W, ds->m_sCells.flip_x != 0, bByte, pabyOut + i0,
                static_cast<float *>(pImage) + i0);
    }
    return CE_None;
}

/* A read of the band's own type at full resolution, once the whole product
 * is computed (not chunk by chunk), copied from the product straight into
 * the caller's rows: gdal_translate's copy then skips GDAL's block cache
 * (a fresh 256 x 256 block per block read, and one more pass over every
 * cell, in gdal_translate's one thread). Same cells as IReadBlock gives.
 * false: the generic path reads it. */
bool TSRasterBand::DirectRead(int nXOff, int nYOff, int nXSize, int nYSize, void *pData,
                              GSpacing nLineSpace, GDALRasterIOExtraArg *psExtraArg,
                              CPLErr *peErr)
{
    TSDataset *ds = static_cast<TSDataset *>(poDS);
    if (ds->m_poWindow || ds->m_psProduct->byte == TSD_BYTE_ALWAYS)
        return false;
    if ((*peErr = ds->EnsureComputed()) != CE_None)
        return true;
    const int W = nRasterXSize, H = nRasterYSize;
    const bool bByte = eDataType == GDT_Byte;
    const float *plane = ds->m_pafProduct + static_cast<size_t>(m_nPlane) * W * H;
    GByte *pabyOut = static_cast<GByte *>(pData);
    for (int i = 0; i < nYSize; i++)
    {
        const int y = nYOff + i;
        const int gy = ds->m_sCells.flip_y ? H - 1 - y : y;
        GByte *pabyRow = pabyOut + static_cast<GPtrDiff_t>(i) * nLineSpace;
        CopyCells(nXSize, plane + static_cast<size_t>(gy) * W, nXOff, W,
                  ds->m_sCells.flip_x != 0, bByte, pabyRow, reinterpret_cast<float *>(pabyRow));
    }
    if (psExtraArg && psExtraArg->pfnProgress &&
        !psExtraArg->pfnProgress(1.0, "", psExtraArg->pProgressData))
    {
        CPLError(CE_Failure, CPLE_UserInterrupt,
                 "TERRASHADE: the read was cancelled by the caller's progress callback");
        *peErr = CE_Failure;
    }
    return true;
}

CPLErr TSRasterBand::IRasterIO(GDALRWFlag eRWFlag, int nXOff, int nYOff, int nXSize,
                               int nYSize, void *pData, int nBufXSize, int nBufYSize,
                               GDALDataType eBufType, GSpacing nPixelSpace, GSpacing nLineSpace,
                               GDALRasterIOExtraArg *psExtraArg)
{
    tsd::EntryState oEntry; /* tsd_entry_state.h */
    std::unique_lock<std::recursive_mutex> oTurn;
    if (!TakeReadTurn(oTurn))
        return CE_Failure; // (before GDAL's block cache, which may hold the block unfilled)
    CallerProgress oCaller(psExtraArg, nXOff, nYOff, nXSize, nYSize); // a computation
                                                                     // started here reports to it
    psExtraArg = oCaller.Arg(psExtraArg);
    CPLErr eErr = CE_None;
    if (!(eRWFlag == GF_Read && nBufXSize == nXSize && nBufYSize == nYSize &&
          eBufType == eDataType && nPixelSpace == GDALGetDataTypeSizeBytes(eDataType) &&
          nLineSpace % nPixelSpace == 0 &&
          reinterpret_cast<uintptr_t>(pData) % static_cast<uintptr_t>(nPixelSpace) == 0 &&
          DirectRead(nXOff, nYOff, nXSize, nYSize, pData, nLineSpace, psExtraArg, &eErr)))
        eErr = GDALPamRasterBand::IRasterIO(eRWFlag, nXOff, nYOff, nXSize, nYSize, pData,
                                            nBufXSize, nBufYSize, eBufType, nPixelSpace,
                                            nLineSpace, psExtraArg);
    if (eErr != CE_None && oCaller.CancelledUnsaid())
        static_cast<TSDataset *>(poDS)->FailCancelled();
    return eErr;
}

bool TSRasterBand::TakeReadTurn(std::unique_lock<std::recursive_mutex> &oTurn)
{
    return static_cast<TSDataset *>(poDS)->TakeReadTurn(oTurn);
}

/* Cells x0 .. x0+n-1 of a product row (mirrored when flip_x) into a block
 * row, as bytes (tsd_to_byte) or floats; the rest of the block row is
 * nodata. */
void TSRasterBand::CopyRow(int n, const float *row, int x0, int W, bool flip_x, bool bByte,
                           GByte *pabyOut, float *pafOut) const
{
    CopyCells(n, row, x0, W, flip_x, bByte, pabyOut, pafOut);
    const float fNaN = std::numeric_limits<float>::quiet_NaN();
    for (int bx = n; bx < nBlockXSize; bx++)
    {
        if (bByte)
            pabyOut[bx] = tsd_to_byte(fNaN);
        else
            pafOut[bx] = fNaN;
    }
}

/* Cells x0 .. x0+n-1 of a product row (mirrored when flip_x) as bytes or
 * floats. */
void TSRasterBand::CopyCells(int n, const float *row, int x0, int W, bool flip_x, bool bByte,
                             GByte *pabyOut, float *pafOut)
{
    if (bByte && !flip_x)
        tsd_row_to_byte(row + x0, n, pabyOut);
    else if (bByte)
        for (int bx = 0; bx < n; bx++)
            pabyOut[bx] = tsd_to_byte(row[W - 1 - (x0 + bx)]);
    else if (!flip_x)
        memcpy(pafOut, row + x0, static_cast<size_t>(n) * sizeof(float));
    else
        for (int bx = 0; bx < n; bx++)
            pafOut[bx] = row[W - 1 - (x0 + bx)];
}

} // namespace tsd
