#!/usr/bin/env python3
"""Fault injection in the SIL: each fault of FAULTS on the paper's motor (paper mode, ideal chain)
and on the public presets (robust design behind the realistic chain of mc_preset.py), one
pmstep-sil run each; what the firmware latched, how long after the injection, and whether the
bridge was off at the end. Writes the table as a report (command, commit, date) and, with
--check, exits 1 unless every fault marked as one to detect was detected with the bridge off.

Usage: tools/fault_injection.py --sil build/host-release/sil/pmstep-sil --tune build/host-release/sil/pmstep-tune
                                [--motors paper,17hs4401,...] [--report docs/reports/fault-injection.md] [--check]
"""

import argparse
import configparser
import json
import os
import subprocess
import sys
import tempfile

import mc_preset
import report

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PRESETS = os.path.join(ROOT, "sil", "scenarios", "motors")
PUBLIC_PRESETS = ("17hs4401", "bj42d29", "as1050")


class Fault:
    """One injected fault: the --set items for a motor (@p sets(motor) -> list), whether it is
    injected at the start or in RUN at the motor's run time, and whether the firmware must detect
    it (False: shown as it comes out, with the reason in @p note)."""

    def __init__(self, label, sets, in_run=False, must_detect=True, note=""):
        self.label = label
        self.sets = sets
        self.in_run = in_run
        self.must_detect = must_detect
        self.note = note


def _at(key, motor):
    return [f"{key}={motor['run_time_s']:.6g}"]


FAULTS = [
    Fault("motor disconnected (both windings open)", lambda m: ["faults.open_phase=both"]),
    Fault("winding a open", lambda m: ["faults.open_phase=a"]),
    Fault("winding b open", lambda m: ["faults.open_phase=b"]),
    Fault(
        "winding a breaks in RUN", lambda m: ["faults.open_phase=a"] + _at("faults.open_phase_time_s", m), in_run=True
    ),
    Fault(
        "winding b breaks in RUN", lambda m: ["faults.open_phase=b"] + _at("faults.open_phase_time_s", m), in_run=True
    ),
    Fault("current sensor a open", lambda m: ["faults.sensor=open", "faults.sensor_phase=a"]),
    Fault(
        "current sensor b fails open in RUN",
        lambda m: ["faults.sensor=open", "faults.sensor_phase=b"] + _at("faults.sensor_time_s", m),
        in_run=True,
    ),
    Fault(
        "current sensor a sticks in RUN",
        lambda m: ["faults.sensor=stuck", "faults.sensor_phase=a"] + _at("faults.sensor_time_s", m),
        in_run=True,
    ),
    Fault(
        "current sensor b sticks in RUN",
        lambda m: ["faults.sensor=stuck", "faults.sensor_phase=b"] + _at("faults.sensor_time_s", m),
        in_run=True,
    ),
    Fault(
        "current ADC at its rail (phase a)",
        lambda m: ["sensors.adc_bits=12", f"sensors.offset_a_A={2.0 * m['current_span_A']:.6g}"],
    ),
    Fault(
        "resistance 10x the datasheet's (wrong motor, bad contact)",
        lambda m: [f"motor.resistance_Ohm={10.0 * m['resistance_Ohm']:.6g}"],
    ),
    Fault("bus at 50 %", lambda m: [f"run.bus_voltage_V={0.5 * m['bus_V']:.6g}"]),
    Fault(
        "load step of 3x the holding torque in RUN",
        lambda m: ["load.type=step", f"load.torque_Nm={3.0 * m['holding_Nm']:.6g}"] + _at("load.step_time_s", m),
        in_run=True,
    ),
    Fault("locked rotor", lambda m: [f"motor.inertia_kgm2={1e6 * m['inertia_kgm2']:.6g}"]),
    Fault(
        "motor disconnected in RUN (both windings open)",
        lambda m: ["faults.open_phase=both"] + _at("faults.open_phase_time_s", m),
        in_run=True,
        must_detect=False,
        note="with i_d* = 0 (paper mode) the zero currents of both phases are what an unloaded motor draws: "
        "T_L-hat takes them as no load and the law asks for no current to check against; a magnetising "
        "current (robust mode) asks for it",
    ),
    Fault(
        "both current sensors fail open in RUN",
        lambda m: ["faults.sensor=open", "faults.sensor_phase=both"] + _at("faults.sensor_time_s", m),
        in_run=True,
        must_detect=False,
        note="as above: two zero readings at once look like an unloaded motor",
    ),
    Fault(
        "current sensor gain -30 % (phase a)",
        lambda m: ["sensors.gain_error_a=-0.3"],
        must_detect=False,
        note="a gain mismatch robust mode's commissioning measures and corrects; detected where it is not",
    ),
]


def read_ini(path):
    ini = configparser.ConfigParser(inline_comment_prefixes=(";",), interpolation=None, strict=False)
    ini.optionxform = str
    ini.read(path)
    return ini


def speed_points(ini):
    """The (t, w) points of a scenario's [speed] points."""
    text = " ".join(ini.get("speed", "points").split())
    return [tuple(float(v) for v in p.split(":")) for p in text.replace(" ", "").split(",") if p]


def plateau_time(points, run_start_s):
    """The middle of the first segment after RUN starts where the speed is constant and not 0."""
    for (t0, w0), (t1, w1) in zip(points, points[1:]):
        if t0 >= run_start_s and w0 == w1 and w0 != 0.0:
            return 0.5 * (t0 + t1)
    raise ValueError("no constant, non-zero speed segment after RUN starts")


