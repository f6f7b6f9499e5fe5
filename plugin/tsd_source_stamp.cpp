/*
 * tsd_source_stamp.cpp - the stamp of the DEM's and ENV_MAP's files
 * (tsd_source_stamp.h).
 */
#include "tsd_source_stamp.h"

#include <sys/stat.h>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

namespace tsd
{

/* One file's part of the stamp. */
static std::string FileStamp(const char *pszPath)
{
    if (!STARTS_WITH(pszPath, "/vsi"))
    {
        struct stat sSt;
        if (stat(pszPath, &sSt) != 0)
            return "missing";
        return CPLSPrintf("%lld bytes, modified %lld.%09ld, changed %lld.%09ld, inode %llu",
                          static_cast<long long>(sSt.st_size),
                          static_cast<long long>(sSt.st_mtim.tv_sec), sSt.st_mtim.tv_nsec,
                          static_cast<long long>(sSt.st_ctim.tv_sec), sSt.st_ctim.tv_nsec,
                          static_cast<unsigned long long>(sSt.st_ino));
    }
    VSIStatBufL sSt;
    if (VSIStatExL(pszPath, &sSt, VSI_STAT_EXISTS_FLAG | VSI_STAT_SIZE_FLAG) != 0)
        return "missing";
    return CPLSPrintf("%llu bytes, modified %lld", static_cast<unsigned long long>(sSt.st_size),
                      static_cast<long long>(sSt.st_mtime));
}

std::string SourceStamp(const char *pszDEMFile, const char *pszEnvMap)
{
    std::string os;
    if (pszDEMFile && *pszDEMFile)
        os = std::string("DEM: ") + FileStamp(pszDEMFile);
    if (pszEnvMap && *pszEnvMap)
        os += std::string(os.empty() ? "" : "; ") + "ENV_MAP: " + FileStamp(pszEnvMap);
    return os;
}

std::string SourcesChangedError(const std::string &osDEM, int nLevel)
{
    const std::string osWhat =
        nLevel ? std::string(CPLSPrintf("overview level %d", nLevel)) : "the product";
    return CPLSPrintf("the DEM '%s' changed on disk since this dataset was opened, so that "
                      "%s would mix its former and its new contents: open it again (in QGIS, "
                      "remove the layer and add it again)",
                      osDEM.c_str(), osWhat.c_str());
}

} // namespace tsd
