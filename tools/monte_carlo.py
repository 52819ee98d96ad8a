#!/usr/bin/env python3
"""Monte Carlo robustness runner for pmstep-sil: many randomised runs, one report.

Usage:
  tools/monte_carlo.py --sil PATH/pmstep-sil --scenario sil/scenarios/robust.ini \\
      --cases N --seed S [--jobs J] --out DIR [--duration SECONDS] [--no-plots] [--check]
  tools/monte_carlo.py --sil PATH/pmstep-sil --scenario FILE --out DIR --case CASE_SEED

Each case draws plant, sensor, inverter, bus, initial-angle and load parameters from the
distribution table DISTRIBUTIONS below (relative to the values of the scenario file, read
once with `pmstep-sil --scenario FILE --print-scenario`) and runs pmstep-sil with them as
`--set section.key=value` overrides, plus `--set run.seed=CASE_SEED` so that the SIL's own
noise is reproducible too.

Seeds: case k (0-based) of a run with base seed S has the case seed S * 100000 + k
(so --cases is at most 100000). The case seed alone fixes everything about a case: its
parameters are drawn by random.Random(case_seed), one draw per row of DISTRIBUTIONS in
table order, and it is the SIL's run.seed. `--case CASE_SEED` re-runs that one case (with
the CSV time series, so `tools/plot_run.py DIR/cases/CASE_SEED` can draw it), prints the
pmstep-sil command line, the drawn parameters, the class and the summary.

Classes (see classify()):
  success      no fault latched, no non-finite value, and after settling
               max |w - w*| < --speed-bound (0.5 rad/s), max angle error < --angle-bound (0.05 rad)
  detected     a fault latched; if the SIL saw a loss of control, the fault came at most
               --latency-bound (0.05 s) after it (the latency is recorded); without a loss of
               control the fault is a false trip (still "detected", counted apart)
  silent       a loss of control with no fault latched within --latency-bound after it
  out_of_spec  no loss of control and no fault, but a bound exceeded (or a non-finite value)
  crashed      pmstep-sil exited other than 0 (ran) or 3 (ran, fault latched), timed out,
               or left no readable summary.json with the fields this tool needs

Outputs in DIR: report.md (with PNG histograms unless --no-plots), cases.csv (one row per
case), summary.json (the aggregate numbers), cases/<case seed>/summary.json (each run).

--check exits with status 1 unless the success rate is >= --min-success (0.99), no case is
silent, none crashed and none saw a non-finite value. The last line printed is always
"N passed, N failed" (passed = success cases, failed = all others).

Only the standard library is needed to run the cases and write the report; numpy and
matplotlib (tools/requirements.txt) are imported only to draw the histograms.
"""
import argparse
import concurrent.futures
import configparser
import csv
import datetime
import json
import math
import os
import shlex
import signal
import statistics
import subprocess
import sys
import threading
import time

# --------------------------------------------------------------------------------------
# The distribution table: the one place that says what is randomised and how.
# (key, kind, a, b):
#   kind "scale":   value = (the scenario file's value) * U[a, b]
#   kind "times K": value = (the value drawn for the earlier row K) * U[a, b]
#   kind "uniform": value = U[a, b]   (the scenario file's value is not used)
# U[a, b] is a + (b - a) * random(), random() in [0, 1): b itself is never drawn.
# --------------------------------------------------------------------------------------
DISTRIBUTIONS = [
    ("motor.resistance_Ohm", "scale", 0.7, 1.3),
    ("motor.inductance_H", "scale", 0.8, 1.2),
    ("motor.torque_constant_Nm_A", "scale", 0.9, 1.1),
    ("motor.inertia_kgm2", "scale", 0.5, 1.5),
    ("motor.friction_Nms_rad", "uniform", 0.0, 0.005),
    ("sensors.offset_a_A", "uniform", -0.02, 0.02),
    ("sensors.offset_b_A", "uniform", -0.02, 0.02),
    ("sensors.gain_error_a", "uniform", -0.01, 0.01),
    ("sensors.gain_error_b", "uniform", -0.01, 0.01),
    # Half to one and a half times the acceptance's 5 mA: a real current channel is never quieter
    # than about half an LSB (8 mA at 12 bits over +-16.5 A); README shows what an undithered one does.
    ("sensors.noise_rms_A", "uniform", 0.0025, 0.0075),
    ("inverter.dead_time_s", "uniform", 0.0, 1.5e-6),
    ("bus.ripple_V", "uniform", 0.0, 2.0),
    ("bus.source_resistance_Ohm", "uniform", 0.0, 0.2),
    ("run.theta0_deg", "uniform", 0.0, 360.0),
    ("load.torque_Nm", "scale", 0.0, 1.0),
    # The firmware compensates the dead time its timer is programmed with; the bridge's own
    # switching delays make the real one differ by up to 10 %.
    ("controller.inverter.dead_time_s", "times inverter.dead_time_s", 0.9, 1.1),
]

SEED_STRIDE = 100000          # case seed = base seed * SEED_STRIDE + case index
SEED_KEY = "run.seed"         # the SIL's noise seed
DURATION_KEY = "run.duration_s"
FAULT_EXIT_STATUS = 3         # pmstep-sil: the run finished and a fault is latched
WILSON_Z_95 = 1.959963984540054
STDERR_TAIL_CHARS = 2000
WORST_CASES = 10

CLASSES = ("success", "detected", "silent", "out_of_spec", "crashed")
CLASS_TEXT = {
    "success": "success",
    "detected": "detected (fault latched)",
    "silent": "silent failure (loss of control, no fault in time)",
    "out_of_spec": "out of spec (bound exceeded, no fault)",
    "crashed": "crashed (pmstep-sil failed or no summary)",
}

