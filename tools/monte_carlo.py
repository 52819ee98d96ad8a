#!/usr/bin/env python3
"""Monte Carlo robustness runner for pmstep-sil: many randomised runs, one report.

Usage:
  tools/monte_carlo.py --sil PATH/pmstep-sil --scenario sil/scenarios/robust.ini \\
      --cases N --seed S --out DIR [--engine dask|threads] [--jobs J] [--scheduler ADDRESS [--ship-sil]]
      [--duration SECONDS] [--no-plots] [--check]
  tools/monte_carlo.py --sil PATH/pmstep-sil --scenario FILE --out DIR --case CASE_SEED
  tools/monte_carlo.py --sil PATH/pmstep-sil --preset sil/scenarios/motors/17hs4401.ini --cases N --out DIR ...

--preset FILE runs the campaign on a motor preset instead of a scenario file: the gain
designer's settings (pmstep-tune --robust, --tune PATH, by default next to --sil) behind the
realistic chain, and a distribution table scaled to the motor (mc_preset.py says how); the
speed bounds are then the paper campaign's as fractions of the designer's top speed (the
success bound 0.5 rad/s x top speed / 9.6 rad/s, the paper motor's) unless --speed-bound is given.
With --scenario FILE as well, the campaign runs that scenario as it is (one written for the
preset, e.g. by position_acceptance.py --write-scenarios) with the preset's distribution table.

Parts: mc_distributions.py (what is drawn), mc_execution.py (running the cases on an
engine, resuming), mc_outcome.py (a case's class and numbers), mc_report.py (aggregate,
report, cases.csv); every
scenario key they set is named in scenario_keys.py.

Engines (--engine): "dask" (default) runs the cases on dask.distributed, by default on a
local cluster of --jobs single-threaded worker processes (default: one per core), or with
--scheduler ADDRESS on an existing cluster (e.g. tcp://10.0.0.5:8786): start its scheduler
with `dask scheduler` and a worker per core on each machine with `dask worker ADDRESS
--nthreads 1 --nworkers N`, from any folder and with no PYTHONPATH: the scheduler and the
workers need only Python of the client's version (3.X) with the dask and distributed that
tools/requirements.txt pins, nothing of this project (the function a worker runs travels
by value in each task graph, mc_execution.py). Each worker runs pmstep-sil at the --sil path,
which must then exist there (same build on a shared or identical path), or, with --ship-sil,
the client uploads its pmstep-sil to every worker (also to workers that join later); either
way the workers' machines need pmstep-sil's shared libraries (tools/install_deps.sh). Nothing
else is shared: the scenario text travels with each case and the results come back to the
client. "threads" runs them on --jobs threads here, with no Dask. The results of a case do
not depend on the engine or the number of workers: its seed alone fixes it. A worker that
dies takes its running cases with it; the scheduler runs them again on the other workers.

Resume: every finished case is kept at once in DIR/cases/<case seed>/result.json; running
the same command again on the same DIR runs only the cases not finished (a campaign stopped
by a kill, a crash or Ctrl-C resumes where it was; --cases may also grow). DIR/campaign.json
holds what fixes the results (pmstep-sil's SHA-256, the scenario file's, the duration and the
distribution table): a folder of another campaign is refused.

Each case draws plant, sensor, inverter, bus, initial-angle and load parameters from the
distribution table DISTRIBUTIONS (mc_distributions.py) (relative to the values of the scenario file, read
once with `pmstep-sil --scenario FILE --print-scenario`) and runs pmstep-sil with them as
`--set section.key=value` overrides, plus `--set run.seed=CASE_SEED` so that the SIL's own
noise is reproducible too.

Seeds: case k (0-based) of a run with base seed S has the case seed S * 100000 + k
(so --cases is at most 100000). The case seed alone fixes everything about a case: its
parameters are drawn by random.Random(case_seed), one draw per row of DISTRIBUTIONS in
table order, and it is the SIL's run.seed. `--case CASE_SEED` re-runs that one case (with
the CSV time series, so `tools/plot_run.py DIR/cases/CASE_SEED` can draw it), prints the
pmstep-sil command line, the drawn parameters, the class and the summary.

Classes (see classify()):
  success      no fault latched, no non-finite value, and after settling
               max |w - w*| < --speed-bound (0.5 rad/s), max angle error < --angle-bound (0.05 rad);
               with --position-bound (a position scenario), every move issued, finished and
               ending within that many electrical rad of its target
  detected     a fault latched; if the SIL saw a loss of control, the fault came at most
               --latency-bound (0.05 s) after it (the latency is recorded); without a loss of
               control the fault is a false trip (still "detected", counted apart)
  silent       a loss of control with no fault latched within --latency-bound after it
  out_of_spec  no loss of control and no fault, but a bound exceeded (or a non-finite value)
  crashed      pmstep-sil exited other than 0 (ran) or 3 (ran, fault latched), timed out,
               or left no readable summary.json with the fields this tool needs

Outputs in DIR: report.md (with PNG histograms unless --no-plots), cases.csv (one row per
case), summary.json (the aggregate numbers), campaign.json, cases/<case seed>/summary.json
and result.json (each run). Each failed case has a failure time (the loss of control, a false
trip's fault, the exceeded maximum's sample) and the speed profile's segment holding it
(mc_segments.py); the report and summary.json count the failures by segment.

--report FILE also writes the campaign's summary (success, silent failures, failure classes,
faults, the command that reruns it; command, commit and date: tools/report.py) as the section
--report-section NAME (default: the preset's name, or the scenario file's) of the page FILE,
replacing that section if the page has it, so that one page (docs/reports/monte-carlo.md) holds
one section per campaign, written by campaigns run in turn.

--check exits with status 1 unless the success rate is >= --min-success (0.99), no case is
silent, none crashed and none saw a non-finite value. The last line printed is always
"N passed, N failed" (passed = success cases, failed = all others).

The threads engine and the report need only the standard library; dask.distributed is
imported for the Dask engine, numpy and matplotlib (tools/requirements.txt) only to draw
the histograms.
"""

