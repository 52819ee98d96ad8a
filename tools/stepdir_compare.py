#!/usr/bin/env python3
"""STEP/DIR drop-in (issue 53): pmstep following a step count against open-loop microstepping on the
same plant and the same step stream.

For each public preset (sil/scenarios/motors/*.ini) pmstep-tune designs the drive (ideal measurement
chain, the plant's detent torque on); then every motion below is planned by the SIL's step generator
(position.source = stepdir, sil/include/sil/step_generator.h) and its step count drives, in two runs of
pmstep-sil on the same scenario, the firmware (its STEP/DIR input, pmstep_stepdir.h with the designer's
settings, following the count once tracked in RUN) and the open-loop microstepping baseline at rated
current (run.controller = microstep, its electrical angle the count's). Motions, per motor (v_top: the
design's top speed; a_ref = k_M I / J, the rated torque's acceleration of the bare rotor;
A_AXIS = 1000 rad/s^2, a printer axis's acceleration: 6400 mm/s^2 on a 40 mm belt pulley's turn):

  moves       S-curves (jerk: the acceleration reached in 20 ms) at v_max = 1/2 v_top, a_max = min(a_ref / 4,
              A_AXIS): forward 2 revolutions, a dwell, back 3 (a reversal through the start), a dwell, a
              short move of 1/8 revolution, back to the start.
  low-speed   trapezoids at v_max = v_top / 50, a_max = min(a_ref / 20, A_AXIS): moves of 2, 8 and 20 full
              steps forward and back (reversals) with standstill dwells of 0.4 s between them.
  high-rate   256 microsteps, trapezoids at v_max = 0.8 v_top, a_max = A_AXIS (at most a_ref / 4): 5
              revolutions forward and back (the 16-bit counter wraps many times).
  aggressive  reported, not checked: trapezoids at v_max = 1/2 v_top and a_max = a_ref / 4 (jerk not
              limited), 16 microsteps whatever the motor: the moves of 'moves'. Beyond what the firmware's
              follower is designed for (it sees the steps only as they come: no look-ahead), it shows
              where its following error and DIAG go.

Microsteps of moves and low-speed: 16, or more on a motor whose microstep is coarse for the drive: the
staircase of the count moves the tracker's speed by about q w_t per microstep q (w_t = varpi_0, the
designer's), which the stall detection compares with its bound (controller.detection.stall_speed_error_rad_s);
the smallest power of two m >= 16 with q w_t at most that bound (the paper motor's p = 6: 256).

Both drives start from the same rotor angle, 30 electrical degrees off an equilibrium of the
alignment (run.theta0_deg = 30 / p: the paper scenario's 30 mechanical degrees sit on an unstable
equilibrium of the paper motor's p = 6, where an open-loop hold never pulls in). The figures are the
summary's "stepdir" (sil/include/sil/metrics.h): the following error is the count's position less the
plant's true position from the equilibrium count 0 is measured from, in full steps pi / (2 p);
"moving" is while the generator's move runs; lost full steps is the final error rounded; the RMS phase
current is over the same window for both drives (from the first move to the end); DIAG is the
firmware's output (following error beyond one full step of its own estimate, or a fault).

Largest load step survived during a move, per preset and drive: the first move of 'moves' (2
revolutions forward from rest, its S-curve and microsteps, whatever --quick) with the SIL's load step
(load.type = step) at the middle of the move, the middle of its cruise, held to the end of the run
(TAIL_S at rest after the move). load.torque_Nm > 0: the plant's load torque T_L in
J dw/dt = T_e - F w - T_L opposes the forward move. Survived, the same for both drives: no step lost
at the end (|final error| < 1/2 full step), still following the count to the end (the firmware did
not leave RUN; the baseline always follows), no fault (pmstep; the baseline has none). DIAG during
the step is reported for pmstep, not counted: the baseline has no DIAG. Bisection on
[0, LOAD_BOUND x the datasheet holding torque], after a run at each end: LOAD_ITERATIONS halvings
(LOAD_ITERATIONS_QUICK with --quick; --load-iterations N, 0 for none), the searches of the motors and
drives --jobs at a time (threads, each running pmstep-sil). Both drives' brackets are the same for a
motor, so their figures lie on one grid.

--check exits 1 when a pmstep run of a checked case loses a step (final error rounds to a full step, or
the count it read differs from the generator's), asserts DIAG, faults, or stops following the count:
every run here is fault-free; or when on a preset pmstep survives a smaller load step than the
baseline. The baseline's losses are reported, not checked. --quick: shorter motions, no aggressive
case and a coarse load search, for CI. --report FILE writes the tables as Markdown (command, commit
and date at the top; tools/report.py) and a plot of the following error against time for both drives
on one preset (--plot-motor, --plot-case) beside it. --json FILE: {"runs": [...], "load_steps": [...]}.

usage: tools/stepdir_compare.py --sil PATH --tune PATH [--motors paper,17hs4401,bj42d29,as1050]
                                [--cases moves,low-speed,high-rate,aggressive] [--quick] [--check]
                                [--load-iterations 9] [--jobs 2]
                                [--out DIR] [--json FILE] [--report docs/reports/step-dir.md]
                                [--plot-motor 17hs4401] [--plot-case moves]
"""

