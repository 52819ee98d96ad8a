"""Monte Carlo campaigns, part 3: the report. Aggregate numbers, the --check verdict,
report.md with its histograms, cases.csv, and the campaign's section of a page of campaigns
(--report FILE --report-section NAME: docs/reports/monte-carlo.md) (see monte_carlo.py for the
whole tool)."""

import csv
import math
import os
import shlex
import statistics

from mc_distributions import (
    DURATION_KEY,
    KEY_PARAMETERS,
    SEED_KEY,
    SEED_STRIDE,
    DISTRIBUTIONS,
    distribution_rows,
    format_value,
)
from mc_execution import rerun_command
from mc_outcome import CLASSES, CLASS_TEXT
import report

WILSON_Z_95 = 1.959963984540054
WORST_CASES = 10


def wilson_interval(successes, n, z=WILSON_Z_95):
    """Wilson score interval (low, high) of a binomial proportion; (0, 1) when n == 0."""
    if n == 0:
        return (0.0, 1.0)
    if not 0 <= successes <= n:
        raise ValueError(f"{successes} successes out of {n}")
    p = successes / n
    z2 = z * z
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = z / (1 + z2 / n) * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n))
    return (max(0.0, centre - half), min(1.0, centre + half))


def percentile(values, q):
    """q-th percentile (0..100) by linear interpolation between order statistics
    (numpy's default "linear" method); None for no values."""
    if not 0 <= q <= 100:
        raise ValueError(f"percentile {q} outside [0, 100]")
    data = sorted(values)
    if not data:
        return None
    pos = (len(data) - 1) * q / 100.0
    lo = math.floor(pos)
    hi = min(lo + 1, len(data) - 1)
    return data[lo] + (data[hi] - data[lo]) * (pos - lo)


def spans_decades(values, decades=2.0):
    """True if the positive values span at least `decades` powers of ten (use a log axis)."""
    positive = [v for v in values if v > 0]
    return len(positive) >= 2 and math.log10(max(positive) / min(positive)) >= decades


def worst_order(cases):
    """Cases sorted for the worst-case table: failures (any class but success) first, then
    by max speed error after settling, largest first (a missing value counts as infinite)."""

    def key(case):
        speed = case["metrics"].get("max_speed_error_rad_s")
        return (case["class"] == "success", -(speed if speed is not None else math.inf), case["seed"])

    return sorted(cases, key=key)


def aggregate(records, args):
    """The aggregate numbers (what summary.json holds)."""
    n = len(records)
    counts = {cls: sum(1 for r in records if r["class"] == cls) for cls in CLASSES}
    false_trips = sum(1 for r in records if r["class"] == "detected" and r["false_trip"])
    low, high = wilson_interval(counts["success"], n)
    faults = {}
    for r in records:
        if r["fault_name"]:
            faults[r["fault_name"]] = faults.get(r["fault_name"], 0) + 1
    nonfinite = sum(1 for r in records if r["metrics"].get("nonfinite_seen"))
    latencies = [
        r["latency_s"]
        for r in records
        if r["class"] == "detected" and not r["false_trip"] and r["latency_s"] is not None
    ]

    def stats(name, transform=lambda v: v, past_settle_only=False):
        values = [
            transform(r["metrics"][name])
            for r in records
            if r["metrics"].get(name) is not None and (r["metrics"]["past_settle"] or not past_settle_only)
        ]
        out = {"n": len(values)}
        for q in (50, 90, 99):
            out[f"p{q}"] = percentile(values, q)
        out["max"] = max(values) if values else None
        return out

    distributions = {
        "max_speed_error_rad_s": stats("max_speed_error_rad_s", past_settle_only=True),
        "max_angle_error_rad": stats("max_angle_error_rad", past_settle_only=True),
        "commissioning_abs_r_rel_error": stats("r_rel_error", abs),
        "commissioning_abs_l_rel_error": stats("l_rel_error", abs),
        "commissioning_abs_k_rel_error": stats("k_rel_error", abs),
        "commissioning_abs_offset_a_error_A": stats("offset_a_error_A", abs),
        "commissioning_abs_offset_b_error_A": stats("offset_b_error_A", abs),
        "commissioning_abs_rest_angle_error_rad": stats("rest_angle_error_rad", abs),
    }
    for name in POSITION_METRICS:
        distributions[name] = stats(name)
    for name in ("r_rel_error", "l_rel_error", "k_rel_error"):
        values = [r["metrics"][name] for r in records if r["metrics"].get(name) is not None]
        distributions[f"commissioning_abs_{name}"]["mean_signed"] = statistics.fmean(values) if values else None
    return {
        "cases": n,
        "base_seed": args.seed,
        "success_rate": counts["success"] / n if n else None,
        "success_rate_wilson95": [low, high],
        "counts": counts,
        "detected_losses": counts["detected"] - false_trips,
        "false_trips": false_trips,
        "faults_by_name": dict(sorted(faults.items(), key=lambda kv: (-kv[1], kv[0]))),
        "nonfinite_cases": nonfinite,
        "detection_latency_s": {
            "n": len(latencies),
            "max": max(latencies) if latencies else None,
            "median": statistics.median(latencies) if latencies else None,
        },
        "distributions": distributions,
        "bounds": {
            "speed_bound_rad_s": args.speed_bound,
            "angle_bound_rad": args.angle_bound,
            "latency_bound_s": args.latency_bound,
            "position_bound_electrical_rad": getattr(args, "position_bound", None),
        },
    }


