/* What the driver says about a DEM and a sun that are likely not what the
 * user meant: refusals at open (a band that is not heights) and warnings
 * (no geotransform, heights of unknown unit on a grid in feet, a
 * MAX_DISTANCE shorter than a cell, a DEM too wide for one sun). */
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cpl_error.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

#include "tsd_connstr.h"
#include "tsd_dataset.h"
#include "tsd_dem_check.h"
#include "tsd_gdal.h"

namespace tsd
{

/* A product written by this driver: a known PRODUCT with its SOURCE_DEM in
 * its metadata. */
static bool HoldsAProduct(GDALDataset *poDS, std::string *posWhat)
{
    const char *pszSource = poDS->GetMetadataItem("SOURCE_DEM");
    const char *pszProduct = poDS->GetMetadataItem("PRODUCT");
    if (!(pszSource && pszProduct && tsd_product_find(pszProduct) >= 0))
        return false;
    *posWhat = CPLSPrintf("PRODUCT=%s of %s", pszProduct, pszSource);
    return true;
}

/* A live TERRASHADE: string among a VRT's sources (gdalbuildvrt of one):
 * its XML says so, without opening anything. A scan of the text, not a
 * parse: a mosaic of ten thousand tiles has megabytes of it. (Hand-written
 * XML can fool it: a source in a comment is taken, one in CDATA or with an
 * escaped prefix is not.) */
static std::string ProductStringSource(const char *pszXML)
{
    static const char szTag[] = "<SourceFilename";
    for (const char *p = strstr(pszXML, szTag); p; p = strstr(p + 1, szTag))
    {
        const char *pszName = strchr(p, '>');
        if (!pszName)
            break;
        pszName++;
        if (EQUALN(pszName, DRIVER, strlen(DRIVER)) && pszName[strlen(DRIVER)] == ':')
            return std::string(pszName, strcspn(pszName, "<"));
    }
    return std::string();
}

/* A mosaic (gdalbuildvrt) keeps no metadata of its sources: its sources
 * say whether it mosaics products. Four files only, spread from its first
 * to its last, each opened, so that a VRT of ten thousand tiles opens as
 * fast as it did. */
static std::string ProductInMosaic(GDALDataset *poDEM, const std::string &osDEM)
{
    if (!poDEM->GetDriver() || !EQUAL(poDEM->GetDriver()->GetDescription(), "VRT"))
        return std::string();
    // quiet, and the caller's last error kept: a source that does not open
    // here is the VRT's reads' to report
    CPLErrorStateBackuper oState;
    CPLErrorHandlerPusher oQuiet(CPLQuietErrorHandler);
    // the .vrt's own text where it is a file (serialising a mosaic of ten
    // thousand tiles would double the time of its open), else its XML
    GByte *pabyText = nullptr;
    std::string osString;
    if (VSIIngestFile(nullptr, poDEM->GetDescription(), &pabyText, nullptr, 256 << 20))
        osString = ProductStringSource(reinterpret_cast<const char *>(pabyText));
    else if (char **papszXML = poDEM->GetMetadata("xml:VRT"))
        osString = papszXML[0] ? ProductStringSource(papszXML[0]) : std::string();
    VSIFree(pabyText);
    if (!osString.empty())
        return CPLSPrintf("the DEM '%s' mosaics TERRASHADE products (its source '%s' is a "
                          "product), not heights: mosaic the DEMs themselves",
                          osDEM.c_str(), osString.c_str());
    const CPLStringList aosAll(poDEM->GetFileList());
    std::vector<const char *> apszTiles;
    for (int i = 0; i < aosAll.size(); i++)
    {
        const char *pszExt = CPLGetExtension(aosAll[i]);
        if (!(EQUAL(pszExt, "vrt") || EQUAL(pszExt, "xml") || EQUAL(pszExt, "ovr") ||
              EQUAL(aosAll[i], poDEM->GetDescription())))
            apszTiles.push_back(aosAll[i]);
    }
    const size_t nTiles = apszTiles.size(), nSample = std::min<size_t>(nTiles, 4);
    std::string osFound;
    for (size_t k = 0; k < nSample && osFound.empty(); k++)
    {
        const char *pszFile = apszTiles[nSample > 1 ? k * (nTiles - 1) / (nSample - 1) : 0];
        GDALDataset *poSrc = GDALDataset::Open(pszFile, GDAL_OF_RASTER);
        std::string osWhat;
        if (poSrc && HoldsAProduct(poSrc, &osWhat))
            osFound = CPLSPrintf("the DEM '%s' mosaics TERRASHADE products (its source '%s' "
                                 "is %s, in its metadata), not heights: mosaic the DEMs "
                                 "themselves",
                                 osDEM.c_str(), pszFile, osWhat.c_str());
        if (poSrc)
            poSrc->ReleaseRef();
    }
    return osFound;
}

std::string DEMNameHint(const std::string &osDEM)
{
    VSIStatBufL sStat;
    // a file whose name is itself a connection string: opened as one
    if (tsd_connstr_matches(osDEM.c_str()) && VSIStatL(osDEM.c_str(), &sStat) == 0)
        return CPLSPrintf(" (a file of that name exists, but a name starting TERRASHADE: is "
                          "read as another product: name the file ./%s)",
                          osDEM.c_str());
    if (osDEM.empty() || STARTS_WITH(osDEM.c_str(), "/vsi") ||
        !CPLIsFilenameRelative(osDEM.c_str()) || strchr(osDEM.c_str(), ':'))
        return std::string();
    char *pszCwd = CPLGetCurrentDir();
    const std::string osHint =
        pszCwd ? CPLSPrintf(" (a relative name, looked for from the working directory %s)", pszCwd)
               : std::string();
    CPLFree(pszCwd);
    return osHint;
}

std::string ProductAsDEM(GDALDataset *poDEM, const std::string &osDEM)
{
    // a product of this driver (TERRASHADE:TERRASHADE:dem.tif): its shading
    // was taken as heights, silently
    const char *pszSource = poDEM->GetMetadataItem("SOURCE_DEM");
    if (poDEM->GetDriver() && EQUAL(poDEM->GetDriver()->GetDescription(), DRIVER))
        return CPLSPrintf("the DEM '%s' is a TERRASHADE product, not a DEM: name the DEM "
                          "itself%s%s%s",
                          osDEM.c_str(), pszSource ? " (" : "", pszSource ? pszSource : "",
                          pszSource ? ")" : "");
    // a product written to a file (or a VRT of one) keeps its metadata: a
    // known PRODUCT with its SOURCE_DEM is a product, whatever its driver
    std::string osWhat;
    if (HoldsAProduct(poDEM, &osWhat))
        return CPLSPrintf("the DEM '%s' is a written TERRASHADE product (%s, in its "
                          "metadata), not a DEM: name the DEM itself",
                          osDEM.c_str(), osWhat.c_str());
    return ProductInMosaic(poDEM, osDEM);
}

std::string NotHeights(GDALDataset *poDEM, int nBand, const std::string &osDEM)
{
    GDALRasterBand *poBand = poDEM->GetRasterBand(nBand);
    // values GDAL would not hand over as they are: the real part alone, or
    // signed bytes as 0..255 (GDAL 3.6 has no Int8: -1 reads as 255)
    const GDALDataType eType = poBand->GetRasterDataType();
    if (GDALDataTypeIsComplex(eType))
        return CPLSPrintf("band %d of '%s' is complex (%s), not heights: choose the band that "
                          "holds heights (BAND), or, if its real part is the heights, write it "
                          "alone first (gdal_translate -ot Float32 '%s' heights.tif)",
                          nBand, osDEM.c_str(), GDALGetDataTypeName(eType), osDEM.c_str());
    const char *pszPixelType = poBand->GetMetadataItem("PIXELTYPE", "IMAGE_STRUCTURE");
    if (eType == GDT_Byte && pszPixelType && EQUAL(pszPixelType, "SIGNEDBYTE"))
        return CPLSPrintf("band %d of '%s' holds signed bytes (PIXELTYPE=SIGNEDBYTE), which "
                          "GDAL %s reads as 0..255 (-1 as 255, a cliff of 255 m between -1 "
                          "and 0): write them as Int16 first (gdal_calc.py -A '%s' "
                          "--type=Int16 --calc='A.astype(numpy.int16)-256*(A>127)' "
                          "--outfile=heights.tif)",
                          nBand, osDEM.c_str(), GDALVersionInfo("RELEASE_NAME"), osDEM.c_str());
    const GDALColorInterp eInterp = poBand->GetColorInterpretation();
    if (eInterp == GCI_Undefined || eInterp == GCI_GrayIndex)
        return std::string();
    const std::string osWhat = eInterp == GCI_PaletteIndex
                                   ? std::string("the class indices of a palette")
                                   : std::string("the ") +
                                         GDALGetColorInterpretationName(eInterp) +
                                         " channel of a colour image";
    return CPLSPrintf("band %d of '%s' holds %s, not heights: choose the band that holds "
                      "heights (BAND), or, if these values are heights, say so "
                      "(gdal_edit.py -colorinterp_%d gray '%s')",
                      nBand, osDEM.c_str(), osWhat.c_str(), nBand, osDEM.c_str());
}

void WarnNoGeoTransform(GDALDataset *poDEM, const std::string &osDEM)
{
    // georeferenced by control points or RPCs, it needs warping first
    const int nGCPs = poDEM->GetGCPCount();
    std::string osHow;
    if (nGCPs > 0)
        osHow = CPLSPrintf("; it is georeferenced by %d ground control points, which "
                           "terrashade does not follow: warp it to a north-up grid first "
                           "(gdalwarp dem.tif north_up.tif)",
                           nGCPs);
    else if (poDEM->GetMetadata("RPC") != nullptr)
        osHow = "; it is georeferenced by rational polynomial coefficients (RPC), which "
                "terrashade does not follow: warp it to a north-up grid first (gdalwarp -rpc "
                "dem.tif north_up.tif)";
    CPLError(CE_Warning, CPLE_AppDefined,
             "TERRASHADE: the DEM '%s' has no geotransform: its cells are taken as 1 x 1 "
             "metre, row 0 north%s",
             osDEM.c_str(), osHow.c_str());
}

void WarnHeightUnit(const tsd_cells &sCells, const OGRSpatialReference &oSRS,
                    const std::string &osDEM)
{
    if (sCells.kind != TSD_CRS_PROJECTED || std::fabs(sCells.unit_to_m - 1) < 1e-9)
        return;
    const char *pszUnit = nullptr;
    oSRS.GetLinearUnits(&pszUnit);
    CPLError(CE_Warning, CPLE_AppDefined,
             "TERRASHADE: the DEM '%s' is gridded in %s (its CRS), but nothing says its "
             "heights' unit: they are taken as metres. If they are in %s too, as on most "
             "such grids, give Z_FACTOR=%.10g or say so (gdal_edit.py -units '%s' '%s')",
             osDEM.c_str(), pszUnit ? pszUnit : "a unit other than metres",
             pszUnit ? pszUnit : "that unit", sCells.unit_to_m, pszUnit ? pszUnit : "ft",
             osDEM.c_str());
}

/* Distances that likely do not say what was meant. A MAX_DISTANCE shorter
 * than the DEM's cells (dfCell: its smallest side)
 * holds no other cell: no shadow or horizon but the cell's own slope. Most
 * often a distance meant in cells (RVT's radius is in pixels) or
 * kilometres. And METHOD=shm's shadow height map follows every occluder to
 * the DEM's edge: MAX_DISTANCE bounds its sky term and EDGE=nodata's reach
 * only (it shadowed a cell from 150 m away at MAX_DISTANCE=10 m, without a
 * word, until session 46). */
void TSDataset::WarnDistances(double dfCell, int W, int H)
{
    // PRODUCT=farshadow: a FAR_THRESHOLD as long as the DEM's longer side
    // (the default 512 on a smaller DEM) leaves the maps empty, but for
    // the diagonals' last cells (all 158 maps of jacksboro's day)
    if (tsd_product_takes(m_psProduct, tsd_option_find("FAR_THRESHOLD")) &&
        m_sOpts.far_threshold >= std::max(W, H))
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: FAR_THRESHOLD=%d cells is as long as the DEM's longer side "
                 "(%d x %d cells) or longer: few occluders if any lie that far from a cell, "
                 "so the maps are empty or nearly. Give a shorter one (e.g. "
                 "FAR_THRESHOLD=%d)",
                 m_sOpts.far_threshold, W, H, std::max(1, std::max(W, H) / 8));
    // every ray leaves the DEM somewhere: an all-nodata product, which
    // gdalinfo -stats then calls "no valid pixels" (an audit)
    // (METHOD=shadowmap refuses EDGE=nodata)
    if (tsd_options_edge(&m_sOpts) == TS_EDGE_NODATA && !(m_sOpts.max_distance > 0))
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: EDGE=nodata without MAX_DISTANCE makes nodata every cell that "
                 "casts a ray (all of them, but a day's steps with the sun down): it "
                 "leaves out the cells whose rays leave the DEM within MAX_DISTANCE, and "
                 "unbounded every ray leaves it. Give MAX_DISTANCE (e.g. the reach of the "
                 "terrain that matters), or EDGE=horizon or open");
    const bool bShm = m_sOpts.max_distance > 0 && m_sOpts.method == TSD_METHOD_SHM &&
                      tsd_product_takes(m_psProduct, tsd_option_find("METHOD"));
    if (bShm)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: METHOD=shm casts shadows from every occluder up to the DEM's "
                 "edge: MAX_DISTANCE=%g m bounds only %sthe reach of EDGE=nodata. "
                 "METHOD=exact casts them from within MAX_DISTANCE",
                 m_sOpts.max_distance,
                 tsd_product_takes(m_psProduct, tsd_option_find("SKY_WEIGHT"))
                     ? "its sky term (SKY_WEIGHT) and "
                     : "");
    // (under METHOD=shm the distance does not bound the shadows: said above)
    if (bShm || !(m_sOpts.max_distance > 0 && m_sOpts.max_distance < dfCell) ||
        !tsd_product_takes(m_psProduct, tsd_option_find("MAX_DISTANCE")))
        return;
    CPLError(CE_Warning, CPLE_AppDefined,
             "TERRASHADE: MAX_DISTANCE=%g m is shorter than the DEM's cells (%.4g m): no "
             "other cell lies within it, so only the slope of a cell's own surface there "
             "casts a shadow or raises a horizon. It is in metres: %g cells are %.4g m",
             m_sOpts.max_distance, dfCell, m_sOpts.max_distance,
             m_sOpts.max_distance * dfCell);
}

