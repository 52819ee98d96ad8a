/* The standstill hold of speed mode and the low-speed drive (pmstep_hold.h), on the vector hold
 * of pmstep_hold.c. */
#include "pmstep_internal.h"

#include <stddef.h>

/* The most a vector can be clear of both phase axes: 1/sqrt(2), on a diagonal. */
#define HOLD_MAX_CLEAR_SIN 0.70710678f

void pmstep_standstill_start(pmstep_t *inst)
{
    pmstep_standstill_t *standstill = &inst->scratch.run.standstill;
    const float current_A = inst->cfg->standstill.hold_current_A;
    inst->hold.standstill_engaged = false;
    inst->hold.standstill_settled = false;
    inst->estimate_kept = false;
    standstill->rest_periods = 0u;
    standstill->keep_cos = 1.0f;
    standstill->keep_sin = 0.0f;
    standstill->motion_rad = 0.0f;
    standstill->motion_leak = 0.0f;
    standstill->drift_rad = 0.0f;
    standstill->aim_load_Nm = 0.0f;
    standstill->vector_rate_rad_s = 0.0f;
    inst->hold.standstill_armed = current_A > 0.0f;
    standstill->quiet_band_rad_s = 0.0f;
    standstill->engage_periods = 0u;
    if (inst->hold.standstill_armed) {
        const pmstep_law_coeffs_t *law = &inst->derived.law_coeffs;
        standstill->quiet_band_rad_s =
            PMSTEP_HOLD_QUIET_FRACTION * pmstep_hold_natural_rad_s(law, current_A, 1.0f) / law->pole_pairs;
        standstill->engage_periods = pmstep_hold_period_count(
            PMSTEP_STANDSTILL_ENGAGE_TIME_CONSTANTS / (inst->cfg->gains.speed_gain_per_s * inst->cfg->timing.period_s));
    }
}

/* The low-speed drive is on and the reference is not at rest: the vector turns. */
static bool standstill_turning(const pmstep_t *inst, const pmstep_standstill_t *standstill, const pmstep_output_t *out)
{
    return inst->cfg->standstill.vector_speed_rad_s > 0.0f
           && pmstep_abs(out->speed_ref_rad_s) >= PMSTEP_STANDSTILL_REFERENCE_FRACTION * standstill->quiet_band_rad_s;
}

/* (c, s) moved to the nearest direction whose smaller component is at least min_sin (at most
 * 1/sqrt(2)): a vector with both phase currents clear of zero. */
static void aim_clear_of_phase_axes(float *c, float *s, float min_sin)
{
    const float larger = sqrtf(1.0f - min_sin * min_sin);
    if (pmstep_abs(*s) < min_sin) {
        *s = *s < 0.0f ? -min_sin : min_sin;
        *c = *c < 0.0f ? -larger : larger;
    } else if (pmstep_abs(*c) < min_sin) {
        *c = *c < 0.0f ? -min_sin : min_sin;
        *s = *s < 0.0f ? -larger : larger;
    } else {
        /* clear already */
    }
}

/* The rest (c, s) turned with the vector load_Nm's load angle ahead of it, so that the vector's
 * currents are clear of zero by PMSTEP_HOLD_PHASE_CLEARANCE_BANDS compensation bands
 * (aim_clear_of_phase_axes; at most on a diagonal); the load angle is the one at the rest before
 * the turn (the detent torque's change over the turn is left, a few hundredths of a radian).
 * Unchanged where the load is beyond the vector's pull (pmstep_hold_vector refuses it). */
static void rest_for_clear_vector(const pmstep_t *inst, float *c, float *s, float load_Nm)
{
    const pmstep_law_coeffs_t *law = &inst->derived.law_coeffs;
    const float current_A = inst->cfg->standstill.hold_current_A;
    const float clear_sin =
        PMSTEP_HOLD_PHASE_CLEARANCE_BANDS * inst->cfg->inverter.dead_time_current_band_A / current_A;
    const float min_sin = (clear_sin < HOLD_MAX_CLEAR_SIN) ? clear_sin : HOLD_MAX_CLEAR_SIN;
    const pmstep_detent_t detent = pmstep_law_detent(law, *c, *s, 0.0f);
    pmstep_hold_aim_t aim = {1.0f, 0.0f, 1.0f};
    if (pmstep_hold_aim_ahead(law, *c, *s, current_A, load_Nm, 0.0f, &detent, &aim)) {
        float cos_clear = aim.cos_vector;
        float sin_clear = aim.sin_vector;
        aim_clear_of_phase_axes(&cos_clear, &sin_clear, min_sin);
        /* the rest turned by the vector's turn, (cos_clear, sin_clear) against (cos_vector, sin_vector) */
        pmstep_turn(*c, *s, cos_clear * aim.cos_vector + sin_clear * aim.sin_vector,
                    sin_clear * aim.cos_vector - cos_clear * aim.sin_vector, c, s);
    }
}

