"""Monte Carlo campaigns on a motor preset (monte_carlo.py --preset): the campaign's scenario
designed for the preset, and a distribution table scaled to the motor.

The distribution table of mc_distributions.py is the paper motor's: its friction (up to
0.005 N m s), load (2 N m), bus ripple (2 V) and source resistance (0.2 Ohm) are absolute
values that mean nothing for a NEMA 17. For a preset (sil/scenarios/motors/*.ini):

- the scenario is pmstep-tune's design of the preset in robust mode behind the realistic
  chain (sil/scenarios/robust.ini's: 12-bit ADC with a span of 3 x the rated current, +-20 mA
  offsets, 5 mA noise, 1 us dead time, one period of delay, switching inverter), with the
  designer's validation profile (ramps to +-80 % and +-5 % of the top speed) and a load step
  30 ms after the start of RUN (the offset calibration and both alignments), as in the paper;
- the plant's R, L, k_M are drawn x U[0.9, 1.1] and J x U[0.8, 1.2] of the preset's values;
- what the paper table gives in absolute units is carried over as the same fraction of the
  motor's own figure: the load as a fraction of the holding torque (2 N m of the paper
  motor's 22.6 N m, 8.8 %), x U[0, 1]; the friction up to twice the preset's assumed value
  or, if more, up to the paper table's friction torque at the profile's peak speed as a
  fraction of the holding torque; the ripple as a fraction of the bus voltage (2 V of 48 V);
  the source resistance as a fraction of the winding resistance (0.2 Ohm of 3 Ohm);
- the measurement chain's rows (offsets, gain errors, noise, dead time and the firmware's
  programmed dead time) and the initial angle are the paper table's, unchanged;
- with --phase-voltage-sensing, the drive also senses each phase's mean voltage per period
  (PHASE_VOLTAGE_SENSING) and the cases draw that sensor's offsets, gain errors and noise
  (PHASE_VOLTAGE_DISTRIBUTIONS, after the other rows: the same seed draws the same case
  otherwise, a paired comparison with the campaign without it).

The speed thresholds scale with the top speed the designer gives (rated current at 90 % of
the bus): the paper campaign's are 0.5 rad/s (success) and 2 rad/s (loss of control) on the
paper motor, whose top speed is 9.6 rad/s, so a preset's are the same fractions of its own top
speed (5.2 % and 21 %); --speed-bound overrides the first. The angle bounds (0.05 rad for
success, 0.5 rad for a loss of control) are electrical angles and stay as they are.
"""

import configparser
import os
import re
import subprocess

from mc_distributions import DISTRIBUTIONS, ToolError
from scenario_keys import KEYS

HERE = os.path.dirname(os.path.abspath(__file__))
PAPER_PRESET = os.path.join(os.path.dirname(HERE), "sil", "scenarios", "motors", "paper.ini")

# The paper table's absolute values and the paper motor's figures they are relative to.
PAPER_LOAD_NM = 2.0
PAPER_FRICTION_MAX_NMS = 0.005
PAPER_PEAK_SPEED_RAD_S = 10.0  # robust.ini's profile: +-10 rad/s
PAPER_RIPPLE_MAX_V = 2.0
PAPER_BUS_V = 48.0
PAPER_SOURCE_RESISTANCE_MAX_OHM = 0.2
PAPER_RESISTANCE_OHM = 3.0

