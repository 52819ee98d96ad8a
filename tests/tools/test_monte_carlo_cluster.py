#!/usr/bin/env python3
"""A campaign of tools/monte_carlo.py on a Dask cluster started as docs/guides/campaigns-on-dask.md says, in a plain
environment: a `dask scheduler` process and a `dask worker ... --nthreads 1 --nworkers 2`
process, started from a temporary folder with nothing but PATH, HOME and TMPDIR in their
environment (no PYTHONPATH, nothing of the project on their path), then
`monte_carlo.py --scheduler tcp://127.0.0.1:PORT` with and without --ship-sil. The scheduler
unpickles every task graph and the workers run the cases, so this fails if either would need
a module of these tools (it did: "No module named 'mc_execution'" on the scheduler).

Needs dask.distributed (tools/requirements.txt, e.g. in .venv; its `dask` command beside the
Python running this) and the real pmstep-sil: $PMSTEP_SIL, else build/host-release/sil/pmstep-sil
or build/host/sil/pmstep-sil. Usage:
  PMSTEP_SIL=build/host/sil/pmstep-sil .venv/bin/python -m unittest -v test_monte_carlo_cluster   (from tests/tools/)
"""

import glob
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import tools_path

TOOLS = tools_path.TOOLS
ROOT = tools_path.ROOT
SCRIPT = os.path.join(TOOLS, "monte_carlo.py")
SCENARIO = os.path.join(ROOT, "sil", "scenarios", "robust.ini")
CASES = 4
DURATION_S = "1.2"  # alignment, commissioning and the start of RUN: short, and still the firmware's run
START_TIMEOUT_S = 60  # the scheduler writing its file, the two workers joining
CAMPAIGN_TIMEOUT_S = 120


def find_sil():
    if os.environ.get("PMSTEP_SIL"):
        return os.environ["PMSTEP_SIL"]
    for preset in ("host-release", "host"):
        path = os.path.join(ROOT, "build", preset, "sil", "pmstep-sil")
        if os.access(path, os.X_OK):
            return path
    raise AssertionError("no pmstep-sil: set PMSTEP_SIL or build one (cmake --build --preset host-release)")


def dask_command():
    """The `dask` command of the Python running this (.venv/bin/dask), as the guide runs it."""
    dask = os.path.join(os.path.dirname(sys.executable), "dask")
    return [dask] if os.access(dask, os.X_OK) else [sys.executable, "-m", "dask"]


def wait_for(predicate, timeout_s, what, procs=()):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return
        for proc in procs:
            if proc.poll() is not None:
                raise AssertionError(f"{what}: {proc.args[:2]} exited with status {proc.returncode}")
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def stop_group(proc):
    """Ends the process group @p proc leads (it was started in a new session): SIGTERM, then SIGKILL
    for what is left of it (a worker's nanny and its worker processes are one group)."""
    try:
        os.killpg(proc.pid, signal.SIGTERM)
    except ProcessLookupError:
        pass
    try:
        proc.wait(timeout=15)
    except subprocess.TimeoutExpired:
        pass
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


def tail(path, chars=4000):
    try:
        with open(path, errors="replace") as f:
            return f.read()[-chars:]
    except OSError:
        return ""


