/**
 * @file pmstep.h
 * @brief Sensorless adaptive speed control of a PM step motor (Tomei & Verrelli):
 *        s-alignment (3), c-alignment (5), then controller (6) — or (13) when the
 *        load torque is known. Fixed step, float32, no heap, no stdio.
 *
 * Lifecycle: pmstep_init() validates the configuration (the struct must outlive
 * the instance), pmstep_start() begins the alignment, pmstep_step() runs one
 * control period from the samples taken at its start and never fails: on a
 * protection trip it latches a fault, commands zero voltage and bridge off.
 * One instance drives one motor; the instance's fields are not API.
 */
/**
 * @mainpage pmstep C API
 *
 * The public headers of the firmware, from their comments (docs/Doxyfile). Names carry their
 * units (speed_rad_s, current_A, period_s); a function that returns a pmstep_status_t lists
 * the codes it can return.
 * - pmstep.h: the control core's lifecycle, commands and readings; pmstep_types.h: its
 *   configuration, measurements, outputs, status, fault and mode codes;
 * - pmstep_position.h: sensorless position control on top of the speed controller;
 * - pmstep_design.h: the gain designer, every setting from a motor's data;
 * - pmstep_console.h: the command and telemetry interface over a byte stream;
 * - pmstep_hal.h: the contract between the core and a port.
 *
 * The other headers of pmstep/ are the core's stages (angle, observer, law, actuation,
 * commissioning, detection, ...), public for the tests and for static allocation: their
 * structures' fields are not API.
 */
#ifndef PMSTEP_H
#define PMSTEP_H

#include "pmstep/pmstep_types.h"
#include "pmstep/pmstep_instance.h" /* the layout, for static allocation only */

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Validates @p cfg and prepares @p inst (mode IDLE).
 * @retval PMSTEP_OK                 ready; @p cfg must outlive @p inst
 * @retval PMSTEP_ERR_NULL_ARGUMENT  @p inst or @p cfg is NULL
 * @retval other negative codes      the first violation pmstep_validate_config() finds
 */
pmstep_status_t pmstep_init(pmstep_t *inst, const pmstep_config_t *cfg);

/**
 * Validates a configuration without an instance (every cause has its own code).
 * @retval PMSTEP_OK                       valid
 * @retval PMSTEP_ERR_NULL_ARGUMENT        @p cfg is NULL
 * @retval PMSTEP_ERR_NONFINITE_PARAMETER  a setting is NaN or Inf
 * @retval PMSTEP_ERR_RESISTANCE ... PMSTEP_ERR_DETECTION_TIME  the first violated condition, group by group in the
 *         order motor, timing, gains, limits, alignment, commissioning, inverter, detection (pmstep_types.h)
 * @retval PMSTEP_ERR_IDENTIFICATION_WINDOW, PMSTEP_ERR_IDENTIFICATION_SPEED, PMSTEP_ERR_MECHANICS_UNIDENTIFIED
 *         the identification settings of the commissioning group (checked with it)
 * @retval PMSTEP_ERR_DERIVED_NONFINITE    a coefficient derived from valid settings is not finite
 */
pmstep_status_t pmstep_validate_config(const pmstep_config_t *cfg);

/** Back to IDLE with every state cleared (fault included); keeps the configuration. */
void pmstep_reset(pmstep_t *inst);

/**
 * IDLE -> OFFSET_CAL (when configured) or S_ALIGN; commissioning restarts.
 * @retval PMSTEP_OK                 started
 * @retval PMSTEP_ERR_NULL_ARGUMENT  @p inst is NULL
 * @retval PMSTEP_ERR_BAD_MODE       not IDLE
 */
pmstep_status_t pmstep_start(pmstep_t *inst);

/**
 * Any mode but FAULT -> IDLE (bridge off).
 * @retval PMSTEP_OK                 stopped
 * @retval PMSTEP_ERR_NULL_ARGUMENT  @p inst is NULL
 * @retval PMSTEP_ERR_BAD_MODE       in FAULT: only pmstep_clear_fault() leaves it
 */
pmstep_status_t pmstep_stop(pmstep_t *inst);

/**
 * FAULT -> IDLE; the angle is lost, so a new start re-aligns.
 * @retval PMSTEP_OK                 cleared
 * @retval PMSTEP_ERR_NULL_ARGUMENT  @p inst is NULL
 * @retval PMSTEP_ERR_BAD_MODE       not in FAULT
 */
