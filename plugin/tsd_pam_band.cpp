/*
 * tsd_pam_band.cpp - a band's nodata value, unit and colour: the user's
 * (through PAM) first, the product's own otherwise (tsd_pam_band.h).
 *
 * PAM keeps them in the .aux.xml of the DEM (a product: one <Subdataset>
 * per DEM and set of options, tsd_dataset_metadata.cpp) or of the atlas, so
 * a value set on one product never reaches another product, other options
 * or the DEM itself. PAM cannot keep a cleared unit or colour, nor a
 * deleted nodata value: clearing one gives back the product's own.
 */
#include "tsd_pam_band.h"

#include "cpl_minixml.h"
#include "cpl_string.h"

#include "tsd_gdal.h"

namespace tsd
{

double TSPamBand::GetNoDataValue(int *pbSuccess)
{
    if (pbSuccess)
        *pbSuccess = TRUE; // every product has one
    const GDALRasterBandPamInfo *psPamInfo = UserPam();
    if (psPamInfo && psPamInfo->bNoDataValueSet)
        return psPamInfo->dfNoDataValue;
    return OwnNoData();
}

const char *TSPamBand::GetUnitType()
{
    const GDALRasterBandPamInfo *psPamInfo = UserPam();
    if (psPamInfo && psPamInfo->pszUnitType)
        return psPamInfo->pszUnitType;
    return OwnUnit();
}

GDALColorInterp TSPamBand::GetColorInterpretation()
{
    const GDALRasterBandPamInfo *psPamInfo = UserPam();
    if (psPamInfo && psPamInfo->eColorInterp != GCI_Undefined)
        return psPamInfo->eColorInterp;
    return OwnColor();
}

double TSPamBand::GetOffset(int *pbSuccess)
{
    const GDALRasterBandPamInfo *psPamInfo = UserPam();
    const bool bSet = psPamInfo && psPamInfo->bOffsetSet;
    if (pbSuccess)
        *pbSuccess = bSet;
    return bSet ? psPamInfo->dfOffset : 0.0;
}

double TSPamBand::GetScale(int *pbSuccess)
{
    const GDALRasterBandPamInfo *psPamInfo = UserPam();
    const bool bSet = psPamInfo && psPamInfo->bScaleSet;
    if (pbSuccess)
        *pbSuccess = bSet;
    return bSet ? psPamInfo->dfScale : 1.0;
}

/* Whether what the user sets on this band is reported; if not, say why
 * and where to set it (GDAL's PAM would take it and report nothing). */
bool TSPamBand::Accepts(const char *pszWhat)
{
    const char *pszWhy = NotHere();
    if (!pszWhy)
        return true;
    Fail(CPLE_NotSupported, CPLSPrintf("%s: the %s of band %d cannot be changed here: %s",
                                       poDS ? poDS->GetDescription() : "", pszWhat, nBand,
                                       pszWhy));
    return false;
}

CPLErr TSPamBand::SetNoDataValue(double dfValue)
{
    return Accepts("nodata value") ? GDALPamRasterBand::SetNoDataValue(dfValue) : CE_Failure;
}

CPLErr TSPamBand::SetUnitType(const char *pszUnit)
{
    return Accepts("unit") ? GDALPamRasterBand::SetUnitType(pszUnit) : CE_Failure;
}

CPLErr TSPamBand::SetColorInterpretation(GDALColorInterp eColor)
{
    return Accepts("colour interpretation") ? GDALPamRasterBand::SetColorInterpretation(eColor)
                                            : CE_Failure;
}

CPLErr TSPamBand::SetOffset(double dfOffset)
{
    return Accepts("offset") ? GDALPamRasterBand::SetOffset(dfOffset) : CE_Failure;
}

CPLErr TSPamBand::SetScale(double dfScale)
{
    return Accepts("scale") ? GDALPamRasterBand::SetScale(dfScale) : CE_Failure;
}

CPLErr TSPamBand::DeleteNoDataValue()
{
    if (!Accepts("nodata value"))
        return CE_Failure;
    const GDALRasterBandPamInfo *psPamInfo = GetPamInfo();
    if (psPamInfo && psPamInfo->bNoDataValueSet)
        return GDALPamRasterBand::DeleteNoDataValue();
    Fail(CPLE_NotSupported,
         CPLSPrintf("%s: band %d's nodata value is the product's own, on the cells it has "
                    "no value for, and cannot be removed (only one set with SetNoDataValue "
                    "or gdal_edit.py -a_nodata can); gdal_translate -a_nodata none writes a "
                    "copy without it",
                    poDS ? poDS->GetDescription() : "", nBand));
    return CE_Failure;
}

bool TSPamBand::DropSavedStatistics()
{
    bool bDropped = false;
    char **papszMD = CSLDuplicate(GDALPamRasterBand::GetMetadata());
    for (char **ppsz = papszMD; ppsz && *ppsz; ppsz++)
    {
        char *pszKey = nullptr;
        CPLParseNameValue(*ppsz, &pszKey);
        if (pszKey && STARTS_WITH_CI(pszKey, "STATISTICS_"))
        {
            GDALPamRasterBand::SetMetadataItem(pszKey, nullptr); // (marks PAM dirty)
            bDropped = true;
        }
        CPLFree(pszKey);
    }
    CSLDestroy(papszMD);
    if (psPam && psPam->psSavedHistograms)
    {
        CPLDestroyXMLNode(psPam->psSavedHistograms);
        psPam->psSavedHistograms = nullptr;
        MarkPamDirty();
        bDropped = true;
    }
    return bDropped;
}

constexpr const char *PAM_STAMP_ITEM = "SOURCE_FILES";
constexpr const char *PAM_STAMP_DOMAIN = "TERRASHADE_PAM";

void StampPamEntry(GDALPamDataset *poDS, const std::string &osStamp)
{
    if (!osStamp.empty() && poDS->GetRasterCount() > 0)
        poDS->GetRasterBand(1)->SetMetadataItem(PAM_STAMP_ITEM, osStamp.c_str(),
                                                PAM_STAMP_DOMAIN);
}

bool DropStaleStatistics(GDALPamDataset *poDS, const std::string &osStamp)
{
    if (poDS->GetRasterCount() < 1)
        return false;
    const char *pszSaved =
        poDS->GetRasterBand(1)->GetMetadataItem(PAM_STAMP_ITEM, PAM_STAMP_DOMAIN);
    if (pszSaved && osStamp == pszSaved)
        return false;
    bool bDropped = false;
    for (int i = 1; i <= poDS->GetRasterCount(); i++)
        bDropped = static_cast<TSPamBand *>(poDS->GetRasterBand(i))->DropSavedStatistics() ||
                   bDropped;
    if (bDropped)
        CPLDebug("TERRASHADE", "%s: statistics saved for other contents of its files dropped "
                 "(saved for '%s', now '%s')",
                 poDS->GetDescription(), pszSaved ? pszSaved : "(no stamp)", osStamp.c_str());
    return bDropped;
}

} // namespace tsd
