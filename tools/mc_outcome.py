"""Monte Carlo campaigns, part 2a: the outcome of one case. Its class against the bounds and
the numbers the report uses, from pmstep-sil's exit status and summary.json (see monte_carlo.py
for the whole tool)."""

import math
import signal

FAULT_EXIT_STATUS = 3  # pmstep-sil: the run finished and a fault is latched

CLASSES = ("success", "detected", "silent", "out_of_spec", "crashed")
CLASS_TEXT = {
    "success": "success",
    "detected": "detected (fault latched)",
    "silent": "silent failure (loss of control, no fault in time)",
    "out_of_spec": "out of spec (bound exceeded, no fault)",
    "crashed": "crashed (pmstep-sil failed or no summary)",
}

# Fields of summary.json that classification needs: (path, type check).
REQUIRED_FIELDS = (
    (("fault", "code"), "number"),
    (("fault", "time_s"), "number"),
    (("robustness", "loss_of_control_time_s"), "number"),
    (("robustness", "max_speed_error_rad_s"), "number_or_null"),
    (("robustness", "max_angle_error_rad"), "number_or_null"),
    (("robustness", "nonfinite_seen"), "bool"),
)


def get_path(summary, path):
    """summary[path[0]][path[1]]..., or KeyError naming the dotted path."""
    node = summary
    for part in path:
        if not isinstance(node, dict) or part not in node:
            raise KeyError(".".join(path))
        node = node[part]
    return node


def summary_problem(summary):
    """None if `summary` has every field classify() needs, else a text naming the first bad one."""
    if not isinstance(summary, dict):
        return "summary.json is not a JSON object"
    for path, kind in REQUIRED_FIELDS:
        name = ".".join(path)
        try:
            value = get_path(summary, path)
        except KeyError:
            return f"summary.json has no field {name} (pmstep-sil older than this tool?)"
        is_number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if kind == "number" and not is_number:
            return f"summary.json field {name} is {value!r}, not a number"
        if kind == "number_or_null" and not (is_number or value is None):
            return f"summary.json field {name} is {value!r}, not a number"
        if kind == "bool" and not isinstance(value, bool):
            return f"summary.json field {name} is {value!r}, not true/false"
    return None


def number_or_none(value):
    """A finite float, or None (JSON null, NaN, infinity, missing)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def fault_name(summary):
    """The latched fault's name ("" if none): fault.name, else fault.text, else the code."""
    fault = summary.get("fault", {})
    if not fault.get("code"):
        return ""
    return str(fault.get("name") or fault.get("text") or f"code {fault.get('code')}")


