/*
 * tsd_source_stamp.cpp - the stamp of the files a product is made of
 * (tsd_source_stamp.h).
 */
#include "tsd_source_stamp.h"

#include <cstdint>
#include <cstring>
#include <sys/stat.h>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

namespace tsd
{

std::string AbsolutePath(const char *pszPath)
{
    static const char *const apszArchives[] = {"/vsizip/", "/vsigzip/", "/vsitar/"};
    std::string osPrefix;
    const char *pszRest = pszPath;
    for (const char *pszArchive : apszArchives)
        if (STARTS_WITH(pszPath, pszArchive))
        {
            osPrefix = pszArchive;
            pszRest = pszPath + strlen(pszArchive);
            break;
        }
    // an archive's name in braces, /vsizip/{a.zip}/dem.tif: its name inside
    // (not /vsigzip/'s: it has no such form, and {g}.tif.gz is a name)
    const bool bBraces = !osPrefix.empty() && osPrefix != "/vsigzip/" && *pszRest == '{' &&
                         strchr(pszRest, '}');
    if (bBraces)
        osPrefix += '{', pszRest++;
    VSIStatBufL sStat;
    // (a name that is no file here: a driver's prefix, GTIFF_DIR:1:dem.tif,
    // left alone; the reopened levels check their files, ReadDEM)
    if (!*pszRest || STARTS_WITH(pszRest, "/vsi") || !CPLIsFilenameRelative(pszRest) ||
        VSIStatL(pszPath, &sStat) != 0)
        return pszPath;
    char *pszCwd = CPLGetCurrentDir();
    // (not CPLFormFilename: its buffer holds 2048 characters)
    std::string osAbs = pszCwd ? osPrefix + pszCwd + "/" + pszRest : std::string(pszPath);
    CPLFree(pszCwd);
    return osAbs;
}

std::vector<std::string> SourceFiles(char **papszDEMFiles, const char *pszEnvMap)
{
    std::vector<std::string> aos;
    const auto Add = [&aos](const char *pszPath) { aos.emplace_back(AbsolutePath(pszPath)); };
    for (char **ppsz = papszDEMFiles; ppsz && *ppsz; ppsz++)
    {
        const size_t n = strlen(*ppsz);
        if (!(n >= 8 && EQUAL(*ppsz + n - 8, ".aux.xml")))
            Add(*ppsz);
    }
    if (pszEnvMap && *pszEnvMap)
        Add(pszEnvMap);
    return aos;
}

/* One file's part of the stamp. */
static std::string FileStamp(const std::string &osPath)
{
    if (!STARTS_WITH(osPath.c_str(), "/vsi"))
    {
        struct stat sSt;
        if (stat(osPath.c_str(), &sSt) != 0)
            return "missing";
        return CPLSPrintf("%llu:%llu:%lld:%lld.%09ld", static_cast<unsigned long long>(sSt.st_dev),
                          static_cast<unsigned long long>(sSt.st_ino),
                          static_cast<long long>(sSt.st_size),
                          static_cast<long long>(sSt.st_mtim.tv_sec), sSt.st_mtim.tv_nsec);
    }
    // /vsigzip/'s stat gives the time 0 once GDAL caches the file's
    // handle, so that every /vsigzip/ DEM read as changed after its open:
    // the compressed file's own stamp instead
    if (STARTS_WITH(osPath.c_str(), "/vsigzip/"))
        return "gz " + FileStamp(osPath.substr(strlen("/vsigzip/")));
    VSIStatBufL sSt;
    if (VSIStatExL(osPath.c_str(), &sSt, VSI_STAT_EXISTS_FLAG | VSI_STAT_SIZE_FLAG) != 0)
        return "missing";
    return CPLSPrintf("%llu:%lld", static_cast<unsigned long long>(sSt.st_size),
                      static_cast<long long>(sSt.st_mtime));
}

std::string SourceStamp(const std::vector<std::string> &aosFiles)
{
    if (aosFiles.empty())
        return "";
    // FNV-1a over each file's stamp, not its path: the same file named
    // another way (relative, through a link) is the same contents
    uint64_t h = 14695981039346656037ULL;
    for (const std::string &osPath : aosFiles)
        for (const char c : FileStamp(osPath) + '\n')
            h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
    return CPLSPrintf("%zu file%s, %016llx", aosFiles.size(), aosFiles.size() == 1 ? "" : "s",
                      static_cast<unsigned long long>(h));
}

std::string SourcesChangedError(const std::string &osDEM, int nLevel,
                                const std::vector<std::string> &aosFiles)
{
    const std::string osWhat =
        nLevel ? std::string(CPLSPrintf("overview level %d", nLevel)) : "the product";
    // by its files: the DEM's name may be a driver's (GTIFF_DIR:1:dem.tif)
    VSIStatBufL sStat;
    for (const std::string &osFile : aosFiles)
        if (VSIStatL(osFile.c_str(), &sStat) != 0)
            return CPLSPrintf("the DEM '%s' (its file '%s') was deleted or moved since this "
                              "dataset was opened, so that %s cannot be computed from it",
                              osDEM.c_str(), osFile.c_str(), osWhat.c_str());
    return CPLSPrintf("the DEM '%s' (or a file it is read from) changed on disk since this "
                      "dataset was opened, so that %s would mix its former and its new "
                      "contents: open it again (in QGIS, remove the layer and add it again)",
                      osDEM.c_str(), osWhat.c_str());
}

} // namespace tsd
