#!/usr/bin/env python3
"""Issue 13 acceptance: sensorless position control on the paper's motor and the motor presets.

For each motor (sil/scenarios/motors/*.ini) and chain:
  ideal       pmstep-tune's design (ideal measurement chain, the plant's detent torque on), then
              N random moves (targets uniform within +-10 revolutions of the c-alignment
              equilibrium RUN starts at, every move at v_max = 1/2 of the design's top speed and
              a_max = 1/4 of k_M I / J, the jerk a_max varpi_0), each given the profile's time
              plus a settling time before the next;
  realistic   pmstep-tune --robust under the presets' realistic chain (mc_preset.py, as the envelope
              and the Monte Carlo: sil/scenarios/robust.ini's sensors, a 12-bit ADC over +-3 x rated
              current, +-20 mA offsets, 5 mA noise, one period of delay, 1 us dead time, and a
              switching inverter, the bridge the designer's dead-time compensation is shaped for),
              the plant's R 20 % above the firmware's, the same moves, then a hold of --hold-s
              seconds under a load stepped to 30 % of the rated torque k_M I. Before the first
              move (speed mode) a loss of control is |w - w*| above robust.ini's 2 rad/s scaled
              to the motor's top speed, as the presets' Monte Carlo scenarios have it; in
              position mode it is a lost step (pmstep-sil's run.loss_position_error_rad).
Each run is pmstep-sil on the scenario with --set overrides; the figures come from its
summary.json ("position", electrical rad = p x mechanical). Prints one line per run and the
issue's criteria, and exits 1 if one fails (--check): ideal chain, final error < 0.1 electrical
rad after every move and overshoot < 1 % of the move; realistic chain, the true position within
0.5 electrical rad of theta* the whole time (moves and hold) and at the end of every move.

usage: tools/position_acceptance.py [--sil PATH] [--tune PATH] [--motors paper,17hs4401,...]
                                    [--chains ideal,realistic] [--moves 50] [--seed 1]
                                    [--hold-s 60] [--out DIR] [--check] [--json FILE]
                                    [--write-scenarios] [--speed-fraction F] [--accel-fraction F]
                                    [--report docs/reports/position-acceptance.md]
--report FILE also writes the table as Markdown (command, commit, date; tools/report.py).
"""

import argparse
import configparser
import json
import math
import os
import random
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# the realistic chain (ADC span sized to the motor) and the speed-mode loss bound scaled to its top speed
from mc_preset import chain_sets, loss_speed_error, paper_top_speed, tune_top_speed  # noqa: E402
import report  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MOTORS = ["paper", "17hs4401", "bj42d29", "as1050"]
REVOLUTION = 2.0 * math.pi
SETTLE_S = 0.5  # after the profile's end, before the next move (the loop's slow pole: 0.15 k_theta)
FINAL_BOUND = 0.1  # electrical rad, the (ideal chain)
OVERSHOOT_BOUND = 0.01  # of the move (ideal chain)
HOLD_BOUND = 0.5  # electrical rad (realistic chain: the whole time)


def read_preset(path):
    ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
    ini.read(path)
    return {
        "rated_A": float(ini["datasheet"]["rated_current_A"]),
        "k_M": float(ini["motor"]["torque_constant_Nm_A"]),
        "J": float(ini["motor"]["inertia_kgm2"]),
        "R": float(ini["motor"]["resistance_Ohm"]),
        "p": int(ini["motor"]["pole_pairs"]),
    }


def design(tune, motor_ini, ini_out, robust, sets, weakened=False):
    """The design's top speed (@p weakened: the field-weakened one), varpi_0 and k_theta."""
    cmd = [tune, "--motor", motor_ini, "--write-ini", ini_out] + (["--robust"] if robust else [])
    for s in sets:
        cmd += ["--set", s]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    top = tune_top_speed(out, weakened)
    varpi = float(re.search(r"varpi_0 ([0-9.e+-]+) rad/s", out).group(1))
    k_theta = float(re.search(r"position loop: k_theta ([0-9.e+-]+)", out).group(1))
    return top, varpi, k_theta