import argparse
import datetime
import json
import os
import re
import shlex
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# The three parts; their names are also this module's (the self-test uses them from here).
from mc_distributions import (
    DISTRIBUTIONS,
    DURATION_KEY,
    KEY_PARAMETERS,
    SEED_KEY,
    SEED_STRIDE,
    ToolError,
    base_values,
    case_seed,
    distribution_rows,
    draw_parameters,
    format_value,
    missing_keys,
    parse_scenario,
    split_case_seed,
)
from mc_execution import (
    ENGINES,
    check_keys,
    read_scenario,
    rerun_command,
    run_all,
    run_case,
    sil_command,
    sil_version,
)
from mc_outcome import (
    CLASSES,
    CLASS_TEXT,
    FAULT_EXIT_STATUS,
    REQUIRED_FIELDS,
    classify,
    extract_metrics,
    fault_name,
    get_path,
    number_or_none,
    summary_problem,
)
from mc_preset import design_scenario, preset_distributions, read_preset, scenario_info
from mc_segments import (
    failures_by_segment,
    label_failures,
    profile_segments,
    segment_of,
    speed_points,
)

FAILURE_CLASSES = ("detected", "silent", "out_of_spec")  # the classes the segment table counts
from mc_report import (
    CSV_METRICS,
    PAGE_TITLE,
    PAGE_WHAT,
    WORST_CASES,
    aggregate,
    campaign_section,
    check_verdict,
    make_plots,
    percentile,
    spans_decades,
    wilson_interval,
    worst_order,
    write_cases_csv,
    write_report,
)
import report  # noqa: E402


