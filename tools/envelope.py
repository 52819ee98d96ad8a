#!/usr/bin/env python3
"""Operating envelope of the motor presets with the gain designer's settings, against open-loop
microstepping at rated current (issue 11). A benchmark that prints and writes figures; not a test.

For each preset (sil/scenarios/motors/) and chain (ideal; realistic = sil/scenarios/robust.ini's
measurement chain with the robust mode; sensed = realistic on a drive that also senses each
phase's mean voltage per period, tools/mc_preset.py's PHASE_VOLTAGE_SENSING), it designs the gains with pmstep-tune
(no hand tuning),
then runs pmstep-sil:
  ramps     RUN of --duration s: ramps to +-80 % and +-5 % of the top speed and holds, repeated;
            fault, max |w - w*| after the transients (% of top), max angle-estimate error
  steps     half the holding torque stepped on at 50 % and 5 % of the top speed: fault, loss of
            synchronism, speed dip, recovery time (back within 2 % of top speed); then the same step
            at STEP_POSITIONS rotor positions spread over one detent period (4 p steps a turn), each
            one survived or not, since a step's outcome near the limit depends on where it lands
  pull-out  the largest load step (fraction of the holding torque, bisection) survived at 50 %
            of the top speed without a fault or a loss of synchronism, ours and microstepping
  copper    per-phase RMS current at 50 % of the top speed without load, ours and microstepping

  tools/envelope.py --sil build/host-release/sil/pmstep-sil --tune build/host-release/sil/pmstep-tune \\
      --out out/envelope [--report docs/reports/envelope.md]

--top weakened scales every speed with the field-weakened top speed in place of the design's (the
speed at which 30 % of the holding torque still fits in the bus with field weakening).

--report FILE also writes the table as Markdown (command, commit, date; tools/report.py) and the
plot beside it (FILE with .png for .md), shown in the report.
"""

import argparse
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from mc_distributions import ToolError  # noqa: E402
from mc_preset import chain_sets, read_preset as read_preset_file, tune_top_speed  # noqa: E402
import report  # noqa: E402

PRESETS = ("paper", "17hs4401", "bj42d29", "as1050")
ROBUST_CHAINS = ("realistic", "sensed")  # designed with --robust, behind mc_preset.py's chain
HOLD_S = 1.0
SETTLE_S = 0.1  # after each ramp, before the tracking error counts ("after transients")
BISECTION_STEPS = 6
STEP_POSITIONS = 8  # load steps spread over one detent period, the nominal one first


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, check=False)


def sets(pairs):
    out = []
    for p in pairs:
        out += ["--set", p]
    return out


def read_preset(name):
    return read_preset_file(os.path.join(ROOT, "sil", "scenarios", "motors", name + ".ini"))


def design(args, name, chain, out_dir):
    preset = read_preset(name)
    robust = chain in ROBUST_CHAINS
    chain_items = chain_sets(preset, chain == "sensed") if robust else []
    ini = os.path.join(out_dir, "design.ini")
    cmd = (
        [args.tune, "--motor", os.path.join(ROOT, "sil", "scenarios", "motors", name + ".ini"), "--write-ini", ini]
        + (["--robust"] if robust else [])
        + sets(chain_items)
    )
    r = run(cmd)
    if r.returncode != 0:
        raise SystemExit("pmstep-tune failed: %s\n%s" % (" ".join(cmd), r.stderr))
    try:
        top = tune_top_speed(r.stdout, args.top == "weakened")
    except ToolError as e:
        raise SystemExit("%s: %s" % (" ".join(cmd), e)) from None
    t_c = float(re.search(r"t_c ([0-9.]+) s", r.stdout).group(1))
    start = t_c + (0.05 if robust else 0.0) + 0.1
    return ini, top, start, preset


def profile(start, legs):
    """Speed points: 0 until start, then (ramp time, level, hold) legs."""
    t = start
    pts = ["0:0", "%.6f:0" % t]
    for ramp_s, level, hold_s in legs:
        t += ramp_s
        pts.append("%.6f:%.6g" % (t, level))
        t += hold_s
        pts.append("%.6f:%.6g" % (t, level))
    return ", ".join(pts), t


def sil(args, ini, out_dir, extra, csv_out=False):
    cmd = (
        [args.sil, "--scenario", ini, "--out", out_dir, "--quiet"]
        + ([] if csv_out else ["--no-csv"])
        + sets(extra)
        + sets(args.set)
    )
    r = run(cmd)
    summary_path = os.path.join(out_dir, "summary.json")
    if not os.path.exists(summary_path):
        raise SystemExit("pmstep-sil wrote no summary: %s\n%s" % (" ".join(cmd), r.stderr))
    return json.load(open(summary_path)), r.returncode


def fault_name(summary):
    return summary["fault"]["name"]


