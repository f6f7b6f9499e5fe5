/*
 * tsd_turn_band.h - the base of a product's bands and an atlas's whose
 * reads take their dataset's turn. GDAL 3.6's block cache of a dataset is
 * not thread-safe: it files a block before IReadBlock fills it, so that a
 * second thread reading the same dataset could take the block unfilled
 * (zeros, nodata, garbage). The statistics, min/max and histograms read
 * blocks straight from that cache; here they take the turn that the
 * dataset's and the band's IRasterIO take (docs/driver.md, "Threads").
 */
#ifndef TSD_TURN_BAND_H
#define TSD_TURN_BAND_H

#include <mutex>

#include "tsd_pam_band.h"

namespace tsd
{

class TSTurnBand : public TSPamBand
{
  protected:
    /* This read's turn: false where it is refused (its error said); else
     * true with oTurn holding the dataset's read lock. */
    virtual bool TakeReadTurn(std::unique_lock<std::recursive_mutex> &oTurn) = 0;

    /* whether GDAL answers an approximate request from an overview level
     * (GetRasterSampleOverview(nSamples)), which is a coarser DEM's product */
    bool ApproxFromLevel(int bApproxOK, GUIntBig nSamples);

  public:
    CPLErr ComputeStatistics(int bApproxOK, double *pdfMin, double *pdfMax, double *pdfMean,
                             double *pdfStdDev, GDALProgressFunc pfnProgress,
                             void *pProgressData) override;
    CPLErr ComputeRasterMinMax(int bApproxOK, double *adfMinMax) override;
    CPLErr GetHistogram(double dfMin, double dfMax, int nBuckets, GUIntBig *panHistogram,
                        int bIncludeOutOfRange, int bApproxOK, GDALProgressFunc pfnProgress,
                        void *pProgressData) override;
};

} // namespace tsd

#endif
