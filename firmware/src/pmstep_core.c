/* The control step: strategy of Section III.A, s-alignment (3) -> c-alignment (5) ->
 * controller (6) (or (13), Remark 1); the lifecycle and commands are in pmstep_lifecycle.c.
 *
 * One step is a sequence of stages, each a function of the module it belongs to:
 *   check      measurements against the protections (here)
 *   commission alignment timing, Remark 2 sums, the commissioned model at t_c (pmstep_commission.c)
 *   control    alignment voltages (here), or controller (6) (pmstep_control.c)
 *   identify   in RUN's first window, every PMSTEP_IDENTIFICATION_DECIMATION periods: the J and F
 *              fit's sums, at its end J and F (pmstep_identify.c)
 *   supervise  detection every PMSTEP_DETECTION_DECIMATION periods in RUN (pmstep_detect.c)
 *   actuate    dead-time compensation, bus limit, output check, delay (pmstep_actuate.c)
 *   continuity the windings and the current sensors carry what the voltage asks (pmstep_continuity.c):
 *              the alignments' peaks, in RUN every PMSTEP_CONTINUITY_DECIMATION periods the bus did not
 *              limit
 *   advance    observer and references over the coming period (pmstep_control.c) */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

static void output_off(pmstep_output_t *out, const pmstep_t *inst)
{
    static const pmstep_output_t zero_output = {0};
    *out = zero_output;
    out->mode = inst->mode;
    out->fault = inst->fault;
    out->fault_step = inst->fault_step;
}

/* Latches @p fault: state cleared, bridge off from this period on. */
static void trip(pmstep_t *inst, pmstep_fault_t fault, pmstep_output_t *out)
{
    pmstep_clear_dynamic_state(inst);
    inst->mode = PMSTEP_MODE_FAULT;
    inst->fault = fault;
    inst->fault_step = inst->step_count;
    output_off(out, inst);
}

/* After a detection: align again with the bridge on, keeping what commissioning measured. */
static void realign(pmstep_t *inst)
{
    pmstep_clear_dynamic_state(inst);
    inst->commissioning.realignments++;
    inst->mode = PMSTEP_MODE_S_ALIGN;
}

/* The inputs a configuration adds: the load torque of known-load mode non-finite; with
 * phase-voltage sensing, a sensed voltage non-finite, or above the bus by more than the sensors'
 * margin (a mean phase voltage cannot exceed the bus). */
static pmstep_fault_t check_optional_inputs(const pmstep_config_t *cfg, const pmstep_meas_t *meas)
{
    if (cfg->known_load_mode && !pmstep_all_finite4(meas->load_torque_Nm, 0.0f, 0.0f, 0.0f)) {
        return PMSTEP_FAULT_MEASUREMENT_NONFINITE;
    }
    if (cfg->inverter.phase_voltage_sensing) {
        const float limit_V = PMSTEP_PHASE_VOLTAGE_RANGE_FACTOR * meas->bus_voltage_V;
        if (!pmstep_all_finite4(meas->phase_voltage_a_V, meas->phase_voltage_b_V, 0.0f, 0.0f)) {
            return PMSTEP_FAULT_MEASUREMENT_NONFINITE;
        }
        if (pmstep_abs(meas->phase_voltage_a_V) > limit_V || pmstep_abs(meas->phase_voltage_b_V) > limit_V) {
            return PMSTEP_FAULT_PHASE_VOLTAGE_RANGE;
        }
    }
    return PMSTEP_FAULT_NONE;
}

/* Check stage: the protections, while the bridge may be on. */
static pmstep_fault_t check_measurements(const pmstep_t *inst, const pmstep_meas_t *meas)
{
    const pmstep_config_t *cfg = inst->cfg;
    if (!pmstep_all_finite4(meas->i_a_A, meas->i_b_A, meas->bus_voltage_V, 0.0f)) {
        return PMSTEP_FAULT_MEASUREMENT_NONFINITE;
    }
    if (pmstep_abs(meas->i_a_A) > cfg->limits.max_phase_current_A
        || pmstep_abs(meas->i_b_A) > cfg->limits.max_phase_current_A) {
        return PMSTEP_FAULT_OVERCURRENT;
    }
    if (meas->bus_voltage_V < cfg->limits.min_bus_voltage_V) {
        return PMSTEP_FAULT_BUS_UNDERVOLTAGE;
    }
    if (meas->bus_voltage_V > cfg->limits.max_bus_voltage_V) {
        return PMSTEP_FAULT_BUS_OVERVOLTAGE;
    }
    return inst->derived.optional_inputs ? check_optional_inputs(cfg, meas) : PMSTEP_FAULT_NONE;
}

