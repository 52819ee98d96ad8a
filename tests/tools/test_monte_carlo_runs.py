#!/usr/bin/env python3
"""Self-test of tools/monte_carlo.py run whole, so that no build is needed: --preset against a
stand-in for pmstep-tune, and one small end-to-end run against a stand-in for pmstep-sil (a
Python script written to a temporary folder, whose outcome per case is fixed by the case
index). Its pure functions are test_monte_carlo.py.

Usage: python3 -m unittest -v test_monte_carlo_runs     (from tests/tools/)
       python3 tests/tools/test_monte_carlo_runs.py           (from anywhere)
"""

import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

import tools_path  # tools/ on the import path
import monte_carlo as mc
import mc_preset

SCRIPT = os.path.join(tools_path.TOOLS, "monte_carlo.py")
ROOT = tools_path.ROOT
PRESET_17HS = os.path.join(ROOT, "sil", "scenarios", "motors", "17hs4401.ini")

FAKE_TUNE = textwrap.dedent('''\
    """Stand-in for pmstep-tune: prints the two lines mc_preset reads and writes a design INI."""
    import sys
    args = sys.argv[1:]
    assert "--robust" in args and "--motor" in args
    top = 9.6 if args[args.index("--motor") + 1].endswith("paper.ini") else 69.0
    print(f"  top speed: {top} rad/s (659 rpm), p w T_s = 0.173 rad; the bus's")
    print("  alignment: 0.594 A (u = 0.891 V), t_s 0.09 s, t_c 0.18 s; swing 957 rad/s")
    if "--write-ini" not in args:
        sys.exit(0)
    path = args[args.index("--write-ini") + 1]
    with open(path, "w") as f:
        f.write("[scenario]\\nname = 17hs4401\\n[motor]\\nresistance_Ohm = 1.5\\n[run]\\nloss_speed_error_rad_s = 2\\n"
                "[speed]\\npoints = 0:0, 0.33:0, 0.38:55.2,\\n    0.68:55.2, 0.73:-55.2, 1.0:0\\n"
                "[load]\\ntype = none\\ntorque_Nm = 2\\nstep_time_s = 0.63\\n"
                "[sensors]\\nadc_bits = 12\\n[controller.alignment]\\nc_align_time_s = 0.18\\n"
                "[controller.commissioning]\\noffset_calibration_time_s = 0.05\\n")
    ''')


def write_fake_tune(folder):
    """FAKE_TUNE as an executable in @p folder; returns its path."""
    tune = os.path.join(folder, "fake-tune")
    with open(tune, "w") as f:
        f.write(f"#!{sys.executable}\n" + FAKE_TUNE)
    os.chmod(tune, 0o755)
    return tune


