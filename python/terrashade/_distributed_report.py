"""terrashade.distributed: what the run tells the user: its failure and exit
status, the driver's warnings (once each), and Dask's progress bar."""
import contextlib
import sys
import threading

LOST = 3  # exit status: the cluster was lost during the run; run it again


class Failure(Exception):
    """A run that cannot go on: a sentence for the user and an exit code."""

    def __init__(self, message, code=1):
        super().__init__(message)
        self.code = code


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