/* Bridge off and the mode of this period; the offset calibration's samples. */
static void offset_calibration_stage(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    const bool sensing = inst->cfg->inverter.phase_voltage_sensing;
    output_off(out, inst);
    pmstep_commission_add_bridge_off(&inst->scratch.sums, meas->i_a_A, meas->i_b_A,
                                     sensing ? meas->phase_voltage_a_V : 0.0f,
                                     sensing ? meas->phase_voltage_b_V : 0.0f);
    if (++inst->mode_step >= inst->derived.offset_cal_steps) {
        /* Offsets for the alignment: the dead-time compensation needs the sign of small currents. */
        pmstep_commission_take_bridge_off(&inst->scratch.sums, &inst->commissioning);
        inst->mode = PMSTEP_MODE_S_ALIGN;
        inst->mode_step = 0u;
    }
}

/* The model RUN works with from t_c: the configured one, with what commissioning measured in
 * place where configured so. */
static void commissioned_model(const pmstep_t *inst, pmstep_electrical_t *model)
{
    const pmstep_config_t *cfg = inst->cfg;
    const pmstep_commissioning_t *result = &inst->commissioning;
    *model = pmstep_configured_electrical(cfg);
    if (cfg->commissioning.use_measured_resistance) {
        model->resistance_Ohm = result->resistance_Ohm;
    }
    if (cfg->commissioning.use_measured_inductance) {
        model->inductance_H = result->inductance_H;
    }
    if (cfg->commissioning.use_measured_torque_constant) {
        model->torque_constant_Nm_A = result->torque_constant_Nm_A;
    }
}

/* At t_c, before the first RUN period: Remark 2 offsets and the commissioned model; the
 * identification window opens. @return a fault, or PMSTEP_FAULT_NONE. */
static pmstep_fault_t finish_commissioning(pmstep_t *inst, const pmstep_meas_t *raw)
{
    pmstep_commissioning_t *result = &inst->commissioning;
    pmstep_electrical_t model;
    const pmstep_fault_t fault = pmstep_commission_finish(&inst->scratch.sums, &inst->derived.commission_plan,
                                                          inst->cfg, raw->i_a_A, inst->actuator.u_applied_a_V, result);
    if (fault != PMSTEP_FAULT_NONE) {
        return fault;
    }
    if (inst->derived.commission_plan.identification_steps > 0u) {
        result->identification = PMSTEP_IDENT_RUNNING; /* RUN's start clears the sums */
    }
    commissioned_model(inst, &model);
    pmstep_apply_model(&inst->derived, inst->cfg, &model);
    return PMSTEP_FAULT_NONE;
}

/* Identify stage, in RUN while the window is open, every PMSTEP_IDENTIFICATION_DECIMATION periods: a
 * sample of the fit (pmstep_identify.h);
 * at the window's end J and F, and with use_identified_mechanics the observer's and the law's
 * coefficients for them (a one-off, like t_c's). */
static void identify_stage(pmstep_t *inst, const pmstep_output_t *out)
{
    if (pmstep_identify_sample(&inst->scratch.run.identify, &inst->cfg->commissioning,
                               inst->derived.commission_plan.identification_steps, out)) {
        pmstep_electrical_t model;
        float friction_Nms_rad;
        commissioned_model(inst, &model);
        friction_Nms_rad = model.friction_Nms_rad;
        if (pmstep_identify_finish(&inst->scratch.run.identify, inst->cfg, &model, &inst->commissioning)) {
            /* Bumpless: T_L-hat takes over the friction torque the new F no longer leaves to it,
             * so F w-hat + T_L-hat, the torque the law asks for at constant speed, is unchanged. */
            inst->observer.load_hat_Nm += (friction_Nms_rad - model.friction_Nms_rad) * inst->observer.speed_hat_rad_s;
            pmstep_apply_model(&inst->derived, inst->cfg, &model);
        }
    }
}

