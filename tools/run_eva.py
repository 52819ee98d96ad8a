#!/usr/bin/env python3
"""Frama-C EVA on the control core: one harness of tests/eva per run, with its figures.

  tools/run_eva.py init|paper|features|known_load|step   (ctest eva.<name>)

init: pmstep_init over every finite configuration (tests/eva/eva_init.c).
paper, features, known_load: pmstep_step from init with that configuration through any
sequence of commands and steps, every measurement any float including NaN and +/-Inf
(tests/eva/eva_step.c, configurations in tests/eva/eva_configs.h); step: the three in one
analysis, each state partition kept apart, so its statement figure is their union.

Prints the alarms, the status of the harness's ACSL assertions, the statements reached (whole
program and in the step's functions) and the time. Fails if an alarm is not one listed in
tests/eva/expected_alarms.txt for this harness (keyed by file, alarm kind and assertion text,
not line numbers), or if an assertion is invalid. Unknown assertions are reported, not failed:
README, "Reliability", says which and why.
"""

import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORE = [
    "pmstep_core",
    "pmstep_lifecycle",
    "pmstep_config",
    "pmstep_derive",
    "pmstep_control",
    "pmstep_detect",
    "pmstep_continuity",
    "pmstep_actuate",
    "pmstep_ref",
    "pmstep_angle",
    "pmstep_commission",
    "pmstep_identify",
    "pmstep_observer",
    "pmstep_law",
    "pmstep_hold",
    "pmstep_standstill",
    "pmstep_weakening",
    "pmstep_presets",
]
# Precision: loops of the configuration check unrolled (init evaluates the configuration exactly),
# init's return states kept apart by status (PMSTEP_OK or not: the instance is set up only on
# the first), the step's paths kept apart up to 300 states.
OPTIONS = [
    "-eva",
    "-warn-special-float",
    "none",
    "-eva-precision",
    "3",
    "-eva-auto-loop-unroll",
    "128",
    "-eva-slevel-function",
    "pmstep_check_settings:500",
    "-eva-split-return-function",
    "pmstep_init:0",
    "-eva-slevel-function",
    "pmstep_step:300",
    "-eva-slevel-function",
    "main:300",
]
HARNESSES = {
    "init": ("eva_init.c", None),
    "paper": ("eva_step.c", "eva_paper_config"),
    "features": ("eva_step.c", "eva_features_config"),
    "sensed": ("eva_step.c", "eva_sensed_config"),
    "known_load": ("eva_step.c", "eva_known_load_config"),
    "step": ("eva_step.c", None),  # the four configurations in one analysis: the union of what they reach
}
# The functions of the step (pmstep_step and what it calls) for the statement figure.
STEP_FUNCTIONS = None


def expected_alarms(name):
    allowed = set()
    path = os.path.join(ROOT, "tests", "eva", "expected_alarms.txt")
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                harness, file, kind, text = [p.strip() for p in line.split("|", 3)]
                if harness == name:
                    allowed.add((file, kind, text))
    return allowed


