/* Vector hold at the end of a move (pmstep_position.h, "Vector hold"; the core's side in
 * pmstep_hold.h). */
#include "pmstep_position_internal.h"

#include <math.h> /* fabsf, sqrtf: one instruction each, no libm call */

/* The periods at rest before a re-aim, the error (electrical rad) that makes one, and the
 * largest error a move may end with to aim at all. */
#define POSITION_REAIM_PERIODS ((int32_t)200)
#define POSITION_REAIM_ERROR_RAD 0.05f
#define POSITION_AIM_MAX_ERROR_RAD 1.0f
/* The wait before aiming, in time constants 1/k_theta of the position loop: the load estimate
 * settles after the deceleration (its transient would aim the vector off; the paper motor's
 * T_L-hat is 2e-3 N m at a move's end, 1e-4 N m 90 ms later). */
#define POSITION_AIM_WAIT_TIME_CONSTANTS 2.0f

/* Aims the core's vector at (pos->rest_cos, rest_sin) ahead by the load angle of
 * pos->aim_load_Nm; false (the stage refused, no vector) for a load beyond the vector's pull. */
static bool aim_core_vector(pmstep_position_t *pos)
{
    const bool aimed =
        pmstep_hold_vector(pos->inst, pos->rest_cos, pos->rest_sin, pos->cfg.hold_current_A, pos->aim_load_Nm)
        == PMSTEP_OK;
    if (!aimed) {
        pmstep_release_vector(pos->inst); /* the loop holds on */
        pos->hold_stage = POSITION_HOLD_REFUSED;
    }
    return aimed;
}

bool pmstep_position_vector_held(const pmstep_position_t *pos)
{
    return (pos->hold_stage == POSITION_HOLD_SETTLING) || (pos->hold_stage == POSITION_HOLD_ANCHORED)
           || (pos->hold_stage == POSITION_HOLD_REAIMED);
}

/* Vector hold: the vector aimed; the speed reference at rest, the loop's integral cleared (the
 * vector carries the load), and a settling time before the rest is counted. */
static void hold_at_rest(pmstep_position_t *pos, int32_t stage)
{
    pmstep_t *inst = pos->inst;
    if (!aim_core_vector(pos)) {
        return;
    }
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pos->error_integral_rad_s = 0.0f;
    pos->hold_stage = stage;
    pos->hold_periods = (int32_t)inst->hold.settle_periods;
    pos->reading_turned = false;
}

/* The target's direction is the estimate's turned by the error left, p (theta* - theta-hat)
 * (within POSITION_AIM_MAX_ERROR_RAD, else the loop holds on). */
static void aim_vector(pmstep_position_t *pos, float position_rad)
{
    const float error = (pos->now.position - position_rad) / pos->inv_pole_pairs;
    const float length = sqrtf(pos->cos_hat * pos->cos_hat + pos->sin_hat * pos->sin_hat);
    float cos_error;
    float sin_error;
    if (!(fabsf(error) <= POSITION_AIM_MAX_ERROR_RAD && length > 0.0f)) {
        pos->hold_stage = POSITION_HOLD_REFUSED;
        return;
    }
    pmstep_small_rotation(error, &cos_error, &sin_error);
    pmstep_turn(pos->cos_hat / length, pos->sin_hat / length, cos_error, sin_error, &pos->rest_cos, &pos->rest_sin);
    pos->aim_load_Nm = pos->inst->observer.load_hat_Nm;
    hold_at_rest(pos, POSITION_HOLD_SETTLING);
}

void pmstep_position_wait_and_aim(pmstep_position_t *pos, float position_rad)
{
    if (pos->hold_stage == POSITION_HOLD_NONE) {
        pos->hold_stage = POSITION_HOLD_WAITING;
        pos->hold_periods = (int32_t)(POSITION_AIM_WAIT_TIME_CONSTANTS / (pos->cfg.gain_per_s * pos->period_s));
    }
    pos->hold_periods -= PMSTEP_POSITION_DECIMATION;
    if (pos->hold_periods <= 0) {
        aim_vector(pos, position_rad);
    }
}

/* The rotor rests p (theta* - theta-hat) from the target: the vector's aim is turned by that
 * displacement (at most POSITION_AIM_MAX_ERROR_RAD a time), its load angle kept. The estimate
 * over the short rest measures what T_L-hat cannot: held, the observer sees the vector's own
 * torque and T_L-hat only confirms the aim. The rotor follows the vector by the same turn, and
 * so does the kept estimate, through the settling too: left to the flux integrals there (which
 * drift at rest), each re-aim would take their drift as the next displacement and walk the
 * rotor off step by step (17HS4401 case 100035: 0.17 to 1.46 electrical rad over 23 s of hold). */
static void correct_aim(pmstep_position_t *pos)
{
    float error = pos->out.position_error_rad / pos->inv_pole_pairs;
    float cos_error;
    float sin_error;
    float c;
    if (fabsf(error) > POSITION_AIM_MAX_ERROR_RAD) {
        error = error > 0.0f ? POSITION_AIM_MAX_ERROR_RAD : -POSITION_AIM_MAX_ERROR_RAD;
    }
    pmstep_small_rotation(error, &cos_error, &sin_error);
    c = pos->rest_cos;
    pmstep_turn(c, pos->rest_sin, cos_error, sin_error, &pos->rest_cos, &pos->rest_sin);
    c = pos->frozen_cos;
    pmstep_turn(c, pos->frozen_sin, cos_error, sin_error, &pos->frozen_cos, &pos->frozen_sin);
    hold_at_rest(pos, POSITION_HOLD_REAIMED);
}