/* Phase a's voltage over the period just ended is not the one the core assumed where phase a's
 * current (offset-corrected) is beyond the compensation's sign threshold with the sign opposite
 * to c-alignment's: an undriven phase whose dead time is over-compensated runs away to the excess
 * over R with whatever sign it had, and at c-alignment's start, until that current passes zero,
 * the bridge applies 2 V_bus t_d / T_s more than the compensation assumed (sensed voltages need
 * no assumption). */
static bool phase_a_voltage_known(const pmstep_t *inst, const pmstep_meas_t *meas)
{
    return inst->cfg->inverter.phase_voltage_sensing || !inst->derived.actuate_coeffs.compensate
           || (meas->i_a_A - inst->commissioning.offset_a_A)
                  >= -pmstep_actuate_sign_threshold(&inst->derived.actuate_coeffs, meas->bus_voltage_V);
}

/* Commission stage: the mode of this period from the alignment timing; the alignment's samples
 * into the Remark 2 sums, or at t_c the commissioned model. A rotor that still moved in the
 * steady-state windows has the alignments repeated from s-alignment (this period its first). */
static pmstep_fault_t commission_stage(pmstep_t *inst, const pmstep_meas_t *meas)
{
    const pmstep_commission_plan_t *plan = &inst->derived.commission_plan;
    float u_a_V;
    float u_b_V;
    if (inst->mode_step >= plan->c_align_end_step) {
        inst->mode = PMSTEP_MODE_RUN;
    } else if (inst->mode_step >= plan->s_align_steps) {
        inst->mode = PMSTEP_MODE_C_ALIGN;
    }
    if (inst->commissioning.measured) {
        return PMSTEP_FAULT_NONE;
    }
    if (inst->mode == PMSTEP_MODE_RUN) {
        const pmstep_fault_t fault = finish_commissioning(inst, meas);
        if ((fault == PMSTEP_FAULT_NONE) && inst->cfg->commissioning.measure_only) {
            pmstep_clear_dynamic_state(inst); /* the commissioning results stay until the next start */
            inst->mode = PMSTEP_MODE_IDLE;
            return PMSTEP_FAULT_NONE;
        }
        if (fault != PMSTEP_FAULT_ALIGNMENT_MOTION
            || inst->commissioning.alignment_repeats >= PMSTEP_ALIGNMENT_MAX_REPEATS) {
            return fault;
        }
        pmstep_commission_repeat(&inst->scratch.sums, &inst->commissioning);
        inst->mode = PMSTEP_MODE_S_ALIGN;
        inst->mode_step = 0u;
    }
    u_a_V = inst->actuator.u_applied_a_V;
    u_b_V = inst->actuator.u_applied_b_V;
    if (inst->cfg->inverter.phase_voltage_sensing) {
        pmstep_sensed_voltages(inst, meas, &u_a_V, &u_b_V);
    }
    pmstep_commission_add_alignment(&inst->scratch.sums, plan, inst->mode_step, meas->i_a_A, meas->i_b_A, u_a_V, u_b_V,
                                    phase_a_voltage_known(inst, meas));
    return PMSTEP_FAULT_NONE;
}

/* Remark 2: the sensor offsets (zero until measured) come off every sample; phase a is put on
 * phase b's scale (1 until measured). */
static pmstep_meas_t calibrated_sample(const pmstep_t *inst, const pmstep_meas_t *meas)
{
    pmstep_meas_t sample = *meas;
    sample.i_a_A = (sample.i_a_A - inst->commissioning.offset_a_A) * inst->commissioning.phase_a_current_scale;
    sample.i_b_A -= inst->commissioning.offset_b_A;
    return sample; /* the phase-voltage offsets come off where the voltages are used (with sensing only) */
}

/* Control stage of the alignments: (3) after its lead-in, or (5), the last window at the lower
 * level with the Remark 2 voltage bias; no telemetry in alignment. */
