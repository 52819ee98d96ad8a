"""Checks a SIL run's commissioning in summary.json against the plant's motor in the scenario
file it ran: no fault latched, the measured L within --max-inductance-error of the motor's,
k_M within --max-torque-constant-error of the motor's, (with --max-resistance-error) R within
that of the motor's, (with --alignment-repeats N) the alignments repeated exactly N times, and
(with --max-rest-angle-error) the rotor's rest at t_c that RUN starts from within that many
electrical rad of the plant's p theta.

usage: check_commissioning.py SUMMARY SCENARIO --max-inductance-error E --max-torque-constant-error E
                              [--max-resistance-error E] [--alignment-repeats N] [--max-rest-angle-error RAD]"""

import argparse
import configparser
import json
import math
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("summary")
    ap.add_argument("scenario")
    for k in ("max-inductance-error", "max-torque-constant-error"):
        ap.add_argument(f"--{k}", type=float, required=True)
    ap.add_argument("--max-resistance-error", type=float)
    ap.add_argument("--alignment-repeats", type=int)
    ap.add_argument("--max-rest-angle-error", type=float)
    a = ap.parse_args()
    with open(a.summary) as f:
        s = json.load(f)
    scenario = configparser.ConfigParser(inline_comment_prefixes=(";", "#"))
    if not scenario.read(a.scenario):
        sys.exit(f"check_commissioning: cannot read {a.scenario}")
    motor_inductance_H = float(scenario["motor"]["inductance_H"])
    motor_torque_constant = float(scenario["motor"]["torque_constant_Nm_A"])
    motor_resistance_Ohm = float(scenario["motor"]["resistance_Ohm"])
    c = s["commissioning"]
    l_ratio = c["inductance_H"] / motor_inductance_H
    k_error = c["torque_constant_Nm_A"] / motor_torque_constant - 1.0
    print(
        f"fault {s['fault']['name']}; measured L {c['inductance_H']:.6g} H ({l_ratio:.3f} x the motor's), "
        f"k_M {c['torque_constant_Nm_A']:.6g} N m/A ({100 * k_error:+.2f} %), R {c['resistance_Ohm']:.6g} Ohm, "
        f"alignments repeated {c['alignment_repeats']:g} time(s)"
    )
    failures = []
    if s["fault"]["name"] != "NONE":
        failures.append(f"fault {s['fault']['name']} latched")
    if not abs(l_ratio - 1.0) <= a.max_inductance_error:
        failures.append(f"L {l_ratio:.3f} x the motor's, bound {100 * a.max_inductance_error:.1f} %")
    if not abs(k_error) <= a.max_torque_constant_error:
        failures.append(f"k_M {100 * k_error:+.2f} % off, bound {100 * a.max_torque_constant_error:.1f} %")
    checks = 3
    if a.max_resistance_error is not None:
        checks += 1
        r_error = c["resistance_Ohm"] / motor_resistance_Ohm - 1.0
        if not abs(r_error) <= a.max_resistance_error:
            failures.append(f"R {100 * r_error:+.2f} % off, bound {100 * a.max_resistance_error:.1f} %")
    if a.alignment_repeats is not None:
        checks += 1
        if c["alignment_repeats"] != a.alignment_repeats:
            failures.append(f"alignments repeated {c['alignment_repeats']:g} time(s), expected {a.alignment_repeats}")
    if a.max_rest_angle_error is not None:
        checks += 1
        t = s["alignment"]
        rest_error = math.atan2(
            c["equilibrium_sin"] * t["cos_ptheta_at_tc"] - c["equilibrium_cos"] * t["sin_ptheta_at_tc"],
            c["equilibrium_cos"] * t["cos_ptheta_at_tc"] + c["equilibrium_sin"] * t["sin_ptheta_at_tc"],
        )
        print(
            f"rest at t_c {math.atan2(c['equilibrium_sin'], c['equilibrium_cos']):+.4f} electrical rad, "
            f"plant {math.atan2(t['sin_ptheta_at_tc'], t['cos_ptheta_at_tc']):+.4f} ({rest_error:+.4f} off)"
        )
        if not abs(rest_error) <= a.max_rest_angle_error:
            failures.append(f"rest at t_c {rest_error:+.4f} rad off, bound {a.max_rest_angle_error} rad")
    for f in failures:
        print("FAIL:", f)
    print(f"{checks - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
