#!/usr/bin/env python3
"""End to end on QEMU: the STEP/DIR input of the mps2-an386 image pmstep-pil-console (plant and core
on the emulated Cortex-M4) following a step stream that the host puts on the image's emulated step
counter period by period (SIM_STEPS), driven over QEMU's serial socket by the host console
(tools/pmstep_console.py), against the host SIL's run of the same stream.

Per case (CASES below: S-curves, and trapezoids without a jerk limit; both with direction reversals
through the start, a short move and dwells), on the paper scenario (its motor, p = 6, its 2 N m load
step at 0.63 s), MICROSTEPS microsteps a full step:
  SIL         pmstep-sil with position.source = stepdir: its step generator plans the moves and the
              drive follows its count; every period's count, the telemetry's quantities, theta*,
              theta-hat and the following error on the plant's true position go to its CSV.
  alignment   the image: stepdir.microsteps set, i_d target 0, telemetry, START. During the
              alignment, before following, bursts of up to 127 edges a period (many SIM_STEPS of 60
              periods) take the emulated 16-bit counter forward through two full turns and back
              through one wrap: the input's count read back (SIM_STEPDIR) is their exact signed sum
              although the counter wrapped (PRE_FOLLOW_EDGES), and the counter ends 200 edges below 65536.
  following   at the period the SIL starts following (its summary's following_start_s),
              SIM_FOLLOW_STEPS: the input starts afresh at the counter's value (the bursts dropped, as
              EN does) and the position loop follows its count. Then the SIL's count, period by period
              (its differences, at most 127 a period), in SIM_STEPS of 60 periods each followed by
              SIM_ADVANCE over them; dwells as one SIM_ADVANCE. After each: SIM_STEPDIR and
              GET_POSITION. The counter crosses its wrap with each move through the start.

Checks: every pulse counted (after each chunk the input's count equals the edges sent since it
started, the emulated counter's edges and value equal the host's sums, and at the end the image's
own figures agree); no DIAG (never flagged, no period asserted), no fault, following to the end,
RUN; the following error below BOUND_FULL_STEPS full steps (pi / (2 p)) at every read-back (the
firmware's own: the count's position at the last update less theta-hat) and at every period on the
plant's true position (the image's --stepdir figures); at the end theta-hat and the plant within the
bound of the count's position. Against the SIL: every telemetry frame within the PIL tolerances of
run_console_e2e.py, theta-hat and theta* read back within POSITION_TOLERANCE_RAD of the SIL's of the
same period, the true following error at its largest within ERROR_TOLERANCE_FULL_STEPS of the SIL's.
Writes OUT/report.txt (the figures of each case) and each case's telemetry CSV.

usage: run_stepdir_e2e.py --qemu Q --image ELF --sil PMSTEP_SIL --out DIR [--substeps 1] [--decimation 200]
"""

import argparse
import csv
import json
import math
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import pmstep_console as pc  # noqa: E402
from run_console_e2e import TOLERANCE  # noqa: E402
from run_store_e2e import Board  # noqa: E402

PERIOD_S = pc.f32(50e-6)  # the paper scenario's period (float32, as the firmware keeps it)
POLE_PAIRS = 6  # the paper's motor
MICROSTEPS = 256  # a microstep of the paper's motor moves the tracker's speed by less than the stall
#                           detection's bound at 256 (tools/stepdir_compare.py); 2 pi / 6144 rad
FULL_STEP_RAD = 0.5 * math.pi / POLE_PAIRS

# The moves (position.points: time s : target, mechanical rad from the c-alignment's equilibrium),
# within the paper motor's top speed (about 9.6 rad/s with the paper's gains) and its rated
# torque's acceleration k_M I / J = 1600 rad/s^2 (less the 2 N m load: 200 rad/s^2); the last move ends
# 0.2 s before the run does (1.68 s and 1.54 s): the final dwell.
CASES = {
    "s-curve": {
        "points": "0.61:1.0,0.95:-0.5,1.35:-0.3,1.5:0.4",
        "v_max": 4.8,
        "a_max": 300.0,
        "j_max": 15000.0,
        "duration_s": 1.9,
    },
    "trapezoid": {
        "points": "0.61:1.5,0.95:-1.0,1.3:0.6",
        "v_max": 7.6,
        "a_max": 300.0,
        "j_max": 0.0,
        "duration_s": 1.75,
    },
}
# Before following, from PRE_FOLLOW_AT: forward two turns of the counter and more, back across a wrap;
# the counter ends at -200 mod 65536, so that every move through the start crosses the wrap.
PRE_FOLLOW_AT = 2000
PRE_FOLLOW_EDGES = (150000, -19128)
BURST = 127  # edges a period in the bursts (SIM_STEPS carries i8 edges)

