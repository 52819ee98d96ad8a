#!/usr/bin/env python3
"""Sweep of the gain designer and the control over a population of motors (tools/motor_population.py)
and the public presets: for every motor and mode, pmstep-tune designs the controller from what a
datasheet gives (the rotor's J and F estimated from the holding torque where the population says
so) and validates it in the SIL (--validate: ramps to +-80 % and +-5 % of the top speed, half the
holding torque stepped on at 50 % and 5 % of it). A motor passes when it is designed and every run
keeps synchronism with no fault; the stricter envelope criteria (tracking within 2 % of the top
speed, angle error within 0.05 rad) are counted apart.

Modes: paper-ideal (the paper's controller, ideal chain) and robust-realistic (the robust design
behind mc_preset.py's realistic chain); paper-realistic, robust-ideal and self-commission-realistic
(the drive's own calibration from the rated current, then its design validated, on the realistic
chain) on request.

It prints the pass rate and the failure modes per mode, writes results.csv, a report (pass rates
by frame, steps/rev and bus; the failures and their dimensionless groups) and a plot of where the
failures sit over the groups that decide the design:
  R/L T_s (electrical pole against the control rate), F/J T_s ... the mechanical pole k_M I/(J w_top),
  p w_top T_s (electrical angle per period at the top speed), k_M w_top / V_bus (back EMF against the
  bus), I_align / (noise) (the alignment current against the sensor noise, 5 mA).

Usage: tools/sweep_motors.py --tune build/host-release/sil/pmstep-tune [--count 500] [--seed 2026]
       [--sample N] [--modes paper-ideal,robust-realistic] [--jobs J] [--engine threads|dask]
       [--out DIR] [--report FILE] [--plot FILE] [--check PCT] [--mc-sample N [--mc-cases C] [--sil PATH]]

--mc-sample N adds a short speed Monte Carlo (C cases, default 20) on N population motors
(tools/sweep_mc.py): the cases by class, and the motors with a silent failure.
"""

import argparse
import collections
import csv
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time

import mc_preset
import motor_population
import report
import sweep_mc

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PRESETS = ("paper", "17hs4401", "bj42d29", "as1050")
MODES = {
    "paper-ideal": {"robust": False, "realistic": False},
    "robust-realistic": {"robust": True, "realistic": True},
    "paper-realistic": {"robust": False, "realistic": True},
    "robust-ideal": {"robust": True, "realistic": False},
    # the drive's own calibration (pmstep_calibrate.h) told only the rated current, p and the detent's
    # presence, then its design validated as the others
    "self-commission-realistic": {"robust": True, "realistic": True, "self_commission": True},
}
LOAD_STEP_OF_HOLDING = 0.5  # the validation's load step (sil/tune/tune_validate.c)
NOISE_A = 0.005  # the realistic chain's current noise (mc_preset.REALISTIC_CHAIN)


def preset_motor(name):
    """A public preset as a population entry (the designer told its own J and F)."""
    path = os.path.join(ROOT, "sil", "scenarios", "motors", f"{name}.ini")
    ini = mc_preset._ini(path)
    motor = {
        k: float(ini.get("motor", k))
        for k in ("resistance_Ohm", "inductance_H", "inertia_kgm2", "friction_Nms_rad", "torque_constant_Nm_A")
    }
    motor.update(
        name=name,
        frame="preset",
        pole_pairs=int(ini.get("motor", "pole_pairs")),
        rated_current_A=float(ini.get("datasheet", "rated_current_A")),
        holding_torque_Nm=float(ini.get("datasheet", "holding_torque_Nm")),
        detent_torque_Nm=float(ini.get("datasheet", "detent_torque_Nm", fallback="0")),
        bus_voltage_V=float(ini.get("run", "bus_voltage_V")),
        load_ratio=0.0,
        path=path,
        told_inertia_kgm2=None,
        told_friction_Nms_rad=None,
    )
    return motor


