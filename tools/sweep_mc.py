"""The motor sweep's Monte Carlo sample (tools/sweep_motors.py --mc-sample N): for a random sample of
the population, a short speed campaign of tools/monte_carlo.py --preset on each motor, the way
tools/mc_preset.py runs one on a public preset: robust mode designed for the motor (told the plant's
J and F) behind the realistic chain, the plant's constants, the chain's errors and the load drawn
around it. What counts is the class of each case, above all a silent failure: a loss of control
with no fault latched within the latency bound (monte_carlo.py's classes).
"""

import json
import os
import random
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
CLASSES = ("success", "detected", "silent", "out_of_spec", "crashed")
SAMPLE_SEED = 2  # apart from the sweep's own --sample (seed 1)


def sample(population, count):
    """@p count motors of @p population, drawn with SAMPLE_SEED."""
    return random.Random(SAMPLE_SEED).sample(population, min(count, len(population)))


def run_motor(motor, sil, tune, work, cases, jobs):
    """One motor's campaign: {'motor', 'counts' (per class) or 'error', 'nonfinite'}."""
    out = os.path.join(work, "mc", motor["name"])
    cmd = [
        sys.executable,
        os.path.join(HERE, "monte_carlo.py"),
        "--sil",
        sil,
        "--tune",
        tune,
        "--preset",
        motor["path"],
        "--out",
        out,
        "--cases",
        str(cases),
        "--engine",
        "threads",
        "--jobs",
        str(jobs),
        "--no-plots",
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    try:
        with open(os.path.join(out, "summary.json")) as f:
            summary = json.load(f)
    except (OSError, ValueError):
        lines = (proc.stderr.strip() or proc.stdout.strip() or "no output").splitlines()
        return {"motor": motor, "error": f"exit {proc.returncode}: {lines[-1]}"}
    return {
        "motor": motor,
        "counts": {c: int(summary["counts"].get(c, 0)) for c in CLASSES},
        "nonfinite": int(summary.get("nonfinite_cases", 0)),
        "silent_seeds": [w["seed"] for w in summary.get("worst_cases", []) if w.get("class") == "silent"],
    }


def run_sample(motors, sil, tune, work, cases, jobs):
    """Every motor's campaign in turn (each campaign runs its cases on @p jobs workers)."""
    results = []
    for k, motor in enumerate(motors, 1):
        results.append(run_motor(motor, sil, tune, work, cases, jobs))
        print(f"sweep_motors: Monte Carlo {k} of {len(motors)} motors", file=sys.stderr, flush=True)
    return results


def totals(results):
    """Cases per class over the sample, motors with a silent failure, motors whose campaign did not run."""
    counts = {c: sum(r.get("counts", {}).get(c, 0) for r in results) for c in CLASSES}
    silent_motors = [r["motor"]["name"] for r in results if r.get("counts", {}).get("silent", 0) > 0]
    not_run = [r for r in results if "error" in r]
    return counts, silent_motors, not_run


def summary_line(results, cases):
    counts, silent_motors, not_run = totals(results)
    run = len(results) - len(not_run)
    return (
        f"Monte Carlo sample: {run} motors x {cases} cases: "
        + ", ".join(f"{c} {counts[c]}" for c in CLASSES)
        + (f"; silent failures on {', '.join(silent_motors)}" if silent_motors else "")
        + (f"; {len(not_run)} campaigns did not run" if not_run else "")
    )


def report_lines(results, cases):
    """The report's section: the classes over the sample and each motor's row."""
    counts, silent_motors, not_run = totals(results)
    total = sum(counts.values())
    out = [
        "",
        "## Monte Carlo sample",
        "",
        f"A speed campaign of {cases} cases (tools/monte_carlo.py --preset) on each of {len(results)} motors "
        f"drawn from the population (seed {SAMPLE_SEED}): robust mode designed for the motor, told its J and F, "
        "behind the realistic chain; the plant's constants, the chain's errors and the load drawn around it as "
        "for the public presets (tools/mc_preset.py). A *silent* case lost control with no fault latched within "
        "0.05 s.",
        "",
        "| class | cases | % |",
        "|---|---|---|",
    ]
    for c in CLASSES:
        out.append(f"| {c} | {counts[c]} | {100.0 * counts[c] / max(1, total):.1f} |")
    out += ["", f"Motors with a silent failure: {', '.join(silent_motors) if silent_motors else 'none'}."]
    if not_run:
        out += [
            "",
            "Campaigns that did not run: " + "; ".join(f"{r['motor']['name']} ({r['error']})" for r in not_run) + ".",
        ]
    out += [
        "",
        "| motor | frame | p | bus (V) | " + " | ".join(CLASSES) + " |",
        "|---|---|---|---|" + "---|" * len(CLASSES),
    ]
    for r in sorted(results, key=lambda r: r["motor"]["name"]):
        m = r["motor"]
        cells = [str(r["counts"][c]) for c in CLASSES] if "counts" in r else ["-"] * len(CLASSES)
        out.append(
            f"| {m['name']} | {m['frame']} | {m['pole_pairs']} | {m['bus_voltage_V']:g} | " + " | ".join(cells) + " |"
        )
    return out
