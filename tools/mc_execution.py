"""Monte Carlo campaigns, part 2: execution. Running pmstep-sil for one case (its outcome:
mc_outcome.py), and running a campaign's cases on an engine: Dask (a local cluster with one
worker per core, or an existing cluster given by its scheduler's address) or a thread pool
on this machine. Finished cases are kept in the output folder as they arrive, so a campaign
that was stopped resumes where it was (see monte_carlo.py for the whole tool).

What runs on a worker is run_sil(): it gets the case's --set arguments, the scenario file's
text and the pmstep-sil path (or finds the binary shipped to the worker), runs pmstep-sil in
a temporary folder of the worker and returns the exit status, the stderr tail and the
parsed summary.json. The function travels in the task graph by value (ByValue): the scheduler,
which unpickles the graph, and the workers, which run it, need Python with the same
dask.distributed and, on the workers, the pmstep-sil binary (shipped with --ship-sil) and its
shared libraries; nothing of the project on their path, and no folder shared with the client.
"""

import configparser
import hashlib
import json
import math
import os
import pickle
import shlex
import shutil
import subprocess
import sys
import tempfile
import threading
import time

from mc_distributions import (
    DISTRIBUTIONS,
    DURATION_KEY,
    SEED_KEY,
    ToolError,
    draw_parameters,
    format_value,
    missing_keys,
    parse_scenario,
    split_case_seed,
)
from mc_outcome import FAULT_EXIT_STATUS, classify, extract_metrics, fault_name

STDERR_TAIL_CHARS = 2000
ENGINES = ("dask", "threads")
RESULT_FILE = "result.json"  # cases/<seed>/result.json: a finished case (what run_sil returned)
CAMPAIGN_FILE = "campaign.json"
# Dask's own periodic work, slowed for a local cluster whose workers spend their time waiting for
# pmstep-sil: no statistical profiler (it samples the running thread every 10 ms for a dashboard
# this cluster does not have), event-loop health checks every second instead of every 20 ms,
# memory and system monitors every 1 and 2 s instead of 100 and 500 ms. Measured on 2 workers
# each waiting 10 s for a subprocess: 1.3 s of CPU (workers and client together) with Dask's
# defaults, 0.2 s with these: 5 % of a 2-core machine back for pmstep-sil.
QUIET_DASK = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
}


