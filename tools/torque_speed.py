#!/usr/bin/env python3
"""The torque-speed curve, measured: the largest constant load torque pmstep (speed mode, with and without
field weakening) and open-loop microstepping at rated current hold at a set of speeds, per public preset and bus
voltage.

For each public preset (sil/scenarios/motors/*.ini) and bus voltage (run.bus_voltage_V: 12, 24, 48 V)
pmstep-tune designs the drive for that bus (--set run.bus_voltage_V=V); a preset the designer refuses at a
bus is recorded as "no design". At SPEED_FRACTIONS of that design's top speed, each drive runs a speed
scenario of pmstep-sil on the design, the same for both drives (run.controller = pmstep | microstep):

  speed.points  0 until RUN's start + LEAD_S, a ramp at min(a_ref / 4, A_AXIS) (a_ref = k_M I / J, the rated
                torque's acceleration of the bare rotor) to the speed, held to the end;
  load          a table (load.type = table): 0 until SETTLE_S after the speed is reached, then up to the load
                torque T over LOAD_RAMP_S and held HOLD_S to the end. T > 0 opposes the forward motion
                (J dw/dt = T_e - F w - T_L). A slow ramp, not a step: the figure is the torque held at the
                speed, not the speed loop's response to a step (over 0.1 s, pmstep's speed error on the ramp
                met the bound at about half the load it holds over 1 s).

Held, the same rule for both drives: no fault; the summary's loss_of_synchronism false over the whole run
(microstepping: the load angle theta_e* - p theta beyond pi; pmstep: its angle estimate off by more than
run.loss_angle_error_rad); and |omega - omega*| at most run.loss_speed_error_rad_s (the run's
loss-of-control bound) from the start of the load ramp to the end of the hold (the summary's
robustness.max_speed_error_rad_s after settling, the settle set to the load ramp's start by run.transient_window_s).

The largest held load by bisection on [0, LOAD_BOUND x the datasheet holding torque] after a run at each
end: ITERATIONS halvings (resolution LOAD_BOUND T_H / 2^n). Copper loss at it: 2 R I_rms^2 (two phases, the
preset's R, the summary's per-phase RMS current over the hold, the load at its full value).

A second grid (not with --quick): at MICROSTEP_FRACTIONS (25, 50, 75, 100 %) of microstepping's own top speed on
the first grid (the highest speed there at which it holds a load), pmstep and microstepping again, and their
ratio; a preset and bus where microstepping holds no load at any speed of the first grid has no second grid.

--check exits 1 when a case could not be evaluated (the SIL failed or gave no summary) or pmstep misses its
targets: it holds less than microstepping where microstepping holds a load, or less than TOP_TORQUE_SHARE of
the holding torque up to CHECK_TOP_FRACTION x the design's top speed. A drive that holds not even no load
("none") is reported. --quick: one
preset (17hs4401), 24 V, speeds 0.25 and 1.5 of the top, 4 halvings (CI). --report FILE writes Markdown
(tools/report.py), with a plot per motor beside it when matplotlib is installed.

usage: tools/torque_speed.py [--sil PATH] [--tune PATH] [--motors paper,17hs4401,bj42d29,as1050]
                             [--buses 12,24,48] [--speeds 0.01,0.25,0.5,0.75,1.0] [--iterations 7]
                             [--quick] [--check] [--jobs 2] [--out DIR] [--json FILE] [--report FILE]
"""

