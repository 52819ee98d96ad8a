#!/usr/bin/env python3
"""Tests of the host console (tools/pmstep_console.py): framing and decoder, every command
against the real firmware console (console-host-drive: console + core on a pty), through the
pty endpoint and the command line; and the tool against a bad line (a fake peer on the pty's
master: noise, sync floods, short replies, a line that closes or takes no bytes, a missing port):
every wait ends by its deadline, every failure is one line and an exit status. The stored
configuration against console-host-drive --flash FILE (a reset: the drive killed and started again
on the same file): setup, backup, erase, restore, refusals, power cuts in a save.

usage: [PMSTEP_TUNE=PATH/TO/pmstep-tune] test_pmstep_console.py PATH/TO/console-host-drive
(the tests that run setup need PMSTEP_TUNE, and are skipped without it)
"""

import configparser
import contextlib
import io
import json
import math
import os
import re
import random
import select
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import pmstep_console as pc  # noqa: E402

DRIVE = None
TOOL = Path(pc.__file__).resolve()


def firmware_config_entries():
    """How many configuration values the firmware's table (pmstep_console_config.c) lists."""
    source = os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "firmware", "console", "src", "pmstep_console_config.c"
    )
    with open(source, encoding="utf-8") as f:
        return len(re.findall(r"^\s+(?:F32|U32|I32|BOOL|F32_RO|U32_RO|SD_F32|SD_U32|SD_BOOL)\(", f.read(), flags=re.M))


class Framing(unittest.TestCase):
    def test_crc_check_value(self):
        self.assertEqual(pc.crc16(b"123456789"), 0x29B1)  # CRC-16/CCITT-FALSE

    def test_round_trip_through_noise(self):
        frames = [pc.encode(pc.HELLO, 1), pc.encode(pc.SPEED_TARGET, 2, struct.pack("<ff", 10.0, 50.0))]
        bad = bytearray(pc.encode(pc.STOP, 3))
        bad[-1] ^= 0xFF
        stream = b"\x00\x13garbage" + frames[0] + bytes(bad) + b"\xa5\xff" + frames[1]
        d = pc.Decoder()
        got = []
        for i in range(0, len(stream), 3):  # fed in pieces
            got += d.feed(stream[i : i + 3])
        self.assertEqual([(t, s) for t, s, _ in got], [(1, 1), (5, 2)])
        self.assertEqual(struct.unpack("<ff", got[1][2]), (10.0, 50.0))
        self.assertGreater(d.bad, 0)

    def test_position_requests_encoded(self):
        frame = pc.encode(pc.MOVE_TO, 9, struct.pack("<ffff", -1.5, 5.0, 50.0, 0.0))
        ((ftype, seq, data),) = pc.Decoder().feed(frame)
        self.assertEqual((ftype, seq, len(data)), (0x0D, 9, 16))
        self.assertEqual(struct.unpack("<ffff", data), (-1.5, 5.0, 50.0, 0.0))
        self.assertEqual((pc.HOLD, pc.GET_POSITION, pc.SET_POSITION_ZERO), (0x0E, 0x0F, 0x10))

    def test_too_long(self):
        with self.assertRaises(ValueError):
            pc.encode(pc.HELLO, 1, bytes(63))