def ok(summary):
    return (
        fault_name(summary) == "NONE"
        and summary.get("final_mode") == "RUN"
        and not summary.get("loss_of_synchronism", False)
    )


def ok_microstep(summary):
    return not summary.get("loss_of_synchronism", True)


def dip_and_recovery(out_dir, step_time_s, bound):
    dip, last_above = 0.0, step_time_s
    with open(os.path.join(out_dir, "run.csv")) as f:
        for row in csv.DictReader(f):
            t = float(row["t_s"])
            if t < step_time_s:
                continue
            e = abs(float(row["omega_rad_s"]) - float(row["omega_ref_rad_s"]))
            dip = max(dip, e)
            if e > bound:
                last_above = t
    return dip, last_above - step_time_s


def hold_error(out_dir, holds, settle_s):
    """Max |w - w*| within the holds [a, b), from a + settle_s on (after the ramp's transient)."""
    worst = 0.0
    with open(os.path.join(out_dir, "run.csv")) as f:
        for row in csv.DictReader(f):
            t = float(row["t_s"])
            if any(a + settle_s <= t < b for a, b in holds):
                worst = max(worst, abs(float(row["omega_rad_s"]) - float(row["omega_ref_rad_s"])))
    return worst


def envelope(args, name, chain):
    out = os.path.join(args.out, name, chain)
    os.makedirs(out, exist_ok=True)
    ini, top, start, preset = design(args, name, chain, out)
    with open(ini) as f:
        pole_pairs = int(re.search(r"^pole_pairs\s*=\s*(\d+)", f.read(), re.M).group(1))
    ramp_s = max(0.05, 0.8 * top / 2000.0)
    row = {"preset": name, "chain": chain, "top_speed_rad_s": top}
    # Ramps for --duration s of RUN.
    legs, t = [], 0.0
    while t < args.duration:
        for level in (0.8, -0.8, 0.05, -0.05):
            legs.append((ramp_s, level * top, HOLD_S))
            t += ramp_s + HOLD_S
    points, end = profile(start, legs)
    holds, t = [], start
    for ramp, _, hold in legs:
        t += ramp
        holds.append((t, t + hold))
        t += hold
    s, _ = sil(
        args,
        ini,
        os.path.join(out, "ramps"),
        ["speed.points=" + points, "run.duration_s=%g" % end, "load.type=none"],
        csv_out=True,
    )
    row["ramps_fault"] = fault_name(s)
    row["ramps_speed_error_pct_top"] = 100.0 * hold_error(os.path.join(out, "ramps"), holds, SETTLE_S) / top
    row["ramps_angle_error_rad"] = s["robustness"]["max_angle_error_rad"]
    print(
        "%-9s %-9s top %6.1f rad/s  ramps: fault %s, |w-w*| %.2f %% of top, angle %.4f rad"
        % (name, chain, top, row["ramps_fault"], row["ramps_speed_error_pct_top"], row["ramps_angle_error_rad"]),
        flush=True,
    )

    def step_run(fraction_of_top, load_fraction, microstep, csv_out=False, delay_s=0.0):
        pts, end = profile(start, [(ramp_s, fraction_of_top * top, 1.0)])
        step_time = end - 0.5 + delay_s  # the run lasts 0.5 s past every step (the speed holds)
        extra = [
            "speed.points=" + pts,
            "run.duration_s=%g" % (end + delay_s),
            "load.type=step",
            "load.torque_Nm=%g" % (load_fraction * preset["holding_torque_Nm"]),
            "load.step_time_s=%g" % step_time,
        ]
        if microstep:
            extra.append("run.controller=microstep")
        d = os.path.join(
            out,
            "step_%s_%g_%g%s"
            % ("ms" if microstep else "ours", fraction_of_top, load_fraction, "_at_%.6f" % delay_s if delay_s else ""),
        )
        summary, _ = sil(args, ini, d, extra, csv_out)
        return summary, d, step_time

    for fraction in (0.5, 0.05):
        s, d, t_step = step_run(fraction, 0.5, False, csv_out=True)
        dip, recovery = dip_and_recovery(d, t_step, 0.02 * top)
        key = "step_at_%g" % fraction
        row[key] = {
            "fault": fault_name(s),
            "lost_sync": s.get("loss_of_synchronism"),
            "dip_rad_s": dip,
            "recovery_ms": 1e3 * recovery,
            "max_angle_error_rad": s["robustness"]["max_angle_error_rad"],
        }
        detent_period_s = 2.0 * math.pi / (4.0 * pole_pairs * fraction * top)
        survived = int(ok(s)) + sum(
            int(ok(step_run(fraction, 0.5, False, delay_s=k * detent_period_s / STEP_POSITIONS)[0]))
            for k in range(1, STEP_POSITIONS)
        )
        row[key]["survived_positions"] = survived
        print(
            "%-9s %-9s 0.5 T_H at %g top: fault %s, sync lost %s, dip %.2f rad/s, recovery %.1f ms; "
            "survived at %d of %d positions over a detent period"
            % (
                name,
                chain,
                fraction,
                fault_name(s),
                s.get("loss_of_synchronism"),
                dip,
                1e3 * recovery,
                survived,
                STEP_POSITIONS,
            ),
            flush=True,
        )

    for microstep in (False, True):
        lo, hi = 0.0, 1.0
        for _ in range(BISECTION_STEPS):
            mid = 0.5 * (lo + hi)
            s, _, _ = step_run(0.5, mid, microstep)
            if ok_microstep(s) if microstep else ok(s):
                lo = mid
            else:
                hi = mid
        row["pullout_%s_of_holding" % ("microstep" if microstep else "ours")] = lo
    # Copper loss at light load.
    pts, end = profile(start, [(ramp_s, 0.5 * top, 1.0)])
    for microstep in (False, True):
        extra = [
            "speed.points=" + pts,
            "run.duration_s=%g" % end,
            "load.type=none",
            "run.metrics_start_s=%g" % (end - 0.5),
        ]
        if microstep:
            extra.append("run.controller=microstep")
        s, _ = sil(args, ini, os.path.join(out, "rms_%s" % ("ms" if microstep else "ours")), extra)
        row["rms_current_%s_A" % ("microstep" if microstep else "ours")] = s.get("rms_phase_current_A")
    print(
        "%-9s %-9s largest step at 0.5 top: ours %.3f, microstepping %.3f of T_H; rms current ours %.3f A, "
        "microstepping %.3f A"
        % (
            name,
            chain,
            row["pullout_ours_of_holding"],
            row["pullout_microstep_of_holding"],
            _or(row["rms_current_ours_A"], -1),
            _or(row["rms_current_microstep_A"], -1),
        ),
        flush=True,
    )
    return row


