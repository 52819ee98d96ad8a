#!/usr/bin/env python3
"""A population of stepper motors covering the datasheet space of printer and CNC steppers, drawn
from stated distributions with a fixed seed (so a sweep over it is repeatable), written as motor
presets that pmstep-tune and pmstep-sil read.

How a motor is drawn (all draws independent unless stated; log-uniform means uniform in log):
  frame          NEMA 8, 11, 14, 17, 23, 34 with weights 1, 2, 3, 6, 4, 2 (printers use 17 most)
  holding T_H    log-uniform in the frame's range FRAMES[frame]["holding_Nm"], within 0.02-6 N m
  steps/rev      200 (p = 50) with probability 0.75, else 400 (0.9 deg, p = 100)
  rated I        log-uniform in the frame's current range, within 0.3-6 A
  rated voltage  R I log-uniform in 1-12 V (winding variants of one frame), R kept within 0.2-30 Ohm
  k_M            T_H / (sqrt(2) I): both phases at rated current give the holding torque
  L              from the flux ratio p L I / k_M log-uniform in 0.4-4 (the winding's flux at rated current
                 over the magnet's: a property of the frame's magnetic design, 0.5-3 in datasheets, which a
                 rewound winding keeps), L kept within 0.3-30 mH and L/R within 0.2-20 ms
  rotor J        J_fit(T_H) x a log-uniform spread of x0.5 to x2, J_fit = 2.1e-5 (T_H / 1 N m)^1.5 kg m^2
                 (fit to NEMA 8-34 datasheets: 0.4 N m -> 5e-6, 1.26 N m -> 3e-5, 4.5 N m -> 2e-4)
  detent         uniform 0-10 % of T_H
  friction F     1.5 % of T_H at 60 rad/s (bearings and iron losses): 2.5e-4 T_H N m s/rad
  bus            12, 24 or 48 V, uniform among those that leave R I at most half the bus
                 (a motor is drawn again if none does)
  load inertia   0 or 1x the rotor's, half the motors each: the plant's J is the rotor's times
                 (1 + ratio); the datasheet (what the designer is told) has no J: pmstep-tune estimates
                 it from the holding torque (the same fit) and has it identified in RUN
Each preset's [datasheet] holds what a datasheet gives (rated current, holding torque, detent,
R, L, steps/rev) and the estimates the designer is told ([told] J and F); [motor] holds the
plant's true values.

Usage: tools/motor_population.py --out DIR [--count 500] [--seed 2026]   (writes DIR/*.ini and
DIR/population.csv); also importable: draw(count, seed) -> list of dicts.
"""

import argparse
import csv
import math
import os
import random

SEED = 2026
COUNT = 500

FRAMES = {
    "NEMA8": {"weight": 1, "holding_Nm": (0.02, 0.05), "current_A": (0.3, 0.8)},
    "NEMA11": {"weight": 2, "holding_Nm": (0.04, 0.15), "current_A": (0.3, 1.2)},
    "NEMA14": {"weight": 3, "holding_Nm": (0.08, 0.5), "current_A": (0.4, 1.5)},
    "NEMA17": {"weight": 6, "holding_Nm": (0.15, 0.8), "current_A": (0.5, 2.5)},
    "NEMA23": {"weight": 4, "holding_Nm": (0.5, 3.0), "current_A": (1.0, 5.0)},
    "NEMA34": {"weight": 2, "holding_Nm": (2.0, 6.0), "current_A": (2.0, 6.0)},
}
BUSES_V = (12.0, 24.0, 48.0)
LIMITS = {"resistance_Ohm": (0.2, 30.0), "inductance_H": (0.3e-3, 30e-3)}


def log_uniform(rng, low, high):
    return math.exp(rng.uniform(math.log(low), math.log(high)))


def inertia_fit_kgm2(holding_Nm):
    """The rotor inertia a frame's datasheets give for its holding torque (the fit in the docstring)."""
    return 2.1e-5 * holding_Nm**1.5


def friction_estimate_Nms_rad(holding_Nm):
    """1.5 % of the holding torque at 60 rad/s."""
    return 0.015 * holding_Nm / 60.0