def check_verdict(agg, min_success):
    """Reasons why --check fails (empty list: it passes)."""
    reasons = []
    n = agg["cases"]
    if n == 0:
        return ["no case was run"]
    if agg["success_rate"] < min_success:
        reasons.append(f"success rate {agg['success_rate']:.4f} < {min_success:g}")
    if agg["counts"]["silent"]:
        reasons.append(f"{agg['counts']['silent']} silent failure(s)")
    if agg["counts"]["crashed"]:
        reasons.append(f"{agg['counts']['crashed']} crashed case(s)")
    if agg["nonfinite_cases"]:
        reasons.append(f"{agg['nonfinite_cases']} case(s) with a non-finite value")
    return reasons


def fmt(value, spec=".3g"):
    """A number for the report ("-" for None)."""
    return "-" if value is None else format(value, spec)


def make_plots(out_dir, records, args):
    """Histograms (PNG) into out_dir; returns [(title, file name)]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    def values(name, past_settle_only):
        return [
            r["metrics"][name]
            for r in records
            if r["metrics"].get(name) is not None and (r["metrics"]["past_settle"] or not past_settle_only)
        ]

    plots = []

    def histogram(data, title, xlabel, file_name, bound=None):
        fig, ax = plt.subplots(figsize=(7, 4))
        note = ""
        if bound is not None and spans_decades(data):
            positive = [v for v in data if v > 0]
            zeros = len(data) - len(positive)
            lo, hi = min(positive), max(max(positive), bound)
            ax.hist(positive, bins=np.geomspace(lo, hi * 1.0001, 40), color="tab:blue")
            ax.set_xscale("log")
            if zeros:
                note = f" ({zeros} case{'s' if zeros != 1 else ''} at 0 not shown)"
        else:
            ax.hist(data, bins=40, color="tab:blue")
        if bound is not None:
            ax.axvline(bound, color="tab:red", linestyle="--", label=f"bound {bound:g}")
            ax.legend()
        ax.set_xlabel(xlabel)
        ax.set_ylabel("cases")
        ax.set_title(
            f"{title}, {len(data)} cases{note}"
            + ("\n(cases not stopped by a fault before settling)" if bound is not None else ""),
            fontsize=10,
        )
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, file_name), dpi=110)
        plt.close(fig)
        plots.append((title, file_name))

    for name, title, xlabel, file_name, bound in (
        (
            "max_speed_error_rad_s",
            "Max speed error after settling",
            "max |w - w*| (rad/s)",
            "hist_speed_error.png",
            args.speed_bound,
        ),
        (
            "max_angle_error_rad",
            "Max angle-estimate error after settling",
            "max |angle error| (rad)",
            "hist_angle_error.png",
            args.angle_bound,
        ),
        (
            "r_rel_error",
            "Commissioned R relative error",
            "R_commissioned / R_plant - 1",
            "hist_commissioning_r.png",
            None,
        ),
        (
            "l_rel_error",
            "Commissioned L relative error",
            "L_commissioned / L_plant - 1",
            "hist_commissioning_l.png",
            None,
        ),
    ):
        data = values(name, past_settle_only=bound is not None)
        if data:
            histogram(data, title, xlabel, file_name, bound)
    return plots


def write_report(path, records, agg, args, scenario, version, plots, started_utc):
    """DIR/report.md."""
    n = agg["cases"]
    counts = agg["counts"]
    low, high = agg["success_rate_wilson95"]
    lines = ["# Monte Carlo robustness report", ""]
    lines += [
        f"- command: `{shlex.join(args.argv)}`",
        f"- scenario: `{args.scenario}` (name `{scenario.get('scenario.name', '?')}`)",
        f"- cases: {n}, base seed {args.seed} (case k has seed {args.seed} * {SEED_STRIDE} + k)",
        f"- date: {started_utc}",
    ]
    preset = agg.get("preset")
    if preset:
        designed = "designed by" if preset["designed"] else "the scenario as given; top speed from"
        load_step = " 30 ms into RUN" if preset["designed"] else " (the scenario's)"
        lines.append(
            f"- motor preset: `{preset['preset_file']}`, {designed} `{shlex.join(preset['tune_command'])}`: "
            f"top speed {preset['top_speed_rad_s']:g} rad/s, profile peak {preset['peak_speed_rad_s']:g} rad/s, "
            f"load step {preset['load_Nm']:.4g} N m{load_step} (distributions scaled to the motor: "
            "tools/mc_preset.py)"
        )
    if version:
        lines.append(f"- pmstep-sil: {version}")
    if args.duration is not None:
        lines.append(f"- duration: {args.duration:g} s per case (`--set {DURATION_KEY}`)")
    lines.append(
        f"- bounds: max speed error < {args.speed_bound:g} rad/s, max angle error < {args.angle_bound:g} rad "
        f"(after settling), fault within {args.latency_bound:g} s of a loss of control"
    )
    if getattr(args, "position_bound", None) is not None:
        lines.append(
            f"- position: every move issued, finished and ending within {args.position_bound:g} electrical "
            f"rad of its target"
        )
    lines.append("")
    rate = agg["success_rate"]
    lines += [
        "## Result",
        "",
        f"**Success rate: {counts['success']}/{n} = {fmt(100 * rate if rate is not None else None, '.1f')} %** "
        f"(Wilson 95 % interval {100 * low:.1f} % to {100 * high:.1f} %)",
        "",
        "| class | cases |",
        "|---|---|",
    ]
    for cls in CLASSES:
        lines.append(f"| {CLASS_TEXT[cls]} | {counts[cls]} |")
    lines += [
        f"| of which detected losses of control | {agg['detected_losses']} |",
        f"| of which false trips (fault, no loss of control) | {agg['false_trips']} |",
        "",
        f"Cases that saw a non-finite value (NaN/Inf): {agg['nonfinite_cases']}",
        "",
    ]
    lat = agg["detection_latency_s"]
    if lat["n"]:
        lines += [
            f"Detection latency over the {lat['n']} detected losses of control: "
            f"max {lat['max'] * 1e3:.3g} ms, median {lat['median'] * 1e3:.3g} ms",
            "",
        ]
    else:
        lines += ["Detection latency: no detected loss of control.", ""]
    if agg["faults_by_name"]:
        lines += ["Faults latched, by name:", "", "| fault | cases |", "|---|---|"]
        lines += [f"| {name} | {count} |" for name, count in agg["faults_by_name"].items()]
        lines.append("")
    else:
        lines += ["No fault latched in any case.", ""]

    by_segment = agg.get("failures_by_segment") or []
    if by_segment:
        classes = list(by_segment[0][1])
        lines += [
            "Failures by the speed profile's segment at their failure time (the loss of control; a false "
            "trip's fault; out of spec: the largest angle error's sample, or the speed error's where only "
            "that bound was exceeded):",
            "",
            "| segment | " + " | ".join(classes) + " |",
            "|---|" + "---|" * len(classes),
        ]
        lines += [
            "| " + segment + " | " + " | ".join(str(row[cls]) for cls in classes) + " |" for segment, row in by_segment
        ]
        lines.append("")
    lines += [
        "## Distributions",
        "",
        "Over the cases that produced the value: the errors after settling over the cases not stopped by "
        "a fault before settling, the commissioning errors where the core measured, a position "
        "scenario's moves and hold on the true position.",
        "",
        "| quantity | n | p50 | p90 | p99 | max |",
        "|---|---|---|---|---|---|",
    ]
    titles = (
        ("max_speed_error_rad_s", "max speed error after settling (rad/s)"),
        ("max_angle_error_rad", "max angle error after settling (rad)"),
        ("commissioning_abs_r_rel_error", "\\|R commissioned / R plant - 1\\|"),
        ("commissioning_abs_l_rel_error", "\\|L commissioned / L plant - 1\\|"),
        ("commissioning_abs_k_rel_error", "\\|k_M commissioned / k_M plant - 1\\|"),
        ("commissioning_abs_offset_a_error_A", "\\|offset a commissioned - true\\| (A)"),
        ("commissioning_abs_offset_b_error_A", "\\|offset b commissioned - true\\| (A)"),
        ("commissioning_abs_rest_angle_error_rad", "\\|rotor's rest at t_c commissioned - true\\| (electrical rad)"),
    )
    titles += tuple(
        (name, title) for name, title in zip(POSITION_METRICS, POSITION_TITLES) if agg["distributions"][name]["n"]
    )  # a position scenario's
    for name, title in titles:
        d = agg["distributions"][name]
        lines.append(f"| {title} | {d['n']} | {fmt(d['p50'])} | {fmt(d['p90'])} | {fmt(d['p99'])} | {fmt(d['max'])} |")
    bias = [
        (label, agg["distributions"][f"commissioning_abs_{name}"]["mean_signed"])
        for label, name in (("R", "r_rel_error"), ("L", "l_rel_error"), ("k_M", "k_rel_error"))
    ]
    if any(v is not None for _l, v in bias):
        lines += ["", "Mean signed commissioning error: " + ", ".join(f"{label} {fmt(v, '+.3g')}" for label, v in bias)]
    lines.append("")
    for title, file_name in plots:
        lines += [f"![{title}]({file_name})", ""]

    worst = worst_order(records)[:WORST_CASES]
    lines += [
        f"## The {len(worst)} worst cases",
        "",
        "Failures first, then by max speed error after settling. Re-run one with the command in the "
        "last column (from the same working folder); it writes the CSV too, for `tools/plot_run.py`.",
        "",
    ]
    header = ["seed", "class", "fault", "max speed err (rad/s)", "max angle err (rad)"]
    header += [title for _k, title, _f in KEY_PARAMETERS] + ["re-run"]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in worst:
        m = r["metrics"]
        cells = [
            str(r["seed"]),
            r["class"] + (" (false trip)" if r["false_trip"] else ""),
            r["fault_name"] or "-",
            fmt(m.get("max_speed_error_rad_s")),
            fmt(m.get("max_angle_error_rad")),
        ]
        for key, _title, as_factor in KEY_PARAMETERS:
            value = r["params"].get(key)
            if value is None:
                cells.append("-")
            elif as_factor:
                cells.append(f"{value / float(scenario[key]):.3f}" if float(scenario[key]) else fmt(value))
            elif key == "inverter.dead_time_s":
                cells.append(f"{value * 1e6:.3f}")
            else:
                cells.append(f"{value:.4g}")
        cells.append(f"`{shlex.join(rerun_command(args, r['seed']))}`")
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    if worst:
        lines += ["The same cases as raw pmstep-sil commands (what the tool ran):", ""]
    for r in worst:
        lines += [
            f"Case {r['seed']} ({r['class']}){': ' + r['reason'] if r['reason'] else ''}",
            "",
            "```sh",
            shlex.join(r["command"]),
            "```",
        ]
        if r["stderr_tail"].strip():
            lines += ["", "stderr (tail):", "", "```", r["stderr_tail"].rstrip(), "```"]
        lines.append("")

    lines += [
        "## Distribution table",
        "",
        "Drawn per case by `random.Random(case seed)`, one draw per row in this order "
        "(`DISTRIBUTIONS` in tools/mc_distributions.py); U[a, b] excludes b.",
        "",
        "| key | drawn as | scenario file's value | range |",
        "|---|---|---|---|",
    ]
    lines += [f"| `{key}` | {law} | {value} | {span} |" for key, law, value, span in distribution_rows(scenario)]
    lines += ["", f"Every case also sets `{SEED_KEY}` to its case seed (the SIL's noise).", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


# ---- the campaign's section of a page of campaigns (--report FILE --report-section NAME) ----
PAGE_TITLE = "Monte Carlo campaigns"
PAGE_WHAT = (
    "One section per campaign of tools/monte_carlo.py (each with the command that reruns it): random "
    "plants, sensors, inverters, buses, initial angles and loads drawn per case from its seed. A case is a "
    "success with no fault, no non-finite value and, after settling, the speed and angle errors within the "
    "bounds; *detected*: a fault latched (within the latency bound of a loss of control, or a false trip "
    "without one); *silent*: a loss of control with no fault in time; *out of spec*: a bound exceeded "
    "without a loss of control or a fault; *crashed*: pmstep-sil failed. The campaign's own report.md "
    "(histograms, worst cases, distribution table) is in its --out folder."
)
REPORT_OPTIONS = ("--report", "--report-section")


def campaign_command(argv, case=None):
    """@p argv without the --report options (and, with @p case, that case's --case instead of
    --cases): the command that reruns the campaign, or one case of it."""
    out, skip = [], False
    for a in argv:
        if skip:
            skip = False
            continue
        name = a.split("=", 1)[0]
        if name in REPORT_OPTIONS or (case is not None and name == "--cases"):
            skip = "=" not in a
            continue
        out.append(a)
    return out + (["--case", str(case)] if case is not None else [])


def campaign_section(name, records, agg, args, argv):
    """The section @p name of the page of campaigns: the summary of the campaign (@p records, @p agg
    as main() builds them, @p args its options) and the command @p argv that reruns it."""
    n = agg["cases"]
    counts = agg["counts"]
    low, high = agg["success_rate_wilson95"]
    preset = agg.get("preset")
    subject = f"preset `{preset['preset']}`" if preset else f"`{report.command([args.scenario])}`"
    lines = [
        report.section_header(
            f"{name}: {subject}, {n} cases, seed {args.seed}", "tools/monte_carlo.py", campaign_command(argv)
        )
    ]
    what = [f"Scenario `{report.command([args.scenario])}`"]
    if preset:
        what.append(
            f"designed for `{report.command([preset['preset_file']])}` "
            f"(top speed {preset['top_speed_rad_s']:g} rad/s, profile peak {preset['peak_speed_rad_s']:g} "
            f"rad/s, load step {preset['load_Nm']:.4g} N m)"
            if preset["designed"]
            else f"with the distributions of `{report.command([preset['preset_file']])}`"
        )
    bounds = (
        f"bounds: |w - w*| < {args.speed_bound:.4g} rad/s and angle error < {args.angle_bound:g} rad after "
        f"settling, a fault within {args.latency_bound:g} s of a loss of control"
    )
    if getattr(args, "position_bound", None) is not None:
        bounds += f", every move ending within {args.position_bound:g} electrical rad of its target"
    what.append(bounds)
    if args.duration is not None:
        what.append(f"{args.duration:g} s per case")
    if agg.get("pmstep_sil_version"):
        what.append(f"pmstep-sil {agg['pmstep_sil_version']}")
    ex = agg.get("execution") or {}
    if ex.get("wall_s") is not None:
        what.append(
            f"{ex.get('cases_run')} cases run ({ex.get('cases_resumed')} resumed) in {ex['wall_s']:.0f} s "
            f"({ex.get('engine')}, {ex.get('workers')} workers)"
        )
    lines += ["; ".join(what) + ".", ""]
    rate = agg["success_rate"]
    faults = ", ".join(f"{fault} {count}" for fault, count in agg["faults_by_name"].items()) or "none"
    lat = agg["detection_latency_s"]
    speed = agg["distributions"]["max_speed_error_rad_s"]
    angle = agg["distributions"]["max_angle_error_rad"]
    lines += [
        "| | |",
        "|---|---|",
        f"| success | **{counts['success']} / {n}** = {fmt(100 * rate if rate is not None else None, '.1f')} % "
        f"(Wilson 95 %: {100 * low:.1f}–{100 * high:.1f} %) |",
        f"| silent failures | **{counts['silent']}** |",
        f"| detected (of which false trips) | {counts['detected']} ({agg['false_trips']}) |",
        f"| out of spec | {counts['out_of_spec']} |",
        f"| crashed | {counts['crashed']} |",
        f"| cases with a non-finite value | {agg['nonfinite_cases']} |",
        f"| faults latched | {faults} |",
        "| detection latency, max / median | "
        + (f"{lat['max'] * 1e3:.3g} / {lat['median'] * 1e3:.3g} ms |" if lat["n"] else "no detected loss of control |"),
        f"| max \\|w - w*\\| after settling, p50 / p90 / p99 / max (rad/s) | {fmt(speed['p50'])} / "
        f"{fmt(speed['p90'])} / {fmt(speed['p99'])} / {fmt(speed['max'])} |",
        f"| max angle error after settling, p50 / p90 / p99 / max (rad) | {fmt(angle['p50'])} / "
        f"{fmt(angle['p90'])} / {fmt(angle['p99'])} / {fmt(angle['max'])} |",
    ]
    by_segment = agg.get("failures_by_segment") or []
    if by_segment:
        classes = list(by_segment[0][1])
        lines += [
            "",
            "Failures by the speed profile's segment at their failure time:",
            "",
            "| segment | " + " | ".join(classes) + " |",
            "|---|" + "---|" * len(classes),
        ]
        lines += [
            "| " + segment + " | " + " | ".join(str(row[cls]) for cls in classes) + " |" for segment, row in by_segment
        ]
    failed = [r for r in worst_order(records) if r["class"] != "success"]
    if failed:
        shown = failed[:WORST_CASES]
        lines += [
            "",
            f"Failed cases ({len(failed)}"
            + (f", the {len(shown)} worst" if len(failed) > len(shown) else "")
            + "): "
            + ", ".join(f"{r['seed']} ({r['class']}" + (", false trip" if r["false_trip"] else "") + ")" for r in shown)
            + ". Rerun one (with its CSV, for tools/plot_run.py): "
            f"`{report.command(campaign_command(argv, shown[0]['seed']))}`, another seed in place of "
            f"{shown[0]['seed']}.",
        ]
    return "\n".join(lines) + "\n"


# A position scenario's figures (electrical rad; none for a speed scenario).
POSITION_METRICS = (
    "position_max_final_error_rad",
    "position_max_tracking_error_rad",
    "position_hold_max_error_rad",
    "position_abs_hold_drift_rad_s",
)
POSITION_TITLES = (
    "largest final error of a move (electrical rad)",
    "largest \\|theta* - theta\\| in position mode (electrical rad)",
    "largest hold error (electrical rad)",
    "\\|hold drift\\| (electrical rad/s)",
)

CSV_METRICS = (
    "max_speed_error_rad_s",
    "max_angle_error_rad",
    "failure_time_s",
    "failure_segment",
    "settle_time_s",
    "loss_of_control_time_s",
    "detection_latency_s",
    "fault_time_s",
    "nonfinite_seen",
    "tracking_max_abs_error_rad_s",
    "commissioning_measured",
    "r_rel_error",
    "l_rel_error",
    "k_rel_error",
    "offset_a_error_A",
    "offset_b_error_A",
    "rest_angle_error_rad",
    "realignments",
    "final_mode",
    "past_settle",
    "wall_s",
) + POSITION_METRICS


def write_cases_csv(path, records):
    """DIR/cases.csv: one row per case."""
    keys = [row[0] for row in DISTRIBUTIONS]
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(
            ["seed", "class", "false_trip", "fault_name", "exit_status"] + keys + list(CSV_METRICS) + ["reason"]
        )
        for r in records:
            row = [
                r["seed"],
                r["class"],
                int(r["false_trip"]),
                r["fault_name"],
                "" if r["exit_status"] is None else r["exit_status"],
            ]
            row += [format_value(r["params"][k]) for k in keys]
            for name in CSV_METRICS:
                value = r["metrics"].get(name)
                if value is None:
                    row.append("")
                elif isinstance(value, bool):
                    row.append(int(value))
                elif isinstance(value, str):
                    row.append(value)
                else:
                    row.append(format_value(value))
            row.append(r["reason"])
            writer.writerow(row)
