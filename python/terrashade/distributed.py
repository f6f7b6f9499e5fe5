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
import argparse
import asyncio
import contextlib
import logging
import os
import re
import signal
import sys
import threading
import time
import uuid

try:
    from osgeo import gdal
except ImportError as _e:  # a Python without GDAL's bindings: a sentence, not a traceback
    sys.exit("terrashade.distributed: error: this Python (%s) cannot import GDAL's "
             "bindings (%s); run it with one that can, e.g. /usr/bin/python3 with "
             "Debian's python3-gdal" % (sys.executable, _e))

from terrashade import windows as W  # noqa: E402 (after the check above)

PROG = "terrashade.distributed"
TILE_MIN, TILE_MAX = 16, 65536
LOST = 3  # exit status: the cluster was lost during the run; run it again
SIDE_FILES = (".aux.xml", ".ovr", ".msk")  # GDAL's beside a GeoTIFF
# The driver's inline option segment (plugin/tsd_connstr.c): KEY=VALUE items,
# an ASCII identifier as KEY with blanks allowed around it, up to the first ':'.
_ITEM = r" *[A-Za-z_][A-Za-z0-9_]* *=[^,:]*"
INLINE = re.compile(r"^(%s(?:,%s)*):" % (_ITEM, _ITEM))


class Failure(Exception):
    """A run that cannot go on: a sentence for the user and an exit code."""

    def __init__(self, message, code=1):
        super().__init__(message)
        self.code = code


def tile_size(text):
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError("must be a whole number, got %r" % text)
    if n < TILE_MIN or n > TILE_MAX or n % 16:
        raise argparse.ArgumentTypeError(
            "must be a multiple of 16 between %d and %d (GeoTIFF tiles are "
            "multiples of 16), got %d" % (TILE_MIN, TILE_MAX, n))
    return n


def positive(text):
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError("must be a whole number >= 1, got %r" % text)
    return n


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog=PROG, description="Compute a TERRASHADE product window by window "
        "on dask.distributed and write it as a tiled GeoTIFF or COG.")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="an existing Dask scheduler (tcp://host:8786); every "
                       "worker must read the DEM by the same path and find the plugin")
    where.add_argument("--workers", type=positive, metavar="N",
                       help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--threads-per-worker", type=positive, default=1, metavar="N",
                   help="threads of each local worker (default 1)")
    p.add_argument("--tile-size", type=tile_size, default=1024, metavar="N",
                   help="window size in cells, a multiple of 16 (default 1024)")
    p.add_argument("-oo", dest="open_options", action="append", default=[],
                   metavar="KEY=VALUE", help="an open option of the driver (repeatable)")
    p.add_argument("--format", choices=["GTiff", "COG"],
                   help="output format (default: COG for *.cog.tif, else GTiff)")
    p.add_argument("-co", dest="creation_options", action="append", default=[],
                   metavar="NAME=VALUE", help="a creation option of the output driver")
    p.add_argument("--timeout", type=positive, default=10, metavar="SECONDS",
                   help="how long to try to reach --scheduler, to wait for its answer "
                   "during the run, and to wait for a worker when the cluster has none "
                   "(default 10)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bar and no summary line")
    p.add_argument("source", metavar="SOURCE", help="TERRASHADE:[KEY=VALUE,...:]dem.tif")
    p.add_argument("dest", metavar="DEST", help="output .tif (GeoTIFF) or .cog.tif (COG)")
    args = p.parse_args(argv)
    for oo in args.open_options:
        if not re.match(r"^[A-Za-z_]\w*=", oo):
            p.error("-oo takes KEY=VALUE, got %r" % oo)
    return args


def split_source(source):
    """SOURCE's inline option segment with its ':' ("" if none) and the DEM."""
    rest = source[len("TERRASHADE:"):]
    m = INLINE.match(rest)
    return (rest[:m.end()], rest[m.end():]) if m else ("", rest)


def given_keys(source, open_options):
    """Upper-case names of the options given inline in SOURCE or by -oo."""
    inline = split_source(source)[0]
    items = list(open_options) + (inline[:-1].split(",") if inline else [])
    return {item.split("=", 1)[0].strip().upper() for item in items}


def absolute_path(text):
    """text (a name, quoted or not) made absolute if it is a relative path
    that exists here; None if it is not one."""
    quoted = len(text) > 1 and text[0] == text[-1] == '"'
    path = text[1:-1] if quoted else text
    if not path or os.path.isabs(path) or path.startswith("/vsi") or not os.path.exists(path):
        return None
    path = os.path.abspath(path)
    return '"%s"' % path if quoted else path


