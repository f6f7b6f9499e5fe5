/* The caller's progress callback of a read; see tsd_caller_progress.h. */
#include "tsd_caller_progress.h"

#include <algorithm>

namespace tsd
{

/* Per thread: readers on several threads (one dataset each) have their
 * own callbacks; the innermost read with one, its callback tracked. */
static thread_local CallerProgress *tl_poRead = nullptr;
static thread_local int tl_nCancelled = 0;

CallerProgress::CallerProgress(const GDALRasterIOExtraArg *psExtraArg, int nXOff, int nYOff,
                               int nXSize, int nYSize)
    : m_nCancelledBefore(tl_nCancelled), m_poPrevRead(tl_poRead)
{
    if (!psExtraArg || !psExtraArg->pfnProgress)
        return;
    m_psUser = psExtraArg;
    m_sArg = *psExtraArg;
    m_sArg.pfnProgress = Track;
    m_sArg.pProgressData = this;
    m_anWindow[0] = nXOff;
    m_anWindow[1] = nYOff;
    m_anWindow[2] = nXSize;
    m_anWindow[3] = nYSize;
    tl_poRead = this;
}

CallerProgress::~CallerProgress()
{
    tl_poRead = m_poPrevRead;
}

int CPL_STDCALL CallerProgress::Track(double dfDone, const char *pszMsg, void *pData)
{
    CallerProgress *poRead = static_cast<CallerProgress *>(pData);
    poRead->m_dfSeen = std::max(poRead->m_dfSeen, std::min(dfDone, 1.0));
    return poRead->m_psUser->pfnProgress(poRead->m_dfSeen, pszMsg ? pszMsg : "",
                                         poRead->m_psUser->pProgressData);
}

/* The computation under way on this thread: its read, and the span of the
 * read's fraction its 0..1 covers. (One at a time: a computation never
 * starts inside another on the same thread.) */
struct Computation
{
    const GDALRasterIOExtraArg *psArg; // the read's, its callback tracked
    double dfFrom, dfSpan;
};
static thread_local Computation tl_sComputation{};

/* A ts_progress_fn over GDAL's callback: non-zero (stop) when it returns
 * FALSE. */
static int CallerStops(double dfDone, void *pUser)
{
    const Computation *c = static_cast<const Computation *>(pUser);
    return !c->psArg->pfnProgress(c->dfFrom + c->dfSpan * dfDone, "", c->psArg->pProgressData);
}

double CallerProgress::Share(const int *panCells) const
{
    const double dfArea = static_cast<double>(m_anWindow[2]) * m_anWindow[3];
    if (!panCells || !(dfArea > 0))
        return 1.0;
    const double w = std::min(m_anWindow[0] + m_anWindow[2], panCells[0] + panCells[2]) -
                     std::max(m_anWindow[0], panCells[0]);
    const double h = std::min(m_anWindow[1] + m_anWindow[3], panCells[1] + panCells[3]) -
                     std::max(m_anWindow[1], panCells[1]);
    return w > 0 && h > 0 ? std::min(1.0, w * h / dfArea) : 0.0;
}

void CallerProgress::Hook(tsd_progress *psProgress, const int *panCells)
{
    const CallerProgress *poRead = tl_poRead;
    if (!poRead)
        return;
    const double dfFrom = poRead->m_dfSeen;
    /* a chunk: as much of the read as GDAL's blocks of it will say */
    tl_sComputation = {&poRead->m_sArg, dfFrom, std::min(1.0 - dfFrom, poRead->Share(panCells))};
    tsd_progress_set_caller(psProgress, CallerStops, &tl_sComputation);
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