def read_scenario(sil, scenario_file):
    """{"section.key": value} of the scenario as pmstep-sil applies it (--print-scenario)."""
    cmd = [sil, "--scenario", scenario_file, "--print-scenario"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    except OSError as e:
        raise ToolError(f"cannot run {sil}: {e}") from None
    except subprocess.TimeoutExpired:
        raise ToolError(f"{shlex.join(cmd)} did not finish in 60 s") from None
    if proc.returncode != 0:
        raise ToolError(f"{shlex.join(cmd)} failed (status {proc.returncode}):\n{proc.stderr.strip()}")
    try:
        return parse_scenario(proc.stdout)
    except configparser.Error as e:
        raise ToolError(f"cannot parse the output of {shlex.join(cmd)} as INI: {e}") from None


def sil_version(sil):
    """First line of `pmstep-sil --version`, or None if it has no such option."""
    try:
        proc = subprocess.run([sil, "--version"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    lines = proc.stdout.strip().splitlines()
    return lines[0].strip() if proc.returncode == 0 and lines else None


def check_keys(sil, scenario_file, scenario, need_duration):
    """ToolError naming every key this tool would set that the installed pmstep-sil lacks."""
    extra = [SEED_KEY] + ([DURATION_KEY] if need_duration else [])
    missing = missing_keys(scenario, extra=extra)
    if not missing:
        return
    rows = {row[0]: row for row in DISTRIBUTIONS}
    lines = []
    for key in missing:
        if key in rows:
            _k, kind, a, b = rows[key]
            if kind == "scale":
                how = f"scenario value x U[{a:g}, {b:g}]"
            elif kind.startswith("times "):
                how = f"{kind[len('times ') :]} x U[{a:g}, {b:g}]"
            else:
                how = f"U[{a:g}, {b:g}]"
            lines.append(f"  {key:34s} drawn {how}")
        elif key == SEED_KEY:
            lines.append(f"  {key:34s} the case seed, for the SIL's own noise")
        else:
            lines.append(f"  {key:34s} set by --duration")
    raise ToolError(
        f"the installed pmstep-sil does not know {len(missing)} of the keys this tool sets:\n"
        + "\n".join(lines)
        + f"\n(its keys: {shlex.join([sil, '--scenario', scenario_file, '--print-scenario'])})\n"
        "Rebuild pmstep-sil from a tree that has them (cmake --build --preset host-release) or point --sil "
        "at one that does; no key is skipped."
    )


def sil_arguments(seed, params, duration):
    """The --set arguments of one case (seed, duration, drawn parameters)."""
    sets = ["--set", f"{SEED_KEY}={seed}"]
    if duration is not None:
        sets += ["--set", f"{DURATION_KEY}={format_value(duration)}"]
    for key, value in params.items():
        sets += ["--set", f"{key}={format_value(value)}"]
    return sets


def sil_command(args, seed, params, case_dir, csv_output):
    """The pmstep-sil command line of one case as run on this machine."""
    cmd = [args.sil, "--scenario", args.scenario, "--out", case_dir, "--quiet"]
    if not csv_output:
        cmd.append("--no-csv")
    return cmd + sil_arguments(seed, params, args.duration)


def rerun_command(args, seed):
    """The command that re-runs one case with this tool (same bounds, same output folder)."""
    if getattr(args, "preset", None):
        cmd = [
            "python3",
            args.script,
            "--sil",
            args.sil,
            "--preset",
            args.preset,
            "--tune",
            args.tune,
            "--out",
            args.out,
        ]
        if getattr(args, "phase_voltage_sensing", False):
            cmd += ["--phase-voltage-sensing"]
    else:
        cmd = ["python3", args.script, "--sil", args.sil, "--scenario", args.scenario, "--out", args.out]
    if args.duration is not None:
        cmd += ["--duration", format_value(args.duration)]
    for option, default in (("speed_bound", 0.5), ("angle_bound", 0.05), ("latency_bound", 0.05)):
        value = getattr(args, option)
        if value != default or (option == "speed_bound" and getattr(args, "preset", None)):
            cmd += ["--" + option.replace("_", "-"), format_value(value)]
    if getattr(args, "position_bound", None) is not None:
        cmd += ["--position-bound", format_value(args.position_bound)]
    for key in getattr(args, "exclude", []):
        cmd += ["--exclude", key]
    return cmd + ["--case", str(seed)]


class Progress:
    """Progress on stderr: one rewritten line on a terminal, else one line per 10 %."""

    def __init__(self, total, stream=sys.stderr):
        self.total, self.stream = total, stream
        self.tty = stream.isatty()
        self.start_s = time.monotonic()
        self.last_decile = 0
        self.lock = threading.Lock()

    def update(self, done, failures):
        with self.lock:
            elapsed_s = time.monotonic() - self.start_s
            eta_s = elapsed_s / done * (self.total - done) if done else math.nan
            line = (
                f"monte_carlo: {done}/{self.total} cases ({100.0 * done / self.total:.0f} %), "
                f"{failures} failure{'s' if failures != 1 else ''}, elapsed {elapsed_s:.1f} s, ETA {eta_s:.1f} s"
            )
            if self.tty:
                self.stream.write("\r" + line + "\033[K" + ("\n" if done == self.total else ""))  # [K: clear the rest
                self.stream.flush()
                return
            decile = done * 10 // self.total
            if decile > self.last_decile:
                self.last_decile = decile
                self.stream.write(line + "\n")
                self.stream.flush()


# --------------------------------------------------------------------------------------
# One case: run on a worker (run_sil), recorded on the client (make_record)
# --------------------------------------------------------------------------------------
def worker_address():
    """The Dask worker this runs on ("" outside a worker)."""
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return ""


def shipped_sil_path(name):
    """Path of a pmstep-sil shipped to this Dask worker (--ship-sil), made executable; None if none."""
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):
        return None
    path = os.path.join(worker.local_directory, name)
    if not os.path.isfile(path):
        return None
    if not os.access(path, os.X_OK):
        os.chmod(path, 0o755)
    return path


def run_sil(task):
    """Runs one case of pmstep-sil where this is called (a Dask worker or a local thread).

    task: {"seed", "sil" (path, or None with "sil_name" for the shipped binary), "scenario_text",
    "scenario_name", "set" (the --set arguments), "timeout_s"}. Returns {"seed", "exit_status"
    (negative: killed by that signal; None: did not finish), "problem" (text or None), "stderr_tail",
    "summary" (parsed summary.json or None), "host", "worker"}. Runs in a temporary folder it removes.
    """
    sil = task["sil"] or shipped_sil_path(task["sil_name"])
    result = {
        "seed": task["seed"],
        "exit_status": None,
        "problem": None,
        "stderr_tail": "",
        "summary": None,
        "host": os.uname().nodename,
        "worker": worker_address(),
    }
    if sil is None:
        result["problem"] = f"no pmstep-sil on this worker ({task['sil_name']} was not shipped)"
        return result
    work = tempfile.mkdtemp(prefix="pmstep-mc-")
    try:
        scenario_path = os.path.join(work, task["scenario_name"])
        with open(scenario_path, "w") as f:
            f.write(task["scenario_text"])
        out = os.path.join(work, "out")
        cmd = [sil, "--scenario", scenario_path, "--out", out, "--quiet", "--no-csv"] + task["set"]
        try:
            proc = subprocess.run(
                cmd,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
                errors="replace",
                timeout=task["timeout_s"],
            )
            result["exit_status"], stderr_text = proc.returncode, proc.stderr
        except subprocess.TimeoutExpired as e:
            result["problem"] = f"timed out after {task['timeout_s']:g} s"
            stderr_text = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
        except OSError as e:
            result["problem"] = f"cannot run pmstep-sil: {e}"
            stderr_text = ""
        result["stderr_tail"] = stderr_text[-STDERR_TAIL_CHARS:]
        if result["problem"] is None:
            try:
                with open(os.path.join(out, "summary.json")) as f:
                    result["summary"] = json.load(f)
            except FileNotFoundError:
                pass
            except (OSError, ValueError) as e:
                if result["exit_status"] in (0, FAULT_EXIT_STATUS):  # else the exit status is the better reason
                    result["problem"] = f"summary.json unreadable: {e}"
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return result


def make_record(args, result, params, base, command):
    """The record of one case (what the report and cases.csv use) from what run_sil returned."""
    summary = result["summary"]
    exit_status = result["exit_status"]
    outcome = classify(
        summary,
        exit_status,
        args.speed_bound,
        args.angle_bound,
        args.latency_bound,
        result["problem"],
        getattr(args, "position_bound", None),
    )
    seed = result["seed"]
    return {
        "seed": seed,
        "index": split_case_seed(seed)[1],
        "params": params,
        "command": command,
        "exit_status": exit_status,
        "class": outcome["class"],
        "false_trip": outcome["false_trip"],
        "latency_s": outcome["latency_s"],
        "reason": outcome["reason"],
        "fault_name": fault_name(summary) if isinstance(summary, dict) and outcome["class"] != "crashed" else "",
        "metrics": (
            dict(extract_metrics(summary, params, base), failure_time_s=outcome["failure_time_s"])
            if outcome["class"] != "crashed"
            else {}
        ),
        "stderr_tail": result["stderr_tail"] if outcome["class"] == "crashed" else "",
        "summary": summary,
        "host": result.get("host", ""),
    }


def run_case(args, seed, base, csv_output=False):
    """Runs one case here, its outputs in DIR/cases/<seed>/ (--case: with the CSV); returns its record."""
    params = draw_parameters(seed, base)
    case_dir = os.path.join(args.out, "cases", str(seed))
    os.makedirs(case_dir, exist_ok=True)
    for stale in ("summary.json", "run.csv"):  # never read a previous run's output
        if os.path.exists(os.path.join(case_dir, stale)):
            os.remove(os.path.join(case_dir, stale))
    cmd = sil_command(args, seed, params, case_dir, csv_output)
    result = {
        "seed": seed,
        "exit_status": None,
        "problem": None,
        "stderr_tail": "",
        "summary": None,
        "host": os.uname().nodename,
    }
    stderr_text = ""
    try:
        proc = subprocess.run(
            cmd,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            errors="replace",
            timeout=args.case_timeout,
        )
        result["exit_status"], stderr_text = proc.returncode, proc.stderr
    except subprocess.TimeoutExpired as e:
        result["problem"] = f"timed out after {args.case_timeout:g} s"
        stderr_text = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
    except OSError as e:
        result["problem"] = f"cannot run pmstep-sil: {e}"
    result["stderr_tail"] = stderr_text[-STDERR_TAIL_CHARS:]
    if result["problem"] is None:
        try:
            with open(os.path.join(case_dir, "summary.json")) as f:
                result["summary"] = json.load(f)
        except FileNotFoundError:
            pass
        except (OSError, ValueError) as e:
            if result["exit_status"] in (0, FAULT_EXIT_STATUS):
                result["problem"] = f"summary.json unreadable: {e}"
    return make_record(args, result, params, base, cmd)


# --------------------------------------------------------------------------------------
# The campaign's folder: what defines it, and the cases already finished (resume)
# --------------------------------------------------------------------------------------
def file_sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def campaign_identity(args, scenario_text):
    """What fixes every case's result: the same identity, the same result for the same seed."""
    return {
        "pmstep_sil_sha256": file_sha256(args.sil),
        "scenario_sha256": hashlib.sha256(scenario_text.encode()).hexdigest(),
        "duration_s": args.duration,
        "distribution_table": [list(row) for row in DISTRIBUTIONS],
    }


def write_json_atomic(path, data):
    """Writes JSON so that a reader (or a resume after a kill) sees the whole file or none."""
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    os.replace(tmp, path)


def open_campaign(args, scenario_text):
    """Checks DIR/campaign.json against this run (writes it for a new folder); returns the
    finished results {seed: result} found in DIR/cases/*/result.json for this run's seeds."""
    identity = campaign_identity(args, scenario_text)
    path = os.path.join(args.out, CAMPAIGN_FILE)
    if os.path.exists(path):
        try:
            with open(path) as f:
                stored = json.load(f)
        except (OSError, ValueError) as e:
            raise ToolError(f"{path} unreadable ({e}): remove it, or use another --out") from None
        differ = [key for key in identity if stored.get(key) != identity[key]]
        if differ:
            raise ToolError(
                f"{args.out} holds another campaign ({', '.join(differ)} differ): its finished cases "
                "would not be this campaign's; use another --out (or remove the folder)"
            )
    else:
        os.makedirs(args.out, exist_ok=True)
        write_json_atomic(path, identity)
    done = {}
    for seed in args.seeds:
        result_path = os.path.join(args.out, "cases", str(seed), RESULT_FILE)
        try:
            with open(result_path) as f:
                result = json.load(f)
        except FileNotFoundError:
            continue
        except (OSError, ValueError):
            continue  # a torn or foreign file: the case runs again
        if isinstance(result, dict) and result.get("seed") == seed:
            done[seed] = result
    return done


def store_result(args, result):
    """Keeps a finished case: DIR/cases/<seed>/summary.json (as pmstep-sil wrote it) and result.json."""
    case_dir = os.path.join(args.out, "cases", str(result["seed"]))
    os.makedirs(case_dir, exist_ok=True)
    if result["summary"] is not None:
        write_json_atomic(os.path.join(case_dir, "summary.json"), result["summary"])
    write_json_atomic(os.path.join(case_dir, RESULT_FILE), result)


# --------------------------------------------------------------------------------------
# Engines
# --------------------------------------------------------------------------------------
def make_task(args, seed, base, scenario_text, shipped):
    """What run_sil needs for one case, and the case's drawn parameters."""
    params = draw_parameters(seed, base)
    task = {
        "seed": seed,
        "sil": None if shipped else os.path.abspath(args.sil),
        "sil_name": os.path.basename(args.sil),
        "scenario_text": scenario_text,
        "scenario_name": os.path.basename(args.scenario),
        "set": sil_arguments(seed, params, args.duration),
        "timeout_s": args.case_timeout,
    }
    return task, params


class ByValue:
    """A function that pickles as its own code (cloudpickle, its module registered by value),
    never as a reference to its module. Distributed pickles a task graph with pickle first,
    which names a function by module and name (mc_execution.run_sil); the scheduler unpickles
    the graph, so a scheduler and workers started without this folder on their path would fail
    with "No module named 'mc_execution'". This pickles as pickle.loads(<cloudpickle of the
    function>): unpickling it needs cloudpickle (a dependency of distributed) and nothing of
    these tools, and gives the plain function. One instance in a batch of tasks (Client.map)
    travels once per batch."""

    def __init__(self, func):
        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[func.__module__])
        self.func = func
        self.__name__ = func.__name__
        self.payload = cloudpickle.dumps(func)

    def __call__(self, *args, **kwargs):
        return self.func(*args, **kwargs)

    def __reduce__(self):
        return pickle.loads, (self.payload,)


DASK_BATCH = 1000  # cases per task graph sent to the scheduler (run_sil travels once per graph)


def run_threads(args, tasks, on_result):
    """The cases on a pool of args.jobs threads on this machine."""
    import concurrent.futures

    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(run_sil, task) for task in tasks]
        try:
            for future in concurrent.futures.as_completed(futures):
                on_result(future.result())
        except KeyboardInterrupt:
            for future in futures:
                future.cancel()
            raise
    return "threads", args.jobs


