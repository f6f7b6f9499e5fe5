/*
 * Progress of a product's computation on stderr, in the style of GDAL's
 * terminal progress ("0...10...20...100 - done."). The computation runs
 * inside the first block read, where GDAL passes no progress callback, so
 * the driver prints its own line: with PROGRESS=yes always, with auto only
 * when stderr is a terminal and the work has taken a while already.
 */
#ifndef TSD_PROGRESS_H
#define TSD_PROGRESS_H

#include <stdio.h>

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
} tsd_progress;

/* Start timing; `label` opens the line, e.g. "computing svf of 512 x 512
 * cells". `out` NULL = stderr. With mode auto the line starts once
 * `after_s` seconds have passed (and only if `out` is a terminal). */
void tsd_progress_begin(tsd_progress *p, tsd_progress_mode mode, FILE *out,
                        const char *label, double after_s);

/* A ts_progress_fn: `user` is the tsd_progress. Never cancels. */
int tsd_progress_report(double done, void *user);

/* Close the line: " - done in 1.2 s." when ok, " - failed." otherwise
 * (only if the line was started). */
void tsd_progress_end(tsd_progress *p, int ok);

#ifdef __cplusplus
}
#endif

#endif
