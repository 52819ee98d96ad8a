#!/usr/bin/env python3
"""Writes the committed seed corpus of the fuzzers (corpus/core, corpus/scenario).

The core's inputs follow the layout described at the top of fuzz_core.c. Word indices of
configuration fields below are those of pmstep_config_t when the seeds were made; after a
change of the struct they point at other fields, and the seeds stay valid inputs.
Usage: tests/fuzz/make_seeds.py   (rewrites the seeds; the fuzz.*_replay tests replay them)
"""

import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

START, STOP, CLEAR, RESET, SPEED_RAW, SPEED, ID_RAW, PLANT, _, MEAS_RAW, MEAS_EDGE, JUMP, NULLS = range(13)


def head(base, perturbations):
    return bytes([(len(perturbations) << 2) | base]) + b"".join(perturbations)


def perturb(word, kind, value=0.0):
    return bytes([word, kind]) + struct.pack("<f", value)


def plant(periods, bus=115, ripple=10, noise=2, offset=128, load=128):
    return bytes([PLANT]) + struct.pack("<H", periods) + bytes([bus, ripple, noise, offset, load])


def speed(target_byte, rate_byte):
    return bytes([SPEED, target_byte, rate_byte])


def meas_raw(i_a, i_b, bus, load):
    return bytes([MEAS_RAW]) + struct.pack("<ffff", i_a, i_b, bus, load)


def edge(which, kind):
    return bytes([MEAS_EDGE, which, kind])


def run(n):
    return b"".join(plant(4095) for _ in range(n))


nan, inf = float("nan"), float("inf")
core = {
    # the paper's configuration: alignments, then RUN at +10 rad/s with load steps
    "paper_run": head(0, []) + bytes([START]) + speed(168, 10) + run(4) + plant(4095, load=200) + run(2),
    # every option on: offset calibration, commissioning with the bias, dead time, drift-free angle
    "features_run": head(1, []) + bytes([START]) + speed(168, 10) + run(4) + plant(4095, load=60) + run(3),
    # the same in known-load mode
    "known_load_run": head(2, []) + bytes([START]) + speed(88, 20) + run(4) + plant(4095, load=180) + run(2),
    # short alignments; a NaN sample latches a fault, commands in FAULT, clear, again
    "short_fault_clear": head(3, [])
    + bytes([START])
    + plant(600)
    + meas_raw(nan, 0.0, 48.0, 0.0)
    + bytes([START, STOP])
    + plant(10)
    + bytes([CLEAR, START])
    + speed(140, 50)
    + plant(2000)
    + bytes([JUMP, 200, 255, 128])
    + plant(3000)
    + bytes([STOP, RESET, START])
    + plant(500),
    # every measurement edge in each mode of the short configuration
    "short_edges": head(3, [])
    + bytes([START])
    + b"".join(plant(90) + edge(w, k) + bytes([CLEAR, START]) for w in range(5) for k in range(12)),
    # the rotor pushed in RUN until detection trips or re-aligns (features: 2 re-alignments)
    "features_push": head(1, [])
    + bytes([START])
    + speed(200, 100)
    + run(2)
    + b"".join(bytes([JUMP, 40 * k, 0, 128]) + plant(1500) for k in range(6)),
    # issue 15 F1: a dead-time band of 1e-40 A (init must refuse it)
    "f1_band": head(0, [perturb(30, 0, 1e-6), perturb(31, 0, 1e-40)]) + bytes([START]) + plant(100),
    # F2: a detection time of 858993.4592 s (refused: longer than 2^24 periods)
    "f2_detection": head(0, [perturb(36, 0, 858993.4592)]) + bytes([START]) + plant(100),
    # F3: gamma 1e-30 (g_w not finite), J 1e28, F 3.4e38
    "f3_gamma": head(0, [perturb(15, 0, 1e-30)]) + bytes([START]) + plant(100),
    "f3_inertia": head(0, [perturb(2, 0, 1e28)]) + bytes([START]) + plant(100),
    "f3_friction": head(0, [perturb(3, 0, 3.4e38)]) + bytes([START]) + plant(100),
    # raw commands: non-finite and huge targets
    "commands": head(3, [])
    + bytes([SPEED_RAW])
    + struct.pack("<ff", inf, 1.0)
    + bytes([SPEED_RAW])
    + struct.pack("<ff", 3e38, 3e38)
    + bytes([ID_RAW])
    + struct.pack("<f", 14.0)
    + bytes([START])
    + plant(2000),
    # a raw configuration: the paper's bytes are not needed, any 156 bytes are an input
    "raw_config": bytes([0x80]) + bytes(range(156)) + bytes([START]) + plant(100),
    # R from one steady state per phase (voltage bias off), and missing arguments
    "features_no_bias": head(1, [perturb(29, 0, 0.0)])
    + bytes([NULLS, START])
    + speed(168, 10)
    + run(4)
    + plant(4095, load=90),
    # 100 us period and the longest alignment the paper allows for it
    "period_100us": head(3, [perturb(6, 2)]) + bytes([START]) + speed(168, 10) + run(3),
}

