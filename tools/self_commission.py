#!/usr/bin/env python3
"""The drive's self-commissioning (firmware/design/include/pmstep/pmstep_calibrate.h) on every public
preset in the SIL, against the design from the datasheet: pmstep-tune --self-commission runs the
drive's own calibration on the preset's plant, told only the rated current, the pole pairs and whether
the motor has a detent (the paper's has none), then validates the drive's design (--validate: ramps to
+-80 % and +-5 % of the top speed, half the holding torque stepped on at 50 % and 5 % of it). Each
preset on its own measurement chain (the preset's) and on the realistic chain of the Monte Carlo
(tools/mc_preset.py: 12-bit ADC, offsets, noise, a switching bridge with 1 us dead time).

Prints, and with --report writes, per preset and chain: R, L, k_M, J, F as measured (against the
plant's and the datasheet design's), the design figures both ways, the runs and simulated time the
calibration took, and whether the drive's design passed the validation. --check: exit 1 unless every
calibration ended and every drive design passed.

Usage: tools/self_commission.py --tune build/host-release/sil/pmstep-tune [--report FILE] [--check]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import mc_preset
import report

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PRESETS = ("paper", "17hs4401", "bj42d29", "as1050")
NO_DETENT = ("paper",)  # motors without a detent torque: the user says so
MOTOR_ROWS = [
    ("resistance_Ohm", "R", "Ohm"),
    ("inductance_H", "L", "H"),
    ("torque_constant_Nm_A", "k_M", "N m/A"),
    ("inertia_kgm2", "J", "kg m^2"),
    ("friction_Nms_rad", "F", "N m s/rad"),
]
DESIGN_ROWS = [
    ("top_speed_rad_s", "top speed", "rad/s"),
    ("observer_bandwidth_rad_s", "observer bandwidth", "rad/s"),
    ("speed_gain_per_s", "speed gain k_w", "1/s"),
    ("s_align_voltage_V", "alignment voltage", "V"),
    ("c_align_time_s", "t_c", "s"),
    ("max_phase_current_A", "overcurrent trip", "A"),
]


def plant_motor(preset):
    ini = mc_preset._ini(os.path.join(ROOT, "sil", "scenarios", "motors", f"{preset}.ini"))
    motor = {k: float(ini.get("motor", k)) for k, _, _ in MOTOR_ROWS}
    rated = float(ini.get("datasheet", "rated_current_A"))
    return motor, rated


def run(tune, preset, chain, work):
    path = os.path.join(ROOT, "sil", "scenarios", "motors", f"{preset}.ini")
    summary = os.path.join(work, f"{preset}-{chain}.json")
    motor, rated = plant_motor(preset)
    cmd = [
        tune,
        "--motor",
        path,
        "--robust",
        "--self-commission",
        "--detent-fraction",
        "0" if preset in NO_DETENT else "0.05",
        "--validate",
        "--summary",
        summary,
    ]
    if chain == "realistic":
        for item in mc_preset.chain_sets({"rated_current_A": rated}):
            cmd += ["--set", item]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    try:
        with open(summary) as f:
            s = json.load(f)
    except (OSError, ValueError):
        s = None
    return {
        "preset": preset,
        "chain": chain,
        "command": cmd,
        "rc": proc.returncode,
        "summary": s,
        "plant": motor,
        "stdout": proc.stdout,
    }


def pct(a, b):
    return f"{100.0 * (a / b - 1.0):+.2f} %" if b else "-"


def render(results, argv):
    lines = [
        report.header(
            "Self-commissioning",
            "tools/self_commission.py",
            argv,
            "The drive's own calibration (`pmstep_calibrate.h`, the `CALIBRATE` request) run in the SIL on each public "
            "preset's plant, told only the rated current, the pole pairs and whether the motor has a detent torque; "
            "its design beside the one `pmstep-tune` makes from the datasheet, and validated the same way. *Preset "
            "chain*: the preset's own measurement chain and bridge; *realistic*: the Monte Carlo's (12-bit ADC, "
            "offsets, noise, a switching bridge with 1 us dead time). How it works: "
            "[design chapter 19](../design/19-self-commissioning.md).",
        )
    ]
    lines += [
        "| Preset | Chain | Outcome | Runs | Simulated | R | L | k_M | J | F | Drive's design validated |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        s = r["summary"]
        cal = (s or {}).get("self_commissioning")
        if cal is None:
            lines.append(f"| {r['preset']} | {r['chain']} | no summary (exit {r['rc']}) | | | | | | | | |")
            continue
        drive = cal.get("drive")
        errs = [
            pct(drive[k], r["plant"][k]) if drive and r["plant"][k] else (f"{drive[k]:.3g}" if drive else "-")
            for k, _, _ in MOTOR_ROWS
        ]
        outcome = (
            "done"
            if cal["status"] == 0
            else f"failed: {cal['text']}" + (f" ({cal['fault']})" if cal.get("fault", "NONE") != "NONE" else "")
        )
        validated = (
            "pass"
            if s.get("synchronous") and s.get("passed")
            else ("synchronous, envelope missed" if s.get("synchronous") else ("fail" if drive else "-"))
        )
        lines.append(
            f"| {r['preset']} | {r['chain']} | {outcome} | {cal['runs']} | {cal['simulated_s']:.2f} s | "
            + " | ".join(errs)
            + f" | {validated} |"
        )
    lines += [
        "",
        "R, L, k_M, J: the drive's measurement against the plant's value; F: the value identified (the "
        "plants' F is small beside J/T_s, and the paper's is 0).",
        "",
    ]
    for r in results:
        s = r["summary"]
        cal = (s or {}).get("self_commissioning")
        if not cal or not cal.get("drive"):
            continue
        ds, drive = cal["datasheet"], cal["drive"]
        lines += [
            f"## {r['preset']}, {r['chain']} chain",
            "",
            "| | Unit | Plant | Datasheet design | Drive's design | Drive against datasheet |",
            "|---|---|---|---|---|---|",
        ]
        for key, name, unit in MOTOR_ROWS:
            lines.append(
                f"| {name} | {unit} | {r['plant'][key]:.5g} | {ds[key]:.5g} | {drive[key]:.5g} | "
                f"{pct(drive[key], ds[key])} |"
            )
        for key, name, unit in DESIGN_ROWS:
            lines.append(f"| {name} | {unit} | | {ds[key]:.5g} | {drive[key]:.5g} | {pct(drive[key], ds[key])} |")
        lines.append("")
    return "\n".join(lines)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tune", required=True)
    ap.add_argument("--report")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args(argv[1:])
    results = []
    with tempfile.TemporaryDirectory(prefix="pmstep-self-commission-") as work:
        for preset in PRESETS:
            for chain in ("preset", "realistic"):
                r = run(a.tune, preset, chain, work)
                results.append(r)
                cal = (r["summary"] or {}).get("self_commissioning") or {}
                print(
                    f"{preset:9s} {chain:9s} {cal.get('text', 'no summary'):30s} runs {cal.get('runs', '-')}, "
                    f"validation {'passed' if (r['summary'] or {}).get('passed') else 'FAILED'}",
                    flush=True,
                )
    text = render(results, argv)
    if a.report:
        report.write(a.report, text)
        print(f"self_commission: wrote {a.report}")
    ok = all(
        ((r["summary"] or {}).get("self_commissioning") or {}).get("status") == 0 and (r["summary"] or {}).get("passed")
        for r in results
    )
    return 0 if ok or not a.check else 1


if __name__ == "__main__":
    sys.exit(main())
