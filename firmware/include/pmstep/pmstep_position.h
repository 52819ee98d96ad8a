/**
 * @file pmstep_position.h
 * @brief Sensorless position control on top of the speed controller: the position estimate
 *        from the estimated angle (c-hat, s-hat), a motion profile (pmstep_motion.h) and an
 *        outer position loop. A library of its own (pmstep_position): the core's step, its
 *        instance and its flash budget do not carry it, and a drive in speed mode pays nothing.
 *
 * Position estimate, mechanical rad:
 *   theta-hat = (2 pi n + atan2(s-hat, c-hat) - zero) / p
 * n counts electrical turns: it follows the crossings of (c-hat, s-hat) between the second and
 * the third quadrant (c-hat < 0, s-hat changing sign), one compare and one add a period; the
 * fine angle is pmstep_atan2_poly() (within 1.2e-5 rad, no libm), computed only where it is read.
 * theta-hat = 0 is the c-alignment's equilibrium (theta = 0 mod 2 pi/p, where RUN starts) until
 * pmstep_position_set_zero() moves it.
 *
 * Position loop (position mode only): the profile's (theta*, w_p, a_p, j_p) and
 *   w*   = w_p + k_theta e + k_I z,     e = theta* - theta-hat,  z' = e
 *   w*'  = a_p + k_theta (w_p - w-hat) + k_I e
 *   w*'' = j_p + (k_I - k_theta^2)(w_p - w-hat)
 * go to the speed law (6) as its reference and derivatives. With the speed loop tracking, the
 * position error obeys (s + k_w)(s^2 + k_theta s + k_I) = 0: the loop's poles are set by
 * k_theta and k_I alone, below the speed loop's k_w (validation: k_theta <= k_w/2,
 * k_I <= k_theta^2/4; the designer's rule k_theta = k_w/4, docs/design). At standstill the
 * law's T-hat_L carries the load; k_I takes out what is left of a speed-estimate bias.
 *
 * Vector hold (hold_current_A > 0): when a move's profile has ended, the rotor is held at the
 * target by a current vector fixed in the stator frame (pmstep_hold_vector(), pmstep_hold.h),
 * aimed at the target's electrical direction (the estimate turned by p (theta* - theta-hat))
 * ahead by the load angle of T_L-hat (read 2/k_theta after the profile ends, while the loop
 * still holds): no estimate drift moves it. Once the rotor has been at rest (|w-hat - w-bar|
 * within the quiet band, and the flux integrals' reading not turned by more than three bands'
 * turn in two updates running: w-hat lags the swing of a light rotor's hold;
 * docs/design/12-position-hold.md; an update with one such turn is neither rest nor motion) for the
 * held rotor's settling time, the estimate is kept where it was
 * then, so it does not drift, and it follows the flux integrals while the rotor moves (a load
 * step). After POSITION_REAIM_PERIODS at rest more than 0.05 electrical rad from the target,
 * the aim is turned by that displacement (the load angle off, or the load changed), and the kept
 * estimate with it (the rotor follows the turn; the flux integrals are not read again, their
 * drift at rest would be taken for the next displacement), and so on until the rotor rests
 * within 0.05. A move, a stop or a speed command releases it; a move or a stop also puts
 * T_L-hat back to the aim's (held, the hold current times the estimate's angle error is in it).
 *
 * Rates: the turn count runs every period (it must see every crossing); the fine angle, the
 * profile and the loop run every PMSTEP_POSITION_DECIMATION = N periods (a cascade's outer loop
 * at a lower rate, as the turn count alone is cheap). An update after period k puts the speed
 * reference of periods k+1 .. k+N: (w*, w*', w*'') above as the state of the speed reference
 * filter, whose held set-point is solved for so that the filter, run on by pmstep_step() every
 * period, ends the N periods at the w* of the next update (the profile is sampled one update
 * ahead, the feedback moved on by its derivatives): the law keeps a smooth reference whose
 * derivatives are its own, with no step at the updates (docs/design/11-position-loop.md). Cost: the
 * sample-and-hold of the error adds about (N/2) T_s of delay to the one period the loop already
 * acts after the speed law; at the loop's bandwidth k_theta the phase lag is
 * k_theta (N/2 + 1) T_s (paper's motor: 25 rad/s x 5 x 50 us = 6e-3 rad, 0.36 deg), and the
 * integral z sums N T_s e per update.
 *
 * Use: pmstep_init() the core, then pmstep_position_init() with the same instance, and call
 * pmstep_position_step() in place of pmstep_step() every period. pmstep_set_speed_target()
 * (any time) returns the drive to speed mode; pmstep_position_move_to() and
 * pmstep_position_hold() put it in position mode. The reference for period k+1 is formed after
 * step k, from the estimate of period k moved on by w-hat T_s: the loop acts one period later
 * than the speed law, far below its bandwidth.
 */