class AgainstTheFirmwareConsole(unittest.TestCase):
    """The tool on one side of a pty, console-host-drive (the C console and the core) on the other."""

    DRIVE_ARGS = []

    def setUp(self):
        self.master, slave = os.openpty()
        self.slave_name = os.ttyname(slave)
        os.close(slave)
        self.drive = subprocess.Popen([DRIVE] + self.DRIVE_ARGS, stdin=self.master, stdout=self.master)
        self.link = pc.open_endpoint(self.slave_name, 115200)
        self.con = pc.Console(self.link)

    def tearDown(self):
        try:
            self.con.sim_finish()
        except Exception:
            pass
        self.link.close()
        try:
            self.drive.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.drive.kill()
        os.close(self.master)

    def test_full_dialogue(self):
        c = self.con
        hello = c.hello()
        self.assertEqual(hello["protocol"], pc.PROTOCOL_VERSION)
        self.assertEqual(hello["identity"], "pmstep host-drive")
        # No store attached: no record format, and the image's own configuration counts as a motor's.
        self.assertEqual((hello["record_format"], hello["store"], hello["configured"]), (0, False, True))
        with self.assertRaisesRegex(pc.DeviceError, "no stored configuration in this image"):
            c.config_status()
        table = c.list_config()
        self.assertEqual(len(table), firmware_config_entries())
        names = [e["name"] for e in table]
        self.assertEqual(len(set(names)), len(names))
        self.assertIn("gains.angle_smoothing", names)
        self.assertIn("standstill.stops_only", names)
        self.assertIn("inverter.phase_voltage_sensing", names)
        self.assertIn("standstill.hold_current_A", names)
        self.assertIn("standstill.vector_speed_rad_s", names)
        self.assertEqual(c.get_config("gains.speed_gain_per_s")["value"], 100.0)
        self.assertTrue(c.get_config("timing.period_s")["read_only"])
        c.set_config("gains.speed_gain_per_s", 120.0)
        self.assertEqual(c.get_config(12)["value"], 120.0)
        with self.assertRaisesRegex(pc.DeviceError, "read-only"):
            c.set_config("timing.period_s", 1e-4)
        with self.assertRaisesRegex(pc.DeviceError, "unknown configuration"):
            c.get_config("no_such_value")
        with self.assertRaisesRegex(pc.DeviceError, "status -20"):  # PMSTEP_ERR_RESISTANCE
            c.set_config("motor.resistance_Ohm", -1.0)
        # The STEP/DIR settings: by name like the rest, each value out of range refused with its own code.
        for name in (
            "stepdir.microsteps",
            "stepdir.invert_direction",
            "stepdir.enable_active_high",
            "stepdir.diag_active_high",
            "stepdir.diag_mode",
            "stepdir.following_error_limit_full_steps",
        ):
            self.assertIn(name, names)
        self.assertEqual(c.get_config("stepdir.microsteps")["value"], 16.0)
        for name, value, code in (
            ("stepdir.microsteps", 0, r"status -135 \(PMSTEP_ERR_STEPDIR_MICROSTEPS"),
            ("stepdir.microsteps", 257, r"status -135 \(PMSTEP_ERR_STEPDIR_MICROSTEPS"),
            ("stepdir.diag_mode", 2, r"status -138 \(PMSTEP_ERR_STEPDIR_DIAG_MODE"),
            ("stepdir.following_error_limit_full_steps", 0.0, r"status -137 \(PMSTEP_ERR_STEPDIR_LIMIT"),
        ):
            with self.subTest(name=name, value=value), self.assertRaisesRegex(pc.DeviceError, code):
                c.set_config(name, value)
        self.assertEqual(c.get_config("stepdir.microsteps")["value"], 16.0)
        c.set_config("stepdir.microsteps", 64)
        self.assertEqual(c.get_config("stepdir.microsteps")["value"], 64.0)
        self.assertEqual(c.status()["mode"], "IDLE")
        c.id_target(0.0)
        c.set_telemetry(10)
        self.assertEqual(c.start(), 0)
        self.assertEqual(c.sim_advance(100), 100)
        c.pump(0.2)
        self.assertEqual([int(r["period"]) for r in c.telemetry], list(range(10, 100, 10)))
        self.assertTrue(all(r["mode"] == 1 and r["bus_voltage_V"] == 48.0 for r in c.telemetry))
        s = c.status()
        self.assertEqual((s["mode"], s["period"], s["fault"]), ("S_ALIGN", 99, 0))
        self.assertAlmostEqual(s["i_a_A"], 0.3, places=6)
        with self.assertRaisesRegex(pc.DeviceError, "refused while the motor runs"):
            c.set_config("gains.speed_gain_per_s", 90.0)
        with self.assertRaisesRegex(pc.DeviceError, "bad value"):
            c.speed(math.nan, 50.0)
        with self.assertRaisesRegex(pc.DeviceError, "status -2"):  # PMSTEP_ERR_BAD_MODE
            c.start()
        self.assertEqual(c.speed(5.0, 20.0), 100)
        cm = c.commissioning()
        self.assertFalse(cm["measured"])
        n = c.counters()
        self.assertEqual(n["rx_crc_errors"], 0)
        self.assertGreater(n["commands_applied"], 10)
        self.assertEqual(c.stop(), 100)
        self.assertEqual(c.sim_advance(1), 101)
        self.assertEqual(c.status()["mode"], "IDLE")  # the step after the stop
        # Telemetry to CSV and back.
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "t.csv")
            pc.write_csv(path, c.telemetry)
            rows = pc.read_csv(path)
            self.assertEqual([r["speed_ref_rad_s"] for r in rows], [r["speed_ref_rad_s"] for r in c.telemetry])
            try:
                import matplotlib  # noqa: F401
            except ImportError:
                return
            png = os.path.join(d, "t.png")
            self.assertEqual(pc.main(["plot", path, png]), 0)
            self.assertGreater(os.path.getsize(png), 1000)

    def test_position_requests_without_position_control(self):
        c = self.con
        for call in (lambda: c.move_to(1.0), lambda: c.hold(), c.position, c.set_position_zero):
            with self.assertRaisesRegex(pc.DeviceError, "no position control"):
                call()
        self.assertEqual(c.counters()["rx_error_replies"], 4)

    def test_sim_stepdir_without_the_input(self):
        c = self.con
        for call in (lambda: c.sim_steps([1, -1]), c.sim_follow_steps, c.sim_stepdir):
            with self.assertRaisesRegex(pc.DeviceError, "not supported by this image"):
                call()
        self.assertEqual(c.counters()["rx_error_replies"], 3)

    def test_interactive(self):
        out = io.StringIO()
        shell = pc.Shell(self.con)
        with contextlib.redirect_stdout(out):
            shell.onecmd("hello")
            shell.onecmd("speed nan")  # refused by the drive: an error line, the shell goes on
            shell.onecmd("id 0.5")
            shell.onecmd("no_such_command")
            self.assertTrue(shell.onecmd("quit"))
        text = out.getvalue()
        self.assertIn("pmstep host-drive", text)
        self.assertIn("error: request 0x05: bad value", text)
        self.assertIn("i_d target 0.5 A: from period 0", text)
        self.assertIn("unknown command: no_such_command", text)

    def test_command_line(self):
        out = io.StringIO()
        self.link.close()
        with contextlib.redirect_stdout(out):
            self.assertEqual(pc.main(["--port", self.slave_name, "status"]), 0)
            self.assertEqual(pc.main(["--port", self.slave_name, "get", "motor.inertia_kgm2"]), 0)
            self.assertEqual(pc.main(["--port", self.slave_name, "start"]), 0)
        text = out.getvalue()
        self.assertIn("mode", text)
        self.assertIn("IDLE", text)
        self.assertIn("inertia_kgm2 = 0.01", text)
        self.assertIn("start: done from period 0", text)
        self.link = pc.open_endpoint(self.slave_name, 115200)
        self.con = pc.Console(self.link)