/* An option given for a product that does not use it does nothing: said,
 * where an audit found eleven such silent for svf alone (SUN_AZIMUTH,
 * STEP_MINUTES, FAR_THRESHOLD...) and farshadow's TILE_SIZE, beside
 * options refused for the same reason (tsd_options_check). */
void TSDataset::WarnUnusedOptions()
{
    char szList[1024];
    const int nUnused = tsd_options_unused(&m_sOpts, m_psProduct, szList, sizeof szList);
    if (nUnused > 0)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: PRODUCT=%s does not use %s: given, %s nothing here",
                 m_psProduct->name, szList, nUnused > 1 ? "they do" : "it does");
}

/* Degrees of arc from the DEM's centre beyond which SUN_POSITION=center warns. */
static const double SUN_REACH_WARN_DEG = 1.0;

/* A warning when the DEM is so wide that the sun computed once at its
 * centre (SUN_POSITION=center) is off by more than a degree at its edges,
 * with what to do about it. */
void TSDataset::WarnSunReach(int W, int H, OGRSpatialReferenceH hSRS, double dfLon,
                             double dfLat)
{
    double dfTurn = 0;
    const double dfReach =
        tsd_sites_reach(m_adfGT, W, H, hSRS, &m_sCells, dfLon, dfLat, &dfTurn);
    if (!(dfReach > SUN_REACH_WARN_DEG) && !(dfTurn > SUN_REACH_WARN_DEG))
        return;
    // per_cell where the product takes it and the options' own checks
    // accept it beside the others given (METHOD, LIGHT_RADIUS, ...)
    const int iSunPosition = tsd_option_find("SUN_POSITION");
    tsd_options sPerCell = m_sOpts;
    sPerCell.sun_position = TSD_SUN_PER_CELL;
    sPerCell.given |= 1ULL << iSunPosition;
    char szWhyNot[512];
    const bool bPerCell = tsd_product_takes(m_psProduct, iSunPosition) &&
                          tsd_options_check(&sPerCell, szWhyNot, sizeof szWhyNot) == 0;
    const char *pszDo = bPerCell ? "SUN_POSITION=per_cell computes the sun across the DEM"
                                 : "Crop the DEM to compute the sun nearer its cells";
    if (dfReach >= dfTurn)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: the DEM reaches %.1f degrees of arc from its centre, where the "
                 "sun is computed for all its cells (SUN_POSITION=center): at its edges the "
                 "sun's elevation and azimuth can be off by about as much. %s",
                 dfReach, pszDo);
    else // a geographic grid near a pole: its columns' meridians converge
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: the DEM's meridians turn by up to %.1f degrees against its "
                 "grid from its centre's (%.1f degrees of arc away), where the sun is "
                 "computed for all its cells (SUN_POSITION=center): at its edges the sun's "
                 "azimuth on the grid can be off by about as much. %s",
                 dfTurn, dfReach, pszDo);
}

