/**
 * @file pmstep_homing.h
 * @brief Homing without a switch: the position loop drives the rotor toward a hard stop at a
 *        constant speed, finds the stop from the loop's own signals, makes it the position's zero
 *        and backs off. In the position library, on top of pmstep_position.h.
 *
 * Seeking: a move toward direction x max_travel_rad at speed_rad_s (accel_rad_s2, its jerk from the
 * reference bandwidth). The rotor meets the stop and stays there while the reference goes on: the
 * stop is found at the first period in which
 *   - the following error d (theta* - theta-hat), d its sign toward the stop, exceeds
 *     stall_error_rad (every loop update), or
 *   - the law's q current d i_q* exceeds stall_current_A once the reference cruises (no
 *     acceleration in it: the profile's own J a / k_M would be taken for a stop).
 * The loop pushes the rotor into the stop for as long as the error builds, J k_w (v + k_theta e)
 * plus what T_L-hat has taken up; the current test bounds that push to k_M stall_current_A
 * whatever the speed. theta-hat at that period is the stop; the rotor is there, pressed by at most
 * the stall torque, so the stop's position is read as well as the estimate reads a rotor at rest
 * (docs/design/21-homing.md; the SIL's hard stop measures it, docs/reports/homing.md).
 *
 * Found: the reference is put at rest on theta-hat (pmstep_position_rest_here(): the loop stops
 * pushing), the zero is set there (pmstep_position_set_zero()), and the rotor moves back_off_rad
 * away from the stop (0: it stays against it, held). Done when that move has ended.
 * Not found: theta-hat went max_travel_rad without meeting a stop; the drive stops and holds.
 * Aborted: the drive left RUN (a fault), or another command took the loop: a speed command, STEP/DIR
 * following, a move, a stop (pmstep_position_hold()) or a new zero changes the homing's own target.
 *
 * The same stall test serves the STEP/DIR input's homing (pmstep_stepdir.h, stall_current_A).
 */
#ifndef PMSTEP_HOMING_H
#define PMSTEP_HOMING_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep_position.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Homing settings (mechanical rad). */
typedef struct {
    float speed_rad_s;     /**< toward the stop, > 0 (designer: docs/design/21-homing.md) */
    float accel_rad_s2;    /**< to and from that speed, > 0 (designer: k_M I_s / (4 J)) */
    float max_travel_rad;  /**< no stop within this travel: not found (> 0; designer: one revolution) */
    float stall_current_A; /**< the stop when d i_q* exceeds it while cruising; in (0, max_phase_current_A)
                                (designer: half the rated current, or half the trip if lower) */
    float stall_error_rad; /**< the stop when the following error exceeds it, > 0 (designer: half a full step) */
    float back_off_rad;    /**< moved away from the stop once found, >= 0 (designer: one full step) */
} pmstep_homing_config_t;

/** Where a homing run stands. */
typedef enum {
    PMSTEP_HOMING_IDLE = 0,        /**< never started */
    PMSTEP_HOMING_SEEKING = 1,     /**< moving toward the stop */
    PMSTEP_HOMING_BACKING_OFF = 2, /**< found; the zero set; moving back_off_rad away */
    PMSTEP_HOMING_DONE = 3,        /**< found, backed off (or held at the stop), position valid from the stop */
    PMSTEP_HOMING_NOT_FOUND = 4,   /**< max_travel_rad without a stop; stopped and holding */
    PMSTEP_HOMING_ABORTED = 5      /**< left RUN or position mode before it was done */
} pmstep_homing_state_t;

/** One homing run's state. */
typedef struct {
    pmstep_homing_config_t cfg;
    pmstep_homing_state_t state;
    float direction;         /**< +1 or -1: toward the stop */
    float stop_rad;          /**< theta-hat at the stop, in the frame before the zero was set */
    bool stalled_by_current; /**< the stop was found by the current test (else by the following error) */
    float target_rad;        /**< the target of the homing's own move (another command's moves it: aborted) */
} pmstep_homing_t;

/**
 * The designer's settings for @p cfg's motor (docs/design/21-homing.md).
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT
 */
pmstep_status_t pmstep_homing_design(const pmstep_config_t *cfg, pmstep_homing_config_t *homing);

/**
 * Starts seeking the stop in @p direction (+1 or -1) from where the drive is.
 * @retval PMSTEP_OK                      seeking
 * @retval PMSTEP_ERR_NULL_ARGUMENT       an argument is NULL
 * @retval PMSTEP_ERR_BAD_MODE            @p pos not tracked (not in RUN)
 * @retval PMSTEP_ERR_NONFINITE_PARAMETER a setting is NaN or Inf
 * @retval PMSTEP_ERR_HOMING              a setting out of its range (above), or @p direction not +1 or -1
 */
pmstep_status_t pmstep_homing_start(pmstep_homing_t *homing, pmstep_position_t *pos, const pmstep_homing_config_t *cfg,
                                    int32_t direction);

/**
 * Once a period, after pmstep_position_step() (or _update()) with that period's outputs. Never fails.
 * @return the state after this period
 */
pmstep_homing_state_t pmstep_homing_update(pmstep_homing_t *homing, pmstep_position_t *pos, const pmstep_output_t *out,
                                           const pmstep_position_output_t *pos_out);

/**
 * The stall test of a loop driving toward @p direction (+1, -1): the following error @p error_rad
 * beyond @p limit_rad, or, with @p cruising, the q current reference beyond @p current_A.
 */
static inline bool pmstep_homing_stalled(float direction, float error_rad, float limit_rad, float i_q_ref_A,
                                         float current_A, bool cruising)
{
    return direction * error_rad > limit_rad || (cruising && direction * i_q_ref_A > current_A);
}

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HOMING_H */
