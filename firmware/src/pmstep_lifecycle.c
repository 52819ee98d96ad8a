/* Lifecycle and commands: init (validation, every coefficient derived from the configuration),
 * reset, start, stop, clear_fault and the set-points; the step is in pmstep_core.c. */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

#include <stddef.h>
#include <string.h>

/* Coefficients of the angle, observer and law for the model @p model. */
void pmstep_apply_model(pmstep_t *inst, const pmstep_electrical_t *model)
{
    pmstep_angle_coeffs_init(&inst->angle_coeffs, inst->cfg, model);
    pmstep_observer_coeffs_init(&inst->observer_coeffs, inst->cfg, model);
    pmstep_law_coeffs_init(&inst->law_coeffs, inst->cfg, model);
}

/* Everything init derives from @p cfg: the coefficients of each block for the configured model,
 * period counts, the detection and actuation constants. */
static void derive(pmstep_t *inst, const pmstep_config_t *cfg)
{
    const pmstep_electrical_t configured = pmstep_configured_electrical(cfg);
    const float period_s = cfg->timing.period_s;
    pmstep_commission_plan_t *plan = &inst->commission_plan;
    inst->cfg = cfg;
    pmstep_ref_coeffs_init(&inst->ref_coeffs, cfg->gains.reference_bandwidth_rad_s, period_s);
    pmstep_apply_model(inst, &configured);
    plan->s_lead_in_steps = pmstep_periods_in(cfg->alignment.s_lead_in_time_s, period_s);
    plan->s_align_steps = pmstep_periods_in(cfg->alignment.s_align_time_s, period_s);
    plan->c_align_end_step = pmstep_periods_in(cfg->alignment.c_align_time_s, period_s);
    plan->window_steps = pmstep_periods_in(cfg->commissioning.steady_state_window_s, period_s);
    plan->inductance_steps = pmstep_periods_in(cfg->commissioning.inductance_window_s, period_s);
    plan->inductance_start_step = plan->s_lead_in_steps + 2u + cfg->timing.computational_delay_periods;
    plan->offsets_from_alignment = cfg->commissioning.alignment_offset_calibration;
    plan->bias_estimation = cfg->commissioning.voltage_bias_level_fraction > 0.0f;
    plan->identification_steps = pmstep_periods_in(cfg->commissioning.identification_time_s, period_s);
    inst->offset_cal_steps = pmstep_periods_in(cfg->commissioning.offset_calibration_time_s, period_s);
    inst->optional_inputs = cfg->known_load_mode || cfg->inverter.phase_voltage_sensing;
    inst->robust_corrections = (cfg->gains.angle_correction_gain_per_s > 0.0f) || (cfg->gains.emf_angle_gain_per_s > 0.0f)
                               || (cfg->gains.transient_observer_boost > 0.0f);
    inst->angle_smoothing = cfg->gains.angle_smoothing > 0.0f;
    pmstep_detect_coeffs_init(&inst->detect_coeffs, cfg);
    pmstep_continuity_coeffs_init(&inst->continuity_coeffs, cfg);
    pmstep_actuate_coeffs_init(&inst->actuate_coeffs, cfg);
    inst->voltage_corrected = inst->actuate_coeffs.sensed || inst->actuate_coeffs.compensate;
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

bool pmstep_derived_coefficients_finite(const pmstep_config_t *cfg)
{
    pmstep_t scratch; /* init's derivation, on the stack of the caller of init/validate */
    derive(&scratch, cfg);
    return floats_finite(&scratch.ref_coeffs, sizeof scratch.ref_coeffs / sizeof(float))
           && floats_finite(&scratch.angle_coeffs, sizeof scratch.angle_coeffs / sizeof(float))
           && floats_finite(&scratch.observer_coeffs, sizeof scratch.observer_coeffs / sizeof(float))
           && floats_finite(&scratch.law_coeffs, offsetof(pmstep_law_coeffs_t, linear_speed_term) / sizeof(float))
           && floats_finite(&scratch.detect_coeffs.alpha, 3u)          /* alpha, angle step, consistency bound */
           && floats_finite(&scratch.actuate_coeffs.dead_time_duty, 2u); /* duty, 1/band */
}

pmstep_status_t pmstep_init(pmstep_t *inst, const pmstep_config_t *cfg)
{
    pmstep_status_t status;
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    status = pmstep_validate_config(cfg);
    if (status != PMSTEP_OK) {
        return status;
    }
    derive(inst, cfg);
    pmstep_reset(inst);
    return PMSTEP_OK;
}

/* Forgets what the last alignment measured: offsets 0, the configured model, sums cleared. */
static void clear_commissioning(pmstep_t *inst)
{
    const pmstep_electrical_t configured = pmstep_configured_electrical(inst->cfg);
    memset(&inst->commissioning, 0, sizeof inst->commissioning);
    inst->commissioning.phase_a_current_scale = 1.0f;
    inst->commissioning.equilibrium_cos = 1.0f;
    pmstep_commission_clear(&inst->scratch.sums);
    pmstep_apply_model(inst, &configured);
}

/* Clears the dynamic state of the strategy; keeps commands (targets) untouched. */
void pmstep_clear_dynamic_state(pmstep_t *inst)
{
    inst->mode_step = 0u;
    inst->run_started = false;
    inst->estimate_kept = false;
    inst->hold.active = false;
    inst->hold.standstill_armed = false;
    inst->hold.standstill_engaged = false;
    inst->hold.standstill_settled = false;
    pmstep_angle_start(&inst->angle, 0.0f, 0.0f);
    pmstep_observer_start(&inst->observer, 0.0f, 0.0f);
    pmstep_actuate_reset(&inst->actuator);
    memset(&inst->scratch.sums.continuity, 0, sizeof inst->scratch.sums.continuity); /* RUN's state may be there */
}

void pmstep_reset(pmstep_t *inst)
{
    inst->mode = PMSTEP_MODE_IDLE;
    inst->fault = PMSTEP_FAULT_NONE;
    inst->fault_step = 0u;
    inst->step_count = 0u;
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pmstep_ref_reset(&inst->i_d_ref, 0.0f);
    pmstep_clear_dynamic_state(inst);
    clear_commissioning(inst); /* the scratch union holds the sums until t_c; RUN's start sets up the rest */
}

pmstep_status_t pmstep_start(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_IDLE) {
        return PMSTEP_ERR_BAD_MODE;
    }
    pmstep_clear_dynamic_state(inst);
    clear_commissioning(inst);
    inst->mode = inst->offset_cal_steps > 0u ? PMSTEP_MODE_OFFSET_CAL : PMSTEP_MODE_S_ALIGN;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_stop(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode == PMSTEP_MODE_FAULT) {
        return PMSTEP_ERR_BAD_MODE;
    }
    pmstep_clear_dynamic_state(inst);
    inst->mode = PMSTEP_MODE_IDLE;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_clear_fault(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_FAULT) {
        return PMSTEP_ERR_BAD_MODE;
    }
    pmstep_clear_dynamic_state(inst);
    inst->fault = PMSTEP_FAULT_NONE;
    inst->mode = PMSTEP_MODE_IDLE;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_set_speed_target(pmstep_t *inst, float target_rad_s, float ramp_rate_rad_s2)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pmstep_all_finite4(target_rad_s, ramp_rate_rad_s2, 0.0f, 0.0f) || !(ramp_rate_rad_s2 > 0.0f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_standstill_command(inst, target_rad_s); /* ends a hold; a zero command keeps the standstill's */
    pmstep_ref_set_target(&inst->speed_ref, target_rad_s, ramp_rate_rad_s2);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_set_id_target(pmstep_t *inst, float target_A)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pmstep_all_finite4(target_A, 0.0f, 0.0f, 0.0f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_ref_set_target(&inst->i_d_ref, target_A, 0.0f);
    return PMSTEP_OK;
}