class PresetDistributions(unittest.TestCase):
    """--preset: the table scaled to the motor (17HS4401: 0.40 N m holding, 1.5 Ohm, 24 V bus)."""

    @classmethod
    def setUpClass(cls):
        import configparser

        cls.preset = mc.read_preset(PRESET_17HS)
        cls.paper_holding = mc_preset.paper_holding_torque()
        cls.peak = 55.2
        cls.table = mc.preset_distributions(cls.preset, cls.peak, cls.paper_holding)
        ini = configparser.ConfigParser(inline_comment_prefixes=(";",))
        ini.read(PRESET_17HS)
        cls.motor = {
            key: ini.getfloat("motor", key.split(".")[1])
            for key in (
                "motor.resistance_Ohm",
                "motor.inductance_H",
                "motor.torque_constant_Nm_A",
                "motor.inertia_kgm2",
            )
        }
        cls.load = 2.0 * 0.40 / cls.paper_holding  # the paper's 2 N m of its 22.6 N m holding torque
        cls.base = dict(cls.motor, **{"load.torque_Nm": cls.load})

    def test_preset_figures(self):
        self.assertEqual(self.preset["holding_torque_Nm"], 0.40)
        self.assertEqual(self.preset["bus_voltage_V"], 24.0)
        self.assertAlmostEqual(self.paper_holding, 2.0 * 8.0 * math.sqrt(2.0), places=5)

    def test_same_rows_as_the_paper_table(self):
        self.assertEqual([row[0] for row in self.table], [row[0] for row in mc.DISTRIBUTIONS])
        paper = {row[0]: row for row in mc.DISTRIBUTIONS}
        for key in (
            "sensors.offset_a_A",
            "sensors.offset_b_A",
            "sensors.gain_error_a",
            "sensors.gain_error_b",
            "sensors.noise_rms_A",
            "inverter.dead_time_s",
            "controller.inverter.dead_time_s",
            "run.theta0_deg",
        ):
            self.assertIn(paper[key], self.table, key)  # the chain's rows unchanged

    def test_draws_scaled_to_the_preset(self):
        drawn = [mc.draw_parameters(seed, self.base, self.table) for seed in range(2000)]
        factors = {
            "motor.resistance_Ohm": (0.9, 1.1),
            "motor.inductance_H": (0.9, 1.1),
            "motor.torque_constant_Nm_A": (0.9, 1.1),
            "motor.inertia_kgm2": (0.8, 1.2),
        }
        for key, (low, high) in factors.items():
            ratios = [p[key] / self.motor[key] for p in drawn]
            self.assertGreaterEqual(min(ratios), low, key)
            self.assertLess(max(ratios), high, key)
            self.assertLess(min(ratios), low + 0.01 * (high - low), key)  # the whole range is used
            self.assertGreater(max(ratios), high - 0.01 * (high - low), key)
        limits = {
            "load.torque_Nm": self.load,  # 8.8 % of 0.40 N m, not 2 N m
            "bus.ripple_V": 2.0 * 24.0 / 48.0,  # 1 V on 24 V, not 2 V
            "bus.source_resistance_Ohm": 0.2 * 1.5 / 3.0,  # 0.1 Ohm, not 0.2 Ohm
            "motor.friction_Nms_rad": 2.0 * 1e-4,
        }  # twice the preset's assumed friction
        for key, limit in limits.items():
            values = [p[key] for p in drawn]
            self.assertGreaterEqual(min(values), 0.0, key)
            self.assertLess(max(values), limit, key)
            self.assertGreater(max(values), 0.99 * limit, key)
        self.assertLess(self.load, 0.036)
        # The paper's absolute friction bound (0.005 N m s, 50 times this motor's) is not drawn.
        self.assertLess(max(p["motor.friction_Nms_rad"] for p in drawn), 0.005 / 20)

    def test_friction_floor_from_the_paper_table(self):
        # A preset without a friction: the paper table's friction torque at its peak speed,
        # as the same fraction of the holding torque, at this profile's peak speed.
        frictionless = dict(self.preset, friction_Nms_rad=0.0)
        table = {row[0]: row for row in mc.preset_distributions(frictionless, self.peak, self.paper_holding)}
        expected = 0.005 * 10.0 * (0.40 / self.paper_holding) / self.peak
        self.assertEqual(table["motor.friction_Nms_rad"][1:3], ("uniform", 0.0))
        self.assertAlmostEqual(table["motor.friction_Nms_rad"][3], expected, places=15)

    def test_designed_scenario(self):
        with tempfile.TemporaryDirectory() as tmp:
            tune = write_fake_tune(tmp)
            path, info = mc_preset.design_scenario(tune, PRESET_17HS, tmp)
            with open(path) as f:
                text = f.read()
        self.assertEqual(info["top_speed_rad_s"], 69.0)
        self.assertEqual(info["peak_speed_rad_s"], 55.2)
        self.assertTrue(info["designed"])
        self.assertAlmostEqual(info["load_Nm"], self.load, places=15)
        # The paper campaign's 0.5 rad/s and 2 rad/s on a motor of 9.6 rad/s top speed, scaled to 69 rad/s.
        self.assertEqual(info["paper_top_speed_rad_s"], 9.6)
        self.assertAlmostEqual(info["speed_bound_rad_s"], 0.5 * 69.0 / 9.6, places=12)
        scenario = mc.parse_scenario(text)
        self.assertEqual(scenario["load.type"], "step")
        self.assertAlmostEqual(float(scenario["load.torque_Nm"]), self.load, places=15)
        # 30 ms into RUN, which starts after the offset calibration and the alignments.
        self.assertAlmostEqual(info["run_start_s"], 0.05 + 0.18, places=12)
        self.assertAlmostEqual(float(scenario["load.step_time_s"]), 0.05 + 0.18 + 0.03, places=12)
        self.assertAlmostEqual(float(scenario["run.loss_speed_error_rad_s"]), 2.0 * 69.0 / 9.6, places=12)
        command = info["tune_command"]
        self.assertIn("--robust", command)
        for item in (
            "sensors.current_full_scale_A=5.1",  # 3 x the rated 1.7 A
            "inverter.model=switching",
            "sensors.noise_rms_A=0.005",
            "run.delay_periods=1",
        ):
            self.assertEqual(command[command.index(item) - 1], "--set", item)
        self.assertTrue(all(len(line) < 197 for line in text.splitlines()))  # the INI reader's limit

    def test_position_scenario_with_the_preset(self):
        """--preset with --scenario: the scenario as written, its v_max as the peak and its load."""
        with tempfile.TemporaryDirectory() as tmp:
            tune = write_fake_tune(tmp)
            scenario = os.path.join(tmp, "moves.ini")
            with open(scenario, "w") as f:
                f.write(
                    "[speed]\npoints = 0:0\n[load]\ntype = step\ntorque_Nm = 0.0849\nstep_time_s = 87.8\n"
                    "[position]\npoints = 0.33:-45.9, 2.17:43.7\nv_max_rad_s = 34.5\n"
                )
            info = mc_preset.scenario_info(tune, PRESET_17HS, scenario)
            self.assertEqual(sorted(os.listdir(tmp)), ["fake-tune", "moves.ini"])  # nothing designed or written
        self.assertEqual(info["peak_speed_rad_s"], 34.5)
        self.assertFalse(info["designed"])
        self.assertEqual(info["load_Nm"], 0.0849)
        self.assertIsNone(info["run_start_s"])
        self.assertAlmostEqual(info["speed_bound_rad_s"], 0.5 * 69.0 / 9.6, places=12)
        table = {
            row[0]: row
            for row in mc.preset_distributions(
                info["figures"], info["peak_speed_rad_s"], info["paper_holding_torque_Nm"]
            )
        }
        self.assertEqual(table["load.torque_Nm"][1:], ("scale", 0.0, 1.0))  # of the scenario's 0.0849 N m
        self.assertEqual(table["motor.inertia_kgm2"][1:], ("scale", 0.8, 1.2))

    def test_bad_preset(self):
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "bad.ini")
            with open(bad, "w") as f:
                f.write("[datasheet]\nrated_current_A = 1.7\n[motor]\nresistance_Ohm = 1.5\n")
            with self.assertRaises(mc.ToolError):
                mc.read_preset(bad)
        proc = subprocess.run(
            [sys.executable, SCRIPT, "--sil", sys.executable, "--out", "unused"],
            capture_output=True,
            text=True,
            timeout=60,
        )
        self.assertEqual(proc.returncode, 2)
        self.assertIn("give --scenario, --preset or both", proc.stderr)


