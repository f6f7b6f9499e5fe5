/*
 * Progress of a product's computation on stderr, in the style of GDAL's
 * terminal progress ("0...10...20...100 - done."). The computation runs
 * inside the first block read, where GDAL passes no progress callback, so
 * the driver prints its own line: with PROGRESS=yes always, with auto only
 * when stderr is a terminal and the work has taken a while already. Where
 * the read that computes has a progress callback of its caller's (GDAL's
 * RasterIO extra argument), the fraction goes to it too, and it may stop
 * the computation.
 */
#ifndef TSD_PROGRESS_H
#define TSD_PROGRESS_H

#include <stdio.h>

#include "terrashade.h"
#include "tsd_options.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    FILE *out;
    int mode;         /* tsd_progress_mode */
    int ticks;        /* ticks of 2.5 % printed, -1 = line not started */
    double t0;        /* monotonic seconds at the start */
    double done;      /* largest fraction reported */
    double after_s;   /* auto: start the line after this many seconds */
    char label[160];
    ts_progress_fn caller; /* the caller's: non-zero stops; NULL = none */
    void *caller_user;
    int cancelled;         /* the caller stopped the computation */
} tsd_progress;

/* Start timing; `label` opens the line, e.g. "computing svf of 512 x 512
 * cells". `out` NULL = stderr. With mode auto the line starts once
 * `after_s` seconds have passed (and only if `out` is a terminal). No
 * caller's callback until tsd_progress_set_caller. */
void tsd_progress_begin(tsd_progress *p, tsd_progress_mode mode, FILE *out,
                        const char *label, double after_s);

/* Tell `caller` the fraction done at every report too; when it returns
 * non-zero the computation stops (TS_ERR_CANCELLED) and `cancelled` is
 * set. */
void tsd_progress_set_caller(tsd_progress *p, ts_progress_fn caller, void *user);

/* A ts_progress_fn: `user` is the tsd_progress. Cancels only when the
 * caller's callback says so. */
int tsd_progress_report(double done, void *user);

/* Close the line: " - done in 1.2 s." when ok, " - cancelled." or
 * " - failed." otherwise (only if the line was started). */
void tsd_progress_end(tsd_progress *p, int ok);

#ifdef __cplusplus
}
#endif

#endif