#ifndef PMSTEP_POSITION_H
#define PMSTEP_POSITION_H

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_motion.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest |electrical angle| p |theta| the position estimate and commands accept (rad): there
 *  the float32 angle still resolves 4e-3 rad (2^-8), 1/25 of a 0.1 rad position bound. */
#define PMSTEP_POSITION_MAX_ELECTRICAL_RAD 32768.0f

/** N: the fine angle, the profile and the position loop run every N-th period (header text).
 *  8 keeps a period with the loop on within 600 instructions on the mean (README, cost). */
#define PMSTEP_POSITION_DECIMATION 8

/** Gains of the position loop. */
typedef struct {
    float gain_per_s;           /**< k_theta > 0, at most k_w/2 (designer: k_w/4) */
    float integral_gain_per_s2; /**< k_I >= 0, at most k_theta^2/4 (a double pole); 0 = none */
    float hold_current_A;       /**< I of the vector hold when a move ends (pmstep_hold.h), below
                                     max_phase_current_A; 0 = the loop holds on the estimate
                                     (designer: max_phase_current_A / 2) */
} pmstep_position_config_t;

/** What pmstep_position_step() estimated and commanded (mechanical rad). The three positions are
 *  those of the last update (every PMSTEP_POSITION_DECIMATION periods; at RUN's first period and
 *  the period after a move from speed mode); pmstep_get_position() and
 *  pmstep_position_reference() give the present period's on demand. */
typedef struct {
    float position_rad;       /**< theta-hat of the update's period k (0 while not tracked) */
    float position_ref_rad;   /**< position mode: theta* of period k+1 the loop tracked; else theta-hat */
    float position_error_rad; /**< position mode: the loop's e = theta*(k+1) - (theta-hat + T_s w-hat); else 0 */
    bool tracked;             /**< RUN: the estimate is valid */
    bool position_mode;       /**< the position loop drives the speed reference */
    bool moving;              /**< the profile is still running (false: holding theta*) */
} pmstep_position_output_t;

struct pmstep_stepdir;

