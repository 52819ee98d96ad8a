"""Tests of the report writers (python3 -m unittest test_reports): tools/report.py's header and
sections, and each measuring tool's --report text on fixed figures (bench_target.py,
bench_position_target.py, bench_sil.py, envelope.py, position_acceptance.py, monte_carlo.py with
mc_report.py, stepdir_compare.py with its load-step search). Standard library only; nothing is measured
or run."""

import argparse
import contextlib
import datetime
import io
import os
import re
import tempfile
import unittest
from unittest import mock

import tools_path  # noqa: F401  (tools/ on the import path)
import bench_position_target
import bench_sil
import bench_target
import envelope
import mc_report
import monte_carlo
import position_acceptance
import report
import stepdir_compare
import torque_speed

TODAY = datetime.date.today().isoformat()


def cells(line):
    """The cells of a Markdown table row (a '|' escaped as '\\|' is inside a cell)."""
    return re.split(r"(?<!\\)\|", line.strip())[1:-1]


class ReportCase(unittest.TestCase):
    def assert_header(self, text, command):
        """@p text names @p command (as run from the repository's root), the commit and today's date."""
        self.assertIn(f"- command: `{command}`", text)
        self.assertIn(f"- commit: `{report.commit()}`", text)
        self.assertRegex(report.commit(), r"^([0-9a-f]{4,}\+?|unknown)$")
        self.assertIn(f"- date: {TODAY}", text)

    def assert_tables(self, text):
        """Every Markdown table of @p text has as many cells in each row as in its header."""
        width = None
        tables = 0
        for line in text.splitlines():
            if line.startswith("|"):
                if width is None:
                    width, tables = len(cells(line)), tables + 1
                self.assertEqual(len(cells(line)), width, line)
            else:
                width = None
        self.assertGreater(tables, 0)


class Header(ReportCase):
    def test_command_commit_date(self):
        sil = os.path.join(report.ROOT, "build", "host-release", "sil", "pmstep-sil")
        text = report.header(
            "T",
            "tools/x.py",
            ["tools/x.py", "--sil", sil, f"--out={report.ROOT}/out/x", "--note", "two words"],
            "What.",
        )
        self.assertTrue(text.startswith("# T\n"))
        self.assert_header(text, "tools/x.py --sil build/host-release/sil/pmstep-sil --out=out/x --note 'two words'")
        self.assertIn("What.", text)

    def test_section_header(self):
        text = report.section_header("S", "tools/y.py", ["tools/y.py", "--cases", "4"])
        self.assertTrue(text.startswith("## S\n"))
        self.assert_header(text, "tools/y.py --cases 4")


class Sections(ReportCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "sub", "page.md")

    def tearDown(self):
        self.dir.cleanup()

    def read(self):
        with open(self.path, encoding="utf-8") as f:
            return f.read()

    def test_replaced_not_duplicated(self):
        report.write_section(self.path, "Page", "a", "## A\n\nfirst a\n", "What.")
        report.write_section(self.path, "Page", "b", "## B\n\nfirst b\n", "What.")
        report.write_section(self.path, "Page", "a", "## A\n\nsecond a\n", "What.")
        text = self.read()
        self.assertEqual(text.count("<!-- section: a -->"), 1)
        self.assertEqual(text.count("<!-- end of section: a -->"), 1)
        self.assertEqual(text.count("# Page\n"), 1)
        self.assertEqual(text.count("What."), 1)
        self.assertNotIn("first a", text)
        self.assertIn("second a", text)
        self.assertIn("first b", text)
        self.assertEqual([n for n, _ in report.sections(text)], ["a", "b"])  # a keeps its place

    def test_order_and_hand_edits(self):
        report.write_section(self.path, "Page", "position", "## P\n", order=("step", "position"))
        with open(self.path, "a", encoding="utf-8") as f:
            f.write("a line added by hand\n")
        report.write_section(
            self.path, "Page", "step", "## S\n| a | b |\n|---|---|\n| 1 | 2 |", order=("step", "position")
        )
        text = self.read()
        self.assertEqual([n for n, _ in report.sections(text)], ["step", "position"])
        self.assertNotIn("a line added by hand", text)
        self.assertIn("| 1 | 2 |\n\n<!-- end of section: step -->", text)  # a blank line ends the table

    def test_bad_name(self):
        with self.assertRaises(ValueError):
            report.write_section(self.path, "Page", "two words", "x")


