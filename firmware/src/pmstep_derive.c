/* Derivation: everything init computes from the configuration once (pmstep_derived_t), shared by
 * init, which derives into the instance, and validation, which derives to check it finite. */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

#include <stddef.h>
#include <string.h>

void pmstep_apply_model(pmstep_derived_t *derived, const pmstep_config_t *cfg, const pmstep_electrical_t *model)
{
    pmstep_angle_coeffs_init(&derived->angle_coeffs, cfg, model);
    pmstep_observer_coeffs_init(&derived->observer_coeffs, cfg, model);
    pmstep_law_coeffs_init(&derived->law_coeffs, cfg, model);
}

void pmstep_derive(pmstep_derived_t *derived, const pmstep_config_t *cfg)
{
    const pmstep_electrical_t configured = pmstep_configured_electrical(cfg);
    const float period_s = cfg->timing.period_s;
    pmstep_commission_plan_t *plan = &derived->commission_plan;
    pmstep_ref_coeffs_init(&derived->ref_coeffs, cfg->gains.reference_bandwidth_rad_s, period_s);
    pmstep_apply_model(derived, cfg, &configured);
    plan->s_lead_in_steps = pmstep_periods_in(cfg->alignment.s_lead_in_time_s, period_s);
    plan->s_align_steps = pmstep_periods_in(cfg->alignment.s_align_time_s, period_s);
    plan->c_align_end_step = pmstep_periods_in(cfg->alignment.c_align_time_s, period_s);
    plan->window_steps = pmstep_periods_in(cfg->commissioning.steady_state_window_s, period_s);
    plan->inductance_steps = pmstep_periods_in(cfg->commissioning.inductance_window_s, period_s);
    plan->inductance_start_step = plan->s_lead_in_steps + 2u + cfg->timing.computational_delay_periods;
    plan->offsets_from_alignment = cfg->commissioning.alignment_offset_calibration;
    plan->bias_estimation = cfg->commissioning.voltage_bias_level_fraction > 0.0f;
    plan->identification_steps = pmstep_periods_in(cfg->commissioning.identification_time_s, period_s);
    derived->offset_cal_steps = pmstep_periods_in(cfg->commissioning.offset_calibration_time_s, period_s);
    derived->optional_inputs = cfg->known_load_mode || cfg->inverter.phase_voltage_sensing;
    derived->robust_corrections = (cfg->gains.angle_correction_gain_per_s > 0.0f)
                                  || (cfg->gains.emf_angle_gain_per_s > 0.0f)
                                  || (cfg->gains.transient_observer_boost > 0.0f);
    derived->angle_smoothing = cfg->gains.angle_smoothing > 0.0f;
    pmstep_detect_coeffs_init(&derived->detect_coeffs, cfg);
    pmstep_continuity_coeffs_init(&derived->continuity_coeffs, cfg);
    pmstep_actuate_coeffs_init(&derived->actuate_coeffs, cfg);
    pmstep_weakening_coeffs_init(&derived->weakening_coeffs, cfg);
    derived->voltage_corrected = derived->actuate_coeffs.sensed || derived->actuate_coeffs.compensate;
}

/* True if the @p count floats stored from @p first on (a run of float members) are all finite. */
static bool floats_finite(const void *first, size_t count)
{
    const unsigned char *bytes = (const unsigned char *)first;
    float sum = 0.0f;
    size_t n;
    for (n = 0; n < count; ++n) {
        float value;
        memcpy(&value, bytes + n * sizeof value, sizeof value);
        sum += value - value; /* 0 for finite values, NaN otherwise */
    }
    return sum == 0.0f;
}

bool pmstep_derived_finite(const pmstep_derived_t *derived)
{
    return floats_finite(&derived->ref_coeffs, sizeof derived->ref_coeffs / sizeof(float))
           && floats_finite(&derived->angle_coeffs, sizeof derived->angle_coeffs / sizeof(float))
           && floats_finite(&derived->observer_coeffs, sizeof derived->observer_coeffs / sizeof(float))
           && floats_finite(&derived->law_coeffs, offsetof(pmstep_law_coeffs_t, linear_speed_term) / sizeof(float))
           && floats_finite(&derived->detect_coeffs.alpha, 3u)           /* alpha, angle step, consistency bound */
           && floats_finite(&derived->actuate_coeffs.dead_time_duty, 2u) /* duty, 1/band */
           && floats_finite(&derived->weakening_coeffs.modulation_squared, 3u); /* m^2, g T_c, I_w */
}