def run_motor(tune, motor, mode, work):
    """pmstep-tune on @p motor in @p mode; the parsed --summary, with the motor's groups."""
    spec = MODES[mode]
    tag = f"{motor['name']}-{mode}"
    summary_path = os.path.join(work, tag + ".json")
    cmd = [tune, "--motor", motor["path"], "--validate", "--summary", summary_path]
    if spec["robust"]:
        cmd.append("--robust")
    if spec["realistic"]:
        for item in mc_preset.chain_sets({"rated_current_A": motor["rated_current_A"]}):
            cmd += ["--set", item]
    if spec.get("self_commission"):
        cmd += ["--self-commission", "--detent-fraction", "0.05" if motor.get("detent_torque_Nm", 0.0) > 0.0 else "0"]
    elif motor.get("told_inertia_kgm2") is not None:
        # a datasheet without J: the designer estimates it from the holding torque and has it identified
        cmd += ["--told-inertia", "0", "--told-friction", f"{motor['told_friction_Nms_rad']:.6g}"]
    started = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    try:
        with open(summary_path) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        summary = {
            "design": {
                "status": None,
                "text": f"pmstep-tune exit {proc.returncode}: "
                + (proc.stderr.strip().splitlines() or ["no output"])[-1],
            },
            "checks": [],
            "passed": False,
            "synchronous": False,
        }
    return {"motor": motor, "mode": mode, "summary": summary, "seconds": time.monotonic() - started, "command": cmd}


def outcome(result):
    """'pass', 'refused: <text>' or 'fail: <first failing check and its fault or criterion>'."""
    s = result["summary"]
    if s["design"]["status"] != 0:
        return "refused: " + s["design"]["text"]
    calibration = s.get("self_commissioning")
    if calibration is not None and calibration["status"] != 0:
        fault = f" ({calibration['fault']})" if calibration.get("fault", "NONE") != "NONE" else ""
        return f"fail: self-commissioning: {calibration['text']}{fault}"
    if s["synchronous"]:
        return "pass"
    for c in s["checks"]:
        if not c["synchronous"]:
            what = c["fault"] if c["fault"] != "NONE" else ("init refused" if not c["ran"] else "synchronism lost")
            return f"fail: {c['check']}: {what}"
    return "fail: unknown"


def groups(result):
    """The dimensionless groups the design depends on, for the plot and the failure table."""
    m = result["motor"]
    d = result["summary"]["design"]
    period_s = 50e-6
    out = {
        "R/L T_s": m["resistance_Ohm"] / m["inductance_H"] * period_s,
        "F/J T_s": m["friction_Nms_rad"] / m["inertia_kgm2"] * period_s,
        "p": m["pole_pairs"],
    }
    if d.get("top_speed_rad_s"):
        top = d["top_speed_rad_s"]
        out["p w_top T_s"] = m["pole_pairs"] * top * period_s
        out["k_M w_top / V_bus"] = m["torque_constant_Nm_A"] * top / m["bus_voltage_V"]
        out["k_M I / (J w_top w_o)"] = (
            m["torque_constant_Nm_A"] * m["rated_current_A"] / m["inertia_kgm2"] / top / d["observer_bandwidth_rad_s"]
        )
        out["I_align / noise"] = d["alignment_current_A"] / NOISE_A
        # the validation's load step T = T_H / 2 against the bus (docs/design/09-validation.md):
        # the speed it takes off the rotor while the current builds, T^2 L / (J k_M V), over w_top
        step_Nm = LOAD_STEP_OF_HOLDING * m["holding_torque_Nm"]
        out["load step G"] = (
            step_Nm
            * step_Nm
            * m["inductance_H"]
            / (m["inertia_kgm2"] * m["torque_constant_Nm_A"] * m["bus_voltage_V"] * top)
        )
    return out


def run_all(tasks, tune, work, jobs, engine):
    results = []
    total = len(tasks)
    started = time.monotonic()
    if engine == "dask":
        from distributed import Client, LocalCluster, as_completed

        with LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
            futures = [client.submit(run_motor, tune, m, mode, work, pure=False) for m, mode in tasks]
            for future in as_completed(futures):
                results.append(future.result())
                progress(len(results), total, started)
    else:
        import concurrent.futures

        with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
            for result in pool.map(lambda t: run_motor(tune, t[0], t[1], work), tasks):
                results.append(result)
                progress(len(results), total, started)
    return results, time.monotonic() - started


