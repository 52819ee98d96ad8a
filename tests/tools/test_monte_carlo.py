#!/usr/bin/env python3
"""Self-test of tools/monte_carlo.py, its pure functions: seeds, draws, the scenario's keys,
each case's classification and metrics, and the campaign's statistics. The tool run whole
(--preset against a stand-in pmstep-tune, and a small campaign against a stand-in pmstep-sil)
is test_monte_carlo_runs.py.

Usage: python3 -m unittest -v test_monte_carlo     (from tests/tools/)
       python3 tests/tools/test_monte_carlo.py           (from anywhere)
"""

import contextlib
import io
import textwrap
import unittest

import tools_path  # noqa: F401  (tools/ on the import path)
import mc_preset
import monte_carlo as mc


def summary(
    fault_code=0,
    fault_time_s=-1.0,
    loss_s=-1.0,
    latency_s=None,
    speed=0.01,
    angle=0.001,
    nonfinite=False,
    name="overcurrent",
):
    """A summary.json as pmstep-sil writes it, with only what classification reads."""
    return {
        "seed": 1,
        "fault": {
            "code": fault_code,
            "name": name if fault_code else "none",
            "text": "t",
            "step": -1,
            "time_s": fault_time_s,
        },
        "final_mode": "FAULT" if fault_code else "RUN",
        "robustness": {
            "settle_time_s": 0.8,
            "max_angle_error_rad": angle,
            "max_speed_error_rad_s": speed,
            "loss_of_control_time_s": loss_s,
            "detection_latency_s": latency_s,
            "nonfinite_seen": nonfinite,
        },
    }


class SeedMapping(unittest.TestCase):
    def test_case_seed(self):
        self.assertEqual(mc.case_seed(7, 0), 700000)
        self.assertEqual(mc.case_seed(7, 11), 700011)
        self.assertEqual(mc.case_seed(0, 99999), 99999)
        self.assertEqual(mc.case_seed(123, 45), 12300045)

    def test_split_is_the_inverse(self):
        self.assertEqual(mc.split_case_seed(700011), (7, 11))
        for base, index in ((0, 0), (1, 99999), (42, 500)):
            self.assertEqual(mc.split_case_seed(mc.case_seed(base, index)), (base, index))

    def test_out_of_range(self):
        with self.assertRaises(ValueError):
            mc.case_seed(7, 100000)
        with self.assertRaises(ValueError):
            mc.case_seed(-1, 0)


class Sampling(unittest.TestCase):
    BASE = {
        "motor.resistance_Ohm": 3.0,
        "motor.inductance_H": 0.006,
        "motor.torque_constant_Nm_A": 2.0,
        "motor.inertia_kgm2": 0.01,
        "load.torque_Nm": 2.0,
    }

    def test_known_draws(self):
        # random.Random(700000).random() gives 0.5252184595196231, 0.7456568194701344, ...
        p = mc.draw_parameters(700000, self.BASE)
        self.assertAlmostEqual(p["motor.resistance_Ohm"], 3.0 * (0.7 + 0.6 * 0.5252184595196231), places=14)
        self.assertAlmostEqual(p["motor.resistance_Ohm"], 3.045393227135322, places=14)
        self.assertAlmostEqual(p["motor.inductance_H"], 0.006589576366728322, places=16)
        self.assertAlmostEqual(p["run.theta0_deg"], 338.237522087197, places=10)
        self.assertAlmostEqual(p["load.torque_Nm"], 0.5791380988738883, places=14)
        self.assertEqual(list(p), [row[0] for row in mc.DISTRIBUTIONS])

    def test_reproducible_and_in_range(self):
        for seed in range(200):
            p = mc.draw_parameters(seed, self.BASE)
            self.assertEqual(p, mc.draw_parameters(seed, self.BASE))
            for key, kind, a, b in mc.DISTRIBUTIONS:
                scale = self.BASE[key] if kind == "scale" else 1.0
                if kind.startswith("times "):
                    scale = p[kind[len("times ") :]]  # relative to a key drawn before it
                self.assertGreaterEqual(p[key], a * scale, key)
                self.assertLess(p[key], b * scale, key)
        self.assertNotEqual(mc.draw_parameters(1, self.BASE), mc.draw_parameters(2, self.BASE))

    def test_format_value_round_trips(self):
        for v in (3.045393227135322, 1.1266034776300019e-06, 0.0, -0.02):
            self.assertEqual(float(mc.format_value(v)), v)


