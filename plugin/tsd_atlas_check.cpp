/*
 * tsd_atlas_check.cpp - what a far-shadow atlas must be (tsd_atlas_check.h):
 * its metadata validated as the options of PRODUCT=farshadow, the source of
 * a new atlas, a DEM that is not an atlas.
 */
#include <cmath>
#include <cstdlib>
#include <string>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

#include "shadow_atlas.h"
#include "tsd_atlas_check.h"

namespace tsd
{

/* The metadata's items that are options go through the option table, as a
 * dataset's options do; the others that matter are checked here. */
std::string CheckAtlasMetadata(const CPLStringList &aosMeta, int nMaps, tsd_options *psOpts)
{
    CPLStringList aosOpts;
    for (int i = 0; i < aosMeta.size(); i++)
    {
        char *pszKey = nullptr;
        CPLParseNameValue(aosMeta[i], &pszKey);
        if (pszKey && tsd_option_find(pszKey) >= 0 && !EQUAL(pszKey, "BACKEND"))
            aosOpts.AddString(aosMeta[i]);
        CPLFree(pszKey);
    }
    const char *pszProduct = aosMeta.FetchNameValue("PRODUCT");
    if (!pszProduct)
        return "PRODUCT is missing (an atlas holds the maps of PRODUCT=farshadow "
               "and says so)";
    if (!EQUAL(pszProduct, "farshadow")) // before the combination, which it decides
        return CPLSPrintf("PRODUCT must be farshadow, got '%s': an atlas holds the "
                          "far-shadow maps of a day", pszProduct);
    char szMsg[1024];
    tsd_options_defaults(psOpts);
    if (tsd_options_apply(psOpts, aosOpts.List(), szMsg, sizeof szMsg) != 0)
        return szMsg;
    if (tsd_options_band_count(psOpts) != nMaps)
        return CPLSPrintf("ATLAS_STEPS=%d, but there are %d map(s)", psOpts->atlas_steps,
                          nMaps);
    if (const char *pszOffset = aosMeta.FetchNameValue("UTC_OFFSET_MINUTES"))
    {
        char *pszEnd = nullptr;
        const long nOffset = strtol(pszOffset, &pszEnd, 10);
        if (pszEnd == pszOffset || *pszEnd || nOffset < -1439 || nOffset > 1439)
            return CPLSPrintf("UTC_OFFSET_MINUTES must be a whole number of minutes "
                              "between -1439 and 1439, got '%s'", pszOffset);
    }
    if (const char *pszFar = aosMeta.FetchNameValue("FAR_THRESHOLD_M"))
    {
        char *pszEnd = nullptr;
        const double dfFar = CPLStrtod(pszFar, &pszEnd);
        if (pszEnd == pszFar || *pszEnd || !(std::isfinite(dfFar) && dfFar > 0))
            return CPLSPrintf("FAR_THRESHOLD_M must be a distance in metres (> 0), got "
                              "'%s'", pszFar);
    }
    return std::string();
}

/* 1 if the file `pszName` is a far-shadow atlas (its magic). */
bool IsAtlasFile(const char *pszName)
{
    VSILFILE *fp = VSIFOpenL(pszName, "rb");
    if (!fp)
        return false;
    GByte abyHead[8] = {0};
    const size_t nRead = VSIFReadL(abyHead, 1, sizeof abyHead, fp);
    VSIFCloseL(fp);
    return ts_atlas_identify(abyHead, nRead) != 0;
}

/* The sentence for an atlas named as its own DEM. */
std::string AtlasAsDEM(const std::string &osDEM, bool bGiven)
{
    return CPLSPrintf("SHADOWS=all: the DEM '%s'%s is a far-shadow atlas (.tsa), not "
                      "a DEM: name the DEM the atlas was made from with the open option "
                      "DEM=...", osDEM.c_str(), bGiven ? "" : " (the atlas's SOURCE_DEM)");
}

std::string CheckAtlasSource(GDALDataset *poSrcDS)
{
    const int nBands = poSrcDS->GetRasterCount();
    for (int b = 1; b <= nBands; b++)
    {
        const GDALDataType eType = poSrcDS->GetRasterBand(b)->GetRasterDataType();
        if (GDALDataTypeIsComplex(eType))
            return CPLSPrintf("band %d of the source is complex (%s): an atlas stores the "
                              "binary far-shadow maps of PRODUCT=farshadow", b,
                              GDALGetDataTypeName(eType));
    }
    tsd_options sSrcOpts;
    const CPLStringList aosSrcMeta(CSLDuplicate(poSrcDS->GetMetadata()));
    const std::string osCause = CheckAtlasMetadata(aosSrcMeta, nBands, &sSrcOpts);
    if (!osCause.empty())
        return CPLSPrintf("the source is not a far-shadow product (an atlas stores the "
                          "maps of TERRASHADE:PRODUCT=farshadow,...:<dem>, or of a copy of "
                          "one): its metadata: %s", osCause.c_str());
    for (int b = 1; b <= nBands; b++)
        if (!poSrcDS->GetRasterBand(b)->GetMetadataItem("UNIX_TIME"))
            return CPLSPrintf("band %d of the source has no UNIX_TIME: every map of "
                              "PRODUCT=farshadow has its time", b);
    return std::string();
}

} // namespace tsd