# Fields of summary.json that classification needs: (path, type check).
REQUIRED_FIELDS = (
    (("fault", "code"), "number"),
    (("fault", "time_s"), "number"),
    (("robustness", "loss_of_control_time_s"), "number"),
    (("robustness", "max_speed_error_rad_s"), "number_or_null"),
    (("robustness", "max_angle_error_rad"), "number_or_null"),
    (("robustness", "nonfinite_seen"), "bool"),
)

# Drawn parameters shown in the worst-case table (key, column title, show as factor).
KEY_PARAMETERS = (
    ("motor.resistance_Ohm", "R/R0", True),
    ("motor.inductance_H", "L/L0", True),
    ("motor.torque_constant_Nm_A", "k_M/k_M0", True),
    ("motor.inertia_kgm2", "J/J0", True),
    ("inverter.dead_time_s", "dead time (us)", False),
    ("load.torque_Nm", "load (Nm)", False),
    ("run.theta0_deg", "theta0 (deg)", False),
)


class ToolError(Exception):
    """A problem with the inputs or the installed pmstep-sil: message for the user, exit status 2."""


# --------------------------------------------------------------------------------------
# Pure functions (tested by tools/test_monte_carlo.py)
# --------------------------------------------------------------------------------------
def case_seed(base_seed, index):
    """Case seed of case `index` (0-based) in a run with base seed `base_seed`."""
    if not 0 <= index < SEED_STRIDE:
        raise ValueError(f"case index {index} outside [0, {SEED_STRIDE})")
    if base_seed < 0:
        raise ValueError(f"base seed {base_seed} is negative")
    return base_seed * SEED_STRIDE + index


def split_case_seed(seed):
    """(base seed, case index) of a case seed: the inverse of case_seed()."""
    return divmod(seed, SEED_STRIDE)


def parse_scenario(text):
    """Scenario INI text (pmstep-sil --print-scenario) to {"section.key": "value"}."""
    parser = configparser.ConfigParser(comment_prefixes=(";", "#"), inline_comment_prefixes=None,
                                       interpolation=None, strict=False)
    parser.optionxform = str  # keep the keys' case
    parser.read_string(text)
    return {f"{section}.{key}": value.strip()
            for section in parser.sections() for key, value in parser.items(section)}


def missing_keys(scenario, table=DISTRIBUTIONS, extra=(SEED_KEY,)):
    """Keys of the distribution table (and `extra`) that the scenario listing lacks, in order."""
    wanted = [row[0] for row in table] + list(extra)
    return [key for key in wanted if key not in scenario]


def base_values(scenario, table=DISTRIBUTIONS):
    """{key: float} of the scenario's value of every "scale" row; ToolError if not a number."""
    values = {}
    for key, kind, _a, _b in table:
        if kind != "scale":
            continue
        try:
            value = float(scenario[key])
        except ValueError:
            raise ToolError(f"scenario value of {key} is '{scenario[key]}', not a number") from None
        if not math.isfinite(value):
            raise ToolError(f"scenario value of {key} is '{scenario[key]}', not finite")
        values[key] = value
    return values


def draw_parameters(seed, base, table=DISTRIBUTIONS):
    """Parameters of the case with this case seed: {key: value}, in table order.

    One random() per row, in table order, from random.Random(seed); `base` holds the
    scenario values of the "scale" rows.
    """
    import random  # local: the module is only needed here

    rng = random.Random(seed)
    params = {}
    for key, kind, a, b in table:
        u = a + (b - a) * rng.random()
        if kind == "scale":
            params[key] = base[key] * u
        elif kind == "uniform":
            params[key] = u
        elif kind.startswith("times ") and kind[len("times "):] in params:
            params[key] = params[kind[len("times "):]] * u
        else:
            raise ValueError(f"{key}: unknown distribution kind '{kind}'")
    return params


def format_value(value):
    """A float as pmstep-sil reads it back exactly (shortest round-trip repr)."""
    return repr(float(value))


def get_path(summary, path):
    """summary[path[0]][path[1]]..., or KeyError naming the dotted path."""
    node = summary
    for part in path:
        if not isinstance(node, dict) or part not in node:
            raise KeyError(".".join(path))
        node = node[part]
    return node


def summary_problem(summary):
    """None if `summary` has every field classify() needs, else a text naming the first bad one."""
    if not isinstance(summary, dict):
        return "summary.json is not a JSON object"
    for path, kind in REQUIRED_FIELDS:
        name = ".".join(path)
        try:
            value = get_path(summary, path)
        except KeyError:
            return f"summary.json has no field {name} (pmstep-sil older than this tool?)"
        is_number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if kind == "number" and not is_number:
            return f"summary.json field {name} is {value!r}, not a number"
        if kind == "number_or_null" and not (is_number or value is None):
            return f"summary.json field {name} is {value!r}, not a number"
        if kind == "bool" and not isinstance(value, bool):
            return f"summary.json field {name} is {value!r}, not true/false"
    return None


def number_or_none(value):
    """A finite float, or None (JSON null, NaN, infinity, missing)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def fault_name(summary):
    """The latched fault's name ("" if none): fault.name, else fault.text, else the code."""
    fault = summary.get("fault", {})
    if not fault.get("code"):
        return ""
    return str(fault.get("name") or fault.get("text") or f"code {fault.get('code')}")