class ScenarioParsing(unittest.TestCase):
    TEXT = textwrap.dedent("""\
        [scenario]
        name = paper

        [motor]
        ; plant R (Ohm)
        resistance_Ohm = 3
        inductance_H = 0.006

        [speed]
        ; set-point
        points = 0:0, 0.65:0, 0.85:10
        """)

    def test_parse(self):
        s = mc.parse_scenario(self.TEXT)
        self.assertEqual(s["scenario.name"], "paper")
        self.assertEqual(s["motor.resistance_Ohm"], "3")
        self.assertEqual(s["speed.points"], "0:0, 0.65:0, 0.85:10")
        self.assertEqual(len(s), 4)

    def test_missing_keys_in_table_order(self):
        s = mc.parse_scenario(self.TEXT)
        table = [
            ("motor.resistance_Ohm", "scale", 0.7, 1.3),
            ("sensors.noise_rms_A", "uniform", 0, 1),
            ("motor.inductance_H", "scale", 0.8, 1.2),
            ("bus.ripple_V", "uniform", 0, 2),
        ]
        self.assertEqual(mc.missing_keys(s, table), ["sensors.noise_rms_A", "bus.ripple_V", "run.seed"])
        self.assertEqual(mc.missing_keys(s, table[:1], extra=()), [])

    def test_base_values_need_numbers(self):
        s = mc.parse_scenario(self.TEXT)
        self.assertEqual(mc.base_values(s, [("motor.inductance_H", "scale", 0.8, 1.2)]), {"motor.inductance_H": 0.006})
        with self.assertRaises(mc.ToolError):
            mc.base_values(s, [("speed.points", "scale", 0.8, 1.2)])


