/*
 * tsd_register.cpp - GDALRegister_TERRASHADE: the driver's entry point. It
 * declares the driver's capabilities, its open options (from the option
 * table) and TERRASHADE_PRODUCTS (from the product table, for the QGIS
 * provider), and sends each name to its kind of dataset: TERRASHADE:...
 * connection strings to a product of a DEM (tsd_dataset.cpp), files with
 * the atlas magic to a far-shadow atlas (tsd_atlas_dataset.cpp).
 */
#include <cerrno>
#include <cstdlib>

#include "cpl_string.h"
#include "gdal_priv.h"

#include "tsd_connstr.h"
#include "tsd_gdal.h"
#include "tsd_entry_state.h"
#include "tsd_options.h"
#include "tsd_products.h"

namespace
{

int IdentifyAny(GDALOpenInfo *poOpenInfo)
{
    tsd::EntryState oEntry;
    return tsd::IdentifyProduct(poOpenInfo) || tsd::IdentifyAtlas(poOpenInfo);
}

GDALDataset *OpenAny(GDALOpenInfo *poOpenInfo)
{
    tsd::EntryState oEntry;
    if (tsd::IdentifyProduct(poOpenInfo))
        return tsd::OpenProduct(poOpenInfo);
    if (!tsd::IdentifyAtlas(poOpenInfo))
        return nullptr;
    return tsd::OpenAtlas(poOpenInfo);
}

/* Delete, rename and copy. A connection string names a product computed
 * from a DEM, not a file; GDAL's default (the files of the opened dataset,
 * which are the DEM's for the auxiliary file's sake) would delete, move or
 * copy the DEM itself, even through QuietDelete when a write is pointed at
 * a connection string. So they are refused; an atlas is a file of its own,
 * handled as GDAL's default handles it. */
bool IsConnection(const char *pszName)
{
    return STARTS_WITH_CI(pszName, TSD_PREFIX);
}

CPLErr RefuseConnection(const char *pszWhat, const char *pszName)
{
    CPLError(CE_Failure, CPLE_NotSupported,
             "TERRASHADE: cannot %s '%s': a connection string names a product computed "
             "from a DEM, not a file of its own; the DEM is left as it is (%s it by its "
             "own name if that is what you mean). A product is read-only: its nodata, "
             "unit and colour are set on a dataset opened read-only (gdal_edit.py -ro, "
             "osgeo.gdal's SetNoDataValue); rasterio's mode 'r+' writes a copy over it "
             "on closing, which is refused so",
             pszWhat, pszName, pszWhat);
    return CE_Failure;
}

/* The files of the atlas pszName: those it lists where it opens, else,
 * where it has the atlas magic but does not open (a damaged or truncated
 * one: the very file a user wants gone, which could be neither deleted nor
 * renamed), itself and its .aux.xml; NULL with the open's error. */
char **AtlasFiles(const char *pszName)
{
    const char *const apszDrivers[] = {tsd::DRIVER, nullptr};
    CPLPushErrorHandler(CPLQuietErrorHandler);
    GDALDatasetH hDS =
        GDALOpenEx(pszName, GDAL_OF_RASTER, apszDrivers, nullptr, nullptr);
    CPLPopErrorHandler();
    if (hDS)
    {
        char **papszFiles = GDALGetFileList(hDS);
        GDALClose(hDS);
        return papszFiles;
    }
    GDALOpenInfo oInfo(pszName, GA_ReadOnly);
    if (!tsd::IdentifyAtlas(&oInfo))
    {
        // not an atlas at all: the open's own error
        GDALClose(GDALOpenEx(pszName, GDAL_OF_RASTER | GDAL_OF_VERBOSE_ERROR, apszDrivers,
                             nullptr, nullptr));
        return nullptr;
    }
    CPLErrorReset(); // (the quiet open's error is no failure of the caller's)
    CPLDebug(tsd::DRIVER, "%s: a damaged atlas, handled as its file", pszName);
    CPLStringList aosFiles;
    aosFiles.AddString(pszName);
    VSIStatBufL sStat;
    const std::string osAux = std::string(pszName) + ".aux.xml";
    if (VSIStatL(osAux.c_str(), &sStat) == 0)
        aosFiles.AddString(osAux.c_str());
    return aosFiles.StealList();
}

CPLErr DeleteAny(const char *pszName)
{
    tsd::EntryState oEntry;
    if (IsConnection(pszName))
        return RefuseConnection("delete", pszName);
    char **papszFiles = AtlasFiles(pszName);
    if (!papszFiles)
        return CE_Failure;
    CPLErr eErr = CE_None;
    for (int i = 0; papszFiles && papszFiles[i]; i++)
        if (VSIUnlink(papszFiles[i]) != 0)
        {
            CPLError(CE_Failure, CPLE_AppDefined, "TERRASHADE: cannot delete '%s': %s",
                     papszFiles[i], VSIStrerror(errno));
            eErr = CE_Failure;
        }
    CSLDestroy(papszFiles);
    return eErr;
}

CPLErr RenameAny(const char *pszNewName, const char *pszOldName)
{
    tsd::EntryState oEntry;
    if (IsConnection(pszOldName) || IsConnection(pszNewName))
        return RefuseConnection("rename", IsConnection(pszOldName) ? pszOldName : pszNewName);
    // as GDAL's DefaultRename, from AtlasFiles (a damaged atlas too)
    char **papszOld = AtlasFiles(pszOldName);
    if (!papszOld)
        return CE_Failure;
    char **papszNew = CPLCorrespondingPaths(pszOldName, pszNewName, papszOld);
    CPLErr eErr = papszNew ? CE_None : CE_Failure;
    for (int i = 0; papszNew && papszOld[i]; i++)
        if (CPLMoveFile(papszNew[i], papszOld[i]) != 0)
        {
            CPLError(CE_Failure, CPLE_AppDefined, "TERRASHADE: cannot rename '%s' to '%s': %s",
                     papszOld[i], papszNew[i], VSIStrerror(errno));
            eErr = CE_Failure;
            break;
        }
    CSLDestroy(papszOld);
    CSLDestroy(papszNew);
    return eErr;
}

CPLErr CopyFilesAny(const char *pszNewName, const char *pszOldName)
{
    tsd::EntryState oEntry;
    if (IsConnection(pszOldName) || IsConnection(pszNewName))
        return RefuseConnection("copy", IsConnection(pszOldName) ? pszOldName : pszNewName);
    return GDALDriver::DefaultCopyFiles(pszNewName, pszOldName);
}

GDALDataset *CreateCopyAny(const char *pszFilename, GDALDataset *poSrcDS, int bStrict,
                           char **papszOptions, GDALProgressFunc pfnProgress,
                           void *pProgressData)
{
    tsd::EntryState oEntry;
    return tsd::CreateAtlasCopy(pszFilename, poSrcDS, bStrict, papszOptions, pfnProgress,
                                pProgressData);
}

/* Set a driver item to a malloc'ed string (NULL: out of memory, not set). */
void SetOwnedItem(GDALDriver *poDriver, const char *pszKey, char *pszValue)
{
    if (pszValue)
        poDriver->SetMetadataItem(pszKey, pszValue);
    free(pszValue);
}

} // namespace

