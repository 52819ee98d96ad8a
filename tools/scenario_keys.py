"""The scenario keys (`section.key` of pmstep-sil) that the Python tools set or read.

The one place that spells them: a key renamed in sil/src/scenario.c is renamed here, and
every tool (monte_carlo.py and its modules, bench_sil.py) follows. Tools name a key by
its entry, e.g. KEYS["plant_resistance"].
"""

KEYS = {
    # [motor]: the plant
    "plant_resistance": "motor.resistance_ohm",
    "plant_inductance": "motor.inductance_h",
    "plant_torque_constant": "motor.torque_constant_nm_per_a",
    "plant_inertia": "motor.inertia_kg_m2",
    "plant_friction": "motor.friction_nm_s_per_rad",
    # [sensors]: the measurement chain
    "sensor_offset_a": "sensors.offset_a_a",
    "sensor_offset_b": "sensors.offset_b_a",
    "sensor_gain_error_a": "sensors.gain_error_a",
    "sensor_gain_error_b": "sensors.gain_error_b",
    "sensor_noise": "sensors.noise_rms_a",
    # [inverter] and [bus]
    "inverter_model": "inverter.model",
    "inverter_dead_time": "inverter.dead_time_s",
    "bus_ripple": "bus.ripple_v",
    "bus_source_resistance": "bus.source_resistance_ohm",
    # [controller]: what the firmware is told
    "firmware_dead_time": "controller.dead_time_s",
    # [run] and [load]
    "seed": "run.seed",
    "duration": "run.duration_s",
    "substeps": "run.substeps",
    "integrator": "run.integrator",
    "initial_angle": "run.theta0_deg",
    "load_torque": "load.torque_nm",
}