class Classification(unittest.TestCase):
    def cls(self, s, exit_status=None, **bounds):
        if exit_status is None:
            exit_status = 3 if s and s["fault"]["code"] else 0
        return mc.classify(s, exit_status, **bounds)

    def test_success(self):
        r = self.cls(summary(speed=0.49, angle=0.049))
        self.assertEqual((r["class"], r["false_trip"], r["latency_s"]), ("success", False, None))

    def test_out_of_spec_on_each_bound(self):
        self.assertEqual(self.cls(summary(speed=0.5))["class"], "out_of_spec")  # bound is strict
        self.assertEqual(self.cls(summary(angle=0.05))["class"], "out_of_spec")
        self.assertEqual(self.cls(summary(speed=None))["class"], "out_of_spec")  # NaN written as null
        self.assertEqual(self.cls(summary(nonfinite=True))["class"], "out_of_spec")
        self.assertEqual(self.cls(summary(speed=0.7), speed_bound_rad_s=1.0)["class"], "success")

    def test_position_bound(self):
        """Issue 13: with --position-bound, every move issued, finished and within the bound."""
        base = summary()
        self.assertEqual(self.cls(base, position_bound_rad=0.5)["class"], "out_of_spec")  # no position figures
        good = {
            "moves": 50,
            "rejected_moves": 0,
            "unfinished_moves": 0,
            "worst_move": 7,
            "max_final_error_electrical_rad": 0.138,
        }
        self.assertEqual(self.cls(dict(base, position=good), position_bound_rad=0.5)["class"], "success")
        self.assertEqual(self.cls(dict(base, position=good))["class"], "success")  # not checked by default
        far = dict(good, max_final_error_electrical_rad=0.5)  # bound is strict
        r = self.cls(dict(base, position=far), position_bound_rad=0.5)
        self.assertEqual(r["class"], "out_of_spec")
        self.assertIn("move 7 ends 0.5 electrical rad off", r["reason"])
        late = dict(good, unfinished_moves=1)
        self.assertEqual(self.cls(dict(base, position=late), position_bound_rad=0.5)["class"], "out_of_spec")

    def test_failure_time(self):
        """Where the failure is: the loss of control, a false trip's fault, the exceeded maximum's sample
        (the angle's where both bounds are exceeded), none for a success or an older summary."""

        def timed(**kw):
            s = summary(**kw)
            s["robustness"].update(max_speed_error_time_s=1.5, max_angle_error_time_s=1.9)
            return s

        self.assertIsNone(self.cls(timed())["failure_time_s"])
        self.assertEqual(self.cls(timed(speed=0.6))["failure_time_s"], 1.5)
        self.assertEqual(self.cls(timed(angle=0.06))["failure_time_s"], 1.9)
        self.assertEqual(self.cls(timed(speed=0.6, angle=0.06))["failure_time_s"], 1.9)
        self.assertIsNone(self.cls(summary(angle=0.06))["failure_time_s"])  # no time in the summary
        self.assertEqual(self.cls(timed(loss_s=1.2))["failure_time_s"], 1.2)  # silent
        self.assertEqual(self.cls(timed(fault_code=6, fault_time_s=1.25, loss_s=1.2))["failure_time_s"], 1.2)
        self.assertEqual(self.cls(timed(fault_code=6, fault_time_s=0.9))["failure_time_s"], 0.9)  # false trip

    def test_detected_loss_with_latency(self):
        r = self.cls(summary(fault_code=2, fault_time_s=1.23, loss_s=1.2, latency_s=0.03))
        self.assertEqual(r["class"], "detected")
        self.assertFalse(r["false_trip"])
        self.assertAlmostEqual(r["latency_s"], 0.03)

    def test_latency_from_times_when_null(self):
        r = self.cls(summary(fault_code=2, fault_time_s=1.24, loss_s=1.2, latency_s=None))
        self.assertEqual(r["class"], "detected")
        self.assertAlmostEqual(r["latency_s"], 0.04)

    def test_late_fault_is_silent(self):
        r = self.cls(summary(fault_code=2, fault_time_s=1.3, loss_s=1.2, latency_s=0.1))
        self.assertEqual(r["class"], "silent")
        self.assertAlmostEqual(r["latency_s"], 0.1)
        self.assertEqual(
            self.cls(summary(fault_code=2, fault_time_s=1.3, loss_s=1.2, latency_s=0.1), latency_bound_s=0.2)["class"],
            "detected",
        )

    def test_fault_before_loss_is_detected(self):
        r = self.cls(summary(fault_code=2, fault_time_s=1.19, loss_s=1.2, latency_s=-0.01))
        self.assertEqual(r["class"], "detected")
        self.assertAlmostEqual(r["latency_s"], -0.01)

    def test_false_trip(self):
        r = self.cls(summary(fault_code=5, fault_time_s=0.7, name="bus undervoltage"))
        self.assertEqual((r["class"], r["false_trip"], r["latency_s"]), ("detected", True, None))
        self.assertIn("bus undervoltage", r["reason"])

    def test_silent_loss(self):
        r = self.cls(summary(loss_s=1.5))
        self.assertEqual((r["class"], r["false_trip"]), ("silent", False))
        self.assertEqual(self.cls(summary(loss_s=0.0))["class"], "silent")  # loss at t = 0 is a loss
        realigned = summary(loss_s=1.5)
        realigned["commissioning"] = {"realignments": 2}
        self.assertIn("no fault latched (2 re-alignment(s))", self.cls(realigned)["reason"])

    def test_crashed(self):
        ok = summary()
        self.assertEqual(mc.classify(ok, 2)["class"], "crashed")
        self.assertEqual(mc.classify(ok, -11)["reason"], "pmstep-sil killed by SIGSEGV")
        self.assertEqual(mc.classify(ok, None)["class"], "crashed")
        self.assertEqual(mc.classify(None, 0)["class"], "crashed")
        self.assertEqual(mc.classify(ok, 0, problem="timed out after 5 s")["reason"], "timed out after 5 s")
        self.assertEqual(mc.classify(ok, 3)["class"], "crashed")  # exit 3 without a fault
        self.assertEqual(mc.classify(summary(fault_code=2, fault_time_s=1.0), 0)["class"], "crashed")
        old = summary()
        del old["robustness"]["nonfinite_seen"]
        r = mc.classify(old, 0)
        self.assertEqual(r["class"], "crashed")
        self.assertIn("robustness.nonfinite_seen", r["reason"])
        bad = summary()
        bad["robustness"]["loss_of_control_time_s"] = "never"
        self.assertEqual(mc.classify(bad, 0)["class"], "crashed")


