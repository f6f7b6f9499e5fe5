/* tsd_dataset_memory.cpp - the MAX_MEMORY check of a dataset's set-up:
 * the product's peak bytes (whole, or by window) against the limit, and
 * the sentence that says what to do where it does not fit. */
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "cpl_conv.h"
#include "cpl_string.h"

#include "tsd_dataset.h"
#include "tsd_gdal.h"

namespace tsd
{

/* Bytes as the MiB a message says: rounded up, so that a MAX_MEMORY of the
 * figure said opens (rounded to the nearest, "needs about 79 MiB ... more
 * than the limit of 79 MiB", and the TILE_SIZE advised at "about 38 MiB"
 * was refused again under MAX_MEMORY=38: session 57's memory audit). */
static double MiBUp(double dfBytes)
{
    return std::ceil(dfBytes / 1048576.0);
}

double MemoryLimit(const tsd_options &sOpts, const char **ppszWhy)
{
    *ppszWhy = "MAX_MEMORY";
    if (sOpts.max_memory_mb > 0)
        return sOpts.max_memory_mb * 1048576.0;
    *ppszWhy = "three quarters of the physical memory; set MAX_MEMORY to change";
    const double dfLimit = 0.75 * static_cast<double>(CPLGetUsablePhysicalRAM());
    return dfLimit > 0 ? dfLimit : static_cast<double>(std::numeric_limits<size_t>::max()) / 2;
}

/* What the environment needs, where it alone does not fit the limit: the
 * light table (its axes, and what takes fewer) or ENV_MAP decoded (its
 * pixels), empty where it fits; dfTotal, with the product, is the
 * MAX_MEMORY that would do. */
static std::string EnvironmentOver(const tsd_options &sOpts, const tsd_env_cost &sEnv,
                                   const ts_env_map_info *psMap, double dfLimit,
                                   const char *pszWhy, double dfTotal)
{
    if (std::max(sEnv.peak, sEnv.kept) <= dfLimit)
        return std::string();
    const double dfNeed = std::ceil(dfTotal / 1048576.0); // the product's share too
    const std::string osSource =
        sOpts.env_map[0] ? CPLSPrintf("ENV_MAP '%s'", sOpts.env_map)
                         : CPLSPrintf("SKY=%s", sOpts.sky);
    if (psMap && sEnv.map_peak >= sEnv.table_peak)
        return CPLSPrintf("decoding %s (%d x %d pixels, read as 12 bytes each, into %.0f "
                          "texels) needs about %.0f MiB, more than the limit of %.0f MiB "
                          "(%s); use a smaller map (larger than 2048 x 1024 it is merged "
                          "to that many texels anyway), or MAX_MEMORY=%.0f or more",
                          osSource.c_str(), psMap->width, psMap->height, sEnv.texels,
                          MiBUp(sEnv.peak), dfLimit / 1048576.0, pszWhy, dfNeed);
    return CPLSPrintf("the light table of %s (DIRECTIONS=%d x ENV_NORMAL_STEPS=%d x "
                      "ENV_HORIZON_STEPS=%d) needs about %.0f MiB while it is built (%.0f MiB "
                      "kept), more than the limit of %.0f MiB (%s); use fewer DIRECTIONS or "
                      "ENV_HORIZON_STEPS%s, or MAX_MEMORY=%.0f or more",
                      osSource.c_str(), sOpts.directions, sOpts.env_normal_steps,
                      sOpts.env_horizon_steps, MiBUp(sEnv.peak), MiBUp(sEnv.kept),
                      dfLimit / 1048576.0, pszWhy,
                      sOpts.env_normal_steps ? " (or ENV_NORMAL_STEPS=0, exact)" : "", dfNeed);
}

/* Refuse products that cannot fit, with a sentence saying what to do.
 * psSun, the cells and nLevel serve the advice on windows (level 0). */
bool CheckMemory(const tsd_options &sOpts, int W, int H, const tsd_window_plan *psPlan,
                 const tsd_sun *psSun, const tsd_cells &sCells, int nLevel,
                 const tsd_env_cost &sEnv, const ts_env_map_info *psMap, double dfDEMCopy,
                 double *pdfLimit, double *pdfHeadroom)
{
    if (!psPlan && (W > TS_MAX_SIDE || H > TS_MAX_SIDE))
    {
        // (found here, not at the first read, where it said no more than the core's limit)
        char szAdvice[512] = "";
        if (nLevel == 0)
            tsd_window_advice(&sOpts, psSun, W, H, tsd_cells_min_x(&sCells, H),
                              sCells.cell_y, std::numeric_limits<double>::max(), sEnv.kept,
                              szAdvice, sizeof szAdvice);
        Fail(TS_ERR_ARG, CPLSPrintf("PRODUCT=%s computes this %d x %d DEM whole, and a DEM "
                                    "computed whole has at most %d cells a side%s; crop or "
                                    "downsample the DEM",
                                    tsd_options_product_name(&sOpts), W, H, TS_MAX_SIDE,
                                    szAdvice));
        return false;
    }
    double dfSteady = 0;
    // windowed: the chunk with its margin, the cache and the far field
    double dfMapX = 1, dfMapY = 1;
    tsd_shadowmap_aspect(sCells.cell_x, sCells.cell_x_row, H, sCells.cell_y, &dfMapX, &dfMapY);
    double dfPeak = psPlan ? tsd_window_peak_bytes(&sOpts, psPlan, &dfSteady)
                           : tsd_product_peak_bytes(&sOpts, W, H, dfMapX, dfMapY, &dfSteady);
    // the environment: set up at open (its peak), then kept while computing
    // (and the DEM's copy in memory, held from open to close)
    dfPeak = std::max(dfPeak + sEnv.kept, sEnv.peak) + dfDEMCopy;
    dfSteady += sEnv.kept + dfDEMCopy;
    const char *pszWhy = nullptr;
    const double dfLimit = MemoryLimit(sOpts, &pszWhy);
    CPLDebug(DRIVER,
             "memory: about %.0f MiB while computing (%.0f MiB kept)%s, limit %.0f MiB; the "
             "environment %.0f MiB set up, %.0f MiB kept",
             dfPeak / 1048576.0, dfSteady / 1048576.0, psPlan ? " by window" : "",
             dfLimit / 1048576.0, sEnv.peak / 1048576.0, sEnv.kept / 1048576.0);
    *pdfLimit = dfLimit;
    *pdfHeadroom = std::max(0.0, dfLimit - dfPeak);
    if (dfPeak <= dfLimit && dfPeak < static_cast<double>(std::numeric_limits<size_t>::max()) / 2)
        return true;
    const std::string osEnv = EnvironmentOver(sOpts, sEnv, psMap, dfLimit, pszWhy, dfPeak);
    if (!osEnv.empty()) // no crop of the DEM helps
    {
        Fail(TS_ERR_NOMEM,
             CPLSPrintf("PRODUCT=%s needs about %.0f MiB while computing (%.0f MiB kept): %s",
                        tsd_options_product_name(&sOpts), MiBUp(dfPeak), MiBUp(dfSteady),
                        osEnv.c_str()));
        return false;
    }
    char szAdvice[512] = "";
    // a small DEM's chunks with their margins can need more than the whole
    // DEM at once: say so, where the advice named no TILE_SIZE at all
    double dfWholeSteady = 0;
    const double dfWhole = std::max(tsd_product_peak_bytes(&sOpts, W, H, dfMapX, dfMapY,
                                                           &dfWholeSteady) +
                                    sEnv.kept, sEnv.peak) + dfDEMCopy;
    if (psPlan && W <= TS_MAX_SIDE && H <= TS_MAX_SIDE && dfWhole <= dfLimit)
        snprintf(szAdvice, sizeof szAdvice,
                 "; TILE_SIZE=0 computes it whole in about %.0f MiB (its chunks with their "
                 "margins need more)",
                 MiBUp(dfWhole));
    else if (nLevel == 0)
        tsd_window_advice(&sOpts, psSun, W, H, tsd_cells_min_x(&sCells, H), sCells.cell_y,
                          dfLimit, sEnv.kept + dfDEMCopy, szAdvice, sizeof szAdvice);
    // (the advice counts the copy too: without it each mode's sent the
    // user to the other, the review)
    const std::string osCopy =
        dfDEMCopy > 0 ? CPLSPrintf("; %.0f MiB of both the DEM's copy from the standard "
                                   "input, which a DEM written to a file does not need",
                                   MiBUp(dfDEMCopy))
                      : "";
    // fewer bands need less where an option sets their count (svf streams its DIRECTIONS)
    const char *pszBands = tsd_product_of(&sOpts)->bands_option;
    const std::string osFewer = !pszBands ? ""
                                : EQUAL(pszBands, "STEP_MINUTES") ? "use a longer STEP_MINUTES, "
                                : std::string("use fewer ") + pszBands + ", ";
    Fail(TS_ERR_NOMEM,
         CPLSPrintf("PRODUCT=%s with %d band(s) on this %d x %d DEM needs "
                    "about %.0f MiB while computing (%.0f MiB kept%s), more than the "
                    "limit of %.0f MiB (%s)%s; crop or downsample the DEM, %sor raise "
                    "MAX_MEMORY", tsd_options_product_name(&sOpts),
                    tsd_options_band_count(&sOpts), W, H, MiBUp(dfPeak), MiBUp(dfSteady),
                    osCopy.c_str(), dfLimit / 1048576.0, pszWhy, szAdvice,
                    osFewer.c_str()));
    return false;
}

} // namespace tsd