def move_time(distance, v, a, j):
    """Time of a jerk-limited move from rest to rest (pmstep_motion.h)."""
    if distance <= 0.0:
        return 0.0

    def change(dv):
        return dv / a + a / j if dv >= a * a / j else 2.0 * math.sqrt(dv / j)

    full = v * change(v)  # distance of the speed changes up to v and back, no cruise
    if full <= distance:
        return 2.0 * change(v) + (distance - full) / v
    lo, hi = 0.0, v
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * change(mid) <= distance else (lo, mid)
    return 2.0 * change(lo) + (distance - lo * change(lo)) / max(lo, 1e-12)


def moves_for(rng, n, start_s, v, a, j):
    times, targets = [], []
    t, position = start_s, 0.0
    for _ in range(n):
        target = rng.uniform(-10.0 * REVOLUTION, 10.0 * REVOLUTION)
        times.append(t)
        targets.append(target)
        t += move_time(abs(target - position), v, a, j) + SETTLE_S
        position = target
    return times, targets, t


def run_sil(sil, scenario, sets, out_dir):
    cmd = [sil, "--quiet", "--no-csv", "--out", out_dir, "--scenario", scenario]
    for s in sets:
        cmd += ["--set", s]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    summary_path = os.path.join(out_dir, "summary.json")
    if not os.path.isfile(summary_path):
        raise RuntimeError(f"pmstep-sil failed ({proc.returncode}): {proc.stderr.strip()}")
    with open(summary_path) as f:
        summary = json.load(f)
    return proc.returncode, summary


def _g(value, spec=".3g"):
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else format(value, spec)


