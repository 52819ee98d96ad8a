/* Sensorless position control on the speed controller (pmstep_position.h). */
#include "pmstep/pmstep_position.h"

#include <math.h> /* fabsf: one instruction, no libm call */
#include <stddef.h>

#define POSITION_ONE ((int32_t)1)
#define POSITION_ZERO ((int32_t)0)
#define POSITION_PI 3.14159265358979f
/* 2 pi = HI + LO with HI = 201/32 exact in 8 bits: n HI is exact for |n| < 2^16 turns. */
#define POSITION_TWO_PI_HI 6.28125f
#define POSITION_TWO_PI_LO 1.93530717958648e-3f

/* atan(z) on [0, 1], odd polynomial of degree 9 (Abramowitz & Stegun 4.4.49, |error| <= 1e-5). */
#define ATAN_C1 0.9998660f
#define ATAN_C3 (-0.3302995f)
#define ATAN_C5 0.1801410f
#define ATAN_C7 (-0.0851330f)
#define ATAN_C9 0.0208351f

float pmstep_atan2_poly(float y, float x)
{
    const float ax = fabsf(x);
    const float ay = fabsf(y);
    const float big = ax > ay ? ax : ay;
    const float small = ax > ay ? ay : ax;
    float z;
    float z2;
    float angle;
    if (!(big > 0.0f)) {
        return 0.0f;
    }
    z = small / big;
    z2 = z * z;
    angle = z * (ATAN_C1 + z2 * (ATAN_C3 + z2 * (ATAN_C5 + z2 * (ATAN_C7 + z2 * ATAN_C9))));
    if (ay > ax) {
        angle = 0.5f * POSITION_PI - angle;
    }
    if (x < 0.0f) {
        angle = POSITION_PI - angle;
    }
    return y < 0.0f ? -angle : angle;
}