static void alignment_stage(const pmstep_t *inst, pmstep_output_t *out)
{
    const pmstep_config_t *cfg = inst->cfg;
    const pmstep_commission_plan_t *plan = &inst->derived.commission_plan;
    output_off(out, inst);
    if ((inst->mode == PMSTEP_MODE_S_ALIGN) && (inst->mode_step < plan->s_lead_in_steps)) {
        out->u_a_V = cfg->alignment.c_align_voltage_V; /* the lead-in, (5)'s vector: away from (3)'s unstable
                                                          equilibrium */
        out->u_b_V = 0.0f;
    } else if (inst->mode == PMSTEP_MODE_S_ALIGN) {
        out->u_a_V = 0.0f;
        out->u_b_V = cfg->alignment.s_align_voltage_V;
        if (pmstep_commission_low_level(plan, inst->mode_step, plan->s_align_steps)) {
            out->u_b_V *= cfg->commissioning.voltage_bias_level_fraction; /* second steady state */
        }
    } else {
        out->u_a_V = cfg->alignment.c_align_voltage_V;
        out->u_b_V = 0.0f;
        if (pmstep_commission_low_level(plan, inst->mode_step, plan->c_align_end_step)) {
            out->u_a_V *= cfg->commissioning.voltage_bias_level_fraction;
        }
    }
}

/* Field weakening on the law's voltage (pmstep_weakening.h): i_d*'s target from the command and i_w. */
static void weakening_stage(pmstep_t *inst, const pmstep_output_t *out, float bus_voltage_V)
{
    const pmstep_observer_coeffs_t *obs = &inst->derived.observer_coeffs;
    /* Park written out, not pmstep_park(): another caller makes -Os keep it out of line in the period */
    const float u_d_V = (out->cos_hat * out->u_a_V) + (out->sin_hat * out->u_b_V);
    const float u_q_V = (out->cos_hat * out->u_b_V) - (out->sin_hat * out->u_a_V);
    const bool helps = pmstep_weakening_helps(obs->r_over_l_per_s, obs->pole_pairs, out->speed_hat_rad_s, u_d_V, u_q_V);
    pmstep_ref_set_target(&inst->i_d_ref,
                          pmstep_weakening_update(&inst->weakening, &inst->derived.weakening_coeffs, out->u_a_V,
                                                  out->u_b_V, bus_voltage_V, helps),
                          0.0f);
}

/* Supervise stage, in RUN, every PMSTEP_DETECTION_DECIMATION periods: field weakening, the observer's estimates
 * within what the motor and the bus allow (the observer holds them at that range's edge, so an
 * estimate at it is a lost observer), then detection. */
static pmstep_fault_t supervise_stage(pmstep_t *inst, const pmstep_output_t *out, const pmstep_meas_t *sample)
{
    if ((inst->step_count % PMSTEP_DETECTION_DECIMATION) != 0u) {
        return PMSTEP_FAULT_NONE;
    }
    if (inst->derived.weakening_coeffs.max_current_A > 0.0f) {
        weakening_stage(inst, out, sample->bus_voltage_V);
    }
    if ((pmstep_abs(inst->observer.speed_hat_rad_s) >= inst->derived.observer_coeffs.speed_bound_rad_s)
        || (pmstep_abs(inst->observer.load_hat_Nm) >= inst->derived.observer_coeffs.load_bound_Nm)) {
        return PMSTEP_FAULT_ESTIMATE_RANGE;
    }
    return pmstep_detect_check(&inst->scratch.run.detector, &inst->derived.detect_coeffs, &inst->cfg->detection, out,
                               sample);
}

/* Dead-time compensation in RUN: the current references (i_d*, i_q*) in the stator frame at the
 * angle the voltage acts at (the law's turn, p w-hat T_s (delay + 1/2)); over the period a phase
 * current sweeps +-s = |the other phase's current| p |w-hat| T_s / 2 about that value, and its
 * PWM ripple straddles zero near it (pmstep_actuate_mean_loss_current; inverter.ripple_dead_zone). */
