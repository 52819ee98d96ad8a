/*
 * STEP/DIR input (see pmstep_stepdir.h): the step count's position, its tracker, DIAG.
 * The tracker's update runs from the position loop (pmstep_position.c) every
 * PMSTEP_POSITION_DECIMATION periods; here are its settings and the per-period parts.
 */
#include "pmstep/pmstep_stepdir.h"

#include <math.h> /* fabsf: one instruction, no libm call */
#include <stddef.h>

#include "pmstep/pmstep_homing.h"
#include "pmstep/pmstep_position.h"
#include "pmstep_position_internal.h"

#define TWO_PI 6.2831853f
#define HALF_PI 1.5707963f
#define MAX_POLE_PHASE 4.0f        /* w_t T at most: the tracker's poles at e^-4 or nearer 1 */
#define STOP_TIME_PER_TRACKER 8.0f /* the designer's stop time: 8 / w_t, the tracker settled to e^-8 */
#define DIAG_PULSE_S 1e-3f         /* the designer's DIAG pulse */
#define STALL_UP ((int32_t)1)      /* stall_direction */
#define STALL_DOWN ((int32_t)-1)

/* e^-x for 0 <= x <= MAX_POLE_PHASE without libm: the series of e^-(x/16) to x^5, squared four times
 * (relative error below 1e-5 over the range). */
static float exp_negative(float x)
{
    const float y = -x * (1.0f / 16.0f);
    float e = 1.0f + y * (1.0f + y * (0.5f + y * ((1.0f / 6.0f) + y * ((1.0f / 24.0f) + y * (1.0f / 120.0f)))));
    int k;
    for (k = 0; k < 4; ++k) {
        e *= e;
    }
    return e;
}