import argparse
import concurrent.futures
import configparser
import csv
import json
import math
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report  # noqa: E402
from mc_preset import tune_top_speed  # noqa: E402
from position_acceptance import read_preset  # noqa: E402  (the preset's rated current, k_M, J, p)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MOTORS = ["paper", "17hs4401", "bj42d29", "as1050"]
CASES = ["moves", "low-speed", "high-rate", "aggressive"]
CHECKED = ["moves", "low-speed", "high-rate"]
DRIVES = ["pmstep", "microstep"]
REVOLUTION = 2.0 * math.pi
LEAD_S = 0.1  # from RUN's start to the first move
TAIL_S = 0.4  # after the last move's end, at rest, to the end of the run
THETA0_ELECTRICAL_DEG = 30.0
JERK_TIME_S = 0.02  # the moves case's S-curve: the acceleration reached in 20 ms
A_AXIS = 1000.0  # rad/s^2: a printer axis (6400 mm/s^2 on a 40 mm pulley's turn)
LOAD_BOUND = 1.5  # the load search's bracket: [0, 1.5 x the datasheet holding torque]
LOAD_ITERATIONS = 9  # its halvings: 1.5 T_H / 512, 0.3 % of the holding torque
LOAD_ITERATIONS_QUICK = 4  # --quick: 1.5 T_H / 16, 9.4 % of it


def design(tune, motor_ini, ini_out, robust=False, sets=()):
    """pmstep-tune's design of the preset into @p ini_out (--robust and the --set items when given); returns
    its top speed, RUN's start, varpi_0 (the tracker's w_t) and the stall detection's bound."""
    cmd = [tune, "--motor", motor_ini, "--write-ini", ini_out] + (["--robust"] if robust else [])
    for item in sets:
        cmd += ["--set", item]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    top = tune_top_speed(out)
    ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
    ini.read(ini_out)
    run_start = float(ini["controller.commissioning"]["offset_calibration_time_s"]) + float(
        ini["controller.alignment"]["c_align_time_s"]
    )
    return (
        top,
        run_start,
        float(ini["controller.gains"]["reference_bandwidth_rad_s"]),
        float(ini["controller.detection"]["stall_speed_error_rad_s"]),
    )


def microsteps_for(preset, tracking_rad_s, stall_rad_s):
    """The smallest power of two m >= 16 whose microstep q = 2 pi / (4 p m) moves the tracker's speed by
    q w_t at most the stall bound."""
    m = 16
    while m < 256 and 2.0 * math.pi / (4.0 * preset["p"] * m) * tracking_rad_s > stall_rad_s:
        m *= 2
    return m


def speed_up_s(v, a, j):
    """A speed change from rest to @p v (sil/src/step_generator.c's speed_up_s)."""
    if j <= 0.0:
        return v / a
    if v >= a * a / j:
        return v / a + a / j
    return 2.0 * math.sqrt(v / j)


def move_time(distance, v, a, j):
    """The step generator's time of a move from rest to rest (sil/include/sil/step_generator.h)."""
    if distance <= 0.0:
        return 0.0
    if v * speed_up_s(v, a, j) <= distance:
        return 2.0 * speed_up_s(v, a, j) + (distance - v * speed_up_s(v, a, j)) / v
    lo, hi = 0.0, v
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * speed_up_s(mid, a, j) <= distance else (lo, mid)
    return 2.0 * speed_up_s(lo, a, j)


def motion(case, preset, design_figures, quick):
    """The case's moves for a motor: microsteps, v, a, j and the targets (mechanical rad) with the dwell
    after each (s)."""
    top, _, tracking_rad_s, stall_rad_s = design_figures
    full_step = math.pi / (2.0 * preset["p"])
    a_ref = preset["k_M"] * preset["rated_A"] / preset["J"]
    microsteps = microsteps_for(preset, tracking_rad_s, stall_rad_s)
    moves = [2.0 * REVOLUTION, -REVOLUTION, -REVOLUTION + REVOLUTION / 8.0, 0.0]
    if quick:
        moves = [REVOLUTION, -0.5 * REVOLUTION, 0.0]
    if case == "moves":
        a = min(0.25 * a_ref, A_AXIS)
        return {
            "microsteps": microsteps,
            "v": 0.5 * top,
            "a": a,
            "j": a / JERK_TIME_S,
            "targets": moves,
            "dwell_s": 0.3,
        }
    if case == "low-speed":
        steps = [2, 0, 8, -8, 20, 0] if not quick else [2, 0, 8, 0]
        return {
            "microsteps": microsteps,
            "v": top / 50.0,
            "a": min(a_ref / 20.0, A_AXIS),
            "j": 0.0,
            "targets": [s * full_step for s in steps],
            "dwell_s": 0.4 if not quick else 0.25,
        }
    if case == "high-rate":
        turns = 5.0 if not quick else 2.0
        return {
            "microsteps": 256,
            "v": 0.8 * top,
            "a": min(0.25 * a_ref, A_AXIS),
            "j": 0.0,
            "targets": [turns * REVOLUTION, 0.0],
            "dwell_s": 0.2,
        }
    if case == "aggressive":
        return {"microsteps": 16, "v": 0.5 * top, "a": 0.25 * a_ref, "j": 0.0, "targets": moves, "dwell_s": 0.3}
    raise ValueError(case)


