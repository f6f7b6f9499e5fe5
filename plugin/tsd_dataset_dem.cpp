/*
 * tsd_dataset_dem.cpp - a TERRASHADE dataset's DEM: its open (GeoTIFF's
 * direct I/O where the name is an OS path), the read ahead on a thread of
 * its own while OpenCL is probed (local GeoTIFFs only), and the read into
 * the grid the computation takes, the messages the read-ahead thread held
 * said again on the caller's.
 */
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include "cpl_conv.h"
#include "cpl_error.h"
#include "cpl_string.h"
#include "gdal_priv.h"

#include "tsd_dataset.h"
#include "tsd_dem.h"
#include "tsd_gdal.h"
#include "tsd_source_stamp.h"
#include "tsd_entry_state.h"

namespace tsd
{

/* The DEM opened for reading. An uncompressed GeoTIFF is read straight
 * into the grid, not through the block cache (GTIFF_DIRECT_IO, which GDAL
 * takes at open): one copy fewer and no cache the size of the DEM, the
 * same values. The user's own setting wins. */
GDALDataset *TSDataset::OpenDEM(const char *pszDEM)
{
    // a file of the operating system's only: a virtual file system may not
    // implement the reads it makes (rasterio's /vsipythonfilelike/: "Read
    // not implemented", where GDAL's own reads succeed)
    const bool bDirect = strstr(pszDEM, "/vsi") == nullptr;
    CPLConfigOptionSetter oDirect("GTIFF_DIRECT_IO", bDirect ? "YES" : nullptr, true);
    return GDALDataset::Open(pszDEM, GDAL_OF_RASTER | GDAL_OF_VERBOSE_ERROR);
}

std::string TSDataset::CopyStdin(const tsd_options &sOpts, const std::string &osDEM)
{
    const char *pszWhy = nullptr;
    const double dfLimit = MemoryLimit(sOpts, &pszWhy);
    static std::atomic<unsigned> nCopies{0};
    const std::string osCopy =
        CPLSPrintf("/vsimem/terrashade_stdin_%ld_%u", static_cast<long>(getpid()), nCopies++);
    // (through the handlers named before it: /vsigzip//vsistdin/ decompressed;
    // GDAL opens /vsistdin with its slash only)
    const std::string osStream =
        osDEM.size() >= 9 && osDEM.compare(osDEM.size() - 9, 9, "/vsistdin") == 0 ? osDEM + "/"
                                                                                  : osDEM;
    VSILFILE *fpIn = VSIFOpenL(osStream.c_str(), "rb");
    VSILFILE *fpOut = fpIn ? VSIFOpenL(osCopy.c_str(), "wb") : nullptr;
    std::vector<GByte> abyChunk(1 << 20);
    double dfBytes = 0;
    bool bOver = false, bFailed = fpOut == nullptr;
    while (!bFailed && !bOver)
    {
        const size_t nRead = VSIFReadL(abyChunk.data(), 1, abyChunk.size(), fpIn);
        dfBytes += static_cast<double>(nRead);
        bOver = dfBytes > dfLimit;
        bFailed = VSIFWriteL(abyChunk.data(), 1, nRead, fpOut) != nRead;
        if (nRead < abyChunk.size())
            break;
    }
    if (fpOut)
        VSIFCloseL(fpOut);
    if (fpIn)
        VSIFCloseL(fpIn);
    if (!bFailed && !bOver && dfBytes > 0)
        return osCopy;
    VSIUnlink(osCopy.c_str());
    Fail(bOver ? CPLE_OutOfMemory : CPLE_OpenFailed,
         bOver ? CPLSPrintf("the DEM '%s' is read whole into memory (a stream reads "
                            "forward only, and the DEM is read more than once), and it holds "
                            "more than the limit of %.0f MiB (%s): write the DEM to a file "
                            "first",
                            osDEM.c_str(), dfLimit / 1048576.0, pszWhy)
         : !fpIn       ? CPLSPrintf("cannot read the DEM '%s' from the standard input",
                                    osDEM.c_str())
         : dfBytes > 0 ? CPLSPrintf("cannot copy the DEM '%s' into memory", osDEM.c_str())
                       : CPLSPrintf("the DEM '%s': the standard input is empty",
                                    osDEM.c_str()));
    return std::string();
}

double TSDataset::StdinCopyBytes() const
{
    const std::string &osCopy = (m_poBase ? m_poBase : this)->m_osStdinCopy;
    VSIStatBufL sStat;
    return !osCopy.empty() && VSIStatL(osCopy.c_str(), &sStat) == 0
               ? static_cast<double>(sStat.st_size)
               : 0.0;
}

/* Whether a file is read without the network and without the host's
 * code: a path of the operating system's, or one through GDAL's own
 * in-process file systems only. Over the network the metadata alone
 * (gdalinfo, QGIS's layer properties) downloaded the whole DEM; and a file
 * system a host adds (rasterio's /vsipythonfilelike/ and /vsiriopener_*,
 * which run Python) read on the driver's thread waited for the host's lock
 * (Python's GIL, which rasterio holds in close, checksum and statistics)
 * while the host waited for the thread: a deadlock. */
static bool ReadAheadSafe(const std::string &osPath)
{
    static const char *const apszInProcess[] = {"/vsimem/", "/vsizip/", "/vsigzip/",
                                                "/vsitar/", "/vsisubfile/", "/vsisparse/"};
    for (size_t i = osPath.find("/vsi"); i != std::string::npos; i = osPath.find("/vsi", i + 1))
    {
        bool bKnown = false;
        for (const char *pszFS : apszInProcess)
            bKnown = bKnown || osPath.compare(i, strlen(pszFS), pszFS) == 0;
        if (!bKnown)
            return false;
    }
    return osPath.find("://") == std::string::npos; // (a URL as a VRT source)
}

/* Start reading the DEM on a thread of its own, for ReadDEM, while this
 * one probes the OpenCL device for the metadata (tens of ms with PoCL):
 * the whole-DEM path only, which reads it once, and only before computing.
 * Under m_oMutex. */
void TSDataset::StartReadAhead()
{
    if (m_poWindow || !m_poDEM || m_bTried || m_oReadAhead.joinable())
        return;
    // a GeoTIFF only, of local files (ReadAheadSafe): the common case, and
    // one whose reads run no code of the host's (a VRT may hold a Python
    // pixel function, at any depth of VRTs of VRTs; GDAL drivers may be
    // written in Python)
    bool bSafe = m_poDEM->GetDriver() &&
                 EQUAL(m_poDEM->GetDriver()->GetDescription(), "GTiff") &&
                 ReadAheadSafe(m_osDEMPath);
    for (const std::string &osFile : m_aosDEMFiles)
        bSafe = bSafe && ReadAheadSafe(osFile);
    if (!bSafe)
        return;
    // the caller's thread-local configuration (CPLSetThreadLocalConfigOption,
    // as GDAL 3.7's gdal.config_options sets it): the thread reads as the
    // caller would (GTiff's options, CPL_DEBUG)
    char **papszThreadConfig = CPLGetThreadLocalConfigOptions();
    try
    {
        m_oReadAhead = std::thread(
            [this, papszThreadConfig]
            {
                CPLSetThreadLocalConfigOptions(papszThreadConfig);
                CSLDestroy(papszThreadConfig);
                tsd::EntryState oEntry; /* its messages' numbers (tsd_entry_state.h) */
                CPLPushErrorHandlerEx(HoldMessage, &m_aoReadMessages);
                char szMsg[1024] = "";
                const auto tStart = std::chrono::steady_clock::now();
                m_eReadStatus = LoadDEM(&m_sReadGrid, szMsg, sizeof szMsg);
                m_osReadMsg = szMsg;
                const std::chrono::duration<double> dfRead =
                    std::chrono::steady_clock::now() - tStart;
                CPLDebug(DRIVER, "read the DEM ahead, on a thread of its own, in %.3f s",
                         dfRead.count());
                CPLPopErrorHandler();
                CPLSetThreadLocalConfigOptions(nullptr);
            });
    }
    catch (const std::exception &)
    {
        // no thread: EnsureComputed reads the DEM itself
        CSLDestroy(papszThreadConfig);
    }
}

void CPL_STDCALL TSDataset::HoldMessage(CPLErr eClass, CPLErrorNum nNum, const char *pszMsg)
{
    auto *paoHeld = static_cast<std::vector<HeldMessage> *>(CPLGetErrorHandlerUserData());
    paoHeld->push_back(HeldMessage{eClass, nNum, pszMsg ? pszMsg : ""});
}

/* The open DEM's band, resampled to the dataset's size, into *psGrid. */
ts_status TSDataset::LoadDEM(ts_grid *psGrid, char *pszMsg, size_t nMsg)
{
    return tsd_dem_load_resampled(GDALGetRasterBand(m_poDEM, m_sOpts.band), &m_sCells,
                                  m_sOpts.z_factor, nRasterXSize, nRasterYSize, psGrid,
                                  pszMsg, nMsg);
}

/* The DEM at the dataset's size into *psGrid: what StartReadAhead read, or
 * read now (an overview level opens the DEM again). */
ts_status TSDataset::ReadDEM(ts_grid *psGrid, char *pszMsg, size_t nMsg)
{
    if (m_oReadAhead.joinable())
    {
        m_oReadAhead.join();
        for (const HeldMessage &oHeld : m_aoReadMessages)
            if (oHeld.eClass == CE_Debug)
            {
                CPLErrorStateBackuper oKeep; // (sets no last error, as CPLDebug's)
                CPLError(oHeld.eClass, oHeld.nNum, "%s", oHeld.osMsg.c_str());
            }
            else
                CPLError(oHeld.eClass, oHeld.nNum, "%s", oHeld.osMsg.c_str());
        m_aoReadMessages.clear();
        *psGrid = m_sReadGrid;
        m_sReadGrid = ts_grid{};
        snprintf(pszMsg, nMsg, "%s", m_osReadMsg.c_str());
        return m_eReadStatus;
    }
    if (m_bDEMReleased && !m_poDEM)
    {
        snprintf(pszMsg, nMsg, "%s", DEMReleasedError().c_str());
        return TS_ERR_INTERNAL;
    }
    if (!m_poDEM) // an overview level: the DEM again, read at its size
    {
        m_poDEM = OpenDEM(m_osDEMPath.c_str());
        // (GTIFF_DIR:1:/data/dem.tif and vrt:///data/dem.tif are absolute)
        const std::string osName =
            STARTS_WITH(m_osDEMPath.c_str(), "vrt://") ? m_osDEMPath.substr(6) : m_osDEMPath;
        const bool bRelative =
            osName.empty() || (osName[0] != '/' && osName.find(":/") == std::string::npos);
        const char *pszRelative = bRelative ? "; its name is relative to the working directory, "
                                              "which changed?"
                                            : "";
        if (!m_poDEM) // (out of file descriptors, moved, a chdir...)
        {
            snprintf(pszMsg, nMsg, "cannot open the DEM '%s' again for overview level %d%s%s",
                     m_osDEM.c_str(), m_nLevel, pszRelative, KEPT_FAILURE);
            return TS_ERR_INTERNAL;
        }
        // the files of the open among its files (a name that stays relative
        // to the working directory, GTIFF_DIR:1:dem.tif, vrt://dem.tif, named
        // another directory's DEM after a chdir, read without a word); files
        // added since (an .ovr of gdaladdo) are the DEM's, as GDAL reads them
        const TSDataset *poLevel0 = m_poBase ? m_poBase : this;
        char **papszFiles = m_poDEM->GetFileList();
        const std::vector<std::string> aosNow = SourceFiles(papszFiles, nullptr);
        CSLDestroy(papszFiles);
        const std::string *posGone = nullptr;
        for (const std::string &osFile : poLevel0->m_aosDEMFiles)
            if (!posGone && std::find(aosNow.begin(), aosNow.end(), osFile) == aosNow.end())
                posGone = &osFile;
        if (posGone && DEMUnchanged()) // (a file deleted or changed: said by the caller)
        {
            GDALClose(m_poDEM);
            m_poDEM = nullptr;
            snprintf(pszMsg, nMsg,
                     "the DEM '%s' opens other files now than when this dataset was opened "
                     "('%s' is not among them%s), so overview level %d is not computed from "
                     "it: open the DEM again",
                     m_osDEM.c_str(), posGone->c_str(), pszRelative, m_nLevel);
            return TS_ERR_ARG;
        }
    }
    return LoadDEM(psGrid, pszMsg, nMsg);
}

OGRSpatialReference GroundSRS(const OGRSpatialReference &oSRS)
{
    OGRSpatialReference oGround(oSRS);
    if (!oGround.IsCompound())
        return oGround;
    std::vector<int> anAxes = oSRS.GetDataAxisToSRSAxisMapping();
    oGround.StripVertical();
    if (anAxes.size() >= 2)
    {
        anAxes.resize(2);
        oGround.SetDataAxisToSRSAxisMapping(anAxes);
    }
    return oGround;
}

} // namespace tsd
