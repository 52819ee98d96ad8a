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
    "short_fault_clear": head(3, []) + bytes([START]) + plant(600) + meas_raw(nan, 0.0, 48.0, 0.0)
    + bytes([START, STOP]) + plant(10) + bytes([CLEAR, START]) + speed(140, 50) + plant(2000)
    + bytes([JUMP, 200, 255, 128]) + plant(3000) + bytes([STOP, RESET, START]) + plant(500),
    # every measurement edge in each mode of the short configuration
    "short_edges": head(3, []) + bytes([START])
    + b"".join(plant(90) + edge(w, k) + bytes([CLEAR, START]) for w in range(5) for k in range(12)),
    # the rotor pushed in RUN until detection trips or re-aligns (features: 2 re-alignments)
    "features_push": head(1, []) + bytes([START]) + speed(200, 100) + run(2)
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
    "commands": head(3, []) + bytes([SPEED_RAW]) + struct.pack("<ff", inf, 1.0) + bytes([SPEED_RAW])
    + struct.pack("<ff", 3e38, 3e38) + bytes([ID_RAW]) + struct.pack("<f", 14.0) + bytes([START]) + plant(2000),
    # a raw configuration: the paper's bytes are not needed, any 156 bytes are an input
    "raw_config": bytes([0x80]) + bytes(range(156)) + bytes([START]) + plant(100),
    # R from one steady state per phase (voltage bias off), and missing arguments
    "features_no_bias": head(1, [perturb(29, 0, 0.0)]) + bytes([NULLS, START]) + speed(168, 10) + run(4)
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

for folder, seeds in (("core", core), ("scenario", scenario)):
    path = os.path.join(HERE, "corpus", folder)
    os.makedirs(path, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(path, name), "wb") as f:
            f.write(data)
    print(f"{len(seeds)} seeds in corpus/{folder}")
