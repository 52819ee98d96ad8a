"""Monte Carlo campaigns, part 1: what is drawn. The distribution table, the case seeds
and the draws (see monte_carlo.py for the whole tool).

Every scenario key comes from scenario_keys.KEYS.
"""

import configparser
import math

from scenario_keys import KEYS

# --------------------------------------------------------------------------------------
# The distribution table: the one place that says what is randomised and how.
# (key, kind, a, b):
#   kind "scale":   value = (the scenario file's value) * U[a, b]
#   kind "times K": value = (the value drawn for the earlier row K) * U[a, b]
#   kind "uniform": value = U[a, b]   (the scenario file's value is not used)
# U[a, b] is a + (b - a) * random(), random() in [0, 1): b itself is never drawn.
# --------------------------------------------------------------------------------------
DISTRIBUTIONS = [
    (KEYS["plant_resistance"], "scale", 0.7, 1.3),
    (KEYS["plant_inductance"], "scale", 0.8, 1.2),
    (KEYS["plant_torque_constant"], "scale", 0.9, 1.1),
    (KEYS["plant_inertia"], "scale", 0.5, 1.5),
    (KEYS["plant_friction"], "uniform", 0.0, 0.005),
    (KEYS["sensor_offset_a"], "uniform", -0.02, 0.02),
    (KEYS["sensor_offset_b"], "uniform", -0.02, 0.02),
    (KEYS["sensor_gain_error_a"], "uniform", -0.01, 0.01),
    (KEYS["sensor_gain_error_b"], "uniform", -0.01, 0.01),
    # Half to one and a half times the acceptance's 5 mA: a real current channel is never quieter
    # than about half an LSB (8 mA at 12 bits over +-16.5 A); README shows what an undithered one does.
    (KEYS["sensor_noise"], "uniform", 0.0025, 0.0075),
    (KEYS["inverter_dead_time"], "uniform", 0.0, 1.5e-6),
    (KEYS["bus_ripple"], "uniform", 0.0, 2.0),
    (KEYS["bus_source_resistance"], "uniform", 0.0, 0.2),
    (KEYS["initial_angle"], "uniform", 0.0, 360.0),
    (KEYS["load_torque"], "scale", 0.0, 1.0),
    # The firmware compensates the dead time its timer is programmed with; the bridge's own
    # switching delays make the real one differ by up to 10 %.
    (KEYS["firmware_dead_time"], "times " + KEYS["inverter_dead_time"], 0.9, 1.1),
]

SEED_STRIDE = 100000  # case seed = base seed * SEED_STRIDE + case index
SEED_KEY = KEYS["seed"]  # the SIL's noise seed
DURATION_KEY = KEYS["duration"]

# Drawn parameters shown in the worst-case table (key, column title, show as factor).
KEY_PARAMETERS = (
    (KEYS["plant_resistance"], "R/R0", True),
    (KEYS["plant_inductance"], "L/L0", True),
    (KEYS["plant_torque_constant"], "k_M/k_M0", True),
    (KEYS["plant_inertia"], "J/J0", True),
    (KEYS["inverter_dead_time"], "dead time (us)", False),
    (KEYS["load_torque"], "load (Nm)", False),
    (KEYS["initial_angle"], "theta0 (deg)", False),
)


class ToolError(Exception):
    """A problem with the inputs or the installed pmstep-sil: message for the user, exit status 2."""


def case_seed(base_seed, index):
    """Case seed of case `index` (0-based) in a run with base seed `base_seed`."""
    if not 0 <= index < SEED_STRIDE:
        raise ValueError(f"case index {index} outside [0, {SEED_STRIDE})")
    if base_seed < 0:
        raise ValueError(f"base seed {base_seed} is negative")
    return base_seed * SEED_STRIDE + index


def split_case_seed(seed):
    """(base seed, case index) of a case seed: the inverse of case_seed()."""
    return divmod(seed, SEED_STRIDE)


def parse_scenario(text):
    """Scenario INI text (pmstep-sil --print-scenario) to {"section.key": "value"}."""
    parser = configparser.ConfigParser(
        comment_prefixes=(";", "#"), inline_comment_prefixes=None, interpolation=None, strict=False
    )
    parser.optionxform = str  # keep the keys' case
    parser.read_string(text)
    return {f"{section}.{key}": value.strip() for section in parser.sections() for key, value in parser.items(section)}


def missing_keys(scenario, table=DISTRIBUTIONS, extra=(SEED_KEY,)):
    """Keys of the distribution table (and `extra`) that the scenario listing lacks, in order."""
    wanted = [row[0] for row in table] + list(extra)
    return [key for key in wanted if key not in scenario]


def base_values(scenario, table=DISTRIBUTIONS):
    """{key: float} of the scenario's value of every "scale" row; ToolError if not a number."""
    values = {}
    for key, kind, _a, _b in table:
        if kind != "scale":
            continue
        try:
            value = float(scenario[key])
        except ValueError:
            raise ToolError(f"scenario value of {key} is '{scenario[key]}', not a number") from None
        if not math.isfinite(value):
            raise ToolError(f"scenario value of {key} is '{scenario[key]}', not finite")
        values[key] = value
    return values


def draw_parameters(seed, base, table=DISTRIBUTIONS):
    """Parameters of the case with this case seed: {key: value}, in table order.

    One random() per row, in table order, from random.Random(seed); `base` holds the
    scenario values of the "scale" rows.
    """
    import random  # local: the module is only needed here

    rng = random.Random(seed)
    params = {}
    for key, kind, a, b in table:
        u = a + (b - a) * rng.random()
        if kind == "scale":
            params[key] = base[key] * u
        elif kind == "uniform":
            params[key] = u
        elif kind.startswith("times ") and kind[len("times ") :] in params:
            params[key] = params[kind[len("times ") :]] * u
        else:
            raise ValueError(f"{key}: unknown distribution kind '{kind}'")
    return params


def format_value(value):
    """A float as pmstep-sil reads it back exactly (shortest round-trip repr)."""
    return repr(float(value))


def distribution_rows(scenario):
    """Rows of the distribution table for the report: key, law, scenario value, drawn range."""
    rows = []
    for key, kind, a, b in DISTRIBUTIONS:
        if kind == "scale":
            value = float(scenario[key])
            rows.append((key, f"scenario value x U[{a:g}, {b:g}]", f"{value:g}", f"[{value * a:.4g}, {value * b:.4g})"))
        elif kind.startswith("times "):
            rows.append(
                (key, f"{kind[len('times ') :]} x U[{a:g}, {b:g}]", f"{scenario.get(key, '-')} (replaced)", "-")
            )
        else:
            rows.append((key, f"U[{a:g}, {b:g}]", f"{scenario.get(key, '-')} (replaced)", f"[{a:g}, {b:g})"))
    return rows