# The bound on the following error, moving or at rest, on the firmware's estimate and on the plant:
# a quarter of a full step (0.065 rad). The SIL's runs of these cases (substeps 1) reach 0.12 and 0.14
# full steps on the plant (with the load step under way, and where a move stops), the firmware's own
# error at the read-backs a little less: a margin of 1.8 at least.
BOUND_FULL_STEPS = 0.25
# PIL against SIL on the same stream, as the per-sample tolerances of run_console_e2e.py: about 10x the
# float32 resolution of positions up to 1.5 rad (1.2e-7 rad), which a few ULPs of difference in the
# plant's libm could move; in full steps (0.26 rad) for the plant's following error.
POSITION_TOLERANCE_RAD = 2e-6
ERROR_TOLERANCE_FULL_STEPS = 1e-5


def sil_run(a, out, case):
    """The host SIL's run of @p case, a CSV row every period: (rows by period, summary)."""
    c = CASES[case]
    sil_out = out / f"sil-{case}"
    subprocess.run(
        [
            a.sil,
            "--quiet",
            "--out",
            str(sil_out),
            "--set",
            f"run.duration_s={c['duration_s']}",
            "--set",
            f"run.substeps={a.substeps}",
            "--set",
            "run.decimation=1",
            "--set",
            "speed.points=0:0",
            "--set",
            "position.source=stepdir",
            "--set",
            f"position.points={c['points']}",
            "--set",
            f"position.v_max_rad_s={c['v_max']}",
            "--set",
            f"position.a_max_rad_s2={c['a_max']}",
            "--set",
            f"position.j_max_rad_s3={c['j_max']}",
            "--set",
            f"stepdir.microsteps={MICROSTEPS}",
        ],
        check=True,
    )
    with open(sil_out / "run.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    summary = json.loads((sil_out / "summary.json").read_text())
    return rows, summary


def chunks(edges, size=pc.SIM_STEPS_MAX):
    return [edges[i : i + size] for i in range(0, len(edges), size)]


def parse_figures(path):
    """The image's --stepdir figures: name -> number."""
    figures = {}
    for line in Path(path).read_text().splitlines():
        name, value = line.split()
        figures[name] = float(value) if "." in value or "e" in value else int(value)
    return figures


def run_case(a, out, case):
    """One case on the target against the SIL: (report lines, failures)."""
    c = CASES[case]
    report, failures = [], []
    rows, summary = sil_run(a, out, case)
    steps = len(rows)
    count = [int(r["step_count"]) for r in rows]
    k_follow = int(round(summary["stepdir"]["following_start_s"] / PERIOD_S))
    if any(count[:k_follow]):
        raise RuntimeError(f"{case}: the SIL counted steps before it followed them")
    edges = [count[k] - (count[k - 1] if k > k_follow else 0) for k in range(k_follow, steps)]
    if max(abs(e) for e in edges) > BURST:
        raise RuntimeError(f"{case}: more than {BURST} edges in one period")

    figures_path = out / f"{case}_stepdir.txt"
    figures_path.unlink(missing_ok=True)
    t0 = time.monotonic()
    board = Board(a, None, c["duration_s"], substeps=a.substeps, extra=["--stepdir", str(figures_path)], nodelay=True)
    con = board.con
    reads = []  # (SIM_STEPDIR, GET_POSITION, edges sent since following began) after each chunk
    try:
        con.set_config("stepdir.microsteps", MICROSTEPS)
        con.id_target(0.0)
        con.set_telemetry(a.decimation)
        con.start()
        # Bursts during the alignment, not followed: the counter through its wrap, counted exactly.
        con.sim_advance(PRE_FOLLOW_AT)
        burst = []
        for total in PRE_FOLLOW_EDGES:
            sign = 1 if total > 0 else -1
            burst += [sign * BURST] * (abs(total) // BURST) + ([total % (sign * BURST)] if total % BURST else [])
        wraps_before = 0
        sent = 0
        for chunk in chunks(burst):
            con.sim_steps(chunk)
            con.sim_advance(len(chunk))
            wraps_before += abs((sent + sum(chunk)) // 65536 - sent // 65536)
            sent += sum(chunk)
        pre = con.sim_stepdir()
        pre_sum = sum(PRE_FOLLOW_EDGES)
        if not (pre["steps"] == pre_sum == pre["edges"] and pre["counter"] == pre_sum % 65536 and not pre["following"]):
            failures.append(f"{case}: before following, {pre} after {pre_sum} edges")
        report.append(
            f"[{case}] before following: {len(burst)} periods of bursts ({len(chunks(burst))} SIM_STEPS, "
            f"{sum(abs(e) for e in burst)} edges, the counter wrapped {wraps_before} times): the input "
            f"counted {pre['steps']} (sent {pre_sum}), counter {pre['counter']}"
        )
        # Following from the SIL's period, then the SIL's count period by period.
        con.sim_advance(k_follow - PRE_FOLLOW_AT - len(burst))
        if con.sim_follow_steps() != k_follow:
            failures.append(f"{case}: following does not begin at period {k_follow}")
        k = k_follow
        sent = 0
        wraps = 0
        chunks_sent = 0
        while k < steps:
            i = k - k_follow
            chunk = edges[i : i + pc.SIM_STEPS_MAX]
            if any(chunk):
                con.sim_steps(chunk)
                chunks_sent += 1
            else:  # a dwell: to the next edge
                n = next((j for j in range(i, len(edges)) if edges[j]), len(edges)) - i
                chunk = edges[i : i + n]
            counter_before = pre_sum + sent
            sent += sum(chunk)
            wraps += abs((pre_sum + sent) // 65536 - counter_before // 65536)
            con.sim_advance(len(chunk))
            k += len(chunk)
            reads.append((con.sim_stepdir(), con.position(), sent))
        status = con.status()
        counters = con.counters()
    finally:
        rc, err = board.finish()
    wall_s = time.monotonic() - t0
    if rc != 0:
        failures.append(f"{case}: the image exited with {rc}: {err.strip()}")
    pc.write_csv(out / f"{case}_telemetry.csv", con.telemetry)
    figures = parse_figures(figures_path)

    # Every pulse counted, no DIAG, following to the end, the firmware's following error.
    bound_rad = BOUND_FULL_STEPS * FULL_STEP_RAD
    worst_fw = 0.0
    worst_hat = worst_ref = 0.0
    for sd, pos, sent_then in reads:
        if (
            sd["steps"] != sent_then
            or sd["edges"] != pre_sum + sent_then
            or sd["counter"] != (pre_sum + sent_then) % 65536
        ):
            failures.append(
                f"{case}: period {sd['period']}: counted {sd['steps']}, edges {sd['edges']}, counter "
                f"{sd['counter']}; sent {sent_then} since following, {pre_sum + sent_then} in all"
            )
        if sd["diag"] or not sd["following"]:
            failures.append(f"{case}: period {sd['period']}: DIAG {sd['diag']}, following {sd['following']}")
        worst_fw = max(worst_fw, abs(sd["following_error_rad"]))
        row = rows[pos["period"]]
        worst_hat = max(worst_hat, abs(pos["position_rad"] - float(row["position_hat_rad"])))
        worst_ref = max(worst_ref, abs(pos["position_ref_rad"] - float(row["position_ref_rad"])))
    last_sd, last_pos, _ = reads[-1]
    if worst_fw > bound_rad:
        failures.append(f"{case}: the firmware's following error reached {worst_fw / FULL_STEP_RAD:.4f} full steps")
    if max(worst_hat, worst_ref) > POSITION_TOLERANCE_RAD:
        failures.append(
            f"{case}: theta-hat / theta* read back differ from the SIL's by {worst_hat:.3g} / "
            f"{worst_ref:.3g} rad (tolerance {POSITION_TOLERANCE_RAD:g})"
        )
    final_offset = abs(last_pos["position_rad"] - last_sd["commanded_rad"])
    if final_offset > bound_rad:
        failures.append(f"{case}: at the end theta-hat is {final_offset / FULL_STEP_RAD:.4f} full steps from the count")
    if not (
        figures["edges_sent"] == figures["steps_counted"] == sent
        and figures["following_periods"] == steps - k_follow
        and figures["microsteps"] == MICROSTEPS
    ):
        failures.append(f"{case}: the image's figures {figures}, sent {sent} over {steps - k_follow} periods")
    if figures["diag_periods"] != 0:
        failures.append(f"{case}: DIAG asserted in {figures['diag_periods']} periods")
    if figures["max_error_full_steps"] > BOUND_FULL_STEPS or abs(figures["final_error_full_steps"]) > BOUND_FULL_STEPS:
        failures.append(
            f"{case}: the following error on the plant reached {figures['max_error_full_steps']:.4f} full "
            f"steps (final {figures['final_error_full_steps']:+.4f})"
        )
    sil_sd = summary["stepdir"]
    d_error = abs(figures["max_error_full_steps"] - sil_sd["max_error_full_steps"])
    if d_error > ERROR_TOLERANCE_FULL_STEPS:
        failures.append(
            f"{case}: the largest following error on the plant {figures['max_error_full_steps']:.6f} full "
            f"steps, the SIL's {sil_sd['max_error_full_steps']:.6f}"
        )
    if status["mode"] != "RUN" or status["fault"] != 0:
        failures.append(f"{case}: final status {status['mode']} fault {status['fault']}")
    if counters["rx_error_replies"] != 0 or counters["tx_dropped"] != 0:
        failures.append(f"{case}: console counters {counters}")

    # Telemetry against the SIL's rows of the same periods.
    worst = {key: 0.0 for key in TOLERANCE}
    periods = [int(t["period"]) for t in con.telemetry]
    if periods != list(range(a.decimation, steps, a.decimation)):
        failures.append(f"{case}: telemetry periods {periods[:3]}..{periods[-3:]} (n={len(periods)})")
    for t in con.telemetry:
        row = rows[int(t["period"])]
        if int(row["mode"]) != t["mode"]:
            failures.append(f"{case}: period {t['period']}: mode {t['mode']} vs SIL {row['mode']}")
        for key, (col, tol) in TOLERANCE.items():
            d = abs(t[key] - float(row[col]))
            worst[key] = max(worst[key], d)
            if not d <= tol:
                failures.append(
                    f"{case}: period {t['period']}: {key} {t[key]!r} vs SIL {row[col]} (|d| {d:.3g} > {tol})"
                )

    absolute = sum(abs(e) for e in edges)
    report += [
        f"[{case}] moves {c['points']} at v_max {c['v_max']} rad/s, a_max {c['a_max']} rad/s^2, j_max {c['j_max']} "
        f"rad/s^3, {MICROSTEPS} microsteps; {steps} periods, following from period {k_follow}; wall {wall_s:.1f} s",
        f"[{case}] following: {chunks_sent} SIM_STEPS, {absolute} edges ({sent:+d} net, peak "
        f"{max(abs(e) for e in edges)} a period), the counter crossed its wrap {wraps} times; counted "
        f"{last_sd['steps']} (every read-back equal to the edges sent, {len(reads)} read-backs); DIAG periods "
        f"{figures['diag_periods']}; final {status['mode']} fault {status['fault']}",
        f"[{case}] following error, full steps (bound {BOUND_FULL_STEPS}): firmware's at read-backs max "
        f"{worst_fw / FULL_STEP_RAD:.4f}; plant's (every period) max {figures['max_error_full_steps']:.4f}, final "
        f"{figures['final_error_full_steps']:+.4f}, "
        f"SIL's max {sil_sd['max_error_full_steps']:.4f} (|d| {d_error:.2g}); "
        f"theta-hat at the end {final_offset / FULL_STEP_RAD:.4f} from the count",
        f"[{case}] against the SIL: theta-hat, theta* read back within {worst_hat:.3g}, {worst_ref:.3g} rad; telemetry "
        f"({len(periods)} frames), largest |difference|: " + ", ".join(f"{k} {v:.3g}" for k, v in worst.items()),
    ]
    return report, failures


def main():
    ap = argparse.ArgumentParser()
    for k in ("qemu", "image", "sil", "out"):
        ap.add_argument(f"--{k}", required=True)
    ap.add_argument("--substeps", type=int, default=1)
    ap.add_argument("--decimation", type=int, default=200)
    ap.add_argument("--cases", default=",".join(CASES))
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    report = [
        f"pmstep STEP/DIR end to end on QEMU mps2-an386: the paper scenario, {a.substeps} plant steps a period, "
        f"the host's step stream on the emulated counter"
    ]
    failures = []
    for case in a.cases.split(","):
        r, f = run_case(a, out, case)
        report += r
        failures += f
    report += [f"FAIL: {f}" for f in failures[:40]] or ["PASS"]
    (out / "report.txt").write_text("\n".join(report) + "\n")
    print("\n".join(report))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
