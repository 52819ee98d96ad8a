/* Controller (6), or (13) with a known load (Remark 1), in RUN: the control stage (angle,
 * Park, observer rates, law, or a vector hold's voltage) and the advance stage (observer,
 * references). */
#include "pmstep_internal.h"

/* Starts controller (6) at t_c: phi at the equilibrium, i-hat = i(t_c), w-hat = T_L-hat = 0, references from 0. */
static void start_run(pmstep_t *inst, const pmstep_meas_t *sample)
{
    const pmstep_ref_t speed_cmd = inst->speed_ref;
    pmstep_angle_start(&inst->angle, sample->i_a_A, sample->i_b_A);
    pmstep_angle_set(&inst->angle, &inst->derived.angle_coeffs, inst->commissioning.equilibrium_cos,
                     inst->commissioning.equilibrium_sin); /* c-alignment's equilibrium (1, 0 unless measured) */
    pmstep_angle_smoother_set(&inst->scratch.run.smoother, inst->commissioning.equilibrium_cos,
                              inst->commissioning.equilibrium_sin);
    pmstep_observer_start(&inst->observer, sample->i_a_A, sample->i_b_A);
    inst->current_integral.i_d_error_integral_As = 0.0f;
    inst->current_integral.i_q_error_integral_As = 0.0f;
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pmstep_ref_set_target(&inst->speed_ref, speed_cmd.target, speed_cmd.ramp_rate_per_s);
    pmstep_ref_reset(&inst->i_d_ref, 0.0f);
    inst->weakening.weakening_A = 0.0f; /* from the command alone: the weakening starts again */
    pmstep_ref_set_target(&inst->i_d_ref, inst->weakening.command_A, 0.0f);
    pmstep_ref_reset(&inst->scratch.run.known_load_filter, inst->cfg->known_load_mode ? sample->load_torque_Nm : 0.0f);
    pmstep_detect_start(&inst->scratch.run.detector); /* the sums are spent */
    pmstep_continuity_start(&inst->scratch.run.continuity);
    pmstep_identify_clear(&inst->scratch.run.identify); /* a re-alignment reopens the window */
    pmstep_standstill_start(inst);
    inst->run_started = true;
}

/* With phase-voltage sensing: the voltage of the period just ended as measured (offsets off), for
 * the flux integrals; the observer's prediction of this sample is redone with it. */
static void sensed_period_voltage(pmstep_t *inst, const pmstep_meas_t *sample, float *u_a_V, float *u_b_V)
{
    pmstep_sensed_voltages(inst, sample, u_a_V, u_b_V);
    pmstep_observer_correct_voltage(&inst->observer, &inst->derived.observer_coeffs,
                                    *u_a_V - inst->actuator.u_applied_a_V, *u_b_V - inst->actuator.u_applied_b_V);
}

/* The standstill's kept rotor in place of the integrals' reading (pmstep_hold.h), and the
 * observer's inputs that depend on the estimate taken again from it: the Park (written out: a
 * second caller makes -Os keep pmstep_park out of line) and the detent torque. */
static void kept_estimate_in(pmstep_t *inst, const pmstep_meas_t *sample, const pmstep_law_refs_t *refs,
                             pmstep_observer_input_t *obs_in, float *cos_hat, float *sin_hat, float *i_d, float *i_q)
{
    pmstep_detent_t detent;
    pmstep_standstill_estimate(inst, cos_hat, sin_hat);
    pmstep_angle_smoother_set(&inst->scratch.run.smoother, *cos_hat, *sin_hat); /* the smoothing's next
                                                                                    prediction starts here */
    *i_d = (*cos_hat * sample->i_a_A) + (*sin_hat * sample->i_b_A);
    *i_q = ((-*sin_hat) * sample->i_a_A) + (*cos_hat * sample->i_b_A);
    obs_in->cos_hat = *cos_hat;
    obs_in->sin_hat = *sin_hat;
    obs_in->i_d_A = *i_d;
    obs_in->i_q_A = *i_q;
    detent = pmstep_law_detent(&inst->derived.law_coeffs, *cos_hat, *sin_hat, inst->observer.speed_hat_rad_s);
    pmstep_law_fade_detent(inst->cfg->gains.detent_fade_speed_rad_s, inst->observer.speed_hat_rad_s,
                           refs->speed_ref_rate_rad_s2, &detent);
    obs_in->detent_torque_Nm = detent.torque_Nm;
}

/* The flux integrals (phi_1, phi_2) over the period just ended, with the voltage the bridge applied
 * over it: the command, the sensed voltage, or the command less the dead time's loss where the
 * samples fix it. */
