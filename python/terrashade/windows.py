"""Windows of a product and the task that reads one through the driver.

This module runs on the Dask workers: it needs osgeo.gdal and the
TERRASHADE plugin there (GDAL_DRIVER_PATH or the installed plugin), not
dask. Functions are sent to workers by reference, so the workers import
terrashade (installed by `make install`, or on PYTHONPATH).
"""
import contextlib
import os
import socket
import threading

from osgeo import gdal

# One open dataset per worker thread: GDAL datasets are not thread-safe, and
# keeping the dataset open lets a worker's later windows reuse what the
# driver has cached (the far-field grid and recent chunks, or the whole
# product where it is computed whole) instead of recomputing it for every
# window. Only within a run: a worker of an existing cluster outlives the
# run, and the DEM may be rewritten at the same name before the next one;
# the client calls forget() at the end. {thread id: (key, dataset)}
_open = {}
_open_lock = threading.Lock()

# Test hook (tests/driver/test_distributed.py): the path of a flag file. The
# first task that manages to create it kills its own worker process, so the
# run loses a worker mid-way exactly once and Dask must retry the window.
CRASH_ONCE_ENV = "TERRASHADE_DISTRIBUTED_CRASH_ONCE"


def windows(width, height, tile):
    """(xoff, yoff, xsize, ysize) of every tile x tile window, row by row;
    the last column and row are cut to the raster's size."""
    if tile < 1:  # (none for a negative one: an empty product written)
        raise ValueError("the window size must be at least 1 cell, got %r" % tile)
    return [(x, y, min(tile, width - x), min(tile, height - y))
            for y in range(0, height, tile) for x in range(0, width, tile)]


def no_driver(where, driver_path):
    """The sentence for GDAL `where` (on which machine) without the
    TERRASHADE driver, its GDAL_DRIVER_PATH being driver_path."""
    return ("GDAL %s cannot find the TERRASHADE driver: set GDAL_DRIVER_PATH there (now %r) "
            "to the directory of gdal_TERRASHADE.so, or install the plugin (make install)"
            % (where, driver_path))


def placement(wins, chunk, workers):
    """For each window, the worker whose dataset computes its driver chunk
    (chunk cells square from the raster's corner, or the whole raster where
    chunk is 0): the windows of one chunk on one worker, the chunks dealt
    round the workers in order, so that no chunk is computed by two workers
    (windows were dealt to any worker, and each one given a window of a
    chunk computed the chunk: svf over a 2048^2 DEM in chunks of 512,
    windows of 128, two workers, 29 s of CPU, now 20). None for every window
    where no worker is known."""
    if not workers:
        return [None] * len(wins)
    order = {}
    for x, y, _, _ in wins:
        order.setdefault((x // chunk, y // chunk) if chunk else (0, 0), len(order))
    return [workers[order[(x // chunk, y // chunk) if chunk else (0, 0)] % len(workers)]
            for x, y, _, _ in wins]


def _dataset(source, open_options, run):
    key, me = (source, tuple(open_options), run), threading.get_ident()
    with _open_lock:
        held = _open.get(me)
        if held is not None and held[0] == key:
            return held[1]
        _open.pop(me, None)
    del held  # the previous one closes before the next opens: bounded memory
    if gdal.GetDriverByName("TERRASHADE") is None:
        # a worker that joined after the start's check (probe): GDAL's open
        # then failed with no message at all
        raise RuntimeError(no_driver("on the worker at %s" % socket.gethostname(),
                                     os.environ.get("GDAL_DRIVER_PATH", "")))
    ds = gdal.OpenEx(source, gdal.OF_RASTER | gdal.OF_READONLY, open_options=list(open_options))
    if ds is None:  # (with GDAL's exceptions off; on, OpenEx raised)
        raise RuntimeError("cannot open %s: %s" % (source, gdal.GetLastErrorMsg()))
    with _open_lock:
        _open[me] = (key, ds)
    return ds


def forget(run):
    """On a worker, after a run: drop the datasets its tasks opened, with
    their far grid and cached chunks (GiB for a large horizon), which a
    worker of an existing cluster would hold until the next run. A task
    still reading keeps its own reference until it returns."""
    with _open_lock:
        for me in [me for me, (key, _) in _open.items() if key[2] == run]:
            del _open[me]


def _maybe_crash():
    flag = os.environ.get(CRASH_ONCE_ENV)
    if not flag:
        return
    try:
        fd = os.open(flag, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return
    os.close(fd)
    os._exit(17)


@contextlib.contextmanager
def gdal_exceptions():
    """GDAL's exceptions on within, the caller's setting back after: the
    package's own calls raise, and a script that imports it keeps its
    mode (this module's functions work in either)."""
    was = gdal.GetUseExceptions()
    gdal.UseExceptions()
    try:
        yield
    finally:
        if not was:
            gdal.DontUseExceptions()


class Warnings:
    """GDAL's warnings while it is pushed (gdal.PushErrorHandler, this
    thread's), each once, in order; errors still raise where GDAL's
    exceptions are on (they come from the last error, which the handler
    does not clear), else the caller tests what GDAL returned."""

    def __init__(self):
        self.messages = []

    def __call__(self, level, number, message):
        if level == gdal.CE_Warning and (number, message) not in self.messages:
            self.messages.append((number, message))


def read_window(source, open_options, window, run):
    """(window, the product's pixels in window (xoff, yoff, xsize, ysize) as
    an array of shape (bands, ysize, xsize), the driver's warnings as
    (number, message) pairs), read through the driver; run names the run
    (its tasks share a worker thread's dataset). The warnings go back to the
    client, which says each once: printed here, every worker of a local
    cluster repeated the client's on the same terminal, and an existing
    cluster's went to the workers' logs."""
    _maybe_crash()
    said = Warnings()
    gdal.PushErrorHandler(said)
    try:
        ds = _dataset(source, open_options, run)
        xoff, yoff, xsize, ysize = window
        a = ds.ReadAsArray(xoff, yoff, xsize, ysize)
    finally:
        gdal.PopErrorHandler()
    if a is None:
        raise RuntimeError("reading window %r of %s failed: %s"
                           % (window, source, gdal.GetLastErrorMsg()))
    return window, a.reshape((ds.RasterCount, ysize, xsize)), said.messages


def probe():
    """On a worker: whether GDAL there finds the TERRASHADE driver."""
    drv = gdal.GetDriverByName("TERRASHADE")
    return {"driver": drv is not None, "gdal": gdal.__version__,
            "GDAL_DRIVER_PATH": os.environ.get("GDAL_DRIVER_PATH", "")}


def ignore_interrupts():
    """On a worker of the run's own local cluster, once it has started:
    Ctrl-C ignored, SIGTERM ending it again. A Ctrl-C at the terminal
    signals the whole process group; the run's process closes its workers,
    while each printed its own KeyboardInterrupt tracebacks. The worker was
    started with both blocked (_distributed_cluster.loop_without_ctrl_c);
    SIGTERM is unblocked here, so that Dask's and multiprocessing's
    terminate() end it where the cluster's close does not. Run on the
    worker's event loop, its main thread."""
    import signal
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the main thread: Ctrl-C stays as it was
        return False
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    return True