def classify(
    summary,
    exit_status,
    speed_bound_rad_s=0.5,
    angle_bound_rad=0.05,
    latency_bound_s=0.05,
    problem=None,
    position_bound_rad=None,
):
    """Class of one run: dict with "class", "false_trip", "latency_s", "reason".

    summary: the parsed summary.json (None if missing or unparsable); exit_status: the
    process's exit status (negative: killed by that signal; None: timed out); problem: a
    text that makes the run "crashed" whatever the summary says (e.g. a timeout);
    position_bound_rad: a position scenario's success also needs every move issued, finished and
    ending within this many electrical rad of its target (summary.json "position").
    """

    def result(cls, reason, false_trip=False, latency_s=None, failure_time_s=None):
        return {
            "class": cls,
            "false_trip": false_trip,
            "latency_s": latency_s,
            "reason": reason,
            "failure_time_s": failure_time_s,
        }

    if problem:
        return result("crashed", problem)
    if exit_status is None:
        return result("crashed", "timed out")
    if exit_status < 0:
        try:
            name = signal.Signals(-exit_status).name
        except ValueError:
            name = f"signal {-exit_status}"
        return result("crashed", f"pmstep-sil killed by {name}")
    if exit_status not in (0, FAULT_EXIT_STATUS):
        return result("crashed", f"pmstep-sil exited with status {exit_status}")
    if summary is None:
        return result("crashed", "no readable summary.json")
    bad = summary_problem(summary)
    if bad:
        return result("crashed", bad)

    fault_code = summary["fault"]["code"]
    if (fault_code != 0) != (exit_status == FAULT_EXIT_STATUS):
        return result("crashed", f"exit status {exit_status} disagrees with fault code {fault_code}")
    rob = summary["robustness"]
    loss_time_s = rob["loss_of_control_time_s"]
    lost = loss_time_s >= 0.0

    if fault_code != 0:
        if not lost:
            return result(
                "detected",
                f"false trip: {fault_name(summary)} without loss of control",
                false_trip=True,
                failure_time_s=summary["fault"]["time_s"],
            )
        latency_s = number_or_none(rob.get("detection_latency_s"))
        if latency_s is None:
            latency_s = summary["fault"]["time_s"] - loss_time_s
        if latency_s > latency_bound_s:
            return result(
                "silent",
                f"loss of control at {loss_time_s:.6g} s, {fault_name(summary)} "
                f"only {latency_s:.3g} s later (> {latency_bound_s:g} s)",
                latency_s=latency_s,
                failure_time_s=loss_time_s,
            )
        return result(
            "detected",
            f"loss of control at {loss_time_s:.6g} s caught by {fault_name(summary)} after {latency_s:.3g} s",
            latency_s=latency_s,
            failure_time_s=loss_time_s,
        )
    if lost:
        realignments = number_or_none((summary.get("commissioning") or {}).get("realignments"))
        note = f" ({realignments:g} re-alignment(s))" if realignments else ""
        return result(
            "silent", f"loss of control at {loss_time_s:.6g} s, no fault latched{note}", failure_time_s=loss_time_s
        )

    speed_error = number_or_none(rob["max_speed_error_rad_s"])
    angle_error = number_or_none(rob["max_angle_error_rad"])
    exceeded = []
    failure_time_s = None  # where the exceeded maximum was (the angle's first; the SIL's older summaries have none)
    if rob["nonfinite_seen"]:
        exceeded.append("non-finite value seen")
    if speed_error is None or speed_error >= speed_bound_rad_s:
        exceeded.append(f"max speed error {rob['max_speed_error_rad_s']} rad/s >= {speed_bound_rad_s:g}")
        failure_time_s = number_or_none(rob.get("max_speed_error_time_s"))
    if angle_error is None or angle_error >= angle_bound_rad:
        exceeded.append(f"max angle error {rob['max_angle_error_rad']} rad >= {angle_bound_rad:g}")
        failure_time_s = number_or_none(rob.get("max_angle_error_time_s"))
    if position_bound_rad is not None:
        exceeded += position_exceeded(summary.get("position"), position_bound_rad)
    if exceeded:
        return result(
            "out_of_spec",
            "; ".join(exceeded),
            failure_time_s=failure_time_s if failure_time_s is None or failure_time_s >= 0.0 else None,
        )
    return result("success", "")


def position_exceeded(position, bound_rad):
    """What a position scenario's summary misses of "every move ends within bound_rad" (empty: nothing)."""
    if not isinstance(position, dict):
        return ["no position figures in summary.json (not a position scenario?)"]
    problems = []
    for key in ("rejected_moves", "unfinished_moves"):
        if number_or_none(position.get(key)) != 0:
            problems.append(f"{position.get(key)} {key.replace('_', ' ')}")
    final = number_or_none(position.get("max_final_error_electrical_rad"))
    if final is None or final >= bound_rad:
        problems.append(
            f"move {position.get('worst_move')} ends {position.get('max_final_error_electrical_rad')} "
            f"electrical rad off >= {bound_rad:g}"
        )
    return problems


