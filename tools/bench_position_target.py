#!/usr/bin/env python3
"""Cost of a control period with the position loop on (issue 13), measured on QEMU's mps2-an386.

The image tests/pil/target/pil_position.c (qemu-pil preset: -Os, link-time optimisation, as
the replay image of tools/bench_target.py) runs the paper's motor on the target through two
moves and a hold: every period pmstep_step() in the port's control interrupt, then
pmstep_position_update() (the two halves of pmstep_position_step()). The QEMU plugin of
bench_target.py counts the instructions of each call, from its first instruction to the one
its call returns to (callees included), in two runs of the same deterministic image; their sum
per period is the cost of pmstep_position_step(). Printed per kind of period: RUN in position
mode, RUN before the first move (speed mode: the estimate only), the alignments. Exits 1 when the
position-mode mean exceeds --max-mean (the issue's budget, 600 instructions).

--stepdir measures the STEP/DIR path instead: the same image in its STEP/DIR mode (--stepdir M)
follows the two moves as a step count at --microsteps per full step (default 16) on an emulated
16-bit counter; every period pmstep_step() in the control interrupt, then the image's after_step():
pmstep_stepdir_count() (inline), pmstep_position_update() (with the step tracker and the stall test
at its updates) and pmstep_stepdir_diag(), counted as one call. Printed per kind of period: RUN
following the steps at an update of the position loop (every PMSTEP_POSITION_DECIMATION-th period),
between updates, and every such period; the whole period is pmstep_step() + after_step(). Exits 1
when the mean of a period following the steps exceeds --stepdir-max-mean (default 700, the
regression guard of pil.stepdir_cost: no target was set for it).

--report FILE measures both and writes the two tables as Markdown (command, commit, date;
tools/report.py) into the section "position" of that page, the cost page of tools/bench_target.py
(docs/reports/cost.md), beside the budgets ctest's pil.position_cost and pil.stepdir_cost enforce
(tests/pil/CMakeLists.txt).

usage: tools/bench_position_target.py [--no-build] [--image ELF --work DIR] [--duration S] [--json FILE]
                                     [--max-mean N] [--stepdir [--microsteps M]] [--stepdir-max-mean N]
                                     [--report docs/reports/cost.md]
(ctest's pil.position_cost and pil.stepdir_cost run it with --no-build on the image of their own
cross build)
"""

import argparse
import json
import re
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_target as bt  # noqa: E402  (the same QEMU, plugin and helpers)
import report  # noqa: E402

IMAGE = bt.PIL / "tests" / "pil" / "target" / "pmstep-pil-position.elf"
# Kinds of period: key -> (label, the image's mode character, at an update (True), between (False) or either)
KINDS = {
    "p": ("RUN, position mode", "p", None),
    "r": ("RUN, speed mode (estimate only)", "r", None),
    "a": ("alignment and idle", "a", None),
}
STEPDIR_KINDS = {
    "p_update": ("RUN following steps, at an update", "p", True),
    "p_between": ("RUN following steps, between updates", "p", False),
    "p": ("RUN following steps, every period", "p", None),
    "r": ("RUN, speed mode (before following)", "r", None),
    "a": ("alignment and idle", "a", None),
}


def call_addresses(elf, callee, caller):
    """Entry of @p callee and the instruction after its call in @p caller."""
    nm = bt.run(["arm-none-eabi-nm", elf], stdout=subprocess.PIPE, text=True).stdout
    entry = next((int(l.split()[0], 16) for l in nm.splitlines() if l.split()[-1] == callee), None)
    if entry is None:
        sys.exit("bench_position_target: no symbol %s in %s (inlined?)" % (callee, elf))
    dis = bt.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf], stdout=subprocess.PIPE, text=True).stdout
    block = dis.split("<%s>:" % caller, 1)[1].split("\n\n", 1)[0]
    lines = [l for l in block.splitlines() if re.match(r"^\s+[0-9a-f]+:", l)]
    for i, l in enumerate(lines):
        if re.search(r"\bbl\s+[0-9a-f]+ <%s>" % re.escape(callee), l):
            return entry, int(lines[i + 1].split(":")[0], 16)
    sys.exit("bench_position_target: no call of %s in %s" % (callee, caller))