# sil/scenarios/robust.ini's measurement chain, as tools/envelope.py gives it to pmstep-tune
# (the ADC span follows the motor: 3 x the rated current).
REALISTIC_CHAIN = (
    "sensors.adc_bits=12",
    "sensors.offset_a_A=0.02",
    "sensors.offset_b_A=-0.02",
    "sensors.noise_rms_A=0.005",
    "inverter.model=switching",
    "inverter.dead_time_s=1e-6",
    "run.delay_periods=1",
)
ADC_SPAN_RATED = 3.0
# A drive that senses each phase's mean voltage over every period (the paper's premise: stator
# voltages measured; controller.inverter.phase_voltage_sensing): the realistic chain plus that
# sensor, 14 bits over +-1.5 x the bus (4.4 mV on a 24 V bus: a capture timer at 170 MHz times the
# bridge's edges to 5.9 ns, 2.8 mV of a 24 V, 50 us period), with offsets of +-50 mV (the
# firmware's offset calibration takes them off), gain errors of +-0.5 % (divider and bus
# measurement) and 5 mV rms of noise.
PHASE_VOLTAGE_SPAN_BUS = 1.5
PHASE_VOLTAGE_SENSING = (
    f"{KEYS['phase_voltage_sensing']}=true",
    f"{KEYS['phase_voltage_bits']}=14",
    f"{KEYS['phase_voltage_offset_a']}=0.05",
    f"{KEYS['phase_voltage_offset_b']}=-0.05",
    f"{KEYS['phase_voltage_gain_error_a']}=0.005",
    f"{KEYS['phase_voltage_gain_error_b']}=-0.005",
    f"{KEYS['phase_voltage_noise']}=0.005",
)
# The Monte Carlo draws that sensor's errors too; the rows follow DISTRIBUTIONS' rows, so a case
# draws the same plant, current sensors, inverter and load as with the realistic chain (paired).
PHASE_VOLTAGE_DISTRIBUTIONS = [
    (KEYS["phase_voltage_offset_a"], "uniform", -0.05, 0.05),
    (KEYS["phase_voltage_offset_b"], "uniform", -0.05, 0.05),
    (KEYS["phase_voltage_gain_error_a"], "uniform", -0.005, 0.005),
    (KEYS["phase_voltage_gain_error_b"], "uniform", -0.005, 0.005),
    (KEYS["phase_voltage_noise"], "uniform", 0.0025, 0.0075),
]
LOAD_STEP_AFTER_RUN_S = 0.03  # robust.ini's: 30 ms after RUN starts (0.68 s)
PAPER_SPEED_BOUND_RAD_S = 0.5  # the paper campaign's success bound (monte_carlo.py --speed-bound)
PAPER_LOSS_SPEED_RAD_S = 2.0  # robust.ini's run.loss_speed_error_rad_s


def _ini(path):
    parser = configparser.ConfigParser(inline_comment_prefixes=(";",), interpolation=None, strict=False)
    parser.optionxform = str
    if not parser.read(path):
        raise ToolError(f"motor preset {path} not found or unreadable")
    return parser


def read_preset(path):
    """The figures of a motor preset a campaign scales to: {"name", "rated_current_A",
    "holding_torque_Nm", "resistance_Ohm", "friction_Nms_rad", "bus_voltage_V"}; ToolError if
    one is missing or not a positive number (the friction may be 0)."""
    ini = _ini(path)
    wanted = (
        ("datasheet", "rated_current_A"),
        ("datasheet", "holding_torque_Nm"),
        ("motor", "resistance_Ohm"),
        ("motor", "friction_Nms_rad"),
        ("run", "bus_voltage_V"),
    )
    figures = {"name": ini.get("scenario", "name", fallback=os.path.splitext(os.path.basename(path))[0])}
    for section, key in wanted:
        try:
            value = float(ini.get(section, key))
        except (configparser.Error, ValueError):
            raise ToolError(f"motor preset {path}: [{section}] {key} missing or not a number") from None
        if not (value >= 0.0 if key == "friction_Nms_rad" else value > 0.0) or value == float("inf"):
            raise ToolError(f"motor preset {path}: [{section}] {key} = {value:g} is out of range")
        figures[key] = value
    return figures


def paper_holding_torque():
    return read_preset(PAPER_PRESET)["holding_torque_Nm"]