class Metrics(unittest.TestCase):
    def test_commissioning_errors_against_the_plant(self):
        s = summary()
        s["commissioning"] = {
            "measured": True,
            "resistance_Ohm": 3.03,
            "inductance_H": 0.0057,
            "torque_constant_Nm_A": 2.2,
            "offset_a_A": 0.015,
            "offset_b_A": -0.01,
            "realignments": 0,
        }
        params = {
            "motor.resistance_Ohm": 3.0,
            "motor.inductance_H": 0.006,
            "sensors.offset_a_A": 0.02,
            "sensors.offset_b_A": -0.02,
        }
        m = mc.extract_metrics(s, params, {"motor.torque_constant_Nm_A": 2.0})
        self.assertAlmostEqual(m["r_rel_error"], 0.01)
        self.assertAlmostEqual(m["l_rel_error"], -0.05)
        self.assertAlmostEqual(m["k_rel_error"], 0.1)  # plant k_M from the scenario when not drawn
        self.assertAlmostEqual(m["offset_a_error_A"], -0.005)
        self.assertAlmostEqual(m["offset_b_error_A"], 0.01)
        self.assertTrue(m["past_settle"])
        s["commissioning"]["measured"] = False
        self.assertIsNone(mc.extract_metrics(s, params, {})["r_rel_error"])

    def test_position_figures(self):
        """Issue 13: a position scenario's moves and hold, electrical rad; none for a speed scenario."""
        s = summary()
        m = mc.extract_metrics(s, {}, {})
        self.assertIsNone(m["position_max_final_error_rad"])
        self.assertIsNone(m["position_abs_hold_drift_rad_s"])
        s["position"] = {
            "moves": 50,
            "max_final_error_electrical_rad": 0.131,
            "max_tracking_error_electrical_rad": 0.366,
            "hold_duration_s": 60.0,
            "hold_max_error_electrical_rad": 0.35,
            "hold_drift_electrical_rad_s": -3.2e-4,
        }
        m = mc.extract_metrics(s, {}, {})
        self.assertEqual(m["position_max_final_error_rad"], 0.131)
        self.assertEqual(m["position_max_tracking_error_rad"], 0.366)
        self.assertEqual(m["position_hold_max_error_rad"], 0.35)
        self.assertEqual(m["position_abs_hold_drift_rad_s"], 3.2e-4)
        s["position"]["hold_duration_s"] = 0.0  # no hold window: no hold figures
        m = mc.extract_metrics(s, {}, {})
        self.assertIsNone(m["position_hold_max_error_rad"])
        self.assertIsNone(m["position_abs_hold_drift_rad_s"])
        self.assertEqual(m["position_max_final_error_rad"], 0.131)

    def test_fault_before_settling(self):
        m = mc.extract_metrics(summary(fault_code=6, fault_time_s=0.7), {}, {})  # settle_time_s = 0.8
        self.assertFalse(m["past_settle"])
        self.assertTrue(mc.extract_metrics(summary(fault_code=6, fault_time_s=0.9), {}, {})["past_settle"])


class Statistics(unittest.TestCase):
    def test_wilson(self):
        low, high = mc.wilson_interval(5, 10)
        self.assertAlmostEqual(low, 0.236593090512564, places=12)
        self.assertAlmostEqual(high, 0.7634069094874361, places=12)
        low, high = mc.wilson_interval(12, 12)
        self.assertAlmostEqual(low, 12 / (12 + 1.959963984540054**2), places=12)  # = 0.75750599...
        self.assertEqual(high, 1.0)
        low, high = mc.wilson_interval(0, 10)
        self.assertEqual(low, 0.0)
        self.assertAlmostEqual(high, 0.2775327998628892, places=12)
        low, high = mc.wilson_interval(99, 100)
        self.assertAlmostEqual(low, 0.9455138038212946, places=12)
        self.assertAlmostEqual(high, 0.9982325679358593, places=12)
        self.assertEqual(mc.wilson_interval(0, 0), (0.0, 1.0))
        with self.assertRaises(ValueError):
            mc.wilson_interval(11, 10)

    def test_percentile(self):
        self.assertEqual(mc.percentile([1, 2, 3, 4], 50), 2.5)
        self.assertAlmostEqual(mc.percentile([1, 2, 3, 4], 90), 3.7)
        self.assertEqual(mc.percentile([4, 3, 2, 1], 0), 1)
        self.assertEqual(mc.percentile([4, 3, 2, 1], 100), 4)
        self.assertAlmostEqual(mc.percentile([15, 20, 35, 40, 50], 40), 29.0)
        self.assertEqual(mc.percentile([7.5], 99), 7.5)
        self.assertIsNone(mc.percentile([], 50))
        values = list(range(1, 101))
        self.assertAlmostEqual(mc.percentile(values, 99), 99.01)

    def test_spans_decades(self):
        self.assertTrue(mc.spans_decades([0.0, 1e-4, 0.02]))
        self.assertFalse(mc.spans_decades([0.01, 0.5]))
        self.assertFalse(mc.spans_decades([0.0, 0.3]))

    def test_worst_order(self):
        def case(seed, cls, speed):
            return {"seed": seed, "class": cls, "metrics": {"max_speed_error_rad_s": speed}}

        cases = [
            case(1, "success", 0.4),
            case(2, "detected", 0.0),
            case(3, "success", 0.45),
            case(4, "crashed", None),
            case(5, "out_of_spec", 3.0),
        ]
        self.assertEqual([c["seed"] for c in mc.worst_order(cases)], [4, 5, 2, 3, 1])


