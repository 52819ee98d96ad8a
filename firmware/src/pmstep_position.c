/* Sensorless position control on the speed controller (pmstep_position.h). */
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "pmstep_position_internal.h"

#include <math.h> /* fabsf: one instruction, no libm call */
#include <stddef.h>

/* The N-th period's update out of line (GCC, Clang): inlined into pmstep_position_update(), the
 * registers it needs would be saved and restored every period. */
#if defined(__GNUC__)
#define POSITION_OUT_OF_LINE __attribute__((noinline))
#else
#define POSITION_OUT_OF_LINE
#endif

/* Terms of the series of hold_coefficients(): a = w0 N T_s <= 8 x 0.5 (validation: w0 T_s <= 0.5);
 * a^j/j! below 1e-9 of e^a beyond j = 40. */
#define POSITION_SERIES_TERMS 40

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
    pos_cfg->hold_current_A =
        0.5f * cfg->limits.max_phase_current_A; /* half the trip (docs/design/12-position-hold.md) */
    return PMSTEP_OK;
}

/* theta-hat (mechanical rad) from the last estimate, the turn count and the zero. */
static float estimate(const pmstep_position_t *pos)
{
    const float fine = pmstep_atan2_poly(pos->sin_hat, pos->cos_hat) - pos->zero_rad;
    const float turns = (float)pos->turns;
    return (POSITION_TWO_PI_HI * turns + (POSITION_TWO_PI_LO * turns + fine)) * pos->inv_pole_pairs;
}

/* The reference filter's response over N periods to a held set-point (put_speed_reference), for
 * a = w0 N T_s: y_N - y = g (r - y) + c23 (x2 - x3) + c12 (x1 - x2) with, from the chain of three
 * lags, g = 1 - e^-a (1 + a + a^2/2) = e^-a sum_{j>=3} a^j/j! (summed: no cancellation),
 * c23 = e^-a (a + a^2/2), c12 = e^-a a^2/2. Kept: 1/g, c23, c12. */
static void hold_coefficients(pmstep_position_t *pos, float a)
{
    float term = 1.0f;
    float exp_a = 1.0f;
    float tail = 0.0f; /* sum_{j>=3} a^j/j! */
    float e;
    int32_t j;
    for (j = 1; j < POSITION_SERIES_TERMS; ++j) {
        term = term * a / (float)j;
        exp_a += term;
        if (j >= 3) {
            tail += term;
        }
    }
    e = 1.0f / exp_a;
    pos->hold_inv_gain = exp_a / tail; /* 1/g = e^a / tail */
    pos->hold_c23 = e * (a + 0.5f * a * a);
    pos->hold_c12 = e * 0.5f * a * a;
}

