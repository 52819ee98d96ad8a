/**
 * @file microstep.h
 * @brief The baseline every stepper user has today: an open-loop microstepping drive at
 *        rated current (run.controller = microstep). It stands in for the firmware in the
 *        SIL loop, at the same control period and through the same measurement chain,
 *        inverter and bus; it is not part of the firmware.
 *
 * Reference: the scenario's speed profile as a plain ramp (the commands of
 * sil_scenario_speed_command(), no H(s) smoothing, as a step/dir pulse train gives),
 * omega*(t), and the commanded electrical angle theta_e* = p * integral of omega* dt
 * (0 before the first ramp: the power-on hold that aligns the rotor to p theta = 0 mod 2 pi).
 *
 * Or, following a STEP/DIR count (position.source = stepdir), the angle itself each period:
 * theta_e* = p n q for a count n of microsteps q (sil_microstep_set_angle()), and omega* its change
 * over the last period (what a drive that sees only the steps knows of the speed).
 *
 * Set-points i_a* = I cos theta_e*, i_b* = I sin theta_e*, I = datasheet.rated_current_A,
 * so the torque is k_M I sin(theta_e* - p theta) and the pull-out torque k_M I.
 *
 * Current regulator (a chopper drive: no back-EMF feed-forward), per phase, with R and L
 * as the drive is told (controller.motor.*):
 *   u = R i* + L (d/dt) i* + L a (i* - i_meas),   a = SIL_MICROSTEP_GAIN_FRACTION / T_s,
 * i* and (d/dt) i* at the sample instant t_k, u clipped to +/- the measured bus voltage and
 * applied now or one period later (run.delay_periods), by the host port like the firmware's.
 */
#ifndef SIL_MICROSTEP_H
#define SIL_MICROSTEP_H

#include "pmstep/pmstep.h"
#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The current loop's rate a as a fraction of the control rate 1/T_s (a T_s = 0.2: the
 *  current error shrinks by 0.8 a period with matched L, and stays well damped with one
 *  period of delay). */
#define SIL_MICROSTEP_GAIN_FRACTION 0.2

typedef struct {
    /* Settings (sil_microstep_init). */
    double period_s;       /**< T_s */
    double current_A;      /**< I: set-point amplitude per phase */
    double resistance_Ohm; /**< R the drive is told */
    double inductance_H;   /**< L the drive is told */
    double pole_pairs;     /**< p the drive is told (electrical per mechanical angle) */
    double gain_per_s;     /**< a */
    /* State: the reference at the present sample t_k. */
    double speed_ref_rad_s;  /**< omega*(t_k), mechanical */
    double target_rad_s;     /**< where the ramp goes */
    double ramp_rate_rad_s2; /**< its slope (> 0; <= 0: a step) */
    double angle_ref_rad;    /**< theta_e*(t_k), electrical, unwrapped */
    bool moving;             /**< a speed command or an angle has been given: the hold is over */
    bool angle_mode;         /**< following an angle (sil_microstep_set_angle()), not a speed profile */
} sil_microstep_t;

/** Settings from @p sc (T_s, datasheet.rated_current_A, controller.motor R, L, p); reference 0. */
void sil_microstep_init(sil_microstep_t *drive, const sil_scenario_t *sc);

/** A speed command (the arguments of pmstep_set_speed_target()): ramp from the present
 *  reference to @p target_rad_s at @p ramp_rate_rad_s2. */
void sil_microstep_set_speed_target(sil_microstep_t *drive, double target_rad_s, double ramp_rate_rad_s2);

/** Angle mode: theta_e* = @p angle_ref_rad (electrical, unwrapped) from the present sample t_k on, and
 *  omega* its change since the last call over T_s (0 at the first: the hold before it is at rest).
 *  The speed profile's commands are not followed any more. */
void sil_microstep_set_angle(sil_microstep_t *drive, double angle_ref_rad);

/**
 * One control period: the phase voltages from the sample @p meas at t_k into @p out
 * (u_a_V, u_b_V, bridge_enable, voltage_limited; the telemetry of the CSV: cos_hat, sin_hat
 * = cos, sin theta_e*; speed_ref_rad_s = omega*; speed_ref_rate_rad_s2; i_a_hat_A, i_b_hat_A
 * = i_a*, i_b*; mode C_ALIGN during the hold, RUN after; the rest 0), then advances the
 * reference to t_k + T_s (theta_e* integrated exactly over the ramp; in angle mode the next
 * sil_microstep_set_angle() gives it).
 */
void sil_microstep_step(sil_microstep_t *drive, const pmstep_meas_t *meas, pmstep_output_t *out);

#ifdef __cplusplus
}
#endif

#endif /* SIL_MICROSTEP_H */
