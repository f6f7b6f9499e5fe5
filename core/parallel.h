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

#endif