class PlainCluster(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.sil = find_sil()
        cls.tmp = tempfile.TemporaryDirectory(prefix="pmstep-mc-cluster-")
        cls.started = []
        try:
            cls.start_cluster()
        except BaseException:
            cls.tearDownClass()  # not called by unittest when this fails
            raise

    @classmethod
    def start_cluster(cls):
        home = os.path.join(cls.tmp.name, "home")
        os.makedirs(home)
        # As a user's shell on another machine: no PYTHONPATH, no project folder, cwd elsewhere.
        plain = {"PATH": "/usr/bin:/bin", "HOME": home, "TMPDIR": home}
        scheduler_file = os.path.join(cls.tmp.name, "scheduler.json")
        cls.logs = {name: os.path.join(cls.tmp.name, f"{name}.log") for name in ("scheduler", "worker")}

        def start(name, args):
            with open(cls.logs[name], "w") as log:
                # Its own session: stop_group() ends it with all its children. --idle-timeout and
                # --death-timeout end them too should this test itself be killed.
                proc = subprocess.Popen(
                    dask_command() + args,
                    cwd=home,
                    env=plain,
                    stdin=subprocess.DEVNULL,
                    stdout=log,
                    stderr=subprocess.STDOUT,
                    start_new_session=True,
                )
            cls.started.append(proc)
            return proc

        scheduler = start(
            "scheduler",
            [
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--dashboard-address",
                ":0",
                "--scheduler-file",
                scheduler_file,
                "--idle-timeout",
                "300",
            ],
        )

        def scheduler_address():
            try:
                with open(scheduler_file) as f:
                    cls.address = json.load(f)["address"]
                return True
            except (OSError, ValueError, KeyError):  # not there yet, or not all written
                return False

        wait_for(scheduler_address, START_TIMEOUT_S, "the scheduler", [scheduler])
        worker = start("worker", ["worker", cls.address, "--nthreads", "1", "--nworkers", "2", "--death-timeout", "60"])
        from distributed import Client  # only to wait for the two workers

        with Client(cls.address, timeout="30s") as client:
            deadline = time.monotonic() + START_TIMEOUT_S
            while len(client.scheduler_info(n_workers=-1)["workers"]) < 2:
                if worker.poll() is not None:
                    raise AssertionError(f"dask worker exited:\n{tail(cls.logs['worker'])}")
                if time.monotonic() > deadline:
                    raise AssertionError(f"the two workers did not join:\n{tail(cls.logs['worker'])}")
                time.sleep(0.1)
            cls.workers = set(client.scheduler_info(n_workers=-1)["workers"])

    @classmethod
    def stop_cluster(cls):
        for proc in reversed(cls.started):
            stop_group(proc)

    @classmethod
    def tearDownClass(cls):
        try:
            cls.stop_cluster()
        finally:
            cls.tmp.cleanup()

    def run_campaign(self, name, *extra):
        """Runs a campaign of CASES cases on the cluster from a temporary folder; returns (stdout, results)."""
        out = os.path.join(self.tmp.name, name)
        env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
        cmd = [
            sys.executable,
            SCRIPT,
            "--sil",
            self.sil,
            "--scenario",
            SCENARIO,
            "--cases",
            str(CASES),
            "--seed",
            "7",
            "--duration",
            DURATION_S,
            "--no-plots",
            "--out",
            out,
            "--scheduler",
            self.address,
            *extra,
        ]
        proc = subprocess.Popen(
            cmd,
            cwd=self.tmp.name,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        try:
            stdout, stderr = proc.communicate(timeout=CAMPAIGN_TIMEOUT_S)
        finally:
            if proc.poll() is None:
                stop_group(proc)
        self.assertEqual(
            proc.returncode,
            0,
            f"the campaign failed:\n{stdout}\n{stderr}\n--- scheduler log (tail):\n"
            f"{tail(self.logs['scheduler'])}\n--- worker log (tail):\n"
            f"{tail(self.logs['worker'])}",
        )
        self.assertEqual(stdout.strip().splitlines()[-1], f"{CASES} passed, 0 failed", stdout)
        self.assertIn(f"dask {self.address}, 2 workers: {CASES} cases run", stdout)
        results = []
        for path in sorted(glob.glob(os.path.join(out, "cases", "*", "result.json"))):
            with open(path) as f:
                results.append(json.load(f))
        self.assertEqual(len(results), CASES)
        for result in results:
            self.assertEqual(result["exit_status"], 0, result["stderr_tail"])
            self.assertIsNotNone(result["summary"])
            self.assertIn(result["worker"], self.workers)  # run by one of this cluster's workers
        return stdout, results

    def test_campaign_with_the_binary_shipped(self):
        """As the guide: --ship-sil, the workers get pmstep-sil from the client."""
        self.run_campaign("shipped", "--ship-sil")

    def test_campaign_with_the_binary_at_its_path(self):
        """Without --ship-sil: the workers run the --sil path (the same machine here)."""
        self.run_campaign("at-path")


if __name__ == "__main__":
    unittest.main()