scenario_paper = open(os.path.join(HERE, "..", "..", "sil", "scenarios", "paper.ini"), "rb").read()
scenario_robust = open(os.path.join(HERE, "..", "..", "sil", "scenarios", "robust.ini"), "rb").read()
scenario = {
    "paper_ini": scenario_paper,
    "robust_ini": scenario_robust,
    "sets": b"[run]\nduration_s = 1\n\n--set\nrun.decimation=10\ncontroller.dead_time_s=1e-6\nspeed.points=0:0,1:5\n",
    "name_traversal": b"[scenario]\nname = ../../x\n",
    "name_plain": b"[scenario]\nname = a.b-c_1\n[speed]\npoints = 0:0,\n  1:1,\n  2:2\n",
    "long_line": b"; " + b"x" * 300 + b"\nduration_s = 0.002\n",
    "nul": b"[run]\nduration_s = 1\0 0\n",
    "long_points": b"[speed]\npoints = " + b",\n  ".join(b"%d.00000:12345" % k for k in range(80)) + b"\n",
    "bad_sets": b"\n--set\nrun.period_s=1e-40\n",
    "load_table": b"[load]\ntype = table\npoints = 0:0, 1:2, 2:-2\n",
    "sensors": b"[sensors]\nadc_bits = 12\ncurrent_full_scale_a = 10\n",
    "inverter": b"[inverter]\nmodel = switching\ndead_time_s = 1e-6\n[bus]\nripple_v = 100\n",
    # --print-scenario's text must read back to the same values: at 9 digits the first printed
    # 0.5 (outside the key's open range), the second two equal times; an exact subnormal was
    # taken and printed as a decimal that underflows; the angle is stored in radians.
    "print_open_bound": b"[sensors]\ngain_error_a = 0.4999999999\n",
    "print_close_times": b"[speed]\npoints = 0:0, 1.0000000001:1, 1.0000000002:2\n",
    "print_subnormal": b"[motor]\nfriction_Nms_rad = 0x1p-1074\n",
    "print_angle": b"[run]\ntheta0_deg = 123.45678901234567\n\n--set\nrun.theta0_deg=-999999.99999999988\n",
    # no decimal of rad * 180 / pi converts back to this one's radians: a neighbouring double does
    "print_angle_neighbour": b"[run]\ntheta0_deg = 1.0029999999999997\n",
}

# The console's inputs follow the layout described at the top of fuzz_console.c.
C_RAW, C_FRAME, C_TWO, C_PERIODS, C_SILENCE, C_SPECIAL = range(6)
HELLO, START, STOP, CLEAR_FAULT, SPEED_TARGET, ID_TARGET, GET_STATUS, GET_CONFIG, SET_CONFIG = range(1, 10)
TELEMETRY, MOVE_TO, SIM_ADVANCE = 0x0B, 0x0D, 0x40
SIM_STEPS, SIM_FOLLOW_STEPS, SIM_STEPDIR = 0x42, 0x43, 0x44
TRIP, MAX_BUS = 21, 23  # ids of limits.max_phase_current_A and limits.max_bus_voltage_V (pmstep_console_config.c)


def c_frame(ftype, seq=1, data=b""):
    return bytes([ftype, seq, len(data)]) + data


def c_periods(n):
    return bytes([C_PERIODS]) + struct.pack("<H", n)


def set_config(ident, value):
    return bytes([ident]) + struct.pack("<f", value)