# ---- each tool's report on fixed figures ----
COST = {
    "qemu": "QEMU emulator version 7.2",
    "gcc": "12.2.1",
    "bit_identical": True,
    "periods": 48000,
    "modes": {
        m: {
            "steps": n,
            "instructions_min": lo,
            "instructions_mean": mean,
            "instructions_max": hi,
            "systick_instructions_mean": mean + 1.0,
            "cycles_model_mean": 2 * mean,
            "taken_branches_mean": 10.0,
            "stack_bytes_measured": stack,
        }
        for m, n, lo, mean, hi, stack in (
            ("S_ALIGN", 6000, 302, 306.0, 317, 208),
            ("C_ALIGN", 6000, 313, 314.0, 319, 208),
            ("RUN", 36000, 473, 563.1, 1070, 252),
        )
    },
    "core_flash_bytes": 18739,
    "instance_bytes": 812,
    "config_bytes": 232,
    "stack_static_bytes": 408,
    "branch_penalty": 2,
    "load_store_pipelining": True,
    "stack_measured_bytes": 252,
    "static_path": ["pmstep_step", "pmstep_commission_finish"],
    "static_unknown": ["memset"],
    "image": (33884, 0, 2976),
    "run_mix": [("vldr", 128.5)],
}
BUDGETS = {
    "run": 600,
    "stack": 256,
    "instance": 816,
    "flash": 19456,
    "position": 615.0,
    "stepdir": 615.0,
    "image_flash": 131072,
    "image_ram": 30720,
}


class Cost(ReportCase):
    def test_step_section(self):
        argv = ["tools/bench_target.py", "--report", "docs/reports/cost.md"]
        text = bench_target.report_section(COST, BUDGETS, argv)
        self.assert_header(text, "tools/bench_target.py --report docs/reports/cost.md")
        self.assert_tables(text)
        self.assertIn("| 473 / 563.1 / 1070 |", text)
        self.assertIn("564.1 (within)", text)  # SysTick mean of RUN against 600
        self.assertIn("| 18739 B | 19456 B | within |", text)
        self.assertIn("| 812 B | 816 B | within |", text)
        self.assertIn("| 33884 B | 131072 B | within |", text)  # text + data
        self.assertIn("| 2976 B | 30720 B | within |", text)  # data + bss
        over = dict(COST, instance_bytes=820)
        self.assertIn("| 820 B | 816 B | **OVER** |", bench_target.report_section(over, BUDGETS, argv))
        self.assertIn("not built", bench_target.report_section(dict(COST, image=None), BUDGETS, argv))

    def test_budgets_read_where_set(self):
        budgets = bench_target.budgets()
        for key in BUDGETS:
            self.assertIsNotNone(budgets[key], key)
            self.assertGreater(budgets[key], 0)

    def test_image_sizes(self):
        out = (
            "   text\t   data\t    bss\t    dec\t    hex\tfilename\n"
            "  33884\t      4\t   2976\t  36864\t   9000\tbuild/x.elf\n"
        )
        self.assertEqual(bench_target.image_sizes(out), (33884, 4, 2976))
        self.assertIsNone(bench_target.image_sizes(""))

    def test_position_section_and_page(self):
        figures = {
            "p": {
                "label": "RUN, position mode",
                "periods": 45999,
                "step": [456, 549.3, 770],
                "update": [32, 60.2, 537],
                "total": [488, 609.5, 1067],
            }
        }
        argv = ["tools/bench_position_target.py", "--max-mean", "615"]
        text = bench_position_target.report_section(figures, "pil-position: fault NONE", 615.0, 615.0, "3", argv)
        self.assert_header(text, "tools/bench_position_target.py --max-mean 615")
        self.assert_tables(text)
        self.assertIn("| 488 / 609.5 / 1067 |", text)
        self.assertIn("mean **609.5** instructions, budget 615 (ctest pil.position_cost): within.", text)
        strict = bench_position_target.report_section(figures, "", 600.0, 615.0, "3", argv)
        self.assertIn("within; over this run's --max-mean 600", strict)
        with tempfile.TemporaryDirectory() as d:
            page = os.path.join(d, "cost.md")
            for name, body in (
                ("position", text),
                ("step", bench_target.report_section(COST, BUDGETS, argv)),
                ("position", text),
            ):
                report.write_section(
                    page, bench_target.COST_TITLE, name, body, bench_target.COST_WHAT, bench_target.COST_SECTIONS
                )
            with open(page) as f:
                page_text = f.read()
        self.assertEqual([n for n, _ in report.sections(page_text)], ["step", "position"])
        self.assertEqual(page_text.count("## Control period with the position loop"), 1)
        self.assertNotIn("STEP/DIR", text)

    def test_position_section_with_stepdir(self):
        figures = {
            "p": {
                "label": "RUN, position mode",
                "periods": 45999,
                "step": [449, 544.8, 764],
                "update": [32, 62.0, 556],
                "total": [481, 606.8, 1079],
            }
        }
        sd = {
            "p_update": {
                "label": "RUN following steps, at an update",
                "periods": 6000,
                "step": [449, 506.2, 525],
                "after": [248, 336.5, 641],
                "total": [697, 842.7, 1164],
            },
            "p": {
                "label": "RUN following steps, every period",
                "periods": 47999,
                "step": [449, 545.2, 764],
                "after": [86, 118.7, 641],
                "total": [535, 663.9, 1164],
            },
        }
        stepdir = {
            "figures": sd,
            "image_report": "pil-position: STEP/DIR at 16 microsteps, fault NONE",
            "microsteps": 16,
            "max_mean": 615.0,
            "enforced": 615.0,
        }
        argv = ["tools/bench_position_target.py", "--report", "docs/reports/cost.md"]
        text = bench_position_target.report_section(figures, "", 615.0, 615.0, "3", argv, stepdir)
        self.assert_tables(text)
        self.assertIn("quantised to 16 microsteps per full step", text)
        self.assertIn(
            "| RUN following steps, at an update | 6000 | 449 / 506.2 / 525 | 248 / 336.5 / 641 | 697 / 842.7 / 1164 |",
            text,
        )
        self.assertIn("mean **606.8** instructions, budget 615 (ctest pil.position_cost): within.", text)
        self.assertIn(
            "STEP/DIR period: mean **663.9** instructions, budget 615 (ctest pil.stepdir_cost): **OVER**.", text
        )
        self.assertLess(text.index("RUN, position mode"), text.index("RUN following steps"))


