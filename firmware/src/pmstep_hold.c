/* Vector hold: a current vector fixed in the stator frame holds the rotor (pmstep_hold.h); the
 * standstill of speed mode and the low-speed drive that use it are in pmstep_standstill.c. */
#include "pmstep_internal.h"

#include <stddef.h>

/* Longest settling time counted, in periods (a weak hold of a heavy rotor): far below the
 * float-to-integer range. */
#define HOLD_MAX_SETTLE_PERIODS 1.0e6f

/* A time in periods as a count: NaN and anything outside [0, max) count as the longest. A model
 * with k_M, J and k_w positive gives neither; the test keeps the conversion defined whatever the
 * model. NaN is tested apart as well, for Frama-C EVA, which does not take it out through an
 * ordered compare (eva.step). */
uint32_t pmstep_hold_period_count(float periods)
{
    const bool defined = periods == periods /* not NaN */ && periods >= 0.0f && periods < HOLD_MAX_SETTLE_PERIODS;
    return (uint32_t)(defined ? periods : HOLD_MAX_SETTLE_PERIODS);
}

/* sqrt(p k_M I cos(delta) / J): the held rotor's natural frequency (rad/s), the commissioned model's. */
float pmstep_hold_natural_rad_s(const pmstep_law_coeffs_t *law, float current_A, float cos_delta)
{
    return sqrtf(law->pole_pairs * current_A * cos_delta / law->j_over_km);
}

/* The vector aimed ahead of the rotor at (c, s) by the load angle of T_L + k_M extra_A:
 * k_M I sin(delta) = T_L - T_detent(rest) + k_M extra_A, k_M from the commissioned model.
 * @return false, @p aim untouched, where |sin delta| is beyond PMSTEP_HOLD_MAX_TORQUE_FRACTION. */
bool pmstep_hold_aim_ahead(const pmstep_law_coeffs_t *law, float c, float s, float current_A, float load_Nm,
                           float extra_A, const pmstep_detent_t *detent, pmstep_hold_aim_t *aim)
{
    const float sin_delta =
        ((load_Nm - detent->torque_Nm) / (law->km_over_l * law->inductance_H) + extra_A) / current_A;
    if (!(pmstep_abs(sin_delta) <= PMSTEP_HOLD_MAX_TORQUE_FRACTION)) {
        return false;
    }
    aim->cos_delta = sqrtf(1.0f - sin_delta * sin_delta);
    pmstep_turn(c, s, aim->cos_delta, sin_delta, &aim->cos_vector, &aim->sin_vector);
    return true;
}

/* Whether the observer's speed estimate follows a rotor swinging at w (rad/s) enough in phase for
 * the damping term: Re(w-hat/w) >= PMSTEP_HOLD_MIN_IN_PHASE_SHARE. The estimate is kept at the
 * vector's aim, so the observer's model lacks the swing's restoring torque and sees the rotor's
 * acceleration as a disturbance d: w~ = s (s + a_e) d / P(s) (docs/design/03-observer.md, d entering
 * w~'), d = s w, hence w-hat/w = 1 - M/P with P = s^3 + c2 s^2 + c1 s + c0 the observer's
 * characteristic polynomial and M = s^2 (s + a_e) = -w^2 (a_e + j w) at s = j w. Compared
 * without a division: (1 - share) |P|^2 >= Re(M conj P) = -w^2 (a_e Re P + w Im P). */
static bool observer_follows_swing(const pmstep_t *inst, float w)
{
    const pmstep_observer_coeffs_t *obs = &inst->derived.observer_coeffs;
    const float a_e = obs->r_over_l_per_s + obs->observer_gain_per_s;
    const float b_squared = obs->km_over_l * obs->km_over_l;
    const float w2 = w * w;
    const float p_re = (obs->load_injection_gain * b_squared * obs->inv_j) - ((a_e + obs->f_over_j_per_s) * w2);
    const float p_im = ((a_e * obs->f_over_j_per_s) + (obs->speed_injection_gain * b_squared) - w2) * w;
    return ((1.0f - PMSTEP_HOLD_MIN_IN_PHASE_SHARE) * ((p_re * p_re) + (p_im * p_im)))
               + (w2 * ((a_e * p_re) + (w * p_im)))
           >= 0.0f;
}

/* pmstep_hold_vector's, with the damping term kept whatever the observer's phase where
 * @p always_damped (the standstill hold of speed mode, pmstep_hold.h). */