def main():
    if len(sys.argv) != 2 or sys.argv[1] not in HARNESSES:
        sys.exit("usage: tools/run_eva.py " + "|".join(HARNESSES))
    name = sys.argv[1]
    if subprocess.run(["sh", "-c", "command -v frama-c"], capture_output=True).returncode != 0:
        print("run_eva: frama-c not installed (tools/install_deps.sh installs frama-c-base): skipped")
        return 77
    harness, config = HARNESSES[name]
    cpp = "-Ifirmware/include -Ifirmware/src -Itests/eva -Itests/include" + (
        f" -DEVA_CONFIG={config}" if config else ""
    )
    cmd = (
        ["frama-c", "-cpp-extra-args=" + cpp, "tests/eva/" + harness]
        + [f"firmware/src/{c}.c" for c in CORE]
        + OPTIONS
        + ["-then", "-metrics", "-metrics-eva-cover"]
    )
    start = time.monotonic()
    # frama-c resolves relative paths against $PWD, not the working directory: set both.
    run = subprocess.run(cmd, cwd=ROOT, env=dict(os.environ, PWD=ROOT), capture_output=True, text=True, check=False)
    seconds = time.monotonic() - start
    log = run.stdout + run.stderr
    os.makedirs(os.path.join(ROOT, "build", "eva"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "eva", name + ".log"), "w", encoding="utf-8") as f:
        f.write(log)
    if run.returncode != 0 or "ANALYSIS SUMMARY" not in log:
        print(log[-4000:])
        sys.exit(f"run_eva: frama-c failed ({run.returncode}); log in build/eva/{name}.log")

    # Alarms: "[eva:alarm] file:line: Warning: \n  kind. assert text;" (assertions of the harness
    # are reported as "assertion 'x' got status ...", counted apart).
    alarms = []
    for m in re.finditer(r"\[eva:alarm\] ([^:]+):\d+: Warning: \n((?:  .*\n)+)", log):
        body = " ".join(m.group(2).split())
        if body.startswith("assertion '"):
            continue
        kind, _, text = body.partition(". ")
        alarms.append((os.path.basename(m.group(1)), kind, text))
    allowed = expected_alarms(name)
    unexpected = [a for a in alarms if a not in allowed]
    statuses = {}
    for m in re.finditer(r"assertion '(\w+)' got (?:final )?status (\w+)", log):
        statuses[m.group(1)] = m.group(2)
    valid = re.search(r"Assertions\s+(\d+) valid\s+(\d+) unknown\s+(\d+) invalid", log)
    reached = re.search(r"(\d+) statements reached \(out of (\d+)\)", log)
    per_function = dict(
        (f, (int(a), int(b))) for f, a, b in re.findall(r"^  (\w+): (\d+) stmts out of (\d+)", log, re.M)
    )
    step = [
        "pmstep_step",
        "output_off",
        "trip",
        "realign",
        "pmstep_clear_dynamic_state",
        "check_measurements",
        "check_optional_inputs",
        "offset_calibration_stage",
        "commission_stage",
        "commissioned_model",
        "finish_commissioning",
        "identify_stage",
        "calibrated_sample",
        "alignment_stage",
        "supervise_stage",
        "reference_current_over_period",
        "compensation_input",
        "bridge_on_stages",
    ]
    step_reached = sum(per_function.get(f, (0, 0))[0] for f in step)
    step_total = sum(per_function.get(f, (0, 0))[1] for f in step)
    unreached = re.search(r"Unreached functions \(\d+\) =\n((?:    .*\n)+)", log)
    print(
        f"run_eva: {name}: {len(alarms)} alarm(s) ({len(alarms) - len(unexpected)} recorded in "
        f"tests/eva/expected_alarms.txt), {seconds:.1f} s"
    )
    if reached:
        print(
            f"run_eva: {name}: statements reached {reached.group(1)} of {reached.group(2)} in the analysed functions;"
            f" in pmstep_step and its own helpers (pmstep_core.c's, pmstep_clear_dynamic_state):"
            f" {step_reached} of {step_total}"
        )
    if unreached:
        print(f"run_eva: {name}: functions not reached: " + " ".join(unreached.group(1).split()))
    if statuses:
        print(f"run_eva: {name}: assertions: " + ", ".join(f"{k} {v}" for k, v in statuses.items()))
    elif valid:
        print(
            f"run_eva: {name}: assertions: {valid.group(1)} valid, {valid.group(2)} unknown, {valid.group(3)} invalid"
        )
    failed = False
    for a in unexpected:
        print(f"run_eva: {name}: alarm not in the record: {a[0]}: {a[1]}: {a[2]}")
        failed = True
    if valid and int(valid.group(3)) > 0:
        print(f"run_eva: {name}: an assertion is invalid")
        failed = True
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