import argparse
import concurrent.futures
import configparser
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import report  # noqa: E402
from homing_sweep import read_motor  # noqa: E402  (the preset)
from stepdir_compare import A_AXIS, design, run_sil  # noqa: E402  (the tune's design with --set, the SIL's run)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MOTORS = ["paper", "17hs4401", "bj42d29", "as1050"]
BUSES = [12.0, 24.0, 48.0]
# Fractions of the design's top speed (i_d = 0, rated current in 90 % of the bus): beyond 1, where field
# weakening takes over, up to the control rate's limit and past it.
SPEED_FRACTIONS = [0.01, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5]
QUICK_FRACTIONS = [0.25, 1.5]
# pmstep as designed (field weakening on), pmstep with it off, open-loop microstepping at rated current
DRIVES = ["pmstep", "pmstep-no-fw", "microstep"]
# The second grid: fractions of microstepping's own top speed (the highest speed of the first grid at which it
# holds a load), where pmstep and microstepping are compared again.
MICROSTEP_FRACTIONS = [0.25, 0.5, 0.75, 1.0]
MICROSTEP_GRID_DRIVES = ["pmstep", "microstep"]
DRIVE_LABELS = {"pmstep": "pmstep", "pmstep-no-fw": "pmstep without field weakening", "microstep": "microstepping"}
# The share of the holding torque a top speed keeps (PMSTEP_DESIGN_WEAKENED_TORQUE_SHARE); --check wants pmstep
# to hold it up to CHECK_TOP_FRACTION x the design's top speed (field weakening's target).
TOP_TORQUE_SHARE = 0.3
CHECK_TOP_FRACTION = 1.5
LEAD_S = 0.1  # from RUN's start to the speed ramp
SETTLE_S = 0.1  # at the speed before the load ramp
LOAD_RAMP_S = 1.0  # the load from 0 to T: quasi-static (a ramp of 0.1 s measured the speed loop's tracking of it)
HOLD_S = 0.5  # T held to the end
LOAD_BOUND = 1.5  # the bracket: [0, 1.5 x the datasheet holding torque]
ITERATIONS = 7  # 1.5 T_H / 128: 1.2 % of the holding torque
ITERATIONS_QUICK = 4  # 1.5 T_H / 16: 9.4 % of it


def bisect(held, lo, hi, iterations):
    """The largest x in [lo, hi] with held(x), assuming held falls off once: a run at each end, then
    @p iterations halvings. Returns (largest held, smallest failed); None for either when there is none
    (held(lo) false: (None, lo); held(hi) true: (hi, None))."""
    if not held(lo):
        return None, lo
    if held(hi):
        return hi, None
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if held(mid) else (lo, mid)
    return lo, hi


def copper_loss_W(rms_phase_current_A, resistance_Ohm):
    """Both phases' copper loss, 2 R I_rms^2, from the per-phase RMS current."""
    return 2.0 * resistance_Ohm * rms_phase_current_A**2


def timeline(motor, top, run_start, fraction):
    """The speed and the times of one case: ramp start, speed reached, load ramp start, end."""
    v = fraction * top
    a = min(0.25 * motor["k_M"] * motor["rated_A"] / motor["J"], A_AXIS)
    ramp = run_start + LEAD_S
    reached = ramp + v / a
    load = reached + SETTLE_S
    return {"v": v, "a": a, "ramp_s": ramp, "reached_s": reached, "load_s": load, "end_s": load + LOAD_RAMP_S + HOLD_S}


def held_failures(s, bound_rad_s):
    """Why a run did not hold its load; [] when it did (the rule of the module's docstring), @p bound_rad_s the
    run's loss-of-control bound on the speed error."""
    why = []
    if s["fault"]["name"] != "NONE":
        why.append("fault " + s["fault"]["name"])
    if s["loss_of_synchronism"]:
        why.append(f"loss of synchronism at {s['loss_of_synchronism_time_s']:.3f} s")
    r = s["robustness"]
    if r["max_speed_error_rad_s"] > bound_rad_s:
        why.append(f"speed error {r['max_speed_error_rad_s']:.3g} rad/s at {r['max_speed_error_time_s']:.3f} s")
    return why


def one_run(args, case, drive, torque, out_dir):
    tl = case["timeline"]
    # The metrics' t_c: RUN's start for pmstep, the end of the hold (the ramp's start) for microstepping.
    t_c = tl["ramp_s"] if drive == "microstep" else case["run_start"]
    sets = [
        f"run.controller={'microstep' if drive == 'microstep' else 'pmstep'}",
        "load.type=table",
        f"speed.points=0:0, {tl['ramp_s']:.6f}:0, {tl['reached_s']:.6f}:{tl['v']:.9g}",
        f"load.points=0:0, {tl['load_s']:.6f}:0, {tl['load_s'] + LOAD_RAMP_S:.6f}:{torque:.9g}",
        f"run.duration_s={tl['end_s']:.6f}",
        f"run.transient_window_s={tl['load_s'] - t_c:.6f}",
        f"run.metrics_start_s={tl['load_s'] + LOAD_RAMP_S:.6f}",
    ]
    if drive == "pmstep-no-fw":
        sets.append("controller.field_weakening.max_current_A=0")
    _, s = run_sil(args.sil, case["scenario"], sets, out_dir, False)
    return s