def schedule(m, start_s):
    """position.points for the moves of @p m from @p start_s, each after the one before and its dwell;
    returns the points and the last move's end."""
    t, position, points = start_s, 0.0, []
    for target in m["targets"]:
        points.append((t, target))
        t += move_time(abs(target - position), m["v"], m["a"], m["j"])
        position = target
        end = t
        t += m["dwell_s"]
    return points, end


def run_sil(sil, scenario, sets, out_dir, with_csv=False):
    cmd = [sil, "--quiet", "--out", out_dir, "--scenario", scenario] + ([] if with_csv else ["--no-csv"])
    for s in sets:
        cmd += ["--set", s]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    path = os.path.join(out_dir, "summary.json")
    if proc.returncode not in (0, 3, 4) or not os.path.isfile(path):
        raise RuntimeError(f"pmstep-sil failed ({proc.returncode}): {proc.stderr.strip()}")
    with open(path) as f:
        return proc.returncode, json.load(f)


def verdict(row):
    """The pmstep run's failures (--check); [] when it kept every step without DIAG or a fault."""
    d = row["stepdir"]
    failures = []
    if row["fault"] != "NONE":
        failures.append("fault " + row["fault"])
    if d["following_start_s"] < 0.0 or d["following_end_s"] >= 0.0:
        failures.append("not following the count to the end")
    if d["lost_full_steps"] != 0:
        failures.append(f"{d['lost_full_steps']} full steps lost")
    if d["drive_steps"] != d["generator_steps"]:
        failures.append(f"counted {d['drive_steps']} of {d['generator_steps']} microsteps")
    if d["diag_periods"] > 0:
        failures.append(f"DIAG at {d['diag_first_s']:.4f} s")
    return failures


def compare(args, motor, case, work):
    motor_ini = os.path.join(ROOT, "sil", "scenarios", "motors", f"{motor}.ini")
    preset = read_preset(motor_ini)
    base = os.path.join(work, f"{motor}.ini")
    if motor not in args.designs:
        args.designs[motor] = design(args.tune, motor_ini, base)
    run_start = args.designs[motor][1]
    m = motion(case, preset, args.designs[motor], args.quick)
    points, end_s = schedule(m, run_start + LEAD_S)
    q = 2.0 * math.pi / (4.0 * preset["p"] * m["microsteps"])
    sets = [
        "speed.points=0:0",
        "load.type=none",
        "position.source=stepdir",
        f"stepdir.microsteps={m['microsteps']}",
        "position.points=" + ", ".join(f"{t:.6f}:{x:.9g}" for t, x in points),
        f"position.v_max_rad_s={m['v']:.9g}",
        f"position.a_max_rad_s2={m['a']:.9g}",
        f"position.j_max_rad_s3={m['j']:.9g}",
        f"run.duration_s={end_s + TAIL_S:.6f}",
        f"run.theta0_deg={THETA0_ELECTRICAL_DEG / preset['p']:.9g}",
        f"run.metrics_start_s={points[0][0]:.6f}",
        f"run.decimation={args.decimation}",
    ]
    plotted = motor == args.plot_motor and case == args.plot_case
    rows = []
    for drive in DRIVES:
        out_dir = os.path.join(work, f"{motor}_{case}_{drive}")
        rc, s = run_sil(args.sil, base, sets + [f"run.controller={drive}"], out_dir, plotted)
        row = {
            "motor": motor,
            "case": case,
            "drive": drive,
            "exit_status": rc,
            "fault": s["fault"]["name"],
            "microsteps": m["microsteps"],
            "v_max_rad_s": m["v"],
            "a_max_rad_s2": m["a"],
            "j_max_rad_s3": m["j"],
            "step_rate_hz": m["v"] / q,
            "moves": len(points),
            "duration_s": end_s + TAIL_S,
            "rms_phase_current_A": s["rms_phase_current_A"],
            "loss_of_synchronism": s["loss_of_synchronism"],
            "stepdir": s["stepdir"],
            "csv": os.path.join(out_dir, "run.csv") if plotted else None,
        }
        row["checked"] = drive == "pmstep" and case in CHECKED
        row["failures"] = verdict(row) if row["checked"] else []
        row["notes"] = verdict(row) if drive == "pmstep" and not row["checked"] else []
        rows.append(row)
    return rows


def designed(args, motor, work):
    """The preset's figures, its datasheet holding torque and pmstep-tune's design of it (once per motor)."""
    motor_ini = os.path.join(ROOT, "sil", "scenarios", "motors", f"{motor}.ini")
    base = os.path.join(work, f"{motor}.ini")
    if motor not in args.designs:
        args.designs[motor] = design(args.tune, motor_ini, base)
    ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
    ini.read(motor_ini)
    return read_preset(motor_ini), float(ini["datasheet"]["holding_torque_Nm"]), base


