/**
 * @file pmstep_stepdir.h
 * @brief STEP/DIR input for position control: the count of step pulses (kept by the port's
 *        hardware counter, read every period) becomes the position reference theta* of the
 *        position loop (pmstep_position.h), with speed and acceleration feed-forward from a
 *        tracking filter; and the DIAG output's state. In the position library; a drive commanded
 *        over its console pays nothing for it.
 *
 * Count: the port's counter counts STEP edges up or down by DIR (a timer clocked by STEP,
 * pmstep_stepdir_count() once a period); the difference to the last read, taken as a signed 16-bit
 * number, is added to the step count, so no pulse is lost while the counter turns by less than
 * 32768 in a period (at 20 kHz, 655 MHz of steps). One microstep is 2 pi / (4 p m) mechanical rad
 * for m microsteps per full step (a two-phase stepper has 4 full steps per electrical turn).
 *
 * Tracker (every PMSTEP_POSITION_DECIMATION periods, T = N T_s): the count's position theta_in is
 * followed by (theta_f, w_f, a_f), predicted over T as constant acceleration and corrected by
 * e = theta_in - theta_f with
 *   theta_f += (1 - r^3) e,   w_f += 3/2 (1 - r)^2 (1 + r) e / T,   a_f += (1 - r)^3 e / T^2,
 * r = exp(-w_t T): the three poles of the error at r (a triple pole at -w_t in continuous time), a
 * type-3 loop: no steady error on a ramp or under constant acceleration (input shaping's
 * accelerations pass as they come), while the counts' staircase is smoothed above w_t
 * (docs/design/20-step-dir.md). The position loop takes theta_f, w_f, a_f as its reference and
 * feed-forward, predicted to the periods it serves.
 *
 * At rest: no step for stop_time_s, the reference is at rest on the last count's position, and the
 * position loop's vector hold may take over (pmstep_position.h); the next step releases it.
 *
 * Stall (stall_current_A > 0: sensorless homing against a stop, and a cap on the push into whatever
 * blocks the axis): at an update, when the following error toward the count exceeds
 * following_error_limit_rad, or the law's i_q* less the tracker's own acceleration's current
 * (J a_f / k_M) exceeds stall_current_A toward the count (pmstep_homing_stalled()), the rotor is
 * taken as blocked: the count's origin is moved so that the tracker rests on theta-hat, the position
 * loop's integral is cleared and T_L-hat put back to its value at the last rest (the block's reaction
 * out of it): the loop stops pressing. Further steps toward the block are dropped.
 * The first step away ends the stall: the drive follows it from where the rotor is, so a motion
 * controller that homes on DIAG, stops and backs off finds the stop where the rotor met it. 0: off,
 * the loop keeps following (DIAG reports the error) and pushes harder as the error grows.
 *
 * DIAG: asserted while the core is in FAULT, while stalled, and when |theta* - theta-hat| exceeds
 * following_error_limit_rad (lost steps, a stall); in level mode for as long as one holds, in
 * pulse mode for diag_pulse_periods at each new assertion (as a TMC driver's StallGuard output).
 */
#ifndef PMSTEP_STEPDIR_H
#define PMSTEP_STEPDIR_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PMSTEP_STEPDIR_MAX_MICROSTEPS 256u

/** DIAG's behaviour. */
typedef enum {
    PMSTEP_DIAG_LEVEL = 0, /**< asserted while a fault or a following error holds */
    PMSTEP_DIAG_PULSE = 1  /**< a pulse of diag_pulse_periods at each new fault or following error */
} pmstep_diag_mode_t;

/** STEP/DIR settings. */
typedef struct {
    uint32_t microsteps;             /**< m, microsteps per full step: 1 to PMSTEP_STEPDIR_MAX_MICROSTEPS */
    bool invert_direction;           /**< DIR's sense reversed */
    float tracking_bandwidth_rad_s;  /**< w_t of the tracker (designer: the speed reference's varpi_0, at most
                                            stall_speed_error_rad_s / q: a microstep q moves the tracker's speed
                                            by about q w_t) */
    float following_error_limit_rad; /**< DIAG beyond this |theta* - theta-hat|, mechanical rad (designer: one
                                            full step, pi / (2 p)) */
    float stop_time_s;               /**< no step for this long: the reference is at rest */
    pmstep_diag_mode_t diag_mode;
    uint32_t diag_pulse_periods; /**< DIAG's pulse in pulse mode (periods, > 0) */
    float stall_current_A;       /**< > 0: a stall at this q current drops the steps toward the block (header
                                            text), below max_phase_current_A; 0: off (designer: off) */
} pmstep_stepdir_config_t;

