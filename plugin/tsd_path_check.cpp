/*
 * tsd_path_check.cpp - names refused before GDAL opens them
 * (tsd_path_check.h).
 */
#include "tsd_path_check.h"

#include <cstring>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

namespace tsd
{

std::string NonRegularSource(const char *pszPath)
{
    std::string osRest = pszPath ? pszPath : "";
    // GDAL's in-process wrappers, outermost first: each reads the file
    // named after it (an audit hung an open on /vsisubfile/0_0,fifo)
    for (;;)
    {
        if (STARTS_WITH_CI(osRest.c_str(), "/vsistdin"))
            return "/vsistdin/";
        bool bWrapped = false;
        for (const char *pszWrapper : {"/vsigzip/", "/vsizip/", "/vsitar/", "/vsisubfile/"})
        {
            if (!STARTS_WITH_CI(osRest.c_str(), pszWrapper))
                continue;
            osRest.erase(0, strlen(pszWrapper));
            if (EQUAL(pszWrapper, "/vsisubfile/"))
            {
                const size_t nComma = osRest.find(',');
                osRest.erase(0, nComma == std::string::npos ? osRest.size() : nComma + 1);
            }
            else if (!osRest.empty() && osRest[0] == '{' && osRest.find('}') != std::string::npos)
                osRest = osRest.substr(1, osRest.find('}') - 1);
            bWrapped = true;
            break;
        }
        if (!bWrapped)
            break;
    }
    if (osRest.empty() || STARTS_WITH(osRest.c_str(), "/vsi"))
        return std::string(); // a URL, an in-memory file: no open that waits
    // the first part of the path that is not a folder: the file itself, or
    // the archive whose member the rest names
    for (size_t nEnd = osRest.find('/', 1);; nEnd = osRest.find('/', nEnd + 1))
    {
        const std::string osPart = osRest.substr(0, nEnd);
        VSIStatBufL sStat;
        if (VSIStatL(osPart.c_str(), &sStat) == 0 && !VSI_ISDIR(sStat.st_mode))
            return VSI_ISREG(sStat.st_mode) ? std::string() : osPart;
        if (nEnd == std::string::npos)
            return std::string();
    }
}

std::string RefusedDEMName(const char *pszDEM, const char *pszWhat, bool bFromFile)
{
    if (STARTS_WITH_CI(pszDEM, "MEM:::") &&
        !CPLTestBool(CPLGetConfigOption("GDAL_MEM_ENABLE_OPEN", "NO")))
        return CPLSPrintf("%s '%s' is a MEM::: name, which reads the process's memory at any "
                          "address it gives: refused (GDAL 3.10 refuses it too), unless the "
                          "configuration option GDAL_MEM_ENABLE_OPEN=YES is set",
                          pszWhat, pszDEM);
    const std::string osSource = NonRegularSource(pszDEM);
    if (osSource == "/vsistdin/")
        return bFromFile ? std::string(CPLSPrintf(
                               "%s '%s' reads the standard input, which a name written in a "
                               "file may not: give the DEM with the open option DEM=...",
                               pszWhat, pszDEM))
                         : std::string();
    if (!osSource.empty())
        return CPLSPrintf("%s '%s' reads '%s', which is not a regular file (a pipe, a "
                          "device...): its open would wait for a writer, for ever. Write "
                          "the DEM to a file first",
                          pszWhat, pszDEM, osSource.c_str());
    return std::string();
}

} // namespace tsd