def absolute_source(source):
    """SOURCE with a relative DEM path that exists here made absolute: each
    worker would resolve it in its own working directory (an existing
    cluster's workers do not share the client's), and read another file of
    that name, or none. Also the file inside another driver's name
    (GTIFF_DIR:1:dem.tif, NETCDF:"dem.nc":z, GPKG:dem.gpkg:table): the
    parts between its ':' that are relative paths existing here."""
    head, dem = split_source(source)
    whole = absolute_path(dem)
    if whole is not None:
        return "TERRASHADE:" + head + whole
    if os.path.exists(dem):  # (an absolute or virtual path, or nothing to do)
        return source
    parts = dem.split(":")
    fixed = [absolute_path(p) or p for p in parts]
    if len(parts) < 2 or fixed == parts:
        return source
    return "TERRASHADE:" + head + ":".join(fixed)


class Said:
    """The driver's warnings said on stderr, each once: the client's open of
    SOURCE, then the tasks' (windows.read_window returns them), as GDAL's
    own handler words them. The tasks open SOURCE with its DEM's path made
    absolute (absolute_source): their warnings that name it are the same
    ones once it is named as SOURCE does (same_dem: (theirs, SOURCE's))."""

    def __init__(self):
        self.reset()

    def reset(self):
        """A new run says its warnings again."""
        self.seen = set()
        self.same_dem = None

    def say(self, messages, bar=None):
        if self.same_dem and self.same_dem[0] != self.same_dem[1]:
            messages = [(n, m.replace(self.same_dem[0], self.same_dem[1]))
                        for n, m in messages]
        new = [m for m in messages if m not in self.seen]
        if not new:
            return
        self.seen.update(new)
        with bar.paused() if bar is not None else contextlib.nullcontext():
            for number, message in new:
                sys.stderr.write("Warning %d: %s\n" % (number, message))


SAID = Said()


def open_source(source, open_options):
    if not source.upper().startswith("TERRASHADE:"):
        raise Failure("SOURCE must be a TERRASHADE connection string "
                      "(TERRASHADE:[KEY=VALUE,...:]dem.tif), got %r" % source)
    if gdal.GetDriverByName("TERRASHADE") is None:
        raise Failure("GDAL cannot find the TERRASHADE driver: set GDAL_DRIVER_PATH "
                      "to the directory of gdal_TERRASHADE.so, or make install")
    said = W.Warnings()
    gdal.PushErrorHandler(said)
    try:
        return gdal.OpenEx(source, gdal.OF_RASTER | gdal.OF_READONLY,
                           open_options=open_options)
    except RuntimeError as e:
        raise Failure("cannot open %s: %s" % (source, e))
    finally:
        gdal.PopErrorHandler()
        SAID.say(said.messages)


def output_format(args):
    if args.format:
        return args.format
    low = args.dest.lower()
    if low.endswith((".cog.tif", ".cog.tiff")):
        return "COG"
    if low.endswith((".tif", ".tiff")):
        return "GTiff"
    raise Failure("cannot tell the format of %s from its name: end it in .tif "
                  "(GeoTIFF) or .cog.tif (COG), or give --format GTiff|COG" % args.dest)


def block_size(tile):
    """The tiled GeoTIFF's internal tile size (DEST, or the one a COG is
    copied from): the window size up to 512, else the largest power of two
    up to 512 that divides it, so that every window covers whole tiles."""
    if tile <= 512:
        return tile
    b = 512
    while tile % b:
        b //= 2
    return b


def create_like(src, path, block, creation_options):
    """A tiled GeoTIFF at path with src's size, bands, types, nodata,
    georeferencing and metadata (what gdal_translate would copy)."""
    # the user's first: GDAL takes the first of a name given twice
    opts = list(creation_options) + ["TILED=YES", "BLOCKXSIZE=%d" % block,
                                     "BLOCKYSIZE=%d" % block, "BIGTIFF=IF_SAFER"]
    b1 = src.GetRasterBand(1)
    try:
        out = gdal.GetDriverByName("GTiff").Create(
            path, src.RasterXSize, src.RasterYSize, src.RasterCount, b1.DataType, opts)
    except RuntimeError as e:
        raise Failure("cannot write %s: %s" % (path, e))
    gt = src.GetGeoTransform(can_return_null=True)
    if gt is not None:  # else none, not the default, whose rows run south to north
        out.SetGeoTransform(gt)
    if src.GetProjection():
        out.SetProjection(src.GetProjection())
    out.SetMetadata(src.GetMetadata())
    for i in range(1, src.RasterCount + 1):
        s, d = src.GetRasterBand(i), out.GetRasterBand(i)
        d.SetDescription(s.GetDescription())
        d.SetColorInterpretation(s.GetColorInterpretation())
        d.SetMetadata(s.GetMetadata())
        if s.GetNoDataValue() is not None:
            d.SetNoDataValue(s.GetNoDataValue())
        if s.GetUnitType():
            d.SetUnitType(s.GetUnitType())
        if s.GetOffset() not in (None, 0.0):
            d.SetOffset(s.GetOffset())
        if s.GetScale() not in (None, 1.0):
            d.SetScale(s.GetScale())
    return out


