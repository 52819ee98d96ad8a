#!/usr/bin/env python3
"""How far the paper's method holds under a real measurement chain.

Runs pmstep-sil with the plant and measurement chain of a scenario (default
sil/scenarios/robust.ini) but the firmware back in the paper's mode: no calibration, no
commissioning, no dead-time compensation, open current integrals, i_d* = 0, and detection off,
so the drift of the angle estimate is observed rather than cut short by a fault. One run per
non-ideality alone on an ideal chain, one with all of them, and, for contrast, the scenario
unchanged (its own firmware settings). Each run lasts 10 s after t_c.

Usage:
  tools/paper_mode_drift.py --sil build/host-release/sil/pmstep-sil [--scenario FILE]
                            [--out DIR] [--jobs N] [--no-plots] [--check]

Writes DIR/report.md (a table: |angle error| 1, 5 and 10 s after t_c, its maximum, when it first
exceeds 0.05 and 0.5 rad, the loss of control and the fault), DIR/summary.json and, unless
--no-plots, DIR/drift.png (|angle error| against time, log scale). --check exits 1 unless every
case ran and the ideal chain stays below 1e-3 rad (the paper's method is exact there). The last
line printed is "N passed, N failed" (passed = cases that ran).
"""

import argparse
import concurrent.futures
import configparser
import csv
import json
import math
import os
import shlex
import subprocess
import sys

RUN_MODE = 3  # pmstep_mode_t PMSTEP_MODE_RUN
HORIZON_S = 10.0  # observed time after t_c
WINDOW_S = 0.1  # "|e| at t" is the max over (t - WINDOW_S, t]
MARKS_S = (1.0, 5.0, 10.0)
THRESHOLDS_RAD = (0.05, 0.5)

# The firmware in the paper's mode, detection off (see the module docstring).
PAPER_FIRMWARE = {
    "controller.commissioning.offset_calibration_time_s": "0",
    "controller.commissioning.alignment_offset_calibration": "false",
    "controller.commissioning.steady_state_window_s": "0",
    "controller.commissioning.inductance_window_s": "0",
    "controller.commissioning.use_measured_resistance": "false",
    "controller.commissioning.use_measured_inductance": "false",
    "controller.commissioning.use_measured_torque_constant": "false",
    "controller.commissioning.voltage_bias_level_fraction": "0",
    "controller.inverter.dead_time_s": "0",
    "controller.gains.angle_correction_gain_per_s": "0",
    "speed.id_target_A": "0",
    "controller.detection.angle_magnitude_bound": "0",
    "controller.detection.speed_consistency_bound_rad_s": "0",
    "controller.detection.stall_speed_error_rad_s": "0",
    "controller.detection.observer_residual_bound_A": "0",
    "load.step_time_s": "0.63",  # 30 ms after t_c = 0.6 s, as in the paper
}

# Every non-ideality off; the paper's plant R.
IDEAL_CHAIN = {
    "sensors.adc_bits": "0",
    "sensors.offset_a_A": "0",
    "sensors.offset_b_A": "0",
    "sensors.noise_rms_A": "0",
    "inverter.dead_time_s": "0",
    "run.delay_periods": "0",
    "motor.resistance_Ohm": "3",
}

# (name, keys taken back from the scenario file on top of the ideal chain)
ALONE = [
    ("12-bit ADC", ["sensors.adc_bits"]),
    ("+-20 mA offsets", ["sensors.offset_a_A", "sensors.offset_b_A"]),
    ("5 mA noise", ["sensors.noise_rms_A"]),
    ("one period delay", ["run.delay_periods"]),
    ("1 us dead time", ["inverter.dead_time_s"]),
    ("plant R +20 %", ["motor.resistance_Ohm"]),
]


def scenario_values(sil, scenario):
    """{section.key: text} of every key of the scenario (pmstep-sil --print-scenario)."""
    text = subprocess.run(
        [sil, "--scenario", scenario, "--print-scenario"], check=True, capture_output=True, text=True
    ).stdout
    parser = configparser.ConfigParser(comment_prefixes=(";",), interpolation=None)
    parser.optionxform = str  # keep the keys' case: units are in them (motor.resistance_Ohm)
    parser.read_string(text)
    return {
        f"{section}.{key}": " ".join(value.split())
        for section in parser.sections()
        for key, value in parser[section].items()
    }