/** State of the position control of one pmstep_t (allocate it statically next to it). */
typedef struct {
    pmstep_t *inst;
    struct pmstep_stepdir *steps; /**< the STEP/DIR input the loop follows (pmstep_position_follow_steps()),
                                       NULL: the motion profile */
    pmstep_position_config_t cfg;
    float inv_pole_pairs;         /**< 1/p */
    float period_s;               /**< T_s */
    float inv_bandwidth_s;        /**< 1/varpi_0 of the speed reference filter */
    float cos_hat;                /**< c-hat of the last period */
    float sin_hat;                /**< s-hat of the last period */
    float speed_hat_rad_s;        /**< w-hat of the last period */
    float zero_rad;               /**< electrical angle subtracted (set zero) */
    int32_t turns;                /**< electrical turns counted since RUN began */
    int32_t sin_negative;         /**< 1 if s-hat < 0 in the last period, else 0 */
    int32_t loop_countdown;       /**< periods to the next update (1: after the next period) */
    float error_integral_rad_s;   /**< z, integral of theta* - theta-hat (rad s) */
    pmstep_position_output_t out; /**< the state's flags (tracked: in RUN since the turn count's reset;
                                       moving: the profile had not ended at the last update or command)
                                       and the last update's positions; each period's output is a copy */
    pmstep_motion_t motion;       /**< theta* and its derivatives (position mode), sampled every N T_s */
    pmstep_motion_sample_t now;   /**< the profile's sample for the period after the last update */
    pmstep_motion_sample_t ahead; /**< the sample for the period after the next update (one ahead) */
    float hold_inv_gain;          /**< the reference filter over N periods (put_speed_reference) */
    float hold_c23;
    float hold_c12;
    /* Vector hold when a move ends (hold_current_A > 0; "Vector hold" above, pmstep_position_hold.c) */
    float rest_cos; /**< the vector's aim before its load angle (stator frame): the target's
                                   electrical direction, corrected by the displacements at rest */
    float rest_sin;
    float aim_load_Nm; /**< the load the aim's load angle is for (T_L-hat when the move ended) */
    float frozen_cos;  /**< the estimate kept while the held rotor is at rest */
    float frozen_sin;
    int32_t hold_stage;   /**< none, waiting, settling, anchored, refused (until the next move) */
    int32_t hold_periods; /**< waiting, settling: periods left; anchored: periods at rest */
    bool reading_turned;  /**< anchored: the last update's reading turned beyond its limit
                                   (three quiet bands' turn), neither rest nor motion yet */
} pmstep_position_t;

/**
 * The designer's rule (docs/design/11-position-loop.md): k_theta = k_w/4, k_I = k_theta^2/8 (poles
 * of s^2 + k_theta s + k_I at 0.15 and 0.85 k_theta, both below the speed loop's k_w).
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT
 */
pmstep_status_t pmstep_position_design(const pmstep_config_t *cfg, pmstep_position_config_t *pos_cfg);

/**
 * Polynomial atan2(y, x) in (-pi, pi], no libm: an odd polynomial of degree 9 on
 * min(|x|,|y|)/max(|x|,|y|), then the octant. Error below 1.2e-5 rad (unit test); 0 at (0, 0).
 */
float pmstep_atan2_poly(float y, float x);

/**
 * Attaches position control to @p inst (already initialised by pmstep_init()) and validates
 * @p cfg against the speed loop's gains. Speed mode, not tracked.
 * @retval PMSTEP_OK                           attached
 * @retval PMSTEP_ERR_NULL_ARGUMENT            an argument is NULL, or @p inst not initialised
 * @retval PMSTEP_ERR_NONFINITE_PARAMETER      a gain is NaN or Inf
 * @retval PMSTEP_ERR_POSITION_GAIN            k_theta <= 0 or above k_w/2
 * @retval PMSTEP_ERR_POSITION_INTEGRAL_GAIN   k_I < 0 or above k_theta^2/4
 */
pmstep_status_t pmstep_position_init(pmstep_position_t *pos, pmstep_t *inst, const pmstep_position_config_t *cfg);

/**
 * One control period: pmstep_step() on the attached instance, then the turn count and, every
 * PMSTEP_POSITION_DECIMATION periods, the position estimate and, in position mode, the loop's
 * speed reference for the next N periods. Never fails; leaving RUN (stop,
 * fault, re-alignment) loses the position (not tracked, speed mode).
 */
void pmstep_position_step(pmstep_position_t *pos, const pmstep_meas_t *meas, pmstep_output_t *out,
                          pmstep_position_output_t *pos_out);

/** The part of pmstep_position_step() after pmstep_step(), for a caller that runs the step itself
 *  (with the output of that step). */
void pmstep_position_update(pmstep_position_t *pos, const pmstep_output_t *out, pmstep_position_output_t *pos_out);