def load_move(preset, design_figures):
    """The load search's move: the first of 'moves' (2 revolutions forward from rest at the count's 0, its
    v, a, j and microsteps), from RUN's start + LEAD_S; the load steps up at the middle of the move, which is
    the middle of its cruise when it has one (the S-curve is symmetric)."""
    m = motion("moves", preset, design_figures, False)
    distance = m["targets"][0]
    start = design_figures[1] + LEAD_S
    duration = move_time(distance, m["v"], m["a"], m["j"])
    up = speed_up_s(m["v"], m["a"], m["j"])
    cruise = (start + up, start + duration - up) if m["v"] * up <= distance else None
    return dict(
        m, distance=distance, start_s=start, end_s=start + duration, step_s=start + 0.5 * duration, cruise=cruise
    )


def load_failures(s):
    """Why a load-step run did not survive; [] when it did: no fault, following the count to the end (the
    firmware; the baseline always follows) and no step lost, |final error| < 1/2 full step. DIAG is not a
    failure."""
    d = s["stepdir"]
    why = []
    if s["fault"]["name"] != "NONE":
        why.append("fault " + s["fault"]["name"])
    if d["following_start_s"] < 0.0 or d["following_end_s"] >= 0.0:
        why.append("not following the count to the end")
    if abs(d["final_error_full_steps"]) >= 0.5:
        why.append(f"{d['final_error_full_steps']:+.0f} full steps lost")
    return why


def load_run(args, motor, drive, torque_Nm, work):
    """One run of the load search's move with a load step of @p torque_Nm (> 0 opposes the forward move)
    held to the end; returns the summary and its load_failures()."""
    preset, _, base = designed(args, motor, work)
    lm = load_move(preset, args.designs[motor])
    sets = [
        "speed.points=0:0",
        "position.source=stepdir",
        f"stepdir.microsteps={lm['microsteps']}",
        f"position.points={lm['start_s']:.6f}:{lm['distance']:.9g}",
        f"position.v_max_rad_s={lm['v']:.9g}",
        f"position.a_max_rad_s2={lm['a']:.9g}",
        f"position.j_max_rad_s3={lm['j']:.9g}",
        f"run.duration_s={lm['end_s'] + TAIL_S:.6f}",
        f"run.theta0_deg={THETA0_ELECTRICAL_DEG / preset['p']:.9g}",
        f"run.metrics_start_s={lm['start_s']:.6f}",
        "load.type=step",
        f"load.torque_Nm={torque_Nm:.9g}",
        f"load.step_time_s={lm['step_s']:.6f}",
        f"run.controller={drive}",
    ]
    out_dir = os.path.join(work, f"{motor}_load-step_{drive}")
    if os.path.isfile(os.path.join(out_dir, "summary.json")):
        os.remove(os.path.join(out_dir, "summary.json"))
    _, s = run_sil(args.sil, base, sets, out_dir, False)
    return s, load_failures(s)


def load_search(args, motor, drive, iterations, work):
    """The largest load step (N m) @p drive survives during the load search's move, by bisection on
    [0, LOAD_BOUND x the holding torque] after a run at each bound: @p iterations halvings of the bracket. The
    figures of the run at the largest survived load and the first failure above it."""
    preset, holding, base = designed(args, motor, work)
    lm = load_move(preset, args.designs[motor])
    limits = configparser.ConfigParser(inline_comment_prefixes=(";",))
    limits.read(base)
    runs = {}

    def survives(torque):
        runs[torque] = load_run(args, motor, drive, torque, work)
        return not runs[torque][1]

    lo, hi = 0.0, LOAD_BOUND * holding
    if not survives(lo):
        lo, hi = None, lo
    elif survives(hi):
        lo, hi = hi, None
    else:
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if survives(mid) else (lo, mid)
    row = {
        "motor": motor,
        "drive": drive,
        "holding_torque_Nm": holding,
        "k_M_rated_Nm": preset["k_M"] * preset["rated_A"],
        "microsteps": lm["microsteps"],
        "v_max_rad_s": lm["v"],
        "a_max_rad_s2": lm["a"],
        "j_max_rad_s3": lm["j"],
        "move_rad": lm["distance"],
        "move_start_s": lm["start_s"],
        "move_end_s": lm["end_s"],
        "step_time_s": lm["step_s"],
        "cruise_s": lm["cruise"],
        "hold_s": TAIL_S,
        "bound_Nm": LOAD_BOUND * holding,
        "iterations": iterations,
        "runs": len(runs),
        "resolution_Nm": LOAD_BOUND * holding / 2**iterations,
        "overcurrent_trip_A": float(limits["controller.limits"]["max_phase_current_A"]) if drive == "pmstep" else None,
        "survived_Nm": lo,
        "failed_Nm": hi,
        "failed_why": runs[hi][1] if hi is not None else [],
    }
    row["survived_fraction"] = None if lo is None else lo / holding
    if lo is not None:
        s = runs[lo][0]
        d = s["stepdir"]
        row.update(
            {
                "max_error_full_steps": d["max_error_full_steps"],
                "final_error_full_steps": d["final_error_full_steps"],
                "diag_periods": d["diag_periods"],
                "diag_first_s": d["diag_first_s"],
                "rms_phase_current_A": s["rms_phase_current_A"],
                "peak_phase_current_a_A": s["max_abs_phase_current_a"],
            }
        )
    return row


