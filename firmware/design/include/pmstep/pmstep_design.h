/**
 * @file pmstep_design.h
 * @brief Gain designer: every setting of pmstep_config_t from a motor's data, by the rules
 *        derived in docs/design (pole placement on the linearised error
 *        dynamics, bandwidths as fractions of the control rate).
 *
 * Portable C99 like the core (no heap, no stdio, float32; sqrtf only), in a library of its
 * own (pmstep_design) so that an image that does not design its gains does not carry it. An
 * MCU can call it at boot from datasheet values, or again from what commissioning measured.
 */
#ifndef PMSTEP_DESIGN_H
#define PMSTEP_DESIGN_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What the designer needs to know of the motor and the drive. */
typedef struct {
    pmstep_motor_config_t motor;          /**< R, L, J, F, k_M, p, detent, rated current (datasheet or measured) */
    float bus_voltage_V;                  /**< nominal DC bus */
    float current_sense_range_A;          /**< the drive's phase-current measurement reads +/- this */
    float bus_sense_range_V;              /**< the drive's bus measurement reads up to this */
    float period_s;                       /**< control period T_s */
    uint32_t computational_delay_periods; /**< 0 or 1 */
    bool self_commissioning;              /**< robust mode: Remark 2 offsets and voltage bias, R/L/k_M measured
                                               at t_c, drift-free angle, dead-time compensation */
    float dead_time_s;                    /**< the bridge's dead time (robust mode; 0 = none) */
    bool phase_voltage_sensing;           /**< the drive senses the phase voltages: passed on to
                                               inverter.phase_voltage_sensing (the gains are the same) */
    bool low_speed_drive;                 /**< robust mode, currents sensed only: the standstill's vector turns at
                                               every speed of its band, not in stops only (stops_only); it turns
                                               below 2 V_bus t_d / (T_s k_M) (standstill.vector_speed_rad_s) */
    float current_resolution_A;           /**< current measurement resolution (ADC step or noise, whichever is
                                               larger): the dead-time compensation's band (robust mode) */
    float holding_torque_Nm;              /**< the datasheet's holding torque (both phases at rated current); 0 = not
                                               given. With it, the data is checked for what no stepper has
                                               (pmstep_design_check_datasheet()), and a rotor inertia of 0 is
                                               estimated from it (PMSTEP_DESIGN_INERTIA_PER_TORQUE) */
    bool accept_implausible;              /**< design for data the datasheet check refuses (the caller warns) */
    bool field_weakening_off;             /**< no field weakening (i_d* stays at its command at every speed) */
} pmstep_design_input_t;

/** The design's figures, for people and for the SIL's validation. */
typedef struct {
    float top_speed_rad_s;           /**< the lower of bus_speed_rad_s and rate_speed_rad_s */
    float bus_speed_rad_s;           /**< speed at which rated current takes 90 % of the bus (i_d = 0) */
    float rate_speed_rad_s;          /**< speed at which the rotor turns PMSTEP_DESIGN_MAX_ELECTRICAL_STEP_RAD per
                                          period */
    float top_electrical_step_rad;   /**< p x top speed x T_s: electrical angle turned per period at top speed */
    float current_bandwidth_rad_s;   /**< R/L + K_i: pole of the current error */
    float observer_bandwidth_rad_s;  /**< w_o: triple pole of the linearised speed/load observer */
    float speed_bandwidth_rad_s;     /**< k_w */
    float alignment_current_A;       /**< u_cs/R = u_cc/R */
    float alignment_frequency_rad_s; /**< sqrt(p k_M I_al / J): natural frequency of the alignment swing */
    float alignment_damping;         /**< its damping ratio (electrical damping through the winding, and F) */
    float condition_4_margin;        /**< left side of (4) over its right side (> 1 when (4) holds) */
    float detent_margin;             /**< 0.9186 k_M I_al / T_d: c-alignment's torque over the least that pulls
                                          the rotor across the detent (0: no detent) */
    float magnetising_current_A;     /**< i_d* the robust mode should run with (0 in paper mode) */
    float rated_torque_Nm;           /**< k_M x rated current (torque of one phase at rated current) */
    float weakening_current_A;       /**< I_w: the most field weakening takes off i_d* (0: off) */
    float weakened_speed_rad_s;      /**< with field weakening, the speed at which PMSTEP_DESIGN_WEAKENED_TORQUE_SHARE
                                          of the holding torque still fits in the bus (i_d* = -I_w), at most
                                          rate_speed_rad_s; top_speed_rad_s without it */
    float inertia_kgm2;              /**< the rotor inertia designed for: the input's, or its estimate */
    bool inertia_estimated;          /**< the input gave no inertia: estimated from the holding torque, to be
                                          identified in RUN (commissioning.identification_*) */
} pmstep_design_report_t;