def classify(summary, exit_status, speed_bound_rad_s=0.5, angle_bound_rad=0.05, latency_bound_s=0.05,
             problem=None):
    """Class of one run: dict with "class", "false_trip", "latency_s", "reason".

    summary: the parsed summary.json (None if missing or unparsable); exit_status: the
    process's exit status (negative: killed by that signal; None: timed out); problem: a
    text that makes the run "crashed" whatever the summary says (e.g. a timeout).
    """
    def result(cls, reason, false_trip=False, latency_s=None):
        return {"class": cls, "false_trip": false_trip, "latency_s": latency_s, "reason": reason}

    if problem:
        return result("crashed", problem)
    if exit_status is None:
        return result("crashed", "timed out")
    if exit_status < 0:
        try:
            name = signal.Signals(-exit_status).name
        except ValueError:
            name = f"signal {-exit_status}"
        return result("crashed", f"pmstep-sil killed by {name}")
    if exit_status not in (0, FAULT_EXIT_STATUS):
        return result("crashed", f"pmstep-sil exited with status {exit_status}")
    if summary is None:
        return result("crashed", "no readable summary.json")
    bad = summary_problem(summary)
    if bad:
        return result("crashed", bad)

    fault_code = summary["fault"]["code"]
    if (fault_code != 0) != (exit_status == FAULT_EXIT_STATUS):
        return result("crashed", f"exit status {exit_status} disagrees with fault code {fault_code}")
    rob = summary["robustness"]
    loss_time_s = rob["loss_of_control_time_s"]
    lost = loss_time_s >= 0.0

    if fault_code != 0:
        if not lost:
            return result("detected", f"false trip: {fault_name(summary)} without loss of control", false_trip=True)
        latency_s = number_or_none(rob.get("detection_latency_s"))
        if latency_s is None:
            latency_s = summary["fault"]["time_s"] - loss_time_s
        if latency_s > latency_bound_s:
            return result("silent", f"loss of control at {loss_time_s:.6g} s, {fault_name(summary)} "
                                    f"only {latency_s:.3g} s later (> {latency_bound_s:g} s)", latency_s=latency_s)
        return result("detected", f"loss of control at {loss_time_s:.6g} s caught by {fault_name(summary)} "
                                  f"after {latency_s:.3g} s", latency_s=latency_s)
    if lost:
        realignments = number_or_none((summary.get("commissioning") or {}).get("realignments"))
        note = f" ({realignments:g} re-alignment(s))" if realignments else ""
        return result("silent", f"loss of control at {loss_time_s:.6g} s, no fault latched{note}")

    speed_error = number_or_none(rob["max_speed_error_rad_s"])
    angle_error = number_or_none(rob["max_angle_error_rad"])
    exceeded = []
    if rob["nonfinite_seen"]:
        exceeded.append("non-finite value seen")
    if speed_error is None or speed_error >= speed_bound_rad_s:
        exceeded.append(f"max speed error {rob['max_speed_error_rad_s']} rad/s >= {speed_bound_rad_s:g}")
    if angle_error is None or angle_error >= angle_bound_rad:
        exceeded.append(f"max angle error {rob['max_angle_error_rad']} rad >= {angle_bound_rad:g}")
    if exceeded:
        return result("out_of_spec", "; ".join(exceeded))
    return result("success", "")


def wilson_interval(successes, n, z=WILSON_Z_95):
    """Wilson score interval (low, high) of a binomial proportion; (0, 1) when n == 0."""
    if n == 0:
        return (0.0, 1.0)
    if not 0 <= successes <= n:
        raise ValueError(f"{successes} successes out of {n}")
    p = successes / n
    z2 = z * z
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = z / (1 + z2 / n) * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n))
    return (max(0.0, centre - half), min(1.0, centre + half))


def percentile(values, q):
    """q-th percentile (0..100) by linear interpolation between order statistics
    (numpy's default "linear" method); None for no values."""
    if not 0 <= q <= 100:
        raise ValueError(f"percentile {q} outside [0, 100]")
    data = sorted(values)
    if not data:
        return None
    pos = (len(data) - 1) * q / 100.0
    lo = math.floor(pos)
    hi = min(lo + 1, len(data) - 1)
    return data[lo] + (data[hi] - data[lo]) * (pos - lo)


def spans_decades(values, decades=2.0):
    """True if the positive values span at least `decades` powers of ten (use a log axis)."""
    positive = [v for v in values if v > 0]
    return len(positive) >= 2 and math.log10(max(positive) / min(positive)) >= decades


def worst_order(cases):
    """Cases sorted for the worst-case table: failures (any class but success) first, then
    by max speed error after settling, largest first (a missing value counts as infinite)."""
    def key(case):
        speed = case["metrics"].get("max_speed_error_rad_s")
        return (case["class"] == "success", -(speed if speed is not None else math.inf), case["seed"])
    return sorted(cases, key=key)


# --------------------------------------------------------------------------------------
# Running pmstep-sil
# --------------------------------------------------------------------------------------
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
                how = f"{kind[len('times '):]} x U[{a:g}, {b:g}]"
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
        "at one that does; no key is skipped.")


def sil_command(args, seed, params, case_dir, csv_output):
    """The pmstep-sil command line of one case."""
    cmd = [args.sil, "--scenario", args.scenario, "--out", case_dir, "--quiet"]
    if not csv_output:
        cmd.append("--no-csv")
    cmd += ["--set", f"{SEED_KEY}={seed}"]
    if args.duration is not None:
        cmd += ["--set", f"{DURATION_KEY}={format_value(args.duration)}"]
    for key, value in params.items():
        cmd += ["--set", f"{key}={format_value(value)}"]
    return cmd


def rerun_command(args, seed):
    """The command that re-runs one case with this tool (same bounds, same output folder)."""
    cmd = ["python3", args.script, "--sil", args.sil, "--scenario", args.scenario, "--out", args.out]
    if args.duration is not None:
        cmd += ["--duration", format_value(args.duration)]
    for option, default in (("speed_bound", 0.5), ("angle_bound", 0.05), ("latency_bound", 0.05)):
        value = getattr(args, option)
        if value != default:
            cmd += ["--" + option.replace("_", "-"), format_value(value)]
    for key in getattr(args, "exclude", []):
        cmd += ["--exclude", key]
    return cmd + ["--case", str(seed)]


