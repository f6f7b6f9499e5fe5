/* cl_host_guard.c - see cl_host_guard.h. */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#include <locale.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>

#include "cl_host_guard.h"

/*
 * Signals. Every disposition the call changed is put back: the drivers'
 * libraries may be in the process before the call (Mesa's llvmpipe links
 * libLLVM, QGIS may have loaded PoCL), so whose handler it is says nothing.
 * The calls take turns (one mutex), so that a second caller does not take
 * the drivers' handlers for the host's.
 */
static pthread_mutex_t g_turn = PTHREAD_MUTEX_INITIALIZER;

typedef struct {
    struct sigaction act[NSIG];
    unsigned char saved[NSIG];
} signal_state;

static void signals_save(signal_state *s)
{
    for (int i = 1; i < NSIG; i++)
        s->saved[i] = i != SIGKILL && i != SIGSTOP && sigaction(i, NULL, &s->act[i]) == 0;
}

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
    locale_t locale; /* the caller's: the drivers run in it, as they did */
} host_call;

static void *guarded(void *p)
{
    const host_call *c = p;
    locale_t old = uselocale(c->locale);
    pthread_mutex_lock(&g_turn);
    signal_state *s = calloc(1, sizeof *s);
    if (s)
        signals_save(s);
    /* the thread's alternate signal stack too: LLVM gives the thread that
     * installs its handlers one of its own (malloc'd), and AddressSanitizer,
     * which gave the thread its own, aborted as the thread ended ("unable
     * to unmap") */
    stack_t alt;
    const int alt_saved = sigaltstack(NULL, &alt) == 0;
    c->fn(c->arg);
    if (alt_saved) {
        alt.ss_flags &= ~SS_ONSTACK;
        sigaltstack(&alt, NULL);
    }
    if (s)
        signals_restore(s);
    free(s);
    pthread_mutex_unlock(&g_turn);
    uselocale(old);
    return NULL;
}

void ts_cl_host_call(void *(*fn)(void *), void *arg)
{
    ts_cl_host_mark_loaded(); /* before the turn: see in_child */
    host_call c = {fn, arg, uselocale((locale_t)0)};
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

/*
 * fork(). A child's flag is set by pthread_atfork's child handler, which
 * runs in every child made after OpenCL was set up (a pid compared with the
 * setter's missed a child that got a pid reused, or PID 1 in a new pid
 * namespace). The child also gets the turns' mutex afresh: a fork while
 * another thread held it left it locked for ever there.
 */
static atomic_int g_loaded;
static atomic_int g_forked;
static pthread_once_t g_atfork_once = PTHREAD_ONCE_INIT;

static void in_child(void)
{
    pthread_mutex_t fresh = PTHREAD_MUTEX_INITIALIZER;
    g_turn = fresh;
    if (atomic_load(&g_loaded))
        atomic_store(&g_forked, 1);
}

static void register_atfork(void)
{
    pthread_atfork(NULL, NULL, in_child);
}

void ts_cl_host_mark_loaded(void)
{
    pthread_once(&g_atfork_once, register_atfork);
    atomic_store(&g_loaded, 1);
}

int ts_cl_host_forked(void)
{
    return atomic_load(&g_forked);
}
