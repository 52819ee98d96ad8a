/* Lifecycle and commands: init (the settings checked, the coefficients derived: pmstep_derive.c),
 * reset, start, stop, clear_fault and the set-points; the step is in pmstep_core.c. */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

#include <stddef.h>
#include <string.h>

pmstep_status_t pmstep_init(pmstep_t *inst, const pmstep_config_t *cfg)
{
    pmstep_derived_t derived;
    pmstep_status_t status;
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    /* The settings' rules, then the one derivation, checked as validation checks its own; the
     * instance is written only once both hold (a refused init leaves a running one as it was). */
    status = pmstep_check_settings(cfg);
    if (status == PMSTEP_OK) {
        pmstep_derive(&derived, cfg);
        if (pmstep_derived_finite(&derived)) {
            inst->cfg = cfg;
            inst->derived = derived;
            pmstep_reset(inst);
        } else {
            status = PMSTEP_ERR_DERIVED_NONFINITE;
        }
    }
    return status;
}

/* Forgets what the last alignment measured: offsets 0, the configured model, sums cleared. */
static void clear_commissioning(pmstep_t *inst)
{
    const pmstep_electrical_t configured = pmstep_configured_electrical(inst->cfg);
    memset(&inst->commissioning, 0, sizeof inst->commissioning);
    inst->commissioning.phase_a_current_scale = 1.0f;
    inst->commissioning.equilibrium_cos = 1.0f;
    pmstep_commission_clear(&inst->scratch.sums);
    pmstep_apply_model(&inst->derived, inst->cfg, &configured);
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
    inst->weakening.command_A = 0.0f;
    inst->weakening.weakening_A = 0.0f;
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
    inst->mode = inst->derived.offset_cal_steps > 0u ? PMSTEP_MODE_OFFSET_CAL : PMSTEP_MODE_S_ALIGN;
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
    inst->weakening.command_A = target_A;
    pmstep_ref_set_target(&inst->i_d_ref, target_A + inst->weakening.weakening_A, 0.0f);
    return PMSTEP_OK;
}
