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
#include "terrashade_backend.h"
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
 * What the backend dispatcher ran for the heavy calls of a product (the
 * ts_backend_* reports of its calls, summed up). Zero it before use.
 */
typedef struct {
    int calls;                /* dispatcher calls */
    int opencl_calls, c_calls;
    ts_backend requested;     /* after TERRASHADE_BACKEND (first call) */
    int fell_back;            /* a call tried OpenCL, failed and ran C */
    char device_opencl[192];  /* the device of the OpenCL calls */
    char device_c[192];       /* the device of the C calls */
    char reason[256];         /* why OpenCL did not run, when it was wanted
                                 (requested not c) and C ran; "" otherwise */
} tsd_backend_summary;

/** The ts_backend of a BACKEND option value. */
ts_backend tsd_backend_to_ts(tsd_backend b);

/** 1 if the product makes backend calls (shade, shadow, horizon, svf,
 * openness, sky; not shadow with a per-cell sun, nor the day products). */
int tsd_product_uses_backend(const tsd_options *o, const tsd_sun *sun);

/** Add one call's report to a summary. */
void tsd_backend_summary_add(tsd_backend_summary *s, const ts_backend_report *r);

/**
 * Predict, without computing, the summary of the product's calls
 * (ts_backend_choose: probes the OpenCL device). 0, or -1 with a sentence
 * in msg (a bad TERRASHADE_BACKEND).
 */
int tsd_backend_predict(const tsd_options *o, tsd_backend_summary *s, char *msg,
                        size_t msg_size);

/** With BACKEND=auto: -1 with a sentence in msg if TERRASHADE_BACKEND is
 * not auto, c or opencl (probes nothing); else 0. */
int tsd_backend_check_env(const tsd_options *o, char *msg, size_t msg_size);

/**
 * The metadata values of a summary: backend "c", "opencl" or "mixed" (some
 * calls on each), device (both, "opencl: ...; c: ..." when mixed).
 */
void tsd_backend_summary_text(const tsd_backend_summary *s, char *backend,
                              size_t backend_size, char *device, size_t device_size);

/**
 * Compute the product into `out`: tsd_options_band_count(o) planes of
 * width*height floats (row stride = width), in the grid's orientation,
 * NaN = nodata; PRODUCT=farshadow writes `bytes` instead (planes of
 * width*height bytes: 0, 1, 255 = nodata) and leaves out unused (it may be
 * NULL then). `sun` (NULL when the sun is given by SUN_AZIMUTH and
 * SUN_ELEVATION) comes from tsd_sun_setup. The horizon sweeps, shadow
 * height maps, normals and direct sun run on the backend of o->backend;
 * `backend` (may be NULL) receives what ran (zeroed here first). 0 on
 * success, -1 with a sentence in msg.
 */
int tsd_product_compute(const ts_grid *grid, const tsd_options *o,
                        const tsd_sun *sun, float *out, uint8_t *bytes,
                        tsd_backend_summary *backend, char *msg, size_t msg_size);

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
