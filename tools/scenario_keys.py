"""The scenario keys (`section.key` of pmstep-sil) that the Python tools set or read.

The one place that spells them: a key renamed in sil/src/scenario_keys.c is renamed here, and
every tool (monte_carlo.py and its modules, bench_sil.py) follows. Tools name a key by
its entry, e.g. KEYS["plant_resistance"].
"""

KEYS = {
    # [motor]: the plant
    "plant_resistance": "motor.resistance_Ohm",
    "plant_inductance": "motor.inductance_H",
    "plant_torque_constant": "motor.torque_constant_Nm_A",
    "plant_inertia": "motor.inertia_kgm2",
    "plant_friction": "motor.friction_Nms_rad",
    # [sensors]: the measurement chain
    "sensor_offset_a": "sensors.offset_a_A",
    "sensor_offset_b": "sensors.offset_b_A",
    "sensor_gain_error_a": "sensors.gain_error_a",
    "sensor_gain_error_b": "sensors.gain_error_b",
    "sensor_noise": "sensors.noise_rms_A",
    "phase_voltage_bits": "sensors.phase_voltage_bits",
    "phase_voltage_span": "sensors.phase_voltage_full_scale_V",
    "phase_voltage_offset_a": "sensors.phase_voltage_offset_a_V",
    "phase_voltage_offset_b": "sensors.phase_voltage_offset_b_V",
    "phase_voltage_gain_error_a": "sensors.phase_voltage_gain_error_a",
    "phase_voltage_gain_error_b": "sensors.phase_voltage_gain_error_b",
    "phase_voltage_noise": "sensors.phase_voltage_noise_rms_V",
    # [inverter] and [bus]
    "inverter_model": "inverter.model",
    "inverter_dead_time": "inverter.dead_time_s",
    "bus_ripple": "bus.ripple_V",
    "bus_source_resistance": "bus.source_resistance_Ohm",
    # [controller]: what the firmware is told
    "firmware_dead_time": "controller.inverter.dead_time_s",
    "phase_voltage_sensing": "controller.inverter.phase_voltage_sensing",
    "ripple_dead_zone": "controller.inverter.ripple_dead_zone",
    "detent_fade_speed": "controller.gains.detent_fade_speed_rad_s",
    # [run] and [load]
    "seed": "run.seed",
    "duration": "run.duration_s",
    "substeps": "run.substeps",
    "integrator": "run.integrator",
    "initial_angle": "run.theta0_deg",
    "load_torque": "load.torque_Nm",
}