/* A new vector's rest: its drift and motion learnt afresh, the sum leaking over its settling time. */
static void learn_rest_afresh(pmstep_standstill_t *standstill, const pmstep_vector_hold_t *hold)
{
    const uint32_t leak_periods = hold->settle_periods + 1u; /* a settling time, at least a period */
    standstill->drift_rad = 0.0f;
    standstill->motion_rad = 0.0f;
    standstill->motion_leak = 1.0f / (float)leak_periods;
}

/* |command| up to which a held vector stays engaged (and may engage): the low-speed drive's band,
 * 0 in stops only (a zero command) or without the drive. */
static float command_band_rad_s(const pmstep_t *inst)
{
    return inst->cfg->standstill.stops_only ? 0.0f : inst->cfg->standstill.vector_speed_rad_s;
}

/* Not yet holding: the hold once the zero command is reached and the rotor has been at rest for
 * engage_periods, aimed at the estimate (normalised) ahead by T_L-hat's load angle, the vector
 * and its rest turned clear of the phase axes (rest_for_clear_vector). */
static void standstill_engage(pmstep_t *inst, pmstep_standstill_t *standstill, const pmstep_output_t *out)
{
    const pmstep_ref_t *ref = &inst->speed_ref;
    const bool stops_only = inst->cfg->standstill.stops_only;
    /* 0: the standstill only; in stops only, the band while the set-point is on its way down */
    const float band_rad_s =
        (stops_only && !(pmstep_abs(ref->setpoint) > 0.0f)) ? 0.0f : inst->cfg->standstill.vector_speed_rad_s;
    const float target_band_rad_s = command_band_rad_s(inst);
    const float vector_speed = band_rad_s > 0.0f ? out->speed_ref_rad_s : 0.0f;
    const bool at_rest = !(pmstep_abs(ref->target) > target_band_rad_s) && !(pmstep_abs(ref->setpoint) > band_rad_s)
                         && pmstep_abs(out->speed_ref_rad_s)
                                < PMSTEP_STANDSTILL_REFERENCE_FRACTION * standstill->quiet_band_rad_s + band_rad_s
                         && pmstep_abs(out->speed_hat_rad_s - vector_speed) < standstill->quiet_band_rad_s + band_rad_s;
    inst->hold.standstill_engaged = false;
    if (!at_rest) {
        standstill->rest_periods = 0u;
        return;
    }
    standstill->rest_periods++;
    if (standstill->rest_periods >= standstill->engage_periods) {
        const float current_A = inst->cfg->standstill.hold_current_A;
        const float length = sqrtf(out->cos_hat * out->cos_hat + out->sin_hat * out->sin_hat);
        float c = 0.0f;
        float s = 0.0f;
        standstill->rest_periods = 0u;
        inst->hold.standstill_settled = false;
        if (length > 0.0f) {
            c = out->cos_hat / length;
            s = out->sin_hat / length;
            if (!standstill_turning(inst, standstill, out)) { /* a turning vector's currents cross zero anyway */
                rest_for_clear_vector(inst, &c, &s, inst->observer.load_hat_Nm);
            }
        }
        /* refused (a load beyond the vector's pull, an estimate at the origin): the law holds on */
        inst->hold.standstill_engaged =
            length > 0.0f && pmstep_hold_engage(inst, c, s, current_A, inst->observer.load_hat_Nm, true) == PMSTEP_OK;
        standstill->keep_cos = c; /* where the vector will hold the rotor: T_L-hat's load angle behind it */
        standstill->keep_sin = s;
        standstill->aim_load_Nm = inst->observer.load_hat_Nm;
        inst->hold.vector_speed_rad_s = vector_speed;
        standstill->vector_rate_rad_s = vector_speed;
        learn_rest_afresh(standstill, &inst->hold);
    }
}

/* The flux integrals' estimate of the period: out's, or, where the kept rotor was put out in
 * its place, the integrals' own read again at the period's sample (the angle corrections left
 * them alone but for the drift-free one's radial step, a few 1e-7 rad on a kept unit vector). */
