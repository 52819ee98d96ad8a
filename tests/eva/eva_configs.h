/* Every reference the Frama-C EVA harnesses make to a field of pmstep_config_t lives in this
 * file, so a rename of the configuration is an edit here only. */
#ifndef PMSTEP_EVA_CONFIGS_H
#define PMSTEP_EVA_CONFIGS_H

#include <float.h>
#include <stddef.h>

#include "__fc_builtin.h"
#include "pmstep/pmstep.h"

/* The configurations the step harnesses analyse. */
static pmstep_config_t eva_paper_config(void)
{
    return pmstep_paper_config();
}

/* Every optional feature on: offset calibration, alignment windows with the voltage bias,
 * inductance window, commissioned R, L, k_M used, dead-time compensation, drift-free angle,
 * every detector (the paper's bounds), re-alignments, one period of delay. */
static pmstep_config_t eva_features_config(void)
{
    pmstep_config_t cfg = pmstep_paper_config();
    cfg.offset_calibration_time_s = 0.005f;
    cfg.alignment_offset_calibration = true;
    cfg.steady_state_window_s = 0.05f;
    cfg.voltage_bias_level_fraction = 0.5f;
    cfg.inductance_window_s = 0.0005f;
    cfg.use_commissioned_resistance = true;
    cfg.use_commissioned_inductance = true;
    cfg.use_commissioned_torque_constant = true;
    cfg.dead_time_s = 1e-6f;
    cfg.dead_time_current_band_a = 0.005f;
    cfg.angle_correction_gain_per_s = 20.0f;
    cfg.max_realignments = 2u;
    cfg.computational_delay_periods = 1u;
    return cfg;
}

/* As eva_features_config in known-load mode (Remark 1), R from one steady state per phase
 * (no voltage bias level), no offset calibration before the alignment. */
static pmstep_config_t eva_known_load_config(void)
{
    pmstep_config_t cfg = eva_features_config();
    cfg.known_load_mode = true;
    cfg.voltage_bias_level_fraction = 0.0f;
    cfg.offset_calibration_time_s = 0.0f;
    cfg.computational_delay_periods = 0u;
    return cfg;
}

/* Any finite float. */
static float eva_any_finite(void)
{
    return Frama_C_float_interval(-FLT_MAX, FLT_MAX);
}

/* Every field of a configuration arbitrary: floats any finite value, integers any value,
 * bools either. */
static void eva_any_config(pmstep_config_t *cfg)
{
    cfg->resistance_ohm = eva_any_finite();
    cfg->inductance_h = eva_any_finite();
    cfg->inertia_kg_m2 = eva_any_finite();
    cfg->friction_nm_s_per_rad = eva_any_finite();
    cfg->torque_constant_nm_per_a = eva_any_finite();
    cfg->pole_pairs = Frama_C_int_interval(INT32_MIN, INT32_MAX);
    cfg->period_s = eva_any_finite();
    cfg->computational_delay_periods = Frama_C_unsigned_int_interval(0u, UINT32_MAX);
    cfg->s_align_time_s = eva_any_finite();
    cfg->c_align_time_s = eva_any_finite();
    cfg->s_align_voltage_v = eva_any_finite();
    cfg->c_align_voltage_v = eva_any_finite();
    cfg->speed_gain_per_s = eva_any_finite();
    cfg->observer_gain_per_s = eva_any_finite();
    cfg->current_gain_per_s = eva_any_finite();
    cfg->adapt_gamma = eva_any_finite();
    cfg->adapt_lambda = eva_any_finite();
    cfg->adapt_r = eva_any_finite();
    cfg->sat_kappa_rad_per_s = eva_any_finite();
    cfg->reference_bandwidth_rad_per_s = eva_any_finite();
    cfg->known_load_mode = Frama_C_nondet(0, 1) != 0;
    cfg->max_phase_current_a = eva_any_finite();
    cfg->min_bus_voltage_v = eva_any_finite();
    cfg->max_bus_voltage_v = eva_any_finite();
    cfg->offset_calibration_time_s = eva_any_finite();
    cfg->alignment_offset_calibration = Frama_C_nondet(0, 1) != 0;
    cfg->steady_state_window_s = eva_any_finite();
    cfg->inductance_window_s = eva_any_finite();
    cfg->use_commissioned_resistance = Frama_C_nondet(0, 1) != 0;
    cfg->use_commissioned_inductance = Frama_C_nondet(0, 1) != 0;
    cfg->use_commissioned_torque_constant = Frama_C_nondet(0, 1) != 0;
    cfg->voltage_bias_level_fraction = eva_any_finite();
    cfg->dead_time_s = eva_any_finite();
    cfg->dead_time_current_band_a = eva_any_finite();
    cfg->angle_correction_gain_per_s = eva_any_finite();
    cfg->angle_magnitude_bound = eva_any_finite();
    cfg->speed_consistency_bound_rad_s = eva_any_finite();
    cfg->stall_speed_error_rad_s = eva_any_finite();
    cfg->observer_residual_bound_a = eva_any_finite();
    cfg->detection_time_s = eva_any_finite();
    cfg->max_realignments = Frama_C_unsigned_int_interval(0u, UINT32_MAX);
}

#endif /* PMSTEP_EVA_CONFIGS_H */
