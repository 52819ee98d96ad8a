#!/usr/bin/env python3
"""Tests of the host console (tools/pmstep_console.py): framing and decoder, and every command
against the real firmware console (console-host-drive: console + core on a pty), through the
pty endpoint and the command line.

usage: test_pmstep_console.py PATH/TO/console-host-drive
"""
import contextlib
import io
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import pmstep_console as pc  # noqa: E402

DRIVE = None


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
            got += d.feed(stream[i:i + 3])
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
        self.assertEqual(hello["protocol"], 1)
        self.assertEqual(hello["identity"], "pmstep host-drive")
        table = c.list_config()
        self.assertEqual(len(table), 58)
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

    def test_interactive(self):
        out = io.StringIO()
        shell = pc.Shell(self.con)
        with contextlib.redirect_stdout(out):
            shell.onecmd("hello")
            shell.onecmd("speed nan")         # refused by the drive: an error line, the shell goes on
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


if __name__ == "__main__":
    DRIVE = sys.argv.pop(1)
    unittest.main()
