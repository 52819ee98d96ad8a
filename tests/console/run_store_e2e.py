#!/usr/bin/env python3
"""End to end on QEMU: the stored configuration and self-commissioning of the mps2-an386 image
pmstep-pil-console (plant and core on the emulated Cortex-M4) with its flash kept in a host file
(--flash: read at boot, written through at every erase and program), driven by the host console
(tools/pmstep_console.py) over QEMU's serial socket. A restart of QEMU with the same file is a reset
of the board; the image stopping in a flash write (--power-cut-after N) is a power cut.

  empty      a board with an empty store: HELLO says no motor configured, START refused (error 10),
             `store` names the boot outcome "empty"
  setup      `setup --motor paper.ini` (pmstep-tune on the host for the board's period, delay and
             sensing): written, applied, read back, saved
  reset      the same flash, a new boot: the stored design in force (every value equal to setup's),
             then the paper scenario's commands (start, the speed command at 0.65 s) over SIM_ADVANCE;
             the target's summary matches the host SIL's run of the same configuration
             (pil-summary-compare, the PIL tolerances)
  power cut  a save of another design cut at its erase, its first and a middle program and its CRC's
             program: after each reset the previous record is in force, value for value
  calibrate  an erased flash, the motor free (no load), `calibrate --current 8 --pole-pairs 6
             --detent-fraction 0` (the paper's motor: 8 A, 6 pole pairs, no detent): done and saved; a reset:
             configured with the
             calibrated design; START and 5 rad/s: RUN at the speed, no fault. The measured R, L, k_M, J,
             F are set beside the plant's and the datasheet design's in the report.

Writes OUT/report.txt. What this proves and what not: the firmware's store, console and
self-commissioning across resets and cut saves, on the real core on the emulated Cortex-M4; not the
STM32G4's flash controller (hal/stm32g4's behavioural model tests its driver).

usage: run_store_e2e.py --qemu Q --image ELF --sil PMSTEP_SIL --tune PMSTEP_TUNE --compare PIL_SUMMARY_COMPARE
                        --out DIR
"""

import argparse
import atexit
import math
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import pmstep_console as pc  # noqa: E402
from run_console_e2e import free_port  # noqa: E402

PAPER = ROOT / "sil" / "scenarios" / "motors" / "paper.ini"
PERIOD_S = 50e-6
RUN_DURATION_S = 0.9  # the paper scenario, as run_console_e2e.py
CALIBRATE_DURATION_S = 9.0
SUBSTEPS = 2
PAPER_MOTOR = {
    "resistance_Ohm": 3.0,
    "inductance_H": 0.006,
    "torque_constant_Nm_A": 2.0,
    "inertia_kgm2": 0.01,
    "friction_Nms_rad": 0.0,
}


BOARDS = []  # every QEMU started, so that none outlives this script when a step fails


@atexit.register
def _stop_boards():
    for board in BOARDS:
        if board.qemu.poll() is None:
            board.qemu.kill()
            board.qemu.wait()