/**
 * theta-hat, mechanical rad from the zero.
 * @retval PMSTEP_OK                 @p position_rad set
 * @retval PMSTEP_ERR_NULL_ARGUMENT  an argument is NULL
 * @retval PMSTEP_ERR_BAD_MODE       not tracked (not in RUN): no estimate
 */
pmstep_status_t pmstep_get_position(const pmstep_position_t *pos, float *position_rad);

/**
 * theta* of the period just run (position mode; theta-hat in speed mode), from the profile: for
 * logs and a console, not needed by the loop.
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT, PMSTEP_ERR_BAD_MODE (not tracked)
 */
pmstep_status_t pmstep_position_reference(const pmstep_position_t *pos, float *position_ref_rad);

/**
 * The present position becomes 0 (theta-hat and, in position mode, theta* and the target move with it).
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT, PMSTEP_ERR_BAD_MODE (not tracked)
 */
pmstep_status_t pmstep_position_set_zero(pmstep_position_t *pos);

/**
 * Moves to @p target_rad (mechanical, from the zero) by a jerk-limited profile from the present
 * reference (pmstep_motion_plan()); re-targets a move under way. From speed mode the profile
 * starts at theta-hat with the present w* and w*'.
 * @param pos          the position layer
 * @param target_rad   where to stop, mechanical rad from the zero
 * @param v_max_rad_s  speed limit of the profile (> 0)
 * @param a_max_rad_s2 acceleration limit of the profile (> 0)
 * @param j_max_rad_s3 jerk limit; 0 = a_max times the reference bandwidth varpi_0
 * @retval PMSTEP_OK                     position mode, moving
 * @retval PMSTEP_ERR_NULL_ARGUMENT      @p pos is NULL
 * @retval PMSTEP_ERR_BAD_MODE           not tracked (not in RUN)
 * @retval PMSTEP_ERR_BAD_COMMAND_VALUE  a value not finite, a limit not > 0 (j_max < 0), or
 *                                       p |target| above PMSTEP_POSITION_MAX_ELECTRICAL_RAD
 */
pmstep_status_t pmstep_position_move_to(pmstep_position_t *pos, float target_rad, float v_max_rad_s, float a_max_rad_s2,
                                        float j_max_rad_s3);

/**
 * Stops as fast as the last move's limits allow (from speed mode: at the present w* at
 * @p a_max_rad_s2 and varpi_0 a_max) and holds where the stop ends.
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT, PMSTEP_ERR_BAD_MODE (not tracked),
 *         PMSTEP_ERR_BAD_COMMAND_VALUE (from speed mode: a_max not finite or not > 0)
 */
pmstep_status_t pmstep_position_hold(pmstep_position_t *pos, float a_max_rad_s2);

/**
 * Puts the reference at rest on theta-hat now: speed 0, the loop's integral at 0 (a stop or an
 * obstacle found: the loop stops pushing toward where the reference had gone). Position mode, not moving.
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT, PMSTEP_ERR_BAD_MODE (not tracked)
 */
pmstep_status_t pmstep_position_rest_here(pmstep_position_t *pos);

/**
 * Position mode on the STEP/DIR input @p sd (pmstep_stepdir.h, initialised for this motor and period):
 * from the next period the loop's reference is the step count's tracker, started where the present
 * reference is (no jump: step count 0 is there). At rest (no step for stop_time_s) the vector hold
 * takes over as at a move's end; the next step releases it. pmstep_position_move_to(),
 * pmstep_position_hold() or a speed command end it, as does leaving RUN.
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT
 * @retval PMSTEP_ERR_BAD_MODE  not tracked (not in RUN)
 * @retval PMSTEP_ERR_STEPDIR_STALL_CURRENT  @p sd's stall current not below max_phase_current_A
 */
pmstep_status_t pmstep_position_follow_steps(pmstep_position_t *pos, struct pmstep_stepdir *sd);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_POSITION_H */
