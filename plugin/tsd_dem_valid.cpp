/* The band a DEM is read through, with every validity it declares in one
 * mask; see tsd_dem_valid.h. */
#include "tsd_dem_valid.h"

#include "tsd_dem.h"

#include <algorithm>
#include <cstring>
#include <new>
#include <vector>

#include "gdal_priv.h"

namespace
{

/* The one band of the DEM's dataset (not the DEM band) whose colour is
 * alpha, or nullptr. */
GDALRasterBand *AlphaOf(GDALRasterBand *poBand)
{
    GDALDataset *poDS = poBand->GetDataset();
    if (!poDS)
        return nullptr;
    for (int i = 1; i <= poDS->GetRasterCount(); i++)
    {
        GDALRasterBand *p = poDS->GetRasterBand(i);
        if (p != poBand && p->GetColorInterpretation() == GCI_AlphaBand)
            return p;
    }
    return nullptr;
}

/* What the DEM says of its validity beyond GDAL's mask. */
struct Extra
{
    bool bNoData = false;           // the nodata value, where GDAL's mask is another
    GDALRasterBand *poAlpha = nullptr; // an alpha band GDAL's mask leaves out
};

Extra ExtraOf(GDALRasterBand *poBand)
{
    Extra s;
    const int nFlags = poBand->GetMaskFlags();
    int bHas = FALSE;
    const double dfNoData = tsd_dem_nodata(GDALRasterBand::ToHandle(poBand), &bHas);
    s.bNoData = bHas && !(nFlags & GMF_NODATA) &&
                GDALNoDataMaskBand::IsNoDataInRange(dfNoData, poBand->GetRasterDataType());
    if (!(nFlags & GMF_ALPHA))
        s.poAlpha = AlphaOf(poBand);
    return s;
}

/* A band of the DEM band's size and blocks, in memory only. */
class ProxyBand : public GDALRasterBand
{
  protected:
    ProxyBand(GDALRasterBand *poSrc, GDALDataType eType)
    {
        nRasterXSize = poSrc->GetXSize();
        nRasterYSize = poSrc->GetYSize();
        eDataType = eType;
        poSrc->GetBlockSize(&nBlockXSize, &nBlockYSize);
    }

    /* Block (nBX, nBY)'s window, cut at the band's edges. */
    void BlockWindow(int nBX, int nBY, int *x, int *y, int *w, int *h) const
    {
        *x = nBX * nBlockXSize;
        *y = nBY * nBlockYSize;
        *w = std::min(nBlockXSize, nRasterXSize - *x);
        *h = std::min(nBlockYSize, nRasterYSize - *y);
    }
};

/* The combined mask: 255 valid, 0 not. */
class ValidMaskBand final : public ProxyBand
{
    GDALRasterBand *m_poSrc;
    GDALRasterBand *m_poNoData; // GDALNoDataMaskBand of m_poSrc, or nullptr
    GDALRasterBand *m_poAlpha;

    /* The mask of a window at full resolution, w bytes a row. */
    CPLErr ReadValid(int x, int y, int w, int h, GByte *pabyOut)
    {
        const size_t n = static_cast<size_t>(w) * h;
        if (m_poSrc->GetMaskFlags() == GMF_ALL_VALID)
            std::fill(pabyOut, pabyOut + n, 255);
        else if (m_poSrc->GetMaskBand()->RasterIO(GF_Read, x, y, w, h, pabyOut, w, h, GDT_Byte,
                                                  0, 0, nullptr) != CE_None)
            return CE_Failure;
        if (m_poNoData)
        {
            std::vector<GByte> ab(n);
            if (m_poNoData->RasterIO(GF_Read, x, y, w, h, ab.data(), w, h, GDT_Byte, 0, 0,
                                     nullptr) != CE_None)
                return CE_Failure;
            for (size_t i = 0; i < n; i++)
                pabyOut[i] = ab[i] ? pabyOut[i] : 0;
        }
        if (m_poAlpha)
        {
            std::vector<float> af(n);
            if (m_poAlpha->RasterIO(GF_Read, x, y, w, h, af.data(), w, h, GDT_Float32, 0, 0,
                                    nullptr) != CE_None)
                return CE_Failure;
            for (size_t i = 0; i < n; i++)
                pabyOut[i] = af[i] > 0 ? pabyOut[i] : 0; // (NaN: not > 0)
        }
        return CE_None;
    }

