#!/usr/bin/env python3
"""Real-time factor of the SIL on the paper scenario (a benchmark that prints figures).

Usage: tools/bench_sil.py [--runs N] [--sil build/host-release/sil/pmstep-sil] [--report docs/reports/benchmarks.md]

Runs the paper scenario (2.4 s, 20 kHz) without CSV output, N times per setting, and
prints the median real-time factor (simulated s per wall s; also per CPU s, which a busy
shared machine inflates less) with the plant's and the firmware step's shares of the wall
time (the runner times every 16th period and scales).
Settings: the default (exponential integrator, one step a period) with the averaged and
the switching inverter, and the RK4 reference at 25 and 10 steps a period.
Targets: >= 150x at the default, >= 60x with the switching inverter. Standard library only.
--report FILE also writes the table as Markdown (command, commit, date, the machine and its load;
tools/report.py).
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
from scenario_keys import KEYS  # noqa: E402  (the one place that names the scenario keys)
import report  # noqa: E402

# (label, --set overrides, target real-time factor or None)
SETTINGS = [
    ("default (exponential x1), averaged", [], 150.0),
    ("default (exponential x1), switching", [f"{KEYS['inverter_model']}=switching"], 60.0),
    ("rk4 x25 (reference), averaged", [f"{KEYS['integrator']}=rk4", f"{KEYS['substeps']}=25"], None),
    ("rk4 x10 (former default), averaged", [f"{KEYS['integrator']}=rk4", f"{KEYS['substeps']}=10"], None),
]


def run_once(sil, overrides, out_dir):
    cmd = [str(sil), "--quiet", "--no-csv", "--out", str(out_dir)]
    for item in overrides:
        cmd += ["--set", item]
    subprocess.run(cmd, check=True)
    return json.loads((out_dir / "summary.json").read_text())


def cpu_model():
    """The processor's name from /proc/cpuinfo, or None."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def load_average():
    try:
        return os.getloadavg()[0]
    except (OSError, AttributeError):
        return None


def report_text(rows, runs, machine, argv):
    """benchmarks.md: @p rows as main() measures them (label, target, rtf, rtf_cpu, per_period_ns,
    plant_ns, plant_share, firmware_ns, firmware_share, wall_s), @p runs per setting, @p machine
    (cpu, cores, load_before, load_after)."""

    def load(v):
        return "-" if v is None else f"{v:.2f}"

    lines = [
        report.header("SIL benchmark", "tools/bench_sil.py", argv),
        f"The paper scenario (2.4 s simulated at 20 kHz) without CSV output, median of {runs} runs per "
        f"setting, on {machine['cpu'] or 'an unnamed processor'} ({machine['cores']} cores, shared: load average "
        f"{load(machine['load_before'])} before the runs, {load(machine['load_after'])} after).",
        "",
        "| setting | real-time factor | target | per CPU s | ns per period | plant | firmware | wall |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        target = f"≥ {r['target']:.0f}x" + ("" if r["rtf"] >= r["target"] else " (**below**)") if r["target"] else "-"
        lines.append(
            f"| {r['label']} | {r['rtf']:.1f}x | {target} | {r['rtf_cpu']:.1f}x | {r['per_period_ns']:.0f} | "
            f"{r['plant_ns']:.0f} ns ({100 * r['plant_share']:.0f} %) | "
            f"{r['firmware_ns']:.0f} ns ({100 * r['firmware_share']:.0f} %) | {r['wall_s']:.3f} s |"
        )
    lines += [
        "",
        "Real-time factor: simulated s per wall s of the run's loop (the target's measure); per CPU s: per "
        "CPU second of the process over the same loop, which leaves out waiting for a core on a shared machine. "
        "Plant: the inverter model and the integration of (1); firmware: the HAL read, `pmstep_step` and the "
        "HAL apply (shares of the wall, every 16th period timed and scaled); the rest is the runner: "
        "set-points, sample, metrics.",
    ]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="runs per setting (median is reported)")
    parser.add_argument("--sil", default=str(ROOT / "build/host-release/sil/pmstep-sil"))
    parser.add_argument(
        "--report", metavar="FILE", help="also write the table as Markdown (docs/reports/benchmarks.md)"
    )
    args = parser.parse_args()
    sil = pathlib.Path(args.sil)
    if not sil.exists():
        sys.exit(
            f"bench_sil: {sil} not found; build it with: cmake --preset host-release && "
            "cmake --build --preset host-release"
        )
    if args.runs < 1:
        sys.exit("bench_sil: --runs must be >= 1")

    print(f"paper scenario, 2.4 s simulated at 20 kHz; median of {args.runs} runs")
    print(
        f"{'setting':<38} {'real-time':>10} {'target':>7} {'(CPU)':>8} {'ns/period':>10} {'plant':>14}"
        f" {'firmware':>14} {'wall':>8}"
    )
    failed = []
    rows = []
    machine = {"cpu": cpu_model(), "cores": os.cpu_count(), "load_before": load_average()}
    with tempfile.TemporaryDirectory() as tmp:
        for label, overrides, target in SETTINGS:
            summaries = [run_once(sil, overrides, pathlib.Path(tmp)) for _ in range(args.runs)]
            timing = [s["timing"] for s in summaries]
            steps = timing[0]["steps"]
            rtf = statistics.median(t["real_time_factor"] for t in timing)
            rtf_cpu = statistics.median(t["simulated_s"] / t["cpu_s"] for t in timing)
            wall = statistics.median(t["wall_s"] for t in timing)
            plant = statistics.median(t["plant_wall_s"] for t in timing)
            firmware = statistics.median(t["firmware_wall_s"] for t in timing)
            per_period = wall / steps * 1e9
            target_text = f"{target:6.0f}x" if target else "      -"
            print(
                f"{label:<38} {rtf:9.1f}x {target_text} {rtf_cpu:7.1f}x {per_period:10.0f}"
                f" {plant / steps * 1e9:5.0f} ns {100 * plant / wall:3.0f}%"
                f" {firmware / steps * 1e9:5.0f} ns {100 * firmware / wall:3.0f}% {wall:7.3f}s"
            )
            if target and rtf < target:
                failed.append(f"{label}: {rtf:.1f}x < {target:.0f}x")
            rows.append(
                {
                    "label": label,
                    "target": target,
                    "rtf": rtf,
                    "rtf_cpu": rtf_cpu,
                    "per_period_ns": per_period,
                    "plant_ns": plant / steps * 1e9,
                    "plant_share": plant / wall,
                    "firmware_ns": firmware / steps * 1e9,
                    "firmware_share": firmware / wall,
                    "wall_s": wall,
                }
            )
    machine["load_after"] = load_average()
    print(
        "(real-time: simulated s per wall s of the run's loop, the target's measure; CPU: per CPU s of the process"
        " over the same loop, which leaves out waiting for a core on a shared machine. plant: the inverter model and"
        " the integration of (1); firmware: the HAL read, pmstep_step and the HAL apply; the rest is the runner:"
        " set-points, sample, metrics)"
    )
    if failed:
        print("below target: " + "; ".join(failed))
    if args.report:
        print(f"bench_sil: wrote {report.write(args.report, report_text(rows, args.runs, machine, sys.argv))}")


if __name__ == "__main__":
    main()