def extract_metrics(summary, params, base):
    """Numbers of one run for the tables and cases.csv (None where not available)."""
    if not isinstance(summary, dict):
        return {}
    rob = summary.get("robustness") or {}
    com = summary.get("commissioning") or {}
    fault = summary.get("fault") or {}
    metrics = {
        "max_speed_error_rad_s": number_or_none(rob.get("max_speed_error_rad_s")),
        "max_angle_error_rad": number_or_none(rob.get("max_angle_error_rad")),
        "settle_time_s": number_or_none(rob.get("settle_time_s")),
        "loss_of_control_time_s": number_or_none(rob.get("loss_of_control_time_s")),
        "detection_latency_s": number_or_none(rob.get("detection_latency_s")),
        "nonfinite_seen": bool(rob.get("nonfinite_seen", False)),
        "tracking_max_abs_error_rad_s": number_or_none((summary.get("speed") or {}).get("tracking_max_abs_error_rad_s")),
        "fault_time_s": number_or_none(fault.get("time_s")),
        "wall_s": number_or_none((summary.get("timing") or {}).get("wall_s")),
        "commissioning_measured": bool(com.get("measured", False)),
        "realignments": number_or_none(com.get("realignments")),
        "final_mode": str(summary.get("final_mode", "")),
    }
    # The "after settling" maxima mean nothing when a fault stopped the run before settling.
    settle_s, fault_s = metrics["settle_time_s"], metrics["fault_time_s"]
    metrics["past_settle"] = not (fault.get("code") and settle_s is not None and fault_s is not None
                                  and 0.0 <= fault_s < settle_s)
    # Commissioned value against the plant's (drawn, else the scenario's) value.
    for name, key, field in (("r_rel_error", "motor.resistance_Ohm", "resistance_Ohm"),
                             ("l_rel_error", "motor.inductance_H", "inductance_H"),
                             ("k_rel_error", "motor.torque_constant_Nm_A", "torque_constant_Nm_A")):
        plant = params.get(key, base.get(key))
        measured = number_or_none(com.get(field))
        ok = metrics["commissioning_measured"] and measured is not None and plant
        metrics[name] = measured / plant - 1.0 if ok else None
    for name, key, field in (("offset_a_error_A", "sensors.offset_a_A", "offset_a_A"),
                             ("offset_b_error_A", "sensors.offset_b_A", "offset_b_A")):
        measured = number_or_none(com.get(field))
        ok = metrics["commissioning_measured"] and measured is not None and key in params
        metrics[name] = measured - params[key] if ok else None
    return metrics


def run_case(args, seed, base, csv_output=False):
    """Runs one case; returns its record (parameters, command, class, metrics, stderr tail)."""
    params = draw_parameters(seed, base)
    case_dir = os.path.join(args.out, "cases", str(seed))
    os.makedirs(case_dir, exist_ok=True)
    summary_path = os.path.join(case_dir, "summary.json")
    for stale in ("summary.json", "run.csv"):  # never read a previous run's output
        if os.path.exists(os.path.join(case_dir, stale)):
            os.remove(os.path.join(case_dir, stale))
    cmd = sil_command(args, seed, params, case_dir, csv_output)
    exit_status, stderr_text, problem = None, "", None
    try:
        proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                              errors="replace", timeout=args.case_timeout)
        exit_status, stderr_text = proc.returncode, proc.stderr
    except subprocess.TimeoutExpired as e:
        problem = f"timed out after {args.case_timeout:g} s"
        stderr_text = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
    except OSError as e:
        problem = f"cannot run pmstep-sil: {e}"
    summary = None
    if problem is None:
        try:
            with open(summary_path) as f:
                summary = json.load(f)
        except FileNotFoundError:
            summary = None
        except (OSError, ValueError) as e:
            problem = f"summary.json unreadable: {e}"
            if exit_status not in (0, FAULT_EXIT_STATUS):
                problem = None  # the exit status is the better reason
    outcome = classify(summary, exit_status, args.speed_bound, args.angle_bound, args.latency_bound, problem)
    return {
        "seed": seed,
        "index": split_case_seed(seed)[1],
        "params": params,
        "command": cmd,
        "exit_status": exit_status,
        "class": outcome["class"],
        "false_trip": outcome["false_trip"],
        "latency_s": outcome["latency_s"],
        "reason": outcome["reason"],
        "fault_name": fault_name(summary) if isinstance(summary, dict) and outcome["class"] != "crashed" else "",
        "metrics": extract_metrics(summary, params, base) if outcome["class"] != "crashed" else {},
        "stderr_tail": stderr_text[-STDERR_TAIL_CHARS:] if outcome["class"] == "crashed" else "",
        "summary": summary,
    }


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
            line = (f"monte_carlo: {done}/{self.total} cases ({100.0 * done / self.total:.0f} %), "
                    f"{failures} failure{'s' if failures != 1 else ''}, elapsed {elapsed_s:.1f} s, ETA {eta_s:.1f} s")
            if self.tty:
                self.stream.write("\r" + line + "\033[K" + ("\n" if done == self.total else ""))  # [K: clear the rest
                self.stream.flush()
                return
            decile = done * 10 // self.total
            if decile > self.last_decile:
                self.last_decile = decile
                self.stream.write(line + "\n")
                self.stream.flush()


def run_all(args, base):
    """Runs the cases over args.jobs workers; returns the records in case order."""
    seeds = [case_seed(args.seed, k) for k in range(args.cases)]
    records = [None] * len(seeds)
    progress = Progress(len(seeds))
    failures = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run_case, args, seed, base): k for k, seed in enumerate(seeds)}
        try:
            for done, future in enumerate(concurrent.futures.as_completed(futures), start=1):
                record = future.result()
                records[futures[future]] = record
                failures += record["class"] != "success"
                progress.update(done, failures)
        except KeyboardInterrupt:
            for future in futures:
                future.cancel()
            raise
    return records


