#!/usr/bin/env python3
"""Homing without a switch (pmstep_homing.h) against the SIL's hard stop, over the homing speed.

For each public motor preset and chain:
  ideal       pmstep-tune's design (ideal measurement chain, the plant's detent torque on);
  realistic   pmstep-tune --robust under the presets' realistic chain (mc_preset.chain_sets: 12-bit ADC,
              offsets, 5 mA noise, a period of delay, dead time, the switching inverter), the plant's R 20 %
              above the firmware's.
the drive homes (position.source = homing) toward a stop placed STOP_FULL_STEPS full steps plus the
distance to reach the speed away from the c-alignment's equilibrium (and a fraction of a step off any detent), at
speeds from
SPEED_FRACTIONS of the design's top speed and at the designer's own speed, alternately in the two
directions. The stop (motor.stop_*) is a one-sided spring that the holding torque presses in by
STOP_COMPLIANCE_FULL_STEPS of a full step, damped at ζ = STOP_DAMPING_RATIO on the rotor's inertia. Each
run is pmstep-sil on the design with --set overrides; the figures are its summary.json's "homing".

Errors in full steps (π / 2p): **stop error** the zero the drive set less where the rotor meets the stop;
**final error** the drive's position after the back-off less the rotor's true distance from the stop.
Verdict (--check): homing done, no fault, |stop error| and |final error| within BOUND_FULL_STEPS, the
largest phase current from the contact to the find within the stall current plus the current the
homing's acceleration takes; and, with no stop in reach, homing ends
not found, holding, without a fault.

usage: tools/homing_sweep.py [--sil PATH] [--tune PATH] [--motors paper,17hs4401,...]
                             [--chains ideal,realistic] [--quick] [--check] [--jobs 2]
                             [--out DIR] [--json FILE] [--report docs/reports/homing.md]
"""

import argparse
import concurrent.futures
import configparser
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report  # noqa: E402
from mc_preset import chain_sets  # noqa: E402
from stepdir_compare import design, microsteps_for, move_time, run_sil  # noqa: E402  (the tune's design, the
# SIL's run, the STEP/DIR case's count and timing)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MOTORS = ["paper", "17hs4401", "bj42d29", "as1050"]
CHAINS = ["ideal", "realistic"]
SPEED_FRACTIONS = [0.001, 0.003, 0.01, 0.03, 0.1, 0.2, 0.3, 0.5]
QUICK_FRACTIONS = [0.01, 0.03]
STOP_FULL_STEPS = 4.37  # cruise before the stop, full steps (off a detent by a fraction)
STOP_COMPLIANCE_FULL_STEPS = 0.05
STOP_DAMPING_RATIO = 0.5
BOUND_FULL_STEPS = 0.25
STEPDIR_BACK_FULL_STEPS = 2.0  # the STEP/DIR case's back-off after the dwell
STEPDIR_DWELL_S = 0.1
THETA0_ELECTRICAL_DEG = 30.0  # the rotor's start: the c-alignment's equilibrium at theta = 0 is the nearest
LEAD_S = 0.1  # from RUN's start to the homing
TAIL_S = 0.3  # after the back-off's expected end


def read_motor(path):
    ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
    ini.read(path)
    return {
        "rated_A": float(ini["datasheet"]["rated_current_A"]),
        "holding_Nm": float(ini["datasheet"]["holding_torque_Nm"]),
        "k_M": float(ini["motor"]["torque_constant_Nm_A"]),
        "J": float(ini["motor"]["inertia_kgm2"]),
        "R": float(ini["motor"]["resistance_Ohm"]),
        "p": int(ini["motor"]["pole_pairs"]),
    }


def designed_homing(sil, scenario, out_dir):
    """The designer's homing settings for the design (a run of no length prints them in its summary)."""
    s = run_sil(
        sil,
        scenario,
        ["speed.points=0:0", "position.source=homing", "position.points=1e3:1", "run.duration_s=1e-3"],
        out_dir,
    )[1]
    return s["homing"]


