#!/usr/bin/env python3
"""Real-time factor of the SIL on the paper scenario (a benchmark that prints figures).

Usage: tools/bench_sil.py [--runs N] [--sil build/host-release/sil/pmstep-sil]

Runs the paper scenario (2.4 s, 20 kHz) without CSV output, N times per setting, and
prints the median real-time factor (simulated s per wall s; also per CPU s, which a busy
shared machine inflates less) with the plant's and the firmware step's shares of the wall
time (the runner times every 16th period and scales).
Settings: the default (exponential integrator, one step a period) with the averaged and
the switching inverter, and the RK4 reference at 25 and 10 steps a period.
Targets: >= 150x at the default, >= 60x with the switching inverter. Standard library only.
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
from scenario_keys import KEYS  # noqa: E402  (the one place that names the scenario keys)

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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="runs per setting (median is reported)")
    parser.add_argument("--sil", default=str(ROOT / "build/host-release/sil/pmstep-sil"))
    args = parser.parse_args()
    sil = pathlib.Path(args.sil)
    if not sil.exists():
        sys.exit(f"bench_sil: {sil} not found; build it with: cmake --preset host-release && "
                 "cmake --build --preset host-release")
    if args.runs < 1:
        sys.exit("bench_sil: --runs must be >= 1")

    print(f"paper scenario, 2.4 s simulated at 20 kHz; median of {args.runs} runs")
    print(f"{'setting':<38} {'real-time':>10} {'target':>7} {'(CPU)':>8} {'ns/period':>10} {'plant':>14}"
          f" {'firmware':>14} {'wall':>8}")
    failed = []
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
            print(f"{label:<38} {rtf:9.1f}x {target_text} {rtf_cpu:7.1f}x {per_period:10.0f}"
                  f" {plant / steps * 1e9:5.0f} ns {100 * plant / wall:3.0f}%"
                  f" {firmware / steps * 1e9:5.0f} ns {100 * firmware / wall:3.0f}% {wall:7.3f}s")
            if target and rtf < target:
                failed.append(f"{label}: {rtf:.1f}x < {target:.0f}x")
    print("(real-time: simulated s per wall s of the run's loop, the target's measure; CPU: per CPU s of the process"
          " over the same loop, which leaves out waiting for a core on a shared machine. plant: the inverter model and"
          " the integration of (1); firmware: the HAL read, pmstep_step and the HAL apply; the rest is the runner:"
          " set-points, sample, metrics)")
    if failed:
        print("below target: " + "; ".join(failed))


if __name__ == "__main__":
    main()