typedef struct {
    float cos_hat;
    float sin_hat;
} sensed_angle_t;

static sensed_angle_t sensed_angle(const pmstep_t *inst, const pmstep_output_t *out)
{
    sensed_angle_t sensed = {out->cos_hat, out->sin_hat};
    if (inst->estimate_kept) {
        pmstep_angle_estimate(&inst->angle, &inst->derived.angle_coeffs, inst->angle.i_a_prev_A, inst->angle.i_b_prev_A,
                              &sensed.cos_hat, &sensed.sin_hat);
    }
    return sensed;
}

void pmstep_standstill_estimate(const pmstep_t *inst, float *cos_hat, float *sin_hat)
{
    const pmstep_standstill_t *standstill = &inst->scratch.run.standstill;
    *cos_hat = standstill->keep_cos;
    *sin_hat = standstill->keep_sin;
}

/* The turn of this period's integrals off the kept estimate (electrical rad, small). */
static float turn_off_kept(const pmstep_standstill_t *standstill, const sensed_angle_t *sensed)
{
    return (standstill->keep_cos * sensed->sin_hat) - (standstill->keep_sin * sensed->cos_hat);
}

/* (J w_v' + F w_v) / k_M (A): the current the vector's own speed profile takes; 0 at rest. */
static float hold_acceleration_A(const pmstep_law_coeffs_t *law, const pmstep_vector_hold_t *hold,
                                 const pmstep_output_t *out)
{
    const bool turning = pmstep_abs(hold->vector_speed_rad_s) > 0.0f;
    return turning ? law->j_over_km * (out->speed_ref_rate_rad_s2 + law->f_over_j_per_s * hold->vector_speed_rad_s)
                   : 0.0f;
}

/* The low-speed drive, each period the vector turns: the kept rotor advanced by p w* T_s (its
 * length put back to 1 by a Newton step), the vector aimed ahead of it by the load angle of
 * T_L + J w*' + F w* - T_detent. @return false where that is beyond the vector's pull
 * (PMSTEP_HOLD_MAX_TORQUE_FRACTION): the law takes over. */
static bool turn_vector(pmstep_t *inst, pmstep_standstill_t *standstill, const pmstep_output_t *out)
{
    const pmstep_law_coeffs_t *law = &inst->derived.law_coeffs;
    pmstep_vector_hold_t *hold = &inst->hold;
    const float turn = law->pole_pairs * out->speed_ref_rad_s * inst->cfg->timing.period_s;
    float c;
    float s;
    pmstep_hold_aim_t aim = {1.0f, 0.0f, 1.0f}; /* pmstep_hold_aim_ahead's */
    pmstep_detent_t detent;
    pmstep_turn(standstill->keep_cos, standstill->keep_sin, 1.0f - 0.5f * turn * turn, turn, &c, &s);
    {
        const float renorm = 1.5f - 0.5f * (c * c + s * s);
        c *= renorm;
        s *= renorm;
    }
    standstill->keep_cos = c;
    standstill->keep_sin = s;
    hold->vector_speed_rad_s = out->speed_ref_rad_s;
    detent = pmstep_law_detent(law, c, s, out->speed_ref_rad_s);
    if (!pmstep_hold_aim_ahead(law, c, s, hold->current_A, standstill->aim_load_Nm, hold_acceleration_A(law, hold, out),
                               &detent, &aim)) {
        return false;
    }
    hold->cos_vector = aim.cos_vector;
    hold->sin_vector = aim.sin_vector;
    /* d delta / dt = -(d T_detent / dt) / (k_M I cos delta) */
    standstill->vector_rate_rad_s =
        out->speed_ref_rad_s
        - detent.rate_Nm_s / (law->pole_pairs * law->km_over_l * law->inductance_H * hold->current_A * aim.cos_delta);
    return true;
}

/* The load T_L the held rotor at (c, s) balances: k_M I sin(v - x) + T_detent(x), less
 * J w_v' + F w_v where the vector turns (pmstep_hold_vector's relation solved for the load). */
static float held_balance_Nm(const pmstep_t *inst, float c, float s, const pmstep_output_t *out)
{
    const pmstep_law_coeffs_t *law = &inst->derived.law_coeffs;
    const pmstep_vector_hold_t *hold = &inst->hold;
    const pmstep_detent_t detent = pmstep_law_detent(law, c, s, 0.0f);
    return law->km_over_l * law->inductance_H
               * (hold->current_A * (hold->sin_vector * c - hold->cos_vector * s) - hold_acceleration_A(law, hold, out))
           + detent.torque_Nm;
}