class AgainstAPositionDrive(AgainstTheFirmwareConsole):
    """console-host-drive --position: position control attached. Its constant samples never reach
    RUN, so the position requests come back with the core's status (the encoding of a move's
    read-back in RUN is checked end to end on QEMU, console.qemu_e2e)."""

    DRIVE_ARGS = ["--position"]

    def test_position_requests_without_position_control(self):
        pass  # attached here

    def test_sim_stepdir_without_the_input(self):
        pass  # attached here

    def test_sim_stepdir(self):
        c = self.con
        s = c.sim_stepdir()
        self.assertEqual(
            (s["steps"], s["edges"], s["counter"], s["following"], s["moving"], s["diag"]),
            (0, 0, 0, False, False, False),
        )
        self.assertEqual(c.sim_steps([-128] * pc.SIM_STEPS_MAX), 0)
        with self.assertRaisesRegex(pc.DeviceError, "busy"):  # the first's edges not out yet
            c.sim_steps([1])
        for bad in ([], [128], [0] * (pc.SIM_STEPS_MAX + 1)):
            with self.assertRaises(pc.UsageError):
                c.sim_steps(bad)
        self.assertEqual(c.sim_advance(100), 100)  # 60 periods of edges, then none
        self.assertEqual(c.sim_steps([127] * 20 + [1]), 0)
        self.assertEqual(c.sim_advance(21), 121)
        total = -128 * pc.SIM_STEPS_MAX + 127 * 20 + 1
        s = c.sim_stepdir()
        self.assertEqual((s["period"], s["steps"], s["edges"], s["counter"]), (120, total, total, total % 65536))
        self.assertAlmostEqual(s["commanded_rad"], total * 2 * math.pi / (4 * 6 * 16), places=2)  # p 6, 16 microsteps
        with self.assertRaisesRegex(pc.DeviceError, "status -2"):  # not tracked: the drive never reaches RUN
            c.sim_follow_steps()
        self.assertEqual(c.sim_stepdir()["steps"], total)  # refused: the input as it was
        self.assertEqual(c.counters()["rx_error_replies"], 1)

    def test_position_before_run(self):
        c = self.con
        p = c.position()
        self.assertEqual((p["status"], p["tracked"], p["position_mode"], p["moving"]), (-2, False, False, False))
        self.assertEqual(p["position_rad"], 0.0)
        with self.assertRaisesRegex(pc.DeviceError, "status -2"):  # PMSTEP_ERR_BAD_MODE: not in RUN
            c.move_to(1.0, 2.0, 20.0)
        with self.assertRaisesRegex(pc.DeviceError, "status -2"):
            c.hold(10.0)
        with self.assertRaisesRegex(pc.DeviceError, "status -2"):
            c.set_position_zero()
        with self.assertRaisesRegex(pc.DeviceError, "bad value"):
            c.move_to(math.inf, 2.0, 20.0)
        self.assertEqual(c.start(), 0)
        self.assertEqual(c.sim_advance(10), 10)
        self.assertEqual(c.position()["period"], 9)
        n = c.counters()
        self.assertEqual((n["rx_error_replies"], n["commands_applied"]), (1, 6))

    def test_home_before_run(self):
        c = self.con
        h = c.home_status()
        self.assertEqual((h["status"], h["state"], h["position_rad"]), (0, "idle", 0.0))
        with self.assertRaisesRegex(pc.DeviceError, "refused to home.*-2"):  # not tracked: not in RUN
            c.home(1.0, 2.0)
        with self.assertRaisesRegex(pc.DeviceError, "bad value"):
            c.home(1.0, math.nan)
        out = io.StringIO()
        err = io.StringIO()
        self.link.close()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            self.assertEqual(pc.main(["--port", self.slave_name, "home", "+"]), 2)  # no --travel: usage
            self.assertEqual(pc.main(["--port", self.slave_name, "home", "up", "--travel", "1"]), 2)
            self.assertEqual(pc.main(["--port", self.slave_name, "home", "-", "--travel", "1"]), 1)
        self.assertIn("home +|- --travel RAD", err.getvalue())
        self.assertIn("refused to home", err.getvalue())
        self.link = pc.open_endpoint(self.slave_name, 115200)
        self.con = pc.Console(self.link)
        self.assertEqual(self.con.home_status()["state"], "idle")

    def test_command_line_position(self):
        out = io.StringIO()
        err = io.StringIO()
        self.link.close()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            self.assertEqual(pc.main(["--port", self.slave_name, "position"]), 0)
            self.assertEqual(pc.main(["--port", self.slave_name, "move", "-1.5", "--vmax", "2", "--amax", "20"]), 1)
            self.assertEqual(pc.main(["--port", self.slave_name, "hold"]), 1)
            self.assertEqual(pc.main(["--port", self.slave_name, "zero"]), 1)
        self.assertIn("status                     -2", out.getvalue())
        self.assertIn("tracked                    False", out.getvalue())
        self.assertEqual(err.getvalue().count("refused request"), 3)
        self.link = pc.open_endpoint(self.slave_name, 115200)
        self.con = pc.Console(self.link)


REPO = Path(__file__).resolve().parents[2]
MOTOR = REPO / "sil" / "scenarios" / "motors" / "17hs4401.ini"
MOTOR_DB = REPO / "tests" / "closed_loop" / "data" / "klipper_motors.cfg"
TUNE = os.environ.get("PMSTEP_TUNE")  # pmstep-tune of the same build (the CMake test passes it)
needs_tune = unittest.skipUnless(TUNE and os.access(TUNE, os.X_OK), "PMSTEP_TUNE does not name a pmstep-tune binary")


