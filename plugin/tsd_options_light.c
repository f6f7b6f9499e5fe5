/* The light's options: LIGHT_RADIUS (the disk of the exact method, and of
 * METHOD=shadowmap's auto filter), METHOD=shm's and METHOD=shadowmap's own
 * options, and the combinations where they make no sense. (METHOD=shm with
 * MAX_DISTANCE bounds its sky term and EDGE=nodata's reach, not its
 * shadows: a warning, TSDataset::WarnDistances.) */
#include "tsd_options_light.h"

#include <math.h>

#include "tsd_products.h"
#include "tsd_text.h"

#define REFUSE(...) return (tsd_fail(msg, n, TS_ERR_ARG, __VA_ARGS__), -1)

int tsd_options_check_light(const tsd_options *o, char *msg, size_t n)
{
    const tsd_product_def *p = tsd_product_of(o);
    /* an option given with its declared default is no mistake */
    tsd_options d;
    tsd_options_defaults(&d);
    const int radius_given = o->light_radius != d.light_radius;
    const int shadowmap = o->method == TSD_METHOD_SHADOWMAP;
    /* (LIGHT_RADIUS's own range, open at both ends, is its row's check) */
    if (radius_given && !tsd_product_takes(p, tsd_option_find("LIGHT_RADIUS")))
        REFUSE("LIGHT_RADIUS applies to PRODUCT=shade and PRODUCT=shadow, not to "
               "PRODUCT=%s", p->name);
    if (radius_given && o->method == TSD_METHOD_SHM)
        REFUSE("LIGHT_RADIUS does not apply to METHOD=shm, whose soft edges are set by "
               "PENUMBRA_DEPTH; use METHOD=exact, METHOD=shadowmap or METHOD=sh");
    if (radius_given && o->sun_position == TSD_SUN_PER_CELL)
        REFUSE("LIGHT_RADIUS applies with SUN_POSITION=center: the per-cell sun is the sun's "
               "own disk");
    if (o->method != TSD_METHOD_SHM && o->penumbra_depth != d.penumbra_depth)
        REFUSE("PENUMBRA_DEPTH applies to METHOD=shm only, of PRODUCT=shade and "
               "PRODUCT=shadow (the other methods soften the shadows by LIGHT_RADIUS)");
    if (!shadowmap && o->shadowmap_scale != d.shadowmap_scale)
        REFUSE("SHADOWMAP_SCALE applies to METHOD=shadowmap only, of PRODUCT=shade and "
               "PRODUCT=shadow");
    if (!shadowmap && !isnan(o->pcf_kernel))
        REFUSE("PCF_KERNEL applies to METHOD=shadowmap only, of PRODUCT=shade and "
               "PRODUCT=shadow");
    if (shadowmap && o->sun_position == TSD_SUN_PER_CELL)
        REFUSE("METHOD=shadowmap renders one depth map for one light direction: it needs "
               "SUN_POSITION=center");
    /* (once taken without a word: shade went exact, shadow kept the centre's sun) */
    if (o->method == TSD_METHOD_SHM && o->sun_position == TSD_SUN_PER_CELL)
        REFUSE("METHOD=shm builds its shadow height maps for one sun direction: it needs "
               "SUN_POSITION=center (METHOD=exact takes a sun per cell)");
    /* said at open (gdalinfo, a QGIS layer), not on the first read; DATETIME's
     * sun is checked once it is computed (tsd_sun_setup) */
    if (shadowmap && !tsd_options_sun_from_time(o) && !(o->sun_elevation > 0))
        REFUSE("METHOD=shadowmap needs the light above the horizon: SUN_ELEVATION must be "
               "greater than 0, got %g (METHOD=exact handles a low light)", o->sun_elevation);
    if (shadowmap && o->max_distance > 0)
        REFUSE("MAX_DISTANCE does not apply to METHOD=shadowmap (its depth map holds the "
               "whole DEM); use METHOD=exact");
    /* it left every cell valid, where unbounded EDGE=nodata blanks them all */
    if (shadowmap && tsd_options_edge(o) == TS_EDGE_NODATA)
        REFUSE("EDGE=nodata does not apply to METHOD=shadowmap (it leaves out the cells "
               "whose rays leave the DEM within MAX_DISTANCE, which METHOD=shadowmap does "
               "not take); use METHOD=exact with MAX_DISTANCE, or EDGE=horizon or open");
    return 0;
}