def stop_sets(motor, direction, reach):
    """The plant's hard stop @p reach from the c-alignment's equilibrium toward @p direction."""
    full_step = math.pi / (2.0 * motor["p"])
    stiffness = motor["holding_Nm"] / (STOP_COMPLIANCE_FULL_STEPS * full_step)
    damping = 2.0 * STOP_DAMPING_RATIO * math.sqrt(stiffness * motor["J"])
    return [
        f"motor.stop_side={direction}",
        f"motor.stop_position_rad={direction * reach:.9g}",
        f"motor.stop_stiffness_Nm_rad={stiffness:.9g}",
        f"motor.stop_damping_Nms_rad={damping:.9g}",
    ]


def plan(motor, top, run_start, homing, fraction, direction, with_stop):
    """The --set items of one homing run; @p fraction of the top speed (None: the designer's speed)."""
    full_step = math.pi / (2.0 * motor["p"])
    v = homing["speed_rad_s"] if fraction is None else fraction * top
    a = homing["accel_rad_s2"]
    reach = STOP_FULL_STEPS * full_step + v * v / a
    back_off = homing["back_off_rad"]
    travel = 3.0 * reach if with_stop else 0.5 * reach
    start = run_start + LEAD_S
    duration = start + (3.0 * reach) / v + 2.0 * v / a + (back_off / v if v > 0 else 0.0) + TAIL_S
    sets = [
        "speed.points=0:0",
        "load.type=none",
        "position.source=homing",
        f"run.theta0_deg={THETA0_ELECTRICAL_DEG / motor['p']:.9g}",
        f"position.points={start:.6f}:{direction * travel:.9g}",
        f"homing.speed_rad_s={v:.9g}",
        f"run.duration_s={duration:.6f}",
    ]
    if with_stop:
        sets += stop_sets(motor, direction, reach)
    return v, sets


def verdict(row):
    h = row["homing"]
    failures = []
    if row["fault"] != "NONE":
        failures.append("fault " + row["fault"])
    if not row["with_stop"]:
        if h["state"] != "not_found":
            failures.append(f"state {h['state']} without a stop")
        return failures
    if h["state"] != "done":
        failures.append("state " + h["state"])
        return failures
    if abs(h["stop_error_full_steps"]) > BOUND_FULL_STEPS:
        failures.append(f"stop error {h['stop_error_full_steps']:+.3f}")
    if abs(h["final_position_error_full_steps"]) > BOUND_FULL_STEPS:
        failures.append(f"final error {h['final_position_error_full_steps']:+.3f}")
    if h["contact_peak_current_a"] > row["current_bound_A"]:
        failures.append(
            f"current {h['contact_peak_current_a']:.3f} A on the stop, above {row['current_bound_A']:.3f} A"
        )
    return failures


def one_run(args, name, chain, motor, scenario, top, run_start, homing, fraction, direction, with_stop, extra):
    v, sets = plan(motor, top, run_start, homing, fraction, direction, with_stop)
    tag = "designer" if fraction is None else f"{fraction:g}"
    out_dir = os.path.join(args.out, f"{name}_{chain}_{tag}_{'stop' if with_stop else 'free'}")
    rc, s = run_sil(args.sil, scenario, sets + extra, out_dir)
    accel_current = motor["J"] * homing["accel_rad_s2"] / motor["k_M"]
    row = {
        "motor": name,
        "chain": chain,
        "fraction": fraction,
        "speed_rad_s": v,
        "top_rad_s": top,
        "direction": direction,
        "with_stop": with_stop,
        "fault": s["fault"]["name"],
        "exit_status": rc,
        "homing": s["homing"],
        "current_bound_A": homing["stall_current_a"] + accel_current,
    }
    row["failures"] = verdict(row)
    return row