static void reference_current_over_period(const pmstep_t *inst, const pmstep_meas_t *sample, const pmstep_output_t *out,
                                          pmstep_compensation_input_t *in)
{
    const float band_A = inst->cfg->inverter.dead_time_current_band_A;
    const float half_turn =
        0.5f * inst->derived.law_coeffs.pole_pairs * inst->cfg->timing.period_s * pmstep_abs(out->speed_hat_rad_s);
    /* the command's voltage sets the ripple; a bridge without ripple is handed 0 V (h = 0), as a
     * factor rather than a branch (no branch in the period) */
    const float ripple_voltage_factor = inst->cfg->inverter.ripple_dead_zone ? 1.0f : 0.0f;
    float cos_act;
    float sin_act;
    float current_a_A;
    float current_b_A;
    pmstep_law_acting_angle(&inst->derived.law_coeffs, out->cos_hat, out->sin_hat, out->speed_hat_rad_s, &cos_act,
                            &sin_act);
    current_a_A = cos_act * out->i_d_ref_A - sin_act * out->i_q_ref_A;
    current_b_A = sin_act * out->i_d_ref_A + cos_act * out->i_q_ref_A;
    in->sign_current_a_A = pmstep_actuate_mean_loss_current(&inst->derived.actuate_coeffs, band_A, current_a_A,
                                                            pmstep_abs(current_b_A) * half_turn,
                                                            ripple_voltage_factor * out->u_a_V, sample->bus_voltage_V);
    in->sign_current_b_A = pmstep_actuate_mean_loss_current(&inst->derived.actuate_coeffs, band_A, current_b_A,
                                                            pmstep_abs(current_a_A) * half_turn,
                                                            ripple_voltage_factor * out->u_b_V, sample->bus_voltage_V);
}

/* What the dead-time compensation works from. Both phases in every mode: the undriven phase
 * of an alignment must really be at 0 V (a short through the bridge: it damps the rotor's
 * swing); left alone, its dead time would clamp it open. The sign of the current: in RUN from
 * the current references over the period (above), which pass through zero smoothly where a
 * sampled current would sit in the ADC's zero code and let the phase clamp;
 * in the alignments, for the driven phase the current its voltage drives it to (u/R > 0), so
 * that the compensation acts from the first period (a sample still at zero would leave the
 * phase clamped open when u is below the dead time's loss: hybrid steppers align at about
 * 1 V on a 24-48 V bus), and for the undriven phase the offset-corrected sample. */
static pmstep_compensation_input_t compensation_input(const pmstep_t *inst, const pmstep_meas_t *sample,
                                                      const pmstep_output_t *out)
{
    pmstep_compensation_input_t in;
    in.sign_current_a_A = sample->i_a_A;
    in.sign_current_b_A = sample->i_b_A;
    if ((inst->mode == PMSTEP_MODE_RUN) && inst->hold.active) { /* a vector hold: its own currents, not the law's */
        in.sign_current_a_A = inst->hold.current_A * inst->hold.cos_frame;
        in.sign_current_b_A = inst->hold.current_A * inst->hold.sin_frame;
    } else if (inst->mode == PMSTEP_MODE_RUN) {
        reference_current_over_period(inst, sample, out, &in);
    } else if (out->u_a_V > 0.0f) {
        in.sign_current_a_A = out->u_a_V / inst->cfg->motor.resistance_Ohm;
    } else if (out->u_b_V > 0.0f) {
        in.sign_current_b_A = out->u_b_V / inst->cfg->motor.resistance_Ohm;
    } else {
        /* bridge off (idle, offset calibration, fault): the samples */
    }
    in.bias_a_V = inst->commissioning.voltage_bias_a_V;
    in.bias_b_V = inst->commissioning.voltage_bias_b_V;
    return in;
}

/* Continuity stage of the alignments (after actuate): the driven phase's peak, and the checks at
 * the ends of the alignments. A fault here latches (a re-alignment cannot mend a winding). */
static pmstep_fault_t continuity_align_stage(pmstep_t *inst, const pmstep_meas_t *sample)
{
    const pmstep_commission_plan_t *plan = &inst->derived.commission_plan;
    const bool a_driven = (inst->mode == PMSTEP_MODE_C_ALIGN) || (inst->mode_step < plan->s_lead_in_steps);
    return pmstep_continuity_align(&inst->scratch.sums.continuity, inst->cfg, a_driven, sample->i_a_A, sample->i_b_A,
                                   (inst->mode_step + 1u) == plan->s_align_steps,
                                   (inst->mode_step + 1u) == plan->c_align_end_step);
}

/* Continuity stage of RUN (after actuate, in a period the bus did not limit, every
 * PMSTEP_CONTINUITY_DECIMATION periods): the phase currents against what the control asks for, in
 * the stator frame: a vector hold's vector, or the law's (i_d*, i_q*) turned by the estimate (the
 * frame in which the current loop tracks them). */