def dask_logs(level):
    """Only Dask's logs of level and above reach stderr, as LocalCluster's
    silence_logs: on its handlers, as Dask's configuration gives its loggers
    their own levels."""
    for handler in logging.getLogger("distributed").handlers:
        handler.setLevel(level)


@contextlib.contextmanager
def interrupts_held():
    """Ctrl-C and SIGTERM held while a cluster starts, raised once it has
    (at the end of the with block, after the caller holds the cluster to
    close): a LocalCluster cut short in its start was left for Dask's exit
    handler, which printed its tracebacks."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got = []
    previous = {s: signal.signal(s, lambda signum, _frame: got.append(signum))
                for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if got:
        raise Terminated() if got[0] == signal.SIGTERM else KeyboardInterrupt()


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
        dask_logs(logging.ERROR)  # as the local cluster's: the program says what failed
        # A worker has one task slot per thread, by default one per core.
        return client, None, 1
    workers = args.workers or os.cpu_count() or 1
    # on this machine's loopback only, with its HTTP servers on free ports:
    # dashboard_address=None still served the scheduler's on 0.0.0.0:8787,
    # reachable from other machines, and warned where that port was taken
    cluster = LocalCluster(n_workers=workers, threads_per_worker=args.threads_per_worker,
                           processes=True, host="127.0.0.1", dashboard_address="127.0.0.1:0",
                           worker_dashboard_address="127.0.0.1:0",
                           silence_logs=logging.ERROR)
    slots = workers * args.threads_per_worker
    return Client(cluster), cluster, max(1, (os.cpu_count() or 1) // slots)


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
        raise Failure("GDAL on worker(s) %s cannot find the TERRASHADE driver: set "
                      "GDAL_DRIVER_PATH there (now %r) or install the plugin"
                      % (", ".join(missing), found[missing[0]]["GDAL_DRIVER_PATH"]))
    return len(found)


class ProgressBar:
    """Dask's console progress bar over futures, on stderr, in a thread of
    its own; ready is set once the scheduler tracks the futures (its first
    draw), or when the bar gives up."""

    def __init__(self, futures):
        self.ready = threading.Event()
        self.lock = threading.Lock()  # a draw, or stop()
        self.drawn = self.stopped = False  # drawn: its line is not ended
        self.thread = threading.Thread(target=self._run, args=(futures,), daemon=True)
        self.thread.start()

    def _run(self, futures):
        from distributed.diagnostics.progressbar import TextProgressBar
        owner = self

        class Bar(TextProgressBar):
            def _draw_bar(self, **kwargs):
                owner.ready.set()
                with owner.lock:
                    if not owner.stopped:
                        super()._draw_bar(**kwargs)
                        owner.drawn = True

            def _draw_stop(self, **kwargs):  # at the end: the line erased
                with owner.lock:
                    if not owner.stopped:
                        super()._draw_stop(**kwargs)
                        owner.drawn = False

        try:
            # dask's console bar writes to stdout; the program's stdout stays clean.
            with contextlib.redirect_stdout(sys.stderr):
                Bar(futures, complete=True)
        except Exception:  # its connection lost with the scheduler: the run says so
            pass
        finally:
            self.ready.set()

    @contextlib.contextmanager
    def paused(self):
        """Within it: no drawing, and a drawn bar's line ended, so that a
        message starts a line of its own (the next draw redraws it). The
        lock is released however the block ends (a broken pipe, Ctrl-C:
        stop() must not wait for ever)."""
        with self.lock:
            if self.drawn and not self.stopped:
                sys.stderr.write("\n")
            yield

    def stop(self):
        """No more drawing; a drawn bar's line is ended, so that the reason
        the run failed starts a line of its own."""
        with self.lock:
            if self.drawn and not self.stopped:
                sys.stderr.write("\n")
            self.stopped = True


def compute(client, watch, out, source, task_options, tile, quiet, run):
    from dask.distributed import as_completed
    wins = W.windows(out.RasterXSize, out.RasterYSize, tile)
    futures = [client.submit(W.read_window, source, task_options, w, run, pure=False)
               for w in wins]
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
                    raise Failure("the window (xoff, yoff, xsize, ysize) = %r of %s "
                                  "failed: %s: %s" % (window_of[fut.key], source,
                                                      type(e).__name__, e))
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


# (device, inode) of the file finish() renames to DEST, once it is about to
RENAMED = []


def finish(partial, fmt, dest, creation_options):
    """partial (closed GeoTIFF) -> dest, in fmt, by rename."""
    final = partial
    if fmt == "COG":
        final = dest + ".partial"
        # The COG driver's own tiles (BLOCKSIZE 512, as gdal_translate -of COG),
        # not the windows': a copy need not match them, and a COG's tiles are
        # what its readers fetch, a request each (GDAL warns below 128).
        try:
            gdal.Translate(final, partial, format="COG",
                           creationOptions=list(creation_options))
        except RuntimeError as e:
            raise Failure("cannot write %s: %s" % (final, e))
        remove(partial)
    # An older DEST's side files described the old product and would be read
    # back for the new one (statistics, histograms, overviews, mask), as
    # gdal_translate's overwrite deletes them.
    for side in SIDE_FILES:
        with contextlib.suppress(FileNotFoundError):
            os.remove(dest + side)
    st = os.stat(final)
    RENAMED[:] = [(st.st_dev, st.st_ino)]  # an interrupt from here on: written()
    os.replace(final, dest)
    if os.path.exists(final + ".aux.xml"):
        os.replace(final + ".aux.xml", dest + ".aux.xml")


def remove(path):
    """path and its .aux.xml, our own files, if there are: a directory by
    that name, or any other cleanup failure, must not hide why the run
    failed."""
    for p in (path, path + ".aux.xml"):
        with contextlib.suppress(OSError):
            os.remove(p)


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
    block = block_size(args.tile_size)
    partial = args.dest + (".tiles.partial" if fmt == "COG" else ".partial")
    dem = src.GetMetadataItem("SOURCE_DEM") or ""
    if os.path.exists(dem) and os.path.exists(args.dest) and os.path.samefile(dem, args.dest):
        raise Failure("DEST %s is the DEM itself: the product would replace it; write "
                      "it to another file" % args.dest)
    size = (src.RasterXSize, src.RasterYSize, src.RasterCount)
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
        keys = given_keys(args.source, args.open_options)
        task_options = list(args.open_options)
        if "THREADS" not in keys:
            task_options.append("THREADS=%d" % threads)
        if "PROGRESS" not in keys:
            task_options.append("PROGRESS=no")  # the Dask bar says it
        tasks_source = absolute_source(args.source)
        SAID.same_dem = (split_source(tasks_source)[1], split_source(args.source)[1])
        n = compute(client, watch, out, tasks_source, task_options, args.tile_size,
                    args.quiet, run_id)
        out.FlushCache()
        out = None
        finish(partial, fmt, args.dest, args.creation_options)
    except BaseException:
        out = None
        remove(partial)
        remove(args.dest + ".partial")
        raise
    finally:
        if client is not None:
            if client.status == "running" and not (watch and watch.lost):
                with contextlib.suppress(Exception):  # the workers close this run's datasets
                    client.run(W.forget, run_id)
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


def written(dest):
    """Whether DEST is the file finish() renamed to it: an interrupt may
    come between any two steps, the rename's own included."""
    if not RENAMED:
        return False
    try:
        st = os.stat(dest)
    except OSError:
        return False
    return (st.st_dev, st.st_ino) == RENAMED[0]


class Terminated(KeyboardInterrupt):
    """SIGTERM (timeout, Slurm, systemd, Kubernetes...), cleaned up as Ctrl-C;
    Python's default ends the program at once and left DEST.partial behind."""


def _terminate(_signum, _frame):
    raise Terminated()


def main(argv=None):
    """The command; returns its exit status. From a script too: GDAL's
    exceptions and the SIGTERM handler are the caller's again after it."""
    args = parse_args(argv)
    SAID.reset()
    RENAMED.clear()
    previous = None
    if threading.current_thread() is threading.main_thread():
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