def stepdir_case(args, name, chain, motor, scenario, figures, homing, extra):
    """Homing on DIAG as a motion controller does it over STEP/DIR (stepdir.stall_current_A the designer's
    homing stall current): the count moves at the designer's homing speed to twice the stop's distance, then,
    after a dwell, back by STEPDIR_BACK_FULL_STEPS; the steps toward the stop past the stall are dropped, so
    the rotor ends that far from the stop."""
    top, run_start, tracking, stall = figures
    full_step = math.pi / (2.0 * motor["p"])
    microsteps = microsteps_for(motor, tracking, stall)
    v, a = homing["speed_rad_s"], homing["accel_rad_s2"]
    reach = STOP_FULL_STEPS * full_step + v * v / a
    back = STEPDIR_BACK_FULL_STEPS * full_step
    t0 = run_start + LEAD_S
    t1 = t0 + move_time(2.0 * reach, v, a, 0.0) + STEPDIR_DWELL_S
    end = t1 + move_time(back, v, a, 0.0) + TAIL_S
    sets = [
        "speed.points=0:0",
        "load.type=none",
        "position.source=stepdir",
        f"stepdir.microsteps={microsteps}",
        f"stepdir.stall_current_A={homing['stall_current_a']:.9g}",
        f"position.points={t0:.6f}:{2.0 * reach:.9g}, {t1:.6f}:{2.0 * reach - back:.9g}",
        f"position.v_max_rad_s={v:.9g}",
        f"position.a_max_rad_s2={a:.9g}",
        "position.j_max_rad_s3=0",
        f"run.duration_s={end:.6f}",
        f"run.theta0_deg={THETA0_ELECTRICAL_DEG / motor['p']:.9g}",
    ]
    sets += stop_sets(motor, 1, reach)
    rc, s = run_sil(args.sil, scenario, sets + extra, os.path.join(args.out, f"{name}_{chain}_stepdir"))
    d = s["stepdir"]
    q = 2.0 * math.pi / (4.0 * motor["p"] * microsteps)
    from_stop = d["generator_steps"] * q - d["final_error_full_steps"] * full_step - reach
    row = {
        "motor": name,
        "chain": chain,
        "microsteps": microsteps,
        "speed_rad_s": v,
        "top_rad_s": top,
        "fault": s["fault"]["name"],
        "exit_status": rc,
        "stepdir": d,
        "stop_contact_s": s["stop_contact_s"],
        "final_error_full_steps": (from_stop + back) / full_step,
        "diag_after_contact_s": (
            d["diag_first_s"] - s["stop_contact_s"] if d["diag_first_s"] >= 0 and s["stop_contact_s"] >= 0 else None
        ),
    }
    failures = []
    if row["fault"] != "NONE":
        failures.append("fault " + row["fault"])
    if d["following_start_s"] < 0.0 or d["following_end_s"] >= 0.0:
        failures.append("not following the count to the end")
    if d["drive_steps"] != d["generator_steps"]:
        failures.append(f"counted {d['drive_steps']} of {d['generator_steps']} microsteps")
    if row["diag_after_contact_s"] is None or row["diag_after_contact_s"] < 0.0:
        failures.append("no DIAG at the stop")
    if abs(row["final_error_full_steps"]) > BOUND_FULL_STEPS:
        failures.append(f"final error {row['final_error_full_steps']:+.3f}")
    row["failures"] = failures
    return row


def stepdir_line(row, markdown):
    d = row["stepdir"]
    cells = [
        row["motor"],
        row["chain"],
        str(row["microsteps"]),
        f"{row['speed_rad_s']:.3g} rad/s ({row['speed_rad_s'] / row['top_rad_s']:.3g} top)",
        f"{1e3 * row['diag_after_contact_s']:.1f} ms" if row["diag_after_contact_s"] is not None else "-",
        str(d["diag_periods"]),
        f"{row['final_error_full_steps']:+.3f}",
        "met" if not row["failures"] else "; ".join(row["failures"]),
    ]
    if markdown:
        return "| " + " | ".join(cells) + " |"
    return "  ".join(cells)


