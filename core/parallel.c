/* Parallel-for on POSIX threads; no pool, no global state. */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "parallel.h"
#include "status_internal.h"

int ts_cpu_count(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (int)n;
}

int ts_thread_count(int requested, long items)
{
    int n = requested > 0 ? requested : ts_cpu_count();
    if (items < n)
        n = items < 1 ? 1 : (int)items;
    return n;
}

enum { WAIT, GO, CANCEL };

typedef struct {
    ts_range_fn fn;
    void *ctx;
    int worker;
    long begin, end;
    atomic_int *state;
} chunk;

static void *run_chunk(void *arg)
{
    chunk *c = arg;
    int s;
    while ((s = atomic_load_explicit(c->state, memory_order_acquire)) == WAIT)
        sched_yield();
    if (s == GO)
        c->fn(c->ctx, c->worker, c->begin, c->end);
    return NULL;
}

/* Chunks start together only once every thread exists, so interdependent
 * chunks (a wavefront) never wait on a chunk that will not run. If a thread
 * cannot be made, the whole range runs as one chunk on the calling thread. */
ts_status ts_parallel_for(int threads, long items, ts_range_fn fn, void *ctx,
                          ts_error *err)
{
    if (items <= 0)
        return ts_ok(err);
    if (threads > items)
        threads = (int)items;
    chunk *chunks = threads > 1 ? malloc((size_t)threads * sizeof *chunks) : NULL;
    pthread_t *tids = threads > 1 ? malloc((size_t)threads * sizeof *tids) : NULL;
    if (!chunks || !tids) {
        free(chunks);
        free(tids);
        fn(ctx, 0, 0, items);
        return ts_ok(err);
    }
    atomic_int state;
    atomic_init(&state, WAIT);
    for (int t = 0; t < threads; t++)
        chunks[t] = (chunk){fn, ctx, t, items * t / threads, items * (t + 1) / threads, &state};
    int started = 1;
    for (int t = 1; t < threads; t++) {
        if (pthread_create(&tids[t], NULL, run_chunk, &chunks[t]) != 0)
            break;
        started++;
    }
    int all = started == threads;
    atomic_store_explicit(&state, all ? GO : CANCEL, memory_order_release);
    if (all)
        run_chunk(&chunks[0]);
    for (int t = 1; t < started; t++)
        pthread_join(tids[t], NULL);
    if (!all)
        fn(ctx, 0, 0, items);
    free(chunks);
    free(tids);
    return ts_ok(err);
}