  protected:
    CPLErr IReadBlock(int nBX, int nBY, void *pData) override
    {
        int x, y, w, h;
        BlockWindow(nBX, nBY, &x, &y, &w, &h);
        std::vector<GByte> ab(static_cast<size_t>(w) * h);
        if (ReadValid(x, y, w, h, ab.data()) != CE_None)
            return CE_Failure;
        for (int j = 0; j < h; j++)
            memcpy(static_cast<GByte *>(pData) + static_cast<size_t>(j) * nBlockXSize,
                   ab.data() + static_cast<size_t>(j) * w, w);
        return CE_None;
    }

    CPLErr IRasterIO(GDALRWFlag eRW, int x, int y, int w, int h, void *pData, int bw, int bh,
                     GDALDataType eType, GSpacing nPixel, GSpacing nLine,
                     GDALRasterIOExtraArg *psExtra) override
    {
        if (eRW != GF_Read || bw != w || bh != h || eType != GDT_Byte)
            return GDALRasterBand::IRasterIO(eRW, x, y, w, h, pData, bw, bh, eType, nPixel,
                                             nLine, psExtra);
        std::vector<GByte> ab(static_cast<size_t>(w) * h);
        if (ReadValid(x, y, w, h, ab.data()) != CE_None)
            return CE_Failure;
        for (int j = 0; j < h; j++)
            for (int i = 0; i < w; i++)
                static_cast<GByte *>(pData)[j * nLine + i * nPixel] =
                    ab[static_cast<size_t>(j) * w + i];
        return CE_None;
    }

  public:
    ValidMaskBand(GDALRasterBand *poSrc, const Extra &s)
        : ProxyBand(poSrc, GDT_Byte), m_poSrc(poSrc),
          m_poNoData(s.bNoData ? new GDALNoDataMaskBand(poSrc) : nullptr), m_poAlpha(s.poAlpha)
    {
    }
    ~ValidMaskBand() override
    {
        FlushCache(true);
        delete m_poNoData;
    }
    bool IsMaskBand() const override { return true; }
};

/* The DEM band's values with the combined mask as its mask. */
class ValidBand final : public ProxyBand
{
    GDALRasterBand *m_poSrc;
    ValidMaskBand m_oMask;

  protected:
    CPLErr IReadBlock(int nBX, int nBY, void *pData) override
    {
        int x, y, w, h;
        BlockWindow(nBX, nBY, &x, &y, &w, &h);
        const int nSize = GDALGetDataTypeSizeBytes(eDataType);
        return m_poSrc->RasterIO(GF_Read, x, y, w, h, pData, w, h, eDataType, nSize,
                                 static_cast<GSpacing>(nSize) * nBlockXSize, nullptr);
    }

    /* Full resolution straight from the DEM; resampled through GDAL's
     * own resampling, which reads both bands here at full resolution and
     * weighs the cells by the combined mask. */
    CPLErr IRasterIO(GDALRWFlag eRW, int x, int y, int w, int h, void *pData, int bw, int bh,
                     GDALDataType eType, GSpacing nPixel, GSpacing nLine,
                     GDALRasterIOExtraArg *psExtra) override
    {
        if (eRW == GF_Read && bw == w && bh == h)
            return m_poSrc->RasterIO(GF_Read, x, y, w, h, pData, bw, bh, eType, nPixel, nLine,
                                     nullptr);
        return GDALRasterBand::IRasterIO(eRW, x, y, w, h, pData, bw, bh, eType, nPixel, nLine,
                                         psExtra);
    }

  public:
    ValidBand(GDALRasterBand *poSrc, const Extra &s)
        : ProxyBand(poSrc, poSrc->GetRasterDataType()), m_poSrc(poSrc), m_oMask(poSrc, s)
    {
    }
    ~ValidBand() override { FlushCache(true); }
    GDALRasterBand *GetMaskBand() override { return &m_oMask; }
    int GetMaskFlags() override { return GMF_PER_DATASET; }
};

} // namespace

GDALRasterBandH tsd_dem_valid_band(GDALRasterBandH hBand)
{
    GDALRasterBand *poBand = GDALRasterBand::FromHandle(hBand);
    const Extra s = ExtraOf(poBand);
    if (!s.bNoData && !s.poAlpha)
        return hBand;
    ValidBand *p = new (std::nothrow) ValidBand(poBand, s);
    return p ? GDALRasterBand::ToHandle(p) : nullptr;
}

void tsd_dem_valid_release(GDALRasterBandH hBand, GDALRasterBandH hValid)
{
    if (hValid && hValid != hBand)
        delete GDALRasterBand::FromHandle(hValid);
}