def parse_args(argv):
    parser = argparse.ArgumentParser(
        description="Monte Carlo robustness runner for pmstep-sil (see the module docstring).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__.split("\n\n", 1)[1],
    )
    parser.add_argument("--sil", required=True, help="the pmstep-sil executable")
    parser.add_argument("--scenario", default=None, help="scenario INI file the cases start from")
    parser.add_argument(
        "--preset",
        default=None,
        metavar="FILE",
        help="a motor preset (sil/scenarios/motors/*.ini): the designer's gains, the realistic chain, "
        "distributions scaled to the motor (mc_preset.py); with --scenario, that scenario "
        "(written for the preset) with the preset's distributions",
    )
    parser.add_argument(
        "--tune", default=None, metavar="PATH", help="pmstep-tune for --preset (default: the one next to --sil)"
    )
    parser.add_argument(
        "--phase-voltage-sensing",
        action="store_true",
        help="with --preset: the drive also senses each phase's mean voltage per period, and the "
        "cases draw that sensor's errors (mc_preset.py)",
    )
    parser.add_argument(
        "--low-speed-drive",
        action="store_true",
        help="with --preset: the design turns the standstill hold's vector below 2 V_bus t_d / (T_s k_M) "
        "(pmstep-tune --low-speed-drive)",
    )
    parser.add_argument(
        "--weakened",
        action="store_true",
        help="with --preset alone: the profile stretched to the field-weakened top speed (pmstep-tune's 'top speed "
        "with it'), the speed thresholds with it (mc_preset.design_scenario)",
    )
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--cases", type=int, default=100, help="number of cases N (default 100)")
    parser.add_argument("--seed", type=int, default=1, help="base seed S: case k has seed S*100000+k (default 1)")
    parser.add_argument(
        "--engine",
        choices=ENGINES,
        default="dask",
        help="dask (default): dask.distributed; threads: a thread pool on this machine",
    )
    parser.add_argument(
        "--jobs", type=int, default=os.cpu_count() or 1, help="local Dask workers or threads (default: one per core)"
    )
    parser.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="run on the existing Dask cluster of this scheduler (e.g. tcp://host:8786)",
    )
    parser.add_argument(
        "--ship-sil",
        action="store_true",
        help="upload --sil to every Dask worker (else each worker runs the --sil path)",
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="SECONDS",
        help="simulated time per case (run.duration_s; default: the scenario's)",
    )
    parser.add_argument("--no-plots", action="store_true", help="no PNG histograms (no numpy/matplotlib needed)")
    parser.add_argument("--check", action="store_true", help="exit 1 unless the run meets the criteria")
    parser.add_argument(
        "--case",
        type=int,
        default=None,
        metavar="CASE_SEED",
        help="re-run the one case with this case seed and print its summary",
    )
    parser.add_argument(
        "--speed-bound",
        type=float,
        default=None,
        metavar="RAD_S",
        help="max |w - w*| after settling for success (default 0.5 rad/s; with --preset the same "
        "fraction of the designer's top speed as 0.5 rad/s of the paper motor's)",
    )
    parser.add_argument(
        "--angle-bound",
        type=float,
        default=0.05,
        metavar="RAD",
        help="max angle-estimate error after settling for success (default 0.05 rad)",
    )
    parser.add_argument(
        "--position-bound",
        type=float,
        default=None,
        metavar="RAD",
        help="a position scenario (position.points): success also needs every move to end within "
        "this many electrical rad of its target (default: not checked)",
    )
    parser.add_argument(
        "--latency-bound",
        type=float,
        default=0.05,
        metavar="SECONDS",
        help="a fault later than this after a loss of control is a silent failure (default 0.05 s)",
    )
    parser.add_argument("--min-success", type=float, default=0.99, help="--check: minimum success rate (default 0.99)")
    parser.add_argument(
        "--exclude",
        action="append",
        default=[],
        metavar="KEY",
        help="leave this row of the distribution table out (the scenario's value stays); "
        "repeatable, e.g. --exclude controller.inverter.dead_time_s for a firmware without compensation",
    )
    parser.add_argument(
        "--report",
        default=None,
        metavar="FILE",
        help="also write the campaign's summary as a section of this Markdown page "
        "(docs/reports/monte-carlo.md), replacing the section of the same name",
    )
    parser.add_argument(
        "--report-section",
        default=None,
        metavar="NAME",
        help="the section's name for --report (letters, digits, '.', '_', '-'; default: the "
        "preset's name, or the scenario file's without .ini)",
    )
    parser.add_argument(
        "--case-timeout",
        type=float,
        default=600.0,
        metavar="SECONDS",
        help="wall time after which one run counts as crashed (default 600 s)",
    )
    args = parser.parse_args(argv[1:])
    if args.scenario is None and args.preset is None:
        parser.error("give --scenario, --preset or both")
    if args.tune is not None and args.preset is None:
        parser.error("--tune is for --preset")
    if args.low_speed_drive and args.preset is None:
        parser.error("--low-speed-drive is for --preset (a scenario file sets controller.standstill itself)")
    if args.weakened and (args.preset is None or args.scenario is not None):
        parser.error("--weakened is for --preset alone (the profile is the designer's)")
    if args.phase_voltage_sensing and args.preset is None:
        parser.error("--phase-voltage-sensing is for --preset (a scenario file sets the sensor itself)")
    if args.preset is not None and args.tune is None:
        args.tune = os.path.join(os.path.dirname(args.sil) or ".", "pmstep-tune")
    if args.case is None and not 1 <= args.cases <= SEED_STRIDE:
        parser.error(f"--cases must be between 1 and {SEED_STRIDE}")
    if args.seed < 0 or (args.case is not None and args.case < 0):
        parser.error("seeds must be >= 0")
    if args.jobs < 1:
        parser.error("--jobs must be >= 1")
    if (args.scheduler or args.ship_sil) and args.engine != "dask":
        parser.error("--scheduler and --ship-sil need --engine dask")
    if args.ship_sil and not args.scheduler:
        parser.error("--ship-sil is for --scheduler (a local cluster runs --sil itself)")
    if args.duration is not None and not args.duration > 0:
        parser.error("--duration must be > 0")
    if not 0 <= args.min_success <= 1:
        parser.error("--min-success must be within [0, 1]")
    if args.report_section is not None and args.report is None:
        parser.error("--report-section is for --report")
    if args.report is not None and args.report_section is None:
        source = args.preset if args.preset is not None and args.scenario is None else args.scenario
        args.report_section = re.sub(r"[^A-Za-z0-9._-]+", "-", os.path.splitext(os.path.basename(source))[0])
        if args.preset is not None and args.scenario is None:
            args.report_section += "".join(
                suffix
                for flag, suffix in (
                    (args.phase_voltage_sensing, "-sensed"),
                    (args.low_speed_drive, "-low-speed-drive"),
                    (args.weakened, "-weakened"),
                )
                if flag
            )
    if args.report_section is not None and not re.fullmatch(r"[A-Za-z0-9._-]+", args.report_section):
        parser.error("--report-section: letters, digits, '.', '_' and '-' only")
    args.argv = argv
    args.script = argv[0]
    return args