pmstep_status_t pmstep_position_init(pmstep_position_t *pos, pmstep_t *inst, const pmstep_position_config_t *cfg)
{
    const pmstep_config_t *core;
    if (pos == NULL || inst == NULL || cfg == NULL || inst->cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    core = inst->cfg;
    if ((cfg->gain_per_s - cfg->gain_per_s) != 0.0f || (cfg->integral_gain_per_s2 - cfg->integral_gain_per_s2) != 0.0f
        || (cfg->hold_current_A - cfg->hold_current_A) != 0.0f) {
        return PMSTEP_ERR_NONFINITE_PARAMETER;
    }
    if (!(cfg->gain_per_s > 0.0f) || cfg->gain_per_s > 0.5f * core->gains.speed_gain_per_s) {
        return PMSTEP_ERR_POSITION_GAIN;
    }
    if (cfg->integral_gain_per_s2 < 0.0f || cfg->integral_gain_per_s2 > 0.25f * cfg->gain_per_s * cfg->gain_per_s) {
        return PMSTEP_ERR_POSITION_INTEGRAL_GAIN;
    }
    if (cfg->hold_current_A < 0.0f || !(cfg->hold_current_A < core->limits.max_phase_current_A)) {
        return PMSTEP_ERR_HOLD_CURRENT;
    }
    pos->inst = inst;
    pos->steps = NULL;
    pos->cfg = *cfg;
    pos->hold_stage = POSITION_HOLD_NONE;
    pos->hold_periods = 0;
    pos->reading_turned = false;
    pos->rest_cos = 1.0f;
    pos->rest_sin = 0.0f;
    pos->aim_load_Nm = 0.0f;
    pos->frozen_cos = 1.0f;
    pos->frozen_sin = 0.0f;
    pos->inv_pole_pairs = 1.0f / (float)core->motor.pole_pairs;
    pos->period_s = core->timing.period_s;
    pos->inv_bandwidth_s = 1.0f / inst->derived.ref_coeffs.bandwidth_rad_s;
    pos->cos_hat = 1.0f;
    pos->sin_hat = 0.0f;
    pos->speed_hat_rad_s = 0.0f;
    pos->zero_rad = 0.0f;
    pos->turns = 0;
    pos->sin_negative = 0;
    pos->out.tracked = false;
    pos->out.position_mode = false;
    pos->error_integral_rad_s = 0.0f;
    pos->loop_countdown = PMSTEP_POSITION_DECIMATION;
    pos->out.moving = false;
    pos->out.position_rad = 0.0f;
    pos->out.position_ref_rad = 0.0f;
    pos->out.position_error_rad = 0.0f;
    /* the profile is sampled at the loop's updates, every PMSTEP_POSITION_DECIMATION periods */
    pmstep_motion_reset(&pos->motion, 0.0f, (float)PMSTEP_POSITION_DECIMATION * pos->period_s);
    pos->now = pmstep_motion_peek(&pos->motion);
    pos->ahead = pos->now;
    hold_coefficients(pos, inst->derived.ref_coeffs.bandwidth_rad_s * pos->motion.period_s);
    return PMSTEP_OK;
}

/* Puts the speed reference channel at (w*, w*', w*'') for the coming N periods: the law reads
 * exactly these in the next period (pmstep_ref_output), then the core's own pmstep_ref_advance()
 * runs the filter on, so w*, w*', w*'' stay one trajectory of H(s) (the law's derivatives are
 * those of its reference). The filter's set-point r is held at the value that brings w* to
 * @p end_speed after the N periods (hold_coefficients(): the discretisation is exact), the
 * reference the next update will put: no step of w* at the update. A speed command given
 * meanwhile ramps on from that set-point (pmstep_ref_set_target); the output stays continuous. */
void pmstep_position_put_speed_reference(pmstep_position_t *pos, float speed, float rate, float accel, float end_speed)
{
    pmstep_ref_t *ref = &pos->inst->speed_ref;
    const float inv_w0 = pos->inv_bandwidth_s;
    const float diff23 = rate * inv_w0;
    const float diff12 = accel * inv_w0 * inv_w0 + diff23;
    const float free_change = pos->hold_c23 * diff23 + pos->hold_c12 * diff12;
    pmstep_ref_place(ref, speed + (end_speed - speed - free_change) * pos->hold_inv_gain, speed, diff12, diff23);
}

/* The loop on the estimate moved on to period k+1, against @p ref, the reference for period k+1; the
 * speed reference it puts serves periods k+1 .. k+N and ends where the next update's will begin: the
 * reference's speed at k+N+1 (@p ahead_speed) plus the feedback terms moved on by their derivatives
 * (k_theta e + k_I z)(t + N T_s) ~ value + N T_s rate + (N T_s)^2/2 accel. z integrates the error
 * sampled every N T_s. */
static inline void loop_output(pmstep_position_t *pos, float position_rad, const pmstep_motion_sample_t *ref,
                               float ahead_speed, bool running)
{
    const float k_p = pos->cfg.gain_per_s;
    const float k_i = pos->cfg.integral_gain_per_s2;
    const float step_s = pos->motion.period_s;
    const float predicted_rad = position_rad + pos->period_s * pos->speed_hat_rad_s;
    const float error_rad = ref->position - predicted_rad;
    const float speed_error = ref->speed - pos->speed_hat_rad_s;
    float feedback;
    float feedback_rate;
    float feedback_accel;
    pos->error_integral_rad_s += step_s * error_rad;
    feedback = k_p * error_rad + k_i * pos->error_integral_rad_s;
    feedback_rate = k_p * speed_error + k_i * error_rad;
    feedback_accel = (k_i - k_p * k_p) * speed_error;
    pmstep_position_put_speed_reference(
        pos, ref->speed + feedback, ref->accel + feedback_rate, ref->jerk + feedback_accel,
        ahead_speed + feedback + step_s * (feedback_rate + 0.5f * step_s * feedback_accel));
    pos->out.moving = running;
    pos->out.position_ref_rad = ref->position;
    pos->out.position_error_rad = error_rad;
}

/* Position mode on a move, an update after period k: the profile's sample for period k+1 (taken one
 * update ahead) and the one for period k+N+1 (sampled now). */
static void position_loop(pmstep_position_t *pos, float position_rad)
{
    const bool running = !pmstep_motion_finished(&pos->motion);
    pos->now = pos->ahead;
    pos->ahead = pmstep_motion_next(&pos->motion);
    loop_output(pos, position_rad, &pos->now, pos->ahead.speed, running);
}

/* Position mode on a STEP/DIR input, an update after period k: the count's tracker (updated with
 * period k's count) moved on to period k+1 and to period k+N+1. */
static void follow_loop(pmstep_position_t *pos, float position_rad)
{
    pos->now = pmstep_stepdir_predict(pos->steps, pos->period_s);
    pos->ahead = pmstep_stepdir_predict(pos->steps, pos->period_s + pos->motion.period_s);
    loop_output(pos, position_rad, &pos->now, pos->ahead.speed, pos->steps->moving);
}

void pmstep_position_step(pmstep_position_t *pos, const pmstep_meas_t *meas, pmstep_output_t *out,
                          pmstep_position_output_t *pos_out)
{
    pmstep_step(pos->inst, meas, out);
    pmstep_position_update(pos, out, pos_out);
}

/* The loop no longer follows a STEP/DIR input (a move, a stop, a speed command, leaving RUN). */
void pmstep_position_stop_following(pmstep_position_t *pos)
{
    if (pos->steps != NULL) {
        pos->steps->following = false;
        pos->steps = NULL;
    }
}

/* Leaving RUN (stop, fault, re-alignment): the position is lost. Leaving position mode this way,
 * the speed channel holds the move's last w* as its target: cleared, so that a new RUN (a
 * re-alignment included) starts at rest, not at that speed. */
POSITION_OUT_OF_LINE static void lose_position(pmstep_position_t *pos)
{
    if (pos->out.position_mode) {
        pmstep_ref_reset(&pos->inst->speed_ref, 0.0f);
    }
    pos->hold_stage = POSITION_HOLD_NONE; /* the core ended its hold on leaving RUN */
    pmstep_position_stop_following(pos);
    pos->out.tracked = false;
    pos->out.position_mode = false;
    pos->out.moving = false;
    pos->out.position_rad = 0.0f;
    pos->out.position_ref_rad = 0.0f;
    pos->out.position_error_rad = 0.0f;
}

/* RUN's first period: (c-hat, s-hat) = (1, 0) at the c-alignment's equilibrium; the first update now. */
static void start_tracking(pmstep_position_t *pos)
{
    pos->out.tracked = true;
    pos->out.position_mode = false;
    pos->turns = 0;
    pos->zero_rad = 0.0f;
    pos->sin_negative = 0;
    pos->loop_countdown = 1;
}

/* Every N-th period: the estimate (the fine angle) and, in position mode, the loop. */
POSITION_OUT_OF_LINE static void update(pmstep_position_t *pos, float i_q_ref_A)
{
    const float position_rad = estimate(pos);
    pos->loop_countdown = PMSTEP_POSITION_DECIMATION;
    pos->out.position_rad = position_rad;
    if (pos->out.position_mode && pos->inst->speed_ref.ramp_rate_per_s > 0.0f) {
        /* A speed command (pmstep_set_speed_target) since the last update: speed mode. The core has
         * been ramping from the held set-point since; the loop writes nothing more. */
        pos->out.position_mode = false;
        pos->out.moving = false;
        pos->hold_stage = POSITION_HOLD_NONE; /* the command released the core's hold */
        pmstep_position_stop_following(pos);
    }
    if (pos->steps != NULL) {
        pmstep_stepdir_track(pos->steps); /* every update, the hold's included: it sees the next step */
        if (pos->steps->moving && pmstep_position_vector_held(pos)) {
            pmstep_position_release_hold(pos);
        }
        if (!pos->steps->moving && !pos->steps->stalled) {
            pos->steps->rest_load_Nm = pos->inst->observer.load_hat_Nm;
        }
        /* the push: i_q* beyond what the tracker's own acceleration asks */
        if (pmstep_stepdir_stall(pos->steps, position_rad,
                                 i_q_ref_A - pos->inst->derived.law_coeffs.j_over_km * pos->steps->accel_rad_s2)) {
            /* the loop stops pressing the block: no integral, and the block's reaction out of T_L-hat */
            pos->error_integral_rad_s = 0.0f;
            pos->inst->observer.load_hat_Nm = pos->steps->rest_load_Nm;
        }
    }
    if (pos->out.position_mode) {
        if (pmstep_position_vector_held(pos)) {
            pmstep_position_vector_hold(pos, position_rad);
        } else {
            if (pos->steps != NULL) {
                follow_loop(pos, position_rad);
            } else {
                position_loop(pos, position_rad);
            }
            if (!pos->out.moving && pos->hold_stage != POSITION_HOLD_REFUSED && pos->cfg.hold_current_A > 0.0f) {
                pmstep_position_wait_and_aim(pos, position_rad);
            }
        }
    } else {
        pos->out.position_ref_rad = position_rad;
        pos->out.position_error_rad = 0.0f;
    }
}

void pmstep_position_update(pmstep_position_t *pos, const pmstep_output_t *out, pmstep_position_output_t *pos_out)
{
    if (out->mode != PMSTEP_MODE_RUN) {
        if (pos->out.tracked) {
            lose_position(pos);
        }
    } else {
        /* Every period: one turn on when s-hat goes negative with c-hat < 0 (through pi), one back. */
        const int32_t sin_negative = (out->sin_hat < 0.0f) ? POSITION_ONE : POSITION_ZERO;
        if (!pos->out.tracked) {
            start_tracking(pos);
        }
        if (out->cos_hat < 0.0f) {
            pos->turns += sin_negative - pos->sin_negative;
        }
        pos->sin_negative = sin_negative;
        pos->cos_hat = out->cos_hat;
        pos->sin_hat = out->sin_hat;
        pos->speed_hat_rad_s = out->speed_hat_rad_s;
        pos->loop_countdown--;
        if (pos->loop_countdown <= 0) {
            update(pos, out->i_q_ref_A);
        }
    }
    *pos_out = pos->out;
}

pmstep_status_t pmstep_get_position(const pmstep_position_t *pos, float *position_rad)
{
    if (pos == NULL || position_rad == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    *position_rad = estimate(pos);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_reference(const pmstep_position_t *pos, float *position_ref_rad)
{
    if (pos == NULL || position_ref_rad == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->out.tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    if (!pos->out.position_mode) {
        *position_ref_rad = estimate(pos);
    } else {
        /* The last update's sample is for the period after it; the period just run is
         * N - countdown - 1 periods on (-1 right after the update): its cubic there. */
        const pmstep_motion_sample_t *now = &pos->now;
        const int32_t periods_on = PMSTEP_POSITION_DECIMATION - pos->loop_countdown - 1;
        const float t_s = (float)periods_on * pos->period_s;
        *position_ref_rad =
            now->position + t_s * (now->speed + t_s * (0.5f * now->accel + t_s * (now->jerk * (1.0f / 6.0f))));
    }
    return PMSTEP_OK;
}