def search(args, case, drive):
    """The largest load @p drive holds in @p case, with the figures of the run at it."""
    grid = f"ms{case['microstep_fraction']:g}" if "microstep_fraction" in case else f"{case['fraction']:g}"
    out_dir = os.path.join(args.out, f"{case['motor']}_{case['bus']:g}V_{grid}_{drive}")
    runs = {}

    def held(torque):
        s = one_run(args, case, drive, torque, out_dir)
        runs[torque] = (s, held_failures(s, case["loss_speed_rad_s"]))
        return not runs[torque][1]

    row = {
        "motor": case["motor"],
        "bus_V": case["bus"],
        "fraction": case["fraction"],
        "drive": drive,
        "speed_rad_s": case["timeline"]["v"],
        "holding_Nm": case["preset"]["holding_Nm"],
        "bound_Nm": LOAD_BOUND * case["preset"]["holding_Nm"],
        "iterations": args.iterations,
        "error": None,
        "held_Nm": None,
        "failed_Nm": None,
        "failed_why": [],
    }
    if "microstep_fraction" in case:
        row["microstep_fraction"] = case["microstep_fraction"]
    try:
        lo, hi = bisect(held, 0.0, row["bound_Nm"], args.iterations)
    except (RuntimeError, KeyError, ValueError) as e:
        row["error"] = str(e)
        return row
    row.update({"held_Nm": lo, "failed_Nm": hi, "failed_why": runs[hi][1] if hi is not None else [], "runs": len(runs)})
    if lo is not None:
        s = runs[lo][0]
        row.update(
            {
                "held_fraction": lo / row["holding_Nm"],
                "rms_phase_current_A": s["rms_phase_current_A"],
                "copper_loss_W": copper_loss_W(s["rms_phase_current_A"], case["preset"]["R"]),
                "max_speed_error_rad_s": s["robustness"]["max_speed_error_rad_s"],
            }
        )
    else:
        row["none_why"] = row["failed_why"]
    return row


def cases(args):
    """The designs (one per preset and bus) and the cases at their speeds; the designs the tune refuses."""
    out, refused = [], []
    os.makedirs(args.out, exist_ok=True)
    for motor in args.motors.split(","):
        motor_ini = os.path.join(ROOT, "sil", "scenarios", "motors", f"{motor}.ini")
        preset = read_motor(motor_ini)
        for bus in args.bus_list:
            scenario = os.path.join(args.out, f"{motor}_{bus:g}V.ini")
            try:
                top, run_start, _, _ = design(args.tune, motor_ini, scenario, False, [f"run.bus_voltage_V={bus:g}"])
            except subprocess.CalledProcessError as e:
                refused.append({"motor": motor, "bus_V": bus, "why": (e.stderr or "").strip().split("\n")[-1]})
                continue
            ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
            ini.read(scenario)
            bound = float(ini["run"]["loss_speed_error_rad_s"])
            for fraction in args.fraction_list:
                out.append(
                    {
                        "motor": motor,
                        "bus": bus,
                        "fraction": fraction,
                        "preset": preset,
                        "scenario": scenario,
                        "top_rad_s": top,
                        "run_start": run_start,
                        "loss_speed_rad_s": bound,
                        "timeline": timeline(preset, top, run_start, fraction),
                    }
                )
    return out, refused


def microstep_cases(all_cases, rows):
    """The second grid's cases: per preset and bus of @p all_cases, MICROSTEP_FRACTIONS of microstepping's top speed
    on the first grid (top_speeds() of @p rows: the highest speed at which it holds a load), each case carrying
    "microstep_fraction"; none where microstepping holds no load at any speed."""
    tops = {(m, b): drives.get("microstep", (None, None))[1] for m, b, _, drives in top_speeds(rows)}
    designs = {(c["motor"], c["bus"]): c for c in all_cases}  # one first-grid case per preset and bus
    out = []
    for key, c in designs.items():
        ms_top = tops.get(key)
        if ms_top is None:
            continue
        for f in MICROSTEP_FRACTIONS:
            fraction = f * ms_top / c["top_rad_s"]
            case = dict(c, fraction=fraction, microstep_fraction=f)
            case["timeline"] = timeline(c["preset"], c["top_rad_s"], c["run_start"], fraction)
            out.append(case)
    return out


