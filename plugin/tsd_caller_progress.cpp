/* The caller's progress callback of a read; see tsd_caller_progress.h. */
#include "tsd_caller_progress.h"

namespace tsd
{

/* Per thread: readers on several threads (one dataset each) have their
 * own callbacks. */
static thread_local const GDALRasterIOExtraArg *tl_psCaller = nullptr;
static thread_local int tl_nCancelled = 0;

CallerProgress::CallerProgress(const GDALRasterIOExtraArg *psExtraArg)
    : m_psPrev(tl_psCaller), m_nCancelledBefore(tl_nCancelled)
{
    if (psExtraArg && psExtraArg->pfnProgress)
        tl_psCaller = psExtraArg;
}

CallerProgress::~CallerProgress()
{
    tl_psCaller = m_psPrev;
}

/* A ts_progress_fn over GDAL's callback: non-zero (stop) when it returns
 * FALSE. */
static int CallerStops(double dfDone, void *pUser)
{
    const GDALRasterIOExtraArg *psArg = static_cast<const GDALRasterIOExtraArg *>(pUser);
    return !psArg->pfnProgress(dfDone, "", psArg->pProgressData);
}

void CallerProgress::Hook(tsd_progress *psProgress)
{
    if (tl_psCaller)
        tsd_progress_set_caller(psProgress, CallerStops,
                                const_cast<GDALRasterIOExtraArg *>(tl_psCaller));
}

void CallerProgress::NoteCancelled()
{
    tl_nCancelled++;
}

bool CallerProgress::CancelledUnsaid() const
{
    return tl_nCancelled != m_nCancelledBefore && CPLGetLastErrorNo() != CPLE_UserInterrupt;
}

} // namespace tsd