static void integrate_period(pmstep_t *inst, const pmstep_meas_t *sample)
{
    float u_a_V = inst->actuator.u_applied_a_V;
    float u_b_V = inst->actuator.u_applied_b_V;
    if (!inst->derived.voltage_corrected) {
        /* the command is the period's voltage: tested first, as the most common case */
    } else if (inst->derived.actuate_coeffs.sensed) {
        sensed_period_voltage(inst, sample, &u_a_V, &u_b_V);
    } else { /* compensated: the dead time's loss, where the samples fix it */
        pmstep_period_currents_t currents;
        currents.i_start_a_A = inst->angle.i_a_prev_A;
        currents.i_start_b_A = inst->angle.i_b_prev_A;
        currents.i_end_a_A = sample->i_a_A;
        currents.i_end_b_A = sample->i_b_A;
        currents.bias_a_V = inst->commissioning.voltage_bias_a_V;
        currents.bias_b_V = inst->commissioning.voltage_bias_b_V;
        pmstep_actuate_voltage_over_period(&inst->actuator, &inst->derived.actuate_coeffs, &currents,
                                           sample->bus_voltage_V, &u_a_V, &u_b_V);
    }
    pmstep_angle_update(&inst->angle, &inst->derived.angle_coeffs, sample->i_a_A, sample->i_b_A, u_a_V, u_b_V);
}

/* The period's angle estimate from the integrals (smoothed where configured:
 * docs/design/16-angle-smoothing.md) and the sampled currents in its frame. */
static void angle_of_period(pmstep_t *inst, const pmstep_meas_t *sample, float *cos_hat, float *sin_hat, float *i_d,
                            float *i_q)
{
    pmstep_angle_estimate(&inst->angle, &inst->derived.angle_coeffs, sample->i_a_A, sample->i_b_A, cos_hat, sin_hat);
    if (inst->derived.angle_smoothing) {
        pmstep_angle_smooth(inst->cfg->gains.angle_smoothing,
                            inst->derived.law_coeffs.pole_pairs * inst->cfg->timing.period_s
                                * inst->observer.speed_hat_rad_s,
                            &inst->scratch.run.smoother, cos_hat, sin_hat);
    }
    pmstep_park(*cos_hat, *sin_hat, sample->i_a_A, sample->i_b_A, i_d, i_q);
}

/* The filtered references of the period (speed, i_d* and, in known-load mode, T_L* of Remark 1) into
 * @p refs; @p known_out is T_L*'s filter output (0 in (6)), and the load the law works against is
 * returned: T_L* or T_L-hat. */
static float period_references(pmstep_t *inst, bool known_load, pmstep_law_refs_t *refs, pmstep_ref_out_t *known_out)
{
    pmstep_ref_out_t ref = pmstep_ref_output(&inst->derived.ref_coeffs, &inst->speed_ref);
    float load_Nm;
    refs->speed_ref_rad_s = ref.value;
    refs->speed_ref_rate_rad_s2 = ref.rate;
    refs->speed_ref_accel_rad_s3 = ref.accel;
    ref = pmstep_ref_output(&inst->derived.ref_coeffs, &inst->i_d_ref);
    refs->i_d_ref_A = ref.value;
    refs->i_d_ref_rate_A_s = ref.rate;
    if (known_load) {
        ref = pmstep_ref_output(&inst->derived.ref_coeffs, &inst->scratch.run.known_load_filter); /* T_L*, Remark 1 */
        load_Nm = ref.value;
    } else {
        ref.value = 0.0f; /* (6): no T_L* */
        ref.rate = 0.0f;
        load_Nm = inst->observer.load_hat_Nm;
    }
    *known_out = ref;
    return load_Nm;
}

/* What the observer takes of the period: the samples, the angle estimate and the currents in its
 * frame, T_L* (Remark 1; 0 in (6)) and the detent torque. */
static void observer_input_of_period(const pmstep_meas_t *sample, float cos_hat, float sin_hat, float i_d, float i_q,
                                     float known_load_Nm, float detent_torque_Nm, pmstep_observer_input_t *obs_in)
{
    obs_in->i_a_A = sample->i_a_A;
    obs_in->i_b_A = sample->i_b_A;
    obs_in->cos_hat = cos_hat;
    obs_in->sin_hat = sin_hat;
    obs_in->i_d_A = i_d;
    obs_in->i_q_A = i_q;
    obs_in->known_load_Nm = known_load_Nm;
    obs_in->detent_torque_Nm = detent_torque_Nm;
}