FAKE_SIL = textwrap.dedent('''\
    """Stand-in for pmstep-sil: the case index (run.seed % 100000) chooses the outcome."""
    import json, os, sys
    KEYS = """[scenario]
    name = fake
    [motor]
    ; plant R (Ohm)
    resistance_Ohm = 3
    inductance_H = 0.006
    inertia_kgm2 = 0.01
    friction_Nms_rad = 0
    torque_constant_Nm_A = 2
    [sensors]
    offset_a_A = 0
    offset_b_A = 0
    gain_error_a = 0
    gain_error_b = 0
    noise_rms_A = 0
    [inverter]
    dead_time_s = 0
    [bus]
    ripple_V = 0
    source_resistance_Ohm = 0
    [controller.inverter]
    dead_time_s = 0
    [run]
    seed = 0
    duration_s = 2.4
    theta0_deg = 30
    [load]
    torque_Nm = 2
    """
    args = sys.argv[1:]
    if "--print-scenario" in args:
        print(KEYS)
        sys.exit(0)
    sets = dict(args[i + 1].split("=", 1) for i, a in enumerate(args) if a == "--set")
    out = args[args.index("--out") + 1]
    index = int(sets["run.seed"]) % 100000
    outcome = ["success", "detected", "false_trip", "silent", "out_of_spec", "crash", "late", "success"][index % 8]
    if outcome == "crash":
        sys.stderr.write("fake: segmentation fault\\n")
        sys.exit(139)
    fault = outcome in ("detected", "false_trip", "late")
    loss = {"detected": 1.0, "silent": 1.1, "late": 1.2}.get(outcome, -1.0)
    fault_time = {"detected": 1.02, "false_trip": 0.9, "late": 1.4}.get(outcome, -1.0)
    r = float(sets["motor.resistance_Ohm"])
    s = {"seed": int(sets["run.seed"]),
         "fault": {"code": 4 if fault else 0, "name": "overcurrent" if fault else "none", "text": "x",
                   "step": 1, "time_s": fault_time},
         "final_mode": "FAULT" if fault else "RUN",
         "speed": {"tracking_max_abs_error_rad_s": 0.1},
         "robustness": {"settle_time_s": 0.8, "max_angle_error_rad": 0.001 * (index + 1),
                        "max_speed_error_rad_s": 2.0 if outcome == "out_of_spec" else 0.01 * (index + 1),
                        "loss_of_control_time_s": loss,
                        "detection_latency_s": (fault_time - loss) if fault and loss >= 0 else None,
                        "nonfinite_seen": False},
         "commissioning": {"offset_a_A": 0.0, "offset_b_A": 0.0, "resistance_Ohm": r * 1.01,
                           "inductance_H": 0.006, "torque_constant_Nm_A": 2.0, "realignments": 0,
                           "measured": True},
         "timing": {"wall_s": 0.01}}
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(s, f)
    sys.exit(3 if fault else 0)
    ''')