def load_searches(args, work):
    """load_search() of every motor and drive, two at a time (args.jobs); rows in motor, drive order."""
    for motor in args.motors.split(","):
        designed(args, motor, work)  # the designs before the threads
    jobs = [(motor, drive) for motor in args.motors.split(",") for drive in DRIVES]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(load_search, args, motor, drive, args.load_iterations, work) for motor, drive in jobs]
        return [f.result() for f in futures]


def load_ratio(loads, motor):
    """pmstep's largest survived load step over microstepping's on @p motor (None without both)."""
    pm = [r["survived_Nm"] for r in loads if r["motor"] == motor and r["drive"] == "pmstep"]
    ms = [r["survived_Nm"] for r in loads if r["motor"] == motor and r["drive"] == "microstep"]
    if not pm or not ms or pm[0] is None or ms[0] is None or ms[0] <= 0.0:
        return None
    return pm[0] / ms[0]


def load_check(loads):
    """--check on the load search: pmstep survives at least the load step microstepping survives, per preset
    (both found on the same grid of the same bracket)."""
    failures = []
    for motor in dict.fromkeys(r["motor"] for r in loads):
        by = {r["drive"]: r["survived_Nm"] for r in loads if r["motor"] == motor}
        pm, ms = by.get("pmstep"), by.get("microstep")
        if pm is None or (ms is not None and pm < ms):
            failures.append(
                f"{motor}: pmstep survives a load step of {pm if pm is not None else 'no'} N m, microstepping {ms} N m"
            )
    return failures


def _f(x, spec=".3f"):
    return format(x, spec)


def table(rows, markdown):
    head = [
        "motor",
        "case",
        "drive",
        "µsteps",
        "step rate",
        "max err moving",
        "RMS moving",
        "max err",
        "RMS err",
        "final",
        "lost",
        "RMS current",
        "DIAG periods (first)",
        "verdict",
    ]
    out = []
    if markdown:
        out += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    else:
        out.append(
            f"{'motor':9s} {'case':10s} {'drive':9s} {'usteps':>6s} {'rate kHz':>8s} {'maxmov':>7s} "
            f"{'rmsmov':>7s} {'max':>7s} {'rms':>7s} {'final':>7s} {'lost':>4s} {'I_rms A':>7s} "
            f"{'DIAG':>12s}  verdict"
        )
    for r in rows:
        d = r["stepdir"]
        diag = (
            "-"
            if r["drive"] == "microstep"
            else (f"{d['diag_periods']} ({d['diag_first_s']:.3f} s)" if d["diag_periods"] > 0 else "0")
        )
        if r["drive"] == "microstep":
            ok = "-"
        elif not r["checked"]:
            ok = "not checked" + (": " + "; ".join(r["notes"]) if r["notes"] else "")
        else:
            ok = "met" if not r["failures"] else "FAILED: " + "; ".join(r["failures"])
        if markdown:
            out.append(
                "| "
                + " | ".join(
                    [
                        r["motor"],
                        r["case"],
                        r["drive"],
                        str(r["microsteps"]),
                        f"{r['step_rate_hz'] / 1e3:.1f} kHz",
                        _f(d["max_error_moving_full_steps"]),
                        _f(d["rms_error_moving_full_steps"]),
                        _f(d["max_error_full_steps"]),
                        _f(d["rms_error_full_steps"]),
                        _f(d["final_error_full_steps"], "+.3f"),
                        str(d["lost_full_steps"]),
                        f"{r['rms_phase_current_A']:.3f} A",
                        diag,
                        "**" + ok + "**" if ok.startswith("FAILED") else ok,
                    ]
                )
                + " |"
            )
        else:
            out.append(
                f"{r['motor']:9s} {r['case']:10s} {r['drive']:9s} {r['microsteps']:6d} "
                f"{r['step_rate_hz'] / 1e3:8.1f} {d['max_error_moving_full_steps']:7.3f} "
                f"{d['rms_error_moving_full_steps']:7.3f} {d['max_error_full_steps']:7.3f} "
                f"{d['rms_error_full_steps']:7.3f} {d['final_error_full_steps']:+7.3f} {d['lost_full_steps']:4d} "
                f"{r['rms_phase_current_A']:7.3f} {diag:>12s}  {ok}"
            )
    return "\n".join(out)