extern "C" void __attribute__((visibility("default"))) GDALRegister_TERRASHADE();

void GDALRegister_TERRASHADE()
{
    if (!GDAL_CHECK_VERSION("TERRASHADE driver"))
        return;
    if (GDALGetDriverByName(tsd::DRIVER) != nullptr)
        return;
    tsd::EntryState oEntry; /* the option list's numbers */
    GDALDriver *poDriver = new GDALDriver();
    poDriver->SetDescription(tsd::DRIVER);
    poDriver->SetMetadataItem(GDAL_DCAP_RASTER, "YES");
    poDriver->SetMetadataItem(GDAL_DMD_LONGNAME,
                              "terrashade: shaded relief with cast shadows, "
                              "horizons, sky-view factor");
    /* (relative, as GDAL's own drivers' topics are: the source tree's) */
    poDriver->SetMetadataItem(GDAL_DMD_HELPTOPIC, "docs/driver.md");
    poDriver->SetMetadataItem(GDAL_DCAP_VIRTUALIO, "YES");
    poDriver->SetMetadataItem(GDAL_DCAP_CREATECOPY, "YES");
    poDriver->SetMetadataItem(GDAL_DMD_EXTENSION, "tsa");
    poDriver->SetMetadataItem(GDAL_DMD_CREATIONDATATYPES, "Byte");
    poDriver->SetMetadataItem(GDAL_DMD_CONNECTION_PREFIX, TSD_PREFIX);
    SetOwnedItem(poDriver, GDAL_DMD_OPENOPTIONLIST, tsd_options_xml());
    SetOwnedItem(poDriver, "TERRASHADE_PRODUCTS", tsd_products_xml());
    poDriver->pfnIdentify = IdentifyAny;
    poDriver->pfnOpen = OpenAny;
    poDriver->pfnCreateCopy = CreateCopyAny;
    poDriver->pfnDelete = DeleteAny;
    poDriver->pfnRename = RenameAny;
    poDriver->pfnCopyFiles = CopyFilesAny;
    GetGDALDriverManager()->RegisterDriver(poDriver);
}