def run_one(args, scenario, base):
    """--case: re-run one case, print what it did; returns the exit status."""
    seed = args.case
    record = run_case(args, seed, base, csv_output=True)
    base_seed, index = split_case_seed(seed)
    print(f"case seed {seed} (base seed {base_seed}, case {index}); pmstep-sil command:")
    print("  " + shlex.join(record["command"]))
    print("drawn parameters:")
    for key, kind, _a, _b in DISTRIBUTIONS:
        value = record["params"][key]
        factor = f"  (x{value / float(scenario[key]):.4f})" if kind == "scale" and float(scenario[key]) else ""
        print(f"  {key:34s} {format_value(value)}{factor}")
    print(f"class: {record['class']}" + (f" - {record['reason']}" if record["reason"] else ""))
    if record["summary"] is not None:
        print("summary.json:")
        print(json.dumps(record["summary"], indent=2))
    if record["stderr_tail"].strip():
        print("stderr (tail):\n" + record["stderr_tail"].rstrip())
    print(f"outputs in {os.path.join(args.out, 'cases', str(seed))} (tools/plot_run.py draws them)")
    passed = record["class"] == "success"
    print(f"{int(passed)} passed, {int(not passed)} failed")
    return 1 if args.check and not passed else 0


def use_preset(args):
    """--preset: designs the campaign's scenario into DIR (or, with --scenario, takes that one as
    it is), puts the preset's distribution table in place of the paper's, and sets the speed
    bound; returns what the report says of the preset."""
    if not os.path.isfile(args.preset):
        raise ToolError(f"motor preset {args.preset} not found")
    if not (os.path.isfile(args.tune) and os.access(args.tune, os.X_OK)):
        raise ToolError(f"{args.tune} is not an executable file (pmstep-tune, built beside pmstep-sil; or give --tune)")
    read_preset(args.preset)  # a clear error for a bad preset before the designer runs
    if args.scenario is not None:
        if not os.path.isfile(args.scenario):
            raise ToolError(f"scenario file {args.scenario} not found")
        info = scenario_info(args.tune, args.preset, args.scenario, args.phase_voltage_sensing, args.low_speed_drive)
    else:
        args.scenario, info = design_scenario(
            args.tune, args.preset, args.out, args.phase_voltage_sensing, args.low_speed_drive, args.weakened
        )
    # In place, so every function's default table (the same list object) sees it.
    DISTRIBUTIONS[:] = preset_distributions(
        info["figures"], info["peak_speed_rad_s"], info["paper_holding_torque_Nm"], args.phase_voltage_sensing
    )
    if args.speed_bound is None:
        args.speed_bound = info["speed_bound_rad_s"]
    print(
        f"monte_carlo: preset {info['preset']}: top speed {info['top_speed_rad_s']:g} rad/s, profile peak "
        f"{info['peak_speed_rad_s']:g} rad/s, load step {info['load_Nm']:.4g} N m, speed bound "
        f"{args.speed_bound:.4g} rad/s; scenario {args.scenario}",
        file=sys.stderr,
    )
    return {
        key: info[key]
        for key in (
            "preset",
            "preset_file",
            "top_speed_rad_s",
            "run_start_s",
            "peak_speed_rad_s",
            "load_Nm",
            "speed_bound_rad_s",
            "tune_command",
            "designed",
        )
    }