def load_table(loads, markdown):
    """The load search's figures, a row per motor and drive."""
    head = [
        "motor",
        "drive",
        "holding torque",
        "load step at",
        "largest load step survived",
        "× holding torque",
        "first failure above",
        "max err",
        "final err",
        "DIAG",
        "RMS current",
        "peak i_a",
        "pmstep / microstepping",
    ]
    out = []
    if markdown:
        out += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    else:
        out.append(
            f"{'motor':9s} {'drive':9s} {'T_H Nm':>7s} {'step s':>7s} {'survived':>9s} {'x T_H':>6s} "
            f"{'fails at':>9s} {'maxerr':>7s} {'final':>7s} {'DIAG':>5s} {'I_rms A':>7s} {'peak ia':>7s} "
            f"{'ratio':>6s}  first failure"
        )
    for r in loads:
        lo, hi = r["survived_Nm"], r["failed_Nm"]
        ratio = load_ratio(loads, r["motor"]) if r["drive"] == "pmstep" else None
        diag = (
            "-"
            if r["drive"] == "microstep" or lo is None
            else (f"yes ({r['diag_first_s']:.3f} s)" if r["diag_periods"] > 0 else "no")
        )
        why = "; ".join(r["failed_why"])
        if markdown:
            at = f"{r['step_time_s']:.3f} s" + (
                f" (cruise {r['cruise_s'][0]:.3f}–{r['cruise_s'][1]:.3f} s)" if r["cruise_s"] else " (no cruise)"
            )
            peak = (
                "-"
                if lo is None
                else f"{r['peak_phase_current_a_A']:.2f} A"
                + (f" (trip {r['overcurrent_trip_A']:g} A)" if r["overcurrent_trip_A"] else "")
            )
            out.append(
                "| "
                + " | ".join(
                    [
                        r["motor"],
                        r["drive"],
                        f"{r['holding_torque_Nm']:.4g} N·m",
                        at,
                        "none" if lo is None else (f"≥ {lo:.4g} N·m" if hi is None else f"{lo:.4g} N·m"),
                        "-" if lo is None else f"{r['survived_fraction']:.3f}",
                        "-" if hi is None else f"{hi:.4g} N·m: {why}",
                        "-" if lo is None else _f(r["max_error_full_steps"]),
                        "-" if lo is None else _f(r["final_error_full_steps"], "+.3f"),
                        diag,
                        "-" if lo is None else f"{r['rms_phase_current_A']:.3f} A",
                        peak,
                        "-" if ratio is None else f"{ratio:.2f}",
                    ]
                )
                + " |"
            )
        else:
            out.append(
                f"{r['motor']:9s} {r['drive']:9s} {r['holding_torque_Nm']:7.4g} {r['step_time_s']:7.3f} "
                + (f"{'none':>9s} {'-':>6s} " if lo is None else f"{lo:9.4g} {r['survived_fraction']:6.3f} ")
                + (f"{'-':>9s} " if hi is None else f"{hi:9.4g} ")
                + (
                    f"{'-':>7s} {'-':>7s} {'-':>5s} {'-':>7s} {'-':>7s} "
                    if lo is None
                    else f"{r['max_error_full_steps']:7.3f} {r['final_error_full_steps']:+7.3f} "
                    f"{'-' if r['drive'] == 'microstep' else ('yes' if r['diag_periods'] > 0 else 'no'):>5s} "
                    f"{r['rms_phase_current_A']:7.3f} {r['peak_phase_current_a_A']:7.3f} "
                )
                + (f"{'-':>6s}" if ratio is None else f"{ratio:6.2f}")
                + f"  {why}"
            )
    return "\n".join(out)


def load_summary(loads):
    """One sentence of the load search: the fractions of the holding torque per drive, the ratios."""
    if not loads:
        return ""
    parts = []
    for drive, name in (("pmstep", "pmstep"), ("microstep", "open-loop microstepping")):
        fr = [r["survived_fraction"] for r in loads if r["drive"] == drive and r["survived_fraction"] is not None]
        if fr:
            parts.append(f"{name} {min(fr):.2f}–{max(fr):.2f}")
    motors = list(dict.fromkeys(r["motor"] for r in loads))
    ratios = [x for x in (load_ratio(loads, m) for m in motors) if x is not None]
    text = (
        "Largest load step survived during a move, as a fraction of the datasheet holding torque: "
        + ", ".join(parts)
        + "."
    )
    if ratios:
        text += (
            f" pmstep survives at least microstepping's load step on {len(motors) - len(load_check(loads))} of "
            f"{len(motors)} presets; pmstep / microstepping {min(ratios):.2f}–{max(ratios):.2f}."
        )
    return text


def plot(rows, path, motor, case):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("stepdir_compare: matplotlib not installed, no plot", file=sys.stderr)
        return None
    series = {}
    for r in rows:
        if r["csv"] and os.path.isfile(r["csv"]):
            t, e = [], []
            with open(r["csv"]) as f:
                for line in csv.DictReader(f):
                    t.append(float(line["t_s"]))
                    e.append(float(line["step_error_full_steps"]))
            series[r["drive"]] = (t, e)
    if not series:
        return None
    fig, ax = plt.subplots(figsize=(10, 4))
    labels = {
        "pmstep": "pmstep (sensorless, following the count)",
        "microstep": "open-loop microstepping, rated current",
    }
    for drive, (t, e) in series.items():
        ax.plot(t, e, label=labels[drive], linewidth=0.9)
    ax.axhline(1.0, color="grey", linestyle=":", linewidth=0.8)
    ax.axhline(-1.0, color="grey", linestyle=":", linewidth=0.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("following error: count - rotor (full steps)")
    ax.set_title(f"{motor}, motion '{case}': the same step stream into both drives")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"stepdir_compare: wrote {path}")
    return path