def draw_one(rng, index):
    frames = list(FRAMES)
    while True:
        frame = rng.choices(frames, weights=[FRAMES[f]["weight"] for f in frames])[0]
        spec = FRAMES[frame]
        holding = log_uniform(rng, *spec["holding_Nm"])
        pole_pairs = 50 if rng.random() < 0.75 else 100
        current = log_uniform(rng, *spec["current_A"])
        resistance = log_uniform(rng, 1.0, 12.0) / current
        torque_constant = holding / (math.sqrt(2.0) * current)
        inductance = log_uniform(rng, 0.4, 4.0) * torque_constant / (pole_pairs * current)
        if not (
            LIMITS["resistance_Ohm"][0] <= resistance <= LIMITS["resistance_Ohm"][1]
            and LIMITS["inductance_H"][0] <= inductance <= LIMITS["inductance_H"][1]
            and 0.2e-3 <= inductance / resistance <= 20e-3
        ):
            continue
        buses = [b for b in BUSES_V if resistance * current <= 0.5 * b]
        if not buses:
            continue
        bus = rng.choice(buses)
        rotor = inertia_fit_kgm2(holding) * log_uniform(rng, 0.5, 2.0)
        load_ratio = rng.choice((0.0, 1.0))
        detent = rng.uniform(0.0, 0.10) * holding
        return {
            "name": f"m{index:04d}",
            "frame": frame,
            "pole_pairs": pole_pairs,
            "rated_current_A": current,
            "holding_torque_Nm": holding,
            "detent_torque_Nm": detent,
            "resistance_Ohm": resistance,
            "inductance_H": inductance,
            "torque_constant_Nm_A": torque_constant,
            "inertia_kgm2": rotor * (1.0 + load_ratio),
            "rotor_inertia_kgm2": rotor,
            "load_ratio": load_ratio,
            "friction_Nms_rad": friction_estimate_Nms_rad(holding),
            "told_inertia_kgm2": inertia_fit_kgm2(holding),
            "told_friction_Nms_rad": friction_estimate_Nms_rad(holding),
            "bus_voltage_V": bus,
        }


def draw(count=COUNT, seed=SEED):
    """@p count motors drawn with @p seed (the module docstring's distributions)."""
    rng = random.Random(seed)
    return [draw_one(rng, k) for k in range(count)]


def preset_text(m):
    """A motor preset (sil/scenarios/motors/*.ini layout) for @p m."""
    return "\n".join(
        [
            f"; Drawn by tools/motor_population.py: {m['frame']}, {200 * m['pole_pairs'] // 50} steps/rev,"
            f" load inertia {m['load_ratio']:g} x the rotor's.",
            "[scenario]",
            f"name = {m['name']}",
            "",
            "[datasheet]",
            f"rated_current_A = {m['rated_current_A']:.6g}",
            f"holding_torque_Nm = {m['holding_torque_Nm']:.6g}",
            f"detent_torque_Nm = {m['detent_torque_Nm']:.6g}",
            "",
            "[motor]",
            f"resistance_Ohm = {m['resistance_Ohm']:.6g}",
            f"inductance_H = {m['inductance_H']:.6g}",
            f"inertia_kgm2 = {m['inertia_kgm2']:.6g}",
            f"friction_Nms_rad = {m['friction_Nms_rad']:.6g}",
            f"torque_constant_Nm_A = {m['torque_constant_Nm_A']:.6g}",
            f"pole_pairs = {m['pole_pairs']}",
            f"detent_torque_Nm = {m['detent_torque_Nm']:.6g}",
            "",
            "[run]",
            f"bus_voltage_V = {m['bus_voltage_V']:g}",
            "",
        ]
    )


FIELDS = [
    "name",
    "frame",
    "pole_pairs",
    "rated_current_A",
    "holding_torque_Nm",
    "detent_torque_Nm",
    "resistance_Ohm",
    "inductance_H",
    "torque_constant_Nm_A",
    "inertia_kgm2",
    "rotor_inertia_kgm2",
    "load_ratio",
    "friction_Nms_rad",
    "told_inertia_kgm2",
    "told_friction_Nms_rad",
    "bus_voltage_V",
]


def write(motors, out):
    os.makedirs(out, exist_ok=True)
    for m in motors:
        with open(os.path.join(out, m["name"] + ".ini"), "w") as f:
            f.write(preset_text(m))
    with open(os.path.join(out, "population.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        for m in motors:
            w.writerow({k: m[k] for k in FIELDS})


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True)
    parser.add_argument("--count", type=int, default=COUNT)
    parser.add_argument("--seed", type=int, default=SEED)
    args = parser.parse_args()
    motors = draw(args.count, args.seed)
    write(motors, args.out)
    print(f"motor_population: {len(motors)} motors (seed {args.seed}) in {args.out}")


if __name__ == "__main__":
    main()
