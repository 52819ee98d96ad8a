#!/usr/bin/env python3
"""Real-time factor of the SIL on the paper scenario (a benchmark that prints figures).

Usage: tools/bench_sil.py [--runs N] [--sil build/host-release/sil/pmstep-sil]

Runs the paper scenario (2.4 s, 20 kHz) without CSV output at 25 RK4 substeps per
period (2 us) and at 5 (10 us), N times each, and prints the median real-time factor
(simulated s per wall s) with the time spent in the plant and in the firmware step
shown apart. Targets: >= 10x at 2 us, >= 40x at 10 us. Needs only the standard library.
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
TARGETS = {25: 10.0, 5: 40.0}


def run_once(sil, substeps, out_dir):
    cmd = [str(sil), "--quiet", "--no-csv", "--out", str(out_dir), "--set", f"run.substeps={substeps}"]
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
    print(f"{'substep':>8} {'real-time':>10} {'target':>7} {'plant':>14} {'firmware step':>14} {'wall':>8}")
    failed = []
    with tempfile.TemporaryDirectory() as tmp:
        for substeps, target in TARGETS.items():
            summaries = [run_once(sil, substeps, pathlib.Path(tmp)) for _ in range(args.runs)]
            timing = [s["timing"] for s in summaries]
            steps = timing[0]["steps"]
            rtf = statistics.median(t["real_time_factor"] for t in timing)
            wall = statistics.median(t["wall_s"] for t in timing)
            plant_ns = statistics.median(t["plant_wall_s"] for t in timing) / (steps * substeps) * 1e9
            step_ns = statistics.median(t["firmware_wall_s"] for t in timing) / steps * 1e9
            h_us = summaries[0]["control_period_s"] / substeps * 1e6
            print(f"{h_us:6.1f}us {rtf:9.1f}x {target:6.0f}x {plant_ns:8.1f} ns/RK4 {step_ns:8.1f} ns/step"
                  f" {wall:7.3f}s")
            if rtf < target:
                failed.append(f"{h_us:.0f} us: {rtf:.1f}x < {target:.0f}x")
    print("(firmware step time includes the HAL read/apply and two clock reads around it)")
    if failed:
        print("below target: " + "; ".join(failed))


if __name__ == "__main__":
    main()