console = {
    # the review's finding: SET_CONFIG max bus then GET_CONFIG of the trip in one receive call
    "busy_set_then_get": bytes([1, C_TWO])
    + c_frame(SET_CONFIG, 1, set_config(MAX_BUS, 60.0))
    + c_frame(GET_CONFIG, 2, bytes([TRIP]))
    + c_periods(4),
    "busy_set_then_speed": bytes([1, C_TWO])
    + c_frame(SET_CONFIG, 1, set_config(TRIP, 10.0))
    + c_frame(SPEED_TARGET, 2, struct.pack("<ff", 1e30, 50.0))
    + c_periods(4),
    # unbounded limits: refused by the validation
    "huge_limits": bytes([0, C_FRAME])
    + c_frame(SET_CONFIG, 1, set_config(TRIP, 3.4e38))
    + c_periods(2)
    + bytes([C_FRAME])
    + c_frame(SET_CONFIG, 2, set_config(MAX_BUS, 3.4e38))
    + c_periods(2),
    # START then SET_CONFIG at the next boundary, before a step ran
    "start_then_set": bytes([0, C_FRAME])
    + c_frame(START)
    + bytes([C_FRAME])
    + c_frame(SET_CONFIG, 2, set_config(12, 90.0))
    + c_periods(3),
    # into RUN, a speed command, telemetry, a busy ID_TARGET behind it, a stop
    "run_speed": bytes([1, C_FRAME])
    + c_frame(START)
    + c_periods(1000)
    + bytes([C_TWO])
    + c_frame(SPEED_TARGET, 2, struct.pack("<ff", 10.0, 50.0))
    + c_frame(ID_TARGET, 3, struct.pack("<f", 300.0))
    + bytes([C_FRAME])
    + c_frame(TELEMETRY, 4, struct.pack("<I", 7))
    + c_periods(3000)
    + bytes([C_FRAME])
    + c_frame(STOP, 5)
    + c_periods(10),
    # a position move, a status, a hold
    "position_move": bytes([1, C_FRAME])
    + c_frame(START)
    + c_periods(1000)
    + bytes([C_FRAME])
    + c_frame(MOVE_TO, 2, struct.pack("<fff", 1.0, 5.0, 50.0))
    + c_periods(4000)
    + bytes([C_FRAME])
    + c_frame(GET_STATUS, 3)
    + c_periods(2),
    # special floats of every typed request, a fault, a refused SET_CONFIG in FAULT, CLEAR_FAULT
    "specials": bytes([3])
    + b"".join(bytes([C_SPECIAL, t, v, 21]) + c_periods(2) for t in range(6) for v in range(16))
    + bytes([C_FRAME])
    + c_frame(START)
    + c_periods(50)
    + bytes([C_FRAME])
    + c_frame(CLEAR_FAULT)
    + c_periods(2),
    # bytes outside frames, a frame cut short, silence
    "garbage": bytes([0, C_RAW, 12])
    + bytes([0xA5, 3, 1, 2, 0xA5, 0xA5, 70, 1, 0, 0xFF, 0x12, 0xA5])
    + bytes([C_SILENCE, 50, C_FRAME])
    + c_frame(HELLO)
    + c_periods(1),
    # the simulation requests on a simulation console
    "simulation": bytes([2, C_FRAME])
    + c_frame(SIM_ADVANCE, 1, struct.pack("<I", 5))
    + bytes([C_FRAME])
    + c_frame(SIM_ADVANCE, 2, struct.pack("<I", 5))
    + c_periods(2),
    # the emulated STEP/DIR input: bursts through the counter's wrap, into RUN, following, edges both ways,
    # a read-back, a second SIM_STEPS refused while the first's edges remain
    "stepdir": bytes([7, C_FRAME])
    + c_frame(START)
    + b"".join(bytes([C_FRAME]) + c_frame(SIM_STEPS, 2, bytes([127]) * 60) + c_periods(60) for _ in range(9))
    + c_periods(1000)
    + bytes([C_FRAME])
    + c_frame(SIM_FOLLOW_STEPS, 3)
    + c_periods(1)
    + bytes([C_TWO])
    + c_frame(SIM_STEPS, 4, bytes([1, 0, 0xFF, 2]) * 15)
    + c_frame(SIM_STEPS, 5, bytes([1]))
    + c_periods(60)
    + bytes([C_FRAME])
    + c_frame(SIM_STEPDIR, 6)
    + c_periods(2),
}

for folder, seeds in (("core", core), ("scenario", scenario), ("console", console)):
    path = os.path.join(HERE, "corpus", folder)
    os.makedirs(path, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(path, name), "wb") as f:
            f.write(data)
    print(f"{len(seeds)} seeds in corpus/{folder}")
