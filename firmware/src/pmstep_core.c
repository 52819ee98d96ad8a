/* Mode machine, protections and the control step: strategy of Section III.A,
 * s-alignment (3) -> c-alignment (5) -> controller (6) (or (13), Remark 1). */
#include "pmstep/pmstep.h"

#include <math.h> /* isfinite: a classification macro, no libm call */
#include <stddef.h>

static uint32_t periods_in(float duration_s, float period_s)
{
    return (uint32_t)(duration_s / period_s + 0.5f);
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
    inst->cfg = cfg;
    pmstep_ref_coeffs_init(&inst->ref_coeffs, cfg->reference_bandwidth_rad_per_s, cfg->period_s);
    pmstep_angle_coeffs_init(&inst->angle_coeffs, cfg);
    pmstep_observer_coeffs_init(&inst->observer_coeffs, cfg);
    pmstep_law_coeffs_init(&inst->law_coeffs, cfg);
    inst->s_align_steps = periods_in(cfg->s_align_time_s, cfg->period_s);
    inst->c_align_end_step = periods_in(cfg->c_align_time_s, cfg->period_s);
    pmstep_reset(inst);
    return PMSTEP_OK;
}

/* Clears the dynamic state of the strategy; keeps commands (targets) untouched. */
static void clear_dynamic_state(pmstep_t *inst)
{
    inst->mode_step = 0u;
    inst->run_started = false;
    pmstep_angle_start(&inst->angle, 0.0f, 0.0f);
    pmstep_observer_start(&inst->observer, 0.0f, 0.0f);
    inst->u_applied_a_v = 0.0f;
    inst->u_applied_b_v = 0.0f;
    inst->u_pending_a_v = 0.0f;
    inst->u_pending_b_v = 0.0f;
}

void pmstep_reset(pmstep_t *inst)
{
    inst->mode = PMSTEP_MODE_IDLE;
    inst->fault = PMSTEP_FAULT_NONE;
    inst->fault_step = 0u;
    inst->step_count = 0u;
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pmstep_ref_reset(&inst->i_d_ref, 0.0f);
    pmstep_ref_reset(&inst->known_load_filter, 0.0f);
    clear_dynamic_state(inst);
}

pmstep_status_t pmstep_start(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_IDLE) {
        return PMSTEP_ERR_BAD_MODE;
    }
    clear_dynamic_state(inst);
    inst->mode = PMSTEP_MODE_S_ALIGN;
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
    clear_dynamic_state(inst);
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
    clear_dynamic_state(inst);
    inst->fault = PMSTEP_FAULT_NONE;
    inst->mode = PMSTEP_MODE_IDLE;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_set_speed_target(pmstep_t *inst, float target_rad_s, float ramp_rate_rad_s2)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!isfinite(target_rad_s) || !isfinite(ramp_rate_rad_s2) || !(ramp_rate_rad_s2 > 0.0f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_ref_set_target(&inst->speed_ref, target_rad_s, ramp_rate_rad_s2);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_set_id_target(pmstep_t *inst, float target_a)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!isfinite(target_a)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_ref_set_target(&inst->i_d_ref, target_a, 0.0f);
    return PMSTEP_OK;
}

static float abs_f(float x)
{
    return x < 0.0f ? -x : x;
}

/* Protections, checked while the bridge may be on. */
static pmstep_fault_t check_measurements(const pmstep_config_t *cfg, const pmstep_meas_t *meas)
{
    if (!isfinite(meas->i_a_a) || !isfinite(meas->i_b_a) || !isfinite(meas->bus_voltage_v)
        || (cfg->known_load_mode && !isfinite(meas->load_torque_nm))) {
        return PMSTEP_FAULT_MEASUREMENT_NONFINITE;
    }
    if (abs_f(meas->i_a_a) > cfg->max_phase_current_a || abs_f(meas->i_b_a) > cfg->max_phase_current_a) {
        return PMSTEP_FAULT_OVERCURRENT;
    }
    if (meas->bus_voltage_v < cfg->min_bus_voltage_v) {
        return PMSTEP_FAULT_BUS_UNDERVOLTAGE;
    }
    if (meas->bus_voltage_v > cfg->max_bus_voltage_v) {
        return PMSTEP_FAULT_BUS_OVERVOLTAGE;
    }
    return PMSTEP_FAULT_NONE;
}

static void latch_fault(pmstep_t *inst, pmstep_fault_t fault)
{
    clear_dynamic_state(inst);
    inst->mode = PMSTEP_MODE_FAULT;
    inst->fault = fault;
    inst->fault_step = inst->step_count;
}