static pmstep_fault_t continuity_run_stage(pmstep_t *inst, const pmstep_meas_t *sample, const pmstep_output_t *out)
{
    float ref_a_A = inst->hold.current_A * inst->hold.cos_frame;
    float ref_b_A = inst->hold.current_A * inst->hold.sin_frame;
    if (!inst->hold.active) {
        ref_a_A = (out->cos_hat * out->i_d_ref_A) - (out->sin_hat * out->i_q_ref_A);
        ref_b_A = (out->sin_hat * out->i_d_ref_A) + (out->cos_hat * out->i_q_ref_A);
    }
    return pmstep_continuity_check(&inst->scratch.run.continuity, &inst->derived.continuity_coeffs, ref_a_A, ref_b_A,
                                   sample->i_a_A, sample->i_b_A)
               ? pmstep_continuity_judge(&inst->scratch.run.continuity, inst->cfg)
               : PMSTEP_FAULT_NONE;
}

/* The stages after commissioning, in a period with the bridge on. @return a fault to latch,
 * or PMSTEP_FAULT_NONE (also after a detection that re-aligns). */
static pmstep_fault_t bridge_on_stages(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    pmstep_control_scratch_t control;
    pmstep_compensation_input_t compensation;
    const pmstep_meas_t sample = calibrated_sample(inst, meas);
    if (inst->mode == PMSTEP_MODE_RUN) {
        pmstep_fault_t fault;
        out->fault = PMSTEP_FAULT_NONE;
        out->fault_step = inst->fault_step;
        pmstep_control_compute(inst, &sample, out, &control);
        if (inst->commissioning.identification == PMSTEP_IDENT_RUNNING
            && (inst->step_count % PMSTEP_IDENTIFICATION_DECIMATION) == 2u) {
            identify_stage(inst, out);
        }
        fault = supervise_stage(inst, out, &sample);
        if (fault != PMSTEP_FAULT_NONE) {
            if (inst->commissioning.realignments >= inst->cfg->detection.max_realignments) {
                return fault;
            }
            realign(inst);
            output_off(out, inst);
            return PMSTEP_FAULT_NONE;
        }
    } else {
        alignment_stage(inst, out);
    }
    if (inst->derived.actuate_coeffs.compensate) {
        compensation = compensation_input(inst, &sample, out);
    }
    if (!pmstep_actuate(&inst->actuator, &inst->derived.actuate_coeffs, &compensation, meas->bus_voltage_V, out)) {
        return PMSTEP_FAULT_STATE_NONFINITE; /* every mode: never the bridge on with such a voltage */
    }
    out->mode = inst->mode;
    out->bridge_enable = true;
    if (inst->mode != PMSTEP_MODE_RUN) {
        const pmstep_fault_t fault = continuity_align_stage(inst, &sample);
        inst->mode_step++;
        return fault;
    }
    if (((inst->step_count % PMSTEP_CONTINUITY_DECIMATION) == 1u) && !out->voltage_limited) {
        const pmstep_fault_t fault = continuity_run_stage(inst, &sample, out);
        if (fault != PMSTEP_FAULT_NONE) {
            return fault;
        }
    }
    return pmstep_control_advance(inst, &control, meas, out);
}

void pmstep_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    pmstep_fault_t fault;
    inst->step_count++;
    if (inst->mode == PMSTEP_MODE_IDLE || inst->mode == PMSTEP_MODE_FAULT) {
        output_off(out, inst);
        return;
    }
    fault = check_measurements(inst, meas);
    if (fault == PMSTEP_FAULT_NONE && inst->mode == PMSTEP_MODE_OFFSET_CAL) {
        offset_calibration_stage(inst, meas, out);
        return;
    }
    if (fault == PMSTEP_FAULT_NONE && inst->mode != PMSTEP_MODE_RUN) {
        /* Only the alignments time modes and measure: once in RUN the stage has nothing to do. */
        fault = commission_stage(inst, meas);
        if (inst->mode == PMSTEP_MODE_IDLE) { /* measure_only: the bridge off from t_c */
            output_off(out, inst);
            return;
        }
    }
    if (fault == PMSTEP_FAULT_NONE) {
        fault = bridge_on_stages(inst, meas, out);
    }
    if (fault != PMSTEP_FAULT_NONE) {
        trip(inst, fault, out);
    }
}
