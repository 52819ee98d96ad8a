"""Tests of tools/sweep_mc.py (python3 -m unittest test_sweep_mc): the Monte Carlo sample's totals,
summary line and report section on made-up campaign results, and a campaign that did not run.
Standard library only; no campaign is run."""

import unittest

import tools_path  # noqa: F401  (tools/ on the import path)
import sweep_mc


def motor(name):
    return {"name": name, "frame": "NEMA17", "pole_pairs": 50, "bus_voltage_V": 24.0}


def campaign(name, success, detected, silent, out_of_spec, crashed=0):
    return {
        "motor": motor(name),
        "nonfinite": 0,
        "counts": {
            "success": success,
            "detected": detected,
            "silent": silent,
            "out_of_spec": out_of_spec,
            "crashed": crashed,
        },
    }


RESULTS = [
    campaign("m0002", 18, 2, 0, 0),
    campaign("m0001", 10, 3, 4, 3),
    {"motor": motor("m0003"), "error": "exit 2: pmstep-tune: cannot design"},
]


class SweepMcTest(unittest.TestCase):
    def test_totals_count_cases_and_name_the_silent_motors(self):
        counts, silent, not_run = sweep_mc.totals(RESULTS)
        self.assertEqual(counts, {"success": 28, "detected": 5, "silent": 4, "out_of_spec": 3, "crashed": 0})
        self.assertEqual(silent, ["m0001"])
        self.assertEqual([r["motor"]["name"] for r in not_run], ["m0003"])

    def test_summary_line(self):
        line = sweep_mc.summary_line(RESULTS, 20)
        self.assertIn("2 motors x 20 cases", line)
        self.assertIn("silent 4", line)
        self.assertIn("silent failures on m0001", line)
        self.assertIn("1 campaigns did not run", line)

    def test_report_section(self):
        lines = sweep_mc.report_lines(RESULTS, 20)
        self.assertIn("| silent | 4 | 10.0 |", lines)
        self.assertIn("Motors with a silent failure: m0001.", lines)
        rows = [l for l in lines if l.startswith("| m000")]
        self.assertEqual(rows[0], "| m0001 | NEMA17 | 50 | 24 | 10 | 3 | 4 | 3 | 0 |")
        self.assertEqual(rows[2], "| m0003 | NEMA17 | 50 | 24 | - | - | - | - | - |")
        self.assertTrue(any("m0003 (exit 2: pmstep-tune: cannot design)" in l for l in lines))

    def test_sample_is_fixed_and_within_the_population(self):
        population = [motor(f"m{k:04d}") for k in range(30)]
        first = sweep_mc.sample(population, 5)
        self.assertEqual(first, sweep_mc.sample(population, 5))
        self.assertEqual(len(sweep_mc.sample(population, 50)), 30)


if __name__ == "__main__":
    unittest.main()