def progress(done, total, started):
    if done == total or done % max(1, total // 20) == 0:
        elapsed = time.monotonic() - started
        print(f"sweep_motors: {done} of {total} runs, {elapsed:.0f} s", file=sys.stderr, flush=True)


def rate_table(results, key):
    """| key | motors | passed | % | per mode."""
    rows = collections.defaultdict(lambda: [0, 0])
    for r in results:
        k = key(r)
        rows[k][0] += 1
        rows[k][1] += outcome(r) == "pass"
    return rows


def write_csv(path, results):
    fields = [
        "name",
        "frame",
        "pole_pairs",
        "bus_voltage_V",
        "rated_current_A",
        "holding_torque_Nm",
        "resistance_Ohm",
        "inductance_H",
        "inertia_kgm2",
        "load_ratio",
        "mode",
        "outcome",
        "envelope_pass",
        "seconds",
    ]
    group_names = [
        "R/L T_s",
        "F/J T_s",
        "p w_top T_s",
        "k_M w_top / V_bus",
        "k_M I / (J w_top w_o)",
        "I_align / noise",
        "load step G",
    ]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields + group_names)
        for r in results:
            m = r["motor"]
            g = groups(r)
            w.writerow(
                [
                    m["name"],
                    m["frame"],
                    m["pole_pairs"],
                    m["bus_voltage_V"],
                    m["rated_current_A"],
                    m["holding_torque_Nm"],
                    m["resistance_Ohm"],
                    m["inductance_H"],
                    m["inertia_kgm2"],
                    m["load_ratio"],
                    r["mode"],
                    outcome(r),
                    r["summary"]["passed"],
                    f"{r['seconds']:.2f}",
                ]
                + [f"{g[n]:.6g}" if n in g else "" for n in group_names]
            )


