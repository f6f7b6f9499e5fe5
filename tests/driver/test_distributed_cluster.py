"""terrashade.distributed on an existing cluster (--scheduler).

- writing a COG: the same pixels as gdal_translate's, COG layout;
- each run reads its own DEM, and the client's relative path of it; the
  workers hold no dataset after the run;
- a cluster without workers: the run waits --timeout for one, then exit 2;
- an existing cluster lost during the run (its scheduler killed or stopped,
  its only worker killed): one sentence, exit 3 within seconds, no DEST.partial;
- an unreachable scheduler or one that is no address: a clear message, exit 2,
  neither DEST nor DEST.partial left behind.
"""
import contextlib
import json
import os
import signal
import socket
import subprocess
import time
import unittest

import tsdistributed as TD
import tsdriver as T
from tsdistributed import HORIZON, PYTHONPATH, SHADE, distributed
from tsdriver import gdal, np


# dask-worker --preload: the worker's windows never finish, so that the run
# is surely under way when the test takes its cluster away; the first that
# starts says so by creating the file $TS_TEST_TASK_STARTED.
STALLED_TASKS = """
import os, time
from terrashade import windows

def read_window(*args):
    open(os.environ["TS_TEST_TASK_STARTED"], "w").close()
    time.sleep(600)

windows.read_window = read_window
"""


class ExternalCluster:
    """A context of dask-scheduler and dask-worker processes, each in a
    session of its own so that a test can kill or stop one of them; every
    process started here (the program's runs too) is killed at its end,
    whether the test passed or not."""

    def __init__(self, directory):
        self.dir = directory
        self.file = os.path.join(directory, "scheduler.json")
        self.procs = {}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for p in self.procs.values():
            with contextlib.suppress(ProcessLookupError):
                os.killpg(p.pid, signal.SIGKILL)
            p.communicate(timeout=30)

    def start(self, name, args, **env):
        """A process; a run's (name "run...") stderr is piped, the others' logged."""
        with open(os.path.join(self.dir, name + ".log"), "w") as log:
            self.procs[name] = subprocess.Popen(
                [str(a) for a in args], stdout=log, start_new_session=True,
                stderr=subprocess.PIPE if name.startswith("run") else subprocess.STDOUT,
                env=T.env(PYTHONPATH=PYTHONPATH, **env))
        return self.procs[name]

    def run(self, name, args):
        return self.start(name, ["/usr/bin/python3", "-m", "terrashade.distributed"] + args)

    def start_cluster(self, preload):
        self.start("scheduler", ["dask-scheduler", "--host", "127.0.0.1", "--port", 0,
                                 "--no-dashboard", "--scheduler-file", self.file])
        self.start("worker", ["dask-worker", "--scheduler-file", self.file, "--nthreads", 1,
                              "--no-nanny", "--no-dashboard", "--preload", preload,
                              "--local-directory", self.dir],
                   TS_TEST_TASK_STARTED=os.path.join(self.dir, "started"))
        self.wait_for(lambda: os.path.exists(self.file) and os.path.getsize(self.file),
                      "the scheduler's file")
        with open(self.file) as f:
            address = json.load(f)["address"]
        # the worker joined: the runs below wait only --timeout 2 s for one,
        # and a dask-worker's start took longer on a loaded machine
        from dask.distributed import Client
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(1, timeout=60)
        return address

    def wait_for(self, done, what, seconds=60):
        for _ in range(int(seconds * 20)):
            if done():
                return
            for name, p in self.procs.items():
                if p.poll() is not None:
                    raise AssertionError("%s ended (exit %s) before %s:\n%s" % (
                        name, p.returncode, what,
                        self.stderr(p) if name.startswith("run") else self.log(name)))
            time.sleep(0.05)
        raise AssertionError("no %s within %d s" % (what, seconds))

    @staticmethod
    def stderr(p, timeout=None):
        """A run's stderr, read as bytes and decoded: text mode would turn the
        progress bar's carriage returns into line ends (a blank first line
        where the bar drew once)."""
        return p.communicate(timeout=timeout)[1].decode(errors="replace")

    def log(self, name):
        with open(os.path.join(self.dir, name + ".log")) as f:
            return f.read()

    def signal(self, name, sig):
        os.killpg(self.procs[name].pid, sig)


