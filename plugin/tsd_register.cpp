/*
 * tsd_register.cpp - GDALRegister_TERRASHADE: the driver's entry point. It
 * declares the driver's capabilities, its open options (from the option
 * table) and TERRASHADE_PRODUCTS (from the product table, for the QGIS
 * provider), and sends each name to its kind of dataset: TERRASHADE:...
 * connection strings to a product of a DEM (tsd_dataset.cpp), files with
 * the atlas magic to a far-shadow atlas (tsd_atlas_dataset.cpp).
 */
#include <cstdlib>

#include "gdal_priv.h"

#include "tsd_connstr.h"
#include "tsd_gdal.h"
#include "tsd_options.h"
#include "tsd_products.h"

namespace
{

int IdentifyAny(GDALOpenInfo *poOpenInfo)
{
    return tsd::IdentifyProduct(poOpenInfo) || tsd::IdentifyAtlas(poOpenInfo);
}

GDALDataset *OpenAny(GDALOpenInfo *poOpenInfo)
{
    if (tsd::IdentifyProduct(poOpenInfo))
        return tsd::OpenProduct(poOpenInfo);
    if (!tsd::IdentifyAtlas(poOpenInfo))
        return nullptr;
    return tsd::OpenAtlas(poOpenInfo);
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
    poDriver->pfnCreateCopy = tsd::CreateAtlasCopy;
    GetGDALDriverManager()->RegisterDriver(poDriver);
}