/* The held rotor moved (a load step): the kept estimate turned by the summed motion ((cos t,
 * sin t) to second order), T_L-hat the held rotor's balance there, and the rest started again. */
static void follow_held_rotor(pmstep_t *inst, pmstep_standstill_t *standstill, const pmstep_output_t *out)
{
    const float turn = standstill->motion_rad;
    float c;
    float s;
    pmstep_turn(standstill->keep_cos, standstill->keep_sin, 1.0f - 0.5f * turn * turn, turn, &c, &s);
    pmstep_angle_set(&inst->angle, &inst->derived.angle_coeffs, c, s);
    inst->observer.load_hat_Nm = held_balance_Nm(inst, c, s, out);
    standstill->aim_load_Nm = inst->observer.load_hat_Nm;
    standstill->rest_periods = 0u;
    standstill->motion_rad = 0.0f;
}

/* One period of the standstill's hold: settling, then the kept estimate and the motion sum. */
static void standstill_hold_period(pmstep_t *inst, pmstep_standstill_t *standstill, const pmstep_output_t *out)
{
    const sensed_angle_t sensed = sensed_angle(inst, out);
    const bool turning = standstill_turning(inst, standstill, out);
    const float speed_change =
        inst->observer.speed_hat_rad_s - inst->hold.vector_speed_rad_s - inst->hold.speed_bias_rad_s;
    standstill->rest_periods++;
    if (turning && (inst->hold.standstill_settled || standstill->rest_periods < inst->hold.settle_periods)) {
        /* Turning: the flux integrals' phase is not the rotor's at low speed (the voltage errors
         * against a back-EMF of the same order), the estimate is the vector's aim throughout. */
        pmstep_angle_set(&inst->angle, &inst->derived.angle_coeffs, standstill->keep_cos, standstill->keep_sin);
        inst->estimate_kept = true;
    } else if (!inst->hold.standstill_settled) {
        inst->estimate_kept = false;
        if (standstill->rest_periods >= inst->hold.settle_periods) {
            /* Settled where the vector holds it (the aim: T_L-hat's load angle behind the vector),
             * not where the integrals drifted to while the current stepped up (R and voltage errors
             * times the hold current), unless they put the rotor beyond the motion bound from it (a
             * load T_L-hat did not know). T_L-hat the balance there, w-hat the rest's (its
             * transient from the step is behind), and no first settling time to take. */
            const float off_aim_rad = turning ? 0.0f : turn_off_kept(standstill, &sensed); /* turning: at the aim */
            inst->hold.standstill_settled = true;
            standstill->motion_rad = pmstep_abs(off_aim_rad) > PMSTEP_HOLD_MOTION_BOUND_RAD ? off_aim_rad : 0.0f;
            follow_held_rotor(inst, standstill, out);
            standstill->rest_periods = inst->hold.settle_periods + 1u;
            inst->observer.speed_hat_rad_s = inst->hold.vector_speed_rad_s + inst->hold.speed_bias_rad_s;
        }
    } else if (pmstep_abs(speed_change) < inst->hold.quiet_band_rad_s) {
        if (standstill->rest_periods <= inst->hold.settle_periods) {
            standstill->keep_cos = sensed.cos_hat; /* the rest's first settling time: taken */
            standstill->keep_sin = sensed.sin_hat;
            standstill->motion_rad = 0.0f;
            inst->estimate_kept = false;
            /* the load the vector is aimed for when it turns: the balance where the rotor came to rest */
            standstill->aim_load_Nm = held_balance_Nm(inst, sensed.cos_hat, sensed.sin_hat, out);
        } else {
            /* the period's turn of the integrals off the kept estimate less their learnt drift, summed
             * with the leak */
            const float turn_rad = turn_off_kept(standstill, &sensed);
            standstill->drift_rad +=
                PMSTEP_HOLD_DRIFT_LEAK_FRACTION * standstill->motion_leak * (turn_rad - standstill->drift_rad);
            standstill->motion_rad +=
                turn_rad - standstill->drift_rad - standstill->motion_leak * standstill->motion_rad;
            if (pmstep_abs(standstill->motion_rad) > PMSTEP_HOLD_MOTION_BOUND_RAD) {
                follow_held_rotor(inst, standstill, out);
                inst->estimate_kept = false;
            } else {
                pmstep_angle_set(&inst->angle, &inst->derived.angle_coeffs, standstill->keep_cos, standstill->keep_sin);
                inst->estimate_kept = true;
            }
        }
    } else {
        standstill->rest_periods = 0u; /* moving: the estimate follows the flux integrals */
        inst->estimate_kept = false;
    }
}