def report_text(results, args, argv):
    """The report: the settings of @p args and one row per run of @p results (main()'s --json)."""
    what = (
        f"Per motor preset: the `pmstep-tune` design, {args.moves} random moves (seed {args.seed}, targets uniform "
        f"in ±10 revolutions of where RUN starts, v_max = {args.speed_fraction:g} of the design's "
        + ("field-weakened " if args.top == "weakened" else "")
        + "top speed, "
        f"a_max = {args.accel_fraction:g} of k_M I / J, jerk a_max ϖ0; each move given its profile's time plus "
        f"{SETTLE_S:g} s). Ideal: the ideal measurement chain, the plant's detent torque on. Realistic: "
        "`pmstep-tune --robust` behind the presets' realistic chain (tools/mc_preset.py: 12-bit ADC over ±3 rated "
        "current, ±20 mA offsets, 5 mA noise, one period of delay, 1 µs dead time, switching inverter), the "
        f"plant's R 20 % above the firmware's, the same moves, then {args.hold_s:g} s of hold under 30 % of "
        'k_M I stepped on. Electrical rad (p × mechanical); "estimate" is the largest |p(θ̂ − θ)| over the '
        'run, "θ* − θ" the largest true position error in position mode (moves and hold), drift in '
        "electrical rad/s over the hold."
    )
    lines = [
        report.header(
            "Position control: acceptance" + (" at the field-weakened top speed" if args.top == "weakened" else ""),
            "tools/position_acceptance.py",
            argv,
            what,
        ),
        "| motor | chain | moves (unfinished) | final error max / mean | overshoot | estimate | θ* − θ | "
        "hold max, drift | simulated | fault | criteria |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        pos = r["position"]
        robust = r["chain"] == "realistic"
        overshoot = pos.get("max_overshoot_fraction")
        hold = (
            f"{_g(pos.get('hold_max_error_electrical_rad'))}, {_g(pos.get('hold_drift_electrical_rad_s'))} /s"
            if robust
            else "-"
        )
        lines.append(
            f"| {r['motor']} | {r['chain']} | {pos.get('moves', 0)} ({pos.get('unfinished_moves', '-')}) | "
            f"{_g(pos.get('max_final_error_electrical_rad'))} / "
            f"{_g(pos.get('mean_final_error_electrical_rad'))} | "
            f"{_g(None if overshoot is None else 100.0 * overshoot, '.2f')} % | "
            f"{_g(pos.get('max_estimate_error_electrical_rad'))} | "
            f"{_g(pos.get('max_tracking_error_electrical_rad'))} | {hold} | {r['simulated_s']:.0f} s | "
            f"{'none' if r['fault'] == 'NONE' else r['fault']} | {'met' if r['pass'] else '**FAILED**'} |"
        )
    passed = sum(1 for r in results if r["pass"])
    lines += [
        "",
        f"Criteria: ideal chain, final error < {FINAL_BOUND:g} electrical rad after every move and overshoot "
        f"< {100 * OVERSHOOT_BOUND:g} % of the move; realistic chain, |θ* − θ| < {HOLD_BOUND:g} electrical rad "
        "the whole time (moves and hold) and at the end of every move; every run without a fault, every move "
        f"finished. **{passed} of {len(results)} runs meet them.**",
    ]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sil", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-sil"))
    ap.add_argument("--tune", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-tune"))
    ap.add_argument("--motors", default=",".join(MOTORS))
    ap.add_argument("--chains", default="ideal,realistic")
    ap.add_argument("--moves", type=int, default=50)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--hold-s", type=float, default=60.0)
    ap.add_argument("--speed-fraction", type=float, default=0.5, help="v_max as a fraction of the top speed")
    ap.add_argument(
        "--top",
        choices=("design", "weakened"),
        default="design",
        help="the top speed v_max is a fraction of: the design's (i_d = 0) or the field-weakened one (pmstep-tune's "
        "'top speed with it'); with weakened the speed-mode loss bound follows the weakened top speeds too",
    )
    ap.add_argument("--accel-fraction", type=float, default=0.25, help="a_max as a fraction of k_M I / J")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "position_acceptance"))
    ap.add_argument("--check", action="store_true", help="exit 1 if a criterion fails")
    ap.add_argument("--json", help="also write every run's figures to this file")
    ap.add_argument(
        "--write-scenarios",
        action="store_true",
        help="also write each run's whole scenario to OUT/<motor>_<chain>_run.ini",
    )
    ap.add_argument(
        "--report", metavar="FILE", help="also write the table as Markdown (docs/reports/position-acceptance.md)"
    )
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    results = []
    failed = False
    paper_top = None  # designed once, for the first realistic run
    print(
        f"{'motor':9s} {'chain':9s} {'moves':>5s} {'final max':>10s} {'final mean':>10s} {'overshoot':>9s} "
        f"{'unfin':>5s} {'estimate':>9s} {'hold max':>9s} {'drift':>10s} {'sim s':>6s} {'fault':>6s}  verdict"
    )
    for motor in args.motors.split(","):
        motor_ini = os.path.join(ROOT, "sil", "scenarios", "motors", f"{motor}.ini")
        preset = read_preset(motor_ini)
        for chain in args.chains.split(","):
            robust = chain == "realistic"
            base = os.path.join(args.out, f"{motor}_{chain}.ini")
            tune_sets = []
            if robust:
                tune_sets = chain_sets({"rated_current_A": preset["rated_A"]})
            top, varpi, k_theta = design(args.tune, motor_ini, base, robust, tune_sets, args.top == "weakened")
            v_max = args.speed_fraction * top
            a_max = args.accel_fraction * preset["k_M"] * preset["rated_A"] / preset["J"]
            j_max = a_max * varpi
            rng = random.Random(args.seed)  # the same moves for both chains
            ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
            ini.read(base)
            run_start = float(ini["controller.commissioning"]["offset_calibration_time_s"]) + float(
                ini["controller.alignment"]["c_align_time_s"]
            )
            times, targets, end_s = moves_for(rng, args.moves, run_start + 0.1, v_max, a_max, j_max)
            sets = [
                "speed.points=0:0",
                "load.type=none",
                "position.points=" + ", ".join(f"{t:.6f}:{x:.6f}" for t, x in zip(times, targets)),
                f"position.v_max_rad_s={v_max:.9g}",
                f"position.a_max_rad_s2={a_max:.9g}",
                f"position.j_max_rad_s3={j_max:.9g}",
                f"run.duration_s={end_s:.6f}",
            ]
            if robust:
                load = 0.3 * preset["k_M"] * preset["rated_A"]
                if paper_top is None:
                    paper_top = paper_top_speed(args.tune, args.top == "weakened")
                sets.append(f"run.loss_speed_error_rad_s={loss_speed_error(top, paper_top):.9g}")
                sets += [
                    f"motor.resistance_Ohm={1.2 * preset['R']:.9g}",  # the plant's; the firmware keeps R
                    "load.type=step",
                    f"load.torque_Nm={load:.9g}",
                    f"load.step_time_s={end_s:.6f}",
                    f"position.hold_start_s={end_s:.6f}",
                    f"run.duration_s={end_s + args.hold_s:.6f}",
                ]
            if args.write_scenarios:
                # the whole scenario of this run, e.g. for tools/monte_carlo.py --scenario
                cmd = [args.sil, "--scenario", base, "--print-scenario"]
                for s in sets:
                    cmd += ["--set", s]
                text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
                with open(os.path.join(args.out, f"{motor}_{chain}_run.ini"), "w") as f:
                    f.write(text)
            rc, summary = run_sil(args.sil, base, sets, os.path.join(args.out, f"{motor}_{chain}"))
            pos = summary.get("position", {})
            fault = summary["fault"]["name"]
            ok = rc == 0 and fault == "NONE" and pos.get("moves") == args.moves and pos.get("unfinished_moves") == 0
            if ok and robust:
                ok = (
                    pos["max_final_error_electrical_rad"] < HOLD_BOUND
                    and pos["max_tracking_error_electrical_rad"] < HOLD_BOUND
                    and pos["hold_max_error_electrical_rad"] < HOLD_BOUND
                )
            elif ok:
                ok = (
                    pos["max_final_error_electrical_rad"] < FINAL_BOUND
                    and pos["max_overshoot_fraction"] < OVERSHOOT_BOUND
                )
            failed |= not ok
            row = {
                "motor": motor,
                "chain": chain,
                "v_max_rad_s": v_max,
                "a_max_rad_s2": a_max,
                "j_max_rad_s3": j_max,
                "k_theta_per_s": k_theta,
                "exit_status": rc,
                "fault": fault,
                "simulated_s": summary["timing"]["simulated_s"],
                "position": pos,
                "pass": ok,
            }
            results.append(row)
            hold = (
                f"{pos['hold_max_error_electrical_rad']:9.3g} {pos['hold_drift_electrical_rad_s']:10.3g}"
                if robust
                else f"{'-':>9s} {'-':>10s}"
            )
            print(
                f"{motor:9s} {chain:9s} {pos.get('moves', 0):5d} "
                f"{pos.get('max_final_error_electrical_rad', math.nan):10.3g} "
                f"{pos.get('mean_final_error_electrical_rad', math.nan):10.3g} "
                f"{100.0 * pos.get('max_overshoot_fraction', math.nan):8.3f}% {pos.get('unfinished_moves', -1):5d} "
                f"{pos.get('max_estimate_error_electrical_rad', math.nan):9.3g} {hold} "
                f"{summary['timing']['simulated_s']:6.0f} {fault[:6]:>6s}  {'pass' if ok else 'FAIL'}"
            )
            sys.stdout.flush()
    print(
        f"units: electrical rad (p x mechanical), drift in electrical rad/s over the hold; criteria: ideal, final < "
        f"{FINAL_BOUND} and overshoot < {100 * OVERSHOOT_BOUND:g} %; realistic, |theta* - theta| < {HOLD_BOUND} "
        f"the whole time and at every move's end"
    )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    if args.report:
        print(f"position_acceptance: wrote {report.write(args.report, report_text(results, args, sys.argv))}")
    return 1 if (failed and args.check) else 0


if __name__ == "__main__":
    sys.exit(main())