/** The top speed turns the rotor at most this electrical angle per period: the speed-consistency
 *  check turns its estimate over PMSTEP_DETECTION_DECIMATION = 4 periods by pmstep_small_rotation(),
 *  whose polynomials stay within 0.023 of cos and sin up to 1.6 rad (docs/design/06-top-speed.md). */
#define PMSTEP_DESIGN_MAX_ELECTRICAL_STEP_RAD 0.4f
/** The share of the holding torque the field-weakened top speed keeps (the q current's room in the
 *  rated current's circle beside I_w, and weakened_speed_rad_s). */
#define PMSTEP_DESIGN_WEAKENED_TORQUE_SHARE 0.3f

/** Rotor inertia of a stepper from its holding torque T_H, where the datasheet gives none:
 *  J = PMSTEP_DESIGN_INERTIA_PER_TORQUE x (T_H / 1 N m)^1.5 kg m^2, a fit to NEMA 8-34 datasheets
 *  (0.4 N m: 5e-6; 1.26 N m: 3e-5; 4.5 N m: 2e-4), within a factor of 2 of most. */
#define PMSTEP_DESIGN_INERTIA_PER_TORQUE 2.1e-5f
/** Paper mode designs for this many times the estimate, the top of its range: its observer and
 *  speed loop ride out a rotor 4 times lighter than designed for, not one 2 times heavier
 *  (docs/design/10-inertia-and-friction.md). Robust mode takes the estimate itself. */
#define PMSTEP_DESIGN_INERTIA_ESTIMATE_SPREAD 2.0f

/**
 * Checks motor data for what no stepper has (only where the holding torque is given):
 * @retval PMSTEP_OK
 * @retval PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT  k_M outside [1/2, 2] x T_H / (sqrt(2) I): the holding torque or the
 *                                               rated current is off (N cm typed as N m, a per-phase figure)
 * @retval PMSTEP_ERR_DATASHEET_TIME_CONSTANT    L/R outside [0.1, 20] ms
 * @retval PMSTEP_ERR_DATASHEET_FLUX_RATIO       p L I / (T_H / (sqrt(2) I)) outside [0.1, 10]: the winding's flux at
 *                                               rated current against the magnet's (0.5-3 in stepper datasheets)
 * @retval PMSTEP_ERR_DATASHEET_INERTIA          J outside [1/10, 10] x the estimate from T_H
 */
pmstep_status_t pmstep_design_check_datasheet(const pmstep_design_input_t *in);

/**
 * Designs every setting of @p cfg for the motor and drive in @p in (see docs/design); the
 * result passes pmstep_validate_config().
 * @retval PMSTEP_OK
 * @retval PMSTEP_ERR_NULL_ARGUMENT        a pointer is NULL
 * @retval PMSTEP_ERR_NONFINITE_PARAMETER  an input is NaN or Inf
 * @retval PMSTEP_ERR_RESISTANCE ... PMSTEP_ERR_POLE_PAIRS  bad motor data (as pmstep_validate_config())
 * @retval PMSTEP_ERR_PERIOD, PMSTEP_ERR_DELAY  bad timing
 * @retval PMSTEP_ERR_RATED_CURRENT        rated current <= 0
 * @retval PMSTEP_ERR_BUS_BELOW_RATED      bus <= 0, or R x rated current above 90 % of it
 * @retval PMSTEP_ERR_SENSE_RANGE          a sensing range <= 0
 * @retval PMSTEP_ERR_SENSE_RANGE_BELOW_RATED  the current sensing cannot read 1.25 x the rated current within
 *                                         PMSTEP_SENSE_RANGE_USABLE_FRACTION of its range
 * @retval PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE    the bus sensing cannot read 1.1 x the bus likewise
 * @retval PMSTEP_ERR_RATE_TOO_SLOW        R/L or F/J too large for the control period
 * @retval PMSTEP_ERR_DEAD_TIME            dead time < 0 or 4 t_d >= T_s
 * @retval PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT  the detent torque T_d at or above k_M I_al x 0.9186, I_al the
 *                                         largest alignment current (4) (0.8 of its limit) and the rating allow
 * @retval PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT ... PMSTEP_ERR_DATASHEET_FLUX_RATIO
 *                                         pmstep_design_check_datasheet(), unless accept_implausible
 * @retval other                           the designed configuration fails pmstep_validate_config()
 */
pmstep_status_t pmstep_design(const pmstep_design_input_t *in, pmstep_config_t *cfg, pmstep_design_report_t *report);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_DESIGN_H */