class Benchmarks(ReportCase):
    def test_table(self):
        rows = [
            {
                "label": "default (exponential x1), averaged",
                "target": 150.0,
                "rtf": 343.0,
                "rtf_cpu": 342.9,
                "per_period_ns": 146.0,
                "plant_ns": 78.0,
                "plant_share": 0.53,
                "firmware_ns": 39.0,
                "firmware_share": 0.27,
                "wall_s": 0.007,
            },
            {
                "label": "default (exponential x1), switching",
                "target": 60.0,
                "rtf": 40.9,
                "rtf_cpu": 41.0,
                "per_period_ns": 1221.0,
                "plant_ns": 1022.0,
                "plant_share": 0.84,
                "firmware_ns": 160.0,
                "firmware_share": 0.13,
                "wall_s": 0.059,
            },
            {
                "label": "rk4 x25 (reference), averaged",
                "target": None,
                "rtf": 20.2,
                "rtf_cpu": 20.2,
                "per_period_ns": 2475.0,
                "plant_ns": 2413.0,
                "plant_share": 0.97,
                "firmware_ns": 39.0,
                "firmware_share": 0.02,
                "wall_s": 0.119,
            },
        ]
        machine = {"cpu": "AMD EPYC", "cores": 2, "load_before": 1.0, "load_after": None}
        text = bench_sil.report_text(rows, 9, machine, ["tools/bench_sil.py", "--runs", "9"])
        self.assert_header(text, "tools/bench_sil.py --runs 9")
        self.assert_tables(text)
        self.assertIn("median of 9 runs", text)
        self.assertIn("| 343.0x | ≥ 150x | 342.9x | 146 | 78 ns (53 %) | 39 ns (27 %) | 0.007 s |", text)
        self.assertIn("≥ 60x (**below**)", text)
        self.assertIn("load average 1.00 before the runs, - after", text)


class Envelope(ReportCase):
    ROW = {
        "preset": "17hs4401",
        "chain": "realistic",
        "top_speed_rad_s": 69.0,
        "ramps_fault": "NONE",
        "ramps_speed_error_pct_top": 0.75,
        "ramps_angle_error_rad": 0.0,
        "step_at_0.5": {
            "fault": "NONE",
            "lost_sync": False,
            "dip_rad_s": 25.8,
            "recovery_ms": 17.0,
            "survived_positions": 8,
        },
        "step_at_0.05": {
            "fault": "STALL",
            "lost_sync": True,
            "dip_rad_s": 1.0,
            "recovery_ms": 1.0,
            "survived_positions": 3,
        },
        "pullout_ours_of_holding": 0.984,
        "pullout_microstep_of_holding": 0.438,
        "rms_current_ours_A": 0.0,
        "rms_current_microstep_A": None,
    }

    def test_table_and_plot(self):
        args = argparse.Namespace(duration=20.0, set=["inverter.dead_time_s=0"], top="design")
        argv = ["tools/envelope.py", "--out", "out/envelope", "--report", "docs/reports/envelope.md"]
        text = envelope.report_text([self.ROW], args, argv, "envelope.png")
        self.assert_header(text, "tools/envelope.py --out out/envelope --report docs/reports/envelope.md")
        self.assert_tables(text)  # markdown()'s |w-w*| escaped in the report
        self.assertIn(
            "| 17hs4401 | realistic | 69.0 | NONE, 0.75, 0.0000 | 25.8, 17; 8/8 / STALL, sync lost; 3/8 | "
            "0.984 / 0.438 | 0.000 / nan |",
            text,
        )  # 0 is a value, None is not
        self.assertIn("![", text)
        self.assertIn("](envelope.png)", text)
        self.assertIn("`--set inverter.dead_time_s=0`", text)
        self.assertNotIn("](", envelope.report_text([self.ROW], args, argv, None))
        self.assertIn("max |w-w*|", envelope.markdown([self.ROW]))  # the tool's own table as it was
        self.assertNotIn("field-weakened", text)
        args.top = "weakened"
        self.assertIn("The top speed here is the field-weakened one", envelope.report_text([self.ROW], args, argv))


