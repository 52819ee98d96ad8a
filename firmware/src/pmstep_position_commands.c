/* The position control's commands (pmstep_position.h): a new zero, moves, stops, rest, following a
 * STEP/DIR count. Each plans the reference the loop of pmstep_position.c follows from the next period. */
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "pmstep_position_internal.h"

#include <math.h> /* fabsf: one instruction, no libm call */
#include <stddef.h>

pmstep_status_t pmstep_position_set_zero(pmstep_position_t *pos)
{
    float position_rad;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    (void)pmstep_get_position(pos, &position_rad); /* tracked: theta-hat */
    pos->turns = 0;
    pos->zero_rad = pmstep_atan2_poly(pos->sin_hat, pos->cos_hat);
    pmstep_motion_shift(&pos->motion, -position_rad);
    if (pos->steps != NULL) {
        pos->steps->origin_rad -= position_rad;
        pos->steps->position_rad -= position_rad;
    }
    pos->now.position -= position_rad;
    pos->ahead.position -= position_rad;
    pos->out.position_rad -= position_rad;
    pos->out.position_ref_rad -= position_rad;
    return PMSTEP_OK;
}

/* Where a profile starts: the next period's reference (position mode), or theta-hat moved on by
 * one period with the speed reference's present w*, w*' (speed mode). */
static pmstep_motion_sample_t profile_start(const pmstep_position_t *pos)
{
    pmstep_motion_sample_t start;
    if (pos->out.position_mode) {
        start = pos->ahead; /* the next update's sample */
    } else {
        const pmstep_ref_out_t ref = pmstep_ref_output(&pos->inst->derived.ref_coeffs, &pos->inst->speed_ref);
        float position_rad;
        (void)pmstep_get_position(pos, &position_rad); /* tracked: every command checks it first */
        start.position = position_rad + pos->period_s * pos->speed_hat_rad_s;
        start.speed = ref.value;
        start.accel = ref.rate;
        start.jerk = 0.0f;
    }
    return start;
}

/* Enters position mode (the loop's integral starts at 0 when it was off, and its updates restart
 * with the next period: the profile's start is that period's). From speed mode the
 * speed channel is put at its own present output with the set-point held there: the coming
 * period reads the same reference, and no ramp of the speed command is left to be taken for a
 * new speed command. */
static void enter_position_mode(pmstep_position_t *pos)
{
    const bool was_position_mode = pos->out.position_mode;
    pmstep_leave_speed_mode(pos->inst); /* the loop's reference from now: no standstill hold of speed mode */
    if (!was_position_mode) {
        const pmstep_ref_out_t ref = pmstep_ref_output(&pos->inst->derived.ref_coeffs, &pos->inst->speed_ref);
        const float step_s = pos->motion.period_s;
        /* the next period reads (w*, w*', w*''); the update after it puts the loop's own */
        pmstep_position_put_speed_reference(pos, ref.value, ref.rate, ref.accel,
                                            ref.value + step_s * (ref.rate + 0.5f * step_s * ref.accel));
        pos->error_integral_rad_s = 0.0f;
        pos->loop_countdown = 1; /* the loop's first update after the next period */
    }
    pos->out.position_mode = true;
    pos->out.moving = !pmstep_motion_finished(&pos->motion);
    pos->ahead = pmstep_motion_next(&pos->motion); /* the new plan's start, for the next update */
    if (!was_position_mode) {
        pos->now = pos->ahead; /* pmstep_position_reference() until then */
    }
}

pmstep_status_t pmstep_position_move_to(pmstep_position_t *pos, float target_rad, float v_max_rad_s, float a_max_rad_s2,
                                        float j_max_rad_s3)
{
    pmstep_motion_sample_t start;
    float electrical;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    electrical = fabsf(target_rad) / pos->inv_pole_pairs;
    if (!(electrical <= PMSTEP_POSITION_MAX_ELECTRICAL_RAD) || !(v_max_rad_s > 0.0f) || !(a_max_rad_s2 > 0.0f)
        || !(j_max_rad_s3 >= 0.0f) || (v_max_rad_s - v_max_rad_s) != 0.0f || (a_max_rad_s2 - a_max_rad_s2) != 0.0f
        || (j_max_rad_s3 - j_max_rad_s3) != 0.0f) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE; /* NaN fails every compare; Inf - Inf is NaN */
    }
    pmstep_position_release_hold(pos);
    pmstep_position_stop_following(pos);
    start = profile_start(pos);
    pmstep_motion_plan(&pos->motion, start.position, start.speed, start.accel, target_rad, v_max_rad_s, a_max_rad_s2,
                       (j_max_rad_s3 > 0.0f) ? j_max_rad_s3 : (a_max_rad_s2 / pos->inv_bandwidth_s));
    enter_position_mode(pos);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_hold(pmstep_position_t *pos, float a_max_rad_s2)
{
    pmstep_motion_sample_t start;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    if (!pos->out.position_mode) {
        if (!(a_max_rad_s2 > 0.0f) || (a_max_rad_s2 - a_max_rad_s2) != 0.0f) {
            return PMSTEP_ERR_BAD_COMMAND_VALUE;
        }
        pos->motion.a_max = a_max_rad_s2;
        pos->motion.j_max = a_max_rad_s2 / pos->inv_bandwidth_s;
    }
    pmstep_position_release_hold(pos);
    pmstep_position_stop_following(pos);
    start = profile_start(pos);
    pmstep_motion_stop(&pos->motion, &start);
    enter_position_mode(pos);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_rest_here(pmstep_position_t *pos)
{
    pmstep_motion_sample_t start;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    pmstep_position_release_hold(pos);
    pmstep_position_stop_following(pos);
    /* the speed channel at rest and position mode entered afresh: the loop's integral at 0 */
    pmstep_ref_reset(&pos->inst->speed_ref, 0.0f);
    pos->out.position_mode = false;
    start = profile_start(pos);
    pmstep_motion_reset(&pos->motion, start.position, pos->motion.period_s);
    enter_position_mode(pos);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_follow_steps(pmstep_position_t *pos, struct pmstep_stepdir *sd)
{
    pmstep_motion_sample_t start;
    if (pos == NULL || sd == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    if (!(sd->cfg.stall_current_A < pos->inst->cfg->limits.max_phase_current_A)) {
        return PMSTEP_ERR_STEPDIR_STALL_CURRENT;
    }
    pmstep_position_release_hold(pos);
    start = profile_start(pos);
    pmstep_position_stop_following(pos);
    pmstep_motion_reset(&pos->motion, start.position, pos->motion.period_s); /* no move left to resume */
    pmstep_stepdir_start(sd, &start);
    sd->rest_load_Nm = pos->inst->observer.load_hat_Nm;
    pos->steps = sd;
    enter_position_mode(pos);
    pos->ahead = start;
    pos->now = start;
    pos->out.moving = true;
    return PMSTEP_OK;
}
