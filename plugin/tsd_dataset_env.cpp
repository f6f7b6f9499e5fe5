/*
 * tsd_dataset_env.cpp - the environment of a TERRASHADE:<dem> dataset
 * (ENV_MAP or SKY, tsd_compute_env.h), set up when the dataset opens so that
 * a bad map fails the open with its sentence: ENV_MAP is read through GDAL's
 * VSI into memory (so /vsimem/, /vsicurl/, /vsizip/... paths work), once
 * (the overview levels light with the dataset's), and decoded by the core's
 * OpenEXR reader. And its metadata.
 */
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cpl_conv.h"
#include "cpl_string.h"
#include "cpl_vsi.h"

#include "tsd_dataset.h"
#include "tsd_path_check.h"
#include "tsd_gdal.h"
#include "tsd_text.h"

namespace tsd
{

/* Larger files are refused: far beyond any map the reader accepts
 * (TS_ENV_MAX_PIXELS of float RGBA, uncompressed, is 1 GiB). */
constexpr vsi_l_offset MAX_MAP_BYTES = static_cast<vsi_l_offset>(2) << 30;

/* The first four bytes of every OpenEXR file (its magic number, 20000630
 * little-endian). */
constexpr GByte EXR_MAGIC[4] = {0x76, 0x2f, 0x31, 0x01};

/* Whether ENV_MAP names no pipe, device or standard input, with the
 * sentence in osError where it does: a pipe's open waits for a writer,
 * forever (an audit), and a device may too (a terminal), also inside
 * /vsigzip/ or /vsisubfile/ (a second audit). Asked before any stat, which
 * opens an archive to look inside it. */
static bool EnvMapIsAFile(const char *pszPath, std::string &osError)
{
    const std::string osSource = NonRegularSource(pszPath);
    if (osSource.empty())
        return true;
    osError = osSource == "/vsistdin/"
                  ? CPLSPrintf("ENV_MAP '%s' reads the standard input: give the file of an "
                               "OpenEXR map",
                               pszPath)
                  : CPLSPrintf("ENV_MAP '%s' reads '%s', which is not a regular file (a pipe, "
                               "a device...), not an OpenEXR file",
                               pszPath, osSource.c_str());
    return false;
}

/* The bytes of the file at pszPath (any GDAL path) into oBytes; false with
 * a sentence in osError. What does not start as an OpenEXR file does is
 * refused after four bytes, and a file larger than MAX_MAP_BYTES before
 * it is read where its size is known (else after MAX_MAP_BYTES). */
static bool ReadWholeFile(const char *pszPath, std::vector<GByte> &oBytes,
                          std::string &osError)
{
    if (!EnvMapIsAFile(pszPath, osError))
        return false;
    VSIStatBufL sStat;
    if (VSIStatExL(pszPath, &sStat, VSI_STAT_EXISTS_FLAG | VSI_STAT_NATURE_FLAG |
                                        VSI_STAT_SIZE_FLAG) != 0)
    {
        osError = CPLSPrintf("cannot open ENV_MAP '%s': no such file", pszPath);
        return false;
    }
    if (VSI_ISDIR(sStat.st_mode))
    {
        osError = CPLSPrintf("ENV_MAP '%s' is a directory, not an OpenEXR file", pszPath);
        return false;
    }
    const std::string osTooLarge =
        CPLSPrintf("ENV_MAP '%s' is larger than %d GiB: not an environment map this driver "
                   "reads",
                   pszPath, static_cast<int>(MAX_MAP_BYTES >> 30));
    if (VSI_ISREG(sStat.st_mode) && static_cast<vsi_l_offset>(sStat.st_size) > MAX_MAP_BYTES)
    {
        osError = osTooLarge;
        return false;
    }
    VSILFILE *fp = VSIFOpenL(pszPath, "rb");
    if (!fp)
    {
        osError = CPLSPrintf("cannot open ENV_MAP '%s': %s", pszPath, VSIStrerror(errno));
        return false;
    }
    // what does not start as OpenEXR does is refused after four bytes
    GByte abyMagic[sizeof EXR_MAGIC];
    if (VSIFReadL(abyMagic, 1, sizeof abyMagic, fp) != sizeof abyMagic ||
        memcmp(abyMagic, EXR_MAGIC, sizeof EXR_MAGIC) != 0)
    {
        VSIFCloseL(fp);
        osError = CPLSPrintf("ENV_MAP '%s' is not an OpenEXR file: it does not start with "
                             "OpenEXR's magic number (76 2f 31 01)",
                             pszPath);
        return false;
    }
    // read to the end, whatever the size the file system reports: until a
    // read gives nothing (GDAL 3.6's /vsizip/ and /vsigzip/ give short reads
    // without their end-of-file flag)
    constexpr size_t CHUNK = 1 << 20;
    size_t nUsed = sizeof EXR_MAGIC;
    bool bOk = true;
    for (;;)
    {
        if (nUsed > MAX_MAP_BYTES) // (a file of exactly MAX_MAP_BYTES reads whole)
        {
            osError = osTooLarge;
            bOk = false;
            break;
        }
        try
        {
            oBytes.resize(nUsed + CHUNK);
        }
        catch (const std::bad_alloc &)
        {
            osError = CPLSPrintf("out of memory reading ENV_MAP '%s'", pszPath);
            bOk = false;
            break;
        }
        if (nUsed == sizeof EXR_MAGIC)
            memcpy(oBytes.data(), abyMagic, sizeof abyMagic);
        const size_t nGot = VSIFReadL(oBytes.data() + nUsed, 1, CHUNK, fp);
        nUsed += nGot;
        if (nGot == 0)
            break;
    }
    VSIFCloseL(fp);
    if (bOk && VSI_ISREG(sStat.st_mode) && nUsed < static_cast<vsi_l_offset>(sStat.st_size))
    {
        osError = CPLSPrintf("cannot read ENV_MAP '%s': %zu of its %llu bytes read", pszPath,
                             nUsed, static_cast<unsigned long long>(sStat.st_size));
        bOk = false;
    }
    oBytes.resize(bOk ? nUsed : 0);
    return bOk;
}

/* What the environment will take, before it is set up (MAX_MEMORY is
 * checked on it with the product, CheckMemory): ENV_MAP's bytes read into
 * oMap and its header parsed. An overview level lights with its dataset's
 * environment, set up at open, where it is the same (always, today: a level
 * has its dataset's options, and its sun is the same instant at the same
 * centre): a level made later read ENV_MAP again (a map deleted meanwhile
 * gave GDAL a NULL level, gdalwarp crashed; a replaced one another light),
 * and under SKY every level built a light table of its own, at the cost of
 * the dataset's. */
bool TSDataset::PlanEnvironment(std::vector<GByte> &oMap)
{
    m_sEnvCost = tsd_env_cost{};
    if (!tsd_options_env(&m_sOpts))
        return true;
    if (m_poBase && m_poBase->m_sRun.env &&
        tsd_environment_same(&m_poBase->m_sOpts, &m_poBase->m_sRun, &m_sOpts, &m_sRun))
    {
        m_sRun.env = m_poBase->m_sRun.env;
        m_sEnvCost.kept = m_poBase->m_sEnvCost.kept; // held while the level computes
        m_sEnvCost.texels = m_poBase->m_sEnvCost.texels;
        CPLDebug(DRIVER, "environment: level %d shares its dataset's", m_nLevel);
        return true;
    }
    char szMsg[1024] = "";
    const ts_status eSt = tsd_environment_check_table(&m_sOpts, szMsg, sizeof szMsg);
    if (eSt != TS_OK)
        return Fail(eSt, szMsg), false;
    if (!m_sOpts.env_map[0])
    {
        tsd_environment_cost(&m_sOpts, nullptr, 0, &m_sEnvCost);
        return true;
    }
    // a file larger than the limit is refused before it is read whole
    std::string osError;
    if (!EnvMapIsAFile(m_sOpts.env_map, osError))
        return Fail(CPLE_OpenFailed, osError.c_str()), false;
    const char *pszWhy = nullptr;
    const double dfLimit = MemoryLimit(m_sOpts, &pszWhy);
    VSIStatBufL sStat;
    if (VSIStatExL(m_sOpts.env_map, &sStat, VSI_STAT_SIZE_FLAG) == 0 &&
        VSI_ISREG(sStat.st_mode) && static_cast<double>(sStat.st_size) > dfLimit)
        return Fail(TS_ERR_NOMEM,
                    CPLSPrintf("ENV_MAP '%s' is a file of %.0f MiB, read whole into memory, "
                               "more than the limit of %.0f MiB (%s); use a smaller map, or "
                               "a MAX_MEMORY well above %.0f (its decoding needs its pixels "
                               "at 12 bytes each besides)",
                               m_sOpts.env_map, sStat.st_size / 1048576.0,
                               dfLimit / 1048576.0, pszWhy,
                               std::ceil(sStat.st_size / 1048576.0))),
               false;
    if (!ReadWholeFile(m_sOpts.env_map, oMap, osError))
    {
        Fail(CPLE_OpenFailed, osError.c_str());
        return false;
    }
    ts_env_map_info sInfo;
    ts_error sErr;
    if (ts_env_exr_info(oMap.data(), oMap.size(), m_sOpts.env_map, &sInfo, &sErr) != TS_OK)
    {
        Fail(tsd_fail_core(szMsg, sizeof szMsg, "ENV_MAP", &sErr), szMsg);
        return false;
    }
    m_sEnvMapInfo = sInfo;
    tsd_environment_cost(&m_sOpts, &sInfo, static_cast<double>(oMap.size()), &m_sEnvCost);
    return true;
}

/* The environment planned (PlanEnvironment), once MAX_MEMORY allows it:
 * ENV_MAP decoded from oMap, or the SKY placed; then its light table. */
bool TSDataset::BuildEnvironment(const std::vector<GByte> &oMap)
{
    if (!tsd_options_env(&m_sOpts) || m_sRun.env)
        return true;
    char szMsg[1024] = "";
    const ts_status eSt = tsd_environment_setup(&m_sOpts, &m_sRun, oMap.data(), oMap.size(),
                                                &m_sEnv, szMsg, sizeof szMsg);
    if (eSt != TS_OK)
    {
        Fail(eSt, szMsg);
        return false;
    }
    m_sRun.env = &m_sEnv;
    WarnSkyAtNight();
    if (m_nLevel == 0 && m_sEnv.has_map && m_sEnv.map.chroma)
        CPLError(CE_Warning, CPLE_AppDefined,
                 "TERRASHADE: ENV_MAP '%s' stores its colour as luminance and chroma (Y, RY, "
                 "BY: OpenEXR's YC images): only its luminance Y is read, so its light is "
                 "grey. Save it with R, G and B channels for a coloured light",
                 m_sOpts.env_map);
    CPLDebug(DRIVER, "environment: %zu texels, flat plane E/pi %g %g %g, peak %g",
             m_sEnv.env.count, m_sEnv.flat[0], m_sEnv.flat[1], m_sEnv.flat[2], m_sEnv.peak);
    return true;
}

/* A standard sky that follows the sun, with the sun below the horizon: the
 * CIE defines its skies for a sun above it; the formula goes on there (a
 * dusk sky's distribution), normalised as every sky to an open plane's 1,
 * so it lights the terrain as by day. Said, not refused: a day's series of
 * shade through dusk keeps going. */
void TSDataset::WarnSkyAtNight() const
{
    // (SKY was checked at open, and excludes ENV_MAP)
    if (m_nLevel != 0 || !m_sOpts.sky[0] || m_sRun.sun_elevation >= 0 ||
        tsd_environment_sunless(&m_sOpts))
        return;
    CPLError(CE_Warning, CPLE_AppDefined,
             "TERRASHADE: SKY=%s with the sun %.1f degrees below the horizon: the CIE "
             "standard skies are defined for a sun above it. Their formula is continued "
             "there (a dusk sky's distribution of light) and normalised, as every sky, so "
             "that an open flat plane gets 1: it lights the terrain as by day, not as a "
             "night sky. SKY=uniform, overcast, cie:1, cie:3 and cie:5 do not follow the sun",
             m_sOpts.sky, -m_sRun.sun_elevation);
}

/* The map (its full path, layout, channels, size), the light of an open
 * flat plane, and the exposure of a Byte envlight. */
void TSDataset::SetupEnvironmentMetadata()
{
    if (!m_sRun.env)
        return;
    const tsd_environment &e = *m_sRun.env; // (a level's: its dataset's)
    if (e.has_map)
    {
        GDALDataset::SetMetadataItem("ENV_MAP", m_sOpts.env_map); // not truncated
        GDALDataset::SetMetadataItem("ENV_MAP_LAYOUT", tsd_environment_layout(&e));
        GDALDataset::SetMetadataItem("ENV_MAP_CHANNELS", e.map.grey ? "Y" : "R,G,B");
        GDALDataset::SetMetadataItem("ENV_MAP_SIZE",
                                     CPLSPrintf("%d x %d", e.map.width, e.map.height));
    }
    GDALDataset::SetMetadataItem(
        "ENV_FLAT_LIGHT", CPLSPrintf("%.6g,%.6g,%.6g", e.flat[0], e.flat[1], e.flat[2]));
    if (m_psProduct->compute == tsd_compute_envlight && tsd_options_output_byte(&m_sOpts))
    {
        // (+ 0.0: an automatic exposure of a peak of 1 is -log2(1) = -0)
        GDALDataset::SetMetadataItem("EXPOSURE", CPLSPrintf("%.6g", e.exposure + 0.0));
        GDALDataset::SetMetadataItem("EXPOSURE_RULE",
                                     e.exposure_auto ? "auto: the brightest unshadowed "
                                                       "surface maps to 255"
                                                     : "given");
        GDALDataset::SetMetadataItem("TRANSFER", "sRGB (IEC 61966-2-1)");
    }
}

} // namespace tsd