def chain_sets(preset, phase_voltage_sensing=False):
    """pmstep-tune/pmstep-sil --set items of the realistic chain for @p preset (the ADC span sized
    to its rated current), with the phase-voltage sensor when @p phase_voltage_sensing."""
    sets = list(REALISTIC_CHAIN) + [f"sensors.current_full_scale_A={ADC_SPAN_RATED * preset['rated_current_A']:g}"]
    if phase_voltage_sensing:
        sets += list(PHASE_VOLTAGE_SENSING) + [
            f"{KEYS['phase_voltage_span']}={PHASE_VOLTAGE_SPAN_BUS * preset['bus_voltage_V']:g}"
        ]
    return sets


def preset_distributions(preset, peak_speed_rad_s, paper_holding_Nm, phase_voltage_sensing=False):
    """The distribution table for a preset (the rows, keys and order of DISTRIBUTIONS, so a
    case draws as many numbers in the same order, then PHASE_VOLTAGE_DISTRIBUTIONS' with
    @p phase_voltage_sensing); see the module docstring."""
    if not peak_speed_rad_s > 0.0:
        raise ToolError(f"the preset's profile peak speed {peak_speed_rad_s:g} rad/s is not positive")
    torque_ratio = preset["holding_torque_Nm"] / paper_holding_Nm
    friction_max = max(
        2.0 * preset["friction_Nms_rad"],
        PAPER_FRICTION_MAX_NMS * PAPER_PEAK_SPEED_RAD_S * torque_ratio / peak_speed_rad_s,
    )
    replace = {
        KEYS["plant_resistance"]: ("scale", 0.9, 1.1),
        KEYS["plant_inductance"]: ("scale", 0.9, 1.1),
        KEYS["plant_torque_constant"]: ("scale", 0.9, 1.1),
        KEYS["plant_inertia"]: ("scale", 0.8, 1.2),
        KEYS["plant_friction"]: ("uniform", 0.0, friction_max),
        KEYS["bus_ripple"]: ("uniform", 0.0, PAPER_RIPPLE_MAX_V * preset["bus_voltage_V"] / PAPER_BUS_V),
        KEYS["bus_source_resistance"]: (
            "uniform",
            0.0,
            PAPER_SOURCE_RESISTANCE_MAX_OHM * preset["resistance_Ohm"] / PAPER_RESISTANCE_OHM,
        ),
        KEYS["load_torque"]: ("scale", 0.0, 1.0),  # of the scenario's load: PAPER_LOAD_NM x torque_ratio
    }
    table = [(key,) + replace[key] if key in replace else (key, kind, a, b) for key, kind, a, b in DISTRIBUTIONS]
    return table + (PHASE_VOLTAGE_DISTRIBUTIONS if phase_voltage_sensing else [])


def _design(tune, preset_path, chain_sets, low_speed_drive=False):
    cmd = [tune, "--motor", preset_path, "--robust"] + (["--low-speed-drive"] if low_speed_drive else [])
    for item in chain_sets:
        cmd += ["--set", item]
    return cmd


def tune_top_speed(output, weakened=False):
    """The top speed (rad/s) pmstep-tune printed in @p output: the design's ("top speed: ", i_d = 0), or
    with @p weakened the field-weakened one ("top speed with it"); ToolError when it printed none."""
    pattern = r"top speed with it ([0-9.eE+-]+) rad/s" if weakened else r"top speed: ([0-9.eE+-]+) rad/s"
    top = re.search(pattern, output)
    if top is None:
        raise ToolError(f"pmstep-tune printed no {'field-weakened ' if weakened else ''}top speed:\n{output}")
    return float(top.group(1))