def microstep_ratio_table(rows):
    """Markdown: per preset and bus, microstepping's top speed and, at each of MICROSTEP_FRACTIONS of it, the two
    drives' largest held loads and their ratio (rows of the second grid, which carry "microstep_fraction")."""
    by = {}
    for r in rows:
        key = (r["motor"], r["bus_V"])
        by.setdefault(key, {}).setdefault(r["microstep_fraction"], {})[r["drive"]] = r
    head = ["motor", "bus V", "microstepping top rad/s"] + [
        f"{f * 100:.0f} %: pmstep / microstepping N m (ratio)" for f in MICROSTEP_FRACTIONS
    ]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for (motor, bus), fractions in by.items():
        top = next(iter(fractions[MICROSTEP_FRACTIONS[-1]].values()))["speed_rad_s"]
        cells = [motor, f"{bus:g}", f"{top:.1f}"]
        for f in MICROSTEP_FRACTIONS:
            pm, ms = fractions.get(f, {}).get("pmstep"), fractions.get(f, {}).get("microstep")
            x = ratio(pm and pm["held_Nm"], ms and ms["held_Nm"])
            cells.append(f"{_newton_metres(pm)} / {_newton_metres(ms)} ({'-' if x is None else f'{x:.2f}'})")
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def ratio(pm, ms):
    """pmstep's largest held load over microstepping's (None without both, or microstepping's 0)."""
    if pm is None or ms is None or ms <= 0.0:
        return None
    return pm / ms


def pair_rows(rows):
    """The rows joined per case: [(case key, pmstep row, microstep row)] in the rows' order."""
    return [(k, d.get("pmstep"), d.get("microstep")) for k, d in case_rows(rows)]


def case_rows(rows):
    """The rows joined per case: [(case key, {drive: row})] in the rows' order."""
    by = {}
    for r in rows:
        by.setdefault((r["motor"], r["bus_V"], r["fraction"]), {})[r["drive"]] = r
    return list(by.items())


def _load(r):
    if r is None or r["error"]:
        return "n/a"
    if r["held_Nm"] is None:
        return "none"
    t = f"{r['held_Nm']:.3f}"
    return ("≥ " if r["failed_Nm"] is None else "") + t + f" ({r['held_fraction']:.2f})"


def _newton_metres(r):
    """A row's largest held load in N m ("≥" at the bracket's top), "none" or "n/a"."""
    if r is None or r["error"]:
        return "n/a"
    if r["held_Nm"] is None:
        return "none"
    return ("≥ " if r["failed_Nm"] is None else "") + f"{r['held_Nm']:.3f}"


def _loss(r):
    return "-" if r is None or r.get("copper_loss_W") is None else f"{r['copper_loss_W']:.2f}"


TABLE_HEAD = [
    "motor",
    "bus V",
    "speed",
    "rad/s",
    "pmstep N·m (× T_H)",
    "without FW N·m (× T_H)",
    "microstep N·m (× T_H)",
    "ratio",
    "pmstep Cu W",
    "without FW Cu W",
    "microstep Cu W",
]
TEXT_WIDTHS = [9, 4, 5, 7, 16, 16, 16, 6, 8, 8, 8]


def _line(cells, markdown):
    if markdown:
        return "| " + " | ".join(cells) + " |"
    return " ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(cells, TEXT_WIDTHS)))


def table(rows, refused, markdown):
    out = [_line(TABLE_HEAD, markdown)]
    if markdown:
        out.append("|" + "---|" * len(TABLE_HEAD))
    for (motor, bus, fraction), d in case_rows(rows):
        pm, nofw, ms = d.get("pmstep"), d.get("pmstep-no-fw"), d.get("microstep")
        r = ratio(pm["held_Nm"] if pm else None, ms["held_Nm"] if ms else None)
        speed = next(x for x in (pm, nofw, ms) if x)["speed_rad_s"]
        cells = [motor, f"{bus:g}", f"{fraction:g}", f"{speed:.1f}", _load(pm), _load(nofw), _load(ms)]
        cells += ["-" if r is None else f"{r:.2f}", _loss(pm), _loss(nofw), _loss(ms)]
        out.append(_line(cells, markdown))
    for d in refused:
        if markdown:
            out.append(_line([d["motor"], f"{d['bus_V']:g}", "-", "-"] + ["no design"] * 3 + ["-"] * 4, True))
        else:
            out.append(f"{d['motor']:9s} {d['bus_V']:4g}  no design: {d['why']}")
    return "\n".join(out)


