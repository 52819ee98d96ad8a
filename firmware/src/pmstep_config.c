/* Configuration: validation with one status per cause. */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

#include <math.h> /* isfinite: a classification macro, no libm call */
#include <stddef.h>
#include <string.h> /* memcpy of one float: a load */

/* A duration setting: not negative, and at most PMSTEP_MAX_DURATION_PERIODS periods, so its
 * conversion to a period count (periods_in() in pmstep_core.c) is exact and defined. */
static bool duration_ok(float duration_s, float period_s)
{
    return duration_s >= 0.0f && duration_s / period_s <= PMSTEP_MAX_DURATION_PERIODS;
}

/* Calibration, commissioning, dead time, drift-free gain (times already checked finite). */
static pmstep_status_t validate_calibration(const pmstep_config_t *cfg)
{
    const float s_align_s = cfg->s_align_time_s;
    const float c_align_s = cfg->c_align_time_s - cfg->s_align_time_s;
    const bool window = cfg->steady_state_window_s > 0.0f;
    if (cfg->offset_calibration_time_s < 0.0f || cfg->steady_state_window_s < 0.0f || cfg->inductance_window_s < 0.0f
        || cfg->steady_state_window_s > 0.5f * s_align_s || cfg->steady_state_window_s > 0.5f * c_align_s
        || cfg->inductance_window_s > 0.5f * s_align_s || !duration_ok(cfg->offset_calibration_time_s, cfg->period_s)) {
        return PMSTEP_ERR_CALIBRATION;
    }
    /* What is used must be measured: R and k_M need the windows, L its rise window. */
    if ((cfg->alignment_offset_calibration && !window) || (cfg->use_commissioned_resistance && !window)
        || (cfg->use_commissioned_torque_constant && !window)
        || (cfg->use_commissioned_inductance && !(cfg->inductance_window_s > 0.0f))) {
        return PMSTEP_ERR_CALIBRATION;
    }
    /* The bias option needs its two windows (2 W) in the second half of each alignment, and
     * W/2 of settling at the lower level: at least 5 L/R. */
    if (cfg->voltage_bias_level_fraction < 0.0f || cfg->voltage_bias_level_fraction >= 1.0f
        || (cfg->voltage_bias_level_fraction > 0.0f
            && (!window || cfg->steady_state_window_s > 0.25f * s_align_s
                || cfg->steady_state_window_s > 0.25f * c_align_s
                || cfg->steady_state_window_s * cfg->resistance_ohm < 10.0f * cfg->inductance_h))) {
        return PMSTEP_ERR_CALIBRATION;
    }
    if (cfg->dead_time_s < 0.0f || 2.0f * cfg->dead_time_s >= 0.5f * cfg->period_s
        || cfg->dead_time_current_band_a < 0.0f
        || ((cfg->dead_time_s > 0.0f || cfg->voltage_bias_level_fraction > 0.0f)
            && !(cfg->dead_time_current_band_a >= PMSTEP_MIN_CURRENT_BAND_A
                 && cfg->dead_time_current_band_a <= cfg->max_phase_current_a))) {
        return PMSTEP_ERR_CALIBRATION;
    }
    if (cfg->angle_correction_gain_per_s < 0.0f || cfg->angle_correction_gain_per_s * cfg->period_s >= 0.5f) {
        return PMSTEP_ERR_CALIBRATION;
    }
    return PMSTEP_OK;
}

pmstep_electrical_t pmstep_configured_electrical(const pmstep_config_t *cfg)
{
    pmstep_electrical_t model;
    model.resistance_ohm = cfg->resistance_ohm;
    model.inductance_h = cfg->inductance_h;
    model.torque_constant_nm_per_a = cfg->torque_constant_nm_per_a;
    return model;
}