# --------------------------------------------------------------------------------------
# Aggregation and report
# --------------------------------------------------------------------------------------
def aggregate(records, args):
    """The aggregate numbers (what summary.json holds)."""
    n = len(records)
    counts = {cls: sum(1 for r in records if r["class"] == cls) for cls in CLASSES}
    false_trips = sum(1 for r in records if r["class"] == "detected" and r["false_trip"])
    low, high = wilson_interval(counts["success"], n)
    faults = {}
    for r in records:
        if r["fault_name"]:
            faults[r["fault_name"]] = faults.get(r["fault_name"], 0) + 1
    nonfinite = sum(1 for r in records if r["metrics"].get("nonfinite_seen"))
    latencies = [r["latency_s"] for r in records
                 if r["class"] == "detected" and not r["false_trip"] and r["latency_s"] is not None]

    def stats(name, transform=lambda v: v, past_settle_only=False):
        values = [transform(r["metrics"][name]) for r in records if r["metrics"].get(name) is not None
                  and (r["metrics"]["past_settle"] or not past_settle_only)]
        out = {"n": len(values)}
        for q in (50, 90, 99):
            out[f"p{q}"] = percentile(values, q)
        out["max"] = max(values) if values else None
        return out

    distributions = {
        "max_speed_error_rad_s": stats("max_speed_error_rad_s", past_settle_only=True),
        "max_angle_error_rad": stats("max_angle_error_rad", past_settle_only=True),
        "commissioning_abs_r_rel_error": stats("r_rel_error", abs),
        "commissioning_abs_l_rel_error": stats("l_rel_error", abs),
        "commissioning_abs_k_rel_error": stats("k_rel_error", abs),
        "commissioning_abs_offset_a_error_A": stats("offset_a_error_A", abs),
        "commissioning_abs_offset_b_error_A": stats("offset_b_error_A", abs),
    }
    for name in ("r_rel_error", "l_rel_error", "k_rel_error"):
        values = [r["metrics"][name] for r in records if r["metrics"].get(name) is not None]
        distributions[f"commissioning_abs_{name}"]["mean_signed"] = statistics.fmean(values) if values else None
    return {
        "cases": n,
        "base_seed": args.seed,
        "success_rate": counts["success"] / n if n else None,
        "success_rate_wilson95": [low, high],
        "counts": counts,
        "detected_losses": counts["detected"] - false_trips,
        "false_trips": false_trips,
        "faults_by_name": dict(sorted(faults.items(), key=lambda kv: (-kv[1], kv[0]))),
        "nonfinite_cases": nonfinite,
        "detection_latency_s": {"n": len(latencies), "max": max(latencies) if latencies else None,
                                "median": statistics.median(latencies) if latencies else None},
        "distributions": distributions,
        "bounds": {"speed_bound_rad_s": args.speed_bound, "angle_bound_rad": args.angle_bound,
                   "latency_bound_s": args.latency_bound},
    }


def check_verdict(agg, min_success):
    """Reasons why --check fails (empty list: it passes)."""
    reasons = []
    n = agg["cases"]
    if n == 0:
        return ["no case was run"]
    if agg["success_rate"] < min_success:
        reasons.append(f"success rate {agg['success_rate']:.4f} < {min_success:g}")
    if agg["counts"]["silent"]:
        reasons.append(f"{agg['counts']['silent']} silent failure(s)")
    if agg["counts"]["crashed"]:
        reasons.append(f"{agg['counts']['crashed']} crashed case(s)")
    if agg["nonfinite_cases"]:
        reasons.append(f"{agg['nonfinite_cases']} case(s) with a non-finite value")
    return reasons


def fmt(value, spec=".3g"):
    """A number for the report ("-" for None)."""
    return "-" if value is None else format(value, spec)


def distribution_rows(scenario):
    """Rows of the distribution table for the report: key, law, scenario value, drawn range."""
    rows = []
    for key, kind, a, b in DISTRIBUTIONS:
        if kind == "scale":
            value = float(scenario[key])
            rows.append((key, f"scenario value x U[{a:g}, {b:g}]", f"{value:g}", f"[{value * a:.4g}, {value * b:.4g})"))
        elif kind.startswith("times "):
            rows.append((key, f"{kind[len('times '):]} x U[{a:g}, {b:g}]", f"{scenario.get(key, '-')} (replaced)",
                         "-"))
        else:
            rows.append((key, f"U[{a:g}, {b:g}]", f"{scenario.get(key, '-')} (replaced)", f"[{a:g}, {b:g})"))
    return rows


