"""Run a TERRASHADE product over a DEM as window tasks on dask.distributed.

    python3 -m terrashade.distributed [--scheduler ADDRESS | --workers N]
        [--tile-size N] [-oo KEY=VALUE ...] SOURCE DEST

SOURCE is a TERRASHADE connection string (TERRASHADE:PRODUCT=svf:dem.tif),
DEST a tiled GeoTIFF or a COG. The client opens SOURCE once for the
product's size, bands, types, nodata, georeferencing and metadata, creates
DEST.partial, submits one task per --tile-size window (each task reads its
window through the driver on a worker) and writes the windows as they
complete, through one dataset, then renames DEST.partial to DEST. Any
failure removes what was written and exits non-zero (3 where the cluster was
lost during the run). See docs/distributed.md.
"""
import contextlib
import logging
import os
import signal
import sys
import threading
import time
import uuid

try:
    from osgeo import gdal  # (the check; the modules below use it too)
except ImportError as _e:  # a Python without GDAL's bindings: a sentence, not a traceback
    sys.exit("terrashade.distributed: error: this Python (%s) cannot import GDAL's "
             "bindings (%s); run it with one that can, e.g. /usr/bin/python3 with "
             "Debian's python3-gdal" % (sys.executable, _e))

# After the check above: these import GDAL. The run's parts, in modules by
# job; their names are this module's too (terrashade.distributed.X, as
# before they moved there).
from terrashade import windows as W  # noqa: E402
from terrashade._distributed_report import (  # noqa: E402,F401
    LOST, SAID, Failure, ProgressBar, Said)
from terrashade._distributed_inputs import (  # noqa: E402,F401
    INLINE, PROG, TILE_MAX, TILE_MIN, _ITEM, absolute_env_map, absolute_path, absolute_source,
    given_keys, local_file, open_source, parse_args, positive, split_source, tile_size)
from terrashade._distributed_output import (  # noqa: E402,F401
    RENAMED, SIDE_FILES, block_size, create_like, finish, output_format, partial_names, remove,
    written)
from terrashade._distributed_cluster import (  # noqa: E402,F401
    Terminated, Watch, _terminate, check_workers, dask_logs, interrupts_held, start_cluster)


def compute(client, watch, out, source, task_options, tile, chunk, quiet, run):
    from dask.distributed import as_completed
    wins = W.windows(out.RasterXSize, out.RasterYSize, tile)
    # each chunk's windows on one worker (loosely: another takes them where
    # it is gone or idle), whose dataset computes the chunk once
    workers = sorted(client.scheduler_info().get("workers", {}))
    futures = [client.submit(W.read_window, source, task_options, w, run, pure=False,
                             workers=None if at is None else [at], allow_other_workers=True)
               for w, at in zip(wins, W.placement(wins, chunk, workers))]
    window_of = dict(zip((f.key for f in futures), wins))
    bar = None if quiet else ProgressBar(futures)
    # Written windows are released so that the workers drop them, but not
    # before the bar's scheduler side has seen every key: it waits for all
    # of them, and a key forgotten first would leave it waiting for ever.
    held = []
    done = 0
    pending = as_completed(futures)
    try:
        while not pending.is_empty():
            batch = pending.next_batch(block=False)
            if not batch:  # as as_completed's own wait, but the cluster is watched
                watch.check(done, len(wins))
                time.sleep(0.1)
            for fut in batch:
                try:
                    (xoff, yoff, _, _), a, warned = fut.result()
                except Exception as e:
                    watch.connected(done, len(wins))  # cancelled with the connection
                    # a DEM (or ENV_MAP) a worker cannot open: say where it ran
                    where = (" (on a Dask worker, which must reach the DEM and ENV_MAP by "
                             "the same path as this machine: a shared file system, not "
                             "/vsimem/)" if "cannot open" in str(e) else "")
                    raise Failure("the window (xoff, yoff, xsize, ysize) = %r of %s "
                                  "failed: %s: %s%s" % (window_of[fut.key], source,
                                                        type(e).__name__, e, where))
                SAID.say(warned, bar)  # (its own errors are not the window's)
                for i in range(out.RasterCount):
                    out.GetRasterBand(i + 1).WriteArray(a[i], xoff, yoff)
                done += 1
                held.append(fut)
            if bar is None or bar.ready.is_set():
                for f in held:
                    f.release()
                held.clear()
    except BaseException:
        if bar is not None:
            bar.stop()
        if not watch.lost:  # else nothing to cancel, and no one to tell
            with contextlib.suppress(Exception):  # why the run failed comes first
                client.cancel(futures)
        raise
    if bar is not None:
        bar.thread.join(timeout=5)
    for f in held:
        f.release()
    return len(wins)