class PositionAcceptance(ReportCase):
    def test_table(self):
        args = argparse.Namespace(moves=50, seed=1, speed_fraction=0.5, accel_fraction=0.25, hold_s=60.0, top="design")
        pos = {
            "moves": 50,
            "unfinished_moves": 0,
            "max_final_error_electrical_rad": 0.0185,
            "mean_final_error_electrical_rad": 0.0019,
            "max_overshoot_fraction": 0.0003,
            "max_estimate_error_electrical_rad": 0.315,
            "max_tracking_error_electrical_rad": 0.342,
            "hold_max_error_electrical_rad": 0.342,
            "hold_drift_electrical_rad_s": 6.8e-5,
        }
        results = [
            {
                "motor": "paper",
                "chain": "realistic",
                "fault": "NONE",
                "simulated_s": 700.4,
                "position": pos,
                "pass": True,
            },
            {
                "motor": "paper",
                "chain": "ideal",
                "fault": "STALL",
                "simulated_s": 3.0,
                "position": {"moves": 3},
                "pass": False,
            },
        ]
        text = position_acceptance.report_text(results, args, ["tools/position_acceptance.py", "--seed", "1"])
        self.assert_header(text, "tools/position_acceptance.py --seed 1")
        self.assert_tables(text)
        self.assertIn(
            "| paper | realistic | 50 (0) | 0.0185 / 0.0019 | 0.03 % | 0.315 | 0.342 | 0.342, 6.8e-05 /s | "
            "700 s | none | met |",
            text,
        )
        self.assertIn("| paper | ideal | 3 (-) | - / - | - % | - | - | - | 3 s | STALL | **FAILED** |", text)
        self.assertIn("**1 of 2 runs meet them.**", text)
        self.assertIn("v_max = 0.5 of the design's top speed", text)
        args.top = "weakened"
        text = position_acceptance.report_text(results, args, ["tools/position_acceptance.py", "--top", "weakened"])
        self.assertIn("# Position control: acceptance at the field-weakened top speed", text)
        self.assertIn("v_max = 0.5 of the design's field-weakened top speed", text)


class MonteCarlo(ReportCase):
    def campaign(self, argv):
        args = monte_carlo.parse_args(argv)
        args.speed_bound = 0.5 if args.speed_bound is None else args.speed_bound
        records = [
            {
                "seed": 100000 + k,
                "class": cls,
                "false_trip": trip,
                "fault_name": fault,
                "reason": "",
                "latency_s": latency,
                "params": {},
                "command": ["pmstep-sil"],
                "stderr_tail": "",
                "metrics": {
                    "max_speed_error_rad_s": speed,
                    "max_angle_error_rad": 0.01,
                    "past_settle": True,
                    "failure_segment": segment,
                },
            }
            for k, (cls, trip, fault, latency, speed, segment) in enumerate(
                (
                    ("success", False, None, None, 0.1, None),
                    ("success", False, None, None, 0.2, None),
                    ("silent", False, None, None, 3.0, "ramp 1"),
                    ("detected", True, "OVERCURRENT", None, 0.3, "hold 2"),
                    ("detected", False, "STALL", 0.02, 2.5, "ramp 1"),
                )
            )
        ]
        agg = mc_report.aggregate(records, args)
        agg["failures_by_segment"] = monte_carlo.failures_by_segment(
            records, monte_carlo.FAILURE_CLASSES, [(0.0, 1.0, "ramp 1"), (1.0, 2.0, "hold 2")]
        )
        agg.update(
            {
                "preset": None,
                "pmstep_sil_version": "pmstep-sil 1.0",
                "execution": {"engine": "threads", "workers": 2, "cases_run": 5, "cases_resumed": 0, "wall_s": 3.2},
            }
        )
        return args, records, agg

    def test_section(self):
        argv = [
            "tools/monte_carlo.py",
            "--sil",
            "build/host-release/sil/pmstep-sil",
            "--scenario",
            "sil/scenarios/robust.ini",
            "--cases",
            "5",
            "--seed",
            "1",
            "--out",
            "out/mc",
            "--report",
            "docs/reports/monte-carlo.md",
            "--report-section",
            "robust",
        ]
        args, records, agg = self.campaign(argv)
        self.assertEqual(args.report_section, "robust")
        text = mc_report.campaign_section("robust", records, agg, args, argv)
        rerun = (
            "tools/monte_carlo.py --sil build/host-release/sil/pmstep-sil --scenario sil/scenarios/robust.ini "
            "--cases 5 --seed 1 --out out/mc"
        )
        self.assert_header(text, rerun)  # the command without --report
        self.assert_tables(text)
        self.assertIn("| success | **2 / 5** = 40.0 % (Wilson 95 %:", text)
        self.assertIn("| silent failures | **1** |", text)
        self.assertIn("| detected (of which false trips) | 2 (1) |", text)
        self.assertIn("| faults latched | OVERCURRENT 1, STALL 1 |", text)
        self.assertIn("| ramp 1 | 1 | 1 | 0 |", text)
        self.assertIn("100002 (silent)", text)
        self.assertIn("100003 (detected, false trip)", text)
        self.assertIn("--out out/mc --case 100002`", text)  # a failed case's rerun, --cases and --report left out
        self.assertIn("3 s (threads, 2 workers)", text)

    def test_page_of_campaigns(self):
        argv = ["tools/monte_carlo.py", "--sil", "x", "--scenario", "sil/scenarios/robust.ini", "--out", "o"]
        args, records, agg = self.campaign(argv)
        with tempfile.TemporaryDirectory() as d:
            page = os.path.join(d, "monte-carlo.md")
            for name in ("paper", "robust", "paper"):
                report.write_section(
                    page,
                    mc_report.PAGE_TITLE,
                    name,
                    mc_report.campaign_section(name, records, agg, args, argv),
                    mc_report.PAGE_WHAT,
                )
            with open(page) as f:
                text = f.read()
        self.assertEqual([n for n, _ in report.sections(text)], ["paper", "robust"])
        self.assertEqual(text.count("## paper:"), 1)
        self.assertEqual(text.count("# Monte Carlo campaigns"), 1)

    def test_section_names(self):
        base = ["tools/monte_carlo.py", "--sil", "x", "--out", "o", "--report", "r.md"]
        self.assertEqual(
            monte_carlo.parse_args(base + ["--scenario", "sil/scenarios/robust.ini"]).report_section, "robust"
        )
        preset = base + ["--preset", "sil/scenarios/motors/17hs4401.ini"]
        self.assertEqual(monte_carlo.parse_args(preset).report_section, "17hs4401")
        self.assertEqual(monte_carlo.parse_args(preset + ["--phase-voltage-sensing"]).report_section, "17hs4401-sensed")
        self.assertEqual(
            monte_carlo.parse_args(preset + ["--scenario", "out/p/as1050_realistic_run.ini"]).report_section,
            "as1050_realistic_run",
        )
        self.assertEqual(monte_carlo.parse_args(preset + ["--report-section", "mine"]).report_section, "mine")
        self.assertIsNone(monte_carlo.parse_args(base[:5] + ["--scenario", "s.ini"]).report)
        for bad in (
            base[:5] + ["--scenario", "s.ini", "--report-section", "x"],  # no --report
            preset + ["--report-section", "two words"],
        ):
            with self.assertRaises(SystemExit), contextlib.redirect_stderr(io.StringIO()):
                monte_carlo.parse_args(bad)

    def test_campaign_command(self):
        argv = ["m.py", "--report=r.md", "--cases", "4", "--report-section", "s", "--seed", "1"]
        self.assertEqual(mc_report.campaign_command(argv), ["m.py", "--cases", "4", "--seed", "1"])
        self.assertEqual(mc_report.campaign_command(argv, 100003), ["m.py", "--seed", "1", "--case", "100003"])