def cases(values, t_c_s):
    """[(name, {key: value})] of the runs, in report order."""
    duration = {"run.duration_s": repr(t_c_s + HORIZON_S), "run.decimation": "20"}
    paper = {**PAPER_FIRMWARE, **duration}
    out = [("ideal chain", {**paper, **IDEAL_CHAIN})]
    for name, keys in ALONE:
        out.append((name, {**paper, **IDEAL_CHAIN, **{k: values[k] for k in keys}}))
    out.append(("all of the scenario's chain", paper))
    out.append(
        (
            "robust mode, all",
            {
                "run.duration_s": repr(
                    float(values["controller.commissioning.offset_calibration_time_s"]) + t_c_s + HORIZON_S
                ),
                "run.decimation": "20",
            },
        )
    )
    return out


def slug(name):
    return "".join(c if c.isalnum() else "_" for c in name.lower()).strip("_")


def angle_error_rad(c_hat, s_hat, cos_ptheta, sin_ptheta):
    """Electrical angle of (c_hat, s_hat) minus p theta, wrapped to (-pi, pi]."""
    return math.atan2(s_hat * cos_ptheta - c_hat * sin_ptheta, c_hat * cos_ptheta + s_hat * sin_ptheta)


def window_max(times, errors, at_s, width_s=WINDOW_S):
    """max |e| over (at - width, at], or None when no sample falls there."""
    inside = [abs(e) for t, e in zip(times, errors) if at_s - width_s < t <= at_s + 1e-12]
    return max(inside) if inside else None


def first_crossing(times, errors, threshold):
    """First time with |e| > threshold, or None."""
    return next((t for t, e in zip(times, errors) if abs(e) > threshold), None)