def paper_motor(work):
    scenario = os.path.join(ROOT, "sil", "scenarios", "paper.ini")
    preset = mc_preset.read_preset(mc_preset.PAPER_PRESET)
    return {
        "name": "paper",
        "mode": "paper mode, ideal chain",
        "scenario": scenario,
        "sets": [],
        "run_time_s": 1.0,
        "current_span_A": 16.5,
        "resistance_Ohm": 3.0,
        "bus_V": 48.0,
        "holding_Nm": preset["holding_torque_Nm"],
        "inertia_kgm2": 0.01,
    }


def preset_motor(name, tune, work):
    path = os.path.join(PRESETS, f"{name}.ini")
    preset = mc_preset.read_preset(path)
    chain = mc_preset.chain_sets(preset)
    scenario = os.path.join(work, f"{name}.ini")
    cmd = [tune, "--motor", path, "--robust", "--write-ini", scenario]
    for item in chain:
        cmd += ["--set", item]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    ini = read_ini(scenario)
    run_start_s = float(ini.get("controller.commissioning", "offset_calibration_time_s")) + float(
        ini.get("controller.alignment", "c_align_time_s")
    )
    return {
        "name": name,
        "mode": "robust mode, realistic chain",
        "scenario": scenario,
        "sets": chain,
        "run_time_s": plateau_time(speed_points(ini), run_start_s),
        "current_span_A": mc_preset.ADC_SPAN_RATED * preset["rated_current_A"],
        "resistance_Ohm": preset["resistance_Ohm"],
        "bus_V": preset["bus_voltage_V"],
        "holding_Nm": preset["holding_torque_Nm"],
        "inertia_kgm2": float(ini.get("motor", "inertia_kgm2")),
    }


def run_case(sil, motor, fault, work):
    out = os.path.join(work, f"{motor['name']}-{FAULTS.index(fault)}")
    cmd = [sil, "--quiet", "--no-csv", "--out", out, "--scenario", motor["scenario"]]
    for item in motor["sets"] + fault.sets(motor):
        cmd += ["--set", item]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    try:
        with open(os.path.join(out, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError) as err:
        raise RuntimeError(
            f"pmstep-sil gave no summary (exit {proc.returncode}): {' '.join(cmd)}\n{proc.stderr}"
        ) from err
    injected_s = motor["run_time_s"] if fault.in_run else 0.0
    code = summary["fault"]["name"]
    detected = code != "NONE"
    loss_s = summary["robustness"]["loss_of_control_time_s"]
    return {
        "fault": fault,
        "code": code,
        "detected": detected,
        "bridge_off": summary["final_mode"] == "FAULT",
        "latency_ms": 1e3 * (summary["fault"]["time_s"] - injected_s) if detected else None,
        "loss_s": loss_s if loss_s is not None and loss_s >= 0 else None,
        "max_current_A": summary["max_abs_phase_current_a"],
    }


def passed(result):
    return not result["fault"].must_detect or (result["detected"] and result["bridge_off"])


def report_text(motors, results, argv):
    lines = [
        report.header("Fault injection", "tools/fault_injection.py", argv),
        "Each fault is injected into the SIL's hardware (`[faults]` and other scenario keys) at the start "
        "or, in RUN, in the middle of the first constant-speed segment of the motor's profile. *Latency* "
        "is the time from the injection to the fault the firmware latched; *bridge off* that the run "
        "ended in FAULT. Faults marked \u2020 are shown as they come out; the others must be detected.",
        "",
    ]
    for motor in motors:
        lines += [
            f"## {motor['name']} ({motor['mode']})",
            "",
            f"RUN faults injected at {motor['run_time_s']:.3f} s.",
            "",
            "| fault | latched | latency (ms) | bridge off | largest phase current (A) |",
            "|---|---|---|---|---|",
        ]
        for r in results[motor["name"]]:
            f = r["fault"]
            latency = f"{r['latency_ms']:.1f}" if r["latency_ms"] is not None else "-"
            label = f.label + ("" if f.must_detect else " \u2020")
            code = (
                r["code"]
                if r["detected"]
                else ("none" + (f", control lost at {r['loss_s']:.3f} s" if r["loss_s"] is not None else ""))
            )
            lines.append(
                f"| {label} | {code} | {latency} | {'yes' if r['bridge_off'] else 'no'} | {r['max_current_A']:.2f} |"
            )
        lines.append("")
    notes = [f for f in FAULTS if f.note]
    if notes:
        lines += ["\u2020 Not required to be detected:", ""] + [f"- {f.label}: {f.note}." for f in notes] + [""]
    return "\n".join(lines)


def main(argv=None):
    argv = sys.argv if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sil", required=True)
    parser.add_argument("--tune", required=True)
    parser.add_argument("--motors", default="paper," + ",".join(PUBLIC_PRESETS))
    parser.add_argument("--report", help="write the table here (Markdown)")
    parser.add_argument(
        "--check", action="store_true", help="exit 1 unless every fault to detect was detected with the bridge off"
    )
    args = parser.parse_args(argv[1:])
    with tempfile.TemporaryDirectory(prefix="pmstep-faults-") as work:
        motors = []
        for name in args.motors.split(","):
            motors.append(paper_motor(work) if name == "paper" else preset_motor(name, args.tune, work))
        results = {}
        for motor in motors:
            results[motor["name"]] = [run_case(args.sil, motor, f, work) for f in FAULTS]
            missed = [r for r in results[motor["name"]] if not passed(r)]
            print(
                f"fault_injection: {motor['name']}: {len(FAULTS) - len(missed)} of {len(FAULTS)} as required"
                + "".join(f"\n  MISSED: {r['fault'].label} ({r['code']})" for r in missed)
            )
    text = report_text(motors, results, argv)
    if args.report:
        print(f"fault_injection: wrote {report.write(args.report, text)}")
    else:
        print(text)
    if args.check and any(not passed(r) for rs in results.values() for r in rs):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
