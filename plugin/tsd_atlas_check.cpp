/*
 * tsd_atlas_check.cpp - what a far-shadow atlas must be (tsd_atlas_check.h):
 * its metadata validated as the options of PRODUCT=farshadow, the source of
 * a new atlas, a DEM that is not an atlas.
 */
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "cpl_vsi.h"
#include "ogr_spatialref.h"

#include "shadow_atlas.h"
#include "tsd_atlas_check.h"
#include "tsd_gdal.h"

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

/* The physical absolute path of an existing file or folder (symbolic
 * links, . and .. resolved), or "" (none, or a GDAL virtual path). */
static std::string Physical(const std::string &osPath)
{
    if (osPath.empty() || STARTS_WITH(osPath.c_str(), "/vsi"))
        return std::string();
    char *pszReal = realpath(osPath.c_str(), nullptr);
    const std::string osReal = pszReal ? pszReal : "";
    free(pszReal);
    return osReal;
}

std::string AtlasSourceDEM(const char *pszAtlas, const std::string &osDEM)
{
    if (osDEM.empty() || !CPLIsFilenameRelative(osDEM.c_str()))
        return osDEM;
    // the atlas's folder's, as a path from here (absolute: also what its
    // metadata shows, so that a copy of it elsewhere still finds the DEM)
    const std::string osNear =
        Physical(CPLFormFilename(CPLGetPath(pszAtlas), osDEM.c_str(), nullptr));
    return osNear.empty() ? osDEM : osNear;
}

/* target as a path relative to the folder base (both physical and
 * absolute), with ../ where it lies outside (CPLExtractRelativePath gives
 * up there). */
static std::string RelativeTo(const std::string &osBase, const std::string &osTarget)
{
    const CPLStringList aosB(CSLTokenizeString2(osBase.c_str(), "/", 0));
    const CPLStringList aosT(CSLTokenizeString2(osTarget.c_str(), "/", 0));
    int n = 0;
    while (n < aosB.size() && n < aosT.size() - 1 && strcmp(aosB[n], aosT[n]) == 0)
        n++;
    std::string osRel;
    for (int i = n; i < aosB.size(); i++)
        osRel += "../";
    for (int i = n; i < aosT.size(); i++)
        osRel += std::string(aosT[i]) + (i + 1 < aosT.size() ? "/" : "");
    return osRel;
}

std::string AtlasSourceDEMToWrite(const char *pszAtlas, const std::string &osDEM)
{
    // (a name of another driver, GTIFF_DIR:1:x.tif, or a virtual path: as
    // it is; an absolute path given: as it is)
    if (osDEM.empty() || !CPLIsFilenameRelative(osDEM.c_str()))
        return osDEM;
    const std::string osDEMReal = Physical(osDEM);
    if (osDEMReal.empty())
        return osDEM;
    // the atlas's folder exists (the atlas is written into it); physical
    // paths both, so that links, . and .. count as the file system has them
    const std::string osDirReal = Physical(CPLGetPath(pszAtlas)[0] ? CPLGetPath(pszAtlas) : ".");
    if (osDirReal.empty() || osDirReal[0] != '/' || osDEMReal[0] != '/')
        return osDEMReal; // (an atlas on /vsimem/, /vsis3/...: the DEM's absolute path)
    return RelativeTo(osDirReal, osDEMReal);
}

std::string CheckAtlasDEM(GDALDataset *poDEM, const std::string &osDEM, bool bGiven, int W,
                          int H, bool bHasGT, const double *padfGT,
                          const OGRSpatialReference *poSRS)
{
    const char *pszWhich = bGiven ? "" : " (the atlas's SOURCE_DEM)";
    if (poDEM->GetRasterXSize() != W || poDEM->GetRasterYSize() != H)
        return CPLSPrintf("SHADOWS=all: the DEM '%s'%s (%d x %d) does not match the %d x %d "
                          "atlas", osDEM.c_str(), pszWhich, poDEM->GetRasterXSize(),
                          poDEM->GetRasterYSize(), W, H);
    double adfGT[6];
    if (bHasGT && poDEM->GetGeoTransform(adfGT) == CE_None)
    {
        // the same geotransform: a product keeps its DEM's, rows' order
        // included (a flipped copy would lay the near shadows the other way
        // up), within a millionth of a cell (rotation terms as
        // tsd_cells_compute accepts them)
        const double dx = std::fabs(padfGT[1]), dy = std::fabs(padfGT[5]);
        const double tol = 1e-6;
        const bool bSame = std::fabs(adfGT[0] - padfGT[0]) <= tol * dx &&
                           std::fabs(adfGT[3] - padfGT[3]) <= tol * dy &&
                           std::fabs(adfGT[1] - padfGT[1]) <= tol * dx &&
                           std::fabs(adfGT[5] - padfGT[5]) <= tol * dy &&
                           std::fabs(adfGT[2] - padfGT[2]) <= tol * dx &&
                           std::fabs(adfGT[4] - padfGT[4]) <= tol * dy;
        if (!bSame)
            return CPLSPrintf("SHADOWS=all: the DEM '%s'%s does not lie where the atlas does "
                              "(its geotransform %.10g, %.10g, %.10g, %.10g, %.10g, %.10g "
                              "against the atlas's %.10g, %.10g, %.10g, %.10g, %.10g, %.10g): "
                              "name the DEM the atlas was made from with DEM=...",
                              osDEM.c_str(), pszWhich, adfGT[0], adfGT[1], adfGT[2], adfGT[3],
                              adfGT[4], adfGT[5], padfGT[0], padfGT[1], padfGT[2], padfGT[3],
                              padfGT[4], padfGT[5]);
    }
    const OGRSpatialReference *poDEMSRS = poDEM->GetSpatialRef();
    // their ground: an atlas keeps no vertical CRS (a product's is the
    // DEM's without it since session 58, one written before keeps it), nor
    // its DEM's data axes (a VRT's "1,2,3")
    if (poSRS && !poSRS->IsEmpty() && poDEMSRS && !poDEMSRS->IsEmpty())
    {
        const OGRSpatialReference oAtlas = GroundSRS(*poSRS), oDEM = GroundSRS(*poDEMSRS);
        const char *const apszIgnoreAxes[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES",
                                              nullptr};
        if (!oAtlas.IsSame(&oDEM, apszIgnoreAxes))
            return CPLSPrintf("SHADOWS=all: the DEM '%s'%s is in another CRS (%s) than the "
                              "atlas (%s): name the DEM the atlas was made from with DEM=...",
                              osDEM.c_str(), pszWhich, poDEMSRS->GetName(), poSRS->GetName());
    }
    return std::string();
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
    const char *pszShadows = poSrcDS->GetMetadataItem("SHADOWS");
    if (pszShadows && EQUAL(pszShadows, "all"))
        return "the source holds far and near shadows (an atlas opened with SHADOWS=all, or "
               "a copy of one): an atlas stores the far shadows alone; write it from the "
               "atlas opened without SHADOWS=all, or from PRODUCT=farshadow";
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