pmstep_status_t pmstep_clear_fault(pmstep_t *inst);

/**
 * Speed set-point: ramps to @p target_rad_s at @p ramp_rate_rad_s2, then filtered by H(s).
 * The reference starts at 0 when RUN begins; a target set earlier is followed from then.
 * @retval PMSTEP_OK                    set
 * @retval PMSTEP_ERR_NULL_ARGUMENT     @p inst is NULL
 * @retval PMSTEP_ERR_BAD_COMMAND_VALUE a value is not finite, or the ramp rate is not > 0
 */
pmstep_status_t pmstep_set_speed_target(pmstep_t *inst, float target_rad_s, float ramp_rate_rad_s2);

/**
 * i_d* set-point (A), stepped and filtered by H(s) (default 0).
 * @retval PMSTEP_OK                    set
 * @retval PMSTEP_ERR_NULL_ARGUMENT     @p inst is NULL
 * @retval PMSTEP_ERR_BAD_COMMAND_VALUE @p target_A is not finite
 */
pmstep_status_t pmstep_set_id_target(pmstep_t *inst, float target_A);

/**
 * Holds the rotor at rest at the electrical angle (@p cos_rest, @p sin_rest) by a current
 * vector of @p current_A fixed in the stator frame, aimed ahead of the rest by the load angle
 * of @p load_Nm (pmstep_hold.h). The law's speed loop pauses; the observer runs on. In force
 * until pmstep_release_vector(), a speed command, or leaving RUN. A new call re-aims.
 * @retval PMSTEP_OK                    holding
 * @retval PMSTEP_ERR_NULL_ARGUMENT     @p inst is NULL
 * @retval PMSTEP_ERR_BAD_MODE          not in RUN, or the known-load mode (Remark 1)
 * @retval PMSTEP_ERR_BAD_COMMAND_VALUE a value not finite, or (cos, sin) not within 1 % of unit length
 * @retval PMSTEP_ERR_HOLD_CURRENT      @p current_A not in (0, max_phase_current_A), or
 *                                      |load - detent| above PMSTEP_HOLD_MAX_TORQUE_FRACTION k_M I
 */
pmstep_status_t pmstep_hold_vector(pmstep_t *inst, float cos_rest, float sin_rest, float current_A, float load_Nm);

/** Ends a vector hold: the law's speed loop takes over from the next period (its current
 *  integrals restart at 0). No effect without a hold. */
void pmstep_release_vector(pmstep_t *inst);

/** The speed reference is taken over by another loop (the position library): the standstill
 *  hold of speed mode (pmstep_standstill_config_t, pmstep_hold.h) ends and stays off until the
 *  next pmstep_set_speed_target(). No effect outside RUN or with a NULL @p inst. */
void pmstep_leave_speed_mode(pmstep_t *inst);

/**
 * Sets the angle estimate to (@p cos_hat, @p sin_hat): the flux integrals are moved so that
 * the present currents give it. For a rotor known to be at that angle (at rest in a hold).
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT, PMSTEP_ERR_BAD_MODE (not in RUN),
 *         PMSTEP_ERR_BAD_COMMAND_VALUE (a value not finite)
 */
pmstep_status_t pmstep_set_angle_estimate(pmstep_t *inst, float cos_hat, float sin_hat);

/** Runs one control period. Never fails; see pmstep_output_t. */
void pmstep_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out);

/** The mode the instance is in now (the next step runs in it unless a transition is due). */
static inline pmstep_mode_t pmstep_get_mode(const pmstep_t *inst)
{
    return inst->mode;
}

/** The fault latched (PMSTEP_FAULT_NONE unless in FAULT). */
static inline pmstep_fault_t pmstep_get_fault(const pmstep_t *inst)
{
    return inst->fault;
}

/** Calibration and commissioning results so far (telemetry; see pmstep_commissioning_t). */
static inline void pmstep_get_commissioning(const pmstep_t *inst, pmstep_commissioning_t *out)
{
    *out = inst->commissioning;
}

/** Configuration of the paper's Section III (motor, gains, t_s = 0.3 s, t_c = 0.6 s), 20 kHz.
 *  In the library pmstep_presets, apart from the core. */
pmstep_config_t pmstep_paper_config(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_H */
