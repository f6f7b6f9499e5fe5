/*
 * tsd_path_check.cpp - names refused before GDAL opens them
 * (tsd_path_check.h).
 */
#include "tsd_path_check.h"

#include <cctype>
#include <cstring>
#include <vector>

#include "cpl_conv.h"
#include "cpl_minixml.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

namespace tsd
{

/* The first part of an OS path that is not a folder, where it is no
 * regular file (the file itself, or the archive whose member the rest
 * names); "" otherwise. */
static std::string NonRegularPrefix(const std::string &osPath)
{
    if (osPath.empty())
        return std::string();
    for (size_t nEnd = osPath.find('/', 1);; nEnd = osPath.find('/', nEnd + 1))
    {
        const std::string osPart = osPath.substr(0, nEnd);
        VSIStatBufL sStat;
        if (VSIStatL(osPart.c_str(), &sStat) == 0 && !VSI_ISDIR(sStat.st_mode))
            return VSI_ISREG(sStat.st_mode) ? std::string() : osPart;
        if (nEnd == std::string::npos)
            return std::string();
    }
}

static std::string NonRegularSourceAt(const char *pszPath, int nDepth);

/* /vsisparse/'s XML names the files it reads (its regions' Filename,
 * relative to the XML where it says relative="1"): each is checked. */
static std::string SparseSources(const std::string &osXML, int nDepth)
{
    VSIStatBufL sStat;
    if (nDepth > 4 || VSIStatL(osXML.c_str(), &sStat) != 0 || !VSI_ISREG(sStat.st_mode) ||
        sStat.st_size > (1 << 20))
        return std::string();
    CPLXMLTreeCloser oTree(CPLParseXMLFile(osXML.c_str()));
    std::vector<const CPLXMLNode *> apsStack{oTree.get()};
    while (!apsStack.empty())
    {
        const CPLXMLNode *psNode = apsStack.back();
        apsStack.pop_back();
        for (; psNode; psNode = psNode->psNext)
        {
            if (psNode->eType != CXT_Element)
                continue;
            if (EQUAL(psNode->pszValue, "Filename"))
            {
                const char *pszName = CPLGetXMLValue(psNode, nullptr, "");
                const std::string osName =
                    CPLTestBool(CPLGetXMLValue(psNode, "relative", "0"))
                        ? std::string(CPLFormFilename(CPLGetPath(osXML.c_str()), pszName,
                                                      nullptr))
                        : std::string(pszName);
                const std::string osFound = NonRegularSourceAt(osName.c_str(), nDepth + 1);
                if (!osFound.empty())
                    return osFound;
            }
            else
                apsStack.push_back(psNode->psChild);
        }
    }
    return std::string();
}

static std::string NonRegularSourceAt(const char *pszPath, int nDepth)
{
    const std::string osName = pszPath ? pszPath : "";
    if (CPLString(osName).ifind("/vsistdin") != std::string::npos)
        return "/vsistdin/";
    // the name whole, and each of its pieces between the separators of
    // GDAL's prefixes and wrappers (a driver's NAME:...:path, vrt://path?,
    // /vsisubfile/o_n,path, /vsizip/{...} at any depth): any of them that is
    // a path of the OS (an audit hung opens on /vsisubfile/0_0,fifo; its
    // review on GTIFF_DIR:1:fifo, vrt://fifo and nested braces)
    // vrt://path?options wraps a path too: its prefix goes (vrt://fifo,
    // vrt:///vsigzip/fifo hung until the second review)
    std::string osBare = osName;
    for (size_t nAt; (nAt = CPLString(osBare).ifind("vrt://")) != std::string::npos;)
        osBare.erase(nAt, 6);
    std::vector<std::string> aosPieces{osName, osBare};
    for (size_t nStart = 0, nEnd;; nStart = nEnd + 1)
    {
        nEnd = osBare.find_first_of(":,{}?\"", nStart);
        // (not a URL's //host/path, after its scheme's ':')
        if (osBare.compare(nStart, 2, "//") != 0)
            aosPieces.push_back(osBare.substr(nStart, nEnd - nStart));
        if (nEnd == std::string::npos)
            break;
    }
    for (std::string osRest : aosPieces)
    {
        // GDAL's in-process wrappers, outermost first: each reads the file
        // named after it
        for (bool bWrapped = true; bWrapped;)
        {
            bWrapped = false;
            for (const char *pszWrapper :
                 {"/vsigzip/", "/vsizip/", "/vsitar/", "/vsisubfile/", "/vsisparse/"})
                if (STARTS_WITH_CI(osRest.c_str(), pszWrapper))
                {
                    if (EQUAL(pszWrapper, "/vsisparse/"))
                    {
                        const std::string osFound =
                            SparseSources(osRest.substr(strlen(pszWrapper)), nDepth);
                        if (!osFound.empty())
                            return osFound;
                    }
                    osRest.erase(0, strlen(pszWrapper));
                    bWrapped = true;
                }
        }
        if (STARTS_WITH(osRest.c_str(), "/vsi"))
            continue; // a URL, an in-memory file: no open that waits
        const std::string osFound = NonRegularPrefix(osRest);
        if (!osFound.empty())
            return osFound;
    }
    return std::string();
}

std::string NonRegularSource(const char *pszPath)
{
    return NonRegularSourceAt(pszPath, 0);
}

std::string RefusedDEMName(const char *pszDEM, const char *pszWhat, bool bFromFile)
{
    // anywhere in the name: vrt://MEM:::... opened it too (the review)
    if (CPLString(pszDEM).ifind("MEM:::") != std::string::npos &&
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

bool IsStdinName(const std::string &osName)
{
    // with GDAL's options too (/vsistdin?buffer_limit=-1: session 58's review
    // found an atlas's SHADOWS=all entry shared by whatever DEM came in), and
    // behind other handlers (/vsigzip//vsistdin/)
    size_t nAt = 0;
    while (osName.compare(nAt, 9, "/vsistdin") != 0)
    {
        // a chain of handlers' prefixes only: /vsiNAME/ (a path's folder
        // named vsistdin is a file's)
        if (osName.compare(nAt, 4, "/vsi") != 0)
            return false;
        const size_t nEnd = osName.find('/', nAt + 4);
        if (nEnd == std::string::npos)
            return false;
        for (size_t i = nAt + 4; i < nEnd; i++)
            if (!isalnum(static_cast<unsigned char>(osName[i])) && osName[i] != '_')
                return false;
        nAt = nEnd + 1;
    }
    // the stream itself (a file in it, /vsitar//vsistdin/x.tif, is not
    // read through a copy: GDAL's handlers seek in the archive)
    const std::string osRest = osName.substr(nAt + 9);
    return osRest.empty() || osRest == "/" || osRest[0] == '?' || osRest.compare(0, 2, "/?") == 0;
}

} // namespace tsd