/* Robust mode's transient observer boost on the rates (docs/design/18-transient-observer-boost.md). */
static void boost_in_transient(pmstep_t *inst, const pmstep_observer_input_t *obs_in,
                               pmstep_observer_mech_rates_t *rates)
{
    pmstep_observer_boost_in_transient(&inst->observer, &inst->derived.observer_coeffs, obs_in,
                                       inst->cfg->gains.transient_observer_boost,
                                       inst->cfg->detection.observer_residual_bound_A, rates);
}

/* The period's estimates, references and currents into @p out. */
static void report_period(const pmstep_t *inst, const pmstep_law_refs_t *refs, float cos_hat, float sin_hat, float i_d,
                          float i_q, float load_Nm, float i_q_ref, pmstep_output_t *out)
{
    out->cos_hat = cos_hat;
    out->sin_hat = sin_hat;
    out->speed_hat_rad_s = inst->observer.speed_hat_rad_s;
    out->load_hat_Nm = load_Nm;
    out->i_a_hat_A = inst->observer.i_a_hat_A;
    out->i_b_hat_A = inst->observer.i_b_hat_A;
    out->speed_ref_rad_s = refs->speed_ref_rad_s;
    out->speed_ref_rate_rad_s2 = refs->speed_ref_rate_rad_s2;
    out->i_d_A = i_d;
    out->i_q_A = i_q;
    out->i_d_ref_A = refs->i_d_ref_A;
    out->i_q_ref_A = i_q_ref;
}

void pmstep_control_compute(pmstep_t *inst, const pmstep_meas_t *sample, pmstep_output_t *out,
                            pmstep_control_scratch_t *scratch)
{
    const bool known_load = inst->cfg->known_load_mode;
    pmstep_observer_input_t *obs_in = &scratch->observer_input;
    pmstep_law_refs_t refs;
    pmstep_ref_out_t ref; /* T_L*'s filter output (Remark 1) */
    float cos_hat;
    float sin_hat;
    float i_d;
    float i_q;
    float load_Nm;
    float i_q_ref;
    pmstep_detent_t detent;
    pmstep_speed_term_t speed;

    if (!inst->run_started) {
        start_run(inst, sample);
    } else {
        integrate_period(inst, sample);
    }
    angle_of_period(inst, sample, &cos_hat, &sin_hat, &i_d, &i_q);
    load_Nm = period_references(inst, known_load, &refs, &ref);
    /* The detent torque is known in form: the law supplies it, the observer expects it (both faded with w-hat). */
    detent = pmstep_law_detent(&inst->derived.law_coeffs, cos_hat, sin_hat, inst->observer.speed_hat_rad_s);
    pmstep_law_fade_detent(inst->cfg->gains.detent_fade_speed_rad_s, inst->observer.speed_hat_rad_s,
                           refs.speed_ref_rate_rad_s2, &detent);
    observer_input_of_period(sample, cos_hat, sin_hat, i_d, i_q, ref.value, detent.torque_Nm, obs_in);
    if (inst->hold.active) {       /* a vector hold: its own voltage, the law's speed loop paused */
        if (inst->estimate_kept) { /* tested in the hold's branch: the law's periods pay nothing for it */
            kept_estimate_in(inst, sample, &refs, obs_in, &cos_hat, &sin_hat, &i_d, &i_q);
        }
        i_q_ref = 0.0f;
        pmstep_hold_voltages(inst, obs_in, out);
    } else {
        speed = pmstep_law_speed_term(&inst->derived.law_coeffs, inst->observer.speed_hat_rad_s - refs.speed_ref_rad_s);
        i_q_ref = pmstep_law_iq_ref(&inst->derived.law_coeffs, &refs, speed.term, load_Nm - detent.torque_Nm);
        obs_in->i_d_err_A = i_d - refs.i_d_ref_A;
        obs_in->i_q_err_A = i_q - i_q_ref;
    }
    scratch->mech_rates =
        pmstep_observer_mech_rates(&inst->observer, &inst->derived.observer_coeffs, obs_in, known_load);

    if (!inst->hold.active) {
        float load_rate;
        float i_q_ref_rate;
        /* outside the vector holds, whose vector is not the law's (docs/design/18-transient-observer-boost.md) */
        if (inst->derived.robust_corrections && (inst->cfg->gains.transient_observer_boost > 0.0f) && !known_load) {
            boost_in_transient(inst, obs_in, &scratch->mech_rates);
        }
        load_rate = known_load ? ref.rate : scratch->mech_rates.load_hat_rate_Nm_s;
        i_q_ref_rate = pmstep_law_iq_ref_rate(&inst->derived.law_coeffs, &refs, speed.slope,
                                              scratch->mech_rates.speed_hat_rate_rad_s2, load_rate - detent.rate_Nm_s);
        pmstep_law_voltages(&inst->derived.law_coeffs, &refs, cos_hat, sin_hat, i_d, i_q,
                            inst->observer.speed_hat_rad_s, i_q_ref, i_q_ref_rate, &inst->current_integral, &out->u_a_V,
                            &out->u_b_V);
    }

    report_period(inst, &refs, cos_hat, sin_hat, i_d, i_q, load_Nm, i_q_ref, out);
}