/* Degrees by which a sweep's ground azimuth may turn on a geographic DEM's
 * rows before it is said. */
static const double SWEEP_TURN_WARN_DEG = 0.5;

/* A geographic DEM's sweeps keep their direction in cells, set at its
 * central row (core/line_geometry.c): on a row whose cells are k times as
 * wide, azimuth a is swept as atan(k tan a), turned by up to
 * atan(|k - 1| / (2 sqrt k)) (at tan a = 1 / sqrt k). Said where that
 * passes SWEEP_TURN_WARN_DEG on its northern or southern rows, with what
 * to do (METHOD=shadowmap takes each row's own width: not said). */
void TSDataset::WarnSweepTurn(int H)
{
    if (!m_sCells.cell_x_row || H < 3 || m_sOpts.method == TSD_METHOD_SHADOWMAP)
        return;
    const double dfCentre = m_sCells.cell_x_row[H / 2];
    double dfTurn = 0, dfChange = 0;
    for (const int y : {0, H - 1})
    {
        const double k = m_sCells.cell_x_row[y] / dfCentre;
        if (k > 0)
            dfTurn = std::max(dfTurn, atan(fabs(k - 1) / (2 * sqrt(k))) * 180 / M_PI);
        dfChange = std::max(dfChange, fabs(k - 1));
    }
    if (!(dfTurn > SWEEP_TURN_WARN_DEG))
        return;
    CPLError(CE_Warning, CPLE_AppDefined,
             "TERRASHADE: the DEM's rows span so many degrees of latitude that its cells' "
             "widths differ from its central row's by up to %.0f %%: its sweeps keep their "
             "direction in cells, taken there, so that on its northern and southern rows an "
             "azimuth is "
             "swept up to %.1f degrees turned toward or away from the meridian (at azimuths "
             "near 45 degrees; none at 0, 90, 180, 270). Horizons and cast shadows there turn "
             "as much; sky-view factor, openness and the day's integrals, which average "
             "over azimuths, change less. Cut the DEM into bands of latitude, or reproject "
             "it to a projected CRS (gdalwarp -t_srs, e.g. a UTM zone)",
             100 * dfChange, dfTurn);
}