def _run_designer(cmd):
    """Runs pmstep-tune; returns what it printed."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise ToolError(f"cannot run {cmd[0]}: {e}") from None
    if proc.returncode != 0:
        raise ToolError(f"{' '.join(cmd)} failed (status {proc.returncode}):\n{proc.stderr.strip()}")
    return proc.stdout


def _points_lines(points):
    """speed.points as an INI value on continuation lines of three points: a point printed at full
    precision takes up to 49 characters, and the scenario reader takes lines of 197 at most."""
    rows = [", ".join(points[i : i + 3]) for i in range(0, len(points), 3)]
    return ",\n    ".join(rows)


def paper_top_speed(tune, weakened=False):
    """The paper motor's top speed (rad/s; pmstep-tune --robust behind its realistic chain), which
    the paper campaign's speed thresholds are relative to (@p weakened: its field-weakened one)."""
    paper_span = ADC_SPAN_RATED * read_preset(PAPER_PRESET)["rated_current_A"]
    paper_chain = list(REALISTIC_CHAIN) + [f"sensors.current_full_scale_A={paper_span:g}"]
    return tune_top_speed(_run_designer(_design(tune, PAPER_PRESET, paper_chain)), weakened)


def loss_speed_error(top_speed_rad_s, paper_top_rad_s):
    """run.loss_speed_error_rad_s for a motor of that top speed: robust.ini's 2 rad/s on the
    paper motor, the same fraction of the motor's own top speed."""
    return PAPER_LOSS_SPEED_RAD_S * top_speed_rad_s / paper_top_rad_s


def _top_speeds(tune, preset_path, chain, low_speed_drive, extra=(), weakened=False):
    """(the preset's top speed, the paper motor's, the preset's field-weakened one; rad/s) from pmstep-tune,
    and the preset's command. With @p weakened the paper motor's is its field-weakened one, else the preset's
    field-weakened one is None."""
    cmd = _design(tune, preset_path, chain, low_speed_drive) + list(extra)
    output = _run_designer(cmd)
    weakened_top = tune_top_speed(output, True) if weakened else None
    return tune_top_speed(output), paper_top_speed(tune, weakened), weakened_top, cmd


def _scenario_peak_and_load(ini, path):
    """(peak |w*| of the scenario's profile, its load torque); a position scenario's peak is its v_max."""
    try:
        moves = [p for p in ini.get("position", "points", fallback="0:0").replace("\n", " ").split(",") if p.strip()]
        if len(moves) > 1 or (moves and float(moves[0].split(":")[1]) != 0.0):
            peak = float(ini.get("position", "v_max_rad_s"))
        else:
            points = [p for p in ini.get("speed", "points").replace("\n", " ").split(",") if p.strip()]
            peak = max(abs(float(p.split(":")[1])) for p in points)
        load = float(ini.get("load", "torque_Nm", fallback="0"))
    except (configparser.Error, ValueError, IndexError) as e:
        raise ToolError(f"{path}: cannot read the profile's peak speed and the load ({e})") from None
    return peak, load


def scenario_info(tune, preset_path, scenario_path, phase_voltage_sensing=False, low_speed_drive=False):
    """A campaign on a scenario written for the preset (e.g. position_acceptance.py --write-scenarios):
    the scenario runs as it is, the preset scales the distributions. Returns the info of
    design_scenario, with the scenario's own peak speed (a position scenario's v_max) and load."""
    preset = read_preset(preset_path)
    top, paper_top, _, cmd = _top_speeds(tune, preset_path, chain_sets(preset, phase_voltage_sensing), low_speed_drive)
    peak, load = _scenario_peak_and_load(_ini(scenario_path), scenario_path)
    return {
        "preset": preset["name"],
        "preset_file": preset_path,
        "top_speed_rad_s": top,
        "paper_top_speed_rad_s": paper_top,
        "run_start_s": None,
        "peak_speed_rad_s": peak,
        "load_Nm": load,
        "tune_command": cmd,
        "figures": preset,
        "paper_holding_torque_Nm": paper_holding_torque(),
        "speed_bound_rad_s": PAPER_SPEED_BOUND_RAD_S * top / paper_top,
        "designed": False,
    }


def _stretch(points, run_start, ratio):
    """speed.points of the validation profile with every speed and every time from @p run_start on
    scaled by @p ratio: the same accelerations, up to @p ratio times the speeds."""
    out = []
    for p in points:
        t, v = (float(x) for x in p.split(":"))
        if t > run_start:
            t = run_start + (t - run_start) * ratio
        out.append(f"{t:.9g}:{v * ratio:.9g}")
    return out


