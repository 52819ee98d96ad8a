/* Scenario keys: one table gives each key its field, type and range (scenario_keys.h). The
 * values are converted and checked in scenario.c, files read in scenario_load.c and written in
 * scenario_print.c. */
#include "scenario_keys.h"

#include <stddef.h>

#define OFF(field) offsetof(sil_scenario_t, field)
#define BIG 1e12

const key_t_ scenario_keys[] = {
    {"datasheet.rated_current_A", KEY_DOUBLE, OFF(datasheet.rated_current_A), 0, 1, 1e4, 0, "rated phase current (A)"},
    {"datasheet.holding_torque_Nm", KEY_DOUBLE, OFF(datasheet.holding_torque_Nm), 0, 1, 1e6, 0, "holding torque, both phases at rated current (Nm)"},
    {"datasheet.detent_torque_Nm", KEY_DOUBLE, OFF(datasheet.detent_torque_Nm), 0, 0, 1e6, 0, "unpowered detent torque (Nm); 0 = not given"},

    {"motor.resistance_Ohm", KEY_DOUBLE, OFF(motor.resistance_Ohm), 0, 1, BIG, 0, "plant R (Ohm)"},
    {"motor.inductance_H", KEY_DOUBLE, OFF(motor.inductance_H), 0, 1, BIG, 0, "plant L (H)"},
    {"motor.inertia_kgm2", KEY_DOUBLE, OFF(motor.inertia_kgm2), 0, 1, BIG, 0, "plant J (kg m^2)"},
    {"motor.friction_Nms_rad", KEY_DOUBLE, OFF(motor.friction_Nms_rad), 0, 0, BIG, 0, "plant F (Nm s/rad)"},
    {"motor.torque_constant_Nm_A", KEY_DOUBLE, OFF(motor.torque_constant_Nm_A), 0, 1, BIG, 0, "plant k_M (Nm/A)"},
    {"motor.pole_pairs", KEY_INT, OFF(motor.pole_pairs), 1, 0, 1000, 0, "plant p"},
    {"motor.detent_torque_Nm", KEY_DOUBLE, OFF(motor.detent_torque_Nm), 0, 0, 1e6, 0, "plant detent torque T_d, -T_d sin(4 p theta) (Nm); 0 = none"},

    {"controller.motor.resistance_Ohm", KEY_FLOAT, OFF(controller.motor.resistance_Ohm), -BIG, 0, BIG, 0, "R the firmware assumes (Ohm)"},
    {"controller.motor.inductance_H", KEY_FLOAT, OFF(controller.motor.inductance_H), -BIG, 0, BIG, 0, "L (H)"},
    {"controller.motor.inertia_kgm2", KEY_FLOAT, OFF(controller.motor.inertia_kgm2), -BIG, 0, BIG, 0, "J (kg m^2)"},
    {"controller.motor.friction_Nms_rad", KEY_FLOAT, OFF(controller.motor.friction_Nms_rad), -BIG, 0, BIG, 0, "F (Nm s/rad)"},
    {"controller.motor.torque_constant_Nm_A", KEY_FLOAT, OFF(controller.motor.torque_constant_Nm_A), -BIG, 0, BIG, 0, "k_M (Nm/A)"},
    {"controller.motor.pole_pairs", KEY_INT, OFF(controller.motor.pole_pairs), -1000, 0, 1000, 0, "p"},
    {"controller.motor.detent_torque_Nm", KEY_FLOAT, OFF(controller.motor.detent_torque_Nm), -BIG, 0, BIG, 0, "detent torque T_d the observer and the law compensate (Nm); 0 = none (the paper)"},
    {"controller.alignment.s_align_time_s", KEY_FLOAT, OFF(controller.alignment.s_align_time_s), -BIG, 0, BIG, 0, "t_s (s)"},
    {"controller.alignment.c_align_time_s", KEY_FLOAT, OFF(controller.alignment.c_align_time_s), -BIG, 0, BIG, 0, "t_c (s)"},
    {"controller.alignment.s_align_voltage_V", KEY_FLOAT, OFF(controller.alignment.s_align_voltage_V), -BIG, 0, BIG, 0, "u_cs (V)"},
    {"controller.alignment.c_align_voltage_V", KEY_FLOAT, OFF(controller.alignment.c_align_voltage_V), -BIG, 0, BIG, 0, "u_cc (V)"},
    {"controller.gains.speed_gain_per_s", KEY_FLOAT, OFF(controller.gains.speed_gain_per_s), -BIG, 0, BIG, 0, "k_omega (1/s)"},
    {"controller.gains.observer_gain_per_s", KEY_FLOAT, OFF(controller.gains.observer_gain_per_s), -BIG, 0, BIG, 0, "K_e (1/s)"},
    {"controller.gains.current_gain_per_s", KEY_FLOAT, OFF(controller.gains.current_gain_per_s), -BIG, 0, BIG, 0, "K_i (1/s)"},
    {"controller.gains.adapt_gamma", KEY_FLOAT, OFF(controller.gains.adapt_gamma), -BIG, 0, BIG, 0, "gamma"},
    {"controller.gains.adapt_lambda", KEY_FLOAT, OFF(controller.gains.adapt_lambda), -BIG, 0, BIG, 0, "lambda"},
    {"controller.gains.adapt_r", KEY_FLOAT, OFF(controller.gains.adapt_r), -BIG, 0, BIG, 0, "r"},
    {"controller.gains.sat_kappa_rad_s", KEY_FLOAT, OFF(controller.gains.sat_kappa_rad_s), -BIG, 0, BIG, 0, "kappa (rad/s)"},
    {"controller.gains.reference_bandwidth_rad_s", KEY_FLOAT, OFF(controller.gains.reference_bandwidth_rad_s), -BIG, 0, BIG, 0, "varpi_0 (rad/s)"},
    {"controller.gains.current_integral_gain_per_s2", KEY_FLOAT, OFF(controller.gains.current_integral_gain_per_s2), -BIG, 0, BIG, 0, "K_I: PI current loop, integral of i - i* in the voltage (1/s^2); 0 = the paper's law"},
    {"controller.gains.angle_correction_gain_per_s", KEY_FLOAT, OFF(controller.gains.angle_correction_gain_per_s), -BIG, 0, BIG, 0, "pulls (c-hat, s-hat) onto the unit circle at this rate (1/s); 0 = the paper's open integrals"},
    {"controller.limits.max_phase_current_A", KEY_FLOAT, OFF(controller.limits.max_phase_current_A), -BIG, 0, BIG, 0, "overcurrent trip (A)"},
    {"controller.limits.min_bus_voltage_V", KEY_FLOAT, OFF(controller.limits.min_bus_voltage_V), -BIG, 0, BIG, 0, "undervoltage trip (V)"},
    {"controller.limits.max_bus_voltage_V", KEY_FLOAT, OFF(controller.limits.max_bus_voltage_V), -BIG, 0, BIG, 0, "overvoltage trip (V)"},
    {"controller.commissioning.offset_calibration_time_s", KEY_FLOAT, OFF(controller.commissioning.offset_calibration_time_s), -BIG, 0, BIG, 0, "Remark 2: bridge off this long before s-alignment, current offsets averaged (s); 0 = none"},
    {"controller.commissioning.alignment_offset_calibration", KEY_BOOL, OFF(controller.commissioning.alignment_offset_calibration), 0, 0, 1, 0, "offsets also from the alignment steady states (true/false)"},
    {"controller.commissioning.steady_state_window_s", KEY_FLOAT, OFF(controller.commissioning.steady_state_window_s), -BIG, 0, BIG, 0, "averaging window at the end of each alignment (s); 0 = none"},
    {"controller.commissioning.inductance_window_s", KEY_FLOAT, OFF(controller.commissioning.inductance_window_s), -BIG, 0, BIG, 0, "current-rise window at the start of s-alignment for L (s); 0 = L not measured"},
    {"controller.commissioning.use_measured_resistance", KEY_BOOL, OFF(controller.commissioning.use_measured_resistance), 0, 0, 1, 0, "RUN uses the measured R (true/false)"},
    {"controller.commissioning.use_measured_inductance", KEY_BOOL, OFF(controller.commissioning.use_measured_inductance), 0, 0, 1, 0, "RUN uses the measured L (true/false)"},
    {"controller.commissioning.use_measured_torque_constant", KEY_BOOL, OFF(controller.commissioning.use_measured_torque_constant), 0, 0, 1, 0, "RUN uses the measured k_M (true/false)"},
    {"controller.commissioning.voltage_bias_level_fraction", KEY_FLOAT, OFF(controller.commissioning.voltage_bias_level_fraction), -BIG, 0, BIG, 0, "Remark 2 voltage bias: second alignment level as a fraction of the voltage (0 = off)"},
    {"controller.commissioning.identification_time_s", KEY_FLOAT, OFF(controller.commissioning.identification_time_s), -BIG, 0, BIG, 0, "J and F identified over this long from t_c (s); the speed commands must accelerate in it; 0 = off"},
    {"controller.commissioning.identification_min_speed_rad_s", KEY_FLOAT, OFF(controller.commissioning.identification_min_speed_rad_s), -BIG, 0, BIG, 0, "identification uses only periods with |w*| at least this (rad/s)"},
    {"controller.commissioning.use_identified_mechanics", KEY_BOOL, OFF(controller.commissioning.use_identified_mechanics), 0, 0, 1, 0, "RUN uses the identified J and F from the window's end (true/false)"},
    {"controller.inverter.dead_time_s", KEY_FLOAT, OFF(controller.inverter.dead_time_s), -BIG, 0, BIG, 0, "dead time per half-bridge to compensate (s); 0 = none"},
    {"controller.inverter.dead_time_current_band_A", KEY_FLOAT, OFF(controller.inverter.dead_time_current_band_A), -BIG, 0, BIG, 0, "dead-time compensation linear within +/- this current (A)"},
    {"controller.detection.angle_magnitude_bound", KEY_FLOAT, OFF(controller.detection.angle_magnitude_bound), -BIG, 0, BIG, 0, "|c-hat^2 + s-hat^2 - 1| above -> angle lost; 0 = off"},
    {"controller.detection.speed_consistency_bound_rad_s", KEY_FLOAT, OFF(controller.detection.speed_consistency_bound_rad_s), -BIG, 0, BIG, 0, "|speed from the angle's rotation - omega-hat| above -> inconsistent (rad/s); 0 = off"},
    {"controller.detection.stall_speed_error_rad_s", KEY_FLOAT, OFF(controller.detection.stall_speed_error_rad_s), -BIG, 0, BIG, 0, "|omega-hat - omega*| above -> stall (rad/s); 0 = off"},
    {"controller.detection.observer_residual_bound_A", KEY_FLOAT, OFF(controller.detection.observer_residual_bound_A), -BIG, 0, BIG, 0, "detection: low-passed |i - i-hat| sum above -> OBSERVER_RESIDUAL (A, 0 = off)"},
    {"controller.detection.persistence_s", KEY_FLOAT, OFF(controller.detection.persistence_s), -BIG, 0, BIG, 0, "persistence before a detection acts (s)"},
    {"controller.detection.max_realignments", KEY_UINT, OFF(controller.detection.max_realignments), 0, 0, 4294967295.0, 0, "0: a detection latches its fault; N: re-align up to N times"},
    {"controller.known_load_mode", KEY_BOOL, OFF(controller.known_load_mode), 0, 0, 1, 0, "Remark 1: load torque measured (true/false)"},

    /* 3600 s / 1 us = 3.6e9 periods: the core's uint32 step counter does not wrap. */
    {"run.duration_s", KEY_DOUBLE, OFF(duration_s), 0, 1, 3600, 0, "simulated time (s)"},
    {"run.period_s", KEY_FLOAT, OFF(controller.timing.period_s), 1e-6, 0, 0.01, 0, "control period T_s (s)"},
    {"run.substeps", KEY_INT, OFF(substeps), 1, 0, 10000, 0, "plant integration steps per control period"},
    {"run.integrator", KEY_INTEGRATOR, OFF(integrator), 0, 0, 0, 0, "exponential (R/L exact, fourth order) | rk4 (classical, the reference)"},
    {"run.delay_periods", KEY_UINT, OFF(controller.timing.computational_delay_periods), 0, 0, 1, 0, "computational delay (0 or 1 period)"},
    {"run.bus_voltage_V", KEY_DOUBLE, OFF(bus_voltage_V), 0, 1, 10000, 0, "DC bus (V)"},
    {"run.theta0_deg", KEY_ANGLE_DEG, OFF(theta0_rad), -1e6, 0, 1e6, 0, "initial rotor angle (mechanical deg)"},
    {"run.omega0_rad_s", KEY_DOUBLE, OFF(omega0_rad_s), -1e4, 0, 1e4, 0, "initial speed (rad/s)"},
    {"run.i_a0_A", KEY_DOUBLE, OFF(i_a0_A), -1e4, 0, 1e4, 0, "initial current a (A)"},
    {"run.i_b0_A", KEY_DOUBLE, OFF(i_b0_A), -1e4, 0, 1e4, 0, "initial current b (A)"},
    {"run.decimation", KEY_INT, OFF(decimation), 1, 0, 100000000, 0, "a CSV row every N periods"},
    {"run.transient_window_s", KEY_DOUBLE, OFF(transient_window_s), 0, 0, 3600, 0, "load-transient window after t_c (s)"},
    {"run.seed", KEY_UINT, OFF(seed), 0, 0, 4294967295.0, 0, "seed of every random draw (GSL MT19937; 0 acts as 4357)"},
    {"run.loss_speed_error_rad_s", KEY_DOUBLE, OFF(loss_speed_error_rad_s), 0, 1, BIG, 0, "|omega - omega*| above this in RUN counts as loss of control (rad/s)"},
    {"run.max_csv_MB", KEY_DOUBLE, OFF(max_csv_MB), 0, 1, 1e6, 0, "refuse to start a run whose run.csv would exceed this (MB)"},
    {"run.loss_angle_error_rad", KEY_DOUBLE, OFF(loss_angle_error_rad), 0, 1, BIG, 0, "angle-estimate error above this in RUN counts as loss of control (rad)"},
    {"run.controller", KEY_DRIVE, OFF(drive), 0, 0, 0, 0, "pmstep (the firmware) | microstep (open-loop microstepping at datasheet.rated_current_A, the baseline)"},
    {"run.metrics_start_s", KEY_DOUBLE, OFF(metrics_start_s), -1, 0, 3600, 0, "start of the RMS-current and load-angle window (s); < 0: start of RUN (t_c) or end of the microstep hold"},

    {"speed.points", KEY_SPEED_POINTS, 0, 0, 0, 0, 0, "set-point t:omega pairs (s:rad/s), piecewise linear"},
    {"speed.id_target_A", KEY_DOUBLE, OFF(id_target_A), -1e4, 0, 1e4, 0, "i_d* (A)"},

    {"load.type", KEY_LOAD_KIND, 0, 0, 0, 0, 0, "none | constant | step | proportional | table"},
    {"load.torque_Nm", KEY_DOUBLE, OFF(load.torque_Nm), -1e6, 0, 1e6, 0, "constant / step load (Nm)"},
    {"load.step_time_s", KEY_DOUBLE, OFF(load.step_time_s), 0, 0, 3600, 0, "time of the step (s)"},
    {"load.coefficient_Nms_rad", KEY_DOUBLE, OFF(load.coefficient_Nms_rad), -1e6, 0, 1e6, 0, "proportional load T_L = c omega"},
    {"load.points", KEY_LOAD_POINTS, 0, 0, 0, 0, 0, "table t:T_L pairs (s:Nm), piecewise linear"},

    {"position.points", KEY_MOVES, 0, 0, 0, 0, 0, "moves t:theta (s : mechanical rad from the c-alignment equilibrium); 0:0 alone = a speed scenario"},
    {"position.v_max_rad_s", KEY_DOUBLE, OFF(move_speed_rad_s), 0, 1, 1e6, 0, "speed limit of every move (rad/s)"},
    {"position.a_max_rad_s2", KEY_DOUBLE, OFF(move_accel_rad_s2), 0, 1, 1e9, 0, "acceleration limit (rad/s^2)"},
    {"position.j_max_rad_s3", KEY_DOUBLE, OFF(move_jerk_rad_s3), 0, 0, 1e12, 0, "jerk limit (rad/s^3); 0 = a_max varpi_0"},
    {"position.hold_start_s", KEY_DOUBLE, OFF(hold_start_s), 0, 0, 3600, 0, "start of the hold window of the position metrics (s); 0 = none"},
    {"controller.position.gain_per_s", KEY_FLOAT, OFF(position.gain_per_s), 0, 0, BIG, 0, "k_theta (1/s); 0 = the designer's rule k_w/4 and k_theta^2/8"},
    {"controller.position.integral_gain_per_s2", KEY_FLOAT, OFF(position.integral_gain_per_s2), -BIG, 0, BIG, 0, "k_I of the position loop (1/s^2)"},

    {"sensors.adc_bits", KEY_ADC_BITS, OFF(sensors.adc_bits), 0, 0, 16, 0, "ADC resolution: 0 = ideal (no quantisation), or 8..16 bits"},
    {"sensors.current_full_scale_A", KEY_DOUBLE, OFF(sensors.current_full_scale_A), 0, 1, 1e6, 0, "current ADC span +/- this, mid-tread, clips beyond (A)"},
    {"sensors.offset_a_A", KEY_DOUBLE, OFF(sensors.offset_a_A), -1e6, 0, 1e6, 0, "current-sensor offset, phase a (A)"},
    {"sensors.offset_b_A", KEY_DOUBLE, OFF(sensors.offset_b_A), -1e6, 0, 1e6, 0, "current-sensor offset, phase b (A)"},
    {"sensors.gain_error_a", KEY_DOUBLE, OFF(sensors.gain_error_a), -0.5, 1, 0.5, 1, "current-sensor gain error, phase a (fraction)"},
    {"sensors.gain_error_b", KEY_DOUBLE, OFF(sensors.gain_error_b), -0.5, 1, 0.5, 1, "current-sensor gain error, phase b (fraction)"},
    {"sensors.noise_rms_A", KEY_DOUBLE, OFF(sensors.noise_rms_A), 0, 0, 1e6, 0, "Gaussian current noise per phase per sample (A rms)"},
    {"sensors.bus_full_scale_V", KEY_DOUBLE, OFF(sensors.bus_full_scale_V), 0, 1, 1e6, 0, "bus ADC span [0, this] (V)"},
    {"sensors.bus_noise_rms_V", KEY_DOUBLE, OFF(sensors.bus_noise_rms_V), 0, 0, 1e6, 0, "Gaussian bus-voltage noise per sample (V rms)"},

    {"inverter.model", KEY_INVERTER_MODEL, OFF(inverter.model), 0, 0, 0, 0, "averaged | switching"},
    {"inverter.dead_time_s", KEY_DOUBLE, OFF(inverter.dead_time_s), 0, 0, 0.01, 1, "dead time per half-bridge (s), below run.period_s / 4"},

    {"bus.source_resistance_Ohm", KEY_DOUBLE, OFF(bus.source_resistance_Ohm), 0, 0, 1e6, 0, "sag V_bus = run.bus_voltage_V - R i_bus (Ohm)"},
    {"bus.ripple_V", KEY_DOUBLE, OFF(bus.ripple_V), 0, 0, 1e4, 0, "bus ripple amplitude, ripple_V sin(2 pi ripple_Hz t) (V)"},
    {"bus.ripple_Hz", KEY_DOUBLE, OFF(bus.ripple_Hz), 0, 0, 1e6, 0, "bus ripple frequency (Hz)"},
};

const size_t scenario_key_count = sizeof scenario_keys / sizeof scenario_keys[0];