class StepDirCompare(ReportCase):
    PRESET = {"rated_A": 1.7, "k_M": 0.16638, "J": 5.4e-6, "R": 1.5, "p": 50}
    DESIGN = (1100.0, 0.25, 2000.0, 13.8)  # top speed, RUN's start, varpi_0, stall bound

    @staticmethod
    def summary(fault="NONE", final=0.0, following_end=-1.0, diag=0):
        return {
            "fault": {"name": fault},
            "rms_phase_current_A": 1.2,
            "max_abs_phase_current_a": 3.3,
            "stepdir": {
                "following_start_s": 0.35,
                "following_end_s": following_end,
                "max_error_full_steps": 2.5,
                "final_error_full_steps": final,
                "diag_periods": diag,
                "diag_first_s": 0.46 if diag else -1.0,
            },
        }

    def load_row(self, motor, drive, survived, failed, holding=0.4):
        row = {
            "motor": motor,
            "drive": drive,
            "holding_torque_Nm": holding,
            "k_M_rated_Nm": holding / 2**0.5,
            "step_time_s": 0.459,
            "cruise_s": (0.304, 0.614),
            "iterations": 9,
            "survived_Nm": survived,
            "failed_Nm": failed,
            "failed_why": ["fault OVERCURRENT"] if failed is not None else [],
            "overcurrent_trip_A": 3.4 if drive == "pmstep" else None,
            "survived_fraction": None if survived is None else survived / holding,
        }
        if survived is not None:
            row.update(
                {
                    "max_error_full_steps": 6.052,
                    "final_error_full_steps": 0.0,
                    "rms_phase_current_A": 1.647,
                    "peak_phase_current_a_A": 3.397,
                    "diag_periods": 136 if drive == "pmstep" else 0,
                    "diag_first_s": 0.46 if drive == "pmstep" else -1.0,
                }
            )
        return row

    def test_survived(self):
        """The same verdict for both drives: DIAG is no failure, half a full step at the end is."""
        self.assertEqual(stepdir_compare.load_failures(self.summary(final=0.49, diag=300)), [])
        self.assertEqual(len(stepdir_compare.load_failures(self.summary(final=-0.5))), 1)
        self.assertEqual(stepdir_compare.load_failures(self.summary(final=412.2)), ["+412 full steps lost"])
        self.assertEqual(
            stepdir_compare.load_failures(self.summary(fault="STALL", following_end=0.5)),
            ["fault STALL", "not following the count to the end"],
        )

    def test_bisection(self):
        """The bracket [0, 1.5 T_H] run at both ends, then halved: the threshold lies in (survived, failed]."""
        with tempfile.TemporaryDirectory() as work:
            base = os.path.join(work, "m.ini")
            with open(base, "w") as f:
                f.write("[controller.limits]\nmax_phase_current_A = 3.4\n")
            args = argparse.Namespace(designs={"m": self.DESIGN})
            for threshold, survived, failed in ((0.153, 0.15, 0.1875), (0.7, 0.6, None), (-1.0, None, 0.0)):
                torques = []

                def run(args, motor, drive, torque, work, threshold=threshold, torques=torques):
                    torques.append(torque)
                    return self.summary(), ([] if torque <= threshold else ["lost"])

                with (
                    mock.patch.object(stepdir_compare, "designed", return_value=(self.PRESET, 0.4, base)),
                    mock.patch.object(stepdir_compare, "load_run", side_effect=run),
                ):
                    row = stepdir_compare.load_search(args, "m", "pmstep", 4, work)
                self.assertEqual(torques[0], 0.0)
                if len(torques) > 1:
                    self.assertAlmostEqual(torques[1], 0.6)
                self.assertAlmostEqual(row["survived_Nm"] or 0.0, survived or 0.0)
                self.assertEqual(row["survived_Nm"] is None, survived is None)
                if failed is None:
                    self.assertIsNone(row["failed_Nm"])
                else:
                    self.assertAlmostEqual(row["failed_Nm"], failed)
                self.assertEqual(len(torques), 6 if 0.0 <= threshold < 0.6 else (2 if threshold >= 0.6 else 1))
                self.assertEqual(row["overcurrent_trip_A"], 3.4)
                self.assertAlmostEqual(row["resolution_Nm"], 0.6 / 16)
                self.assertGreater(row["step_time_s"], row["move_start_s"])
                self.assertLess(row["step_time_s"], row["move_end_s"])

    def test_report(self):
        run = {
            "motor": "17hs4401",
            "case": "moves",
            "drive": "pmstep",
            "microsteps": 16,
            "step_rate_hz": 17600.0,
            "rms_phase_current_A": 0.84,
            "checked": True,
            "failures": [],
            "notes": [],
            "stepdir": {
                "max_error_moving_full_steps": 0.113,
                "rms_error_moving_full_steps": 0.033,
                "max_error_full_steps": 0.113,
                "rms_error_full_steps": 0.023,
                "final_error_full_steps": 0.0,
                "lost_full_steps": 0,
                "diag_periods": 0,
                "diag_first_s": -1.0,
            },
        }
        loads = [
            self.load_row("17hs4401", "pmstep", 0.4535, 0.4547),
            self.load_row("17hs4401", "microstep", 0.1793, 0.1805),
            self.load_row("bj42d29", "pmstep", 0.1, 0.11, 0.41),
            self.load_row("bj42d29", "microstep", 0.2, 0.21, 0.41),
        ]
        args = argparse.Namespace(quick=False, plot_motor="17hs4401", plot_case="moves")
        argv = ["tools/stepdir_compare.py", "--check"]
        text = stepdir_compare.report_text([run], args, argv, None, loads)
        self.assert_header(text, "tools/stepdir_compare.py --check")
        self.assert_tables(text)
        self.assertIn("## Largest load step survived during a move", text)
        self.assertIn(
            "| 17hs4401 | pmstep | 0.4 N·m | 0.459 s (cruise 0.304–0.614 s) | 0.4535 N·m | 1.134 | "
            "0.4547 N·m: fault OVERCURRENT | 6.052 | +0.000 | yes (0.460 s) | 1.647 A | "
            "3.40 A (trip 3.4 A) | 2.53 |",
            text,
        )
        self.assertIn("| 17hs4401 | microstep | 0.4 N·m | 0.459 s (cruise 0.304–0.614 s) | 0.1793 N·m | 0.448 |", text)
        self.assertIn("9 halvings: resolution 1.5 / 512 = 0.29 % of the holding torque", text)
        self.assertIn("√2 k_M I on these presets", text)
        self.assertIn(
            "pmstep survives at least microstepping's load step on 1 of 2 presets; pmstep / microstepping 0.50–2.53.",
            text,
        )
        self.assertEqual(len(stepdir_compare.load_check(loads)), 1)
        self.assertTrue(stepdir_compare.load_check(loads)[0].startswith("bj42d29:"))
        self.assertEqual(stepdir_compare.load_check(loads[:2]), [])
        self.assertNotIn("## Largest load step", stepdir_compare.report_text([run], args, argv, None, []))