pmstep_status_t pmstep_stepdir_design(const pmstep_config_t *cfg, uint32_t microsteps, pmstep_stepdir_config_t *sd)
{
    float pulse_periods;
    if (cfg == NULL || sd == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (microsteps < 1u || microsteps > PMSTEP_STEPDIR_MAX_MICROSTEPS) {
        return PMSTEP_ERR_STEPDIR_MICROSTEPS;
    }
    sd->microsteps = microsteps;
    sd->invert_direction = false;
    sd->tracking_bandwidth_rad_s = cfg->gains.reference_bandwidth_rad_s;
    if (cfg->detection.stall_speed_error_rad_s > 0.0f) {
        /* a microstep q moves the tracker's speed by about q w_t: at most the stall detection's bound
         * (docs/design/20-step-dir.md, The staircase) */
        const float microstep_rad = TWO_PI / (4.0f * (float)cfg->motor.pole_pairs * (float)microsteps);
        const float staircase_rad_s = cfg->detection.stall_speed_error_rad_s / microstep_rad;
        if (staircase_rad_s < sd->tracking_bandwidth_rad_s) {
            sd->tracking_bandwidth_rad_s = staircase_rad_s;
        }
    }
    sd->following_error_limit_rad = HALF_PI / (float)cfg->motor.pole_pairs; /* one full step */
    sd->stop_time_s = STOP_TIME_PER_TRACKER / sd->tracking_bandwidth_rad_s;
    sd->diag_mode = PMSTEP_DIAG_LEVEL;
    pulse_periods = (DIAG_PULSE_S / cfg->timing.period_s) + 0.5f; /* rounded to whole periods */
    sd->diag_pulse_periods = (uint32_t)pulse_periods;
    if (sd->diag_pulse_periods == 0u) {
        sd->diag_pulse_periods = 1u;
    }
    sd->stall_current_A = 0.0f;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_stepdir_init(pmstep_stepdir_t *sd, const pmstep_stepdir_config_t *cfg, int32_t pole_pairs,
                                    float period_s, uint16_t counter)
{
    float update_s;
    float r;
    float one_minus_r;
    if (sd == NULL || cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (cfg->microsteps < 1u || cfg->microsteps > PMSTEP_STEPDIR_MAX_MICROSTEPS) {
        return PMSTEP_ERR_STEPDIR_MICROSTEPS;
    }
    if (pole_pairs < 1 || !(period_s > 0.0f)) {
        return PMSTEP_ERR_NULL_ARGUMENT; /* a position control's, checked there already */
    }
    update_s = (float)PMSTEP_POSITION_DECIMATION * period_s;
    if (!(cfg->tracking_bandwidth_rad_s > 0.0f) || !(cfg->tracking_bandwidth_rad_s * update_s <= MAX_POLE_PHASE)) {
        return PMSTEP_ERR_STEPDIR_TRACKING;
    }
    if (!(cfg->following_error_limit_rad > 0.0f) || !(cfg->stop_time_s > 0.0f) || cfg->diag_pulse_periods == 0u
        || (cfg->following_error_limit_rad - cfg->following_error_limit_rad) != 0.0f
        || (cfg->stop_time_s - cfg->stop_time_s) != 0.0f) {
        return PMSTEP_ERR_STEPDIR_LIMIT;
    }
    if ((cfg->diag_mode != PMSTEP_DIAG_LEVEL) && (cfg->diag_mode != PMSTEP_DIAG_PULSE)) {
        return PMSTEP_ERR_STEPDIR_DIAG_MODE;
    }
    if (!(cfg->stall_current_A >= 0.0f) || (cfg->stall_current_A - cfg->stall_current_A) != 0.0f) {
        return PMSTEP_ERR_STEPDIR_STALL_CURRENT;
    }
    sd->cfg = *cfg;
    sd->rad_per_microstep = TWO_PI / (4.0f * (float)pole_pairs * (float)cfg->microsteps);
    sd->update_s = update_s;
    r = exp_negative(cfg->tracking_bandwidth_rad_s * update_s);
    one_minus_r = 1.0f - r;
    sd->gain_position = 1.0f - r * r * r;
    sd->gain_speed = 1.5f * one_minus_r * one_minus_r * (1.0f + r) / update_s;
    sd->gain_accel = one_minus_r * one_minus_r * one_minus_r / (update_s * update_s);
    sd->stop_updates = (uint32_t)(cfg->stop_time_s / update_s) + 1u;
    sd->last_counter = counter;
    sd->steps = 0;
    sd->steps_at_update = 0;
    sd->origin_rad = 0.0f;
    sd->position_rad = 0.0f;
    sd->speed_rad_s = 0.0f;
    sd->accel_rad_s2 = 0.0f;
    sd->quiet_updates = sd->stop_updates;
    sd->moving = false;
    sd->following = false;
    sd->diag = false;
    sd->diag_cause = false;
    sd->diag_pulse_left = 0u;
    sd->stalled = false;
    sd->stall_direction = 0;
    sd->stall_steps = 0;
    sd->stall_position_rad = 0.0f;
    sd->rest_load_Nm = 0.0f;
    return PMSTEP_OK;
}

float pmstep_stepdir_commanded(const pmstep_stepdir_t *sd)
{
    return sd->origin_rad + (float)sd->steps * sd->rad_per_microstep;
}

float pmstep_stepdir_following_error(const pmstep_stepdir_t *sd, float position_rad)
{
    return sd->origin_rad + (float)sd->steps_at_update * sd->rad_per_microstep - position_rad;
}

bool pmstep_stepdir_diag(pmstep_stepdir_t *sd, pmstep_mode_t mode, float position_rad, bool tracked)
{
    const bool lost = sd->following && tracked
                      && fabsf(pmstep_stepdir_following_error(sd, position_rad)) > sd->cfg.following_error_limit_rad;
    const bool cause = mode == PMSTEP_MODE_FAULT || lost || (sd->following && sd->stalled);
    if (sd->cfg.diag_mode == PMSTEP_DIAG_LEVEL) {
        sd->diag = cause;
    } else {
        if (cause && !sd->diag_cause) {
            sd->diag_pulse_left = sd->cfg.diag_pulse_periods; /* a new assertion: one pulse */
        }
        sd->diag = sd->diag_pulse_left > 0u;
        if (sd->diag_pulse_left > 0u) {
            sd->diag_pulse_left--;
        }
    }
    sd->diag_cause = cause;
    return sd->diag;
}

void pmstep_stepdir_start(pmstep_stepdir_t *sd, const pmstep_motion_sample_t *start)
{
    sd->stalled = false;
    sd->steps_at_update = sd->steps;
    sd->origin_rad = start->position - (float)sd->steps * sd->rad_per_microstep;
    sd->position_rad = start->position;
    sd->speed_rad_s = start->speed;
    sd->accel_rad_s2 = start->accel;
    sd->quiet_updates = 0u;
    sd->moving = true;
    sd->following = true;
}

void pmstep_stepdir_track(pmstep_stepdir_t *sd)
{
    const float t = sd->update_s;
    const int32_t steps = sd->steps;
    float error;
    /* predict over T at constant acceleration, then correct by the count's position */
    sd->position_rad += t * (sd->speed_rad_s + 0.5f * t * sd->accel_rad_s2);
    sd->speed_rad_s += t * sd->accel_rad_s2;
    error = sd->origin_rad + (float)steps * sd->rad_per_microstep - sd->position_rad;
    sd->position_rad += sd->gain_position * error;
    sd->speed_rad_s += sd->gain_speed * error;
    sd->accel_rad_s2 += sd->gain_accel * error;
    if (steps != sd->steps_at_update) {
        sd->quiet_updates = 0u;
    } else if (sd->quiet_updates < sd->stop_updates) {
        sd->quiet_updates++;
    }
    sd->steps_at_update = steps;
    sd->moving = sd->quiet_updates < sd->stop_updates;
    if (!sd->moving) {
        /* at rest on the last count: the loop's hold aims there */
        sd->position_rad = sd->origin_rad + (float)steps * sd->rad_per_microstep;
        sd->speed_rad_s = 0.0f;
        sd->accel_rad_s2 = 0.0f;
    }
}

pmstep_motion_sample_t pmstep_stepdir_predict(const pmstep_stepdir_t *sd, float ahead_s)
{
    pmstep_motion_sample_t s;
    s.position = sd->position_rad + ahead_s * (sd->speed_rad_s + 0.5f * ahead_s * sd->accel_rad_s2);
    s.speed = sd->speed_rad_s + ahead_s * sd->accel_rad_s2;
    s.accel = sd->accel_rad_s2;
    s.jerk = 0.0f;
    return s;
}

/* The tracker at rest on the stall's position, the count up to now mapped there: the steps since are dropped. */
static void drop_steps(pmstep_stepdir_t *sd)
{
    sd->stall_steps = sd->steps_at_update;
    sd->origin_rad = sd->stall_position_rad - (float)sd->steps_at_update * sd->rad_per_microstep;
    sd->position_rad = sd->stall_position_rad;
    sd->speed_rad_s = 0.0f;
    sd->accel_rad_s2 = 0.0f;
}

bool pmstep_stepdir_stall(pmstep_stepdir_t *sd, float position_rad, float push_A)
{
    bool found = false;
    if (sd->stalled) {
        const int32_t moved = sd->steps_at_update - sd->stall_steps;
        if (moved * sd->stall_direction > 0) {
            drop_steps(sd); /* still toward the block */
        } else if (moved != 0) {
            sd->stalled = false; /* a step away: followed from where the rotor rests */
        } else {
            /* no step since */
        }
    } else if (sd->cfg.stall_current_A > 0.0f) {
        const float error_rad = pmstep_stepdir_following_error(sd, position_rad);
        const float direction = error_rad >= 0.0f ? 1.0f : -1.0f;
        if (pmstep_homing_stalled(direction, error_rad, sd->cfg.following_error_limit_rad, push_A,
                                  sd->cfg.stall_current_A, true)) {
            sd->stalled = true;
            sd->stall_direction = (error_rad >= 0.0f) ? STALL_UP : STALL_DOWN;
            sd->stall_position_rad = position_rad;
            drop_steps(sd);
            found = true;
        }
    } else {
        /* no stall test */
    }
    return found;
}