/** The STEP/DIR input's state (allocate it statically beside the position control). */
typedef struct pmstep_stepdir {
    pmstep_stepdir_config_t cfg;
    float rad_per_microstep; /**< 2 pi / (4 p m), mechanical */
    float update_s;          /**< T = N T_s */
    float gain_position;     /**< 1 - r^3 */
    float gain_speed;        /**< 3/2 (1 - r)^2 (1 + r) / T */
    float gain_accel;        /**< (1 - r)^3 / T^2 */
    uint32_t stop_updates;   /**< updates without a step that put the reference at rest */
    uint16_t last_counter;   /**< the counter at the last read */
    int32_t steps;           /**< microsteps counted since the input was taken (signed) */
    int32_t steps_at_update; /**< the count the tracker last saw */
    float origin_rad;        /**< theta* of step count 0 (mechanical) */
    float position_rad;      /**< the tracker's theta_f, w_f, a_f after its last update */
    float speed_rad_s;
    float accel_rad_s2;
    uint32_t quiet_updates;   /**< updates since the last step */
    bool moving;              /**< steps within stop_time_s, or the tracker not yet at rest */
    bool following;           /**< the position loop follows the count (pmstep_position_follow_steps()) */
    bool diag;                /**< DIAG's state (asserted: true) */
    bool diag_cause;          /**< a fault or a following error held at the last evaluation */
    uint32_t diag_pulse_left; /**< pulse mode: periods of the pulse left */
    bool stalled;             /**< the rotor is blocked toward stall_direction: steps that way are dropped */
    int32_t stall_direction;  /**< +1 or -1 while stalled */
    int32_t stall_steps;      /**< the count when the steps were last dropped */
    float stall_position_rad; /**< theta-hat where the stall was found: the tracker rests there */
    float rest_load_Nm;       /**< T_L-hat at the last update at rest before a stall: the load the axis had
                                   before the block took its share (pmstep_position.c puts it back at a stall) */
} pmstep_stepdir_t;

/**
 * The designer's settings for @p cfg's motor with @p microsteps per full step: w_t = varpi_0, or the
 * stall detection's speed bound over the microstep q where that is lower (docs/design/20-step-dir.md), the
 * following-error limit one full step, stop_time_s 8 / w_t, DIAG in level mode (pulse 1 ms), no stall
 * current (the homing's, pmstep_homing_design(), when the axis homes on DIAG).
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT
 * @retval PMSTEP_ERR_STEPDIR_MICROSTEPS  @p microsteps not within 1..256
 */
pmstep_status_t pmstep_stepdir_design(const pmstep_config_t *cfg, uint32_t microsteps, pmstep_stepdir_config_t *sd);

/**
 * Checks @p cfg and sets @p sd up for a motor of @p pole_pairs at period @p period_s, with the counter
 * at @p counter (nothing counted yet, not followed).
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT
 * @retval PMSTEP_ERR_STEPDIR_MICROSTEPS  microsteps not within 1..256
 * @retval PMSTEP_ERR_STEPDIR_TRACKING    w_t not > 0, or w_t T above 4 (the tracker's poles at e^-4)
 * @retval PMSTEP_ERR_STEPDIR_LIMIT       the following-error limit or the stop time not > 0, or a pulse of 0
 * @retval PMSTEP_ERR_STEPDIR_DIAG_MODE   diag_mode neither PMSTEP_DIAG_LEVEL nor PMSTEP_DIAG_PULSE
 * @retval PMSTEP_ERR_STEPDIR_STALL_CURRENT  the stall current < 0 or not finite (its bound by the trip is
 *                                           checked by pmstep_position_follow_steps())
 */
pmstep_status_t pmstep_stepdir_init(pmstep_stepdir_t *sd, const pmstep_stepdir_config_t *cfg, int32_t pole_pairs,
                                    float period_s, uint16_t counter);

/** Once a period (the control interrupt, after the step): the port's counter (its low 16 bits). */
static inline void pmstep_stepdir_count(pmstep_stepdir_t *sd, uint32_t counter)
{
    const uint16_t now = (uint16_t)counter;
    const int32_t delta = (int32_t)(int16_t)(uint16_t)(now - sd->last_counter);
    sd->last_counter = now;
    sd->steps += sd->cfg.invert_direction ? -delta : delta;
}

/** The count's own position theta_in (mechanical rad, the position loop's frame). */
float pmstep_stepdir_commanded(const pmstep_stepdir_t *sd);

/**
 * DIAG's state after a period: @p mode the core's, @p pos_out the position control's output of that
 * period (its theta-hat, and whether it is tracked). The following error is the count's position at
 * the last update less that update's theta-hat. Once a period, after pmstep_position_update().
 * @return true: assert DIAG.
 */
bool pmstep_stepdir_diag(pmstep_stepdir_t *sd, pmstep_mode_t mode, float position_rad, bool tracked);

/** The following error at the last update: the count's position less theta-hat (mechanical rad). */
float pmstep_stepdir_following_error(const pmstep_stepdir_t *sd, float position_rad);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_STEPDIR_H */
