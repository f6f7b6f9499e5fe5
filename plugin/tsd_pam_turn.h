/*
 * tsd_pam_turn.h - one turn on the products' auxiliary file of a DEM
 * (<DEM>.terrashade.aux.xml), between threads and between processes.
 */
#ifndef TSD_PAM_TURN_H
#define TSD_PAM_TURN_H

#include <mutex>

namespace tsd
{

/* One turn on the products' auxiliary file of a DEM: this process's
 * threads on the same folder one at a time, and processes too, by an
 * advisory lock (flock) on the DEM's directory, which every product of that
 * DEM shares and which is never written: GDAL rewrites an .aux.xml whole
 * (reads, truncates, writes), so processes saving statistics of several
 * products at once lost each other's entries. (Not on the DEM's file: its
 * open and close here would drop the POSIX locks this process holds on it,
 * SQLite's in a GeoPackage DEM.) Saves lock exclusively, loads shared (a
 * load never reads a half-written file). Nested turns of the same thread
 * (GDAL's save calls TrySaveXML again to write into GDAL_PAM_PROXY_DIR)
 * take no second lock. No lock where the DEM is not a local file
 * (/vsimem/: its threads one at a time), where the file system refuses it
 * (NFS's emulation of flock on a directory) or after a wait (10 s a save,
 * 2 s a load): then as before. Threads on other folders do not wait: one
 * mutex for the whole process held every thread's opens and saves while
 * one waited on another process's lock (9.9 s, session 59's audit). */
class PamFileTurn
{
    std::unique_lock<std::recursive_mutex> m_oThreads; // this folder's threads
    int m_fd = -1;

  public:
    PamFileTurn(const char *pszDEM, bool bWrite);
    ~PamFileTurn();
    PamFileTurn(const PamFileTurn &) = delete;
    PamFileTurn &operator=(const PamFileTurn &) = delete;
};

} // namespace tsd

#endif
