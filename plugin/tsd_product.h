/*
 * tsd_product.h - compute a TERRASHADE product from a core grid: the
 * sequence of core calls for each PRODUCT / METHOD, streaming one horizon
 * direction at a time so that memory stays bounded. No GDAL.
 */
#ifndef TSD_PRODUCT_H
#define TSD_PRODUCT_H

#include <stddef.h>
#include <stdint.h>

#include "terrashade.h"
#include "tsd_options.h"
#include "tsd_sun.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Peak memory in bytes while computing a width x height product, the DEM
 * grid included; `steady` (may be NULL) receives what stays afterwards
 * (the product, as float planes). Doubles, so that nothing overflows.
 */
double tsd_product_peak_bytes(const tsd_options *o, int width, int height,
                              double *steady);

/**
 * Compute the product into `out`: tsd_options_band_count(o) planes of
 * width*height floats (row stride = width), in the grid's orientation,
 * NaN = nodata; PRODUCT=farshadow writes `bytes` instead (planes of
 * width*height bytes: 0, 1, 255 = nodata) and leaves out unused (it may be
 * NULL then). `sun` (NULL when the sun is given by SUN_AZIMUTH and
 * SUN_ELEVATION) comes from tsd_sun_setup. 0 on success, -1 with a
 * sentence in msg.
 */
int tsd_product_compute(const ts_grid *grid, const tsd_options *o,
                        const tsd_sun *sun, float *out, uint8_t *bytes,
                        char *msg, size_t msg_size);

/** Byte value of a 0..1 product as gdaldem writes it: 0 for nodata, else
 * 1 + 254 v rounded, 1 for v <= 0. */
static inline unsigned char tsd_to_byte(float v)
{
    if (v != v)
        return 0;
    if (v <= 0)
        return 1;
    if (v >= 1)
        return 255;
    return (unsigned char)(1.0f + 254.0f * v + 0.5f);
}

#ifdef __cplusplus
}
#endif

#endif