def summary_text(rows):
    """One paragraph of the figures: the checked cases' verdicts, the largest errors of both drives."""
    pm = [r for r in rows if r["checked"]]
    parts = [f"pmstep, checked cases: {sum(1 for r in pm if not r['failures'])} of {len(pm)} runs met the verdict"]
    for drive, name in (("pmstep", "pmstep"), ("microstep", "open-loop microstepping")):
        for checked in (True, False):
            rs = [r for r in rows if r["drive"] == drive and (r["case"] in CHECKED) == checked]
            if rs:
                lost = sum(1 for r in rs if r["stepdir"]["lost_full_steps"] != 0)
                diag = sum(1 for r in rs if r["stepdir"]["diag_periods"] > 0)
                parts.append(
                    f"{name}, {'checked cases' if checked else 'aggressive case'}: largest following error "
                    f"{max(r['stepdir']['max_error_full_steps'] for r in rs):.3f} full steps, "
                    f"{lost} of {len(rs)} runs with steps lost" + (f", {diag} with DIAG" if drive == "pmstep" else "")
                )
    return "; ".join(parts) + "."


def load_text(loads):
    """The load search's section of the report: what was run, the table, the summary's sentence."""
    iterations = loads[0]["iterations"]
    quadrature = all(
        abs(r["holding_torque_Nm"] - math.sqrt(2.0) * r["k_M_rated_Nm"]) <= 0.01 * r["holding_torque_Nm"] for r in loads
    )
    what = (
        "Per preset and drive, the largest load torque step the drive survives during a move, found by bisection. "
        "The move is the first of **moves**: 2 revolutions forward from rest, S-curve at ½ the top speed and "
        f"min(¼ k_M I / J, {A_AXIS:g} rad/s²), the acceleration reached in {JERK_TIME_S * 1e3:g} ms, the same "
        "microsteps. The SIL's `load.type = step` steps the load torque up at the middle of the move (the middle of "
        'its cruise; column "load step at") and holds it to the end of the run, '
        f"{TAIL_S:g} s at rest after the move: the drive carries it while finishing the move and holding. "
        "`load.torque_Nm` is positive, which opposes the forward move (the plant's J dω/dt = T_e − F ω − T_L, "
        "T_L the load). "
        "**Survived**, the same for both drives: no step lost at the end (|final error| < ½ full step, the final "
        "error rounded to full steps is 0) and the drive still following the count to the end of the run (the "
        "firmware did not leave RUN; the baseline always follows), and for pmstep no fault. DIAG may assert during "
        "the step; it is reported for pmstep at its largest survived load but not counted as a failure, since "
        "open-loop microstepping has no DIAG. "
        f"Bisection on [0, {LOAD_BOUND:g} × the holding torque], after a run at each end, {iterations} halvings: "
        f"resolution {LOAD_BOUND:g} / {2**iterations} = {LOAD_BOUND / 2**iterations * 100:.2g} % of the holding "
        "torque (it assumes survival falls off once with the load). "
        "Holding torque: the preset's datasheet `holding_torque_Nm` (both phases at rated current"
        + (", √2 k_M I on these presets" if quadrature else "")
        + "). "
        "The figures of the run at the largest survived load: max and final following error (full steps, count − "
        "rotor), the RMS phase current from the move's start to the end, the peak of phase a's current. "
        "Currents differ: open-loop microstepping drives a sine of rated amplitude whatever the load, so its "
        "torque is at most k_M I (= holding / √2), and with the load held to the end its static lag counts in the "
        "final error: < ½ full step at rest allows k_M I sin 45° (½ × holding where holding = √2 k_M I) at most. "
        "pmstep's current follows the load up to the overcurrent trip of its design "
        '(`controller.limits.max_phase_current_A`, given in the column "peak i_a"); a larger load faults it '
        '(column "first failure above").'
    )
    return [
        "## Largest load step survived during a move",
        "",
        what,
        "",
        load_table(loads, True),
        "",
        load_summary(loads),
        "",
    ]