STEPDIR_COLUMNS = ["motor", "chain", "µsteps", "speed", "DIAG after contact", "DIAG periods", "final error", "verdict"]


def sweep(args):
    jobs = []
    stepdir_jobs = []
    for name in args.motors.split(","):
        motor_ini = os.path.join(ROOT, "sil", "scenarios", "motors", f"{name}.ini")
        motor = read_motor(motor_ini)
        for chain in args.chains.split(","):
            robust = chain == "realistic"
            sets = chain_sets({"rated_current_A": motor["rated_A"]}) if robust else []
            scenario = os.path.join(args.out, f"{name}_{chain}.ini")
            figures = design(args.tune, motor_ini, scenario, robust, sets)
            top, run_start = figures[0], figures[1]
            homing = designed_homing(args.sil, scenario, os.path.join(args.out, f"{name}_{chain}_design"))
            extra = sets + ([f"motor.resistance_Ohm={1.2 * motor['R']:.9g}"] if robust else [])
            fractions = (QUICK_FRACTIONS if args.quick else SPEED_FRACTIONS) + [None]
            for n, fraction in enumerate(fractions):
                jobs.append(
                    (
                        name,
                        chain,
                        motor,
                        scenario,
                        top,
                        run_start,
                        homing,
                        fraction,
                        1 if n % 2 == 0 else -1,
                        True,
                        extra,
                    )
                )
            jobs.append((name, chain, motor, scenario, top, run_start, homing, None, 1, False, extra))
            stepdir_jobs.append((name, chain, motor, scenario, figures, homing, extra))
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(one_run, args, *job) for job in jobs]
        stepdir_futures = [pool.submit(stepdir_case, args, *job) for job in stepdir_jobs]
        rows = []
        for future in futures:
            row = future.result()
            rows.append(row)
            print(line(row, False))
            sys.stdout.flush()
        print("STEP/DIR homing on DIAG: " + "  ".join(STEPDIR_COLUMNS))
        stepdir_rows = []
        for future in stepdir_futures:
            row = future.result()
            stepdir_rows.append(row)
            print(stepdir_line(row, False))
            sys.stdout.flush()
    return rows, stepdir_rows


COLUMNS = [
    "motor",
    "chain",
    "speed",
    "stop",
    "state",
    "found by",
    "after contact",
    "stop error",
    "final error",
    "current on the stop",
    "stall current",
    "stop's push",
    "verdict",
]


def line(row, markdown):
    h = row["homing"]
    speed = f"{row['speed_rad_s']:.3g} rad/s ({row['speed_rad_s'] / row['top_rad_s']:.3g} top)"
    if row["fraction"] is None:
        speed += ", designer's"
    found_after = (
        f"{1e3 * (h['found_s'] - h['contact_s']):.1f} ms" if h["found_s"] >= 0 and h["contact_s"] >= 0 else "-"
    )
    done = row["with_stop"] and h["state"] == "done"
    cells = [
        row["motor"],
        row["chain"],
        speed,
        "yes" if row["with_stop"] else "none in reach",
        h["state"],
        h["found_by"].replace("_", " ") if done else "-",
        found_after if done else "-",
        f"{h['stop_error_full_steps']:+.3f}" if done else "-",
        f"{h['final_position_error_full_steps']:+.3f}" if done else "-",
        f"{h['contact_peak_current_a']:.3f} A" if row["with_stop"] else "-",
        f"{h['stall_current_a']:.3f} A",
        f"{h['seek_peak_stop_torque_nm']:.3f} Nm" if row["with_stop"] else "-",
        "met" if not row["failures"] else "; ".join(row["failures"]),
    ]
    if markdown:
        return "| " + " | ".join(cells) + " |"
    return "  ".join(cells)


