/*
 * tsd_turn_band.cpp - a band's statistics, min/max and histograms in its
 * dataset's read turn (tsd_turn_band.h).
 */
#include "tsd_turn_band.h"

namespace tsd
{

bool TSTurnBand::ApproxFromLevel(int bApproxOK, GUIntBig nSamples)
{
    return bApproxOK && GetOverviewCount() > 0 && !HasArbitraryOverviews() &&
           GetRasterSampleOverview(nSamples) != this;
}

CPLErr TSTurnBand::ComputeStatistics(int bApproxOK, double *pdfMin, double *pdfMax,
                                     double *pdfMean, double *pdfStdDev,
                                     GDALProgressFunc pfnProgress, void *pProgressData)
{
    std::unique_lock<std::recursive_mutex> oTurn;
    if (!TakeReadTurn(oTurn))
        return CE_Failure;
    // GDAL takes approximate statistics from an overview level, which here
    // is the product of a coarser DEM, not an average of this one (an svf
    // level 16 times coarser: mean 0.965 where the product's is 0.765):
    // the caller gets them, but they are not saved, where a later
    // GetStatistics, and gdal_translate's copy into the file it writes,
    // took them for this product's (QGIS's default stretch on a large DEM)
    // (GDAL's own test, gcore/gdalrasterband.cpp; the band's saved items,
    // exact ones among them, are what they were before)
    const bool bFromLevel = ApproxFromLevel(bApproxOK, GDALSTAT_APPROX_NUMSAMPLES);
    static const char *const apszItems[] = {"STATISTICS_MINIMUM",       "STATISTICS_MAXIMUM",
                                            "STATISTICS_MEAN",          "STATISTICS_STDDEV",
                                            "STATISTICS_VALID_PERCENT", "STATISTICS_APPROXIMATE"};
    CPLStringList aosBefore;
    if (bFromLevel)
        for (const char *pszItem : apszItems)
            if (const char *pszValue = GDALPamRasterBand::GetMetadataItem(pszItem))
                aosBefore.SetNameValue(pszItem, pszValue);
    const CPLErr eErr = GDALPamRasterBand::ComputeStatistics(
        bApproxOK, pdfMin, pdfMax, pdfMean, pdfStdDev, pfnProgress, pProgressData);
    if (bFromLevel)
        for (const char *pszItem : apszItems)
            GDALPamRasterBand::SetMetadataItem(pszItem, aosBefore.FetchNameValue(pszItem));
    return eErr;
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
    // an approximate histogram is the coarsest level's (GDAL's
    // GetRasterSampleOverview(0)), another DEM's product: the caller gets it,
    // but it is not saved, where GetDefaultHistogram, gdalinfo -hist and
    // QGIS then reported it as this band's (as for the statistics above)
    // (a saved exact histogram that matches still answers it)
    const bool bFromLevel = ApproxFromLevel(bApproxOK, 0);
    const auto Saved = [this]() -> CPLXMLNode *
    { return psPam ? psPam->psSavedHistograms : nullptr; };
    CPLXMLNode *psLastBefore = nullptr;
    for (CPLXMLNode *psItem = Saved() ? Saved()->psChild : nullptr; psItem;
         psItem = psItem->psNext)
        psLastBefore = psItem;
    const bool bHadAny = Saved() != nullptr;
    const CPLErr eErr = GDALPamRasterBand::GetHistogram(dfMin, dfMax, nBuckets, panHistogram,
                                                        bIncludeOutOfRange, bApproxOK,
                                                        pfnProgress, pProgressData);
    if (bFromLevel && Saved())
    {
        // what GDAL's PAM appended: dropped again
        CPLXMLNode *psAdded = psLastBefore ? psLastBefore->psNext : Saved()->psChild;
        if (psLastBefore)
            psLastBefore->psNext = nullptr;
        else
            Saved()->psChild = nullptr;
        CPLDestroyXMLNode(psAdded);
        if (!bHadAny)
        {
            CPLDestroyXMLNode(psPam->psSavedHistograms);
            psPam->psSavedHistograms = nullptr;
        }
    }
    return eErr;
}

} // namespace tsd
