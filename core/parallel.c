/* Parallel-for on POSIX threads; no pool, no global state. Each thread
 * takes its creator's locale (uselocale), so that a caller that holds the
 * "C" locale while the process has the user's (the GDAL driver, whose
 * numbers must read and print with a '.') has it in its workers too. */
#include <locale.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "parallel.h"
#include "status_internal.h"

int ts_cpu_count(void)
{
    /* the CPUs this process may run on (taskset, a container's cpuset):
     * all the online ones ran twice the threads under taskset -c 0 */
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set);
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
    locale_t locale; /* the creator's */
} chunk;

static void *run_chunk(void *arg)
{
    chunk *c = arg;
    if (c->worker > 0)
        uselocale(c->locale);
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
    const locale_t loc = uselocale((locale_t)0);
    for (int t = 0; t < threads; t++)
        chunks[t] = (chunk){fn, ctx, t, items * t / threads, items * (t + 1) / threads, &state,
                            loc};
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

struct ts_range_queue {
    atomic_long next;
    long items, grain;
    int threads;
};

int ts_range_next(ts_range_queue *q, long *begin, long *end)
{
    long at = atomic_load_explicit(&q->next, memory_order_relaxed), n;
    do {
        if (at >= q->items)
            return 0;
        const long left = q->items - at;
        /* guided: half of what is left, split among the threads, in
         * whole grains */
        n = (left / (2L * q->threads) + q->grain - 1) / q->grain * q->grain;
        n = n < q->grain ? q->grain : n;
        n = n > left ? left : n;
    } while (!atomic_compare_exchange_weak_explicit(&q->next, &at, at + n, memory_order_relaxed,
                                                    memory_order_relaxed));
    *begin = at;
    *end = at + n;
    return 1;
}

typedef struct {
    ts_ranges_fn fn;
    void *ctx;
    int worker;
    ts_range_queue *q;
    locale_t locale; /* the creator's */
} ranges_worker;

static void *run_ranges(void *arg)
{
    ranges_worker *r = arg;
    uselocale(r->locale);
    r->fn(r->ctx, r->worker, r->q);
    return NULL;
}

ts_status ts_parallel_ranges(int threads, long items, long grain, ts_ranges_fn fn, void *ctx,
                             ts_error *err)
{
    if (items <= 0)
        return ts_ok(err);
    ts_range_queue q;
    atomic_init(&q.next, 0);
    q.items = items;
    q.grain = grain < 1 ? 1 : grain;
    const long most = (items + q.grain - 1) / q.grain; /* ranges there can be */
    q.threads = threads < 1 ? 1 : threads > most ? (int)most : threads;
    ranges_worker *w = q.threads > 1 ? malloc((size_t)q.threads * sizeof *w) : NULL;
    pthread_t *tids = q.threads > 1 ? malloc((size_t)q.threads * sizeof *tids) : NULL;
    int started = 1;
    const locale_t loc = uselocale((locale_t)0);
    if (w && tids)
        for (int t = 1; t < q.threads; t++) {
            w[t] = (ranges_worker){fn, ctx, t, &q, loc};
            if (pthread_create(&tids[t], NULL, run_ranges, &w[t]) != 0)
                break;
            started++;
        }
    /* (no thread made: the calling one takes every range) */
    fn(ctx, 0, &q);
    for (int t = 1; t < started; t++)
        pthread_join(tids[t], NULL);
    free(w);
    free(tids);
    return ts_ok(err);
}

typedef struct {
    ts_range_fn fn;
    void *ctx;
} range_fn_each;

static void each_range(void *ctx, int worker, ts_range_queue *q)
{
    const range_fn_each *e = ctx;
    long begin, end;
    while (ts_range_next(q, &begin, &end))
        e->fn(e->ctx, worker, begin, end);
}

ts_status ts_parallel_for_ranges(int threads, long items, long grain, ts_range_fn fn, void *ctx,
                                 ts_error *err)
{
    range_fn_each e = {fn, ctx};
    return ts_parallel_ranges(threads, items, grain, each_range, &e, err);
}

/* One batch of ts_parallel_reported: fn over base + [begin, end). */
typedef struct {
    ts_range_fn fn;
    void *ctx;
    long base;
} batch_of;

static void batch_range(void *ctx, int worker, long begin, long end)
{
    const batch_of *b = ctx;
    b->fn(b->ctx, worker, b->base + begin, b->base + end);
}

ts_status ts_parallel_reported(int threads, long items, long grain, ts_range_fn fn, void *ctx,
                               const ts_horizon_opts *report, double from, double to,
                               int batches, ts_error *err)
{
    if (!report || !report->progress)
        batches = 1;
    ts_status st = TS_OK;
    for (int k = 0; st == TS_OK && k < batches; k++) {
        batch_of b = {fn, ctx, items * k / batches};
        const long n = items * (k + 1) / batches - b.base;
        if (batches > 1 && (st = ts_progress(report, from + (to - from) * k / batches, err)) !=
                               TS_OK)
            break;
        if (n > 0)
            st = grain > 0 ? ts_parallel_for_ranges(threads, n, grain, batch_range, &b, err)
                           : ts_parallel_for(threads, n, batch_range, &b, err);
    }
    return st;
}
