/* cl_host_guard.c - see cl_host_guard.h. */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#include "cl_host_guard.h"

/* The dispositions of every signal a process may catch. */
typedef struct {
    struct sigaction act[NSIG];
    unsigned char saved[NSIG];
} signal_state;

static void signals_save(signal_state *s)
{
    for (int i = 1; i < NSIG; i++)
        s->saved[i] = i != SIGKILL && i != SIGSTOP && sigaction(i, NULL, &s->act[i]) == 0;
}

/* Only those that changed: a disposition set again to itself is a no-op,
 * but a host's handler installed meanwhile on another thread stays. */
static void signals_restore(const signal_state *s)
{
    for (int i = 1; i < NSIG; i++) {
        struct sigaction now;
        if (s->saved[i] && sigaction(i, NULL, &now) == 0 &&
            (now.sa_handler != s->act[i].sa_handler || now.sa_flags != s->act[i].sa_flags))
            sigaction(i, &s->act[i], NULL);
    }
}

typedef struct {
    void *(*fn)(void *);
    void *arg;
} host_call;

static void *guarded(void *p)
{
    const host_call *c = p;
    signal_state *s = malloc(sizeof *s);
    if (s)
        signals_save(s);
    c->fn(c->arg);
    if (s)
        signals_restore(s);
    free(s);
    return NULL;
}

void ts_cl_host_call(void *(*fn)(void *), void *arg)
{
    host_call c = {fn, arg};
    pthread_attr_t attr;
    pthread_t tid;
    int made = 0;
    if (pthread_attr_init(&attr) == 0) {
        made = pthread_attr_setstacksize(&attr, (size_t)8 << 20) == 0 &&
               pthread_create(&tid, &attr, guarded, &c) == 0;
        pthread_attr_destroy(&attr);
    }
    if (made)
        pthread_join(tid, NULL);
    else
        guarded(&c);
}

static atomic_long g_loaded_by; /* the pid that set OpenCL up, 0: none */

void ts_cl_host_mark_loaded(void)
{
    long none = 0;
    atomic_compare_exchange_strong(&g_loaded_by, &none, (long)getpid());
}

int ts_cl_host_forked(void)
{
    const long by = atomic_load(&g_loaded_by);
    return by != 0 && by != (long)getpid();
}
