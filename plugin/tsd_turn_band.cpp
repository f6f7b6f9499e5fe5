/*
 * tsd_turn_band.cpp - a band's statistics, min/max and histograms in its
 * dataset's read turn (tsd_turn_band.h).
 */
#include "tsd_turn_band.h"

namespace tsd
{

CPLErr TSTurnBand::ComputeStatistics(int bApproxOK, double *pdfMin, double *pdfMax,
                                     double *pdfMean, double *pdfStdDev,
                                     GDALProgressFunc pfnProgress, void *pProgressData)
{
    std::unique_lock<std::recursive_mutex> oTurn;
    if (!TakeReadTurn(oTurn))
        return CE_Failure;
    return GDALPamRasterBand::ComputeStatistics(bApproxOK, pdfMin, pdfMax, pdfMean, pdfStdDev,
                                                pfnProgress, pProgressData);
}

CPLErr TSTurnBand::ComputeRasterMinMax(int bApproxOK, double *adfMinMax)
{
    std::unique_lock<std::recursive_mutex> oTurn;
    if (!TakeReadTurn(oTurn))
        return CE_Failure;
    return GDALPamRasterBand::ComputeRasterMinMax(bApproxOK, adfMinMax);
}

CPLErr TSTurnBand::GetHistogram(double dfMin, double dfMax, int nBuckets,
                                GUIntBig *panHistogram, int bIncludeOutOfRange, int bApproxOK,
                                GDALProgressFunc pfnProgress, void *pProgressData)
{
    std::unique_lock<std::recursive_mutex> oTurn;
    if (!TakeReadTurn(oTurn))
        return CE_Failure;
    return GDALPamRasterBand::GetHistogram(dfMin, dfMax, nBuckets, panHistogram,
                                           bIncludeOutOfRange, bApproxOK, pfnProgress,
                                           pProgressData);
}

} // namespace tsd