def report_text(rows, args, argv, picture, loads):
    what = (
        "Per public preset, pmstep-tune's design (ideal measurement chain, the plant's detent torque on) and "
        "the step streams below from the SIL's step generator (`position.source = stepdir`), each into the firmware "
        "following the count (`pmstep_stepdir.h`, the designer's tracker and DIAG limit of one full step) and "
        "into open-loop microstepping at rated current (`run.controller = microstep`) on the same plant: "
        f"**moves** (S-curves at ½ the top speed and min(¼ k_M I / J, {A_AXIS:g} rad/s²), reversals, dwells), "
        f"**low-speed** (trapezoids at 1/50 of the top speed over 2 to 20 full steps, reversals and standstill "
        f"dwells), **high-rate** (256 µsteps, trapezoids at 0.8 × the top speed and min(¼ k_M I / J, {A_AXIS:g} "
        "rad/s²), several revolutions and back) and, not checked, **aggressive** (16 µsteps, trapezoids at ½ the "
        "top speed and ¼ k_M I / J, no jerk limit: beyond what a follower that sees the steps only as they come "
        "is designed for). Microsteps of moves and low-speed: 16, or the smallest power of two whose microstep "
        "moves the tracker's speed by at most the stall detection's bound (the paper motor, p = 6: 256). "
        "Errors in full steps (π / 2p): the count's position less the rotor's true position, \"moving\" while a "
        "move runs; lost = the final error rounded; the RMS phase current from the first move to the end; "
        "DIAG periods of the firmware's output. Both drives start 30 electrical degrees off an equilibrium. "
        "Verdict (pmstep, checked cases, `--check`): no step lost, every pulse counted, no DIAG, no fault, "
        "following to the "
        "end." + (" Shorter motions (`--quick`)." if args.quick else "")
    )
    lines = [
        report.header("STEP/DIR: pmstep against open-loop microstepping", "tools/stepdir_compare.py", argv, what),
        table(rows, True),
        "",
    ]
    lines.append(summary_text(rows) + (" " + load_summary(loads) if loads else ""))
    lines.append("")
    if picture:
        lines += [
            f"![Following error against time, {args.plot_motor}, motion {args.plot_case}, both drives]({picture})",
            "",
        ]
    if loads:
        lines += load_text(loads)
    return "\n".join(lines)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sil", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-sil"))
    ap.add_argument("--tune", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-tune"))
    ap.add_argument("--motors", default=",".join(MOTORS))
    ap.add_argument("--cases", help=f"default: {','.join(CASES)} ({','.join(CHECKED)} with --quick)")
    ap.add_argument("--quick", action="store_true", help="shorter motions (CI)")
    ap.add_argument("--check", action="store_true", help="exit 1 if a pmstep run loses a step, asserts DIAG or faults")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "stepdir_compare"))
    ap.add_argument("--decimation", type=int, default=10, help="CSV row stride of the plotted runs (periods)")
    ap.add_argument("--json", help="also write every run's figures to this file")
    ap.add_argument(
        "--report", metavar="FILE", help="write the table as Markdown (docs/reports/step-dir.md), the plot beside it"
    )
    ap.add_argument("--plot-motor", default="17hs4401")
    ap.add_argument("--plot-case", default="moves")
    ap.add_argument(
        "--load-iterations",
        type=int,
        help=f"halvings of the load-step search (default {LOAD_ITERATIONS}, {LOAD_ITERATIONS_QUICK} with "
        "--quick); 0: no search",
    )
    ap.add_argument("--jobs", type=int, default=2, help="load searches run at once (threads, each a pmstep-sil)")
    args = ap.parse_args(argv[1:])
    if args.cases is None:
        args.cases = ",".join(CHECKED if args.quick else CASES)
    if args.load_iterations is None:
        args.load_iterations = LOAD_ITERATIONS_QUICK if args.quick else LOAD_ITERATIONS
    for c in args.cases.split(","):
        if c not in CASES:
            ap.error(f"unknown case '{c}' (cases: {', '.join(CASES)})")
    for m in args.motors.split(","):
        if not os.path.isfile(os.path.join(ROOT, "sil", "scenarios", "motors", f"{m}.ini")):
            ap.error(f"unknown motor '{m}' (presets: {', '.join(MOTORS)})")
    os.makedirs(args.out, exist_ok=True)
    args.designs = {}
    rows = []
    print(table([], False))
    for motor in args.motors.split(","):
        for case in args.cases.split(","):
            new = compare(args, motor, case, args.out)
            rows += new
            for line in table(new, False).split("\n")[1:]:
                print(line)
            sys.stdout.flush()
    failed = [r for r in rows if r["failures"]]
    print("units: full steps (pi / 2p mechanical rad), count - rotor; step rate at v_max; verdict for pmstep only")
    print("stepdir_compare: " + summary_text(rows))
    loads = []
    if args.load_iterations > 0:
        loads = load_searches(args, args.out)
        print("largest load step survived during a move (N m; x T_H: of the datasheet holding torque); the run at it:")
        print(load_table(loads, False))
        print("stepdir_compare: " + load_summary(loads))
        for failure in load_check(loads):
            print("stepdir_compare: load step: " + failure)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"runs": rows, "load_steps": loads}, f, indent=1)
    png = os.path.join(args.out, "step-dir.png")
    plotted = plot(rows, png, args.plot_motor, args.plot_case)
    if args.report:
        picture = None
        if plotted:
            picture = os.path.splitext(args.report)[0] + ".png"
            os.makedirs(os.path.dirname(os.path.abspath(picture)), exist_ok=True)
            if os.path.abspath(picture) != os.path.abspath(png):
                shutil.copyfile(png, picture)
        text = report_text(rows, args, argv, os.path.basename(picture) if picture else None, loads)
        print(f"stepdir_compare: wrote {report.write(args.report, text)}")
    return 1 if ((failed or load_check(loads)) and args.check) else 0


if __name__ == "__main__":
    sys.exit(main())