def extract_metrics(summary, params, base):
    """Numbers of one run for the tables and cases.csv (None where not available)."""
    if not isinstance(summary, dict):
        return {}
    rob = summary.get("robustness") or {}
    com = summary.get("commissioning") or {}
    fault = summary.get("fault") or {}
    metrics = {
        "max_speed_error_rad_s": number_or_none(rob.get("max_speed_error_rad_s")),
        "max_angle_error_rad": number_or_none(rob.get("max_angle_error_rad")),
        "settle_time_s": number_or_none(rob.get("settle_time_s")),
        "loss_of_control_time_s": number_or_none(rob.get("loss_of_control_time_s")),
        "detection_latency_s": number_or_none(rob.get("detection_latency_s")),
        "nonfinite_seen": bool(rob.get("nonfinite_seen", False)),
        "tracking_max_abs_error_rad_s": number_or_none(
            (summary.get("speed") or {}).get("tracking_max_abs_error_rad_s")
        ),
        "fault_time_s": number_or_none(fault.get("time_s")),
        "wall_s": number_or_none((summary.get("timing") or {}).get("wall_s")),
        "cpu_s": number_or_none((summary.get("timing") or {}).get("cpu_s")),
        "firmware_wall_s": number_or_none((summary.get("timing") or {}).get("firmware_wall_s")),
        "plant_wall_s": number_or_none((summary.get("timing") or {}).get("plant_wall_s")),
        "commissioning_measured": bool(com.get("measured", False)),
        "realignments": number_or_none(com.get("realignments")),
        "final_mode": str(summary.get("final_mode", "")),
    }
    # A position scenario (issue 13): its moves and hold, electrical rad, on the true position.
    pos = summary.get("position") if isinstance(summary.get("position"), dict) else {}
    moved = (number_or_none(pos.get("moves")) or 0) > 0
    held = moved and (number_or_none(pos.get("hold_duration_s")) or 0.0) > 0.0
    drift = number_or_none(pos.get("hold_drift_electrical_rad_s")) if held else None
    metrics["position_max_final_error_rad"] = (
        number_or_none(pos.get("max_final_error_electrical_rad")) if moved else None
    )
    metrics["position_max_tracking_error_rad"] = (
        number_or_none(pos.get("max_tracking_error_electrical_rad")) if moved else None
    )
    metrics["position_hold_max_error_rad"] = number_or_none(pos.get("hold_max_error_electrical_rad")) if held else None
    metrics["position_abs_hold_drift_rad_s"] = abs(drift) if drift is not None else None
    # The "after settling" maxima mean nothing when a fault stopped the run before settling.
    settle_s, fault_s = metrics["settle_time_s"], metrics["fault_time_s"]
    metrics["past_settle"] = not (
        fault.get("code") and settle_s is not None and fault_s is not None and 0.0 <= fault_s < settle_s
    )
    # Commissioned value against the plant's (drawn, else the scenario's) value.
    for name, key, field in (
        ("r_rel_error", "motor.resistance_Ohm", "resistance_Ohm"),
        ("l_rel_error", "motor.inductance_H", "inductance_H"),
        ("k_rel_error", "motor.torque_constant_Nm_A", "torque_constant_Nm_A"),
    ):
        plant = params.get(key, base.get(key))
        measured = number_or_none(com.get(field))
        ok = metrics["commissioning_measured"] and measured is not None and plant
        metrics[name] = measured / plant - 1.0 if ok else None
    for name, key, field in (
        ("offset_a_error_A", "sensors.offset_a_A", "offset_a_A"),
        ("offset_b_error_A", "sensors.offset_b_A", "offset_b_A"),
    ):
        measured = number_or_none(com.get(field))
        ok = metrics["commissioning_measured"] and measured is not None and key in params
        metrics[name] = measured - params[key] if ok else None
    # Where commissioning put the rotor at t_c (its start angle) against where the plant's rotor was.
    align = summary.get("alignment") if isinstance(summary.get("alignment"), dict) else {}
    rest = [
        number_or_none(v)
        for v in (
            com.get("equilibrium_cos"),
            com.get("equilibrium_sin"),
            align.get("cos_ptheta_at_tc"),
            align.get("sin_ptheta_at_tc"),
        )
    ]
    ok = metrics["commissioning_measured"] and all(v is not None for v in rest)
    metrics["rest_angle_error_rad"] = (
        math.atan2(rest[1] * rest[2] - rest[0] * rest[3], rest[0] * rest[2] + rest[1] * rest[3]) if ok else None
    )
    return metrics