def dem_files(dem):
    """The local files GDAL reads for the DEM (a VRT's sources among them)."""
    try:
        ds = gdal.OpenEx(dem, gdal.OF_RASTER)
    except RuntimeError:
        return []
    files = (ds.GetFileList() or []) if ds is not None else []
    return [f for f in map(local_file, files) if f is not None]


def run(args):
    src = open_source(args.source, args.open_options)
    fmt = output_format(args)
    if args.dest.startswith("/vsi"):  # found now, not when the result is renamed to it
        raise Failure("cannot write %s: DEST must be a file path, not a GDAL virtual file "
                      "system: the result is written beside it and renamed into place; "
                      "write it to a local file and copy that" % args.dest)
    if os.path.isdir(args.dest):
        raise Failure("cannot write %s: it is a directory; DEST names the output file"
                      % args.dest)
    if os.path.exists(args.dest) and not os.path.isfile(args.dest):
        # the result is renamed into place: it would replace a pipe or a
        # device (/dev/null, run as root) with a file
        raise Failure("cannot write %s: it is not a regular file (a pipe, a device...); "
                      "DEST names the output file" % args.dest)
    block = block_size(args.tile_size)
    tiles_partial, dest_partial = partial_names(args.dest)
    partial = tiles_partial if fmt == "COG" else dest_partial
    dem = src.GetMetadataItem("SOURCE_DEM") or ""
    dem_file = local_file(dem)  # (an archive's: /vsizip/dem.zip/dem.tif onto dem.zip)
    if dem_file and os.path.exists(args.dest) and os.path.samefile(dem_file, args.dest):
        raise Failure("DEST %s is the DEM itself%s: the product would replace it; write "
                      "it to another file"
                      % (args.dest, "" if dem_file == dem else " (its archive, for %s)" % dem))
    for part in dem_files(dem):  # a VRT's sources: replaced the same way (exit 0)
        if os.path.exists(args.dest) and os.path.samefile(part, args.dest):
            raise Failure("DEST %s is a file of the DEM %s: the product would replace it; "
                          "write it to another file" % (args.dest, dem))
    env_map = src.GetMetadataItem("ENV_MAP") or ""
    if os.path.exists(env_map) and os.path.exists(args.dest) and \
            os.path.samefile(env_map, args.dest):
        raise Failure("DEST %s is the ENV_MAP of SOURCE: the product would replace it; "
                      "write it to another file" % args.dest)
    size = (src.RasterXSize, src.RasterYSize, src.RasterCount)
    # the driver's chunks (TILE_SIZE, where it windows: FAR_GRID), else the
    # whole product at once (0)
    chunk = int(src.GetMetadataItem("TILE_SIZE") or 0) if src.GetMetadataItem("FAR_GRID") else 0
    out = client = cluster = watch = None
    run_id = uuid.uuid4().hex  # no worker reuses a dataset opened for an earlier run
    t0 = time.time()
    try:  # from the partial's creation on: a Ctrl-C may come at any time
        out = create_like(src, partial, block, [] if fmt == "COG" else args.creation_options)
        src = None
        with interrupts_held():
            client, cluster, threads = start_cluster(args)
        watch = Watch(client, args.timeout, args.dest)
        nworkers = check_workers(client, watch)
        if cluster is not None:  # its workers: a Ctrl-C is this process's to handle
            client.run(W.ignore_interrupts)
        keys = given_keys(args.source, args.open_options)
        args.source, task_options = absolute_env_map(args.source, args.open_options)
        if "THREADS" not in keys:
            task_options.append("THREADS=%d" % threads)
        if "PROGRESS" not in keys:
            task_options.append("PROGRESS=no")  # the Dask bar says it
        tasks_source = absolute_source(args.source)
        SAID.same_dem = (split_source(tasks_source)[1], split_source(args.source)[1])
        n = compute(client, watch, out, tasks_source, task_options, args.tile_size, chunk,
                    args.quiet, run_id)
        out.FlushCache()
        out = None
        finish(partial, fmt, args.dest, args.creation_options, dest_partial)
    except BaseException:
        out = None
        remove(partial)
        remove(dest_partial)
        raise
    finally:
        if client is not None:
            if client.status == "running" and not (watch and watch.lost):
                # the workers close this run's datasets, within --timeout: a
                # worker that stopped answering (a stopped process) held an
                # interrupted run for Dask's 30 s connect timeout
                def forget():
                    with contextlib.suppress(Exception):
                        client.run(W.forget, run_id)
                t = threading.Thread(target=forget, daemon=True)
                t.start()
                t.join(args.timeout)
            with contextlib.suppress(Exception):  # bounded; a closing error hides no result
                client.close(timeout=args.timeout)
        if cluster is not None:
            cluster.close()
    if not args.quiet:
        print("%s: wrote %s (%d x %d, %d band%s, %s) from %d window%s of %d on %d "
              "worker%s in %.1f s" % (PROG, args.dest, size[0], size[1], size[2],
                                       "s"[:size[2] > 1], fmt, n, "s"[:n > 1],
                                       args.tile_size, nworkers, "s"[:nworkers > 1],
                                       time.time() - t0),
              file=sys.stderr)