class Board:
    """One boot of the image: QEMU with the flash file (none: an image without a store), the console
    connected. @p extra: more of the image's options; @p nodelay: QEMU sends each byte of the image's
    replies at once (TCP_NODELAY; without it the host's delayed ACK holds a reply back some 40 ms)."""

    def __init__(
        self,
        a,
        flash,
        duration_s,
        summary=None,
        cut_after=None,
        no_load=False,
        substeps=SUBSTEPS,
        extra=(),
        nodelay=False,
    ):
        self.port = free_port()
        args = ["pil-console", "--duration", str(duration_s), "--substeps", str(substeps)]
        args += ["--flash", str(flash)] if flash is not None else []
        args += list(extra)
        if summary:
            args += ["--summary", str(summary)]
        if cut_after:
            args += ["--power-cut-after", str(cut_after)]
        if no_load:
            args.append("--no-load")
        semi = ",".join(["enable=on", "target=native"] + [f"arg={x}" for x in args])
        self.cmd = [
            a.qemu,
            "-M",
            "mps2-an386",
            "-cpu",
            "cortex-m4",
            "-nographic",
            "-monitor",
            "none",
            "-serial",
            f"tcp:127.0.0.1:{self.port},server=on,wait=on" + (",nodelay=on" if nodelay else ""),
            "-semihosting-config",
            semi,
            "-kernel",
            a.image,
        ]
        self.qemu = subprocess.Popen(self.cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        BOARDS.append(self)
        self.link = None
        for _ in range(200):
            try:
                self.link = pc.open_endpoint(f"tcp:127.0.0.1:{self.port}", timeout=0.05)
                break
            except Exception:  # noqa: BLE001 - QEMU not listening yet
                time.sleep(0.05)
        if self.link is None:
            self.qemu.kill()
            raise RuntimeError("could not connect to QEMU's serial socket")
        self.con = pc.Console(self.link, reply_timeout=20.0)

    def command(self, *argv):
        """One host-console command, as `pmstep_console.py --port ... ARGV` runs it; its output kept."""
        print("  $ pmstep_console.py " + " ".join(shlex.quote(x) for x in argv), flush=True)
        return pc.run_command(self.con, list(argv))

    def finish(self):
        """SIM_FINISH, then the image's exit status and its stderr."""
        try:
            self.con.sim_finish()
        finally:
            self.link.close()
        rc = self.qemu.wait(timeout=120)
        return rc, self.qemu.stderr.read().decode(errors="replace")

    def lost(self):
        """The image stopped by itself (a power cut): its exit status and stderr."""
        self.link.close()
        rc = self.qemu.wait(timeout=60)
        return rc, self.qemu.stderr.read().decode(errors="replace")


def values(con):
    board = pc.read_board(con)
    return {e["name"]: v for e, v in zip(board.table, board.record.values)}


def scenario_value(text_type, v):
    """A configuration value as the scenario reader takes it: booleans true/false, integers exact."""
    if text_type == "bool":
        return "true" if v else "false"
    if text_type in ("u32", "i32"):
        return str(int(v))
    return repr(v)


def main():
    ap = argparse.ArgumentParser()
    for k in ("qemu", "image", "sil", "tune", "compare", "out"):
        ap.add_argument(f"--{k}", required=True)
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    os.environ["PMSTEP_TUNE"] = a.tune
    flash = out / "flash.bin"
    report, failures = [], []

    def check(ok, what):
        (report if ok else failures).append(("ok: " if ok else "") + what)

    # ---- empty store ----
    flash.unlink(missing_ok=True)
    b = Board(a, flash, RUN_DURATION_S)
    hello = b.con.hello()
    check(
        hello["store"] and not hello["configured"],
        f"empty: HELLO says store {hello['store']}, configured {hello['configured']}",
    )
    try:
        b.con.start()
        check(False, "empty: START accepted with no motor configured")
    except pc.DeviceError as e:
        check(e.code == pc.ERR_NOT_CONFIGURED, f"empty: START refused with error {e.code}")
    st = b.con.config_status()
    check(st["boot_status"] == -140, f"empty: boot outcome {pc.store_outcome(st['boot_status'])}")

    # ---- setup from the paper's motor preset ----
    b.command("setup", "--motor", str(PAPER))
    designed = values(b.con)
    st = b.con.config_status()
    check(st["configured"] and st["slot"] >= 0, f"setup: saved in slot {st['slot']}, sequence {st['sequence']}")
    rc, err = b.finish()

    # ---- reset: the stored design in force; the paper scenario against the host SIL ----
    summary = out / "reset_summary.json"
    summary.unlink(missing_ok=True)
    b = Board(a, flash, RUN_DURATION_S, summary=summary)
    hello = b.con.hello()
    check(hello["configured"], f"reset: HELLO says configured {hello['configured']}")
    after = values(b.con)
    b_table = pc.read_board(b.con).table
    diff = [k for k in designed if designed[k] != after[k]]
    check(not diff, f"reset: {len(after)} values in force equal setup's" + (f" (differ: {diff})" if diff else ""))
    steps = int(math.floor(RUN_DURATION_S / PERIOD_S + 0.5))
    k_speed = next(k for k in range(steps) if k * pc.f32(PERIOD_S) >= 0.65)
    b.con.id_target(0.0)
    check(b.con.start() == 0, "reset: START accepted")
    b.con.sim_advance(k_speed, timeout=600.0)
    b.con.speed(10.0, 50.0)
    b.con.sim_advance(steps - k_speed, timeout=600.0)
    status = b.con.status()
    rc, err = b.finish()
    check(
        status["mode"] == "RUN" and status["fault"] == 0,
        f"reset: after the scenario {status['mode']}, fault {status['fault']}",
    )
    sets = []
    for e in b_table:
        if e["read_only"]:
            continue  # the board's read-only values: the paper scenario's own
        if e["name"].startswith("stepdir."):
            continue  # the STEP/DIR input's settings: the console's, not the core configuration the SIL runs
        sets += ["--set", f"controller.{e['name']}={scenario_value(e['type'], after[e['name']])}"]
    subprocess.run(
        [
            a.sil,
            "--quiet",
            "--no-csv",
            "--out",
            str(out / "sil"),
            "--set",
            f"run.duration_s={RUN_DURATION_S}",
            "--set",
            f"run.substeps={SUBSTEPS}",
        ]
        + sets,
        check=True,
    )
    cmp = subprocess.run(
        [a.compare, str(out / "sil" / "summary.json"), str(summary)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    (out / "reset_compare.txt").write_text(cmp.stdout)
    check(
        cmp.returncode == 0, "reset: the target's run of the stored design matches the host SIL's (pil-summary-compare)"
    )

    # ---- power cuts in a save ----
    unit_ops = 1 + (pc.RECORD_HEADER.size + 4 * len(after) + 4 * len(pc.MEASURED_FIELDS) + 4 + 7) // 8
    for cut in (1, 2, unit_ops // 2, unit_ops):
        b = Board(a, flash, RUN_DURATION_S, cut_after=cut)
        try:
            b.command("set", "motor.inertia_kgm2", "0.02")
            b.command("save")
            check(False, f"power cut at operation {cut}: the save completed")
        except pc.ConsoleError:
            pass
        rc, err = b.lost()
        check(
            rc == 5 and "power cut" in err, f"power cut at operation {cut} of {unit_ops}: the image stopped (exit {rc})"
        )
        b = Board(a, flash, RUN_DURATION_S)
        now = values(b.con)
        diff = [k for k in designed if designed[k] != now[k]]
        check(
            not diff and b.con.hello()["configured"],
            f"power cut at operation {cut}: after the reset the previous record is in force"
            + (f" (differ: {diff})" if diff else ""),
        )
        b.finish()

    # ---- calibrate from the rated current ----
    flash.unlink(missing_ok=True)
    b = Board(a, flash, CALIBRATE_DURATION_S, no_load=True)
    b.con.sim_advance(10, timeout=60.0)  # a few periods: the bus measured
    t0 = time.monotonic()
    calibrated = None
    try:
        b.command(
            "calibrate",
            "--current",
            "8",
            "--pole-pairs",
            "6",
            "--detent-fraction",
            "0",
            "--advance",
            "4000",
            "--timeout",
            "1200",
        )
        calibrated = b.con.calibrate_status()
        check(True, f"calibrate: done in {calibrated['runs']} runs ({time.monotonic() - t0:.0f} s wall)")
    except pc.ConsoleError as e:
        check(False, f"calibrate: {e}")
    cal_values = values(b.con)
    rc, err = b.finish()
    if calibrated is not None:
        b = Board(a, flash, CALIBRATE_DURATION_S, no_load=True)
        hello = b.con.hello()
        now = values(b.con)
        check(hello["configured"] and now == cal_values, "calibrate: after a reset the calibrated design is in force")
        check(b.con.start() == 0, "calibrate: START accepted")
        b.con.sim_advance(int(1.0 / PERIOD_S), timeout=900.0)
        b.con.speed(5.0, 20.0)
        b.con.sim_advance(int(1.0 / PERIOD_S), timeout=900.0)
        status = b.con.status()
        b.finish()
        check(
            status["mode"] == "RUN" and status["fault"] == 0 and abs(status["speed_hat_rad_s"] - 5.0) < 0.25,
            f"calibrate: the motor runs: {status['mode']}, fault {status['fault']}, speed_hat "
            f"{status['speed_hat_rad_s']:.4f} rad/s (5 commanded)",
        )
        rows = []
        for key, plant in PAPER_MOTOR.items():
            drive = calibrated[key]
            ds = designed[f"motor.{key}"]
            rel = f"{100.0 * (drive / plant - 1.0):+.2f} %" if plant else f"{drive:.3g}"
            rows.append(f"  {key:22s} plant {plant:<10.5g} datasheet design {ds:<10.5g} drive {drive:<10.5g} ({rel})")
        for name in (
            "gains.speed_gain_per_s",
            "gains.observer_gain_per_s",
            "gains.current_gain_per_s",
            "alignment.s_align_voltage_V",
            "alignment.c_align_time_s",
            "limits.max_phase_current_A",
        ):
            ds, drive = designed[name], cal_values[name]
            rows.append(
                f"  {name:30s} datasheet {ds:<10.5g} drive {drive:<10.5g} ({100.0 * (drive / ds - 1.0):+.1f} %)"
            )
        report.append("calibrate on the target, the paper's motor (robust mode; the datasheet design: paper mode):")
        report.extend(rows)
    report += [f"FAIL: {f}" for f in failures] or ["PASS"]
    (out / "report.txt").write_text("\n".join(report) + "\n")
    print("\n".join(report))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