def top_speeds(rows):
    """Per motor and bus: the design's top speed and, per drive, the highest speed of the grid at which it holds
    TOP_TORQUE_SHARE of the holding torque and the highest at which it holds a load: [(motor, bus, design top,
    {drive: (speed at the share or None, speed with a load or None)})]."""
    out = {}
    for r in rows:
        if r["error"]:
            continue
        key = (r["motor"], r["bus_V"])
        top = r["speed_rad_s"] / r["fraction"]
        entry = out.setdefault(key, (top, {}))[1].setdefault(r["drive"], [None, None])
        if r["held_Nm"] is not None:
            if r["held_Nm"] >= TOP_TORQUE_SHARE * r["holding_Nm"]:
                entry[0] = max(entry[0] or 0.0, r["speed_rad_s"])
            entry[1] = max(entry[1] or 0.0, r["speed_rad_s"])
    return [(m, b, top, drives) for (m, b), (top, drives) in out.items()]


def top_speed_table(rows):
    """Markdown: top_speeds() with each speed also as a multiple of the design's top speed."""

    def cell(v, top):
        return "none" if v is None else f"{v:.1f} ({v / top:.2f}×)"

    head = ["motor", "bus V", "design top rad/s"]
    for drive in DRIVES:
        head += [f"{DRIVE_LABELS[drive]}: at {TOP_TORQUE_SHARE * 100:.0f} % T_H", f"{DRIVE_LABELS[drive]}: any load"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for motor, bus, top, drives in top_speeds(rows):
        cells = [motor, f"{bus:g}", f"{top:.1f}"]
        for drive in DRIVES:
            share, any_load = drives.get(drive, (None, None))
            cells += [cell(share, top), cell(any_load, top)]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def unevaluated(rows):
    """--check: the cases that could not be evaluated (the SIL failed or gave no summary)."""
    return [
        f"{r['motor']} {r['bus_V']:g} V {r['fraction']:g} x top {r['drive']}: {r['error']}" for r in rows if r["error"]
    ]


def shortfalls(rows):
    """--check: the cases where pmstep (as designed) misses its targets: it holds less than microstepping where
    microstepping holds a load, or less than TOP_TORQUE_SHARE of the holding torque at up to CHECK_TOP_FRACTION x
    the design's top speed."""
    out = []
    for (motor, bus, fraction), d in case_rows(rows):
        pm, ms = d.get("pmstep"), d.get("microstep")
        if not pm or pm["error"]:
            continue
        held = pm["held_Nm"] or 0.0
        where = f"{motor} {bus:g} V {fraction:g} x top: pmstep holds {held:.3f} N m"
        if ms and not ms["error"] and ms["held_Nm"] is not None and held < ms["held_Nm"]:
            out.append(f"{where}, microstepping {ms['held_Nm']:.3f}")
        if fraction <= CHECK_TOP_FRACTION and held < TOP_TORQUE_SHARE * pm["holding_Nm"]:
            out.append(f"{where}, under {TOP_TORQUE_SHARE * 100:.0f} % of the holding torque")
    return out


def limits(rows):
    """What stopped each drive above its largest held load: Markdown list lines, one per case where the drive
    held no load (its reason at no load), then per drive a count of the first failures' kinds."""
    lines = [
        f"- {r['motor']} {r['bus_V']:g} V, {r['fraction']:g} × top, {r['drive']}: holds no load ("
        + "; ".join(r["failed_why"])
        + ")"
        for r in rows
        if not r["error"] and r["held_Nm"] is None
    ]
    for drive in DRIVES:
        kinds = {}
        for r in rows:
            if r["drive"] == drive and r["held_Nm"] is not None and r["failed_why"]:
                kind = r["failed_why"][0].split(" at ")[0].split(" rad/s")[0]
                kind = "speed error" if kind.startswith("speed error") else kind
                kinds[kind] = kinds.get(kind, 0) + 1
        if kinds:
            lines.append(
                f"- {drive}, first failure above the largest held load: "
                + ", ".join(f"{k} in {n}" for k, n in sorted(kinds.items()))
            )
    return lines


def summary(rows):
    """One sentence: the ratios' range and how many cases pmstep holds less."""
    pairs = [(pm, ms) for _, pm, ms in pair_rows(rows) if pm and ms]
    rs = [x for x in (ratio(pm["held_Nm"], ms["held_Nm"]) for pm, ms in pairs) if x is not None]
    if not rs:
        return "no case with both drives' figures."
    less = sum(1 for x in rs if x < 1.0)
    return (
        f"pmstep / microstepping largest held load {min(rs):.2f}–{max(rs):.2f} over {len(rs)} cases; "
        f"pmstep holds less than microstepping in {less} of them."
    )


def plot(rows, motor, path):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    fig, ax = plt.subplots(figsize=(7, 4.5))
    drawn = False
    for i, bus in enumerate(sorted({r["bus_V"] for r in rows if r["motor"] == motor})):
        for drive, style in (("pmstep", "-"), ("pmstep-no-fw", ":"), ("microstep", "--")):
            pts = sorted(
                (r["speed_rad_s"], r["held_Nm"])
                for r in rows
                if r["motor"] == motor and r["bus_V"] == bus and r["drive"] == drive and r["held_Nm"] is not None
            )
            if pts:
                ax.plot(
                    [p[0] for p in pts],
                    [p[1] for p in pts],
                    style,
                    marker="o",
                    color=f"C{i}",
                    label=f"{DRIVE_LABELS[drive]}, {bus:g} V",
                )
                drawn = True
    if not drawn:
        plt.close(fig)
        return None
    ax.set_xlabel("speed (rad/s)")
    ax.set_ylabel("largest constant load held (N·m)")
    ax.set_title(f"{motor}: torque against speed")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


WHAT = (
    "Per public preset and bus voltage, pmstep-tune's design for that bus, and at fractions of its top speed (the "
    "speed at which rated current fills 90 % of the bus with i_d = 0) the largest constant load torque each "
    "drive holds: pmstep in speed mode as designed (field weakening on), the same design with field weakening "
    "off (`controller.field_weakening.max_current_A = 0`), and open-loop microstepping at rated current "
    "(`run.controller = microstep`) on the same plant and scenario; *ratio* is pmstep's over microstepping's. "
    "The speed ramps at min(¼ k_M I / J, "
    f"{A_AXIS:g} rad/s²) from RUN's start + {LEAD_S:g} s; {SETTLE_S:g} s after it is reached the load (opposing "
    f"the motion) ramps from 0 over {LOAD_RAMP_S:g} s and is held {HOLD_S:g} s to the end. **Held**, the same "
    "rule for both drives: no fault, the summary's `loss_of_synchronism` false (microstepping: load angle beyond "
    "π; pmstep: angle estimate off by more than `run.loss_angle_error_rad`), and |ω − ω*| within "
    "`run.loss_speed_error_rad_s` from the load ramp's start to the end. Bisection on [0, "
    f'{LOAD_BOUND:g} × the datasheet holding torque T_H]; "≥": held at the bracket\'s top. Copper loss: '
    "2 R I_rms² at the largest held load, I_rms per phase over the hold (the load at its full value). "
    "Currents differ: microstepping drives rated current whatever the load (pull-out torque k_M I); pmstep's "
    "current follows the load up to its overcurrent trip (`controller.limits.max_phase_current_A`, above rated "
    "current), so its largest held load may need more than rated current: compare the copper losses."
)


def report_text(rows, refused, args, argv, pictures, ms_rows=()):
    what = WHAT + (
        f" {args.iterations} halvings: resolution {LOAD_BOUND:g} T_H / {2**args.iterations} = "
        f"{LOAD_BOUND / 2**args.iterations * 100:.2g} % of T_H."
    )
    lines = [
        report.header("Torque against speed: pmstep and open-loop microstepping", "tools/torque_speed.py", argv, what),
        table(rows, refused, True),
        "",
        summary(rows),
        "",
        f"## Top speeds\n\nPer drive, the highest speed of the grid at which it holds {TOP_TORQUE_SHARE * 100:.0f} % "
        "of the datasheet holding torque, and the highest at which it holds a load at all; in parentheses as a "
        "multiple of the design's top speed (the grid's unit). A drive's curve between grid speeds is not measured.",
        "",
        top_speed_table(rows),
        "",
    ]
    if ms_rows:
        lines += [
            "## Against microstepping's own top speed\n\nAt "
            + ", ".join(f"{f * 100:.0f}" for f in MICROSTEP_FRACTIONS)
            + " % of microstepping's top speed (the highest speed of the grid above at which it holds a load), "
            "the largest load each drive holds (N m) and the ratio pmstep / microstepping; a preset and bus "
            "where microstepping holds no load on that grid has no row.",
            "",
            microstep_ratio_table(ms_rows),
            "",
            summary(ms_rows),
            "",
        ]
    if limits(rows):
        lines += limits(rows) + [""]
    for motor, picture in pictures:
        lines += [f"![{motor}: largest held load against speed]({picture})", ""]
    return "\n".join(lines)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sil", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-sil"))
    ap.add_argument("--tune", default=os.path.join(ROOT, "build", "host-release", "sil", "pmstep-tune"))
    ap.add_argument("--motors")
    ap.add_argument("--buses", help="bus voltages, V (default 12,24,48; 24 with --quick)")
    ap.add_argument("--speeds", help="fractions of the design's top speed")
    ap.add_argument("--iterations", type=int, help=f"halvings (default {ITERATIONS}, {ITERATIONS_QUICK} with --quick)")
    ap.add_argument("--quick", action="store_true", help="17hs4401, 24 V, speeds 0.25 and 1.5, 4 halvings (CI)")
    ap.add_argument(
        "--check", action="store_true", help="exit 1 if a case could not be evaluated or pmstep misses its targets"
    )
    ap.add_argument("--jobs", type=int, default=2, help="searches at once (threads, each running pmstep-sil)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "torque_speed"))
    ap.add_argument("--json", help="also write every search's figures to this file")
    ap.add_argument("--report", metavar="FILE", help="write the table as Markdown, the plots beside it")
    args = ap.parse_args(argv[1:])
    args.motors = args.motors or ("17hs4401" if args.quick else ",".join(MOTORS))
    args.bus_list = [float(x) for x in (args.buses or ("24" if args.quick else "12,24,48")).split(",")]
    args.fraction_list = [
        float(x)
        for x in (args.speeds or ",".join(str(f) for f in (QUICK_FRACTIONS if args.quick else SPEED_FRACTIONS))).split(
            ","
        )
    ]
    if args.iterations is None:
        args.iterations = ITERATIONS_QUICK if args.quick else ITERATIONS
    for m in args.motors.split(","):
        if not os.path.isfile(os.path.join(ROOT, "sil", "scenarios", "motors", f"{m}.ini")):
            ap.error(f"unknown motor '{m}' (presets: {', '.join(MOTORS)})")
    all_cases, refused = cases(args)
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(search, args, c, d) for c in all_cases for d in DRIVES]
        rows = [f.result() for f in futures]
        ms_rows = []
        if not args.quick:
            ms_futures = [
                pool.submit(search, args, c, d) for c in microstep_cases(all_cases, rows) for d in MICROSTEP_GRID_DRIVES
            ]
            ms_rows = [f.result() for f in ms_futures]
    print(table(rows, refused, False))
    print(
        f"torque_speed: load N m (x datasheet holding torque), resolution {LOAD_BOUND:g} T_H / "
        f"{2**args.iterations}; Cu W: 2 R I_rms^2 at the largest held load"
    )
    print("torque_speed: " + summary(rows))
    if ms_rows:
        print(microstep_ratio_table(ms_rows))
        print("torque_speed: at fractions of microstepping's top speed: " + summary(ms_rows))
    for line in limits(rows):
        print("torque_speed: " + line[2:])
    bad = unevaluated(rows + ms_rows)
    for b in bad:
        print("torque_speed: not evaluated: " + b)
    short = list(dict.fromkeys(shortfalls(rows) + shortfalls(ms_rows)))  # a speed both grids have, once
    for b in short:
        print("torque_speed: short: " + b)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"cases": rows, "microstep_grid": ms_rows, "no_design": refused}, f, indent=1)
    if args.report:
        pictures = []
        stem = os.path.splitext(args.report)[0]
        for motor in dict.fromkeys(r["motor"] for r in rows):
            path = plot(rows + ms_rows, motor, f"{stem}-{motor}.png")
            if path:
                pictures.append((motor, os.path.basename(path)))
        if not pictures:
            print("torque_speed: matplotlib not installed, no plots", file=sys.stderr)
        text = report_text(rows, refused, args, argv, pictures, ms_rows)
        print(f"torque_speed: wrote {report.write(args.report, text)}")
    return 1 if (bad or short) and args.check else 0


if __name__ == "__main__":
    sys.exit(main())