def counts(image, work, plugin, calls, prefix, image_args):
    """One run of @p image (semihosting arguments @p image_args after the files) per call of @p calls,
    {name: (entry, ret)}: the instructions of each period's call by name, the periods' modes and
    update flags, and the image's report line. The runs must agree on the periods."""
    modes, updates = work / ("%s-modes.txt" % prefix), work / ("%s-updates.txt" % prefix)
    values, seen, out = {}, [], ""
    for name, (entry, ret) in calls.items():
        path = work / ("%s-%s.txt" % (prefix, name))
        out = bt.qemu(
            image,
            [modes, *image_args, "--updates", updates],
            ["-plugin", "%s,entry=0x%x,ret=0x%x,out=%s" % (plugin, entry, ret, path)],
        ).stdout
        values[name] = [int(l) for l in path.read_text().splitlines() if not l.startswith("#")]
        seen.append((modes.read_text(), updates.read_text()))
    mode_text, update_text = seen[0]
    if any(s != seen[0] for s in seen) or any(len(v) != len(mode_text) for v in values.values()):
        sys.exit(
            "bench_position_target: %s: %s counts for %d periods, or the runs differ"
            % (prefix, ", ".join("%d %s" % (len(v), n) for n, v in values.items()), len(mode_text))
        )
    return values, mode_text, update_text, out.strip()


def kind_figures(kinds, modes, updates, values):
    """Min, mean and max per kind of period (@p kinds) of each call's counts @p values and of their sum
    ("total"); kinds without a period are left out."""
    figures = {}
    for key, (label, mode, at_update) in kinds.items():
        idx = [i for i, m in enumerate(modes) if m == mode and (at_update is None or (updates[i] == "u") == at_update)]
        if not idx:
            continue
        figures[key] = {"label": label, "periods": len(idx)}
        columns = {name: [v[i] for i in idx] for name, v in values.items()}
        columns["total"] = [sum(v[i] for v in values.values()) for i in idx]
        for name, c in columns.items():
            figures[key][name] = [min(c), statistics.fmean(c), max(c)]
    return figures


def fmt(v):
    return "%d / %.1f / %d" % (v[0], v[1], v[2])


def print_table(figures, columns):
    """@p figures as main() prints them: @p columns [(key, heading)] after the period and its count."""
    width = max([34] + [len(f["label"]) for f in figures.values()])
    print("%-*s %6s   " % (width, "period", "steps") + " ".join("%-22s" % h for _, h in columns))
    for f in figures.values():
        print("%-*s %6d   " % (width, f["label"], f["periods"]) + " ".join("%-22s" % fmt(f[k]) for k, _ in columns))


def markdown_rows(figures, columns):
    """@p figures as Markdown table rows, @p columns the keys after the period and its count."""
    return [
        f"| {f['label']} | {f['periods']} | " + " | ".join(fmt(f[k]) for k in columns) + " |" for f in figures.values()
    ]


def budget_line(what, mean, budget, enforced, max_mean, flag, test):
    """The verdict on @p mean against @p budget (ctest @p test's, @p enforced, if known; else this
    run's @p max_mean, given as @p flag)."""
    return (
        f"{what}: mean **{mean:.1f}** instructions, budget {budget:g} "
        f"({'ctest ' + test if enforced is not None else 'this run'}): "
        f"{'within' if mean <= budget else '**OVER**'}"
        + (f"; {'within' if mean <= max_mean else 'over'} this run's {flag} {max_mean:g}" if max_mean != budget else "")
        + "."
    )


