"""Monte Carlo campaigns: where in the speed profile each failure happened.

A case that is not a success has a failure time (mc_outcome.classify): the loss of control for
a detected or silent failure, the fault for a false trip, and for an out-of-spec case the
sample of the largest angle error (or of the largest speed error, when only that bound was
exceeded). This module names the piece of the scenario's speed set-point profile (speed.points,
piecewise linear) that holds that time, so that a campaign's report can say which manoeuvre its
failures come from: commissioning (before the case's RUN started), a ramp, a constant speed,
standstill, or after the profile's last point. Position scenarios (position.points other than
"0:0") move by their own profile: their failures get no segment.
"""

COMMISSIONING = "commissioning"
AFTER_PROFILE = "after the profile"


def _number(text):
    value = float(text)
    return 0.0 if value == 0.0 else value  # no "-0"


def speed_points(scenario):
    """[(t_s, omega_rad_s)] of scenario["speed.points"] (scenario: {"section.key": text}); [] if it
    has none or is a position scenario. ValueError on a malformed point."""
    moves = scenario.get("position.points", "0:0").replace("\n", " ").replace(" ", "")
    if moves not in ("", "0:0"):
        return []
    points = []
    for item in scenario.get("speed.points", "").replace("\n", " ").split(","):
        if item.strip():
            t_text, value_text = item.split(":")
            points.append((_number(t_text), _number(value_text)))
    return points


def profile_segments(points):
    """[(t_start_s, t_end_s, label)] for consecutive points: "ramp a -> b rad/s" where the
    set-point changes, "at a rad/s" where it holds (a != 0), "standstill" where it holds at 0;
    each label ends with its time span, so that it names one segment."""
    segments = []
    for (t0, v0), (t1, v1) in zip(points, points[1:]):
        if t1 <= t0:
            continue
        if v0 != v1:
            label = f"ramp {v0:.4g} -> {v1:.4g} rad/s"
        elif v0 == 0.0:
            label = "standstill"
        else:
            label = f"at {v0:.4g} rad/s"
        segments.append((t0, t1, f"{label}, {t0:.3f}-{t1:.3f} s"))
    return segments


def segment_of(time_s, run_start_s, segments):
    """The label of the segment holding time_s; COMMISSIONING before run_start_s (when known),
    AFTER_PROFILE past the last segment; None without a time, without segments, or before the
    profile's first point."""
    if time_s is None or not segments:
        return None
    if run_start_s is not None and time_s < run_start_s:
        return COMMISSIONING
    for t0, t1, label in segments:
        if t0 <= time_s < t1:
            return label
    return AFTER_PROFILE if time_s >= segments[-1][1] else None


def label_failures(records, scenario):
    """Sets each record's metrics["failure_segment"] (None for a success, a crash or a position
    scenario) from its metrics["failure_time_s"] and the RUN start in its summary; returns the
    profile's segments."""
    segments = profile_segments(speed_points(scenario))
    for r in records:
        metrics = r["metrics"]
        if not metrics:
            continue
        summary = r.get("summary") if isinstance(r.get("summary"), dict) else {}
        run_start = (summary.get("robustness") or {}).get("run_start_time_s")
        run_start = run_start if isinstance(run_start, (int, float)) and not isinstance(run_start, bool) else None
        metrics["failure_segment"] = segment_of(metrics.get("failure_time_s"), run_start, segments)
    return segments


def failures_by_segment(records, classes, segments):
    """[[segment, {class: count}]] of the cases in @p classes that have a segment, in the
    profile's order (commissioning first, after the profile last)."""
    order = [COMMISSIONING] + [label for _, _, label in segments] + [AFTER_PROFILE]
    table = {}
    for r in records:
        segment = r["metrics"].get("failure_segment") if r["metrics"] else None
        if r["class"] in classes and segment is not None:
            table.setdefault(segment, {cls: 0 for cls in classes})[r["class"]] += 1
    return [[segment, table[segment]] for segment in order if segment in table]