class CodeNames(unittest.TestCase):
    """The host tool's names of status codes: the store's table against its header, the core's from
    its header at run time."""

    def parse_header_enum(self, header, name):
        import gen_reference  # tools/, on the path above

        return {v.value: v.name for v in gen_reference.parse_enum(gen_reference.Source(REPO, header), name)}

    def test_store_codes_match_the_header(self):
        header = self.parse_header_enum("firmware/console/include/pmstep_store.h", "pmstep_store_status_t")
        self.assertEqual({code: row[0] for code, row in pc.STORE_CODES.items()}, header)

    def test_request_names_match_the_header(self):
        header = self.parse_header_enum("firmware/console/include/pmstep_console.h", "pmstep_console_type_t")
        frames = {pc.TELEMETRY_FRAME, pc.ERROR_FRAME}  # not requests
        self.assertEqual(set(pc.REQUEST_NAMES), set(header) - frames)

    def test_console_errors_match_the_header(self):
        header = self.parse_header_enum("firmware/console/include/pmstep_console.h", "pmstep_console_error_t")
        self.assertEqual(set(pc.ERRORS), set(header))

    def test_core_codes_named_from_the_header(self):
        header = self.parse_header_enum("firmware/include/pmstep/pmstep_types.h", "pmstep_status_t")
        code = next(v for v, n in header.items() if n == "PMSTEP_ERR_INERTIA")
        self.assertTrue(pc.describe_code(code).startswith(f"status {code} (PMSTEP_ERR_INERTIA: "))
        self.assertIn("(PMSTEP_STORE_ERR_FORMAT, another format: a record of another firmware)", pc.describe_code(-142))
        self.assertIn("a record of another firmware", pc.store_outcome(-142))
        self.assertEqual(pc.describe_code(-9999), "status -9999")  # no name: the number

    def test_record_round_trip(self):
        rec = pc.Record(
            pc.RECORD_FORMAT,
            0x1234,
            0xABCD,
            0,
            [pc.f32(0.1), 2.0, -3.5],
            dict(zip(pc.MEASURED_FIELDS, [6] + [pc.f32(0.01 * k) for k in range(7)])),
        )
        data = rec.encode()
        self.assertEqual(len(data), 32 + 4 * 3 + 4 * 8 + 4)
        back = pc.Record.decode(data)
        self.assertEqual(
            (back.board_id, back.layout_id, back.values, back.measured),
            (rec.board_id, rec.layout_id, rec.values, rec.measured),
        )
        bad = bytearray(data)
        bad[40] ^= 1
        with self.assertRaisesRegex(pc.MalformedReply, "CRC"):
            pc.Record.decode(bytes(bad))