def speed_range(rows):
    """Per motor and chain: the band of speeds, around the designer's, in which every run met the verdict
    (lowest, highest), the top speed, the largest |stop error| in it, and the runs met of those tried."""
    out = []
    keys = sorted({(r["motor"], r["chain"]) for r in rows}, key=lambda k: (MOTORS.index(k[0]), k[1]))
    for motor, chain in keys:
        tried = sorted(
            (r for r in rows if r["motor"] == motor and r["chain"] == chain and r["with_stop"]),
            key=lambda r: r["speed_rad_s"],
        )
        top = tried[0]["top_rad_s"]
        home = next(i for i, r in enumerate(tried) if r["fraction"] is None)
        band = []
        if not tried[home]["failures"]:
            lo = hi = home
            while lo > 0 and not tried[lo - 1]["failures"]:
                lo -= 1
            while hi + 1 < len(tried) and not tried[hi + 1]["failures"]:
                hi += 1
            band = tried[lo : hi + 1]
        worst = max(abs(r["homing"]["stop_error_full_steps"]) for r in band) if band else None
        n_met = sum(1 for r in tried if not r["failures"])
        out.append(
            (
                motor,
                chain,
                band[0]["speed_rad_s"] if band else None,
                band[-1]["speed_rad_s"] if band else None,
                top,
                worst,
                n_met,
                len(tried),
            )
        )
    return out


def summary_text(rows):
    parts = []
    for motor, chain, lo, hi, top, worst, n_met, n in speed_range(rows):
        if lo is None:
            parts.append(f"{motor} {chain}: the designer's speed missed ({n_met} of {n} met)")
        else:
            parts.append(
                f"{motor} {chain}: {n_met} of {n} met, every speed from {lo:.3g} to {hi:.3g} rad/s "
                f"({lo / top:.3g} to {hi / top:.3g} of the top speed) met, the stop found there within "
                f"{worst:.3f} full steps"
            )
    return "; ".join(parts) + "."


def stepdir_summary(stepdir_rows):
    met = [r for r in stepdir_rows if not r["failures"]]
    latency = [r["diag_after_contact_s"] for r in met]
    worst = max((abs(r["final_error_full_steps"]) for r in met), default=0.0)
    text = f"STEP/DIR homing on DIAG: {len(met)} of {len(stepdir_rows)} met"
    if met:
        text += (
            f", DIAG {1e3 * min(latency):.1f} to {1e3 * max(latency):.1f} ms after the contact, the rotor "
            f"{STEPDIR_BACK_FULL_STEPS:g} full steps from the stop after the back-off within {worst:.3f} full steps"
        )
    return text + "."


WHAT = (
    "Per public motor preset, on the **ideal** chain (pmstep-tune's design, the plant's detent torque on) and "
    "on the **realistic** one (pmstep-tune --robust under the presets' realistic measurement chain of "
    "tools/mc_preset.py, the plant's R 20 % above the firmware's), the drive homes (`position.source = "
    "homing`, pmstep_homing.h) toward the SIL's hard stop (`motor.stop_*`: a one-sided spring that the "
    f"holding torque presses in by {STOP_COMPLIANCE_FULL_STEPS:g} of a full step, damped at ζ = "
    f"{STOP_DAMPING_RATIO:g} on the rotor's inertia), placed {STOP_FULL_STEPS:g} full steps plus the distance "
    "to reach the speed from the c-alignment's equilibrium, at speeds from "
    f"{SPEED_FRACTIONS[0]:g} to {SPEED_FRACTIONS[-1]:g} of the design's top speed and at the designer's own, "
    "alternately in the two directions, and once with no stop in reach. Full steps are π / 2p. **Stop "
    "error**: the zero the drive set less where the rotor meets the stop; **final error**: the drive's "
    "position after the back-off less the rotor's true distance from the stop; **current on the stop**: "
    "the largest phase current from the contact to the find; **stop's push**: the largest torque of the "
    "stop on the rotor while seeking (the impact at the higher speeds). Verdict: homing done, no fault, "
    f"|stop error| and |final error| within {BOUND_FULL_STEPS:g} full steps, the current on the stop within "
    "the stall current plus the current of the homing's acceleration; with no stop in reach, not found and "
    "holding without a fault."
)


