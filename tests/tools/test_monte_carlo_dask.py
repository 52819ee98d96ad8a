#!/usr/bin/env python3
"""Campaigns of tools/monte_carlo.py on Dask, with the real pmstep-sil:

1. the same cases on a thread, on a local Dask cluster of 2 workers, and on an external
   cluster (scheduler and 2 workers started here, pmstep-sil shipped to them) with one
   worker killed (SIGKILL) mid-campaign: every case finishes, and every case's result is
   the same, bit for bit, whatever the engine and the number of workers;
2. a campaign killed mid-way (client and local cluster, SIGKILL) and run again on the same
   folder: the finished cases are not run again, the result is the same;
3. a folder of another campaign is refused.

Needs dask.distributed (tools/requirements.txt, e.g. in .venv). Usage:
  PMSTEP_SIL=build/host/sil/pmstep-sil .venv/bin/python -m unittest -v test_monte_carlo_dask   (from tests/tools/)
"""

import csv
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
CASES = 8
DURATION_S = "1.2"  # alignment, commissioning and the start of RUN: a short case that still runs the firmware
TIMEOUT_S = 600


def campaign(out, *extra, sil=None):
    """The command line of a campaign of CASES cases."""
    return [
        sys.executable,
        SCRIPT,
        "--sil",
        sil or os.environ["PMSTEP_SIL"],
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
        *extra,
    ]


def finished(out):
    return glob.glob(os.path.join(out, "cases", "*", "result.json"))


def results(out):
    """{seed: result.json without where and how long it ran}."""
    found = {}
    for path in finished(out):
        with open(path) as f:
            result = json.load(f)
        for key in ("host", "worker"):
            result.pop(key, None)
        summary = result.get("summary") or {}
        summary.pop("timing", None)
        found[result["seed"]] = result
    return found


def cases_csv(out):
    """cases.csv rows without the wall-time column."""
    with open(os.path.join(out, "cases.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    for row in rows:
        row.pop("wall_s")
    return rows


def wait_for(predicate, timeout_s, what):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


class DaskCampaigns(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.environ.get("PMSTEP_SIL"):
            raise AssertionError("set PMSTEP_SIL to the pmstep-sil to test (see the module docstring)")
        cls.tmp = tempfile.TemporaryDirectory()
        cls.reference_out = os.path.join(cls.tmp.name, "reference")
        proc = subprocess.run(
            campaign(cls.reference_out, "--engine", "threads", "--jobs", "1"),
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
        if proc.returncode != 0:
            raise AssertionError(f"reference campaign failed:\n{proc.stdout}\n{proc.stderr}")
        cls.reference = results(cls.reference_out)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def assert_same_as_reference(self, out):
        got = results(out)
        self.assertEqual(sorted(got), sorted(self.reference))
        for seed, result in got.items():
            self.assertEqual(result, self.reference[seed], f"case {seed} differs from the reference run")
        self.assertEqual(cases_csv(out), cases_csv(self.reference_out))

    def test_reference_ran_every_case(self):
        self.assertEqual(len(self.reference), CASES)
        for result in self.reference.values():
            self.assertEqual(result["exit_status"], 0, result["stderr_tail"])
            self.assertIsNotNone(result["summary"])

    def test_local_cluster_of_two_workers(self):
        out = os.path.join(self.tmp.name, "local")
        proc = subprocess.run(campaign(out, "--jobs", "2"), capture_output=True, text=True, timeout=TIMEOUT_S)
        self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
        self.assertIn("dask local cluster, 2 workers", proc.stdout)
        self.assertIn("2 local workers", proc.stderr)
        self.assertEqual(proc.stdout.strip().splitlines()[-1], f"{CASES} passed, 0 failed")
        self.assert_same_as_reference(out)

    def test_external_cluster_with_a_worker_killed(self):
        out = os.path.join(self.tmp.name, "external")
        scheduler_file = os.path.join(self.tmp.name, "scheduler.json")
        dask_cli = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
        started = []
        try:
            started.append(
                subprocess.Popen(
                    dask_cli
                    + [
                        "--scheduler-file",
                        scheduler_file,
                        "--host",
                        "127.0.0.1",
                        "--port",
                        "0",
                        "--dashboard-address",
                        ":0",
                    ],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
            )
            wait_for(lambda: os.path.exists(scheduler_file), 60, "the scheduler")
            with open(scheduler_file) as f:
                address = json.load(f)["address"]
            workers = [
                subprocess.Popen(
                    [
                        sys.executable,
                        "-m",
                        "distributed.cli.dask_worker",
                        address,
                        "--nthreads",
                        "1",
                        "--no-nanny",
                        "--name",
                        f"w{k}",
                        "--local-directory",
                        os.path.join(self.tmp.name, f"w{k}"),
                    ],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
                for k in range(2)
            ]
            started += workers
            # pmstep-sil reaches the workers by upload (--ship-sil), not by its path.
            client = subprocess.Popen(
                campaign(out, "--scheduler", address, "--ship-sil"),
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
            started.append(client)
            wait_for(lambda: len(finished(out)) >= 2 or client.poll() is not None, TIMEOUT_S, "two finished cases")
            self.assertIsNone(client.poll(), "the campaign ended before a worker could be killed")
            workers[0].send_signal(signal.SIGKILL)
            workers[0].wait()
            killed_at = len(finished(out))
            stdout, stderr = client.communicate(timeout=TIMEOUT_S)
            self.assertEqual(client.returncode, 0, stdout + stderr)
            self.assertLess(killed_at, CASES, "every case had finished before the kill")
            self.assertEqual(stdout.strip().splitlines()[-1], f"{CASES} passed, 0 failed")
            self.assertIn(f"dask {address}", stdout)
            self.assert_same_as_reference(out)
        finally:
            for proc in reversed(started):
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()

    def test_killed_campaign_resumes(self):
        out = os.path.join(self.tmp.name, "resumed")
        cmd = campaign(out, "--jobs", "2")
        # Its own process group, so that one signal kills the client and its local cluster together.
        first = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        try:
            wait_for(lambda: len(finished(out)) >= 3 or first.poll() is not None, TIMEOUT_S, "three finished cases")
            self.assertIsNone(first.poll(), "the campaign ended before it could be killed")
            os.killpg(first.pid, signal.SIGKILL)
            first.wait()
        finally:
            if first.poll() is None:
                os.killpg(first.pid, signal.SIGKILL)
                first.wait()
        kept = len(results(out))
        self.assertGreaterEqual(kept, 3)
        if kept == CASES:
            self.skipTest("every case finished before the kill")
        before = {path: os.stat(path).st_mtime_ns for path in finished(out)}
        second = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
        self.assertEqual(second.returncode, 0, second.stdout + second.stderr)
        self.assertIn(f"{kept} of {CASES} cases already finished, {CASES - kept} to run", second.stderr)
        self.assertIn(f"{CASES - kept} cases run ({kept} resumed)", second.stdout)
        for path, mtime in before.items():  # a finished case is not run (nor written) again
            self.assertEqual(os.stat(path).st_mtime_ns, mtime, path)
        self.assert_same_as_reference(out)

    def test_other_campaign_in_the_folder_is_refused(self):
        cmd = campaign(self.reference_out, "--engine", "threads")
        cmd[cmd.index("--duration") + 1] = "1.3"
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("holds another campaign (duration_s differ)", proc.stderr)


if __name__ == "__main__":
    unittest.main()