class FailureSegments(unittest.TestCase):
    SCENARIO = {
        "speed.points": "0:0, 0.33:0, 0.38:55.2,\n0.68:55.2, 0.73:-55.2, 1.0:0, 1.3:0",
        "position.points": "0:0",
    }

    def test_segments_of_the_profile(self):
        segments = mc.profile_segments(mc.speed_points(self.SCENARIO))
        self.assertEqual(
            [label for _, _, label in segments],
            [
                "standstill, 0.000-0.330 s",
                "ramp 0 -> 55.2 rad/s, 0.330-0.380 s",
                "at 55.2 rad/s, 0.380-0.680 s",
                "ramp 55.2 -> -55.2 rad/s, 0.680-0.730 s",
                "ramp -55.2 -> 0 rad/s, 0.730-1.000 s",
                "standstill, 1.000-1.300 s",
            ],
        )
        self.assertEqual(mc.segment_of(0.2, 0.23, segments), "commissioning")
        self.assertEqual(mc.segment_of(0.3, 0.23, segments), "standstill, 0.000-0.330 s")
        self.assertEqual(mc.segment_of(0.38, 0.23, segments), "at 55.2 rad/s, 0.380-0.680 s")  # a start belongs to it
        self.assertEqual(mc.segment_of(1.3, 0.23, segments), "after the profile")
        self.assertIsNone(mc.segment_of(None, 0.23, segments))
        self.assertIsNone(mc.segment_of(0.3, 0.23, segments[1:]))  # before a profile that starts later
        self.assertEqual(mc.speed_points(dict(self.SCENARIO, **{"position.points": "0.5:3"})), [])

    def test_table_in_profile_order(self):
        def record(cls, time_s, run_start=0.23):
            return {
                "class": cls,
                "metrics": {"failure_time_s": time_s},
                "summary": {"robustness": {"run_start_time_s": run_start}},
            }

        records = [
            record("out_of_spec", 1.1),
            record("silent", 0.5),
            record("detected", 0.1),
            record("out_of_spec", 1.2),
            record("success", None),
            {"class": "crashed", "metrics": {}},
        ]
        segments = mc.label_failures(records, self.SCENARIO)
        self.assertIsNone(records[4]["metrics"]["failure_segment"])
        table = mc.failures_by_segment(records, ("detected", "silent", "out_of_spec"), segments)
        self.assertEqual(
            table,
            [
                ["commissioning", {"detected": 1, "silent": 0, "out_of_spec": 0}],
                ["at 55.2 rad/s, 0.380-0.680 s", {"detected": 0, "silent": 1, "out_of_spec": 0}],
                ["standstill, 1.000-1.300 s", {"detected": 0, "silent": 0, "out_of_spec": 2}],
            ],
        )


class WeakenedProfile(unittest.TestCase):
    def test_stretch_keeps_the_accelerations(self):
        """Speeds and the times in RUN scaled by the same ratio; the points before RUN stay."""
        points = ["0:0", "0.5:0", "0.6:55.2", "1.6:55.2", "1.7:-55.2"]
        out = mc_preset._stretch(points, 0.5, 2.0)
        self.assertEqual(out, ["0:0", "0.5:0", "0.7:110.4", "2.7:110.4", "2.9:-110.4"])
        t = [float(p.split(":")[0]) for p in out]
        v = [float(p.split(":")[1]) for p in out]
        self.assertAlmostEqual((v[2] - v[1]) / (t[2] - t[1]), 55.2 / 0.1)

    def test_weakened_is_for_a_preset_alone(self):
        with contextlib.redirect_stderr(io.StringIO()), self.assertRaises(SystemExit):
            mc.parse_args(["monte_carlo.py", "--sil", "x", "--scenario", "s.ini", "--weakened", "--out", "o"])


if __name__ == "__main__":
    unittest.main()