def report_section(figures, image_report, max_mean, enforced, duration, argv, stepdir=None):
    """The section "position" of the cost page: @p figures as main() measures them (its --json),
    the image's own lines @p image_report, the tool's budget @p max_mean and the one ctest enforces
    @p enforced (None if unknown); with @p stepdir (main()'s --json "stepdir": its figures, image
    report, microsteps, max_mean and enforced budget) the STEP/DIR table after it."""
    budget = enforced if enforced is not None else max_mean
    lines = [
        report.section_header(
            "Control period with the position loop: `pmstep_position_step()`", "tools/bench_position_target.py", argv
        ),
        f"The image tests/pil/target/pil_position.c runs the paper's motor on the target through two moves and "
        f"a hold ({duration} s simulated); every period `pmstep_step()` in the control interrupt, then "
        "`pmstep_position_update()`. Exact instruction counts of each call (QEMU plugin, callees included); "
        "their sum per period is the cost of `pmstep_position_step()`. Min / mean / max per kind of period.",
        "",
    ]
    if image_report:
        lines += ["The image's own report:", "", "```", image_report, "```", ""]
    lines += [
        "| period | periods | `pmstep_step` | `pmstep_position_update` | sum (`pmstep_position_step`) |",
        "|---|---|---|---|---|",
    ]
    lines += markdown_rows(figures, ("step", "update", "total"))
    lines.append("")
    if "p" in figures:
        lines.append(
            budget_line(
                "Position-mode period",
                figures["p"]["total"][1],
                budget,
                enforced,
                max_mean,
                "--max-mean",
                "pil.position_cost",
            )
        )
    else:
        lines.append("No period in position mode: **no figure**.")
    if stepdir is not None:
        sd_budget = stepdir["enforced"] if stepdir["enforced"] is not None else stepdir["max_mean"]
        lines += [
            "",
            "### Following a STEP/DIR step count",
            "",
            f"The same image in its STEP/DIR mode: the two moves, planned by the SIL's step generator with the "
            f"drive's jerk, sampled each period and quantised to {stepdir['microsteps']} microsteps per full "
            "step, advance an emulated 16-bit step counter; following starts once the position is tracked. "
            "Every period `pmstep_step()` in the control interrupt, then the image's `after_step()`, one call: "
            "`pmstep_stepdir_count()` (inline), `pmstep_position_update()` (at an update, every "
            "`PMSTEP_POSITION_DECIMATION`-th period, the step tracker, the stall test and the position loop) "
            "and `pmstep_stepdir_diag()`. Min / mean / max per kind of period.",
            "",
        ]
        if stepdir["image_report"]:
            lines += ["The image's own report:", "", "```", stepdir["image_report"], "```", ""]
        lines += [
            "| period | periods | `pmstep_step` | after the step (count, `pmstep_position_update`, "
            "`pmstep_stepdir_diag`) | sum (the period) |",
            "|---|---|---|---|---|",
        ]
        lines += markdown_rows(stepdir["figures"], ("step", "after", "total"))
        lines.append("")
        if "p" in stepdir["figures"]:
            lines.append(
                budget_line(
                    "STEP/DIR period",
                    stepdir["figures"]["p"]["total"][1],
                    sd_budget,
                    stepdir["enforced"],
                    stepdir["max_mean"],
                    "--stepdir-max-mean",
                    "pil.stepdir_cost",
                )
            )
        else:
            lines.append("No period following the steps: **no figure**.")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--no-build", action="store_true", help="use the existing image")
    ap.add_argument("--image", type=Path, default=IMAGE, help="position image (default: build/qemu-pil's)")
    ap.add_argument("--work", type=Path, default=bt.BENCH, help="directory for the plugin and the counts")
    ap.add_argument("--duration", default="3", help="simulated seconds (default 3: two moves and a hold)")
    ap.add_argument("--json", help="also write the figures to this JSON file")
    ap.add_argument(
        "--max-mean",
        type=float,
        default=600.0,
        help="budget of a position-mode period, mean instructions (default 600)",
    )
    ap.add_argument(
        "--stepdir",
        action="store_true",
        help="measure the STEP/DIR path (the image's --stepdir) instead of the drive's own moves",
    )
    ap.add_argument("--microsteps", type=int, default=16, help="STEP/DIR microsteps per full step (default 16)")
    ap.add_argument(
        "--stepdir-max-mean",
        type=float,
        default=700.0,
        help="budget of a period following the steps, mean instructions (default 700)",
    )
    ap.add_argument(
        "--report",
        metavar="FILE",
        help='measure both and write the tables as Markdown into the section "position" of this '
        "page (docs/reports/cost.md)",
    )
    args = ap.parse_args()
    if not args.no_build:
        bt.run(["cmake", "--preset", "qemu-pil"], cwd=bt.ROOT, stdout=subprocess.DEVNULL)
        bt.run(
            ["cmake", "--build", "--preset", "qemu-pil", "--target", "pmstep-pil-position"],
            cwd=bt.ROOT,
            stdout=subprocess.DEVNULL,
        )
    args.work.mkdir(parents=True, exist_ok=True)
    plugin = args.work / "pil_insn_plugin.so"
    bt.run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-o", plugin, bt.PLUGIN_SRC])
    step = call_addresses(args.image, "pmstep_step", "Irq10_Handler")
    budgets = bt.budgets()
    figures, stepdir, verdicts, report_lines = None, None, [], ""
    if args.report or not args.stepdir:
        values, modes, updates, report_lines = counts(
            args.image,
            args.work,
            plugin,
            {"step": step, "update": call_addresses(args.image, "pmstep_position_update", "main")},
            "position",
            ["--duration", args.duration],
        )
        figures = kind_figures(KINDS, modes, updates, values)
        print("Control period with the position loop on a Cortex-M4F: QEMU mps2-an386, -Os + LTO")
        print(report_lines)
        print()
        print_table(
            figures,
            (("step", "pmstep_step min/mean/max"), ("update", "position_update"), ("total", "sum (position_step)")),
        )
        verdicts.append(("position-mode period", figures, args.max_mean))
    if args.report or args.stepdir:
        values, modes, updates, sd_lines = counts(
            args.image,
            args.work,
            plugin,
            {"step": step, "after": call_addresses(args.image, "after_step", "main")},
            "stepdir",
            ["--duration", args.duration, "--stepdir", args.microsteps],
        )
        stepdir = {
            "figures": kind_figures(STEPDIR_KINDS, modes, updates, values),
            "image_report": sd_lines,
            "microsteps": args.microsteps,
            "max_mean": args.stepdir_max_mean,
            "enforced": budgets["stepdir"],
        }
        if figures is not None:
            print()
        print(
            "Control period following a STEP/DIR step count (%d microsteps per full step) on a Cortex-M4F: "
            "pmstep_step, then after_step (the count, pmstep_position_update, pmstep_stepdir_diag)" % args.microsteps
        )
        print(sd_lines)
        print()
        print_table(
            stepdir["figures"],
            (("step", "pmstep_step min/mean/max"), ("after", "after_step"), ("total", "sum (period)")),
        )
        verdicts.append(("STEP/DIR period", stepdir["figures"], args.stepdir_max_mean))
    if args.json:
        Path(args.json).write_text(
            json.dumps(dict(figures or {}, **({"stepdir": stepdir} if stepdir else {})), indent=1)
        )
    if args.report:  # written now, printed last
        text = report_section(
            figures, report_lines, args.max_mean, budgets["position"], args.duration, sys.argv, stepdir
        )
        wrote = "bench_position_target: wrote %s" % report.write_section(
            args.report, bt.COST_TITLE, "position", text, bt.COST_WHAT, bt.COST_SECTIONS
        )
    ok = True
    for what, figs, max_mean in verdicts:
        if "p" not in figs:
            print("no %s" % what)
            ok = False
            continue
        mean = figs["p"]["total"][1]
        print(
            "%s: mean %.1f instructions, budget %.0f: %s"
            % (what, mean, max_mean, "within" if mean <= max_mean else "OVER")
        )
        ok = ok and mean <= max_mean
    if args.report:
        print(wrote)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
