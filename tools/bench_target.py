#!/usr/bin/env python3
"""Cost of the control step on a Cortex-M4F, measured on QEMU's mps2-an386.

The replay image (tests/pil/target/pil_replay.c, built by the qemu-pil preset with the
STM32G431 image's flags: -Os and link-time optimisation) runs every period of the paper
scenario, recorded by the host SIL, through the real pmstep_step() from the port's
control interrupt. Two measurements:

  exact    a QEMU TCG plugin (hal/qemu_mps2/tools/pil_insn_plugin.c) counts every guest
           instruction executed between the first instruction of pmstep_step() and the
           instruction its call returns to: the instructions of each step, callees
           included. Min, mean and max per mode.
  SysTick  the image reads SysTick around each step; with -icount shift=0 one instruction
           is 1 ns of virtual time and SysTick (25 MHz) advances every 40 instructions, so
           the mean over thousands of steps is the mean instruction count (cross-check).

Cycles at 170 MHz, two estimates:
  1 cycle/instruction   the issue's convention (600 instructions = 3.5 us)
  Cortex-M4 timings     each executed instruction weighted by the Cortex-M4 TRM's
                        cycle counts (ARM DDI 0439B, tables 3-1 and 7-1: single loads and
                        stores 2, or 1 right after another single load/store, as neighbouring
                        ones pipeline; LDM/STM/PUSH/POP and VLDM/VSTM/VPUSH/VPOP 1+N,
                        VDIV/VSQRT 14, VMLA-type 3, SDIV/UDIV 12, other ALU/FPU 1) plus a
                        pipeline refill of P cycles (default 2, 1..3 on the M4) for every
                        taken branch or return, counted by the plugin; memory without wait
                        states (code in CCM SRAM, or flash with every fetch an ART hit).
                        "Right after" is by address, so a load at a branch target may get
                        the pipelined cost; --no-pipelining charges every load/store 2.

Footprint: the core library's text + rodata (arm-none-eabi-size), the instance
sizeof(pmstep_t) printed by the image, the step's stack measured in the image (painted
stack below the interrupt's SP), and a static bound from -fstack-usage and the call
graph of the non-LTO library (arm-m4f preset); the STM32G431 image's flash (text + data)
and RAM (data + bss) from arm-none-eabi-size on the stm32g431 preset's build.

Report: --report FILE writes these figures as Markdown (command, commit, date; tools/report.py)
into the section "step" of that page, each beside the budget ctest's pil.cost enforces
(tests/pil/CMakeLists.txt) and the STM32G431 image's beside hal/stm32g4/check_image.cmake's;
tools/bench_position_target.py --report writes the section "position" of the same page.

usage: tools/bench_target.py [--no-build] [--branch-penalty P] [--no-pipelining] [--json FILE]
                             [--report docs/reports/cost.md]
"""

import argparse
import collections
import json
import os
import re
import shutil
import struct
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import report  # noqa: E402  (the reports' header and sections)