pmstep_fault_t pmstep_control_advance(pmstep_t *inst, const pmstep_control_scratch_t *scratch,
                                      const pmstep_meas_t *meas, const pmstep_output_t *out)
{
    const pmstep_config_t *cfg = inst->cfg;
    const float period_s = cfg->timing.period_s;
    if (inst->derived.robust_corrections) { /* one test a period where none is on (the paper's estimate) */
        if (inst->derived.angle_coeffs.correction_gain > 0.0f) {
            pmstep_angle_correct(&inst->angle, &inst->derived.angle_coeffs, out->cos_hat, out->sin_hat);
        }
        /* outside the vector holds, whose vector sets the angle; in the position library's moves
         * too, where without it the current loop at 0.2/T_s rang at the electrical frequency
         * (docs/design/15-back-emf-angle-correction.md) */
        if ((inst->derived.angle_coeffs.emf_turn_gain > 0.0f) && !inst->hold.active) {
            const pmstep_observer_input_t *in = &scratch->observer_input;
            const pmstep_observer_coeffs_t *obs = &inst->derived.observer_coeffs;
            const float err_a = in->i_a_A - inst->observer.i_a_hat_A;
            const float err_b = in->i_b_A - inst->observer.i_b_hat_A;
            /* Park written out, not pmstep_park(): a second caller makes -Os keep it out of line
             * (pmstep_hold_voltages) */
            const float i_d_residual_A = out->cos_hat * err_a + out->sin_hat * err_b;
            const float i_q_residual_A = out->cos_hat * err_b - out->sin_hat * err_a;
            const float bound_A = cfg->detection.observer_residual_bound_A;
            /* Paused where the residuals are no settled reading of the angle (pmstep_angle.h): the
             * q residual beyond the detection's bound (a transient: a load step, w-hat lagging),
             * or a d residual that would mean more than PMSTEP_EMF_ANGLE_MAX_READING_RAD. */
            const bool settled_q = !(bound_A > 0.0f) || (pmstep_abs(i_q_residual_A) < bound_A);
            const bool settled_d =
                pmstep_abs(i_d_residual_A) * (obs->r_over_l_per_s + obs->observer_gain_per_s)
                < PMSTEP_EMF_ANGLE_MAX_READING_RAD * obs->km_over_l * pmstep_abs(out->speed_hat_rad_s);
            if (settled_q && settled_d) {
                pmstep_angle_follow_emf(&inst->angle, &inst->derived.angle_coeffs, out->cos_hat, out->sin_hat,
                                        i_d_residual_A, out->speed_hat_rad_s);
            }
        }
    }
    pmstep_observer_advance(&inst->observer, &inst->derived.observer_coeffs, &scratch->observer_input,
                            &scratch->mech_rates, inst->actuator.u_applied_a_V, inst->actuator.u_applied_b_V, period_s);
    if (!out->voltage_limited) { /* anti-windup: the integral holds while the bus limits the voltage */
        pmstep_law_integrate(&inst->current_integral, &inst->derived.law_coeffs, scratch->observer_input.i_d_err_A,
                             scratch->observer_input.i_q_err_A, period_s);
    }
    pmstep_ref_advance(&inst->derived.ref_coeffs, &inst->speed_ref, period_s);
    pmstep_ref_advance(&inst->derived.ref_coeffs, &inst->i_d_ref, period_s);
    if (inst->hold.standstill_armed) {
        pmstep_standstill_advance(inst, out);
    }
    if (cfg->known_load_mode) {
        pmstep_ref_set_target(&inst->scratch.run.known_load_filter, meas->load_torque_Nm, 0.0f);
        pmstep_ref_advance(&inst->derived.ref_coeffs, &inst->scratch.run.known_load_filter, period_s);
    }
    /* The current integrals need no check here: they enter the next voltage, which actuate checks. */
    return pmstep_all_finite6(inst->observer.speed_hat_rad_s, inst->observer.load_hat_Nm, inst->observer.i_a_hat_A,
                              inst->observer.i_b_hat_A, inst->angle.phi_a, inst->angle.phi_b)
               ? PMSTEP_FAULT_NONE
               : PMSTEP_FAULT_STATE_NONFINITE;
}