/* Starts controller (6) at t_c: phi = 0, i-hat = i(t_c), w-hat = T_L-hat = 0, references from 0. */
static void start_run(pmstep_t *inst, const pmstep_meas_t *meas)
{
    const pmstep_ref_t speed_cmd = inst->speed_ref;
    const pmstep_ref_t i_d_cmd = inst->i_d_ref;
    pmstep_angle_start(&inst->angle, meas->i_a_a, meas->i_b_a);
    pmstep_observer_start(&inst->observer, meas->i_a_a, meas->i_b_a);
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pmstep_ref_set_target(&inst->speed_ref, speed_cmd.target, speed_cmd.ramp_rate_per_s);
    pmstep_ref_reset(&inst->i_d_ref, 0.0f);
    pmstep_ref_set_target(&inst->i_d_ref, i_d_cmd.target, 0.0f);
    pmstep_ref_reset(&inst->known_load_filter, inst->cfg->known_load_mode ? meas->load_torque_nm : 0.0f);
    inst->run_started = true;
}

/* Controller (6) / (13) for one sample; writes the unlimited voltage and telemetry. */
static void run_controller(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out,
                           pmstep_observer_input_t *obs_in, pmstep_observer_mech_rates_t *mech)
{
    const bool known_load = inst->cfg->known_load_mode;
    const pmstep_ref_out_t speed_ref = pmstep_ref_output(&inst->ref_coeffs, &inst->speed_ref);
    const pmstep_ref_out_t i_d_ref = pmstep_ref_output(&inst->ref_coeffs, &inst->i_d_ref);
    const pmstep_ref_out_t load_ref = pmstep_ref_output(&inst->ref_coeffs, &inst->known_load_filter);
    pmstep_law_refs_t refs;
    float cos_hat;
    float sin_hat;
    float i_d;
    float i_q;
    float load_nm;
    float load_rate;
    float i_q_ref;
    float i_q_ref_rate;

    if (!inst->run_started) {
        start_run(inst, meas);
    } else {
        pmstep_angle_update(&inst->angle, &inst->angle_coeffs, meas->i_a_a, meas->i_b_a,
                            inst->u_applied_a_v, inst->u_applied_b_v);
    }
    pmstep_angle_estimate(&inst->angle, &inst->angle_coeffs, meas->i_a_a, meas->i_b_a, &cos_hat, &sin_hat);
    pmstep_park(cos_hat, sin_hat, meas->i_a_a, meas->i_b_a, &i_d, &i_q);

    refs.speed_ref_rad_s = speed_ref.value;
    refs.speed_ref_rate = speed_ref.rate;
    refs.speed_ref_accel = speed_ref.accel;
    refs.i_d_ref_a = i_d_ref.value;
    refs.i_d_ref_rate = i_d_ref.rate;

    load_nm = known_load ? load_ref.value : inst->observer.load_hat_nm;
    i_q_ref = pmstep_law_iq_ref(&inst->law_coeffs, &refs, inst->observer.speed_hat_rad_s, load_nm);

    obs_in->i_a_a = meas->i_a_a;
    obs_in->i_b_a = meas->i_b_a;
    obs_in->cos_hat = cos_hat;
    obs_in->sin_hat = sin_hat;
    obs_in->i_d_a = i_d;
    obs_in->i_q_a = i_q;
    obs_in->i_d_err_a = i_d - refs.i_d_ref_a;
    obs_in->i_q_err_a = i_q - i_q_ref;
    obs_in->known_load_nm = load_ref.value;
    *mech = pmstep_observer_mech_rates(&inst->observer, &inst->observer_coeffs, obs_in, known_load);

    load_rate = known_load ? load_ref.rate : mech->load_hat_rate_nm_per_s;
    i_q_ref_rate = pmstep_law_iq_ref_rate(&inst->law_coeffs, &refs, inst->observer.speed_hat_rad_s,
                                          mech->speed_hat_rate_rad_s2, load_rate);
    pmstep_law_voltages(&inst->law_coeffs, &refs, cos_hat, sin_hat, i_d, i_q, inst->observer.speed_hat_rad_s,
                        i_q_ref, i_q_ref_rate, &out->u_a_v, &out->u_b_v);

    out->cos_hat = cos_hat;
    out->sin_hat = sin_hat;
    out->speed_hat_rad_s = inst->observer.speed_hat_rad_s;
    out->load_hat_nm = load_nm;
    out->i_a_hat_a = inst->observer.i_a_hat_a;
    out->i_b_hat_a = inst->observer.i_b_hat_a;
    out->speed_ref_rad_s = speed_ref.value;
    out->speed_ref_dot_rad_s2 = speed_ref.rate;
    out->i_d_a = i_d;
    out->i_q_a = i_q;
    out->i_d_ref_a = refs.i_d_ref_a;
    out->i_q_ref_a = i_q_ref;
}