class EndToEnd(unittest.TestCase):
    """The whole tool against the stand-in: 16 cases, two of each outcome."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.sil = os.path.join(cls.tmp.name, "fake-sil")
        with open(cls.sil, "w") as f:
            f.write(f"#!{sys.executable}\n" + FAKE_SIL)
        os.chmod(cls.sil, 0o755)
        cls.scenario = os.path.join(cls.tmp.name, "fake.ini")
        with open(cls.scenario, "w") as f:
            f.write("[scenario]\nname = fake\n")
        cls.out = os.path.join(cls.tmp.name, "mc")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def run_tool(self, *extra):
        cmd = [
            sys.executable,
            SCRIPT,
            "--sil",
            self.sil,
            "--scenario",
            self.scenario,
            "--out",
            self.out,
            "--no-plots",
            "--engine",
            "threads",
            *extra,
        ]
        return subprocess.run(cmd, capture_output=True, text=True, timeout=120)

    def test_run_and_check(self):
        proc = self.run_tool("--cases", "16", "--seed", "3", "--jobs", "3", "--check")
        self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
        lines = proc.stdout.strip().splitlines()
        self.assertEqual(lines[-1], "4 passed, 12 failed")
        self.assertIn("silent failure", proc.stdout)
        self.assertIn("crashed", proc.stdout)
        # Not a terminal: one progress line per 10 %.
        progress = [line for line in proc.stderr.splitlines() if "cases (" in line]
        self.assertEqual(len(progress), 10)
        self.assertTrue(progress[-1].startswith("monte_carlo: 16/16 cases (100 %)"))

        with open(os.path.join(self.out, "summary.json")) as f:
            agg = json.load(f)
        self.assertEqual(agg["counts"], {"success": 4, "detected": 4, "silent": 4, "out_of_spec": 2, "crashed": 2})
        self.assertEqual(agg["false_trips"], 2)
        self.assertEqual(agg["detected_losses"], 2)
        self.assertEqual(agg["faults_by_name"], {"overcurrent": 6})
        self.assertAlmostEqual(agg["detection_latency_s"]["max"], 0.02)
        self.assertAlmostEqual(agg["success_rate"], 0.25)
        self.assertAlmostEqual(agg["distributions"]["commissioning_abs_r_rel_error"]["max"], 0.01)
        self.assertFalse(agg["check"]["passed"])

        with open(os.path.join(self.out, "cases.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([int(r["seed"]) for r in rows], list(range(300000, 300016)))
        self.assertEqual(rows[5]["class"], "crashed")
        self.assertIn("exited with status 139", rows[5]["reason"])
        self.assertEqual(rows[2]["false_trip"], "1")
        self.assertEqual(
            float(rows[0]["motor.resistance_Ohm"]),
            mc.draw_parameters(
                300000,
                {
                    "motor.resistance_Ohm": 3.0,
                    "motor.inductance_H": 0.006,
                    "motor.torque_constant_Nm_A": 2.0,
                    "motor.inertia_kgm2": 0.01,
                    "load.torque_Nm": 2.0,
                },
            )["motor.resistance_Ohm"],
        )

        with open(os.path.join(self.out, "report.md")) as f:
            report = f.read()
        self.assertIn("Success rate: 4/16 = 25.0 %", report)
        self.assertIn("fake: segmentation fault", report)  # the crashed case's stderr tail
        self.assertIn("--case 300005", report)
        for key, _kind, _a, _b in mc.DISTRIBUTIONS:
            self.assertIn(f"`{key}`", report)

    def test_one_case(self):
        proc = self.run_tool("--case", "300001")
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("class: detected", proc.stdout)
        self.assertIn("--set run.seed=300001", proc.stdout)
        self.assertEqual(proc.stdout.strip().splitlines()[-1], "0 passed, 1 failed")
        proc = self.run_tool("--case", "300000", "--check")
        self.assertEqual(proc.returncode, 0, proc.stdout)
        self.assertEqual(proc.stdout.strip().splitlines()[-1], "1 passed, 0 failed")

    def test_missing_key_stops(self):
        paper = os.path.join(self.tmp.name, "old-sil")
        with open(paper, "w") as f:
            f.write(f"#!{sys.executable}\nprint('[motor]\\nresistance_Ohm = 3\\n')\n")
        os.chmod(paper, 0o755)
        proc = subprocess.run(
            [
                sys.executable,
                SCRIPT,
                "--sil",
                paper,
                "--scenario",
                self.scenario,
                "--out",
                self.out,
                "--cases",
                "2",
                "--no-plots",
            ],
            capture_output=True,
            text=True,
            timeout=60,
        )
        self.assertEqual(proc.returncode, 2)
        self.assertIn("does not know 16 of the keys", proc.stderr)
        self.assertIn("sensors.noise_rms_A", proc.stderr)
        self.assertEqual(proc.stdout.strip().splitlines()[-1], "0 passed, 0 failed")


if __name__ == "__main__":
    unittest.main()
