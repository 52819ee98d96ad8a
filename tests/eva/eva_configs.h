/* Every reference the Frama-C EVA harnesses make to a field of pmstep_config_t lives in this
 * file, so a rename of the configuration is an edit here only. */
#ifndef PMSTEP_EVA_CONFIGS_H
#define PMSTEP_EVA_CONFIGS_H

#include <float.h>
#include <stddef.h>

#include "__fc_builtin.h"
#include "pmstep/pmstep.h"
#include "pmstep_test_configs.h"

/* The configurations the step harnesses analyse. */
static pmstep_config_t eva_paper_config(void) { return pmstep_paper_config(); }

/* Every optional feature on (tests/include/pmstep_test_configs.h, shared with the fuzzer). */
static pmstep_config_t eva_features_config(void) { return pmstep_test_features_config(); }

/* As eva_features_config in known-load mode (Remark 1), R from one steady state per phase
 * (no voltage bias level), no offset calibration before the alignment. */
static pmstep_config_t eva_known_load_config(void)
{
    pmstep_config_t cfg = eva_features_config();
    cfg.known_load_mode = true;
    cfg.standstill.hold_current_A = 0.0f;     /* a vector hold needs (6) */
    cfg.standstill.vector_speed_rad_s = 0.0f; /* and the low-speed drive turns it */
    cfg.commissioning.voltage_bias_level_fraction = 0.0f;
    cfg.commissioning.offset_calibration_time_s = 0.0f;
    cfg.timing.computational_delay_periods = 0u;
    return cfg;
}

/* As eva_features_config with phase-voltage sensing: the sensed voltages in the flux integrals,
 * the observer and the Remark 2 steady states, their offsets from the offset calibration. */
static pmstep_config_t eva_sensed_config(void)
{
    pmstep_config_t cfg = eva_features_config();
    cfg.inverter.phase_voltage_sensing = true;
    return cfg;
}

/* Any finite float. */
static float eva_any_finite(void) { return Frama_C_float_interval(-FLT_MAX, FLT_MAX); }

/* Every field of a configuration arbitrary: floats any finite value, integers any value,
 * bools either. */
static void eva_any_config(pmstep_config_t *cfg)
{
    cfg->motor.resistance_Ohm = eva_any_finite();
    cfg->motor.inductance_H = eva_any_finite();
    cfg->motor.inertia_kgm2 = eva_any_finite();
    cfg->motor.friction_Nms_rad = eva_any_finite();
    cfg->motor.torque_constant_Nm_A = eva_any_finite();
    cfg->motor.pole_pairs = Frama_C_int_interval(INT32_MIN, INT32_MAX);
    cfg->timing.period_s = eva_any_finite();
    cfg->timing.computational_delay_periods = Frama_C_unsigned_int_interval(0u, UINT32_MAX);
    cfg->alignment.s_align_time_s = eva_any_finite();
    cfg->alignment.c_align_time_s = eva_any_finite();
    cfg->alignment.s_lead_in_time_s = eva_any_finite();
    cfg->alignment.s_align_voltage_V = eva_any_finite();
    cfg->alignment.c_align_voltage_V = eva_any_finite();
    cfg->gains.speed_gain_per_s = eva_any_finite();
    cfg->gains.observer_gain_per_s = eva_any_finite();
    cfg->gains.current_gain_per_s = eva_any_finite();
    cfg->gains.adapt_gamma = eva_any_finite();
    cfg->gains.adapt_lambda = eva_any_finite();
    cfg->gains.adapt_r = eva_any_finite();
    cfg->gains.sat_kappa_rad_s = eva_any_finite();
    cfg->gains.reference_bandwidth_rad_s = eva_any_finite();
    cfg->known_load_mode = Frama_C_nondet(0, 1) != 0;
    cfg->limits.max_phase_current_A = eva_any_finite();
    cfg->limits.min_bus_voltage_V = eva_any_finite();
    cfg->limits.max_bus_voltage_V = eva_any_finite();
    cfg->limits.current_sense_range_A = eva_any_finite();
    cfg->limits.bus_sense_range_V = eva_any_finite();
    cfg->commissioning.offset_calibration_time_s = eva_any_finite();
    cfg->commissioning.alignment_offset_calibration = Frama_C_nondet(0, 1) != 0;
    cfg->commissioning.steady_state_window_s = eva_any_finite();
    cfg->commissioning.inductance_window_s = eva_any_finite();
    cfg->commissioning.use_measured_resistance = Frama_C_nondet(0, 1) != 0;
    cfg->commissioning.use_measured_inductance = Frama_C_nondet(0, 1) != 0;
    cfg->commissioning.use_measured_torque_constant = Frama_C_nondet(0, 1) != 0;
    cfg->commissioning.voltage_bias_level_fraction = eva_any_finite();
    cfg->inverter.dead_time_s = eva_any_finite();
    cfg->inverter.dead_time_current_band_A = eva_any_finite();
    cfg->inverter.phase_voltage_sensing = Frama_C_nondet(0, 1) != 0;
    cfg->inverter.ripple_dead_zone = Frama_C_nondet(0, 1) != 0;
    cfg->gains.angle_correction_gain_per_s = eva_any_finite();
    cfg->gains.current_integral_gain_per_s2 = eva_any_finite();
    cfg->gains.current_integral_gain_q_per_s2 = eva_any_finite();
    cfg->gains.emf_angle_gain_per_s = eva_any_finite();
    cfg->gains.emf_angle_corner_rad_s = eva_any_finite();
    cfg->gains.angle_smoothing = eva_any_finite();
    cfg->gains.transient_observer_boost = eva_any_finite();
    cfg->gains.detent_fade_speed_rad_s = eva_any_finite();
    cfg->motor.detent_torque_Nm = eva_any_finite();
    cfg->motor.rated_current_A = eva_any_finite();
    cfg->detection.angle_magnitude_bound = eva_any_finite();
    cfg->detection.speed_consistency_bound_rad_s = eva_any_finite();
    cfg->detection.stall_speed_error_rad_s = eva_any_finite();
    cfg->detection.observer_residual_bound_A = eva_any_finite();
    cfg->detection.persistence_s = eva_any_finite();
    cfg->detection.max_realignments = Frama_C_unsigned_int_interval(0u, UINT32_MAX);
    cfg->commissioning.identification_time_s = eva_any_finite();
    cfg->commissioning.identification_min_speed_rad_s = eva_any_finite();
    cfg->commissioning.use_identified_mechanics = Frama_C_nondet(0, 1) != 0;
    cfg->standstill.hold_current_A = eva_any_finite();
    cfg->standstill.vector_speed_rad_s = eva_any_finite();
    cfg->standstill.stops_only = Frama_C_nondet(0, 1) != 0;
    cfg->field_weakening.max_current_A = eva_any_finite();
    cfg->field_weakening.modulation = eva_any_finite();
    cfg->field_weakening.gain_A_per_s = eva_any_finite();
}

#endif /* PMSTEP_EVA_CONFIGS_H */