def report_text(rows, stepdir_rows, args, argv):
    lines = [report.header("Homing without a switch", "tools/homing_sweep.py", argv, WHAT), ""]
    lines += ["## Console homing (pmstep_homing.h)", ""]
    lines.append("| " + " | ".join(COLUMNS) + " |")
    lines.append("|" + "---|" * len(COLUMNS))
    lines += [line(r, True) for r in rows]
    lines += [""] + ["- " + part for part in summary_text(rows).rstrip(".").split("; ")] + [""]
    lines += ["## Homing on DIAG over STEP/DIR (stepdir.stall_current_A)", "", STEPDIR_TEXT, ""]
    lines.append("| " + " | ".join(STEPDIR_COLUMNS) + " |")
    lines.append("|" + "---|" * len(STEPDIR_COLUMNS))
    lines += [stepdir_line(r, True) for r in stepdir_rows]
    lines += ["", stepdir_summary(stepdir_rows), ""]
    return "\n".join(lines)


STEPDIR_TEXT = (
    "The count (the SIL's step generator, trapezoids at the designer's homing speed and acceleration) "
    "runs to twice the stop's distance, then, after a dwell, back by "
    f"{STEPDIR_BACK_FULL_STEPS:g} full steps, as a motion controller homing on DIAG and backing off "
    "does; the drive's stall current is the designer's homing stall current. **DIAG after contact**: "
    "the first DIAG period less the rotor's first contact; **final error**: the rotor's true distance "
    f"from the stop less the {STEPDIR_BACK_FULL_STEPS:g} full steps of the back-off (the steps toward "
    "the stop past the stall are dropped). Verdict: every pulse counted, following to the end, DIAG at "
    f"the stop, no fault, |final error| within {BOUND_FULL_STEPS:g} full steps."
)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sil", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-sil"))
    ap.add_argument("--tune", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-tune"))
    ap.add_argument("--motors", default=",".join(MOTORS))
    ap.add_argument("--chains", default=",".join(CHAINS))
    ap.add_argument("--quick", action="store_true", help=f"speeds {QUICK_FRACTIONS} of the top and the designer's (CI)")
    ap.add_argument("--check", action="store_true", help="exit 1 if a run misses the verdict")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "homing_sweep"))
    ap.add_argument("--json", help="also write every run's figures to this file")
    ap.add_argument("--report", metavar="FILE", help="write the table as Markdown (docs/reports/homing.md)")
    args = ap.parse_args(argv[1:])
    for m in args.motors.split(","):
        if m not in MOTORS:
            ap.error(f"unknown motor '{m}' (presets: {', '.join(MOTORS)})")
    for c in args.chains.split(","):
        if c not in CHAINS:
            ap.error(f"unknown chain '{c}' (chains: {', '.join(CHAINS)})")
    os.makedirs(args.out, exist_ok=True)
    print("  ".join(COLUMNS))
    rows, stepdir_rows = sweep(args)
    print("homing_sweep: " + summary_text(rows))
    print("homing_sweep: " + stepdir_summary(stepdir_rows))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"console": rows, "stepdir": stepdir_rows}, f, indent=1)
    if args.report:
        print(f"homing_sweep: wrote {report.write(args.report, report_text(rows, stepdir_rows, args, argv))}")
    failed = [r for r in rows + stepdir_rows if r["failures"]]
    return 1 if (failed and args.check) else 0


if __name__ == "__main__":
    sys.exit(main())
