"""terrashade.distributed: the Dask cluster: started (Ctrl-C and SIGTERM
held until it has) or reached, its workers checked, and watched during the
run; SIGTERM cleaned up as Ctrl-C."""
import asyncio
import contextlib
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time

from terrashade import windows as W
from terrashade._distributed_inputs import PROG
from terrashade._distributed_report import LOST, Failure


def dask_logs(level):
    """Only Dask's logs of level and above reach stderr, as LocalCluster's
    silence_logs: on its handlers, as Dask's configuration gives its loggers
    their own levels."""
    for handler in logging.getLogger("distributed").handlers:
        handler.setLevel(level)


def cores():
    """The cores this process may run on (taskset, a container's cpuset), as
    the driver's THREADS=0 takes them: os.cpu_count() counts every online one."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def start_cluster(args):
    """(client, cluster or None, task options to add)."""
    from dask.distributed import Client, LocalCluster
    if args.scheduler:
        try:
            client = Client(args.scheduler, timeout="%ds" % args.timeout)
        except ValueError as e:  # not an address: no port, an unknown scheme...
            raise Failure("--scheduler %s is not a Dask scheduler address such as "
                          "tcp://host:8786 (%s)" % (args.scheduler, e), code=2)
        except TypeError as e:  # tls:// without Dask's TLS settings (no SSL context)
            raise Failure("--scheduler %s needs Dask's TLS settings: the CA, certificate and "
                          "key in the Dask configuration (distributed.comm.tls.*, e.g. "
                          "DASK_DISTRIBUTED__COMM__TLS__CA_FILE and __CLIENT__CERT/__KEY) "
                          "(%s)" % (args.scheduler, e), code=2)
        except (OSError, TimeoutError) as e:
            raise Failure("cannot reach the Dask scheduler at %s within %d s: %s"
                          % (args.scheduler, args.timeout, e), code=2)
        dask_logs(logging.CRITICAL)  # as the local cluster's: the program says what failed
        # A worker has one task slot per thread, by default one per core.
        return client, None, 1
    workers = args.workers or cores()
    runner = loop_without_ctrl_c()
    before = children()
    from distributed.deploy.spec import SpecCluster
    clusters_before = set(SpecCluster._instances)
    try:
        # on this machine's loopback only, with its HTTP servers on free ports:
        # dashboard_address=None still served the scheduler's on 0.0.0.0:8787,
        # reachable from other machines, and warned where that port was taken;
        # Dask's logs below CRITICAL unsaid: the program says what failed, where
        # a killed worker's "Couldn't gather keys" ERROR lines came before it
        cluster = OwnCluster(LocalCluster(
            n_workers=workers, threads_per_worker=args.threads_per_worker, processes=True,
            host="127.0.0.1", dashboard_address="127.0.0.1:0",
            worker_dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL,
            loop=runner.loop), runner, before)
    except BaseException:
        # a start cut short (a second Ctrl-C): its workers, still blocking
        # SIGTERM, would hold the exit handlers' terminate() and join().
        # The IO loop is stopped first, so that their nannies do not
        # restart them (they did, and the new ones woke to a parent gone and
        # printed tracebacks): the half-started cluster holds the loop too.
        # Dask's exit handler is kept from that cluster (it asserted on its
        # workers' state).
        for c in set(SpecCluster._instances) - clusters_before:
            with contextlib.suppress(Exception):
                c._loop_runner.stop()
            SpecCluster._instances.discard(c)
        runner.stop()
        kill_children_since(before)
        raise
    slots = workers * args.threads_per_worker
    try:
        client = Client(cluster.cluster)
    except BaseException:
        cluster.close()
        raise
    return client, cluster, max(1, cores() // slots)


def loop_without_ctrl_c():
    """A running IO loop for the run's local cluster, its thread started with
    SIGINT and SIGTERM blocked. The cluster's worker processes are started
    from threads of that thread and keep its signal mask through fork and
    exec, so a Ctrl-C at the terminal, or a SIGTERM to the whole process
    group (systemd's or Slurm's stop), does not reach them while they
    start: one then left them half started or gone and the cluster's start
    waiting for ever. This process's main thread still gets both
    (interrupts_held) and closes the cluster. Once started, the workers
    ignore SIGINT and take SIGTERM again (windows.ignore_interrupts); a
    worker the run's interrupt kept from that is killed where the close
    fails (OwnCluster.close)."""
    from distributed.utils import LoopRunner
    from multiprocessing import resource_tracker
    # started first: started by a spawn in the loop's thread, it would end
    # with SIG_UNBLOCK there (CPython's launcher), the mask lost
    resource_tracker.ensure_running()
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        runner = LoopRunner(asynchronous=False)
        runner.start()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
    return runner


class OwnCluster:
    """The run's LocalCluster and the loop it runs on: closed together. Its
    workers are this process's children started since `before` (their pids)."""

    def __init__(self, cluster, runner, before):
        self.cluster, self.runner, self.before = cluster, runner, before

    def close(self):
        try:
            self.cluster.close()
        except BaseException:
            # its workers may still block SIGTERM (stopped during their
            # start): the exit handlers' terminate() and join() would wait
            # for them for ever
            kill_children_since(self.before)
            raise
        finally:
            self.runner.stop()