def main(argv=None):
    """The command; returns its exit status. From a script too: GDAL's
    exceptions and the SIGTERM handler are the caller's again after it."""
    try:
        args = parse_args(argv)
    except SystemExit as e:  # a usage error (2, said), --help (0): returned, not raised
        return e.code if isinstance(e.code, int) else 2
    SAID.reset()
    RENAMED.clear()
    previous = None
    # Dask's log levels, which the run's silence (dask_logs, the local
    # cluster's silence_logs) sets for the whole process: the script's again
    # (its handlers are set up by its import)
    import distributed  # noqa: F401
    logs = [(h, h.level) for h in logging.getLogger("distributed").handlers]
    # (an ignored SIGTERM stays ignored, as SIGINT: interrupts_held)
    if threading.current_thread() is threading.main_thread() and \
            signal.getsignal(signal.SIGTERM) is not signal.SIG_IGN:
        previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        with W.gdal_exceptions():
            run(args)
    except Failure as e:
        print("%s: error: %s" % (PROG, e), file=sys.stderr)
        return e.code
    except Exception as e:  # GDAL or Dask, unforeseen: a sentence, not a traceback
        print("%s: error: %s: %s (nothing written to %s)"
              % (PROG, type(e).__name__, e, args.dest), file=sys.stderr)
        return 1
    except KeyboardInterrupt as e:
        terminated = isinstance(e, Terminated)
        what = "terminated" if terminated else "interrupted"
        if written(args.dest):  # while the cluster closed, DEST being complete
            print("%s: %s while closing the cluster; %s was written in full" % (
                PROG, what, args.dest), file=sys.stderr)
        else:
            print("%s: %s; nothing written to %s" % (PROG, what, args.dest), file=sys.stderr)
        return 128 + (signal.SIGTERM if terminated else signal.SIGINT)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        for handler, level in logs:
            handler.setLevel(level)
    return 0


if __name__ == "__main__":
    sys.exit(main())