def make_plots(out_dir, records, args):
    """Histograms (PNG) into out_dir; returns [(title, file name)]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    def values(name, past_settle_only):
        return [r["metrics"][name] for r in records if r["metrics"].get(name) is not None
                and (r["metrics"]["past_settle"] or not past_settle_only)]

    plots = []

    def histogram(data, title, xlabel, file_name, bound=None):
        fig, ax = plt.subplots(figsize=(7, 4))
        note = ""
        if bound is not None and spans_decades(data):
            positive = [v for v in data if v > 0]
            zeros = len(data) - len(positive)
            lo, hi = min(positive), max(max(positive), bound)
            ax.hist(positive, bins=np.geomspace(lo, hi * 1.0001, 40), color="tab:blue")
            ax.set_xscale("log")
            if zeros:
                note = f" ({zeros} case{'s' if zeros != 1 else ''} at 0 not shown)"
        else:
            ax.hist(data, bins=40, color="tab:blue")
        if bound is not None:
            ax.axvline(bound, color="tab:red", linestyle="--", label=f"bound {bound:g}")
            ax.legend()
        ax.set_xlabel(xlabel)
        ax.set_ylabel("cases")
        ax.set_title(f"{title}, {len(data)} cases{note}" + ("\n(cases not stopped by a fault before settling)"
                                                           if bound is not None else ""), fontsize=10)
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, file_name), dpi=110)
        plt.close(fig)
        plots.append((title, file_name))

    for name, title, xlabel, file_name, bound in (
            ("max_speed_error_rad_s", "Max speed error after settling", "max |w - w*| (rad/s)",
             "hist_speed_error.png", args.speed_bound),
            ("max_angle_error_rad", "Max angle-estimate error after settling", "max |angle error| (rad)",
             "hist_angle_error.png", args.angle_bound),
            ("r_rel_error", "Commissioned R relative error", "R_commissioned / R_plant - 1",
             "hist_commissioning_r.png", None),
            ("l_rel_error", "Commissioned L relative error", "L_commissioned / L_plant - 1",
             "hist_commissioning_l.png", None)):
        data = values(name, past_settle_only=bound is not None)
        if data:
            histogram(data, title, xlabel, file_name, bound)
    return plots


def write_report(path, records, agg, args, scenario, version, plots, started_utc):
    """DIR/report.md."""
    n = agg["cases"]
    counts = agg["counts"]
    low, high = agg["success_rate_wilson95"]
    lines = ["# Monte Carlo robustness report", ""]
    lines += [f"- command: `{shlex.join(args.argv)}`",
              f"- scenario: `{args.scenario}` (name `{scenario.get('scenario.name', '?')}`)",
              f"- cases: {n}, base seed {args.seed} (case k has seed {args.seed} * {SEED_STRIDE} + k)",
              f"- date: {started_utc}"]
    if version:
        lines.append(f"- pmstep-sil: {version}")
    if args.duration is not None:
        lines.append(f"- duration: {args.duration:g} s per case (`--set {DURATION_KEY}`)")
    lines.append(f"- bounds: max speed error < {args.speed_bound:g} rad/s, max angle error < {args.angle_bound:g} rad "
                 f"(after settling), fault within {args.latency_bound:g} s of a loss of control")
    lines.append("")
    rate = agg["success_rate"]
    lines += ["## Result", "",
              f"**Success rate: {counts['success']}/{n} = {fmt(100 * rate if rate is not None else None, '.1f')} %** "
              f"(Wilson 95 % interval {100 * low:.1f} % to {100 * high:.1f} %)", "",
              "| class | cases |", "|---|---|"]
    for cls in CLASSES:
        lines.append(f"| {CLASS_TEXT[cls]} | {counts[cls]} |")
    lines += [f"| of which detected losses of control | {agg['detected_losses']} |",
              f"| of which false trips (fault, no loss of control) | {agg['false_trips']} |", "",
              f"Cases that saw a non-finite value (NaN/Inf): {agg['nonfinite_cases']}", ""]
    lat = agg["detection_latency_s"]
    if lat["n"]:
        lines += [f"Detection latency over the {lat['n']} detected losses of control: "
                  f"max {lat['max'] * 1e3:.3g} ms, median {lat['median'] * 1e3:.3g} ms", ""]
    else:
        lines += ["Detection latency: no detected loss of control.", ""]
    if agg["faults_by_name"]:
        lines += ["Faults latched, by name:", "", "| fault | cases |", "|---|---|"]
        lines += [f"| {name} | {count} |" for name, count in agg["faults_by_name"].items()]
        lines.append("")
    else:
        lines += ["No fault latched in any case.", ""]

    lines += ["## Distributions", "",
              "Over the cases that produced the value: the errors after settling over the cases not stopped by "
              "a fault before settling, the commissioning errors where the core measured.", "",
              "| quantity | n | p50 | p90 | p99 | max |", "|---|---|---|---|---|---|"]
    titles = (("max_speed_error_rad_s", "max speed error after settling (rad/s)"),
              ("max_angle_error_rad", "max angle error after settling (rad)"),
              ("commissioning_abs_r_rel_error", "\\|R commissioned / R plant - 1\\|"),
              ("commissioning_abs_l_rel_error", "\\|L commissioned / L plant - 1\\|"),
              ("commissioning_abs_k_rel_error", "\\|k_M commissioned / k_M plant - 1\\|"),
              ("commissioning_abs_offset_a_error_A", "\\|offset a commissioned - true\\| (A)"),
              ("commissioning_abs_offset_b_error_A", "\\|offset b commissioned - true\\| (A)"))
    for name, title in titles:
        d = agg["distributions"][name]
        lines.append(f"| {title} | {d['n']} | {fmt(d['p50'])} | {fmt(d['p90'])} | {fmt(d['p99'])} | {fmt(d['max'])} |")
    bias = [(label, agg["distributions"][f"commissioning_abs_{name}"]["mean_signed"])
            for label, name in (("R", "r_rel_error"), ("L", "l_rel_error"), ("k_M", "k_rel_error"))]
    if any(v is not None for _l, v in bias):
        lines += ["", "Mean signed commissioning error: " + ", ".join(f"{label} {fmt(v, '+.3g')}" for label, v in bias)]
    lines.append("")
    for title, file_name in plots:
        lines += [f"![{title}]({file_name})", ""]

    worst = worst_order(records)[:WORST_CASES]
    lines += [f"## The {len(worst)} worst cases", "",
              "Failures first, then by max speed error after settling. Re-run one with the command in the "
              "last column (from the same working folder); it writes the CSV too, for `tools/plot_run.py`.", ""]
    header = ["seed", "class", "fault", "max speed err (rad/s)", "max angle err (rad)"]
    header += [title for _k, title, _f in KEY_PARAMETERS] + ["re-run"]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in worst:
        m = r["metrics"]
        cells = [str(r["seed"]), r["class"] + (" (false trip)" if r["false_trip"] else ""), r["fault_name"] or "-",
                 fmt(m.get("max_speed_error_rad_s")), fmt(m.get("max_angle_error_rad"))]
        for key, _title, as_factor in KEY_PARAMETERS:
            value = r["params"].get(key)
            if value is None:
                cells.append("-")
            elif as_factor:
                cells.append(f"{value / float(scenario[key]):.3f}" if float(scenario[key]) else fmt(value))
            elif key == "inverter.dead_time_s":
                cells.append(f"{value * 1e6:.3f}")
            else:
                cells.append(f"{value:.4g}")
        cells.append(f"`{shlex.join(rerun_command(args, r['seed']))}`")
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    if worst:
        lines += ["The same cases as raw pmstep-sil commands (what the tool ran):", ""]
    for r in worst:
        lines += [f"Case {r['seed']} ({r['class']}){': ' + r['reason'] if r['reason'] else ''}", "",
                  "```sh", shlex.join(r["command"]), "```"]
        if r["stderr_tail"].strip():
            lines += ["", "stderr (tail):", "", "```", r["stderr_tail"].rstrip(), "```"]
        lines.append("")

    lines += ["## Distribution table", "",
              "Drawn per case by `random.Random(case seed)`, one draw per row in this order "
              "(`DISTRIBUTIONS` in tools/monte_carlo.py); U[a, b] excludes b.", "",
              "| key | drawn as | scenario file's value | range |", "|---|---|---|---|"]
    lines += [f"| `{key}` | {law} | {value} | {span} |" for key, law, value, span in distribution_rows(scenario)]
    lines += ["", f"Every case also sets `{SEED_KEY}` to its case seed (the SIL's noise).", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


CSV_METRICS = ("max_speed_error_rad_s", "max_angle_error_rad", "settle_time_s", "loss_of_control_time_s",
               "detection_latency_s", "fault_time_s", "nonfinite_seen", "tracking_max_abs_error_rad_s",
               "commissioning_measured", "r_rel_error", "l_rel_error", "k_rel_error", "offset_a_error_A",
               "offset_b_error_A", "realignments", "final_mode", "past_settle", "wall_s")


def write_cases_csv(path, records):
    """DIR/cases.csv: one row per case."""
    keys = [row[0] for row in DISTRIBUTIONS]
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["seed", "class", "false_trip", "fault_name", "exit_status"] + keys + list(CSV_METRICS)
                        + ["reason"])
        for r in records:
            row = [r["seed"], r["class"], int(r["false_trip"]), r["fault_name"],
                   "" if r["exit_status"] is None else r["exit_status"]]
            row += [format_value(r["params"][k]) for k in keys]
            for name in CSV_METRICS:
                value = r["metrics"].get(name)
                if value is None:
                    row.append("")
                elif isinstance(value, bool):
                    row.append(int(value))
                elif isinstance(value, str):
                    row.append(value)
                else:
                    row.append(format_value(value))
            row.append(r["reason"])
            writer.writerow(row)


# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------
def parse_args(argv):
    parser = argparse.ArgumentParser(
        description="Monte Carlo robustness runner for pmstep-sil (see the module docstring).",
        formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__.split("\n\n", 1)[1])
    parser.add_argument("--sil", required=True, help="the pmstep-sil executable")
    parser.add_argument("--scenario", required=True, help="scenario INI file the cases start from")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--cases", type=int, default=100, help="number of cases N (default 100)")
    parser.add_argument("--seed", type=int, default=1, help="base seed S: case k has seed S*100000+k (default 1)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel runs (default: cores)")
    parser.add_argument("--duration", type=float, default=None, metavar="SECONDS",
                        help="simulated time per case (run.duration_s; default: the scenario's)")
    parser.add_argument("--no-plots", action="store_true", help="no PNG histograms (no numpy/matplotlib needed)")
    parser.add_argument("--check", action="store_true", help="exit 1 unless the run meets the criteria")
    parser.add_argument("--case", type=int, default=None, metavar="CASE_SEED",
                        help="re-run the one case with this case seed and print its summary")
    parser.add_argument("--speed-bound", type=float, default=0.5, metavar="RAD_S",
                        help="max |w - w*| after settling for success (default 0.5 rad/s)")
    parser.add_argument("--angle-bound", type=float, default=0.05, metavar="RAD",
                        help="max angle-estimate error after settling for success (default 0.05 rad)")
    parser.add_argument("--latency-bound", type=float, default=0.05, metavar="SECONDS",
                        help="a fault later than this after a loss of control is a silent failure (default 0.05 s)")
    parser.add_argument("--min-success", type=float, default=0.99, help="--check: minimum success rate (default 0.99)")
    parser.add_argument("--exclude", action="append", default=[], metavar="KEY",
                        help="leave this row of the distribution table out (the scenario's value stays); "
                             "repeatable, e.g. --exclude controller.inverter.dead_time_s for a firmware without compensation")
    parser.add_argument("--case-timeout", type=float, default=600.0, metavar="SECONDS",
                        help="wall time after which one run counts as crashed (default 600 s)")
    args = parser.parse_args(argv[1:])
    if args.case is None and not 1 <= args.cases <= SEED_STRIDE:
        parser.error(f"--cases must be between 1 and {SEED_STRIDE}")
    if args.seed < 0 or (args.case is not None and args.case < 0):
        parser.error("seeds must be >= 0")
    if args.jobs < 1:
        parser.error("--jobs must be >= 1")
    if args.duration is not None and not args.duration > 0:
        parser.error("--duration must be > 0")
    if not 0 <= args.min_success <= 1:
        parser.error("--min-success must be within [0, 1]")
    args.argv = argv
    args.script = argv[0]
    return args


def run_one(args, scenario, base):
    """--case: re-run one case, print what it did; returns the exit status."""
    seed = args.case
    record = run_case(args, seed, base, csv_output=True)
    base_seed, index = split_case_seed(seed)
    print(f"case seed {seed} (base seed {base_seed}, case {index}); pmstep-sil command:")
    print("  " + shlex.join(record["command"]))
    print("drawn parameters:")
    for key, kind, _a, _b in DISTRIBUTIONS:
        value = record["params"][key]
        factor = f"  (x{value / float(scenario[key]):.4f})" if kind == "scale" and float(scenario[key]) else ""
        print(f"  {key:34s} {format_value(value)}{factor}")
    print(f"class: {record['class']}" + (f" - {record['reason']}" if record["reason"] else ""))
    if record["summary"] is not None:
        print("summary.json:")
        print(json.dumps(record["summary"], indent=2))
    if record["stderr_tail"].strip():
        print("stderr (tail):\n" + record["stderr_tail"].rstrip())
    print(f"outputs in {os.path.join(args.out, 'cases', str(seed))} (tools/plot_run.py draws them)")
    passed = record["class"] == "success"
    print(f"{int(passed)} passed, {int(not passed)} failed")
    return 1 if args.check and not passed else 0


def main(argv):
    args = parse_args(argv)
    unknown = [key for key in args.exclude if key not in [row[0] for row in DISTRIBUTIONS]]
    if unknown:
        print(f"monte_carlo: --exclude {', '.join(unknown)}: not in the distribution table", file=sys.stderr)
        return 2
    # In place, so every function's default table (the same list object) sees it.
    DISTRIBUTIONS[:] = [row for row in DISTRIBUTIONS if row[0] not in args.exclude]
    started_utc = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    try:
        if not (os.path.isfile(args.sil) and os.access(args.sil, os.X_OK)):
            raise ToolError(f"{args.sil} is not an executable file (build it: cmake --preset host-release && "
                            "cmake --build --preset host-release)")
        if not os.path.isfile(args.scenario):
            raise ToolError(f"scenario file {args.scenario} not found")
        if not args.no_plots and args.case is None:
            try:  # fail now rather than after the runs
                import matplotlib  # noqa: F401
                import numpy  # noqa: F401
            except ImportError as e:
                raise ToolError(f"the histograms need numpy and matplotlib ({e}); install tools/requirements.txt "
                                "(e.g. into .venv) or pass --no-plots") from None
        scenario = read_scenario(args.sil, args.scenario)
        check_keys(args.sil, args.scenario, scenario, args.duration is not None)
        base = base_values(scenario)
        os.makedirs(args.out, exist_ok=True)
    except (ToolError, OSError) as e:
        sys.stderr.write(f"monte_carlo: {e}\n")
        print("0 passed, 0 failed")
        return 2

    if args.case is not None:
        return run_one(args, scenario, base)

    version = sil_version(args.sil)
    print(f"monte_carlo: {args.cases} cases of {args.scenario}, base seed {args.seed}, {args.jobs} jobs -> {args.out}",
          file=sys.stderr)
    try:
        records = run_all(args, base)
    except KeyboardInterrupt:
        sys.stderr.write("\nmonte_carlo: interrupted\n")
        print("0 passed, 0 failed")
        return 130

    agg = aggregate(records, args)
    agg.update({"scenario": args.scenario, "command": shlex.join(args.argv), "date": started_utc,
                "pmstep_sil_version": version, "duration_s": args.duration,
                "distribution_table": [list(row) for row in DISTRIBUTIONS],
                "worst_cases": [{"seed": r["seed"], "class": r["class"], "reason": r["reason"],
                                 "max_speed_error_rad_s": r["metrics"].get("max_speed_error_rad_s"),
                                 "command": shlex.join(r["command"])}
                                for r in worst_order(records)[:WORST_CASES]]})
    plots = []
    if not args.no_plots:
        plots = make_plots(args.out, records, args)
    reasons = check_verdict(agg, args.min_success)
    agg["check"] = {"min_success": args.min_success, "passed": not reasons, "reasons": reasons}
    write_report(os.path.join(args.out, "report.md"), records, agg, args, scenario, version, plots, started_utc)
    write_cases_csv(os.path.join(args.out, "cases.csv"), records)
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(agg, f, indent=2)
        f.write("\n")

    counts = agg["counts"]
    low, high = agg["success_rate_wilson95"]
    print(f"success {counts['success']}/{agg['cases']} ({100 * agg['success_rate']:.1f} %, "
          f"Wilson 95 % {100 * low:.1f}-{100 * high:.1f} %); "
          + ", ".join(f"{cls} {counts[cls]}" for cls in CLASSES[1:])
          + f" (false trips {agg['false_trips']}); non-finite {agg['nonfinite_cases']}")
    if agg["faults_by_name"]:
        print("faults: " + ", ".join(f"{name} x{count}" for name, count in agg["faults_by_name"].items()))
    crashed = [r for r in records if r["class"] == "crashed"]
    for r in crashed[:WORST_CASES]:
        tail = r["stderr_tail"].strip().splitlines()
        print(f"crashed case {r['seed']}: {r['reason']}" + (f" ({tail[-1]})" if tail else ""))
    if len(crashed) > WORST_CASES:
        print(f"... and {len(crashed) - WORST_CASES} more crashed cases (cases.csv)")
    print(f"report: {os.path.join(args.out, 'report.md')}")
    status = 0
    if args.check:
        if reasons:
            print("check FAILED: " + "; ".join(reasons))
            status = 1
        else:
            print(f"check passed: success rate >= {args.min_success:g}, no silent failure, no crash, no non-finite value")
    print(f"{counts['success']} passed, {agg['cases'] - counts['success']} failed")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv))