/* Scales (u_a, u_b) so neither H-bridge exceeds the measured bus; keeps the vector's direction. */
static bool limit_to_bus(float *u_a_v, float *u_b_v, float bus_voltage_v)
{
    const float largest = abs_f(*u_a_v) > abs_f(*u_b_v) ? abs_f(*u_a_v) : abs_f(*u_b_v);
    if (largest > bus_voltage_v) {
        const float scale = bus_voltage_v / largest;
        *u_a_v *= scale;
        *u_b_v *= scale;
        return true;
    }
    return false;
}

static void output_off(pmstep_output_t *out, const pmstep_t *inst)
{
    static const pmstep_output_t zero_output = {0};
    *out = zero_output;
    out->mode = inst->mode;
    out->fault = inst->fault;
    out->fault_step = inst->fault_step;
}

void pmstep_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    const pmstep_config_t *cfg = inst->cfg;
    pmstep_observer_input_t obs_in;
    pmstep_observer_mech_rates_t mech;
    pmstep_fault_t fault;
    float next_a_v;
    float next_b_v;

    inst->step_count++;
    if (inst->mode == PMSTEP_MODE_IDLE || inst->mode == PMSTEP_MODE_FAULT) {
        output_off(out, inst);
        return;
    }
    fault = check_measurements(cfg, meas);
    if (fault != PMSTEP_FAULT_NONE) {
        latch_fault(inst, fault);
        output_off(out, inst);
        return;
    }

    output_off(out, inst);
    if (inst->mode_step >= inst->c_align_end_step) {
        inst->mode = PMSTEP_MODE_RUN;
    } else if (inst->mode_step >= inst->s_align_steps) {
        inst->mode = PMSTEP_MODE_C_ALIGN;
    }
    switch (inst->mode) {
    case PMSTEP_MODE_S_ALIGN: /* (3) */
        out->u_a_v = 0.0f;
        out->u_b_v = cfg->s_align_voltage_v;
        break;
    case PMSTEP_MODE_C_ALIGN: /* (5) */
        out->u_a_v = cfg->c_align_voltage_v;
        out->u_b_v = 0.0f;
        break;
    default: /* RUN: (6) or (13) */
        run_controller(inst, meas, out, &obs_in, &mech);
        break;
    }
    out->voltage_limited = limit_to_bus(&out->u_a_v, &out->u_b_v, meas->bus_voltage_v);
    out->mode = inst->mode;
    out->bridge_enable = true;

    /* The voltage the bridge applies over the coming period. */
    if (cfg->computational_delay_periods == 0u) {
        next_a_v = out->u_a_v;
        next_b_v = out->u_b_v;
    } else {
        next_a_v = inst->u_pending_a_v;
        next_b_v = inst->u_pending_b_v;
        inst->u_pending_a_v = out->u_a_v;
        inst->u_pending_b_v = out->u_b_v;
    }
    inst->u_applied_a_v = next_a_v;
    inst->u_applied_b_v = next_b_v;

    if (inst->mode == PMSTEP_MODE_RUN) {
        pmstep_observer_advance(&inst->observer, &inst->observer_coeffs, &obs_in, &mech, next_a_v, next_b_v,
                                cfg->period_s);
        pmstep_ref_advance(&inst->ref_coeffs, &inst->speed_ref, cfg->period_s);
        pmstep_ref_advance(&inst->ref_coeffs, &inst->i_d_ref, cfg->period_s);
        if (cfg->known_load_mode) {
            pmstep_ref_set_target(&inst->known_load_filter, meas->load_torque_nm, 0.0f);
            pmstep_ref_advance(&inst->ref_coeffs, &inst->known_load_filter, cfg->period_s);
        }
        if (!isfinite(out->u_a_v) || !isfinite(out->u_b_v) || !isfinite(inst->observer.speed_hat_rad_s)
            || !isfinite(inst->observer.load_hat_nm) || !isfinite(inst->observer.i_a_hat_a)
            || !isfinite(inst->observer.i_b_hat_a) || !isfinite(inst->angle.phi_a)
            || !isfinite(inst->angle.phi_b)) {
            latch_fault(inst, PMSTEP_FAULT_STATE_NONFINITE);
            output_off(out, inst);
            return;
        }
    } else {
        inst->mode_step++;
    }
}
