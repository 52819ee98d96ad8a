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

--report FILE writes the table as Markdown (command, commit, date; tools/report.py) into the
section "position" of that page, the cost page of tools/bench_target.py (docs/reports/cost.md),
beside the budget ctest's pil.position_cost enforces (tests/pil/CMakeLists.txt).

usage: tools/bench_position_target.py [--no-build] [--image ELF --work DIR] [--duration S] [--json FILE]
                                     [--max-mean N] [--report docs/reports/cost.md]
(ctest's pil.position_cost runs it with --no-build on the image of its own cross build)
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
KINDS = {"p": "RUN, position mode", "r": "RUN, speed mode (estimate only)", "a": "alignment and idle"}


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


def counts(image, work, plugin, entry, ret, name, duration):
    modes = work / "position-modes.txt"
    steps = work / ("position-%s.txt" % name)
    out = bt.qemu(image, [modes, "--duration", duration],
                  ["-plugin", "%s,entry=0x%x,ret=0x%x,out=%s" % (plugin, entry, ret, steps)]).stdout
    values = [int(l) for l in steps.read_text().splitlines() if not l.startswith("#")]
    return values, modes.read_text(), out.strip()


def report_section(figures, image_report, max_mean, enforced, duration, argv):
    """The section "position" of the cost page: @p figures as main() measures them (its --json),
    the image's own lines @p image_report, the tool's budget @p max_mean and the one ctest enforces
    @p enforced (None if unknown)."""
    budget = enforced if enforced is not None else max_mean
    lines = [report.section_header("Control period with the position loop: `pmstep_position_step()`",
                                   "tools/bench_position_target.py", argv),
             f"The image tests/pil/target/pil_position.c runs the paper's motor on the target through two moves and "
             f"a hold ({duration} s simulated); every period `pmstep_step()` in the control interrupt, then "
             "`pmstep_position_update()`. Exact instruction counts of each call (QEMU plugin, callees included); "
             "their sum per period is the cost of `pmstep_position_step()`. Min / mean / max per kind of period.", ""]
    if image_report:
        lines += ["The image's own report:", "", "```", image_report, "```", ""]
    lines += ["| period | periods | `pmstep_step` | `pmstep_position_update` | sum (`pmstep_position_step`) |",
              "|---|---|---|---|---|"]

    def fmt(v):
        return "%d / %.1f / %d" % (v[0], v[1], v[2])
    for f in figures.values():
        lines.append(f"| {f['label']} | {f['periods']} | {fmt(f['step'])} | {fmt(f['update'])} | {fmt(f['total'])} |")
    lines.append("")
    if "p" in figures:
        mean = figures["p"]["total"][1]
        lines.append(f"Position-mode period: mean **{mean:.1f}** instructions, budget {budget:g} "
                     f"({'ctest pil.position_cost' if enforced is not None else 'this run'}): "
                     f"{'within' if mean <= budget else '**OVER**'}"
                     + (f"; {'within' if mean <= max_mean else 'over'} this run's --max-mean {max_mean:g}"
                        if max_mean != budget else "") + ".")
    else:
        lines.append("No period in position mode: **no figure**.")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--no-build", action="store_true", help="use the existing image")
    ap.add_argument("--image", type=Path, default=IMAGE, help="position image (default: build/qemu-pil's)")
    ap.add_argument("--work", type=Path, default=bt.BENCH, help="directory for the plugin and the counts")
    ap.add_argument("--duration", default="3", help="simulated seconds (default 3: two moves and a hold)")
    ap.add_argument("--json", help="also write the figures to this JSON file")
    ap.add_argument("--max-mean", type=float, default=600.0,
                    help="budget of a position-mode period, mean instructions (default 600)")
    ap.add_argument("--report", metavar="FILE",
                    help="also write the table as Markdown into the section \"position\" of this page "
                         "(docs/reports/cost.md)")
    args = ap.parse_args()
    if not args.no_build:
        bt.run(["cmake", "--preset", "qemu-pil"], cwd=bt.ROOT, stdout=subprocess.DEVNULL)
        bt.run(["cmake", "--build", "--preset", "qemu-pil", "--target", "pmstep-pil-position"], cwd=bt.ROOT,
               stdout=subprocess.DEVNULL)
    args.work.mkdir(parents=True, exist_ok=True)
    plugin = args.work / "pil_insn_plugin.so"
    bt.run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-o", plugin, bt.PLUGIN_SRC])
    step_entry, step_ret = call_addresses(args.image, "pmstep_step", "Irq10_Handler")
    update_entry, update_ret = call_addresses(args.image, "pmstep_position_update", "main")
    step, modes, report_lines = counts(args.image, args.work, plugin, step_entry, step_ret, "step", args.duration)
    update, modes2, _ = counts(args.image, args.work, plugin, update_entry, update_ret, "update", args.duration)
    if not (len(step) == len(update) == len(modes) and modes == modes2):
        sys.exit("bench_position_target: %d step counts, %d update counts, %d periods" %
                 (len(step), len(update), len(modes)))
    print("Control period with the position loop on a Cortex-M4F: QEMU mps2-an386, -Os + LTO")
    print(report_lines)
    print()
    print("%-34s %6s   %-22s %-22s %-22s" % ("period", "steps", "pmstep_step min/mean/max",
                                              "position_update", "sum (position_step)"))
    figures = {}
    for kind, label in KINDS.items():
        idx = [i for i, m in enumerate(modes) if m == kind]
        if not idx:
            continue
        s = [step[i] for i in idx]
        u = [update[i] for i in idx]
        t = [step[i] + update[i] for i in idx]

        def fmt(v):
            return "%d / %.1f / %d" % (min(v), statistics.fmean(v), max(v))
        print("%-34s %6d   %-22s %-22s %-22s" % (label, len(idx), fmt(s), fmt(u), fmt(t)))
        figures[kind] = {"label": label, "periods": len(idx),
                         "step": [min(s), statistics.fmean(s), max(s)],
                         "update": [min(u), statistics.fmean(u), max(u)],
                         "total": [min(t), statistics.fmean(t), max(t)]}
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=1))
    if args.report:  # written now, printed last
        text = report_section(figures, report_lines, args.max_mean, bt.budgets()["position"], args.duration, sys.argv)
        wrote = "bench_position_target: wrote %s" % report.write_section(
            args.report, bt.COST_TITLE, "position", text, bt.COST_WHAT, bt.COST_SECTIONS)
    if "p" not in figures:
        print("no period in position mode")
        if args.report:
            print(wrote)
        return 1
    mean = figures["p"]["total"][1]
    print("position-mode period: mean %.1f instructions, budget %.0f: %s" %
          (mean, args.max_mean, "within" if mean <= args.max_mean else "OVER"))
    if args.report:
        print(wrote)
    return 0 if mean <= args.max_mean else 1


if __name__ == "__main__":
    sys.exit(main())
