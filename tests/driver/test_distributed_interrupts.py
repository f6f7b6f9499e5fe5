"""terrashade.distributed interrupted: Ctrl-C (SIGINT) or SIGTERM during a
run removes the partial file and leaves an older DEST as it was (exit 130 or
143); once DEST is in place, it is the whole new product and the message
says so.
"""
import os
import signal
import subprocess
import time
import unittest

import tsdistributed as TD
import tsdriver as T
from tsdistributed import HORIZON, PYTHONPATH
from tsdriver import gdal


class DistributedInterrupts(TD.DistributedCase):
    def big_dem(self):
        """600 x 600 cells of 10 m: its svf in 512 directions takes seconds."""
        dem = self.path("big.tif")
        if not os.path.exists(dem):
            T.write_tif(dem, T.fractal_dem(600, seed=5, relief=300.0),
                        (500000, 10, 0, 4000000, 0, -10), 32617)
        return dem

    def start_signalled_run(self, dest, long=False):
        """A run of the horizon product into dest (long: the big DEM's svf in
        512 directions, seconds), to be signalled: in its own session (the
        shell's job control may ignore SIGINT)."""
        what = (["-oo", "PRODUCT=svf", "-oo", "DIRECTIONS=512", T.conn(self.big_dem())] if long
                else T.oo_args(HORIZON) + [T.conn(self.dem)])
        return subprocess.Popen(
            ["/usr/bin/python3", "-m", "terrashade.distributed", "--workers", "1",
             "--tile-size", "64", "-q"] + what + [dest],
            stderr=subprocess.PIPE, text=True, start_new_session=True,
            env=T.env(PYTHONPATH=PYTHONPATH),
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))

    def test_interrupted_run_leaves_nothing(self):
        """Ctrl-C (SIGINT) and SIGTERM (what timeout, Slurm, systemd or
        Kubernetes send) during a run: the partial file is removed, an older
        DEST stays as it was, exit 130 or 143. SIGTERM ended the program on
        the spot and left DEST.partial behind. At once, and 0.4 and 0.8 s
        into the cluster's start (a cluster cut short there was left to
        Dask's exit handler, which printed tracebacks)."""
        dest = self.path("interrupted.tif")
        for sig, code, said, delay in ((signal.SIGINT, 130, "interrupted", 0.0),
                                       (signal.SIGTERM, 143, "terminated", 0.0),
                                       (signal.SIGINT, 130, "interrupted", 0.4),
                                       (signal.SIGINT, 130, "interrupted", 0.8)):
            with self.subTest(said, delay=delay):
                with open(dest, "w") as f:
                    f.write("an older result")
                # (a long run: the horizon's ended before a signal 0.8 s into
                # the cluster's start on an idle machine, session 59's CI)
                p = self.start_signalled_run(dest, long=True)
                for _ in range(600):  # created before the cluster starts
                    if TD.partials(dest) or p.poll() is not None:
                        break
                    time.sleep(0.05)
                time.sleep(delay)
                self.assertIsNone(p.poll(), "the run ended before the signal")
                p.send_signal(sig)
                err = p.communicate(timeout=120)[1]
                self.assertEqual(p.returncode, code, err)
                self.assertIn("terrashade.distributed: %s; nothing written to %s"
                              % (said, dest), err)
                # while the cluster starts: it is closed, not left to Dask's
                # exit handler (its tracebacks until session 49)
                self.assertNotIn("Traceback", err)
                with open(dest) as f:
                    self.assertEqual(f.read(), "an older result")
                os.remove(dest)
                self.assert_nothing_left(dest)

    def ctrl_c_to_the_group(self, dest, after, sig=signal.SIGINT, again=None):
        """A run of 2 workers into dest, signalled as Ctrl-C at the terminal
        signals it (SIGINT to the whole process group; or sig, as systemd's
        or Slurm's stop sends SIGTERM), `after` seconds once both worker
        processes exist, and `again` seconds later a second time: its exit
        status and stderr. No worker process outlives it. The run takes
        10-20 s on this machine: one of 5 s (horizons in 128 directions) ended
        before a signal 3 s after the workers' start on an idle CI machine,
        and Python discarded the Ctrl-C that came while it exited (exit 0;
        session 55's CI)."""
        dem = self.big_dem()
        p = subprocess.Popen(
            ["/usr/bin/python3", "-m", "terrashade.distributed", "--workers", "2",
             "--tile-size", "64", "-q", "-oo", "PRODUCT=svf", "-oo", "DIRECTIONS=512",
             T.conn(dem), dest],
            stderr=subprocess.PIPE, text=True, start_new_session=True,
            env=T.env(PYTHONPATH=PYTHONPATH),
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        workers = []
        for _ in range(1200):  # the workers' processes
            workers = [w for w in subprocess.run(["pgrep", "-P", str(p.pid), "-f", "spawn_main"],
                                                 capture_output=True, text=True).stdout.split()]
            if len(workers) == 2 or p.poll() is not None:
                break
            time.sleep(0.05)
        time.sleep(after)
        self.assertIsNone(p.poll(), "the run ended before the signal")
        os.killpg(p.pid, sig)
        if again is not None:
            time.sleep(again)
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:  # (the group is gone)
                pass
        try:
            err = p.communicate(timeout=120)[1]
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            self.fail("the run did not end within 120 s of a %s to its group %.1f s "
                      "after its workers' processes started" % (sig.name, after))
        print("exit %d: %s" % (p.returncode, err.strip()))
        for _ in range(100):  # the workers end with the run (or within 5 s)
            alive = [w for w in workers if os.path.exists("/proc/%s" % w)]
            if not alive:
                break
            time.sleep(0.05)
        self.assertEqual(alive, [], "worker processes left running")
        return p.returncode, err

    def test_ctrl_c_at_the_terminal(self):
        """Ctrl-C at the terminal signals the whole process group, the
        cluster's workers too: the run stops as for its own Ctrl-C, and the
        workers print nothing (each printed its KeyboardInterrupt
        tracebacks until session 50). The signal goes once the workers have
        started, while they compute."""
        dest = self.path("group.tif")
        code, err = self.ctrl_c_to_the_group(dest, 3.0)
        self.assertEqual(code, 130, err)
        self.assertIn("terrashade.distributed: interrupted; nothing written to %s" % dest, err)
        self.assertNotIn("Traceback", err)
        self.assertNotIn("KeyboardInterrupt", err)
        self.assert_nothing_left(dest)

    def test_ctrl_c_at_the_terminal_while_workers_start(self):
        """The same Ctrl-C at the terminal while the worker processes start,
        and a SIGTERM to the whole group (systemd's and Slurm's stop): it
        reached them before they ignore it, ended some half started, and
        the cluster's start waited for them for ever (a run hung until a
        second signal; session 52). The workers are started with SIGINT and
        SIGTERM blocked now; the run stops once the start is over."""
        dest = self.path("starting.tif")
        for sig, code, said, after in ((signal.SIGINT, 130, "interrupted", 0.0),
                                       (signal.SIGINT, 130, "interrupted", 0.3),
                                       (signal.SIGTERM, 143, "terminated", 0.3)):
            with self.subTest(said, after=after):
                code_got, err = self.ctrl_c_to_the_group(dest, after, sig)
                self.assertEqual(code_got, code, err)
                self.assertIn("%s while the Dask cluster starts" % said, err)
                self.assertIn("terrashade.distributed: %s; nothing written to %s"
                              % (said, dest), err)
                self.assertNotIn("Traceback", err)
                self.assertNotIn("KeyboardInterrupt", err)
                self.assert_nothing_left(dest)

    def test_second_ctrl_c_while_workers_start(self):
        """A second Ctrl-C while the workers start stops the run without
        waiting for the start: exit 130 within seconds, and the workers cut
        short (still blocking SIGTERM, which the exit handlers' terminate()
        sends) are killed, not waited for."""
        dest = self.path("twice.tif")
        code, err = self.ctrl_c_to_the_group(dest, 0.0, again=0.2)
        self.assertEqual(code, 130, err)
        self.assert_nothing_left(dest)
        # no traceback: Dask's exit handler asserted on the half-started
        # cluster's workers, and workers spawned after the kill woke to a
        # parent gone (session 53)
        self.assertNotIn("Traceback", err)

    def test_signals_held_while_the_cluster_starts(self):
        """While the cluster starts, one Ctrl-C or SIGTERM is held, said,
        and raised once the start is over; a second is raised at once (a
        start can wait for ever on a worker that the first one ended)."""
        import io
        from contextlib import redirect_stderr
        from terrashade._distributed_cluster import Terminated, interrupts_held
        # Python's own handler, whatever the runner gave (a suite started in
        # the background of a script has SIGINT ignored: session 53)
        before = signal.signal(signal.SIGINT, signal.default_int_handler)
        self.addCleanup(signal.signal, signal.SIGINT, before)
        for sig, exc in ((signal.SIGINT, KeyboardInterrupt), (signal.SIGTERM, Terminated)):
            with self.subTest(sig=sig):
                said, reached = io.StringIO(), []
                with redirect_stderr(said), self.assertRaises(exc):
                    with interrupts_held():
                        os.kill(os.getpid(), sig)
                        time.sleep(0.05)
                        reached.append("after the first")
                self.assertEqual(reached, ["after the first"])
                self.assertIn("while the Dask cluster starts: stopping once it has", said.getvalue())
                with redirect_stderr(io.StringIO()), self.assertRaises(exc):
                    with interrupts_held():
                        os.kill(os.getpid(), sig)
                        time.sleep(0.05)
                        os.kill(os.getpid(), sig)
                        time.sleep(0.05)
                        reached.append("after the second")
                self.assertEqual(reached, ["after the first"])
        # the handlers are given back
        self.assertIs(signal.getsignal(signal.SIGINT), signal.default_int_handler)

    def test_an_ignored_signal_stays_ignored(self):
        """A run started in the background of a script (`... &`) has SIGINT
        ignored: a Ctrl-C to the terminal's process group must not stop it
        while its cluster starts (interrupts_held took SIGINT over, and such
        a run ended with exit 130, until session 53)."""
        from unittest import mock
        import terrashade.distributed as D
        from terrashade._distributed_cluster import interrupts_held
        for sig in (signal.SIGINT, signal.SIGTERM):
            before = signal.signal(sig, signal.SIG_IGN)
            self.addCleanup(signal.signal, sig, before)
        reached = []
        with interrupts_held():
            for sig in (signal.SIGINT, signal.SIGTERM):
                os.kill(os.getpid(), sig)
            time.sleep(0.05)
            reached.append("after the signals")
        self.assertEqual(reached, ["after the signals"])
        # the run itself keeps SIGTERM ignored too (main() took it over)
        seen = []
        with mock.patch.object(D, "run", lambda args: seen.append(
                signal.getsignal(signal.SIGTERM))):
            self.assertEqual(D.main(["TERRASHADE:" + T.JACKSBORO, self.path("x.tif")]), 0)
        self.assertEqual(seen, [signal.SIG_IGN])
        for sig in (signal.SIGINT, signal.SIGTERM):
            self.assertIs(signal.getsignal(sig), signal.SIG_IGN)

    def test_interrupt_after_dest_is_written(self):
        """Ctrl-C once DEST is in place, while the cluster closes (~0.6 s):
        DEST is the whole new product, and the message says so (until
        session 49 it said 'nothing written' over the new DEST). The signal
        goes as soon as DEST is replaced; a run that ends first exits 0."""
        dest = self.path("late.tif")
        with open(dest, "w") as f:
            f.write("an older result")
        before = os.stat(dest).st_ino
        p = self.start_signalled_run(dest)
        for _ in range(60000):
            if p.poll() is not None or os.stat(dest).st_ino != before:
                break
            time.sleep(0.002)
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
        err = p.communicate(timeout=120)[1]
        print("exit %d: %s" % (p.returncode, err.strip()))
        self.assertIn(p.returncode, (0, 130), err)
        self.assertNotIn("nothing written", err)
        if p.returncode == 130:
            self.assertIn("terrashade.distributed: interrupted while closing the cluster; "
                          "%s was written in full" % dest, err)
        ds = gdal.Open(dest)
        self.assertEqual((ds.RasterXSize, ds.RasterYSize), (200, 150))
        ds = None


if __name__ == "__main__":
    unittest.main(verbosity=2)