def files_open(path):
    """In this process (run on a worker): how many descriptors hold path open."""
    fds = "/proc/self/fd"
    count = 0
    for fd in os.listdir(fds):
        try:
            count += os.path.realpath(os.readlink(os.path.join(fds, fd))) == path
        except OSError:
            pass
    return count


class DistributedCluster(TD.DistributedCase):
    def test_existing_cluster_writes_cog(self):
        from dask.distributed import LocalCluster
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None, scheduler_port=0)
        try:
            dest = self.path("cluster.cog.tif")
            # inline options, as a caller that cannot pass -oo would give them
            src = "TERRASHADE:PRODUCT=horizon,DIRECTIONS=4:" + self.dem
            distributed(["--scheduler", cluster.scheduler_address, "--tile-size", 64,
                         src, dest])
        finally:
            cluster.close()
        self.assertEqual(gdal.Open(dest).GetMetadata("IMAGE_STRUCTURE").get("LAYOUT"), "COG")
        self.assert_identical(dest, self.reference(HORIZON, "ref_cog.tif"))

    def test_existing_cluster_reads_the_dem_of_each_run(self):
        """A worker keeps its dataset open between the tasks of a run, not
        between runs: a DEM rewritten at the same path between two runs on
        the same cluster gave the first run's product again, silently; and
        after a run the workers held its datasets (here the DEM's file) until
        the next one."""
        from dask.distributed import Client, LocalCluster
        dem = self.path("rewritten_dem.tif")
        with open(self.dem, "rb") as f, open(dem, "wb") as g:
            g.write(f.read())
        svf = {"PRODUCT": "svf", "DIRECTIONS": 8, "TILE_SIZE": 64}  # windowed: holds the DEM
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None, scheduler_port=0)
        try:
            for run in (1, 2):
                if run == 2:  # the same name, steeper terrain
                    ds = gdal.Open(dem, gdal.GA_Update)
                    band = ds.GetRasterBand(1)
                    z = band.ReadAsArray()
                    band.WriteArray(np.where(z == -9999, z, 3 * z))
                    ds = None
                dest = self.path("rerun%d.tif" % run)
                distributed(["--scheduler", cluster.scheduler_address, "--tile-size", 64,
                             "-q"] + T.oo_args(svf) + [T.conn(dem), dest])
                self.assert_identical(dest, T.translate(dem, self.path("ref_rerun%d.tif" % run),
                                                        svf))
                # the workers outlive the run, but not its datasets (their far
                # grid and cached chunks: GiB for a large horizon)
                with Client(cluster) as client:
                    held = client.run(files_open, os.path.realpath(dem))
                self.assertEqual(sorted(held.values()), [0, 0], "the DEM held after the run")
        finally:
            cluster.close()

    def test_existing_cluster_reads_the_clients_relative_dem(self):
        """A relative DEM in SOURCE is the client's file: the workers of an
        existing cluster, started elsewhere, resolved it in their own working
        directory and read another DEM of that name there, silently."""
        from dask.distributed import Client, LocalCluster
        client_dir, worker_dir = self.path("client_dir"), self.path("worker_dir")
        for d in (client_dir, worker_dir):
            os.makedirs(d, exist_ok=True)
        with open(self.dem, "rb") as f, open(os.path.join(client_dir, "rel.tif"), "wb") as g:
            g.write(f.read())
        other = os.path.join(worker_dir, "rel.tif")  # the same name, other terrain
        T.run(["gdal_translate", "-q", "-scale", "0", "1", "0", "3", "-ot", "Float32",
               self.dem, other])
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=None, scheduler_port=0)
        svf = {"PRODUCT": "svf", "DIRECTIONS": 4}
        # the file inside another driver's name too (session 46: it failed,
        # 'cannot open the DEM GTIFF_DIR:1:rel.tif', on such a cluster)
        sources = {"relative.tif": "TERRASHADE:rel.tif",
                   "relative_dir.tif": "TERRASHADE:GTIFF_DIR:1:rel.tif"}
        try:
            with Client(cluster) as client:  # the workers' working directory
                client.run(os.chdir, worker_dir)
            for name, source in sources.items():
                distributed(["--scheduler", cluster.scheduler_address, "--tile-size", 64,
                             "-q"] + T.oo_args(svf) + [source, self.path(name)],
                            cwd=client_dir)
        finally:
            cluster.close()
        for name, source in sources.items():
            ref = self.path("ref_" + name)  # gdal_translate where the client runs
            T.run(["gdal_translate", "-q"] + T.oo_args(svf) + [source, ref], cwd=client_dir)
            self.assert_identical(self.path(name), ref)

    def test_cluster_without_workers(self):
        """A cluster with no worker at the start: the run waits --timeout for
        one to join (they may still be starting), then says so, exit 2
        (session 46: it failed at once, exit 1, whatever --timeout said)."""
        with ExternalCluster(self.path("")) as c:
            c.start("scheduler", ["dask-scheduler", "--host", "127.0.0.1", "--port", 0,
                                  "--no-dashboard", "--scheduler-file", c.file])
            c.wait_for(lambda: os.path.exists(c.file) and os.path.getsize(c.file),
                       "the scheduler's file")
            with open(c.file) as f:
                address = json.load(f)["address"]
            dest = self.path("no_workers.tif")
            start = time.monotonic()
            p = distributed(["--scheduler", address, "--timeout", 2, "-q",
                             T.conn(self.dem), dest], ok=False)
            took = time.monotonic() - start
            print("  no workers: exit %d after %.1f s: %s"
                  % (p.returncode, took, p.stderr.strip()))
            self.assertEqual(p.returncode, 2)
            self.assertIn("has no workers (none joined within 2 s, --timeout)", p.stderr)
            self.assertGreaterEqual(took, 2.0)
            self.assert_nothing_left(dest)

    def test_cluster_lost_during_the_run(self):
        """The scheduler of an existing cluster killed (its connection
        closes), stopped (it answers nothing: a machine or network gone), or
        its only worker killed, while the run waits for windows: one
        sentence that says what was lost, exit 3 within seconds, the older
        DEST untouched and no DEST.partial. The program waited for ever on a
        stopped scheduler or a cluster without workers, and printed Dask's
        tracebacks (its progress bar's thread) and, ten seconds after the
        scheduler died, 'OSError: Timed out trying to connect'."""
        preload = self.path("stalled_tasks.py")
        with open(preload, "w") as f:
            f.write(STALLED_TASKS)
        for lost, sig, said in (
                ("scheduler", signal.SIGKILL,
                 "lost the Dask scheduler at {address} during the run, after 0 of 12 windows: "
                 "its connection closed"),
                ("scheduler", signal.SIGSTOP,
                 "lost the Dask scheduler at {address} during the run, after 0 of 12 windows: "
                 "it did not answer for 2 s (--timeout)"),
                ("worker", signal.SIGKILL,
                 "lost the workers of the Dask cluster at {address} during the run, after 0 "
                 "of 12 windows: the scheduler has had none for 2 s (--timeout)")):
            directory = self.path("lost_%s_%s" % (lost, sig.name))
            os.mkdir(directory)
            with self.subTest(lost=lost, signal=sig.name), ExternalCluster(directory) as cluster:
                address = cluster.start_cluster(preload)
                dest = os.path.join(directory, "out.tif")
                with open(dest, "w") as f:
                    f.write("an older result")
                # the first with Dask's progress bar, whose thread printed a traceback
                quiet = [] if lost == "scheduler" and sig == signal.SIGKILL else ["-q"]
                p = cluster.run("run", ["--scheduler", address, "--timeout", 2, "--tile-size",
                                        64] + quiet + T.oo_args(SHADE) + [T.conn(self.dem), dest])
                cluster.wait_for(lambda: os.path.exists(os.path.join(directory, "started")),
                                 "a task")
                t0 = time.time()
                cluster.signal(lost, sig)
                err = cluster.stderr(p, 60)  # a hang fails here, not in CI's limit
                took = time.time() - t0
                print("%s %s: exit %d after %.1f s" % (lost, sig.name, p.returncode, took))
                self.assertEqual(p.returncode, 3, err)
                # one sentence on a line of its own (after the bar's, whose draws
                # each start with a carriage return), no traceback
                lines = err.rstrip("\n").split("\n")
                self.assertTrue(lines[-1].startswith("terrashade.distributed: error: "
                                                     + said.format(address=address)), err)
                self.assertEqual([line for line in lines[:-1] if "% Completed" not in line],
                                 [], err)
                self.assertIn("; nothing written to %s: run the command again" % dest, err)
                # at once when its connection closes, else after --timeout (2 s) and
                # up to a second between checks: generous bounds for a loaded machine
                self.assertLess(took, 5 if sig == signal.SIGKILL and lost == "scheduler"
                                else 10)
                with open(dest) as f:
                    self.assertEqual(f.read(), "an older result")
                os.remove(dest)
                self.assert_nothing_left(dest)
                if sig == signal.SIGSTOP:  # and at the start: not reached, as when absent
                    p = cluster.run("run_at_start", ["--scheduler", address, "--timeout", 2,
                                                     "-q", T.conn(self.dem), dest])
                    err = cluster.stderr(p, 60)
                    self.assertEqual(p.returncode, 2, err)
                    self.assertIn("cannot reach the Dask scheduler at %s within 2 s" % address,
                                  err)
                    self.assertNotIn("Traceback", err)
                    self.assert_nothing_left(dest)

    def test_unreachable_scheduler(self):
        with socket.socket() as s:  # a port nobody listens on
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        dest = self.path("unreachable.tif")
        p = distributed(["--scheduler", "tcp://127.0.0.1:%d" % port, "--timeout", 2,
                         T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("cannot reach the Dask scheduler at tcp://127.0.0.1:%d within 2 s"
                      % port, p.stderr)
        self.assert_nothing_left(dest)

    def test_malformed_scheduler_address(self):
        for address, reason in [("scheduler", "missing port number"),
                                ("bogus://host:8786", "unknown address scheme")]:
            with self.subTest(address):
                dest = self.path("malformed.tif")
                p = distributed(["--scheduler", address, "--timeout", 2, T.conn(self.dem),
                                 dest], ok=False)
                self.assertEqual(p.returncode, 2, p.stderr)
                self.assertIn("--scheduler %s is not a Dask scheduler address such as "
                              "tcp://host:8786 (%s" % (address, reason), p.stderr)
                self.assertNotIn("Traceback", p.stderr)
                self.assert_nothing_left(dest)
        # a TLS address without Dask's TLS settings: what to set, not a TypeError
        dest = self.path("tls.tif")
        p = distributed(["--scheduler", "tls://127.0.0.1:8786", "--timeout", 2,
                         T.conn(self.dem), dest], ok=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("--scheduler tls://127.0.0.1:8786 needs Dask's TLS settings", p.stderr)
        self.assertNotIn("TypeError:", p.stderr.split("needs Dask's TLS settings")[0])
        self.assert_nothing_left(dest)


if __name__ == "__main__":
    unittest.main(verbosity=2)