ROOT = Path(__file__).resolve().parent.parent
PIL = ROOT / "build" / "qemu-pil"
BENCH = PIL / "bench"
SIL = ROOT / "build" / "host-release" / "sil" / "pmstep-sil"
ARM_M4F = ROOT / "build" / "arm-m4f"
REPLAY = PIL / "tests" / "pil" / "target" / "pmstep-pil-replay.elf"
PLUGIN_SRC = ROOT / "hal" / "qemu_mps2" / "tools" / "pil_insn_plugin.c"
MODES = ["IDLE", "S_ALIGN", "C_ALIGN", "RUN", "FAULT", "OFFSET_CAL"]  # pmstep_mode_t
CPU_HZ = 170e6
CONTROL_HZ = 20e3
IN_WORDS = 6  # SIL_RECORD_IN_WORDS
OUT_WORDS = 19  # SIL_RECORD_OUT_WORDS
OUT_MODE = 4  # SIL_RECORD_OUT_MODE
IMAGE = ROOT / "build" / "stm32g431" / "hal" / "stm32g4" / "pmstep-stm32g431.elf"
PIL_CMAKE = ROOT / "tests" / "pil" / "CMakeLists.txt"
IMAGE_CHECK = ROOT / "hal" / "stm32g4" / "check_image.cmake"
# The cost page (docs/reports/cost.md): this tool's section, then bench_position_target.py's.
COST_TITLE = "Cost on the target (Cortex-M4F)"
COST_SECTIONS = ("step", "position")
COST_WHAT = (
    "What the control step costs on a Cortex-M4F (QEMU's mps2-an386, the images' flags: `-Os` with "
    "link-time optimisation) and what the core and the STM32G431 image take, each figure beside the "
    "budget ctest enforces (`pil.cost`, `pil.position_cost`, `pil.stepdir_cost` in "
    "tests/pil/CMakeLists.txt; the image's fit in hal/stm32g4/check_image.cmake)."
)


def run(cmd, **kw):
    kw.setdefault("check", True)
    return subprocess.run([str(c) for c in cmd], **kw)


def build():
    for preset in ("qemu-pil", "host-release", "arm-m4f", "stm32g431"):
        run(["cmake", "--preset", preset], cwd=ROOT, stdout=subprocess.DEVNULL)
        run(["cmake", "--build", "--preset", preset], cwd=ROOT, stdout=subprocess.DEVNULL)


def qemu(image, args, extra=()):
    semi = "enable=on,target=native," + ",".join("arg=" + str(a) for a in [image.name, *args])
    return run(
        [
            "qemu-system-arm",
            "-M",
            "mps2-an386",
            "-cpu",
            "cortex-m4",
            "-nographic",
            "-monitor",
            "none",
            "-serial",
            "none",
            *extra,
            "-semihosting-config",
            semi,
            "-kernel",
            image,
        ],
        stdout=subprocess.PIPE,
        text=True,
    )


def step_addresses(elf):
    """Entry of pmstep_step and the instruction after its call in the control interrupt."""
    nm = run(["arm-none-eabi-nm", elf], stdout=subprocess.PIPE, text=True).stdout
    entry = next(int(l.split()[0], 16) for l in nm.splitlines() if l.split()[-1] == "pmstep_step")
    dis = run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf], stdout=subprocess.PIPE, text=True).stdout
    block = dis.split("<Irq10_Handler>:", 1)[1]
    lines = [l for l in block.splitlines() if re.match(r"^\s+[0-9a-f]+:", l)]
    for i, l in enumerate(lines):
        if re.search(r"\bbl\s+[0-9a-f]+ <pmstep_step>", l):
            return entry, int(lines[i + 1].split(":")[0], 16)
    sys.exit("bench_target: no call of pmstep_step in the control interrupt")


