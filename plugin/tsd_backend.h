/*
 * tsd_backend.h - the BACKEND option and what the backend dispatcher
 * (cl/terrashade_backend.h) ran for a product's heavy calls, summed up for
 * the metadata items BACKEND, BACKEND_DEVICE and BACKEND_FALLBACK_REASON.
 * Plain C, no GDAL.
 */
#ifndef TSD_BACKEND_H
#define TSD_BACKEND_H

#include <stddef.h>

#include "terrashade_backend.h"
#include "tsd_options.h"

#ifdef __cplusplus
extern "C" {
#endif

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

/** Add one call's report to a summary. */
void tsd_backend_summary_add(tsd_backend_summary *s, const ts_backend_report *r);

/** Add a summary (of one chunk of a windowed product) to another (of the
 * chunks computed so far), as if its calls had been added one by one. */
void tsd_backend_summary_merge(tsd_backend_summary *s, const tsd_backend_summary *add);

/** The reasons of the steps that run in C whatever the backend (with
 * TS_CL_CAPPED_SWEEP_REASON, MAX_DISTANCE's): the same before computing
 * (tsd_backend_predict) as after. */
#define TSD_PYRAMID_C_REASON                                                               \
    "HORIZON_METHOD=pyramid runs on the C backend (there is no OpenCL pyramid)"
#define TSD_PER_CELL_C_REASON "SUN_POSITION=per_cell: the per-cell sun runs in C only"

/** Add a step that runs in C whatever the backend (it has no OpenCL
 * path), why: the reason the metadata and the BACKEND=opencl warning give.
 * requested: the options' backend. */
void tsd_backend_note_c(tsd_backend_summary *s, ts_backend requested, const char *why);

/** Why a heavy step of this product runs in C with these options whatever
 * the backend (MAX_DISTANCE's capped sweeps, the pyramid's horizons, the
 * per-cell sun), or NULL; *all: every heavy step does (a horizon product,
 * a shadow), else the product is mixed where OpenCL runs. */
const char *tsd_backend_c_step(const tsd_options *o, int *all);

/**
 * Predict, without computing, the summary of the product's calls
 * (ts_backend_choose: probes the OpenCL device), with the C step of
 * tsd_backend_c_step. 0, or -1 with a sentence in msg (a bad
 * TERRASHADE_BACKEND).
 */
int tsd_backend_predict(const tsd_options *o, tsd_backend_summary *s, char *msg,
                        size_t msg_size);

/** The environment's choices, checked at open (probes nothing): -1 with a
 * sentence in msg if TERRASHADE_SIMD is not auto, avx512, avx2 or none
 * (every product runs C code), or, for a product that chooses a backend
 * (uses_backend) with BACKEND=auto, if TERRASHADE_BACKEND is not auto, c or
 * opencl, or TERRASHADE_OPENCL_BATCH is not 1..TSD_OPENCL_BATCH_MAX (for a
 * product that chooses a backend); else 0. */
int tsd_backend_check_env(const tsd_options *o, int uses_backend, char *msg, size_t msg_size);

/** The most azimuths a horizon stream sweeps in one OpenCL call
 * (TERRASHADE_OPENCL_BATCH): unset or empty 0 (automatic: one on a CPU
 * device, TSD_OPENCL_BATCH_DEFAULT on a GPU or an accelerator), else an
 * integer from 1 to TSD_OPENCL_BATCH_MAX; -1 with a sentence in msg for
 * anything else. */
#define TSD_OPENCL_BATCH_DEFAULT 16
#define TSD_OPENCL_BATCH_MAX 256
int tsd_backend_batch(char *msg, size_t msg_size);

/**
 * The metadata values of a summary: backend "c", "opencl" or "mixed" (some
 * calls on each), device (both, "opencl: ...; c: ..." when mixed).
 */
void tsd_backend_summary_text(const tsd_backend_summary *s, char *backend,
                              size_t backend_size, char *device, size_t device_size);

#ifdef __cplusplus
}
#endif

#endif
