/*
 * tsd_pam_turn.cpp - one turn on the products' auxiliary file of a DEM
 * (tsd_pam_turn.h).
 */
#include "tsd_pam_turn.h"

#include <cerrno>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <chrono>
#include <map>
#include <string>
#include <utility>

#include "cpl_conv.h"
#include "cpl_error.h"
#include "cpl_port.h"

namespace tsd
{

namespace
{
/* How long a save or load waits for another process's turn on the same
 * DEM's file before it goes ahead without one (a save takes milliseconds;
 * a holder stuck on a network file system must not hang this one). A load
 * waits less: any process that may read the DEM's folder can hold its lock
 * (an audit held it: each open of a product waited 30 s a turn, 61-93 s),
 * and a load without a turn at worst misses a save's entries. */
constexpr int PAM_LOCK_WAIT_MS = 10000;
constexpr int PAM_LOAD_WAIT_MS = 2000;
/* After a wait ran out on a folder, this process's turns on it go ahead
 * without waiting for this long (an open takes several turns): a load's
 * loads only (a save waited behind a busy moment must still take turns,
 * or entries are lost), a save's both. */
constexpr double PAM_STUCK_S = 60.0;

/* A folder by any name: its device and inode; (0, 0) for the DEMs that are
 * no local file, whose threads take turns on one mutex. */
using Folder = std::pair<dev_t, ino_t>;
using Clock = std::chrono::steady_clock;

/* What the turns share, under Shared().oMutex, which is never held while a
 * turn waits: each folder's mutex (a map's entries stay where they are), and
 * the folders whose loads' [0] or saves' [1] wait ran out, and when. */
struct SharedState
{
    std::mutex oMutex;
    std::map<Folder, std::recursive_mutex> oFolders;
    std::map<Folder, Clock::time_point> aoStuck[2];
};

SharedState &Shared()
{
    static SharedState s;
    return s;
}

std::recursive_mutex &FolderMutex(const Folder &oFolder)
{
    std::lock_guard<std::mutex> oLock(Shared().oMutex);
    return Shared().oFolders[oFolder];
}

bool IsStuck(bool bWrite, const Folder &oFolder)
{
    std::lock_guard<std::mutex> oLock(Shared().oMutex);
    const auto &oStuck = Shared().aoStuck[bWrite ? 1 : 0];
    const auto oIt = oStuck.find(oFolder);
    return oIt != oStuck.end() &&
           std::chrono::duration<double>(Clock::now() - oIt->second).count() < PAM_STUCK_S;
}

/* A wait ran out: the folder's loads go ahead without one, and its saves
 * too after a save's. */
void MarkStuck(bool bWrite, const Folder &oFolder)
{
    std::lock_guard<std::mutex> oLock(Shared().oMutex);
    for (int i = 0; i <= (bWrite ? 1 : 0); i++)
        Shared().aoStuck[i][oFolder] = Clock::now();
}

/* A turn taken: this kind of turn waits again. */
void ClearStuck(bool bWrite, const Folder &oFolder)
{
    std::lock_guard<std::mutex> oLock(Shared().oMutex);
    Shared().aoStuck[bWrite ? 1 : 0].erase(oFolder);
}

/* This thread's turns within one another (the proxy directory's save). */
thread_local int t_nDepth = 0;
} // namespace

PamFileTurn::PamFileTurn(const char *pszDEM, bool bWrite)
{
    if (t_nDepth > 0)
    {
        t_nDepth++;
        return;
    }
    const bool bLocal = pszDEM && *pszDEM && !STARTS_WITH(pszDEM, "/vsi");
    if (bLocal)
    {
        const std::string osDir = CPLGetPath(pszDEM);
        m_fd = open(osDir.empty() ? "." : osDir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    }
    struct stat sDir;
    const Folder oFolder =
        m_fd >= 0 && fstat(m_fd, &sDir) == 0 ? Folder(sDir.st_dev, sDir.st_ino) : Folder(0, 0);
    m_oThreads = std::unique_lock<std::recursive_mutex>(FolderMutex(oFolder));
    t_nDepth++; // (once the turn is taken: a throw before left it raised, unlocked)
    if (m_fd < 0)
        return;
    const bool bStuck = IsStuck(bWrite, oFolder);
    const int nWait = bStuck ? 0 : bWrite ? PAM_LOCK_WAIT_MS : PAM_LOAD_WAIT_MS;
    for (int nWaited = 0;; nWaited += 5)
    {
        if (flock(m_fd, (bWrite ? LOCK_EX : LOCK_SH) | LOCK_NB) == 0)
        {
            ClearStuck(bWrite, oFolder);
            return;
        }
        if (errno != EWOULDBLOCK && errno != EINTR)
            break; // no locks here (some network file systems)
        if (nWaited >= nWait)
        {
            CPLDebug("TERRASHADE", "no turn on the auxiliary file of %s after %d ms: going "
                     "ahead without one (a %s)", pszDEM, nWaited, bWrite ? "save" : "load");
            if (!bStuck)
                MarkStuck(bWrite, oFolder);
            break;
        }
        usleep(5000);
    }
    close(m_fd);
    m_fd = -1;
}

PamFileTurn::~PamFileTurn()
{
    t_nDepth--;
    if (m_fd >= 0)
        close(m_fd); // (releases the lock, then the folder's mutex)
}

} // namespace tsd