def record_outputs(path):
    """Host outputs (tuples of words) from the SIL record."""
    w = struct.unpack("<%dI" % (os.path.getsize(path) // 4), Path(path).read_bytes())
    # header: magic, version, config words, input words, output words, config, i_d* (sil/include/sil/record.h)
    config_words, in_words, out_words = w[2], w[3], w[4]
    if (in_words, out_words) != (IN_WORDS, OUT_WORDS):
        sys.exit("bench_target: record layout %d/%d words, expected %d/%d" % (in_words, out_words, IN_WORDS, OUT_WORDS))
    i, outs = 5 + config_words + 1, []
    while True:
        tag = w[i]
        if tag == 1:
            i += 3
        elif tag == 2:
            outs.append(w[i + 1 + IN_WORDS : i + 1 + IN_WORDS + OUT_WORDS])
            i += 1 + IN_WORDS + OUT_WORDS
        elif tag == 3:
            return outs
        else:
            sys.exit("bench_target: bad record")


def target_outputs(path):
    w = struct.unpack("<%dI" % (os.path.getsize(path) // 4), Path(path).read_bytes())
    n = (len(w) - 5) // OUT_WORDS
    return [w[3 + OUT_WORDS * k : 3 + OUT_WORDS * (k + 1)] for k in range(n)]


def mode_ranges(modes):
    """Contiguous [first, last) step ranges per mode."""
    ranges = {}
    for k, m in enumerate(modes):
        first, last = ranges.get(m, (k, k))
        ranges[m] = (min(first, k), k + 1)
    return ranges


# ---- cycle model (Cortex-M4 TRM, ARM DDI 0439B) ----
CONDS = {"eq", "ne", "cs", "cc", "hs", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le", "al"}
BASES = [
    "ldrsb",
    "ldrsh",
    "ldrb",
    "ldrh",
    "ldrd",
    "ldr",
    "strb",
    "strh",
    "strd",
    "str",
    "ldmia",
    "ldmdb",
    "ldm",
    "stmia",
    "stmdb",
    "stm",
    "push",
    "pop",
    "vldr",
    "vstr",
    "vldmia",
    "vldmdb",
    "vstmia",
    "vstmdb",
    "vpush",
    "vpop",
    "vdiv",
    "vsqrt",
    "vmla",
    "vmls",
    "vnmla",
    "vnmls",
    "vfma",
    "vfms",
    "vfnma",
    "vfnms",
    "vmov",
    "sdiv",
    "udiv",
    "mla",
    "mls",
]


def register_count(ops):
    n = 0
    for part in re.findall(r"\{([^}]*)\}", ops):
        for item in part.split(","):
            item = item.strip()
            m = re.match(r"([rsd])(\d+)\s*-\s*[rsd](\d+)", item)
            if m:
                k = int(m.group(3)) - int(m.group(2)) + 1
                n += 2 * k if m.group(1) == "d" else k
            elif item:
                n += 2 if item.startswith("d") else 1
    return n


def base_mnemonic(mnemonic):
    m = mnemonic.split(".")[0]
    if m not in BASES and len(m) > 2 and m[-2:] in CONDS and not m.startswith("b"):
        m = m[:-2]  # conditional form inside an IT block
    return m


def single_load_store(mnemonic):
    m = base_mnemonic(mnemonic)
    return m in ("vldr", "vstr") or (re.match(r"^(ldr|str)", m) is not None and m not in ("ldrd", "strd"))


def base_cycles(mnemonic, ops):
    m = base_mnemonic(mnemonic)
    if m in ("vdiv", "vsqrt"):
        return 14
    if m in ("vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms"):
        return 3
    if m in ("vldr", "vstr"):
        return 2
    if m in ("vpush", "vpop", "vldmia", "vldmdb", "vstmia", "vstmdb"):
        return 1 + register_count(ops)
    if m == "vmov":
        return 2 if ops.count(",") >= 2 else 1
    if m.startswith("v"):
        return 1
    if m in ("ldm", "ldmia", "ldmdb", "stm", "stmia", "stmdb", "push", "pop"):
        return 1 + register_count(ops)
    if m in ("ldrd", "strd"):
        return 3
    if re.match(r"^(ldr|str)", m):
        return 2
    if m in ("sdiv", "udiv"):
        return 12
    if m in ("mla", "mls"):
        return 2
    return 1


def disassembly(elf):
    dis = run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf], stdout=subprocess.PIPE, text=True).stdout
    insns = {}
    for l in dis.splitlines():
        m = re.match(r"^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$", l)
        if m:
            insns[int(m.group(1), 16)] = (m.group(2), m.group(3))
    return insns


def model_cycles(profile_path, insns, penalty, pipelining):
    cycles = taken = 0
    mix = collections.Counter()
    addresses = sorted(insns)
    previous = {a: addresses[i - 1] for i, a in enumerate(addresses) if i > 0}
    for l in Path(profile_path).read_text().splitlines():
        if l.startswith("#"):
            continue
        pc, _size, count, jumps = l.split()
        pc, count, jumps = int(pc, 16), int(count), int(jumps)
        mnemonic, ops = insns.get(pc, ("?", ""))
        c = base_cycles(mnemonic, ops)
        if pipelining and single_load_store(mnemonic) and pc in previous and single_load_store(insns[previous[pc]][0]):
            c = 1
        cycles += count * c
        taken += jumps
        mix[mnemonic.split(".")[0]] += count
    return cycles + penalty * taken, taken, mix


# ---- static stack bound: -fstack-usage of the non-LTO library + its call graph ----
def clone_name(symbol):
    """A GCC clone's name without its numbers: the .su file lists aim.constprop.isra for the
    object's aim.constprop.0.isra.0."""
    return re.sub(r"\.[0-9]+(?=\.|$)", "", symbol)


def static_stack(root_function="pmstep_step"):
    su_dir = ARM_M4F / "firmware" / "CMakeFiles" / "pmstep_core.dir" / "src"
    lib = ARM_M4F / "firmware" / "libpmstep_core.a"
    frames = {}
    for su in su_dir.glob("*.su"):
        for l in su.read_text().splitlines():
            name, size, _kind = l.rsplit("\t", 2)
            frames[clone_name(name.rsplit(":", 1)[1])] = int(size)
    dis = run(["arm-none-eabi-objdump", "-dr", lib], stdout=subprocess.PIPE, text=True).stdout
    calls, current = collections.defaultdict(set), None
    for l in dis.splitlines():
        m = re.match(r"^[0-9a-f]+ <([^>]+)>:$", l)
        if m:
            current = clone_name(m.group(1))
            continue
        m = re.search(r"R_ARM_THM_(?:CALL|JUMP24)\s+(\S+)", l)
        if m and current:
            calls[current].add(clone_name(m.group(1)))
    unknown = set()

    def depth(f, seen=()):
        if f not in frames:
            unknown.add(f)
            return 0, [f]
        best, path = 0, []
        for g in calls.get(f, ()):
            if g in seen:
                continue
            d, p = depth(g, seen + (f,))
            if d > best:
                best, path = d, p
        return frames[f] + best, [f] + path

    total, path = depth(root_function)
    return total, path, sorted(unknown)


# ---- the budgets ctest enforces, read where they are set, and the report ----
def budgets():
    """{name: value} of the budgets ctest enforces: pil.cost's MAX_RUN, MAX_STACK, MAX_INSTANCE,
    MAX_FLASH, pil.position_cost's --max-mean and pil.stepdir_cost's --stepdir-max-mean
    (tests/pil/CMakeLists.txt) as run, stack, instance, flash, position and stepdir; the STM32G431
    image's flash and RAM limits (hal/stm32g4/check_image.cmake) as image_flash and image_ram. A
    budget not found is None."""
    out = dict.fromkeys(("run", "stack", "instance", "flash", "position", "stepdir", "image_flash", "image_ram"))
    try:
        text = PIL_CMAKE.read_text()
        for key, value in re.findall(r"-DMAX_(RUN|STACK|INSTANCE|FLASH)=(\d+)", text):
            out[key.lower()] = int(value)
        for key, flag in (("position", "--max-mean"), ("stepdir", "--stepdir-max-mean")):
            m = re.search(r"bench_position_target\.py[^)]*\s%s\s+([0-9.]+)" % flag, text)
            if m:
                out[key] = float(m.group(1))
    except OSError:
        pass
    try:
        m = re.search(r"flash GREATER (\d+) OR ram GREATER (\d+)", IMAGE_CHECK.read_text())
        if m:
            out["image_flash"], out["image_ram"] = int(m.group(1)), int(m.group(2))
    except OSError:
        pass
    return out


def image_sizes(size_output):
    """(text, data, bss) of the first file in arm-none-eabi-size's Berkeley output, or None."""
    m = re.search(r"^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+[0-9a-f]+\s+\S", size_output or "", re.M)
    return tuple(int(v) for v in m.groups()) if m else None


def budget_cell(budget, unit=" B"):
    return "-" if budget is None else f"{budget}{unit}"


def verdict(value, budget):
    """'within' / 'OVER' of @p value against @p budget ('-' without a budget)."""
    if budget is None or value is None:
        return "-"
    return "within" if value <= budget else "**OVER**"


def report_section(r, budget, argv):
    """The section "step" of the cost page from the figures @p r main() measured (the keys of its
    --json, plus stack_measured_bytes, static_path, static_unknown, run_mix, image) and @p budget
    (budgets())."""
    lines = [
        report.section_header("Control step: `pmstep_step()` on the paper scenario", "tools/bench_target.py", argv),
        f"{r['qemu']}, arm-none-eabi-gcc {r['gcc']}, `-Os` with link-time optimisation; all {r['periods']} "
        f"periods of the paper scenario recorded by the host SIL and replayed through the real `pmstep_step()` "
        f"from the port's control interrupt; outputs "
        f"{'**bit-identical** to' if r['bit_identical'] else '**DIFFERENT** from'} the host's.",
        "",
        "Instructions per step: exact counts of a QEMU plugin (every instruction from the step's entry to its "
        "return, callees included) and the SysTick estimate under `-icount shift=0` (what `pil.cost` checks). "
        "Time and CPU load at 170 MHz and 20 kHz, at 1 cycle per instruction and in the Cortex-M4 timing model "
        f"(ARM DDI 0439B cycle counts, {r['branch_penalty']} cycles per taken branch"
        f"{', neighbouring loads and stores pipelined' if r['load_store_pipelining'] else ''}, no wait states).",
        "",
    ]
    modes = [m for m in ("S_ALIGN", "C_ALIGN", "RUN") if m in r["modes"]]
    lines += ["| | " + " | ".join(modes) + " |", "|---|" + "---|" * len(modes)]

    def row(label, cell):
        lines.append(f"| {label} | " + " | ".join(cell(r["modes"][m], m) for m in modes) + " |")

    row("steps", lambda f, m: str(f["steps"]))
    row(
        "instructions, exact: min / mean / max",
        lambda f, m: f"{f['instructions_min']} / {f['instructions_mean']:.1f} / {f['instructions_max']}",
    )
    row(
        "instructions, SysTick mean" + (f" (budget of RUN: {budget['run']})" if budget["run"] is not None else ""),
        lambda f, m: (
            f"{f['systick_instructions_mean']:.1f}"
            + (f" ({verdict(f['systick_instructions_mean'], budget['run'])})" if m == "RUN" else "")
        ),
    )
    row(
        "1 cycle/instruction: mean time, CPU at 20 kHz (worst step)",
        lambda f, m: (
            f"{f['instructions_mean'] / CPU_HZ * 1e6:.2f} µs, "
            f"{f['instructions_mean'] / CPU_HZ * CONTROL_HZ * 100:.1f} % "
            f"({f['instructions_max'] / CPU_HZ * 1e6:.2f} µs, "
            f"{f['instructions_max'] / CPU_HZ * CONTROL_HZ * 100:.1f} %)"
        ),
    )
    row(
        "Cortex-M4 timing model: mean cycles, time, CPU at 20 kHz",
        lambda f, m: (
            f"{f['cycles_model_mean']:.0f}, {f['cycles_model_mean'] / CPU_HZ * 1e6:.2f} µs, "
            f"{f['cycles_model_mean'] / CPU_HZ * CONTROL_HZ * 100:.1f} %"
        ),
    )
    row(
        "stack measured in the LTO image" + (f" (budget {budget['stack']} B)" if budget["stack"] is not None else ""),
        lambda f, m: f"{f['stack_bytes_measured']} B ({verdict(f['stack_bytes_measured'], budget['stack'])})",
    )
    if r.get("run_mix"):
        lines += ["", "RUN's instruction mix, per step: " + ", ".join(f"{k} {n:.1f}" for k, n in r["run_mix"]) + "."]
    lines += [
        "",
        "| footprint | measured | budget | |",
        "|---|---|---|---|",
        f"| core flash, text + rodata (`libpmstep_core.a`, `-Os`, arm-none-eabi-size --totals) | "
        f"{r['core_flash_bytes']} B | {budget_cell(budget['flash'])} | "
        f"{verdict(r['core_flash_bytes'], budget['flash'])} |",
        f"| instance `sizeof(pmstep_t)` | {r['instance_bytes']} B | "
        f"{budget_cell(budget['instance'])} | "
        f"{verdict(r['instance_bytes'], budget['instance'])} |",
        f"| configuration `sizeof(pmstep_config_t)` (const, may live in flash) | {r['config_bytes']} B | - | - |",
        f"| stack of `pmstep_step()`, measured in the LTO image (deepest mode) | {r['stack_measured_bytes']} B | "
        f"{budget_cell(budget['stack'])} | "
        f"{verdict(r['stack_measured_bytes'], budget['stack'])} |",
        f"| stack of `pmstep_step()`, static bound (`-fstack-usage` + call graph, non-LTO library) | "
        f"{r['stack_static_bytes']} B | not checked | - |",
    ]
    image = r.get("image")
    if image:
        text, data, bss = image
        lines += [
            f"| STM32G431 image flash, text + data (build/stm32g431, arm-none-eabi-size) | {text + data} B | "
            f"{budget_cell(budget['image_flash'])} | "
            f"{verdict(text + data, budget['image_flash'])} |",
            f"| STM32G431 image RAM, data + bss (the 2 KiB stack reserve apart) | {data + bss} B | "
            f"{budget_cell(budget['image_ram'])} | "
            f"{verdict(data + bss, budget['image_ram'])} |",
        ]
    else:
        lines.append(
            "| STM32G431 image | not built (`cmake --preset stm32g431 && cmake --build --preset stm32g431`) | | |"
        )
    lines += [
        "",
        f"Static bound's deepest path: {' → '.join(r['static_path'])}"
        + (f"; not counted: {', '.join(r['static_unknown'])} (newlib leaf routines)" if r["static_unknown"] else "")
        + ".",
    ]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument(
        "--no-build", action="store_true", help="use the existing build/qemu-pil, host-release, arm-m4f, stm32g431"
    )
    ap.add_argument("--branch-penalty", type=int, default=2, help="pipeline refill cycles per taken branch (1..3)")
    ap.add_argument(
        "--no-pipelining",
        action="store_true",
        help="charge every single load/store 2 cycles (no credit for neighbouring ones)",
    )
    ap.add_argument("--json", help="also write the figures to this JSON file")
    ap.add_argument(
        "--report",
        metavar="FILE",
        help='also write the figures as Markdown into the section "step" of this page (docs/reports/cost.md)',
    )
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="override a key of the paper scenario for the recorded run (pmstep-sil --set), e.g. "
        "controller.commissioning.identification_time_s=1.8 to count RUN with identification",
    )
    args = ap.parse_args()
    for tool in ("qemu-system-arm", "arm-none-eabi-gcc", "cc"):
        if shutil.which(tool) is None:
            sys.exit("bench_target: %s not found (tools/install_deps.sh installs it)" % tool)
    if not args.no_build:
        build()
    BENCH.mkdir(parents=True, exist_ok=True)

    rec = BENCH / "paper.rec"
    sets = [a for kv in args.set for a in ("--set", kv)]
    run([SIL, "--quiet", "--no-csv", "--out", BENCH / "paper", "--record", rec] + sets)
    plugin = BENCH / "pil_insn_plugin.so"
    run(["cc", "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", "-o", plugin, PLUGIN_SRC])
    entry, ret = step_addresses(REPLAY)

    # SysTick under -icount (and the image's stack and instance figures).
    out_icount = BENCH / "target-icount.out"
    cost_path = BENCH / "cost.txt"
    qemu(REPLAY, [rec, out_icount, cost_path], ["-icount", "shift=0"])
    cost = cost_path.read_text()
    systick = {
        m.group(1): (float(m.group(2)), int(m.group(3)))
        for m in re.finditer(r"^mode (\S+) steps \d+ .* instructions_mean ([0-9.]+) stack_max_bytes (\d+)", cost, re.M)
    }
    instance = int(re.search(r"^sizeof_pmstep_t (\d+)", cost, re.M).group(1))
    config_size = int(re.search(r"^sizeof_pmstep_config_t (\d+)", cost, re.M).group(1))

    # Exact counts per step.
    out_exact = BENCH / "target.out"
    steps_path = BENCH / "steps.txt"
    qemu(REPLAY, [rec, out_exact], ["-plugin", "%s,entry=0x%x,ret=0x%x,out=%s" % (plugin, entry, ret, steps_path)])
    counts = [int(l) for l in steps_path.read_text().splitlines() if not l.startswith("#")]
    host = record_outputs(rec)
    target = target_outputs(out_exact)
    identical = host == target and host == target_outputs(out_icount)
    modes = [MODES[o[OUT_MODE]] for o in target]
    if len(counts) != len(modes):
        sys.exit("bench_target: %d counted steps for %d periods" % (len(counts), len(modes)))
    per_mode = collections.defaultdict(list)
    for m, c in zip(modes, counts):
        per_mode[m].append(c)

    # Cycle model per mode: one profiled run per contiguous range of steps.
    insns = disassembly(REPLAY)
    cycles = {}
    for m, (first, last) in sorted(mode_ranges(modes).items(), key=lambda kv: kv[1]):
        prof = BENCH / ("profile-%s.txt" % m)
        qemu(
            REPLAY,
            [rec, BENCH / "target-profile.out"],
            [
                "-plugin",
                "%s,entry=0x%x,ret=0x%x,out=%s,profile=%s,profile_from=%d,profile_to=%d"
                % (plugin, entry, ret, BENCH / "steps-profile.txt", prof, first, last),
            ],
        )
        total, taken, mix = model_cycles(prof, insns, args.branch_penalty, not args.no_pipelining)
        cycles[m] = (total / (last - first), taken / (last - first), mix)

    size = run(
        ["arm-none-eabi-size", "--totals", PIL / "firmware" / "libpmstep_core.a"], stdout=subprocess.PIPE, text=True
    ).stdout
    flash = int(re.search(r"^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+[0-9a-f]+\s+\(TOTALS\)", size, re.M).group(1))
    image_size = run(
        ["arm-none-eabi-size", IMAGE], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, check=False
    ).stdout
    static_total, static_path, static_unknown = static_stack()
    gcc = run(["arm-none-eabi-gcc", "-dumpversion"], stdout=subprocess.PIPE, text=True).stdout.strip()
    qemu_version = run(["qemu-system-arm", "--version"], stdout=subprocess.PIPE, text=True).stdout.splitlines()[0]

    print("Control step on a Cortex-M4F: QEMU mps2-an386 (%s), arm-none-eabi-gcc %s, -Os + LTO" % (qemu_version, gcc))
    print(
        "paper scenario, %d periods replayed; outputs %s the host's"
        % (len(counts), "bit-identical to" if identical else "DIFFERENT from")
    )
    print()
    print(
        "%-8s %6s  %5s %7s %5s  %8s  %8s %7s %6s  %8s %7s %6s"
        % ("mode", "steps", "min", "mean", "max", "SysTick", "cyc 1/i", "us", "CPU%", "cyc M4", "us", "CPU%")
    )
    print(
        "%-8s %6s  %19s  %8s  %22s  %22s"
        % (
            "",
            "",
            "instructions (exact)",
            "estimate",
            "@170 MHz, 20 kHz",
            "TRM timings, P=%d%s" % (args.branch_penalty, "" if args.no_pipelining else ", pipel."),
        )
    )
    figures = {}
    for m in ("S_ALIGN", "C_ALIGN", "RUN"):
        v = per_mode[m]
        mean = sum(v) / len(v)
        c = cycles[m][0]
        us1, usm = mean / CPU_HZ * 1e6, c / CPU_HZ * 1e6
        print(
            "%-8s %6d  %5d %7.1f %5d  %8.1f  %8.0f %7.2f %6.1f  %8.0f %7.2f %6.1f"
            % (
                m,
                len(v),
                min(v),
                mean,
                max(v),
                systick[m][0],
                mean,
                us1,
                us1 * CONTROL_HZ / 1e4,
                c,
                usm,
                usm * CONTROL_HZ / 1e4,
            )
        )
        figures[m] = {
            "steps": len(v),
            "instructions_min": min(v),
            "instructions_mean": mean,
            "instructions_max": max(v),
            "systick_instructions_mean": systick[m][0],
            "cycles_model_mean": c,
            "taken_branches_mean": cycles[m][1],
            "stack_bytes_measured": systick[m][1],
        }
    run_max = max(per_mode["RUN"])
    print()
    print(
        "worst RUN step: %d instructions = %.2f us at 1 cycle/instruction, %.1f %% of a 50 us period"
        % (run_max, run_max / CPU_HZ * 1e6, run_max / CPU_HZ * CONTROL_HZ * 100)
    )
    top = cycles["RUN"][2].most_common(8)
    print("RUN instruction mix (per step): " + ", ".join("%s %.1f" % (k, n / len(per_mode["RUN"])) for k, n in top))
    print()
    print("footprint")
    print("  core flash (text + rodata, libpmstep_core.a, -Os): %d B" % flash)
    print(
        "  instance sizeof(pmstep_t): %d B; configuration sizeof(pmstep_config_t): %d B (const, may live in flash)"
        % (instance, config_size)
    )
    print(
        "  stack of pmstep_step(), measured in the LTO image: %d B (deepest of all modes)"
        % max(s for _, s in systick.values())
    )
    print(
        "  stack of pmstep_step(), static bound (-fstack-usage, non-LTO library): %d B via %s%s"
        % (
            static_total,
            " -> ".join(static_path),
            ("; not counted: " + ", ".join(static_unknown) + " (newlib leaf routines)") if static_unknown else "",
        )
    )
    if image_size:
        print("  STM32G431 image (build/stm32g431):")
        print("    " + "\n    ".join(image_size.strip().splitlines()))
    result = {
        "qemu": qemu_version,
        "gcc": gcc,
        "bit_identical": identical,
        "periods": len(counts),
        "modes": figures,
        "core_flash_bytes": flash,
        "instance_bytes": instance,
        "config_bytes": config_size,
        "stack_static_bytes": static_total,
        "branch_penalty": args.branch_penalty,
        "load_store_pipelining": not args.no_pipelining,
    }
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n")
    if args.report:
        result.update(
            {
                "stack_measured_bytes": max(s for _, s in systick.values()),
                "static_path": static_path,
                "static_unknown": static_unknown,
                "image": image_sizes(image_size),
                "run_mix": [(k, n / len(per_mode["RUN"])) for k, n in top],
            }
        )
        print(
            "bench_target: wrote %s"
            % report.write_section(
                args.report, COST_TITLE, "step", report_section(result, budgets(), sys.argv), COST_WHAT, COST_SECTIONS
            )
        )
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