def design_scenario(tune, preset_path, out_dir, phase_voltage_sensing=False, low_speed_drive=False, weakened=False):
    """Designs the preset with pmstep-tune (robust mode, realistic chain) and writes the
    campaign's scenario to out_dir/preset_scenario.ini. Returns (its path, info) with info =
    {"preset", "top_speed_rad_s", "run_start_s", "peak_speed_rad_s", "load_Nm", "tune_command", ...}.
    With @p weakened the profile's speeds and its times in RUN are stretched by the field-weakened top
    speed over the design's (the same ramps' accelerations up to +-80 % of the weakened top speed), and
    the speed thresholds follow the weakened top speeds (the preset's and the paper motor's)."""
    preset = read_preset(preset_path)
    paper_holding = paper_holding_torque()
    chain = chain_sets(preset, phase_voltage_sensing)
    os.makedirs(out_dir, exist_ok=True)
    design_path = os.path.join(out_dir, "preset_design.ini")
    top, paper_top, weakened_top, cmd = _top_speeds(
        tune, preset_path, chain, low_speed_drive, ["--write-ini", design_path], weakened
    )
    ini = _ini(design_path)
    try:
        points = [p.strip() for p in ini.get("speed", "points").replace("\n", " ").split(",") if p.strip()]
        # RUN starts after the offset calibration and the two alignments (t_c counts from their start).
        run_start = float(ini.get("controller.commissioning", "offset_calibration_time_s", fallback="0")) + float(
            ini.get("controller.alignment", "c_align_time_s")
        )
        if weakened:
            ratio = weakened_top / top
            points = _stretch(points, run_start, ratio)
            duration = float(ini.get("run", "duration_s"))
            ini.set("run", "duration_s", repr(run_start + (duration - run_start) * ratio))
            top = weakened_top
        peak = max(abs(float(p.split(":")[1])) for p in points)
    except (configparser.Error, ValueError, IndexError) as e:
        raise ToolError(
            f"{design_path}: cannot read speed.points, the duration and the alignment times ({e})"
        ) from None
    info = {
        "preset": preset["name"],
        "preset_file": preset_path,
        "top_speed_rad_s": top,
        "paper_top_speed_rad_s": paper_top,
        "run_start_s": run_start,
        "peak_speed_rad_s": peak,
        "load_Nm": PAPER_LOAD_NM * preset["holding_torque_Nm"] / paper_holding,
        "tune_command": cmd,
        "figures": preset,
        "paper_holding_torque_Nm": paper_holding,
        "designed": True,
    }
    speed_bound = PAPER_SPEED_BOUND_RAD_S * top / paper_top
    loss_speed = loss_speed_error(top, paper_top)
    ini.set("scenario", "name", f"{preset['name']}_mc")
    ini.set("load", "type", "step")
    ini.set("load", "torque_Nm", repr(info["load_Nm"]))
    ini.set("load", "step_time_s", repr(run_start + LOAD_STEP_AFTER_RUN_S))
    ini.set("run", "loss_speed_error_rad_s", repr(loss_speed))
    lines = [
        "; Monte Carlo scenario of the motor preset " + os.path.basename(preset_path) + " (monte_carlo.py --preset):",
        "; pmstep-tune --robust behind the realistic chain (tools/mc_preset.py), with a load step",
        f"; of {info['load_Nm']:.6g} N m {LOAD_STEP_AFTER_RUN_S:g} s into RUN and loss of control at",
        f"; |w - w*| > {loss_speed:.6g} rad/s (2 rad/s x top speed / the paper motor's)",
    ]
    for section in ini.sections():
        lines.append(f"[{section}]")
        for key, value in ini.items(section):
            value = _points_lines(points) if (section, key) == ("speed", "points") else value.replace("\n", " ")
            lines.append(f"{key} = {value}")
    path = os.path.join(out_dir, "preset_scenario.ini")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    info["speed_bound_rad_s"] = speed_bound
    return path, info