def children():
    """The pids of this process's multiprocessing children: those it has
    registered, and on Linux those /proc lists as its children running
    multiprocessing's spawn (one started but not yet registered), not a
    script's other subprocesses."""
    pids = {p.pid for p in multiprocessing.active_children() if p.pid}
    me = os.getpid()
    with contextlib.suppress(OSError):
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open("/proc/%s/stat" % entry) as f:
                    stat = f.read()
                # the field after the command name, which may hold ")"
                if int(stat.rsplit(")", 1)[1].split()[1]) != me:
                    continue
                with open("/proc/%s/cmdline" % entry, "rb") as f:
                    if b"multiprocessing" in f.read():
                        pids.add(int(entry))
            except (OSError, ValueError, IndexError):
                continue
    return pids


def kill_children_since(before):
    """SIGKILL to this process's children (the local cluster's workers,
    restarted ones too) whose pids are not in before."""
    for pid in children() - before:
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)


class Watch:
    """Whether the cluster can still finish the run. Dask cancels every
    future at once when the client's connection to the scheduler closes,
    but waits for ever on a scheduler that answers nothing (its machine or
    the network gone) and on a cluster without workers: the run checks the
    scheduler's answer (within --timeout) and its workers (none for longer
    than --timeout) whenever a second has passed without a window."""

    EVERY = 1.0  # s between checks

    def __init__(self, client, timeout, dest):
        self.client, self.timeout, self.dest = client, timeout, dest
        self.address = client.scheduler.address
        self.lost = False  # then the client's scheduler calls would hang or fail
        self.checked = self.workers_seen = time.monotonic()

    def fail(self, what, why, done=None, total=None):
        self.lost = True
        # The client's close then cancels its reconnection, which Dask logs with
        # tracebacks, in part through asyncio's logger (the root's last resort).
        dask_logs(logging.CRITICAL)
        logging.getLogger().setLevel(logging.CRITICAL)
        when = ("during the run, after %d of %d windows" % (done, total) if total
                else "before the run's windows were submitted")
        raise Failure("lost %s at %s %s: %s; nothing written to %s: run the command again "
                      "once the cluster is back (a run starts over)"
                      % (what, self.address, when, why, self.dest), code=LOST)

    def connected(self, done=None, total=None):
        if self.client.status != "running":  # "connecting" again, or closed: futures lost
            self.fail("the Dask scheduler", "its connection closed (the scheduler ended, "
                      "or its machine or the network went away)", done, total)

    def check(self, done, total):
        self.connected(done, total)
        now = time.monotonic()
        if now - self.checked < self.EVERY:
            return
        try:
            workers = self.client.sync(self.client.scheduler.ncores,
                                       callback_timeout=self.timeout)
        except asyncio.TimeoutError:
            self.fail("the Dask scheduler", "it did not answer for %d s (--timeout)"
                      % self.timeout, done, total)
        except OSError as e:  # Dask's CommClosedError too
            self.connected(done, total)
            self.fail("the Dask scheduler", "%s: %s" % (type(e).__name__, e), done, total)
        self.checked = now = time.monotonic()
        if workers:
            self.workers_seen = now
        elif now - self.workers_seen > self.timeout:
            self.fail("the workers of the Dask cluster", "the scheduler has had none for "
                      "%d s (--timeout)" % self.timeout, done, total)


def check_workers(client, watch):
    """The workers' count, once every one can run the tasks; waits up to
    --timeout for a first worker (a cluster's may still be starting)."""
    try:
        if not client.scheduler_info().get("workers"):
            client.wait_for_workers(1, timeout=watch.timeout)
    except (asyncio.TimeoutError, TimeoutError):
        watch.connected()
        raise Failure("the Dask cluster at %s has no workers (none joined within %d s, "
                      "--timeout): start them (dask-worker %s)"
                      % (watch.address, watch.timeout, watch.address), code=2)
    try:
        found = client.run(W.probe)
    except Exception as e:
        watch.connected()
        raise Failure("the Dask workers cannot run terrashade's tasks (%s): install "
                      "the terrashade package on them (make install) or put it on "
                      "their PYTHONPATH" % e)
    if not found:
        raise Failure("the Dask cluster at %s has no workers" % watch.address, code=2)
    missing = [w for w, r in found.items() if not r["driver"]]
    if missing:
        raise Failure(W.no_driver("on worker(s) %s" % ", ".join(missing),
                                  found[missing[0]]["GDAL_DRIVER_PATH"]))
    return len(found)


class Terminated(KeyboardInterrupt):
    """SIGTERM (timeout, Slurm, systemd, Kubernetes...), cleaned up as Ctrl-C;
    Python's default ends the program at once and left DEST.partial behind."""


def _terminate(_signum, _frame):
    raise Terminated()


@contextlib.contextmanager
def interrupts_held():
    """Ctrl-C and SIGTERM held while a cluster starts, raised once it has
    (at the end of the with block, after the caller holds the cluster to
    close): a LocalCluster cut short in its start was left for Dask's exit
    handler, which printed its tracebacks. A second signal is raised at
    once: the start may never end (below)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got = []

    def held(signum, _frame):
        # a second one: the user insists (a start can wait for ever on
        # workers that a Ctrl-C sent to the whole process group ended)
        if got:
            raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()
        got.append(signum)
        print("%s: %s while the Dask cluster starts: stopping once it has (again "
              "to stop at once)" % (PROG, "terminated" if signum == signal.SIGTERM
                                    else "interrupted"), file=sys.stderr, flush=True)
    # (a signal the process ignores stays ignored: a run started in the
    # background of a script, `... &`, has SIGINT ignored and must not stop
    # at a Ctrl-C to the terminal's process group)
    previous = {s: signal.signal(s, held) for s in (signal.SIGINT, signal.SIGTERM)
                if signal.getsignal(s) is not signal.SIG_IGN}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if got:
        raise Terminated() if got[0] == signal.SIGTERM else KeyboardInterrupt()
