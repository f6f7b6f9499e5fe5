/* tsd_dataset_memory.cpp - the MAX_MEMORY check of a dataset's set-up:
 * the product's peak bytes (whole, or by window) against the limit, and
 * the sentence that says what to do where it does not fit. */
#include <algorithm>
#include <limits>
#include <string>

#include "cpl_conv.h"
#include "cpl_string.h"

#include "tsd_dataset.h"
#include "tsd_gdal.h"

namespace tsd
{

/* Refuse products that cannot fit, with a sentence saying what to do.
 * psSun, the cells and nLevel serve the advice on windows (level 0). */
bool CheckMemory(const tsd_options &sOpts, int W, int H, const tsd_window_plan *psPlan,
                 const tsd_sun *psSun, const tsd_cells &sCells, int nLevel,
                 double *pdfHeadroom)
{
    if (!psPlan && (W > TS_MAX_SIDE || H > TS_MAX_SIDE))
    {
        // (found here, not at the first read, where it said no more than the core's limit)
        char szAdvice[512] = "";
        if (nLevel == 0)
            tsd_window_advice(&sOpts, psSun, W, H, tsd_cells_min_x(&sCells, H),
                              sCells.cell_y, std::numeric_limits<double>::max(), szAdvice,
                              sizeof szAdvice);
        Fail(TS_ERR_ARG, CPLSPrintf("PRODUCT=%s computes this %d x %d DEM whole, and a DEM "
                                    "computed whole has at most %d cells a side%s; crop or "
                                    "downsample the DEM",
                                    tsd_options_product_name(&sOpts), W, H, TS_MAX_SIDE,
                                    szAdvice));
        return false;
    }
    double dfSteady = 0;
    // windowed: the chunk with its margin, the cache and the far field
    const double dfPeak = psPlan ? tsd_window_peak_bytes(&sOpts, psPlan, &dfSteady)
                                 : tsd_product_peak_bytes(&sOpts, W, H, &dfSteady);
    double dfLimit = 0;
    const char *pszWhy = "MAX_MEMORY";
    if (sOpts.max_memory_mb > 0)
        dfLimit = sOpts.max_memory_mb * 1048576.0;
    else
    {
        dfLimit = 0.75 * static_cast<double>(CPLGetUsablePhysicalRAM());
        pszWhy = "three quarters of the physical memory; set MAX_MEMORY to change";
        if (dfLimit <= 0)
            dfLimit = static_cast<double>(std::numeric_limits<size_t>::max()) / 2;
    }
    CPLDebug(DRIVER, "memory: about %.0f MiB while computing (%.0f MiB kept)%s, limit %.0f MiB",
             dfPeak / 1048576.0, dfSteady / 1048576.0, psPlan ? " by window" : "",
             dfLimit / 1048576.0);
    *pdfHeadroom = std::max(0.0, dfLimit - dfPeak);
    if (dfPeak <= dfLimit && dfPeak < static_cast<double>(std::numeric_limits<size_t>::max()) / 2)
        return true;
    char szAdvice[512] = "";
    // a small DEM's chunks with their margins can need more than the whole
    // DEM at once: say so, where the advice named no TILE_SIZE at all
    double dfWholeSteady = 0;
    const double dfWhole = tsd_product_peak_bytes(&sOpts, W, H, &dfWholeSteady);
    if (psPlan && W <= TS_MAX_SIDE && H <= TS_MAX_SIDE && dfWhole <= dfLimit)
        snprintf(szAdvice, sizeof szAdvice,
                 "; TILE_SIZE=0 computes it whole in about %.0f MiB (its chunks with their "
                 "margins need more)",
                 dfWhole / 1048576.0);
    else if (nLevel == 0)
        tsd_window_advice(&sOpts, psSun, W, H, tsd_cells_min_x(&sCells, H), sCells.cell_y,
                          dfLimit, szAdvice, sizeof szAdvice);
    // fewer bands need less where an option sets their count (svf streams its DIRECTIONS)
    const char *pszBands = tsd_product_of(&sOpts)->bands_option;
    const std::string osFewer = !pszBands ? ""
                                : EQUAL(pszBands, "STEP_MINUTES") ? "use a longer STEP_MINUTES, "
                                : std::string("use fewer ") + pszBands + ", ";
    Fail(TS_ERR_NOMEM,
         CPLSPrintf("PRODUCT=%s with %d band(s) on this %d x %d DEM needs "
                    "about %.0f MiB while computing (%.0f MiB kept), more than the "
                    "limit of %.0f MiB (%s)%s; crop or downsample the DEM, %sor raise "
                    "MAX_MEMORY", tsd_options_product_name(&sOpts),
                    tsd_options_band_count(&sOpts), W, H, dfPeak / 1048576.0,
                    dfSteady / 1048576.0, dfLimit / 1048576.0, pszWhy, szAdvice,
                    osFewer.c_str()));
    return false;
}

} // namespace tsd