def run_case(sil, scenario, out_dir, name, sets):
    folder = os.path.join(out_dir, "cases", slug(name))
    cmd = [sil, "--scenario", scenario, "--out", folder, "--quiet"]
    for key, value in sets.items():
        cmd += ["--set", f"{key}={value}"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    result = {"name": name, "command": " ".join(shlex.quote(c) for c in cmd), "ran": False}
    if proc.returncode not in (0, 3):
        result["error"] = proc.stderr.strip()[-300:]
        return result
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    t_c = summary["robustness"]["run_start_time_s"]
    times, errors = [], []
    with open(os.path.join(folder, "run.csv")) as f:
        for row in csv.DictReader(f):
            if int(row["mode"]) == RUN_MODE:
                times.append(float(row["t_s"]) - t_c)
                errors.append(
                    angle_error_rad(
                        float(row["cos_hat"]), float(row["sin_hat"]), float(row["cos_ptheta"]), float(row["sin_ptheta"])
                    )
                )
    loss = summary["robustness"]["loss_of_control_time_s"]
    result.update(
        {
            "ran": True,
            "times_s": times,
            "errors_rad": errors,
            "at_s": {str(m): window_max(times, errors, m) for m in MARKS_S},
            "max_rad": max((abs(e) for e in errors), default=None),
            "first_above_s": {str(th): first_crossing(times, errors, th) for th in THRESHOLDS_RAD},
            "loss_after_tc_s": loss - t_c if loss >= 0 else None,
            "fault": summary["fault"]["name"],
            "fault_after_tc_s": (summary["fault"]["time_s"] - t_c if summary["fault"]["time_s"] >= 0 else None),
        }
    )
    return result


def fmt(value, spec=".3g", unit=""):
    return "-" if value is None else f"{value:{spec}}{unit}"


def table(results):
    head = (
        "| case | \\|e\\| at 1 s | at 5 s | at 10 s | max | > 0.05 rad at | > 0.5 rad at "
        "| loss of control at | fault |\n|---|---|---|---|---|---|---|---|---|\n"
    )
    rows = []
    for r in results:
        if not r["ran"]:
            rows.append(f"| {r['name']} | did not run: {r.get('error', '')} |||||||| |")
            continue
        fault = "-" if r["fault"] == "NONE" else f"{r['fault']} at {fmt(r['fault_after_tc_s'], '.3f', ' s')}"
        rows.append(
            "| "
            + " | ".join(
                [
                    r["name"],
                    *(fmt(r["at_s"][str(m)]) for m in MARKS_S),
                    fmt(r["max_rad"]),
                    *(fmt(r["first_above_s"][str(th)], ".3f", " s") for th in THRESHOLDS_RAD),
                    fmt(r["loss_after_tc_s"], ".3f", " s"),
                    fault,
                ]
            )
            + " |"
        )
    return head + "\n".join(rows) + "\n"


def plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 5))
    for r in results:
        if r["ran"] and r["times_s"]:
            ax.semilogy(r["times_s"], [max(abs(e), 1e-6) for e in r["errors_rad"]], label=r["name"], lw=1)
    for th in THRESHOLDS_RAD:
        ax.axhline(th, color="k", ls="--", lw=0.8)
    ax.set_xlabel("time after t_c (s)")
    ax.set_ylabel("|angle error| (electrical rad)")
    ax.set_title("Paper's method (detection off) under each non-ideality; robust mode for contrast")
    ax.set_xlim(0, HORIZON_S)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sil", required=True, help="the pmstep-sil executable")
    ap.add_argument("--scenario", default="sil/scenarios/robust.ini", help="plant and chain to take")
    ap.add_argument("--out", default="out/paper_drift", help="output folder")
    ap.add_argument("--jobs", type=int, default=2, help="parallel runs")
    ap.add_argument("--no-plots", action="store_true", help="no drift.png (no matplotlib needed)")
    ap.add_argument("--check", action="store_true", help="exit 1 unless all ran and the ideal chain < 1e-3 rad")
    args = ap.parse_args(argv)
    values = scenario_values(args.sil, args.scenario)
    t_c_s = float(values["controller.alignment.c_align_time_s"])
    todo = cases(values, t_c_s)
    os.makedirs(args.out, exist_ok=True)
    results = [None] * len(todo)
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = {pool.submit(run_case, args.sil, args.scenario, args.out, n, s): k for k, (n, s) in enumerate(todo)}
        for done, future in enumerate(concurrent.futures.as_completed(futures), 1):
            results[futures[future]] = future.result()
            print(f"paper_mode_drift: {done}/{len(todo)} runs", file=sys.stderr)
    report = [
        "# The paper's method under a real measurement chain",
        "",
        f"Plant and chain of `{args.scenario}`; the firmware in the paper's mode (no calibration, "
        "commissioning, dead-time compensation or drift-free correction; i_d* = 0) with detection off, "
        f"observed for {HORIZON_S:g} s after t_c. Each non-ideality alone on an ideal chain, then all of them; "
        "the last row is the scenario unchanged (robust mode, detection on). |e| is the electrical "
        f"angle error of (c-hat, s-hat), max over the {WINDOW_S:g} s before each mark.",
        "",
        table(results),
        "Commands:",
        "",
    ]
    report += [f"- {r['name']}: `{r['command']}`" for r in results]
    if not args.no_plots:
        plot(results, os.path.join(args.out, "drift.png"))
        report += ["", "![angle error after t_c](drift.png)"]
    with open(os.path.join(args.out, "report.md"), "w") as f:
        f.write("\n".join(report) + "\n")
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump([{k: v for k, v in r.items() if k not in ("times_s", "errors_rad")} for r in results], f, indent=1)
    print(table(results))
    ran = sum(r["ran"] for r in results)
    failed = len(results) - ran
    status = 0
    if args.check:
        ideal = results[0]
        if failed or not ideal["ran"] or not (ideal["max_rad"] is not None and ideal["max_rad"] < 1e-3):
            print(
                f"check FAILED: {failed} case(s) did not run; ideal chain max {fmt(ideal.get('max_rad'))} rad "
                "(bound 1e-3)",
                file=sys.stderr,
            )
            status = 1
    print(f"{ran} passed, {failed} failed")
    return 1 if failed else status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