pmstep_status_t pmstep_position_design(const pmstep_config_t *cfg, pmstep_position_config_t *pos_cfg)
{
    if (cfg == NULL || pos_cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    pos_cfg->gain_per_s = 0.25f * cfg->gains.speed_gain_per_s;
    pos_cfg->integral_gain_per_s2 = pos_cfg->gain_per_s * pos_cfg->gain_per_s / 8.0f;
    return PMSTEP_OK;
}

/* theta-hat (mechanical rad) from the last estimate, the turn count and the zero. */
static float estimate(const pmstep_position_t *pos)
{
    const float fine = pmstep_atan2_poly(pos->sin_hat, pos->cos_hat) - pos->zero_rad;
    const float turns = (float)pos->turns;
    return (POSITION_TWO_PI_HI * turns + (POSITION_TWO_PI_LO * turns + fine)) * pos->inv_pole_pairs;
}

pmstep_status_t pmstep_position_init(pmstep_position_t *pos, pmstep_t *inst, const pmstep_position_config_t *cfg)
{
    const pmstep_config_t *core;
    if (pos == NULL || inst == NULL || cfg == NULL || inst->cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    core = inst->cfg;
    if ((cfg->gain_per_s - cfg->gain_per_s) != 0.0f || (cfg->integral_gain_per_s2 - cfg->integral_gain_per_s2) != 0.0f) {
        return PMSTEP_ERR_NONFINITE_PARAMETER;
    }
    if (!(cfg->gain_per_s > 0.0f) || cfg->gain_per_s > 0.5f * core->gains.speed_gain_per_s) {
        return PMSTEP_ERR_POSITION_GAIN;
    }
    if (cfg->integral_gain_per_s2 < 0.0f || cfg->integral_gain_per_s2 > 0.25f * cfg->gain_per_s * cfg->gain_per_s) {
        return PMSTEP_ERR_POSITION_INTEGRAL_GAIN;
    }
    pos->inst = inst;
    pos->cfg = *cfg;
    pos->inv_pole_pairs = 1.0f / (float)core->motor.pole_pairs;
    pos->period_s = core->timing.period_s;
    pos->inv_bandwidth_s = 1.0f / inst->ref_coeffs.bandwidth_rad_s;
    pos->cos_hat = 1.0f;
    pos->sin_hat = 0.0f;
    pos->speed_hat_rad_s = 0.0f;
    pos->zero_rad = 0.0f;
    pos->turns = 0;
    pos->sin_negative = 0;
    pos->tracked = false;
    pos->position_mode = false;
    pos->position_ref_rad = 0.0f;
    pos->error_integral_rad_s = 0.0f;
    pmstep_motion_reset(&pos->motion, 0.0f, pos->period_s);
    return PMSTEP_OK;
}

/* Puts the speed reference channel at (w*, w*', w*'') with its set-point held at w*: the law
 * reads exactly these in the next period (pmstep_ref_output), and a speed command given
 * meanwhile ramps on from w* (pmstep_ref_set_target). */
static void put_speed_reference(pmstep_position_t *pos, float speed, float rate, float accel)
{
    pmstep_ref_t *ref = &pos->inst->speed_ref;
    const float inv_w0 = pos->inv_bandwidth_s;
    pmstep_ref_reset(ref, speed); /* at rest on w*, then the filter's differences for w*', w*'' */
    ref->diff23 = rate * inv_w0;
    ref->diff12 = accel * inv_w0 * inv_w0 + ref->diff23;
}

/* Position mode, after period k: the profile at k+1 and the loop on the estimate moved on to k+1. */
static void position_loop(pmstep_position_t *pos, float position_rad)
{
    const float k_p = pos->cfg.gain_per_s;
    const float k_i = pos->cfg.integral_gain_per_s2;
    const pmstep_motion_sample_t ref = pmstep_motion_next(&pos->motion);
    const float predicted_rad = position_rad + pos->period_s * pos->speed_hat_rad_s;
    const float error_rad = ref.position - predicted_rad;
    const float speed_error = ref.speed - pos->speed_hat_rad_s;
    pos->error_integral_rad_s += pos->period_s * error_rad;
    put_speed_reference(pos, ref.speed + k_p * error_rad + k_i * pos->error_integral_rad_s,
                        ref.accel + k_p * speed_error + k_i * error_rad,
                        ref.jerk + (k_i - k_p * k_p) * speed_error);
    pos->position_ref_rad = ref.position;
}

void pmstep_position_step(pmstep_position_t *pos, const pmstep_meas_t *meas, pmstep_output_t *out,
                          pmstep_position_output_t *pos_out)
{
    pmstep_step(pos->inst, meas, out);
    pmstep_position_update(pos, out, pos_out);
}

void pmstep_position_update(pmstep_position_t *pos, const pmstep_output_t *out, pmstep_position_output_t *pos_out)
{
    int32_t sin_negative;
    float position_rad;
    if (out->mode != PMSTEP_MODE_RUN) {
        /* Not in RUN (or left it: stop, fault, re-alignment): the position is lost. Leaving position
         * mode this way, the speed channel holds the move's last w* as its target: cleared, so that a
         * new RUN (a re-alignment included) starts at rest, not at that speed. */
        if (pos->position_mode) {
            pmstep_ref_reset(&pos->inst->speed_ref, 0.0f);
        }
        pos->tracked = false;
        pos->position_mode = false;
        pos_out->position_rad = 0.0f;
        pos_out->position_ref_rad = 0.0f;
        pos_out->position_error_rad = 0.0f;
        pos_out->tracked = false;
        pos_out->position_mode = false;
        pos_out->moving = false;
        return;
    }
    if (!pos->tracked) {
        /* RUN's first period: (c-hat, s-hat) = (1, 0) at the c-alignment's equilibrium. */
        pos->tracked = true;
        pos->turns = 0;
        pos->zero_rad = 0.0f;
        pos->sin_negative = 0;
        pos->position_mode = false;
    }
    /* One turn on when s-hat goes negative with c-hat < 0 (through pi), one back the other way. */
    sin_negative = (out->sin_hat < 0.0f) ? POSITION_ONE : POSITION_ZERO;
    if (out->cos_hat < 0.0f) {
        pos->turns += sin_negative - pos->sin_negative;
    }
    pos->sin_negative = sin_negative;
    pos->cos_hat = out->cos_hat;
    pos->sin_hat = out->sin_hat;
    pos->speed_hat_rad_s = out->speed_hat_rad_s;
    position_rad = estimate(pos);

    if (pos->position_mode && pos->inst->speed_ref.ramp_rate_per_s > 0.0f) {
        pos->position_mode = false; /* a speed command (pmstep_set_speed_target) since the last period */
    }
    pos_out->position_rad = position_rad;
    pos_out->tracked = true;
    pos_out->position_mode = pos->position_mode;
    if (pos->position_mode) {
        pos_out->position_ref_rad = pos->position_ref_rad; /* theta* of the period just run */
        pos_out->position_error_rad = pos->position_ref_rad - position_rad;
        position_loop(pos, position_rad);
        pos_out->moving = !pmstep_motion_finished(&pos->motion);
    } else {
        pos_out->position_ref_rad = position_rad;
        pos_out->position_error_rad = 0.0f;
        pos_out->moving = false;
    }
}

pmstep_status_t pmstep_get_position(const pmstep_position_t *pos, float *position_rad)
{
    if (pos == NULL || position_rad == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    *position_rad = estimate(pos);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_set_zero(pmstep_position_t *pos)
{
    float position_rad;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    position_rad = estimate(pos);
    pos->turns = 0;
    pos->zero_rad = pmstep_atan2_poly(pos->sin_hat, pos->cos_hat);
    pmstep_motion_shift(&pos->motion, -position_rad);
    pos->position_ref_rad -= position_rad;
    return PMSTEP_OK;
}

/* Where a profile starts: the next period's reference (position mode), or theta-hat moved on by
 * one period with the speed reference's present w*, w*' (speed mode). */
static pmstep_motion_sample_t profile_start(const pmstep_position_t *pos)
{
    pmstep_motion_sample_t start;
    if (pos->position_mode) {
        start = pmstep_motion_peek(&pos->motion);
    } else {
        const pmstep_ref_out_t ref = pmstep_ref_output(&pos->inst->ref_coeffs, &pos->inst->speed_ref);
        start.position = estimate(pos) + pos->period_s * pos->speed_hat_rad_s;
        start.speed = ref.value;
        start.accel = ref.rate;
        start.jerk = 0.0f;
    }
    return start;
}

/* Enters position mode (the loop's integral starts at 0 when it was off). From speed mode the
 * speed channel is put at its own present output with the set-point held there: the coming
 * period reads the same reference, and no ramp of the speed command is left to be taken for a
 * new speed command. */
static void enter_position_mode(pmstep_position_t *pos, float start_position_rad)
{
    if (!pos->position_mode) {
        const pmstep_ref_out_t ref = pmstep_ref_output(&pos->inst->ref_coeffs, &pos->inst->speed_ref);
        put_speed_reference(pos, ref.value, ref.rate, ref.accel);
        pos->error_integral_rad_s = 0.0f;
        pos->position_ref_rad = start_position_rad;
    }
    pos->position_mode = true;
}

pmstep_status_t pmstep_position_move_to(pmstep_position_t *pos, float target_rad, float v_max_rad_s,
                                        float a_max_rad_s2, float j_max_rad_s3)
{
    pmstep_motion_sample_t start;
    float electrical;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    electrical = fabsf(target_rad) / pos->inv_pole_pairs;
    if (!(electrical <= PMSTEP_POSITION_MAX_ELECTRICAL_RAD) || !(v_max_rad_s > 0.0f) || !(a_max_rad_s2 > 0.0f)
        || !(j_max_rad_s3 >= 0.0f) || (v_max_rad_s - v_max_rad_s) != 0.0f || (a_max_rad_s2 - a_max_rad_s2) != 0.0f
        || (j_max_rad_s3 - j_max_rad_s3) != 0.0f) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE; /* NaN fails every compare; Inf - Inf is NaN */
    }
    start = profile_start(pos);
    pmstep_motion_plan(&pos->motion, start.position, start.speed, start.accel, target_rad, v_max_rad_s, a_max_rad_s2,
                       (j_max_rad_s3 > 0.0f) ? j_max_rad_s3 : (a_max_rad_s2 / pos->inv_bandwidth_s));
    enter_position_mode(pos, start.position);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_hold(pmstep_position_t *pos, float a_max_rad_s2)
{
    pmstep_motion_sample_t start;
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    if (!pos->position_mode) {
        if (!(a_max_rad_s2 > 0.0f) || (a_max_rad_s2 - a_max_rad_s2) != 0.0f) {
            return PMSTEP_ERR_BAD_COMMAND_VALUE;
        }
        pos->motion.a_max = a_max_rad_s2;
        pos->motion.j_max = a_max_rad_s2 / pos->inv_bandwidth_s;
    }
    start = profile_start(pos);
    pmstep_motion_stop(&pos->motion, &start);
    enter_position_mode(pos, start.position);
    return PMSTEP_OK;
}
