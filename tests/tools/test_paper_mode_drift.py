"""Unit tests of tools/paper_mode_drift.py's pure functions (python3 -m unittest test_paper_mode_drift)."""

import math
import unittest

import tools_path  # noqa: F401  (tools/ on the import path)
import paper_mode_drift as drift


class AngleError(unittest.TestCase):
    def test_sign_and_wrap(self):
        # estimate at 0.3 rad, truth at 0.1 rad: +0.2
        self.assertAlmostEqual(drift.angle_error_rad(math.cos(0.3), math.sin(0.3), math.cos(0.1), math.sin(0.1)), 0.2)
        # estimate at -3.1, truth at 3.1: wraps to +0.0831853...
        e = drift.angle_error_rad(math.cos(-3.1), math.sin(-3.1), math.cos(3.1), math.sin(3.1))
        self.assertAlmostEqual(e, 2 * math.pi - 6.2)

    def test_magnitude_does_not_matter(self):
        self.assertAlmostEqual(drift.angle_error_rad(2 * math.cos(0.5), 2 * math.sin(0.5), 1.0, 0.0), 0.5)


class Series(unittest.TestCase):
    times = [0.0, 0.5, 0.95, 1.0, 1.05, 2.0]
    errors = [0.0, -0.02, 0.03, -0.06, 0.7, 0.1]

    def test_window_max(self):
        self.assertEqual(drift.window_max(self.times, self.errors, 1.0), 0.06)  # (0.9, 1.0]
        self.assertEqual(drift.window_max(self.times, self.errors, 2.0), 0.1)
        self.assertIsNone(drift.window_max(self.times, self.errors, 1.5))

    def test_first_crossing(self):
        self.assertEqual(drift.first_crossing(self.times, self.errors, 0.05), 1.0)
        self.assertEqual(drift.first_crossing(self.times, self.errors, 0.5), 1.05)
        self.assertIsNone(drift.first_crossing(self.times, self.errors, 1.0))


class Cases(unittest.TestCase):
    values = {
        "sensors.adc_bits": "12",
        "sensors.offset_a_A": "0.02",
        "sensors.offset_b_A": "-0.02",
        "sensors.noise_rms_A": "0.005",
        "run.delay_periods": "1",
        "inverter.dead_time_s": "1e-06",
        "motor.resistance_Ohm": "3.6",
        "controller.commissioning.offset_calibration_time_s": "0.05",
    }

    def test_composition(self):
        runs = dict(drift.cases(self.values, 0.6))
        self.assertEqual(len(runs), 9)
        ideal = runs["ideal chain"]
        self.assertEqual(ideal["sensors.adc_bits"], "0")
        self.assertEqual(ideal["controller.gains.angle_correction_gain_per_s"], "0")
        self.assertEqual(ideal["run.duration_s"], repr(10.6))
        self.assertEqual(runs["+-20 mA offsets"]["sensors.offset_b_A"], "-0.02")
        self.assertEqual(runs["+-20 mA offsets"]["sensors.adc_bits"], "0")
        self.assertNotIn("sensors.adc_bits", runs["all of the scenario's chain"])
        self.assertEqual(runs["robust mode, all"], {"run.duration_s": repr(0.05 + 0.6 + 10.0), "run.decimation": "20"})

    def test_format_and_slug(self):
        self.assertEqual(drift.fmt(None), "-")
        self.assertEqual(drift.fmt(0.0123456), "0.0123")
        self.assertEqual(drift.fmt(1.5, ".3f", " s"), "1.500 s")
        self.assertEqual(drift.slug("plant R +20 %"), "plant_r__20")


if __name__ == "__main__":
    unittest.main()
