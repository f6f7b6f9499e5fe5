/* cl_host_guard.c - see cl_host_guard.h. */
#ifdef HAVE_CONFIG_H
#include <config.h>
#endif

#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* dladdr, dl_iterate_phdr */
#endif
#include <dlfcn.h>
#include <link.h>
#include <locale.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "cl_host_guard.h"

/*
 * Signals. A disposition is put back only when the call set it to a
 * handler in a library the OpenCL drivers brought into the process (one
 * loaded during a guarded call: libLLVM, libpocl...): a host's handler set
 * meanwhile on another thread stays. The calls take turns (one mutex), so
 * that a second caller does not take the drivers' handlers for the host's.
 */
#define MAX_DRIVER_LIBS 64

static pthread_mutex_t g_turn = PTHREAD_MUTEX_INITIALIZER;
static const char *g_driver_libs[MAX_DRIVER_LIBS]; /* under g_turn */
static int g_driver_lib_count;

typedef struct {
    struct sigaction act[NSIG];
    unsigned char saved[NSIG];
    char **libs; /* the objects loaded before the call, NULL-ended */
    int lib_count, lib_room;
} signal_state;

static int add_loaded(struct dl_phdr_info *info, size_t size, void *p)
{
    (void)size;
    signal_state *s = p;
    if (s->lib_count + 1 >= s->lib_room) {
        const int room = s->lib_room ? 2 * s->lib_room : 64;
        char **grown = realloc(s->libs, (size_t)room * sizeof *grown);
        if (!grown)
            return 1;
        s->libs = grown;
        s->lib_room = room;
    }
    s->libs[s->lib_count++] = strdup(info->dlpi_name ? info->dlpi_name : "");
    s->libs[s->lib_count] = NULL;
    return 0;
}

static int was_loaded(const signal_state *s, const char *name)
{
    for (int i = 0; i < s->lib_count; i++)
        if (s->libs[i] && !strcmp(s->libs[i], name))
            return 1;
    return 0;
}

static int is_driver_lib(const char *name)
{
    for (int i = 0; i < g_driver_lib_count; i++)
        if (!strcmp(g_driver_libs[i], name))
            return 1;
    return 0;
}

/* Remember the objects that came during the call as the drivers'. */
static int note_new(struct dl_phdr_info *info, size_t size, void *p)
{
    (void)size;
    const signal_state *s = p;
    const char *name = info->dlpi_name ? info->dlpi_name : "";
    if (*name && !was_loaded(s, name) && !is_driver_lib(name) &&
        g_driver_lib_count < MAX_DRIVER_LIBS) {
        char *kept = strdup(name);
        if (kept)
            g_driver_libs[g_driver_lib_count++] = kept;
    }
    return 0;
}

static void signals_save(signal_state *s)
{
    for (int i = 1; i < NSIG; i++)
        s->saved[i] = i != SIGKILL && i != SIGSTOP && sigaction(i, NULL, &s->act[i]) == 0;
    dl_iterate_phdr(add_loaded, s);
}

static void signals_restore(signal_state *s)
{
    dl_iterate_phdr(note_new, s);
    for (int i = 1; i < NSIG; i++) {
        struct sigaction now;
        Dl_info where;
        if (!s->saved[i] || sigaction(i, NULL, &now) != 0 ||
            (now.sa_handler == s->act[i].sa_handler && now.sa_flags == s->act[i].sa_flags))
            continue;
        void *fn = (now.sa_flags & SA_SIGINFO) ? (void *)now.sa_sigaction
                                               : (void *)now.sa_handler;
        if (fn != (void *)SIG_DFL && fn != (void *)SIG_IGN && dladdr(fn, &where) &&
            where.dli_fname && is_driver_lib(where.dli_fname))
            sigaction(i, &s->act[i], NULL);
    }
    for (int i = 0; i < s->lib_count; i++)
        free(s->libs[i]);
    free(s->libs);
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
    c->fn(c->arg);
    if (s)
        signals_restore(s);
    free(s);
    pthread_mutex_unlock(&g_turn);
    uselocale(old);
    return NULL;
}

void ts_cl_host_call(void *(*fn)(void *), void *arg)
{
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
 * namespace).
 */
static atomic_int g_loaded;
static atomic_int g_forked;
static pthread_once_t g_atfork_once = PTHREAD_ONCE_INIT;

static void in_child(void)
{
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
