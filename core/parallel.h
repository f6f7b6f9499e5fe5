/* A minimal parallel-for over an index range, on POSIX threads. */
#ifndef TS_PARALLEL_H
#define TS_PARALLEL_H

#include "terrashade.h"

/* Work on items [begin, end) of a job; `worker` is the thread's index. */
typedef void (*ts_range_fn)(void *ctx, int worker, long begin, long end);

/* Thread count to use: requested if > 0, else the number of cores, never
 * more than `items`, never less than 1. */
int ts_thread_count(int requested, long items);

/* Split [0, items) into `threads` contiguous chunks and run fn on each, the
 * first chunk on the calling thread. The chunks start together once all
 * threads exist; if a thread cannot be made, fn runs once on the calling
 * thread over the whole range instead. So fn must accept any sub-range. */
ts_status ts_parallel_for(int threads, long items, ts_range_fn fn, void *ctx,
                          ts_error *err);

/* The ranges of ts_parallel_ranges: what is left of [0, items). */
typedef struct ts_range_queue ts_range_queue;

/* Take the next range of q into [*begin, *end): a share of what is left
 * (half of it split among the threads), a multiple of the grain but the
 * last, at least the grain; 0 when nothing is left. */
int ts_range_next(ts_range_queue *q, long *begin, long *end);

/* Work on the ranges a worker takes from q (ts_range_next, until it says
 * none is left). */
typedef void (*ts_ranges_fn)(void *ctx, int worker, ts_range_queue *q);

/* Run fn on `threads` threads (the first the calling one), each taking
 * ranges of [0, items) until none is left: sizes that shrink as the work
 * runs out, so that a thread on a slower core (or a harder part of the
 * work) takes less, and the threads end together. Every item lies in
 * exactly one range; which thread takes it, and in how many pieces, is
 * not fixed, so fn's results must not depend on that (nor on the ranges
 * running together: they need not). If a thread cannot be made, fewer
 * threads take the ranges. */
ts_status ts_parallel_ranges(int threads, long items, long grain, ts_ranges_fn fn, void *ctx,
                             ts_error *err);

/* The grains of ts_parallel_for_ranges for work row by row (rows a range
 * holds at least) and cell by cell (cells). */
#define TS_ROWS_GRAIN 8
#define TS_CELLS_GRAIN 4096

/* ts_parallel_ranges for a ts_range_fn: fn once for each range a worker
 * takes, in turn (so fn must accept any sub-range, and several on one
 * worker). For work item by item (rows), where a split in fixed halves
 * would wait on the slower core. */
ts_status ts_parallel_for_ranges(int threads, long items, long grain, ts_range_fn fn, void *ctx,
                                 ts_error *err);

/* A long pass that reports its progress and takes a cancel: fn over [0,
 * items) in `batches` batches, with ts_progress(report) before each, from
 * `from` to below `to` (a stop ends it with TS_ERR_CANCELLED); where report
 * has no callback, one batch and no report. Each batch runs by
 * ts_parallel_for_ranges with `grain`, or with grain 0 by ts_parallel_for
 * (fixed shares: for work each call of which has a fixed cost). fn's
 * results must not depend on the batches, as they must not on the
 * threads' shares. */
ts_status ts_parallel_reported(int threads, long items, long grain, ts_range_fn fn, void *ctx,
                               const ts_horizon_opts *report, double from, double to,
                               int batches, ts_error *err);

#endif