def main(argv):
    args = parse_args(argv)
    preset_info = None
    if args.preset is not None:
        try:
            os.makedirs(args.out, exist_ok=True)
            preset_info = use_preset(args)
        except (ToolError, OSError) as e:
            sys.stderr.write(f"monte_carlo: {e}\n")
            print("0 passed, 0 failed")
            return 2
    elif args.speed_bound is None:
        args.speed_bound = 0.5
    unknown = [key for key in args.exclude if key not in [row[0] for row in DISTRIBUTIONS]]
    if unknown:
        print(f"monte_carlo: --exclude {', '.join(unknown)}: not in the distribution table", file=sys.stderr)
        return 2
    # In place, so every function's default table (the same list object) sees it.
    DISTRIBUTIONS[:] = [row for row in DISTRIBUTIONS if row[0] not in args.exclude]
    started_utc = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    try:
        if not (os.path.isfile(args.sil) and os.access(args.sil, os.X_OK)):
            raise ToolError(
                f"{args.sil} is not an executable file (build it: cmake --preset host-release && "
                "cmake --build --preset host-release)"
            )
        if not os.path.isfile(args.scenario):
            raise ToolError(f"scenario file {args.scenario} not found")
        if not args.no_plots and args.case is None:
            try:  # fail now rather than after the runs
                import matplotlib  # noqa: F401
                import numpy  # noqa: F401
            except ImportError as e:
                raise ToolError(
                    f"the histograms need numpy and matplotlib ({e}); install tools/requirements.txt "
                    "(e.g. into .venv) or pass --no-plots"
                ) from None
        scenario = read_scenario(args.sil, args.scenario)
        check_keys(args.sil, args.scenario, scenario, args.duration is not None)
        base = base_values(scenario)
        os.makedirs(args.out, exist_ok=True)
    except (ToolError, OSError) as e:
        sys.stderr.write(f"monte_carlo: {e}\n")
        print("0 passed, 0 failed")
        return 2

    if args.case is not None:
        return run_one(args, scenario, base)

    version = sil_version(args.sil)
    where = (
        args.scheduler
        if args.scheduler
        else (f"{args.jobs} local " + ("workers" if args.engine == "dask" else "threads"))
    )
    print(
        f"monte_carlo: {args.cases} cases of {args.scenario}, base seed {args.seed}, {args.engine} on {where} "
        f"-> {args.out}",
        file=sys.stderr,
    )
    args.seeds = [case_seed(args.seed, k) for k in range(args.cases)]
    wall_start = time.monotonic()
    try:
        with open(args.scenario) as f:
            scenario_text = f.read()
        records, engine, workers, resumed = run_all(args, base, scenario_text)
    except KeyboardInterrupt:
        sys.stderr.write("\nmonte_carlo: interrupted (the finished cases are kept; the same command resumes)\n")
        print("0 passed, 0 failed")
        return 130
    except (ToolError, OSError) as e:
        sys.stderr.write(f"monte_carlo: {e}\n")
        print("0 passed, 0 failed")
        return 2
    wall_s = time.monotonic() - wall_start

    def mean_of(name):
        values = [r["metrics"].get(name) for r in records if r["metrics"].get(name) is not None]
        return sum(values) / len(values) if values else None

    segments = label_failures(records, scenario)
    agg = aggregate(records, args)
    agg["failures_by_segment"] = failures_by_segment(records, FAILURE_CLASSES, segments)
    agg.update(
        {
            "scenario": args.scenario,
            "command": shlex.join(args.argv),
            "date": started_utc,
            "pmstep_sil_version": version,
            "duration_s": args.duration,
            "execution": {
                "engine": engine,
                "workers": workers,
                "cases_run": len(records) - resumed,
                "cases_resumed": resumed,
                "wall_s": wall_s,
                "campaign_wall_s_per_case": wall_s / (len(records) - resumed) if len(records) > resumed else None,
                # Inside pmstep-sil, per case: the run's loop, its CPU time, the firmware and
                # plant shares (sampled), as each summary.json's timing reports them.
                "sil_loop_wall_s_mean": mean_of("wall_s"),
                "sil_loop_cpu_s_mean": mean_of("cpu_s"),
                "sil_firmware_wall_s_mean": mean_of("firmware_wall_s"),
                "sil_plant_wall_s_mean": mean_of("plant_wall_s"),
            },
            "distribution_table": [list(row) for row in DISTRIBUTIONS],
            "preset": preset_info,
            "worst_cases": [
                {
                    "seed": r["seed"],
                    "class": r["class"],
                    "reason": r["reason"],
                    "max_speed_error_rad_s": r["metrics"].get("max_speed_error_rad_s"),
                    "command": shlex.join(r["command"]),
                }
                for r in worst_order(records)[:WORST_CASES]
            ],
        }
    )
    plots = []
    if not args.no_plots:
        plots = make_plots(args.out, records, args)
    reasons = check_verdict(agg, args.min_success)
    agg["check"] = {"min_success": args.min_success, "passed": not reasons, "reasons": reasons}
    write_report(os.path.join(args.out, "report.md"), records, agg, args, scenario, version, plots, started_utc)
    write_cases_csv(os.path.join(args.out, "cases.csv"), records)
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(agg, f, indent=2)
        f.write("\n")

    counts = agg["counts"]
    low, high = agg["success_rate_wilson95"]
    print(
        f"success {counts['success']}/{agg['cases']} ({100 * agg['success_rate']:.1f} %, "
        f"Wilson 95 % {100 * low:.1f}-{100 * high:.1f} %); "
        + ", ".join(f"{cls} {counts[cls]}" for cls in CLASSES[1:])
        + f" (false trips {agg['false_trips']}); non-finite {agg['nonfinite_cases']}"
    )
    if agg["faults_by_name"]:
        print("faults: " + ", ".join(f"{name} x{count}" for name, count in agg["faults_by_name"].items()))
    crashed = [r for r in records if r["class"] == "crashed"]
    for r in crashed[:WORST_CASES]:
        tail = r["stderr_tail"].strip().splitlines()
        print(f"crashed case {r['seed']}: {r['reason']}" + (f" ({tail[-1]})" if tail else ""))
    if len(crashed) > WORST_CASES:
        print(f"... and {len(crashed) - WORST_CASES} more crashed cases (cases.csv)")
    print(
        f"{engine}, {workers} workers: {len(records) - resumed} cases run ({resumed} resumed) in {wall_s:.1f} s"
        + (f", {(wall_s / (len(records) - resumed)):.3f} s per case" if len(records) > resumed else "")
    )
    ex = agg["execution"]
    if ex["sil_loop_wall_s_mean"] is not None:

        def secs(name):
            return "-" if ex[name] is None else f"{ex[name]:.3f} s"

        print(
            f"per case inside pmstep-sil (mean): loop {secs('sil_loop_wall_s_mean')} wall, "
            f"{secs('sil_loop_cpu_s_mean')} CPU; firmware {secs('sil_firmware_wall_s_mean')}, "
            f"plant {secs('sil_plant_wall_s_mean')}"
        )
    print(f"report: {os.path.join(args.out, 'report.md')}")
    if args.report:
        page = report.write_section(
            args.report,
            PAGE_TITLE,
            args.report_section,
            campaign_section(args.report_section, records, agg, args, args.argv),
            PAGE_WHAT,
        )
        print(f"report section {args.report_section}: {page}")
    status = 0
    if args.check:
        if reasons:
            print("check FAILED: " + "; ".join(reasons))
            status = 1
        else:
            print(
                f"check passed: success rate >= {args.min_success:g}, no silent failure, no crash, no non-finite value"
            )
    print(f"{counts['success']} passed, {agg['cases'] - counts['success']} failed")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv))