class AgainstAStoredConfiguration(unittest.TestCase):
    """console-host-drive --flash FILE: the stored configuration on a flash kept in a file. A reset of
    the board is the process killed (a power cut) and started again on the same file; the tool runs
    as on the command line (pc.main) on the pty's other side."""

    BOARD_ID = 0x0B0A4D17

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.flash = os.path.join(self.tmp.name, "flash.bin")
        self.master, slave = os.openpty()
        self.slave_name = os.ttyname(slave)
        os.close(slave)
        self.drive = None
        self.boot()

    def tearDown(self):
        self.power_off()
        os.close(self.master)
        self.tmp.cleanup()

    def power_off(self):
        """Kills the drive (a power cut: the file holds what its flash holds); @return its exit
        status and what it wrote on stderr."""
        if self.drive is None:
            return None, ""
        if self.drive.poll() is None:
            self.drive.kill()
        _, err = self.drive.communicate(timeout=10)
        code, self.drive = self.drive.returncode, None
        return code, err.decode("utf-8", "replace")

    def boot(self, *args):
        """A reset: the drive started again on the same flash file, the bytes of the old one's line
        dropped."""
        self.power_off()
        os.set_blocking(self.master, False)
        try:
            while os.read(self.master, 4096):
                pass
        except OSError:  # nothing more (EAGAIN), or the tool's side is not open (EIO)
            pass
        self.drive = subprocess.Popen(
            [DRIVE, "--flash", self.flash, "--board-id", hex(self.BOARD_ID), *args],
            stdin=self.master,
            stdout=self.master,
            stderr=subprocess.PIPE,
        )

    def cli(self, *args):
        """The command line against the drive: (exit status, stdout, stderr)."""
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = pc.main(["--port", self.slave_name, *args])
            except SystemExit as e:  # argparse
                code = e.code
        return code, out.getvalue(), err.getvalue()

    def ok(self, *args):
        code, out, err = self.cli(*args)
        self.assertEqual(code, 0, f"{args}: {out}{err}")
        return out

    def hello(self):
        out = self.ok("hello")
        return {k: v for k, v in re.findall(r"^  (\w+) +(.*)$", out, flags=re.M)}

    def take_backup(self, name):
        path = os.path.join(self.tmp.name, name)
        self.ok("backup", path)
        with open(path, encoding="utf-8") as f:
            return path, json.load(f)

    def design(self, *motor):
        """pmstep-tune's design for the board, run here, not by the tool: @p motor (its motor arguments),
        the board's read-only values (read with `get`) as the scenario's; the [controller.*] values by
        the table's names."""
        ini = os.path.join(self.tmp.name, "design.ini")
        argv = [TUNE, *motor]
        for name, key in pc.READ_ONLY_SCENARIO_KEYS.items():
            value = re.search(r"= (\S+) ", self.ok("get", name)).group(1)
            argv += ["--set", f"{key}={value}"]
        subprocess.run(argv + ["--write-ini", ini], check=True, stdout=subprocess.DEVNULL)
        cp = configparser.ConfigParser(interpolation=None)
        cp.optionxform = str
        cp.read(ini)
        out = {}
        for section in cp.sections():
            if section.startswith("controller"):
                for key, text in cp.items(section):
                    name = (section[len("controller.") :] + "." if section != "controller" else "") + key
                    out[name] = {"true": 1.0, "false": 0.0}.get(text, None)
                    out[name] = out[name] if out[name] is not None else float(text)
        return out

    def test_empty_store_refuses_start(self):
        h = self.hello()
        self.assertEqual(
            (h["protocol"], h["record_format"], h["store"], h["configured"]),
            (str(pc.PROTOCOL_VERSION), str(pc.RECORD_FORMAT), "True", "False"),
        )
        code, _, err = self.cli("start")
        self.assertEqual(code, 1)
        self.assertIn("no motor configured", err)
        self.assertIn("setup --motor MOTOR.ini", err)
        self.assertEqual(len(err.splitlines()), 1, err)
        code, _, err = self.cli("save")
        self.assertEqual(code, 1)
        self.assertIn("nothing to save", err)
        out = self.ok("store")
        self.assertRegex(out, r"configured +no")
        self.assertRegex(out, r"boot +empty \(")
        self.assertRegex(out, r"board id +0x0b0a4d17")
        with open(self.flash, "rb") as f:  # the absent file became an erased flash
            self.assertEqual(f.read(), b"\xff" * 4096)

    def test_setup_errors_write_nothing(self):
        for args, code, message in (
            (["setup"], 2, "give --motor"),
            (
                ["setup", "--motor", str(MOTOR), "--tune", "/nonexistent/pmstep-tune"],
                2,
                "pmstep-tune not found at /nonexistent/pmstep-tune",
            ),
            (["setup", "--motor", str(MOTOR), "--set", "run.period_s=1e-4"], 2, "read-only"),
            (["setup", "--motor", "/nonexistent.ini"], 2, "no such file"),
        ):
            with self.subTest(args=args):
                got, _, err = self.cli(*args)
                self.assertEqual(got, code, err)
                self.assertIn(message, err)
        self.assertRegex(self.ok("store"), r"configured +no")

    @needs_tune
    def test_setup_reset_backup_erase_restore(self):
        out = self.ok("setup", "--motor", str(MOTOR))
        self.assertIn("read back equal", out)
        self.assertIn("saved: slot 0, sequence 1", out)
        self.assertIn("bus 24 V (the motor preset's run.bus_voltage_V)", out)
        design = self.design("--motor", str(MOTOR))
        self.boot()  # reset
        h = self.hello()
        self.assertEqual(h["configured"], "True")
        self.assertIn(
            f"motor.resistance_Ohm = {pc.f32_text(pc.f32(design['motor.resistance_Ohm']))} ",
            self.ok("get", "motor.resistance_Ohm"),
        )
        path, saved = self.take_backup("setup.json")
        # Every value the design gives and the board has is the design's (float32); the rest the board's.
        for name, value in saved["values"].items():
            if name in design:
                self.assertEqual(pc.f32(float(value)), pc.f32(design[name]), name)
        self.assertRegex(self.ok("store"), r"boot +ok")
        self.boot("--board-id", hex(self.BOARD_ID + 1))  # the same flash on another board: not loaded
        self.assertEqual(self.hello()["configured"], "False")
        self.assertRegex(self.ok("store"), r"boot +another board \(made for another board: ")
        self.boot()
        out = self.ok("erase")
        self.assertIn("no motor configured", out)
        self.assertEqual(self.cli("start")[0], 1)  # the defaults in force at once
        self.boot()
        self.assertEqual(self.hello()["configured"], "False")
        self.assertRegex(self.ok("store"), r"boot +empty")
        out = self.ok("restore", path, "--save")
        self.assertIn("saved: slot 0, sequence 1", out)
        self.boot()
        self.assertEqual(self.hello()["configured"], "True")
        _, again = self.take_backup("again.json")
        self.assertEqual(again, saved)
        self.assertIn("start: done", self.ok("start"))
        link = pc.open_endpoint(self.slave_name)
        try:
            pc.Console(link).sim_advance(3)  # the steps of the alignment: the motor runs
        finally:
            link.close()
        code, _, err = self.cli("restore", path)
        self.assertEqual(code, 1, err)
        # S_ALIGN, or FAULT: the host drive's constant 48 V bus is above the trip designed for 24 V
        self.assertRegex(
            err,
            r"restore needs the motor stopped \(IDLE\), it is in "
            r"(S_ALIGN: `stop`|FAULT: `clear`) first",
        )

    @needs_tune
    def test_stepdir_settings_saved_backed_up_and_restored(self):
        self.ok("setup", "--motor", str(MOTOR))
        self.ok("set", "stepdir.microsteps", "32")
        self.ok("set", "stepdir.enable_active_high", "1")
        self.ok("set", "stepdir.following_error_limit_full_steps", "1.5")
        code, _, err = self.cli("set", "stepdir.microsteps", "300")
        self.assertEqual(code, 1, err)
        self.assertIn("PMSTEP_ERR_STEPDIR_MICROSTEPS", err)
        self.ok("save")
        self.boot()  # reset: the saved STEP/DIR settings in force again
        self.assertIn("stepdir.microsteps = 32 ", self.ok("get", "stepdir.microsteps"))
        self.assertIn("stepdir.enable_active_high = 1 ", self.ok("get", "stepdir.enable_active_high"))
        path, saved = self.take_backup("stepdir.json")
        self.assertEqual(saved["values"]["stepdir.microsteps"], 32)
        self.assertIs(saved["values"]["stepdir.enable_active_high"], True)
        self.assertEqual(saved["values"]["stepdir.following_error_limit_full_steps"], 1.5)
        # A backup of the firmware before the STEP/DIR settings (no stepdir.* values) restores here: the
        # STEP/DIR settings in force are kept, and said so.
        older = dict(saved, values={k: v for k, v in saved["values"].items() if not k.startswith("stepdir.")})
        old_path = os.path.join(self.tmp.name, "before-stepdir.json")
        with open(old_path, "w", encoding="utf-8") as f:
            json.dump(older, f)
        self.ok("defaults")
        out = self.ok("restore", old_path, "--save")
        self.assertRegex(
            out,
            r"not in the backup, the value in force kept: stepdir\.microsteps, "
            r"stepdir\.invert_direction, ",
        )
        self.boot()
        self.assertEqual(self.hello()["configured"], "True")
        self.assertIn("stepdir.microsteps = 16 ", self.ok("get", "stepdir.microsteps"))
        self.ok("restore", path, "--save")
        self.boot()
        self.assertIn("stepdir.microsteps = 32 ", self.ok("get", "stepdir.microsteps"))

    @needs_tune
    def test_refused_restores_change_nothing(self):
        self.ok("setup", "--motor", str(MOTOR))
        path, saved = self.take_backup("setup.json")

        def edited(name, change):
            data = json.loads(json.dumps(saved))
            change(data)
            p = os.path.join(self.tmp.name, name)
            with open(p, "w", encoding="utf-8") as f:
                json.dump(data, f)
            return p

        cases = [
            (
                edited("inertia.json", lambda d: d["values"].update({"motor.inertia_kgm2": -1e-5})),
                1,
                r"refused the record: status -\d+ \(PMSTEP_ERR_INERTIA: ",
            ),  # the core's code, by name
            (
                edited("unknown.json", lambda d: d["values"].update({"no.such_value": 1.0})),
                1,
                r"values this board does not: no\.such_value;",
            ),
            (
                edited("period.json", lambda d: d["values"].update({"timing.period_s": 1e-4})),
                1,
                r"other read-only values: timing\.period_s \(backup 0\.0001, board ",
            ),
            (
                edited("pole_pairs.json", lambda d: d["values"].update({"motor.pole_pairs": 50.5})),
                1,
                r"motor\.pole_pairs = 50\.5: not a whole number",
            ),
            (edited("novalues.json", lambda d: d.pop("values")), 2, r"no \"values\" by name"),
        ]
        for p, code, message in cases:
            with self.subTest(os.path.basename(p)):
                got, _, err = self.cli("restore", p, "--save")
                self.assertEqual(got, code, err)
                self.assertRegex(err, message)
                self.assertEqual(len(err.splitlines()), 1, err)
                self.assertEqual(self.take_backup("now.json")[1], saved)
        self.boot()
        self.assertEqual(self.take_backup("after_reset.json")[1], saved)
        self.assertRegex(self.ok("store"), r"sequence +1\n")

    @needs_tune
    def test_motor_database_and_a_refused_design(self):
        out = self.ok("setup", "--motor-db", str(MOTOR_DB), "--name", "ldo-42sth48-2504ah", "--bus-voltage", "36")
        self.assertIn("bus 36 V (--bus-voltage)", out)
        self.assertIn("saved: slot 0, sequence 1", out)
        design = self.design(
            "--motor-db", str(MOTOR_DB), "--name", "ldo-42sth48-2504ah", "--set", "run.bus_voltage_V=36"
        )
        self.assertIn(
            f"limits.max_bus_voltage_V = {pc.f32_text(pc.f32(design['limits.max_bus_voltage_V']))} ",
            self.ok("get", "limits.max_bus_voltage_V"),
        )  # the trip designed for 36 V
        _, before = self.take_backup("before.json")
        code, out, err = self.cli("setup", "--motor-db", str(MOTOR_DB), "--name", "ncm-as-nm")  # N cm as N m
        self.assertEqual(code, 1, err)
        self.assertIn("pmstep-tune refused the design (exit 1); nothing written", err)
        self.assertEqual(self.take_backup("after.json")[1], before)

    @needs_tune
    def test_power_cut_in_a_save_keeps_the_previous_record(self):
        """The drive loses its power in the middle of a save (its own flash operation number N cut
        half-way, then it exits): after the reset the record saved before is in force. The cut at
        the save's erase, its first program, one half-way, and the CRC's (the last); then a save
        without a cut, which the next reset finds."""
        self.ok("setup", "--motor", str(MOTOR))
        _, saved = self.take_backup("setup.json")
        units = (len(saved["record"]) // 2 + 7) // 8  # 8-byte programs of a save, after its erase
        gain = saved["values"]["gains.speed_gain_per_s"]
        for cut in (1, 2, 1 + units // 2, 1 + units):
            with self.subTest(cut=cut):
                self.boot("--power-cut-after", str(cut))
                self.ok("set", "gains.speed_gain_per_s", str(gain + 10))
                code, _, err = self.cli("save")
                self.assertEqual(code, 3, err)  # no reply: the drive is gone
                status, drive_err = self.power_off()
                self.assertEqual(status, 3)
                self.assertIn(f"power cut in flash operation {cut} ({'erase' if cut == 1 else 'program'}", drive_err)
                self.boot()
                self.assertEqual(self.take_backup("after.json")[1], saved)
                self.assertRegex(self.ok("store"), r"slot +0\n  sequence +1\n")
        self.boot("--power-cut-after", str(2 + units))  # after the save's last operation
        self.ok("set", "gains.speed_gain_per_s", str(gain + 10))
        self.assertIn("saved: slot 1, sequence 2", self.ok("save"))
        self.boot()
        self.assertIn(f"= {pc.f32_text(pc.f32(gain + 10))} ", self.ok("get", "gains.speed_gain_per_s"))


class AgainstABadLine(unittest.TestCase):
    """The tool on one side of a pty, a fake peer (a thread of this test) on the master. A peer
    lives at most PEER_LIFETIME_S, then goes quiet: a tool whose wait does not end at its deadline
    comes back then and fails the timing assertion instead of hanging the run. Timing bounds are
    generous (the deadline plus seconds): they tell "ended at the deadline" from "ended when the
    line went quiet", nothing finer."""

    REPLY_TIMEOUT_S = 0.3
    WAIT_BOUND_S = 2.0  # a wait of REPLY_TIMEOUT_S must end within this
    PEER_LIFETIME_S = 6.0  # > WAIT_BOUND_S: a hanging tool is seen as one
    # The short reply the peer sends to each request, in DATA bytes (the right length in brackets).
    SHORT_REPLY_BYTES = {
        pc.HELLO: 1,  # (2 or more)
        pc.START: 5,  # ACK (6)
        pc.GET_STATUS: 3,  # (60)
        pc.GET_CONFIG: 6,  # (7 or more)
        pc.GET_COMMISSIONING: 9,  # (41)
        pc.GET_COUNTERS: 43,  # (44)
        pc.GET_POSITION: 18,
    }  # (19)

    def setUp(self):
        self.master, self.slave = os.openpty()  # the slave stays open: the master reads no EIO
        self.slave_name = os.ttyname(self.slave)  # before the tool (a subprocess) opens the pty
        os.set_blocking(self.master, False)
        self.master_open = True
        self.stop = threading.Event()
        self.peer = None
        self.link = pc.open_endpoint(self.slave_name, 115200)  # raw mode before the peer writes
        self.con = pc.Console(self.link, reply_timeout=self.REPLY_TIMEOUT_S)

    def tearDown(self):
        self.stop.set()
        if self.peer is not None:
            self.peer.join(timeout=10)
        self.link.close()
        if self.master_open:
            os.close(self.master)
        os.close(self.slave)

    # ---- the fake peer ----
    def start_peer(self, behaviour, *args):
        self.peer_end = time.monotonic() + self.PEER_LIFETIME_S
        self.peer = threading.Thread(target=behaviour, args=args, daemon=True)
        self.peer.start()

    def alive(self):
        return not self.stop.is_set() and time.monotonic() < self.peer_end

    def write(self, data):
        """Writes @p data to the master unless the peer's life ends first (a full pty: retried)."""
        while data and self.alive():
            try:
                data = data[os.write(self.master, data) :]
            except BlockingIOError:
                time.sleep(0.001)

    def requests(self):
        """The requests the tool sends, as (type, seq), while the peer lives."""
        decoder = pc.Decoder()
        while self.alive():
            if not select.select([self.master], [], [], 0.01)[0]:
                continue
            try:
                data = os.read(self.master, 4096)
            except BlockingIOError:
                continue
            for ftype, seq, _ in decoder.feed(data):
                yield ftype, seq

    def close_master(self):
        os.close(self.master)
        self.master_open = False

    def noise(self, chunk_bytes, interval_s, byte=None):
        rng = random.Random(57)
        while self.alive():
            self.write(bytes([byte]) * chunk_bytes if byte is not None else rng.randbytes(chunk_bytes))
            time.sleep(interval_s)

    def short_replies(self, close_at_request=None):
        """Answers each request with a reply of its type and seq, SHORT_REPLY_BYTES long; closes
        the line 0.2 s after request number @p close_at_request (1: the first) arrives."""
        for n, (ftype, seq) in enumerate(self.requests(), 1):
            if n == close_at_request:
                time.sleep(0.2)
                self.close_master()
                return
            self.write(pc.encode(ftype | 0x80, seq, bytes(self.SHORT_REPLY_BYTES.get(ftype, 0))))

    def drain_after_lifetime(self):
        """Reads nothing while it lives (the pty fills, the tool's writes stall), then drains."""
        self.stop.wait(self.PEER_LIFETIME_S)
        while not self.stop.is_set():
            try:
                os.read(self.master, 65536)
            except BlockingIOError:
                time.sleep(0.001)

    # ---- every wait ends by its deadline ----
    def assert_waits_end_at_the_deadline(self):
        t0 = time.monotonic()
        with self.assertRaises(TimeoutError):
            self.con.status()
        wait_s = time.monotonic() - t0
        self.assertLess(wait_s, self.WAIT_BOUND_S, "wait_reply ran past its deadline")
        self.assertGreaterEqual(wait_s, self.REPLY_TIMEOUT_S)
        t0 = time.monotonic()
        self.con.pump(self.REPLY_TIMEOUT_S)
        self.assertLess(time.monotonic() - t0, self.WAIT_BOUND_S, "pump ran past its deadline")

    def test_noise_times_out_at_the_deadline(self):
        self.start_peer(self.noise, 512, 0.001)  # about 0.5 MB/s of random bytes
        self.assert_waits_end_at_the_deadline()

    def test_slow_noise_1_byte_per_10_ms_times_out_at_the_deadline(self):
        self.start_peer(self.noise, 1, 0.010)
        self.assert_waits_end_at_the_deadline()

    def test_sync_flood_times_out_at_the_deadline(self):
        self.start_peer(self.noise, 512, 0.001, pc.SYNC)  # 0xA5 0xA5...: a sync, a length out of range
        self.assert_waits_end_at_the_deadline()
        self.assertGreater(self.con.decoder.bad, 0)

    # ---- a short reply of the right type and seq: MalformedReply ----
    def test_short_replies_are_malformed_reply_errors(self):
        c = self.con
        self.start_peer(self.short_replies)
        for call, message in (
            (c.hello, "HELLO reply: 1 bytes, expected 2 or more"),
            (c.start, "START reply: 5 bytes, expected 6"),
            (c.status, "STATUS reply: 3 bytes, expected 60"),
            (lambda: c.get_config("gains.speed_gain_per_s"), "CONFIG reply: 6 bytes, expected 7 or more"),
            (c.list_config, "CONFIG reply: 6 bytes"),  # not taken for the table's end
            (c.commissioning, "COMMISSIONING reply: 9 bytes, expected 41"),
            (c.counters, "COUNTERS reply: 43 bytes, expected 44"),
            (c.position, "POSITION reply: 18 bytes, expected 19"),
        ):
            with self.subTest(message):
                with self.assertRaisesRegex(Exception, "^malformed " + message) as raised:
                    call()
                self.assertIsInstance(raised.exception, pc.MalformedReply)

    def test_short_reply_on_the_command_line_is_one_line(self):
        self.start_peer(self.short_replies)
        self.link.close()
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = pc.main(["--port", self.slave_name, "status"])
        self.assertEqual(code, 4)
        self.assertEqual(
            err.getvalue().splitlines(), ["pmstep_console: error: malformed STATUS reply: 3 bytes, expected 60"]
        )

    def test_short_reply_in_the_shell_keeps_the_shell(self):
        self.start_peer(self.short_replies)
        out = io.StringIO()
        shell = pc.Shell(self.con)
        with contextlib.redirect_stdout(out):
            self.assertFalse(shell.onecmd("status"))
            self.assertFalse(shell.onecmd("counters"))
            self.assertTrue(shell.onecmd("quit"))
        self.assertEqual(
            out.getvalue().splitlines(),
            [
                "error: malformed STATUS reply: 3 bytes, expected 60",
                "error: malformed COUNTERS reply: 43 bytes, expected 44",
            ],
        )

    # ---- a line that fails: LinkError ----
    def test_line_closed_mid_wait_is_a_link_error(self):
        self.con.reply_timeout = 10.0  # the line closes 0.2 s into the wait: long before that
        self.start_peer(self.short_replies, 1)
        t0 = time.monotonic()
        with self.assertRaisesRegex(Exception, "the line failed or closed while reading") as raised:
            self.con.status()
        self.assertLess(time.monotonic() - t0, 5.0)
        self.assertIsInstance(raised.exception, pc.LinkError)
        with self.assertRaisesRegex(Exception, "the line failed or closed while") as raised:
            self.con.hello()  # and stays failed, the next request with it
        self.assertIsInstance(raised.exception, pc.LinkError)

    def run_tool(self, *args, stdin=""):
        """The command line in a subprocess against the pty: (exit status, stdout, stderr)."""
        self.link.close()
        r = subprocess.run(
            [sys.executable, str(TOOL), "--port", self.slave_name, *args],
            input=stdin,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            timeout=60,
        )
        return r.returncode, r.stdout, r.stderr

    def test_line_closed_mid_wait_on_the_command_line_is_one_line(self):
        self.start_peer(self.short_replies, 1)
        code, _, err = self.run_tool("status")
        self.assertEqual(code, 5)
        self.assertEqual(len(err.splitlines()), 1, err)
        self.assertRegex(err, "^pmstep_console: error: .*the line failed or closed while")

    def test_line_closed_in_the_shell_ends_it(self):
        """A malformed reply: an error line, the shell goes on; then the line closes: one line on
        stderr, exit status 5, the commands after it not run."""
        self.start_peer(self.short_replies, 2)
        code, out, err = self.run_tool("interactive", stdin="status\nhello\ncounters\n")
        self.assertEqual(code, 5)
        self.assertIn("error: malformed STATUS reply: 3 bytes, expected 60", out)
        self.assertNotIn("COUNTERS", out)
        self.assertEqual(len(err.splitlines()), 1, err)
        self.assertRegex(err, "^pmstep_console: error: .*the line failed or closed while")

    def test_line_that_takes_no_bytes_is_a_link_error(self):
        """Nobody reads the master: the pty fills, a write stalls; the link's write timeout (2 s by
        default) ends it."""
        self.start_peer(self.drain_after_lifetime)
        t0 = time.monotonic()
        with self.assertRaisesRegex(Exception, "the line took no bytes for 2 s") as raised:
            for _ in range(100000):  # some 900 kB: far more than a pty holds
                self.con.send(pc.HELLO)
        self.assertLess(time.monotonic() - t0, 5.0)
        self.assertIsInstance(raised.exception, pc.LinkError)


class CommandLineFailures(unittest.TestCase):
    def test_missing_port_is_one_line(self):
        for port in ("/dev/does-not-exist", "bogus://nowhere"):
            with self.subTest(port):
                r = subprocess.run(
                    [sys.executable, str(TOOL), "--port", port, "status"],
                    stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE,
                    text=True,
                    timeout=60,
                )
                self.assertEqual(r.returncode, 6)
                self.assertEqual(r.stdout, "")
                self.assertEqual(len(r.stderr.splitlines()), 1, r.stderr)
                self.assertRegex(r.stderr, f"^pmstep_console: error: cannot open port {port}: ")


if __name__ == "__main__":
    DRIVE = sys.argv.pop(1)
    unittest.main()
