/*
 * tsd_caller_progress.h - the progress callback of the caller of a read
 * (GDALRasterIOExtraArg's pfnProgress: Python's ReadAsArray(callback=),
 * gdal.Translate's through GDAL's copy) for the computation the read
 * starts: a product, or a chunk, is computed inside the first read that
 * needs it, deep below GDAL's RasterIO, where no argument reaches.
 */
#ifndef TSD_CALLER_PROGRESS_H
#define TSD_CALLER_PROGRESS_H

#include "gdal_priv.h"

#include "tsd_progress.h"

namespace tsd
{

/** For its lifetime, a RasterIO with a progress callback on this thread:
 * set by the datasets' and bands' IRasterIO; an inner RasterIO without
 * one keeps the outer's. */
class CallerProgress
{
    const GDALRasterIOExtraArg *m_psPrev;
    int m_nCancelledBefore; // NoteCancelled's count at the start

  public:
    explicit CallerProgress(const GDALRasterIOExtraArg *psExtraArg);
    ~CallerProgress();
    CallerProgress(const CallerProgress &) = delete;
    CallerProgress &operator=(const CallerProgress &) = delete;

    /** Hook the callback of the read under way on this thread, if any,
     * to psProgress: told the fraction computed, it stops the computation
     * by returning FALSE. */
    static void Hook(tsd_progress *psProgress);

    /** Count a computation that the callback stopped on this thread. */
    static void NoteCancelled();

    /** Whether a computation under this read was stopped but the last
     * error does not say so (GDAL reports a failed block read after
     * ours, as CPLE_AppDefined): then the read says it again. */
    bool CancelledUnsaid() const;
};

} // namespace tsd

#endif
