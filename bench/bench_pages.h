/* bench_pages.h - first mapping of a benchmark's buffers, outside its timings.
 *
 * The kernel maps a page of a fresh allocation on its first write. On the
 * development VM that cost 4-23 us a page (docs/performance-history.md, "Pyramid
 * horizons, session 14"), charged to whichever timed run first writes the
 * buffer: in a bench that compares runs sharing one output, the first run's
 * time would include it and the others' not. Benches therefore write every
 * page of their outputs once before timing anything. */
#ifndef BENCH_PAGES_H
#define BENCH_PAGES_H

#include <stddef.h>

/* One write to every page of p's `bytes` (volatile: a memset of zeros right
 * after malloc may be turned into calloc, which writes nothing). */
static inline void bench_touch_pages(void *p, size_t bytes)
{
    volatile unsigned char *b = p;
    for (size_t i = 0; i < bytes; i += 4096)
        b[i] = 0;
}

#endif