class TorqueSpeed(ReportCase):
    @staticmethod
    def row(motor, bus, fraction, drive, held, failed, holding=0.4, error=None):
        r = {
            "motor": motor,
            "bus_V": bus,
            "fraction": fraction,
            "drive": drive,
            "speed_rad_s": 69.0 * fraction,
            "holding_Nm": holding,
            "error": error,
            "held_Nm": held,
            "failed_Nm": failed,
            "failed_why": ["fault OVERCURRENT"] if failed is not None else [],
        }
        if held is not None:
            r.update(
                {
                    "held_fraction": held / holding,
                    "rms_phase_current_A": 1.5,
                    "copper_loss_W": torque_speed.copper_loss_W(1.5, 1.5),
                }
            )
        return r

    def test_bisection(self):
        """A run at each end of the bracket, then halvings: the threshold lies in [held, failed)."""
        for threshold, held, failed, runs in ((0.153, 0.15, 0.1875, 6), (0.7, 0.6, None, 2), (-1.0, None, 0.0, 1)):
            xs = []

            def ok(x, threshold=threshold, xs=xs):
                xs.append(x)
                return x <= threshold

            lo, hi = torque_speed.bisect(ok, 0.0, 0.6, 4)
            self.assertEqual(xs[0], 0.0)
            self.assertEqual(len(xs), runs)
            self.assertEqual(lo is None, held is None)
            self.assertAlmostEqual(lo or 0.0, held or 0.0)
            self.assertEqual(hi is None, failed is None)
            self.assertAlmostEqual(hi or 0.0, failed or 0.0)

    def test_copper_loss(self):
        """2 R I_rms^2: 1.5 A per phase in 1.5 ohm is 6.75 W for the two phases."""
        self.assertAlmostEqual(torque_speed.copper_loss_W(1.5, 1.5), 6.75)
        self.assertEqual(torque_speed.copper_loss_W(0.0, 2.0), 0.0)

    def test_held(self):
        """The same rule for both drives: a fault, a loss of synchronism or the speed error above the bound."""

        def summary(fault="NONE", lost=False, error=1.0):
            return {
                "fault": {"name": fault},
                "loss_of_synchronism": lost,
                "loss_of_synchronism_time_s": 0.5,
                "robustness": {"max_speed_error_rad_s": error, "max_speed_error_time_s": 0.6},
            }

        self.assertEqual(torque_speed.held_failures(summary(error=2.0), 2.0), [])
        self.assertEqual(torque_speed.held_failures(summary(error=2.01), 2.0), ["speed error 2.01 rad/s at 0.600 s"])
        self.assertEqual(len(torque_speed.held_failures(summary("OVERCURRENT", True, 3.0), 2.0)), 3)

    def test_timeline(self):
        """The ramp from RUN's start + LEAD_S at min(a_ref / 4, A_AXIS); the load after SETTLE_S at the speed."""
        motor = {"rated_A": 1.7, "k_M": 0.16638, "J": 5.4e-6, "R": 1.5, "p": 50, "holding_Nm": 0.4}
        tl = torque_speed.timeline(motor, 69.0, 0.25, 0.5)
        self.assertAlmostEqual(tl["a"], 1000.0)
        self.assertAlmostEqual(tl["reached_s"] - tl["ramp_s"], 0.0345)
        self.assertAlmostEqual(tl["load_s"], 0.25 + torque_speed.LEAD_S + 0.0345 + torque_speed.SETTLE_S)
        self.assertAlmostEqual(tl["end_s"] - tl["load_s"], torque_speed.LOAD_RAMP_S + torque_speed.HOLD_S)

    def test_report(self):
        rows = [
            self.row("17hs4401", 24.0, 0.25, "pmstep", 0.525, 0.5625),
            self.row("17hs4401", 24.0, 0.25, "pmstep-no-fw", 0.5, 0.5125),
            self.row("17hs4401", 24.0, 0.25, "microstep", 0.225, 0.2625),
            self.row("17hs4401", 24.0, 0.75, "pmstep", 0.6, None),
            self.row("17hs4401", 24.0, 0.75, "pmstep-no-fw", None, 0.0),
            self.row("17hs4401", 24.0, 0.75, "microstep", None, 0.0),
            self.row("17hs4401", 12.0, 0.25, "pmstep", None, None, error="pmstep-sil failed (1): x"),
            self.row("17hs4401", 12.0, 0.25, "microstep", 0.1, 0.11),
        ]
        refused = [{"motor": "paper", "bus_V": 12.0, "why": "cannot design"}]
        self.assertAlmostEqual(torque_speed.ratio(0.525, 0.225), 2.3333333)
        self.assertIsNone(torque_speed.ratio(0.5, 0.0))
        self.assertEqual(len(torque_speed.unevaluated(rows)), 1)
        # 0.225 N m at 0.25 x top is over 30 % of 0.4 N m and over microstepping's; at 0.75 x top pmstep holds
        # 0.6: no shortfall. A row under both marks is named twice.
        self.assertEqual(torque_speed.shortfalls(rows), [])
        short = rows + [
            self.row("as1050", 24.0, 1.5, "pmstep", 0.1, 0.11),
            self.row("as1050", 24.0, 1.5, "microstep", 0.2, 0.21),
            self.row("as1050", 24.0, 2.0, "pmstep", None, 0.0),
        ]
        self.assertEqual(
            torque_speed.shortfalls(short),
            [
                "as1050 24 V 1.5 x top: pmstep holds 0.100 N m, microstepping 0.200",
                "as1050 24 V 1.5 x top: pmstep holds 0.100 N m, under 30 % of the holding torque",
            ],
        )
        args = argparse.Namespace(iterations=7)
        argv = ["tools/torque_speed.py", "--report", "x.md"]
        text = torque_speed.report_text(rows, refused, args, argv, [("17hs4401", "x-17hs4401.png")])
        self.assert_header(text, "tools/torque_speed.py --report x.md")
        self.assert_tables(text)
        self.assertIn(
            "| 17hs4401 | 24 | 0.25 | 17.2 | 0.525 (1.31) | 0.500 (1.25) | 0.225 (0.56) | 2.33 | 6.75 | 6.75 | 6.75 |",
            text,
        )
        self.assertIn("| ≥ 0.600 (1.50) | none | none | - |", text)
        self.assertIn("| n/a | n/a | 0.100 (0.25) |", text)
        self.assertIn("| paper | 12 | - | - | no design | no design | no design |", text)
        # top speeds: pmstep holds 30 % of T_H (0.12 N m) at 0.75 x top, without FW at 0.25 x, microstepping too
        self.assertIn(
            "| 17hs4401 | 24 | 69.0 | 51.8 (0.75×) | 51.8 (0.75×) | 17.2 (0.25×) | 17.2 (0.25×) | 17.2 (0.25×) "
            "| 17.2 (0.25×) |",
            text,
        )
        self.assertIn("resolution 1.5 T_H / 128", text)
        self.assertIn("2.33–2.33 over 1 cases; pmstep holds less than microstepping in 0 of them", text)
        self.assertIn("![17hs4401: largest held load against speed](x-17hs4401.png)", text)
        self.assertIn("- 17hs4401 24 V, 0.75 × top, microstep: holds no load (fault OVERCURRENT)", text)
        self.assertIn("- pmstep, first failure above the largest held load: fault OVERCURRENT in 1", text)

    def test_microstep_grid(self):
        """The second grid at fractions of microstepping's own top speed: the cases from the first grid's rows,
        none where microstepping holds no load; the table of the two drives and their ratio."""
        motor = {"rated_A": 1.7, "k_M": 0.16638, "J": 5.4e-6, "R": 1.5, "p": 50, "holding_Nm": 0.4}
        first = [
            {
                "motor": m,
                "bus": 24.0,
                "fraction": f,
                "preset": motor,
                "scenario": m + ".ini",
                "top_rad_s": 69.0,
                "run_start": 0.25,
                "timeline": torque_speed.timeline(motor, 69.0, 0.25, f),
            }
            for m in ("17hs4401", "paper")
            for f in (0.25, 1.25)
        ]
        rows = [
            self.row("17hs4401", 24.0, 0.25, "microstep", 0.225, 0.2625),
            self.row("17hs4401", 24.0, 1.25, "microstep", 0.05, 0.0625),
            self.row("paper", 24.0, 0.25, "microstep", None, 0.0),
            self.row("paper", 24.0, 1.25, "microstep", None, 0.0),
        ]
        cases = torque_speed.microstep_cases(first, rows)
        self.assertEqual([c["microstep_fraction"] for c in cases], torque_speed.MICROSTEP_FRACTIONS)
        self.assertEqual({c["motor"] for c in cases}, {"17hs4401"})
        # microstepping's top is 1.25 x 69 rad/s: its quarter is 0.3125 x the design's top
        self.assertAlmostEqual(cases[0]["fraction"], 0.3125)
        self.assertAlmostEqual(cases[-1]["timeline"]["v"], 86.25)
        ms_rows = []
        for f, pm, ms in ((0.25, 0.5, 0.25), (0.5, 0.45, 0.15), (0.75, 0.3, None), (1.0, 0.2, 0.05)):
            for drive, held in (("pmstep", pm), ("microstep", ms)):
                r = self.row("17hs4401", 24.0, 1.25 * f, drive, held, None if held == 0.5 else 0.6)
                r["microstep_fraction"] = f
                ms_rows.append(r)
        table = torque_speed.microstep_ratio_table(ms_rows)
        self.assertIn(
            "| 17hs4401 | 24 | 86.2 | ≥ 0.500 / 0.250 (2.00) | 0.450 / 0.150 (3.00) | 0.300 / none (-) "
            "| 0.200 / 0.050 (4.00) |",
            table,
        )
        args = argparse.Namespace(iterations=7)
        text = torque_speed.report_text(rows, [], args, ["tools/torque_speed.py"], [], ms_rows)
        self.assert_tables(text)
        self.assertIn("## Against microstepping's own top speed", text)
        self.assertIn("2.00–4.00 over 3 cases; pmstep holds less than microstepping in 0 of them", text)


if __name__ == "__main__":
    unittest.main()