/* The low-speed drive's vector has stopped turning: aimed afresh at its kept rotor for T_L,aim,
 * clear of the phase axes as an engagement at rest is (the rest it stopped at may put a phase
 * current in the dead-time band, where the motion sum would read the integrals' drift as
 * motion), and settled again. A load beyond its pull: released to the law. */
static void stop_turning(pmstep_t *inst, pmstep_standstill_t *standstill)
{
    float c = standstill->keep_cos;
    float s = standstill->keep_sin;
    rest_for_clear_vector(inst, &c, &s, standstill->aim_load_Nm);
    if (pmstep_hold_engage(inst, c, s, inst->hold.current_A, standstill->aim_load_Nm, true) == PMSTEP_OK) {
        standstill->keep_cos = c;
        standstill->keep_sin = s;
        inst->hold.standstill_settled = false;
        standstill->rest_periods = 0u;
        learn_rest_afresh(standstill, &inst->hold);
    } else {
        inst->observer.load_hat_Nm = standstill->aim_load_Nm; /* the law starts from the aim's */
        pmstep_release_vector(inst);
        inst->hold.standstill_engaged = false;
        standstill->rest_periods = 0u;
    }
}

void pmstep_standstill_advance(pmstep_t *inst, const pmstep_output_t *out)
{
    pmstep_standstill_t *standstill = &inst->scratch.run.standstill;
    if (!inst->hold.active) {
        standstill_engage(inst, standstill, out);
        return;
    }
    if (!inst->hold.standstill_engaged) {
        return; /* a hold of the application's own (pmstep_hold_vector) */
    }
    standstill_hold_period(inst, standstill, out);
    if (!standstill_turning(inst, standstill, out)) {
        /* stopped for good (a reversal only passes through zero) */
        const bool was_turning = pmstep_abs(inst->hold.vector_speed_rad_s) > 0.0f;
        const bool zero_command =
            !(pmstep_abs(inst->speed_ref.target) > 0.0f) && !(pmstep_abs(inst->speed_ref.setpoint) > 0.0f);
        if (was_turning && zero_command) {
            stop_turning(inst, standstill);
        }
        inst->hold.vector_speed_rad_s = 0.0f; /* at rest the vector stays where it is */
        standstill->vector_rate_rad_s = 0.0f;
    } else if (!turn_vector(inst, standstill, out)) {
        pmstep_release_vector(inst); /* a load beyond the turning vector's pull: the law's */
        inst->hold.standstill_engaged = false;
        standstill->rest_periods = 0u;
    } else {
        /* turned and aimed for the next period */
    }
}

void pmstep_standstill_command(pmstep_t *inst, float target_rad_s)
{
    const bool in_run = inst->mode == PMSTEP_MODE_RUN && inst->run_started;
    if (!in_run || pmstep_abs(target_rad_s) > command_band_rad_s(inst) || !inst->hold.standstill_engaged) {
        /* the low-speed drive's law starts from the aim's T_L; in stops only it keeps the observer's,
         * as the standstill's own release does (with the aim's, the envelope's steps changed) */
        if (inst->hold.standstill_engaged && inst->cfg->standstill.vector_speed_rad_s > 0.0f
            && !inst->cfg->standstill.stops_only) {
            inst->observer.load_hat_Nm = inst->scratch.run.standstill.aim_load_Nm;
        }
        pmstep_release_vector(inst); /* a speed command ends a hold; a zero one keeps the standstill's */
        inst->hold.standstill_engaged = false;
    }
    if (in_run) {
        inst->hold.standstill_armed = inst->cfg->standstill.hold_current_A > 0.0f; /* speed mode again */
    }
}

void pmstep_leave_speed_mode(pmstep_t *inst)
{
    if (inst != NULL && inst->mode == PMSTEP_MODE_RUN && inst->run_started) {
        pmstep_standstill_t *standstill = &inst->scratch.run.standstill;
        if (inst->hold.standstill_engaged) {
            pmstep_release_vector(inst);
            inst->hold.standstill_engaged = false;
        }
        inst->hold.standstill_armed = false;
        standstill->rest_periods = 0u;
    }
}
