/*
 * cl_host_guard.h - calls into the OpenCL drivers kept from harming the
 * host process (internal to the OpenCL backend).
 *
 * The drivers run inside the host's process (QGIS, a Python script), and
 * PoCL, Debian's CPU driver, with its LLVM, was found (session 55) to:
 * - need a deep stack: its probe of the CPU and its clang overflowed a
 *   host's thread of 64 KiB (SIGSEGV);
 * - take 15 signals over for the whole process when it starts (LLVM's crash
 *   handlers: HUP, INT, QUIT, ILL, TRAP, ABRT, BUS, FPE, USR1, SEGV, USR2,
 *   TERM, XCPU, XFSZ, SYS), which swallowed a host's SIGUSR1 (Python's
 *   faulthandler dump) and un-ignored its SIGXFSZ;
 * - leave threads that a fork() does not copy: an OpenCL call in the child
 *   of a process that had set OpenCL up waits for them for ever.
 */
#ifndef TS_CL_HOST_GUARD_H
#define TS_CL_HOST_GUARD_H

/* fn(arg) on a thread of its own with an 8 MiB stack (on the caller's
 * where no such thread can be made), in the caller's locale, the process
 * marked as having set OpenCL up (ts_cl_host_forked); every signal
 * disposition the call changed is put back as it was before it (one call
 * at a time: a second caller would take the drivers' handlers for the
 * host's). A host that sets a disposition on another thread while the
 * drivers start (~50 ms) may have it undone. fn must not call this. */
void ts_cl_host_call(void *(*fn)(void *), void *arg);

/* Record that this process has set OpenCL up (its drivers are loaded). */
void ts_cl_host_mark_loaded(void);

/* 1 if OpenCL was set up in a parent process before a fork() that made
 * this one (pthread_atfork): the drivers' threads stayed there, and OpenCL
 * must not be used here. */
int ts_cl_host_forked(void);

#endif