/* The kept estimate put back into the core's angle integrals: pmstep_angle_set itself, not
 * pmstep_set_angle_estimate, whose checks (RUN, finite values) hold here already (a hold runs in
 * RUN, and the kept estimate is the core's own output) and cost the position-mode period 1.5
 * instructions on the mean (pil.position_cost). */
static void put_back_kept_estimate(pmstep_position_t *pos)
{
    pmstep_angle_set(&pos->inst->angle, &pos->inst->derived.angle_coeffs, pos->frozen_cos, pos->frozen_sin);
}

/* Whether the flux integrals' reading is within POSITION_READING_MOTION_BANDS quiet bands' turn
 * over one update (PMSTEP_POSITION_DECIMATION periods, p w_band N T_s electrical rad a band) of
 * the estimate last taken or kept. w-hat alone does not tell: a load step swings the held rotor
 * at the hold's natural frequency, above the observer's bandwidth, and w-hat lags it by more than
 * a quarter turn (17HS4401 at 1.7 A, 257 Hz: w-hat +0.6 rad/s, within the band, with the rotor at
 * -8). The reading follows the swing; |c_k s-hat - s_k c-hat| is sin of the turn, the estimate
 * near unit length. */
static bool reading_at_rest(const pmstep_position_t *pos, float band_rad_s)
{
    const float turn_limit_rad = POSITION_READING_MOTION_BANDS * band_rad_s
                                 * ((float)PMSTEP_POSITION_DECIMATION * pos->period_s) / pos->inv_pole_pairs;
    return fabsf((pos->frozen_cos * pos->sin_hat) - (pos->frozen_sin * pos->cos_hat)) < turn_limit_rad;
}

/* At rest for one more update; after a settling time of it, the estimate is kept (taken then,
 * not when the rest began: the ring-down's last motion would be lost); POSITION_REAIM_PERIODS
 * later, if more than POSITION_REAIM_ERROR_RAD from the target, re-aimed. */
static void one_more_update_at_rest(pmstep_position_t *pos)
{
    const int32_t keep_after = (int32_t)pos->inst->hold.settle_periods;
    pos->hold_periods += PMSTEP_POSITION_DECIMATION;
    if ((pos->hold_periods - PMSTEP_POSITION_DECIMATION) < keep_after) {
        pos->frozen_cos = pos->cos_hat;
        pos->frozen_sin = pos->sin_hat;
    } else {
        put_back_kept_estimate(pos);
    }
    if ((pos->hold_periods >= (keep_after + POSITION_REAIM_PERIODS))
        && ((fabsf(pos->out.position_error_rad) / pos->inv_pole_pairs) > POSITION_REAIM_ERROR_RAD)) {
        correct_aim(pos);
    }
}

/* An update in a vector hold: settling (after a re-aim, with the turned estimate kept), then the
 * estimate kept while the rotor is at rest (it would drift: nothing observes its phase at zero
 * speed) and followed while the rotor moves (w-hat beyond the quiet band, or the flux integrals'
 * reading turned beyond its limit in two updates running: reading_at_rest);
 * after POSITION_REAIM_PERIODS more at rest more than POSITION_REAIM_ERROR_RAD from the target
 * (the aim's load angle off, or the load changed), the aim is corrected (pmstep_position.h). */
void pmstep_position_vector_hold(pmstep_position_t *pos, float position_rad)
{
    pmstep_t *inst = pos->inst;
    pos->out.moving = false;
    pos->out.position_ref_rad = pos->now.position;
    pos->out.position_error_rad = pos->now.position - position_rad;
    if (pos->hold_stage != POSITION_HOLD_ANCHORED) {
        const bool reaimed = pos->hold_stage == POSITION_HOLD_REAIMED;
        if (reaimed) {
            put_back_kept_estimate(pos);
        }
        pos->hold_periods -= PMSTEP_POSITION_DECIMATION;
        if (pos->hold_periods <= 0) {
            /* settled: the rest is counted from here; after a re-aim with the estimate already kept */
            pos->hold_periods = reaimed ? (int32_t)inst->hold.settle_periods : 0;
            pos->hold_stage = POSITION_HOLD_ANCHORED;
        }
    } else {
        const bool quiet = fabsf(pos->speed_hat_rad_s - inst->hold.speed_bias_rad_s) < inst->hold.quiet_band_rad_s;
        const bool reading_still = reading_at_rest(pos, inst->hold.quiet_band_rad_s);
        if (quiet && reading_still) {
            pos->reading_turned = false;
            one_more_update_at_rest(pos);
        } else if (quiet && !pos->reading_turned) {
            /* turned beyond the limit once: a swing's first update, or the reading's noise at its
             * rare largest; neither kept nor re-aimed on it */
            pos->reading_turned = true;
        } else {
            /* moving (w-hat, or the reading turned in two updates running): the estimate follows
             * the flux integrals, the last reading the next one's reference */
            pos->hold_periods = 0;
            pos->reading_turned = false;
            pos->frozen_cos = pos->cos_hat;
            pos->frozen_sin = pos->sin_hat;
        }
    }
}

/* Ends a vector hold (a move, a stop). A vector that held the rotor leaves the law T_L-hat of its
 * aim: held, the observer balanced the vector's torque at the estimated angle, and an angle error
 * e there puts k_M I sin(e) of the hold current into T_L-hat (the 17HS4401 at 1.7 A: 0.045 N m
 * for e = 0.16 rad), a torque the rotor does not have once the current falls to the law's. */
void pmstep_position_release_hold(pmstep_position_t *pos)
{
    if (pmstep_position_vector_held(pos)) {
        pos->inst->observer.load_hat_Nm = pos->aim_load_Nm;
    }
    if (pos->hold_stage != POSITION_HOLD_NONE) {
        pmstep_release_vector(pos->inst);
        pos->hold_stage = POSITION_HOLD_NONE;
    }
}