def _or(value, missing):
    """@p value, or @p missing for None (a value of 0 is a value)."""
    return missing if value is None else value


def markdown(rows):
    lines = [
        "| preset | chain | top speed (rad/s) | ramps: fault, max |w-w*| (% top), angle error (rad) | "
        "0.5 T_H step at 50 % / 5 % top: dip (rad/s), recovery (ms); survived at k of "
        + str(STEP_POSITIONS)
        + " positions | largest step at 50 % top, ours / "
        "microstepping (x T_H) | RMS phase current at 50 % top, no load: ours / microstepping (A) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:

        def step(k, r=r):
            x = r[k]
            positions = "; %d/%d" % (x["survived_positions"], STEP_POSITIONS)
            if x["fault"] not in ("NONE", None) or x["lost_sync"]:
                return "%s%s%s" % (x["fault"], ", sync lost" if x["lost_sync"] else "", positions)
            return "%.1f, %.0f%s" % (x["dip_rad_s"], x["recovery_ms"], positions)

        lines.append(
            "| %s | %s | %.1f | %s, %.2f, %.4f | %s / %s | %.3f / %.3f | %.3f / %.3f |"
            % (
                r["preset"],
                r["chain"],
                r["top_speed_rad_s"],
                r["ramps_fault"],
                r["ramps_speed_error_pct_top"],
                _or(r["ramps_angle_error_rad"], math.nan),
                step("step_at_0.5"),
                step("step_at_0.05"),
                r["pullout_ours_of_holding"],
                r["pullout_microstep_of_holding"],
                _or(r["rms_current_ours_A"], math.nan),
                _or(r["rms_current_microstep_A"], math.nan),
            )
        )
    return "\n".join(lines) + "\n"


def report_text(rows, args, argv, plot_name=None):
    """The report: what was measured (@p args' presets, chains, duration and --set), markdown(@p rows)
    and, if @p plot_name, the plot beside it."""
    what = (
        "Designer's gains (`pmstep-tune`, no per-motor tuning), 20 kHz, the plant's detent torque on; "
        '"realistic" is sil/scenarios/robust.ini\'s chain (12-bit ADC over ±3 I, ±20 mA offsets, 5 mA noise, '
        'one period of delay, 1 µs dead time, switching inverter) with the robust mode, "sensed" the same on a '
        "drive that senses the phase voltages (tools/mc_preset.py). Ramps: %g s of RUN to ±80 %% and ±5 %% of "
        "the top speed (at least that long: whole rounds of four), each level held %g s; tracking is the "
        "largest |w-w*| in the holds from %g s after each "
        "ramp. Steps: half the holding torque T_H stepped on at 50 %% and 5 %% of the top speed (dip and "
        "recovery, back within 2 %% of the top speed, of the nominal step), and again at %d rotor positions "
        "over one detent period. Pull-out: the largest step survived at 50 %% of the top speed without a fault "
        "or a loss of synchronism (bisection, %d steps). Microstepping: the SIL's open-loop baseline at rated "
        "current." % (args.duration, HOLD_S, SETTLE_S, STEP_POSITIONS, BISECTION_STEPS)
    )
    if args.top == "weakened":
        what += (
            " The top speed here is the field-weakened one (pmstep-tune's 'top speed with it': 30 % of the "
            "holding torque in the bus with i_d* at its most negative, at most the control rate's 0.4 rad a "
            "period), not the design's i_d = 0 one of envelope.md: every speed above scales with it."
        )
    if args.set:
        what += " Every run after the design with " + ", ".join("`--set %s`" % item for item in args.set) + "."
    # markdown()'s header has |w-w*| unescaped, which splits its cell in a Markdown table: escaped here,
    # out/.../envelope.md and the printed table left as they are.
    lines = [
        report.header(
            "Operating envelope against open-loop microstepping"
            + (" at the field-weakened top speed" if args.top == "weakened" else ""),
            "tools/envelope.py",
            argv,
            what,
        ),
        markdown(rows).replace("max |w-w*|", "max \\|w-w*\\|", 1),
    ]
    if plot_name:
        lines += ["![Largest load step survived and RMS phase current, ours and microstepping](%s)" % plot_name, ""]
    return "\n".join(lines)


def plot(rows, path):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("envelope: matplotlib not installed, no plot", file=sys.stderr)
        return None
    labels = ["%s\n%s" % (r["preset"], r["chain"]) for r in rows]
    x = range(len(rows))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    axes[0].bar([i - 0.2 for i in x], [r["pullout_ours_of_holding"] for r in rows], 0.4, label="pmstep (sensorless)")
    axes[0].bar(
        [i + 0.2 for i in x], [r["pullout_microstep_of_holding"] for r in rows], 0.4, label="open-loop microstepping"
    )
    axes[0].set_ylabel("largest load step survived at 50 % top speed (x holding torque)")
    axes[1].bar([i - 0.2 for i in x], [r["rms_current_ours_A"] or 0 for r in rows], 0.4, label="pmstep")
    axes[1].bar([i + 0.2 for i in x], [r["rms_current_microstep_A"] or 0 for r in rows], 0.4, label="microstepping")
    axes[1].set_ylabel("RMS phase current, no load, 50 % top speed (A)")
    for ax in axes:
        ax.set_xticks(list(x))
        ax.set_xticklabels(labels, fontsize=7)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("envelope: wrote %s" % path)
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sil", required=True)
    ap.add_argument("--tune", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--presets", default=",".join(PRESETS))
    ap.add_argument(
        "--chains",
        default="ideal,realistic",
        help="comma-separated: ideal, realistic, sensed (realistic with phase-voltage sensing)",
    )
    ap.add_argument("--duration", type=float, default=20.0, help="RUN time of the ramps run (s)")
    ap.add_argument(
        "--top",
        choices=("design", "weakened"),
        default="design",
        help="the speed the profiles scale with: the design's top speed (rated current in the bus with i_d = 0), "
        "or the field-weakened one (30 %% of the holding torque in the bus with i_d* = -I_w; pmstep-tune's "
        "'top speed with it')",
    )
    ap.add_argument(
        "--report",
        metavar="FILE",
        help="also write the table as Markdown here (docs/reports/envelope.md), the plot beside it",
    )
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="a pmstep-sil --set applied to every run after the design (e.g. one impairment "
        "of the chain removed: --set inverter.dead_time_s=0 --set controller.inverter.dead_time_s=0)",
    )
    args = ap.parse_args()
    unknown = [c for c in args.chains.split(",") if c not in ("ideal",) + ROBUST_CHAINS]
    if unknown:
        ap.error("unknown chain %s (ideal, %s)" % (", ".join(unknown), ", ".join(ROBUST_CHAINS)))
    rows = []
    for name in args.presets.split(","):
        for chain in args.chains.split(","):
            rows.append(envelope(args, name, chain))
    os.makedirs(args.out, exist_ok=True)
    json.dump(rows, open(os.path.join(args.out, "envelope.json"), "w"), indent=1)
    table = markdown(rows)
    open(os.path.join(args.out, "envelope.md"), "w").write(table)
    print(table)
    png = os.path.join(args.out, "envelope.png")
    plotted = plot(rows, png)
    if args.report:
        picture = None
        if plotted:  # this run's, not one left in --out
            picture = os.path.splitext(args.report)[0] + ".png"
            os.makedirs(os.path.dirname(os.path.abspath(picture)), exist_ok=True)
            if os.path.abspath(picture) != os.path.abspath(png):
                shutil.copyfile(png, picture)
        text = report_text(rows, args, sys.argv, os.path.basename(picture) if picture else None)
        print("envelope: wrote %s" % report.write(args.report, text))


if __name__ == "__main__":
    main()