/* EDGE=horizon's sea level beyond the edges above heights of grid g
 * (tsd_grid_below_sea_warning): once per DEM, whichever level computes
 * first (QGIS zoomed out reads only an overview). */
void TSDataset::WarnBelowSea(const ts_grid *g)
{
    char szWarning[512];
    std::atomic<bool> &bWarned = (m_poBase ? m_poBase : this)->m_bBelowSeaWarned;
    if (bWarned || tsd_options_edge(&m_sOpts) != TS_EDGE_HORIZON ||
        !tsd_grid_below_sea_warning(g, szWarning, sizeof szWarning) || bWarned.exchange(true))
        return;
    CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szWarning);
}

/* Voids wider than MAX_DISTANCE (tsd_grid_voids_warning), from the whole
 * DEM's grid (or an overview level's) or a chunk's (a run of voids cut by
 * the chunk's edge is at least as wide as it shows): once per DEM. A reprojected
 * DEM's collar, or a lake left nodata, put openness of up to 150 degrees
 * along its border, unsaid (EDGE=horizon and nodata did not apply there). */
void TSDataset::WarnVoids(const ts_grid *g)
{
    char szWarning[768];
    TSDataset *poBase = m_poBase ? m_poBase : this; // (an overview level's cells: in its)
    std::atomic<bool> &bWarned = poBase->m_bVoidsWarned;
    if (bWarned || !tsd_product_takes(m_psProduct, tsd_option_find("MAX_DISTANCE")) ||
        !tsd_grid_voids_warning(g, m_sOpts.max_distance,
                                static_cast<double>(poBase->nRasterXSize) / nRasterXSize,
                                static_cast<double>(poBase->nRasterYSize) / nRasterYSize,
                                szWarning, sizeof szWarning) ||
        bWarned.exchange(true))
        return;
    CPLError(CE_Warning, CPLE_AppDefined, "TERRASHADE: %s", szWarning);
}

} // namespace tsd