pmstep_status_t pmstep_hold_engage(pmstep_t *inst, float cos_rest, float sin_rest, float current_A, float load_Nm,
                                   bool always_damped)
{
    const pmstep_law_coeffs_t *law;
    pmstep_vector_hold_t *hold;
    pmstep_detent_t detent;
    pmstep_hold_aim_t aim = {1.0f, 0.0f, 1.0f}; /* pmstep_hold_aim_ahead's */
    float natural_rad_s;
    float natural_per_period; /* w_n T_s, rad */
    float settle_periods;
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_RUN || !inst->run_started || inst->cfg->known_load_mode) {
        return PMSTEP_ERR_BAD_MODE;
    }
    if (!pmstep_all_finite4(cos_rest, sin_rest, current_A, load_Nm)
        || !(pmstep_abs(cos_rest * cos_rest + sin_rest * sin_rest - 1.0f) <= 0.02f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    if (!(current_A > 0.0f && current_A < inst->cfg->limits.max_phase_current_A)) {
        return PMSTEP_ERR_HOLD_CURRENT;
    }
    law = &inst->derived.law_coeffs;
    hold = &inst->hold;
    detent = pmstep_law_detent(law, cos_rest, sin_rest, 0.0f);
    if (!pmstep_hold_aim_ahead(law, cos_rest, sin_rest, current_A, load_Nm, 0.0f, &detent, &aim)) {
        return PMSTEP_ERR_HOLD_CURRENT;
    }
    hold->cos_vector = aim.cos_vector;
    hold->sin_vector = aim.sin_vector;
    natural_rad_s = pmstep_hold_natural_rad_s(law, current_A, aim.cos_delta);
    hold->current_A = current_A;
    /* no damping term where w-hat lags the swing (its term would be a spring, not a damper),
     * but in the standstill hold of speed mode (pmstep_hold.h) */
    hold->damping_s = (always_damped || observer_follows_swing(inst, natural_rad_s))
                          ? (2.0f * PMSTEP_HOLD_DAMPING_RATIO * law->pole_pairs / natural_rad_s)
                          : 0.0f;
    hold->quiet_band_rad_s = PMSTEP_HOLD_QUIET_FRACTION * natural_rad_s / law->pole_pairs;
    natural_per_period = natural_rad_s * inst->cfg->timing.period_s;
    hold->bias_gain = natural_per_period / PMSTEP_HOLD_BIAS_CORNER_RATIO;
    settle_periods = PMSTEP_HOLD_SETTLE_TIME_CONSTANTS / (PMSTEP_HOLD_DAMPING_RATIO * natural_per_period);
    hold->settle_periods = pmstep_hold_period_count(settle_periods);
    hold->cos_frame = hold->cos_vector;
    hold->sin_frame = hold->sin_vector;
    if (!hold->active) { /* from the law: its integrals were of other errors */
        inst->current_integral.i_d_error_integral_As = 0.0f;
        inst->current_integral.i_q_error_integral_As = 0.0f;
        hold->speed_bias_rad_s = 0.0f;
        hold->vector_speed_rad_s = 0.0f;
        inst->scratch.run.standstill.vector_rate_rad_s = 0.0f; /* held: the frame does not turn */
        hold->active = true;
    }
    inst->estimate_kept = false; /* the standstill keeps it once its rotor has settled */
    return PMSTEP_OK;
}

pmstep_status_t pmstep_hold_vector(pmstep_t *inst, float cos_rest, float sin_rest, float current_A, float load_Nm)
{
    return pmstep_hold_engage(inst, cos_rest, sin_rest, current_A, load_Nm, false);
}

void pmstep_release_vector(pmstep_t *inst)
{
    if (inst != NULL && inst->hold.active) {
        inst->hold.active = false;
        inst->estimate_kept = false;
        inst->hold.vector_speed_rad_s = 0.0f;
        inst->scratch.run.standstill.vector_rate_rad_s = 0.0f;
        inst->current_integral.i_d_error_integral_As = 0.0f;
        inst->current_integral.i_q_error_integral_As = 0.0f;
    }
}

pmstep_status_t pmstep_set_angle_estimate(pmstep_t *inst, float cos_hat, float sin_hat)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_RUN || !inst->run_started) {
        return PMSTEP_ERR_BAD_MODE;
    }
    if (!pmstep_all_finite4(cos_hat, sin_hat, 0.0f, 0.0f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_angle_set(&inst->angle, &inst->derived.angle_coeffs, cos_hat, sin_hat);
    pmstep_angle_smoother_set(&inst->scratch.run.smoother, cos_hat, sin_hat); /* and the smoothing's */
    return PMSTEP_OK;
}

/* The hold's arithmetic is written out here, not through pmstep_park(), pmstep_law_voltages()
 * or pmstep_small_rotation(): a second caller makes -Os keep those out of line, and the RUN
 * step then pays their calls every period (LTO image: about 40 instructions a period). */
void pmstep_hold_voltages(pmstep_t *inst, pmstep_observer_input_t *obs_in, pmstep_output_t *out)
{
    pmstep_vector_hold_t *hold = &inst->hold;
    const pmstep_law_coeffs_t *law = &inst->derived.law_coeffs;
    const float vector_speed = hold->vector_speed_rad_s;
    const float speed_change = inst->observer.speed_hat_rad_s - vector_speed - hold->speed_bias_rad_s;
    /* the frame's own speed: the rotor's w_v plus the load angle's rate (the detent torque's); 0
     * wherever the vector does not turn (every path that stops it zeroes it: no test here, which
     * every period of a position hold would pay) */
    const float frame_speed = inst->scratch.run.standstill.vector_rate_rad_s;
    float turn = -hold->damping_s * speed_change;
    float c;
    float s;
    float c_act;
    float s_act;
    float i_d_err;
    float i_q_err;
    float u_d;
    float u_q;
    if (pmstep_abs(turn) > PMSTEP_HOLD_MAX_DAMPING_TURN) {
        turn = turn > 0.0f ? PMSTEP_HOLD_MAX_DAMPING_TURN : -PMSTEP_HOLD_MAX_DAMPING_TURN;
    }
    hold->speed_bias_rad_s += hold->bias_gain * speed_change; /* w-bar: (w-hat - w_v) low-passed at w_n / 20 */
    {
        /* the vector turned by the damping, (cos t, sin t) to second order: |t| <= 0.5, and the
         * frame needs no more than a damping term's accuracy */
        const float cos_turn = 1.0f - 0.5f * turn * turn;
        c = hold->cos_vector * cos_turn - hold->sin_vector * turn;
        s = hold->sin_vector * cos_turn + hold->cos_vector * turn;
    }
    {
        /* the frame the voltage acts in: turned on at w_frame over the delay and half the period
         * (none at rest), to second order (pmstep_law_acting_angle's first terms: at the band's
         * speed the turn is a few hundredths of a radian) */
        const float cos_act = 1.0f + frame_speed * frame_speed * law->turn_cos_w2;
        const float sin_act = frame_speed * law->turn_sin_w1;
        c_act = c * cos_act - s * sin_act;
        s_act = s * cos_act + c * sin_act;
    }
    hold->cos_frame = c_act;
    hold->sin_frame = s_act;
    /* the currents in the frame (Park), their errors from i_d* = I, i_q* = 0 */
    i_d_err = c * obs_in->i_a_A + s * obs_in->i_b_A - hold->current_A;
    i_q_err = c * obs_in->i_b_A - s * obs_in->i_a_A;
    obs_in->i_d_err_A = i_d_err; /* the PI integral's errors (the observer of (6) reads none) */
    obs_in->i_q_err_A = i_q_err;
    /* the law's current loop (pmstep_law_voltages) at zero speed: u = L [(R/L) i* - K_i e - K_I z] */
    u_d = law->inductance_H
          * (law->r_over_l_per_s * hold->current_A - law->current_gain_per_s * i_d_err
             - law->current_integral_gain_per_s2 * inst->current_integral.i_d_error_integral_As);
    /* turning: L I p w_frame for the vector's rotation and the back-EMF k_M w_v, on q (the load
     * angle's share on d is left to the integral) */
    u_q = law->inductance_H
          * (frame_speed * law->pole_pairs * hold->current_A + vector_speed * law->km_over_l
             - law->current_gain_per_s * i_q_err
             - law->current_integral_gain_per_s2 * inst->current_integral.i_q_error_integral_As);
    out->u_a_V = c_act * u_d - s_act * u_q;
    out->u_b_V = s_act * u_d + c_act * u_q;
}