def run_dask(args, tasks, on_result):
    """The cases on Dask: an existing cluster (args.scheduler) or a local one of args.jobs
    single-threaded worker processes. A worker that dies takes its running cases with it;
    the scheduler runs them again on the others."""
    try:
        import dask
        from distributed import Client, LocalCluster, as_completed
        from distributed.diagnostics.plugin import UploadFile
    except ImportError as e:
        raise ToolError(
            f"the Dask engine needs dask.distributed ({e}): install tools/requirements.txt "
            "(e.g. tools/setup_venv.sh, then run with .venv/bin/python) or pass --engine threads"
        ) from None
    # The scheduler and the workers need nothing of these tools: run_sil travels by value (and
    # ShipSil below, a class of this module registered by value, too).
    case = ByValue(run_sil)
    cluster = None
    with dask.config.set(
        QUIET_DASK
    ):  # the local cluster's processes and this client (an external cluster's are its own)
        if args.scheduler:
            client = Client(args.scheduler, timeout="60s")
        else:
            cluster = LocalCluster(n_workers=args.jobs, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
    try:
        if args.ship_sil:

            class ShipSil(UploadFile):
                name = "pmstep-sil"  # its own plugin name, beside any other uploaded file

            client.register_plugin(ShipSil(args.sil, load=False))
        workers = len(client.scheduler_info(n_workers=-1)["workers"]) if args.scheduler else args.jobs
        futures = client.map(
            case, tasks, key=[f"pmstep-case-{task['seed']}" for task in tasks], pure=False, batch_size=DASK_BATCH
        )
        try:
            for future in as_completed(futures):
                on_result(future.result())
        except KeyboardInterrupt:
            client.cancel(futures)
            raise
        return ("dask " + (args.scheduler if args.scheduler else "local cluster")), workers
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_all(args, base, scenario_text):
    """Runs the campaign's unfinished cases on args.engine, keeping each as it finishes;
    returns (the records in case order, the engine's description, workers, cases resumed)."""
    done = open_campaign(args, scenario_text)
    records = {}
    progress = Progress(len(args.seeds))
    counter = {"done": 0, "failures": 0}
    commands = {}
    params_of = {}
    tasks = []
    for seed in args.seeds:
        task, params = make_task(args, seed, base, scenario_text, args.ship_sil)
        params_of[seed] = params
        commands[seed] = sil_command(args, seed, params, os.path.join(args.out, "cases", str(seed)), False)
        if seed not in done:
            tasks.append(task)

    def on_result(result, stored=False):
        if not stored:
            store_result(args, result)
        seed = result["seed"]
        record = make_record(args, result, params_of[seed], base, commands[seed])
        records[seed] = record
        counter["done"] += 1
        counter["failures"] += record["class"] != "success"
        progress.update(counter["done"], counter["failures"])

    if done:
        print(
            f"monte_carlo: resuming {args.out}: {len(done)} of {len(args.seeds)} cases already finished, "
            f"{len(tasks)} to run",
            file=sys.stderr,
        )
    for seed in args.seeds:
        if seed in done:
            on_result(done[seed], stored=True)
    engine, workers = ("none (every case was finished)", 0)
    if tasks:
        runner = run_dask if args.engine == "dask" else run_threads
        engine, workers = runner(args, tasks, on_result)
    return [records[seed] for seed in args.seeds], engine, workers, len(done)
