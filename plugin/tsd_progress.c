/* The driver's progress line on stderr; see tsd_progress.h. */
#define _POSIX_C_SOURCE 200809L
#include "tsd_progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

#define TICKS 40 /* of 2.5 % each, a number every fourth */

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void tsd_progress_begin(tsd_progress *p, tsd_progress_mode mode, FILE *out,
                        const char *label, double after_s)
{
    p->after_s = after_s >= 0 ? after_s : 0;
    p->out = out ? out : stderr;
    p->mode = mode;
    p->ticks = -1;
    p->t0 = now_s();
    p->done = 0.0;
    snprintf(p->label, sizeof p->label, "%s", label ? label : "computing");
    p->caller = NULL;
    p->caller_user = NULL;
    p->cancelled = 0;
    if (mode == TSD_PROGRESS_YES)
        tsd_progress_report(0.0, p);
}

void tsd_progress_set_caller(tsd_progress *p, ts_progress_fn caller, void *user)
{
    p->caller = caller;
    p->caller_user = user;
}

/* Print ticks up to `upto` (0..TICKS), opening the line first. */
static void advance(tsd_progress *p, int upto)
{
    if (p->ticks < 0) {
        fprintf(p->out, "TERRASHADE: %s: 0", p->label);
        p->ticks = 0;
    }
    while (p->ticks < upto) {
        p->ticks++;
        if (p->ticks % 4 == 0)
            fprintf(p->out, "%d", p->ticks * 100 / TICKS);
        else
            fputc('.', p->out);
    }
    fflush(p->out);
}

int tsd_progress_report(double done, void *user)
{
    tsd_progress *p = user;
    if (!p)
        return 0;
    if (done > p->done)
        p->done = done > 1.0 ? 1.0 : done;
    int print = p->mode == TSD_PROGRESS_YES ||
                (p->mode == TSD_PROGRESS_AUTO &&
                 (p->ticks >= 0 || (isatty(fileno(p->out)) && now_s() - p->t0 >= p->after_s)));
    if (print)
        advance(p, (int)(p->done * TICKS + 1e-9));
    if (p->caller && p->caller(p->done, p->caller_user))
        p->cancelled = 1;
    return p->cancelled;
}

void tsd_progress_end(tsd_progress *p, int ok)
{
    if (!p || p->ticks < 0)
        return;
    if (ok) {
        advance(p, TICKS);
        fprintf(p->out, " - done in %.1f s.\n", now_s() - p->t0);
    } else {
        fprintf(p->out, p->cancelled ? " - cancelled.\n" : " - failed.\n");
    }
    fflush(p->out);
}