def plot(path, results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pairs = [("R/L T_s", "p w_top T_s"), ("k_M w_top / V_bus", "k_M I / (J w_top w_o)"), ("I_align / noise", "F/J T_s")]
    modes = sorted({r["mode"] for r in results})
    fig, axes = plt.subplots(len(modes), len(pairs), figsize=(5 * len(pairs), 4 * len(modes)), squeeze=False)
    for row, mode in enumerate(modes):
        for col, (x, y) in enumerate(pairs):
            ax = axes[row][col]
            for passed, colour, label in ((True, "tab:green", "pass"), (False, "tab:red", "fail or refused")):
                pts = [
                    (groups(r).get(x), groups(r).get(y))
                    for r in results
                    if r["mode"] == mode and (outcome(r) == "pass") == passed
                ]
                pts = [p for p in pts if p[0] and p[1]]
                if pts:
                    ax.scatter([p[0] for p in pts], [p[1] for p in pts], s=8, c=colour, label=label, alpha=0.7)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(x)
            ax.set_ylabel(y)
            ax.set_title(mode)
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def mode_counts(results, mode):
    """A mode's runs, and of them: passed, meeting the envelope criteria, with STATE_NONFINITE."""
    rs = [r for r in results if r["mode"] == mode]
    passed = sum(outcome(r) == "pass" for r in rs)
    envelope = sum(bool(r["summary"]["passed"]) for r in rs)
    nonfinite = sum(any(c["fault"] == "STATE_NONFINITE" for c in r["summary"]["checks"]) for r in rs)
    return rs, passed, envelope, nonfinite


def summary_lines(results, modes):
    lines = []
    for mode in modes:
        rs, passed, envelope, nonfinite = mode_counts(results, mode)
        lines.append(
            f"{mode}: {passed} of {len(rs)} pass ({100.0 * passed / max(1, len(rs)):.1f} %); "
            f"envelope criteria {envelope}; STATE_NONFINITE in {nonfinite}"
        )
        modes_seen = collections.Counter(outcome(r) for r in rs if outcome(r) != "pass")
        lines += [f"  {n:4d}  {what}" for what, n in modes_seen.most_common()]
    return lines


def report_text(results, modes, argv, seconds, jobs, population_note, mc=None):
    out = [
        report.header(
            "Motor sweep",
            "tools/sweep_motors.py",
            argv,
            "The gain designer and the control over a population of motors drawn by "
            "tools/motor_population.py (" + population_note + ") and the public presets. A motor passes "
            "when it is designed and its validation (ramps to +-80 % and +-5 % of the top speed, half "
            "the holding torque stepped on at 50 % and 5 % of it) runs with no fault and no loss of "
            "synchronism; *envelope* counts the motors that also meet the tracking (2 % of the top speed) "
            "and angle (0.05 rad) bounds.",
        ),
        f"{len(results)} runs in {seconds:.0f} s on {jobs} workers.",
        "",
    ]
    out += [
        "## Pass rates",
        "",
        "| mode | motors | pass | % | envelope | STATE_NONFINITE |",
        "|---|---|---|---|---|---|",
    ]
    for mode in modes:
        rs, passed, envelope, nonfinite = mode_counts(results, mode)
        out.append(
            f"| {mode} | {len(rs)} | {passed} | {100.0 * passed / max(1, len(rs)):.1f} | {envelope} | {nonfinite} |"
        )
    for title, key in (
        ("frame", lambda r: r["motor"]["frame"]),
        ("steps/rev", lambda r: 4 * r["motor"]["pole_pairs"]),
        ("bus (V)", lambda r: f"{r['motor']['bus_voltage_V']:g}"),
    ):
        out += [
            "",
            f"## By {title}",
            "",
            "| " + title + " | " + " | ".join(modes) + " |",
            "|---|" + "---|" * len(modes),
        ]
        tables = {mode: rate_table([r for r in results if r["mode"] == mode], key) for mode in modes}
        for k in sorted({k for t in tables.values() for k in t}, key=str):
            cells = []
            for mode in modes:
                n, p = tables[mode].get(k, [0, 0])
                cells.append(f"{p} / {n}" if n else "-")
            out.append(f"| {k} | " + " | ".join(cells) + " |")
    out += ["", "## Failures", ""]
    # load step G: the validation's step against the bus (docs/design/09-validation.md#load-step-bus-limit)
    for mode in modes:
        gs = [groups(r).get("load step G") for r in results if r["mode"] == mode and outcome(r) == "pass"]
        gs = [g for g in gs if g is not None]
        if gs:
            out.append(f"- {mode}: the largest load step G of a motor that passes is {max(gs):.3g}.")
    out.append("")
    failures = [r for r in results if outcome(r) != "pass"]
    if not failures:
        out.append("None.")
    else:
        out += [
            "| motor | mode | outcome | R (Ohm) | L (mH) | I (A) | T_H (N m) | p | bus (V) | load step G |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in sorted(failures, key=lambda r: (r["mode"], r["motor"]["name"])):
            m = r["motor"]
            out.append(
                f"| {m['name']} | {r['mode']} | {outcome(r)} | {m['resistance_Ohm']:.3g} | "
                f"{1e3 * m['inductance_H']:.3g} | {m['rated_current_A']:.3g} | {m['holding_torque_Nm']:.3g} | "
                f"{m['pole_pairs']} | {m['bus_voltage_V']:g} | {groups(r).get('load step G', math.nan):.3g} |"
            )
    if mc is not None:
        out += sweep_mc.report_lines(mc["results"], mc["cases"])
    return "\n".join(out) + "\n"


def main(argv=None):
    argv = sys.argv if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tune", required=True)
    parser.add_argument("--count", type=int, default=motor_population.COUNT)
    parser.add_argument("--seed", type=int, default=motor_population.SEED)
    parser.add_argument("--sample", type=int, help="a random sample of this many population motors (seed 1)")
    parser.add_argument("--no-presets", action="store_true")
    parser.add_argument("--modes", default="paper-ideal,robust-realistic")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--engine", choices=("threads", "dask"), default="threads")
    parser.add_argument("--out", help="folder for the presets, results.csv and the summaries (default: temporary)")
    parser.add_argument("--report")
    parser.add_argument("--plot")
    parser.add_argument("--check", type=float, help="exit 1 unless every mode passes at least this many percent")
    parser.add_argument(
        "--require-clean",
        action="store_true",
        help="exit 1 if a run overflowed (STATE_NONFINITE) or pmstep-tune gave no summary",
    )
    parser.add_argument(
        "--mc-sample",
        type=int,
        default=0,
        metavar="N",
        help="a short speed Monte Carlo on N population motors (tools/sweep_mc.py)",
    )
    parser.add_argument("--mc-cases", type=int, default=20, help="cases per motor of --mc-sample (default 20)")
    parser.add_argument("--sil", help="pmstep-sil for --mc-sample (default: beside --tune)")
    parser.add_argument(
        "--told-exact",
        action="store_true",
        help="tell the designer the plant's J and F (no estimate from the holding torque)",
    )
    args = parser.parse_args(argv[1:])
    modes = args.modes.split(",")
    for mode in modes:
        if mode not in MODES:
            parser.error(f"unknown mode {mode} (one of {', '.join(MODES)})")
    population = motor_population.draw(args.count, args.seed)
    if args.sample:
        population = random.Random(1).sample(population, min(args.sample, len(population)))
    if args.told_exact:
        for m in population:
            m["told_inertia_kgm2"] = None
    note = f"{args.count} motors, seed {args.seed}" + (f", a sample of {len(population)}" if args.sample else "")
    note += (
        ", the designer told the plant's J and F" if args.told_exact else ", J and F estimated from the holding torque"
    )
    with tempfile.TemporaryDirectory(prefix="pmstep-sweep-") as tmp:
        work = args.out or tmp
        os.makedirs(work, exist_ok=True)
        motor_population.write(population, work)
        for m in population:
            m["path"] = os.path.join(work, m["name"] + ".ini")
        motors = population + ([] if args.no_presets else [preset_motor(n) for n in PRESETS])
        tasks = [(m, mode) for mode in modes for m in motors]
        results, seconds = run_all(tasks, os.path.abspath(args.tune), work, args.jobs, args.engine)
        results.sort(key=lambda r: (r["mode"], r["motor"]["name"]))
        write_csv(os.path.join(work, "results.csv"), results)
        mc = None
        if args.mc_sample > 0:
            tune = os.path.abspath(args.tune)
            sil = os.path.abspath(args.sil or os.path.join(os.path.dirname(tune), "pmstep-sil"))
            mc = {
                "cases": args.mc_cases,
                "results": sweep_mc.run_sample(
                    sweep_mc.sample(population, args.mc_sample), sil, tune, work, args.mc_cases, args.jobs
                ),
            }
    for line in summary_lines(results, modes):
        print(line)
    print(f"sweep_motors: {len(results)} runs in {seconds:.0f} s on {args.jobs} workers")
    if mc is not None:
        print(sweep_mc.summary_line(mc["results"], mc["cases"]))
    if args.report:
        report.write(args.report, report_text(results, modes, argv, seconds, args.jobs, note, mc))
        print(f"sweep_motors: wrote {args.report}")
    if args.plot:
        plot(args.plot, results)
        print(f"sweep_motors: wrote {args.plot}")
    if args.require_clean:
        unclean = [
            r
            for r in results
            if r["summary"]["design"]["status"] is None
            or any(c["fault"] == "STATE_NONFINITE" for c in r["summary"]["checks"])
        ]
        for r in unclean:
            print(f"sweep_motors: UNCLEAN: {r['motor']['name']} {r['mode']}: {outcome(r)}")
        mc_unclean = (
            []
            if mc is None
            else [r for r in mc["results"] if r.get("nonfinite", 0) > 0 or r.get("counts", {}).get("crashed", 0) > 0]
        )
        for r in mc_unclean:
            print(
                f"sweep_motors: UNCLEAN: Monte Carlo on {r['motor']['name']}: {r.get('counts')}, "
                f"non-finite in {r.get('nonfinite')}"
            )
        if unclean or mc_unclean:
            return 1
    if args.check is not None:
        for mode in modes:
            rs = [r for r in results if r["mode"] == mode]
            if 100.0 * sum(outcome(r) == "pass" for r in rs) / max(1, len(rs)) < args.check:
                return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