pmstep_status_t pmstep_validate_config(const pmstep_config_t *cfg)
{
    if (cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    {
        /* Every float of the configuration, by offset: one small table instead of a copy of each. */
        static const unsigned char float_fields[] = {
            offsetof(pmstep_config_t, resistance_ohm), offsetof(pmstep_config_t, inductance_h),
            offsetof(pmstep_config_t, inertia_kg_m2), offsetof(pmstep_config_t, friction_nm_s_per_rad),
            offsetof(pmstep_config_t, torque_constant_nm_per_a), offsetof(pmstep_config_t, period_s),
            offsetof(pmstep_config_t, s_align_time_s), offsetof(pmstep_config_t, c_align_time_s),
            offsetof(pmstep_config_t, s_align_voltage_v), offsetof(pmstep_config_t, c_align_voltage_v),
            offsetof(pmstep_config_t, speed_gain_per_s), offsetof(pmstep_config_t, observer_gain_per_s),
            offsetof(pmstep_config_t, current_gain_per_s), offsetof(pmstep_config_t, adapt_gamma),
            offsetof(pmstep_config_t, adapt_lambda), offsetof(pmstep_config_t, adapt_r),
            offsetof(pmstep_config_t, sat_kappa_rad_per_s), offsetof(pmstep_config_t, reference_bandwidth_rad_per_s),
            offsetof(pmstep_config_t, max_phase_current_a), offsetof(pmstep_config_t, min_bus_voltage_v),
            offsetof(pmstep_config_t, max_bus_voltage_v), offsetof(pmstep_config_t, offset_calibration_time_s),
            offsetof(pmstep_config_t, steady_state_window_s), offsetof(pmstep_config_t, inductance_window_s),
            offsetof(pmstep_config_t, dead_time_s), offsetof(pmstep_config_t, dead_time_current_band_a),
            offsetof(pmstep_config_t, angle_correction_gain_per_s), offsetof(pmstep_config_t, angle_magnitude_bound),
            offsetof(pmstep_config_t, speed_consistency_bound_rad_s),
            offsetof(pmstep_config_t, stall_speed_error_rad_s), offsetof(pmstep_config_t, detection_time_s),
            offsetof(pmstep_config_t, voltage_bias_level_fraction),
            offsetof(pmstep_config_t, observer_residual_bound_a)};
        size_t n;
        for (n = 0; n < sizeof float_fields; ++n) {
            float value;
            memcpy(&value, (const unsigned char *)cfg + float_fields[n], sizeof value);
            if (!isfinite(value)) {
                return PMSTEP_ERR_NONFINITE_PARAMETER;
            }
        }
    }
    if (!(cfg->resistance_ohm > 0.0f)) {
        return PMSTEP_ERR_RESISTANCE;
    }
    if (!(cfg->inductance_h > 0.0f)) {
        return PMSTEP_ERR_INDUCTANCE;
    }
    if (!(cfg->inertia_kg_m2 > 0.0f)) {
        return PMSTEP_ERR_INERTIA;
    }
    if (!(cfg->torque_constant_nm_per_a > 0.0f)) {
        return PMSTEP_ERR_TORQUE_CONSTANT;
    }
    if (cfg->friction_nm_s_per_rad < 0.0f) {
        return PMSTEP_ERR_FRICTION;
    }
    if (cfg->pole_pairs < 1) {
        return PMSTEP_ERR_POLE_PAIRS;
    }
    if (!(cfg->period_s >= PMSTEP_MIN_PERIOD_S && cfg->period_s <= PMSTEP_MAX_PERIOD_S)) {
        return PMSTEP_ERR_PERIOD;
    }
    if (!(cfg->speed_gain_per_s > 0.0f) || !(cfg->observer_gain_per_s > 0.0f) || !(cfg->current_gain_per_s > 0.0f)
        || !(cfg->adapt_gamma > 0.0f) || !(cfg->adapt_lambda > 0.0f) || !(cfg->adapt_r > 0.0f)
        || !(cfg->sat_kappa_rad_per_s > 0.0f)) {
        return PMSTEP_ERR_GAIN;
    }
    {
        /* Forward-Euler observer and current loop: keep their poles well inside the unit circle. */
        const float r_over_l = cfg->resistance_ohm / cfg->inductance_h;
        if ((r_over_l + cfg->observer_gain_per_s) * cfg->period_s >= 0.5f
            || (r_over_l + cfg->current_gain_per_s) * cfg->period_s >= 0.5f) {
            return PMSTEP_ERR_PERIOD_TOO_LONG;
        }
    }
    if (!(cfg->reference_bandwidth_rad_per_s > 0.0f) || cfg->reference_bandwidth_rad_per_s * cfg->period_s > 0.5f) {
        return PMSTEP_ERR_REFERENCE_BANDWIDTH;
    }
    if (cfg->computational_delay_periods > 1u) {
        return PMSTEP_ERR_DELAY;
    }
    if (!(cfg->max_phase_current_a > 0.0f) || !(cfg->min_bus_voltage_v > 0.0f)
        || !(cfg->max_bus_voltage_v > cfg->min_bus_voltage_v)) {
        return PMSTEP_ERR_LIMITS;
    }
    if (!(cfg->s_align_voltage_v > 0.0f) || !(cfg->c_align_voltage_v > 0.0f)
        || cfg->s_align_voltage_v > cfg->min_bus_voltage_v || cfg->c_align_voltage_v > cfg->min_bus_voltage_v) {
        return PMSTEP_ERR_ALIGNMENT_VOLTAGE;
    }
    if (cfg->s_align_voltage_v >= cfg->max_phase_current_a * cfg->resistance_ohm
        || cfg->c_align_voltage_v >= cfg->max_phase_current_a * cfg->resistance_ohm) {
        return PMSTEP_ERR_ALIGNMENT_CURRENT;
    }
    if (!(cfg->s_align_time_s >= cfg->period_s) || !(cfg->c_align_time_s - cfg->s_align_time_s >= cfg->period_s)
        || !duration_ok(cfg->c_align_time_s, cfg->period_s)) {
        return PMSTEP_ERR_ALIGNMENT_TIME;
    }
    if (validate_calibration(cfg) != PMSTEP_OK) {
        return PMSTEP_ERR_CALIBRATION;
    }
    {
        /* The persistence is 0 (only with every detector off) or at least 4 periods. */
        const bool any_detector = cfg->angle_magnitude_bound > 0.0f || cfg->speed_consistency_bound_rad_s > 0.0f
                                  || cfg->stall_speed_error_rad_s > 0.0f || cfg->observer_residual_bound_a > 0.0f;
        if (cfg->angle_magnitude_bound < 0.0f || cfg->speed_consistency_bound_rad_s < 0.0f
            || cfg->stall_speed_error_rad_s < 0.0f || cfg->observer_residual_bound_a < 0.0f
            || !(cfg->detection_time_s >= 4.0f * cfg->period_s || (cfg->detection_time_s == 0.0f && !any_detector))
            || !duration_ok(cfg->detection_time_s, cfg->period_s)) {
            return PMSTEP_ERR_DETECTION;
        }
    }
    {
        /* Condition (4): k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) > 0. */
        const float r = cfg->resistance_ohm;
        const float margin = cfg->torque_constant_nm_per_a * cfg->c_align_voltage_v
                                 / ((float)cfg->pole_pairs * cfg->inductance_h * r)
                             - (cfg->s_align_voltage_v * cfg->s_align_voltage_v
                                + cfg->c_align_voltage_v * cfg->c_align_voltage_v)
                                   / (2.0f * r * r);
        if (!(margin > 0.0f)) {
            return PMSTEP_ERR_ALIGNMENT_CONDITION;
        }
    }
    return pmstep_derived_coefficients_finite(cfg) ? PMSTEP_OK : PMSTEP_ERR_DERIVED_NONFINITE;
}
