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
 * set by the datasets' and bands' IRasterIO, with the window read (raster
 * cells); an inner RasterIO without one keeps the outer's. The callback
 * sees one fraction of the read that never goes back: GDAL's own reports
 * (through Arg()) and the computations' (Hook), each computation's 0..1
 * spread over its share of what is left of the read (a chunk: the part of
 * the window it covers), never below what the callback was told. */
class CallerProgress
{
    int m_nCancelledBefore; // NoteCancelled's count at the start
    GDALRasterIOExtraArg m_sArg{}; // the caller's, with Track as its callback
    const GDALRasterIOExtraArg *m_psUser = nullptr; // the caller's own, if hooked
    double m_dfSeen = 0;           // the most the callback was told in this read
    int m_anWindow[4] = {0, 0, 0, 0};
    CallerProgress *m_poPrevRead; // the outer read with a callback, if any

    static int CPL_STDCALL Track(double dfDone, const char *pszMsg, void *pData);
    double Share(const int *panCells) const; // of the window, 1 without cells

  public:
    CallerProgress(const GDALRasterIOExtraArg *psExtraArg, int nXOff, int nYOff, int nXSize,
                   int nYSize);
    ~CallerProgress();
    CallerProgress(const CallerProgress &) = delete;
    CallerProgress &operator=(const CallerProgress &) = delete;

    /** What to pass on to GDAL's RasterIO in place of psExtraArg: the same,
     * with the callback tracked. */
    GDALRasterIOExtraArg *Arg(GDALRasterIOExtraArg *psExtraArg)
    {
        return m_psUser ? &m_sArg : psExtraArg;
    }

    /** Hook the callback of the read under way on this thread, if any,
     * to psProgress: told the fraction computed, it stops the computation
     * by returning FALSE. panCells (x, y, width, height in raster cells;
     * NULL: the whole read) is what the computation covers. */
    static void Hook(tsd_progress *psProgress, const int *panCells = nullptr);

    /** Count a computation that the callback stopped on this thread. */
    static void NoteCancelled();

    /** Whether a computation under this read was stopped but the last
     * error does not say so (GDAL reports a failed block read after
     * ours, as CPLE_AppDefined): then the read says it again. */
    bool CancelledUnsaid() const;
};

} // namespace tsd

#endif
