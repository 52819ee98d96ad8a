/**
 * @file pmstep_calibrate.h
 * @brief Self-commissioning on the drive: from the rated current (and the pole pairs) alone, the
 *        motor's R, L and k_M measured by the core's own commissioning, its J and F identified in
 *        RUN, and every setting designed for them by pmstep_design(). Portable C99 like the
 *        designer; runs at period boundaries in the main loop, never in the control interrupt.
 *
 * Sequence (docs/design/19-self-commissioning.md):
 *
 *  1. Measuring runs (commissioning.measure_only: offsets, s- and c-alignment, then the bridge off).
 *     The first is designed for a winding of PMSTEP_CALIBRATE_MIN_RESISTANCE_OHM: its alignment
 *     voltage drives at most the design's alignment current (no more than the rated current) through
 *     any winding the drive supports. A run whose current stays below a quarter of what it was designed
 *     for (the continuity check's open phase at t_s) is repeated for a winding PMSTEP_CALIBRATE_PROBE_STEP
 *     times larger; a run that measures R designs the next for that R. Once a run measures R within
 *     PMSTEP_CALIBRATE_R_AGREEMENT of the R it was designed for, its R, L and k_M are the motor's.
 *  2. Identification runs: a design for the measured R, L, k_M (J estimated from the holding torque
 *     sqrt(2) k_M I where none is known), RUN through +0.8 and -0.8 of the top speed with the
 *     identification window open; J and F come from the fit. A J outside [1/2, 2] of the one designed
 *     for is designed for in another run; a run that latches a fault (the first design's J may be far
 *     off) is repeated at half its speed levels (PMSTEP_CALIBRATE_IDENTIFY_ROUNDS runs at most).
 *  3. The final design for the measured R, L, k_M and the identified J, F, validated by pmstep_init():
 *     in force from then on (the caller stores it).
 *
 * The detent torque, which no measurement here gives, is the request's fraction of the holding torque:
 * PMSTEP_CALIBRATE_DETENT_PER_HOLDING for the hybrid steppers of printers and CNC machines (their
 * datasheets: 4-6 %), 0 for a motor without one. It sets s-alignment's lead-in and the detent's
 * compensation in RUN.
 */
#ifndef PMSTEP_CALIBRATE_H
#define PMSTEP_CALIBRATE_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_design.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PMSTEP_CALIBRATE_MIN_RESISTANCE_OHM 0.2f  /**< the smallest winding calibrated: the first run's */
#define PMSTEP_CALIBRATE_MAX_RESISTANCE_OHM 40.0f /**< beyond this the phases are taken as open (no motor) */
#define PMSTEP_CALIBRATE_USABLE_BUS 0.899f        /**< R I at most this of the bus: within the designer's 90 % */
#define PMSTEP_CALIBRATE_PROBE_STEP 4.0f          /**< the continuity check's ratio: a run that sees less than
                                                       1/4 of its design current is repeated for 4 x the R */
#define PMSTEP_CALIBRATE_R_AGREEMENT 0.25f        /**< |R measured / R designed for - 1| that ends the measuring */
#define PMSTEP_CALIBRATE_MEASURE_ROUNDS 8u        /**< measuring runs at most */
#define PMSTEP_CALIBRATE_IDENTIFY_ROUNDS 3u       /**< identification runs at most */
#define PMSTEP_CALIBRATE_DETENT_PER_HOLDING 0.05f /**< T_d of a hybrid stepper, of the holding torque */
#define PMSTEP_CALIBRATE_MAX_DETENT_PER_HOLDING 0.2f /**< the largest fraction a request may give */
#define PMSTEP_CALIBRATE_SPEED_OF_TOP 0.8f        /**< identification's speed levels, of the top speed: halved
                                                       for the next run after a run that latched a fault */
#define PMSTEP_CALIBRATE_ACCEL_OF_RATED 0.2f      /**< its ramps' acceleration, of k_M I / J */
#define PMSTEP_CALIBRATE_HOLD_S 0.3f              /**< each level held this long */
#define PMSTEP_CALIBRATE_RUN_MARGIN_S 1.0f        /**< a run not over this long after its plan: a timeout */

/** What the user tells: the rest is measured. */
typedef struct {
    float rated_current_A; /**< the motor's rated phase current (amplitude): no run drives more */
    int32_t pole_pairs;    /**< 50 for a 1.8 deg stepper, 100 for 0.9 deg */
    bool robust;           /**< the final design in robust mode (Remark 2 calibration, drift-free angle,
                                dead-time compensation): for real hardware */
    float detent_per_holding; /**< the detent torque as a fraction of the holding torque, which nothing here
                                   measures: PMSTEP_CALIBRATE_DETENT_PER_HOLDING for a hybrid stepper, 0 for a
                                   motor without one; in [0, 0.2] */
} pmstep_calibrate_request_t;

typedef enum {
    PMSTEP_CALIBRATE_IDLE = 0,
    PMSTEP_CALIBRATE_MEASURING = 1,   /**< measuring runs: R, L, k_M */
    PMSTEP_CALIBRATE_IDENTIFYING = 2, /**< identification runs: J, F */
    PMSTEP_CALIBRATE_DONE = 3,        /**< the final design in force */
    PMSTEP_CALIBRATE_FAILED = 4       /**< stopped; status says why, the bridge off */
} pmstep_calibrate_stage_t;

/** Why a calibration failed (disjoint from pmstep_status_t's and the store's codes); a design the
 *  designer or the core refused gives its pmstep_status_t instead. */
typedef enum {
    PMSTEP_CALIBRATE_OK = 0,
    PMSTEP_CALIBRATE_ERR_REQUEST = -160,        /**< rated current not > 0, pole pairs < 1, or a value not finite */
    PMSTEP_CALIBRATE_ERR_NO_MOTOR = -161,       /**< no current even designed for the largest winding (
                                                     PMSTEP_CALIBRATE_MAX_RESISTANCE_OHM, or what the bus drives at the
                                                     rated current): a phase open or no motor connected */
    PMSTEP_CALIBRATE_ERR_FAULT = -162,          /**< a run latched a fault (pmstep_calibrate_t::fault) */
    PMSTEP_CALIBRATE_ERR_NOT_CONVERGED = -163,  /**< R never agreed with the R designed for */
    PMSTEP_CALIBRATE_ERR_IDENTIFICATION = -164, /**< J and F not identified (pmstep_calibrate_t::identification) */
    PMSTEP_CALIBRATE_ERR_TIMEOUT = -165,        /**< a run did not end when planned */
    PMSTEP_CALIBRATE_ERR_CANCELLED = -166       /**< stopped from outside (pmstep_calibrate_cancel()) */
} pmstep_calibrate_status_t;

/** A calibration: its request, progress and results (read them; the rest is its own). */
typedef struct {
    pmstep_calibrate_stage_t stage;
    int32_t status;                /**< 0, a pmstep_calibrate_status_t, or a pmstep_status_t of a refused design */
    pmstep_fault_t fault;          /**< the fault that ended the last run (PMSTEP_FAULT_NONE: none) */
    uint32_t runs;                 /**< runs started */
    float resistance_Ohm;          /**< measured (0 until then) */
    float inductance_H;
    float torque_constant_Nm_A;
    float inertia_kgm2;            /**< identified (0 until then) */
    float friction_Nms_rad;
    pmstep_identification_t identification; /**< the last identification's outcome */
    pmstep_design_report_t report; /**< the last design's figures */
    /* own state */
    pmstep_calibrate_request_t request;
    pmstep_config_t board;         /**< the drive's own values: period, delay, sensing, dead time */
    float bus_voltage_V;
    float design_resistance_Ohm;   /**< the R the present run is designed for */
    float design_inertia_kgm2;     /**< the J the present run is designed for (0: estimated) */
    float design_friction_Nms_rad;
    uint32_t rounds;               /**< runs in the present stage */
    bool running;                  /**< a run is under way */
    uint32_t run_start;            /**< period its start took effect */
    uint32_t run_limit;            /**< periods it may take */
    uint32_t profile_step;         /**< identification: the speed command next due */
    uint32_t profile_at;           /**< period it is due at, from run_start */
    float speed_of_top;            /**< identification's speed levels, of the top speed */
    bool identified;               /**< the run's window closed: its outcome taken (a fault after it, on the way
                                        back to rest, does not lose it) */
} pmstep_calibrate_t;

/**
 * Starts a calibration for @p req on the drive described by @p board (its timing, sensing ranges,
 * dead time and phase-voltage sensing are kept; everything else is designed), on a bus of
 * @p bus_voltage_V as measured. Nothing moves until pmstep_calibrate_boundary().
 * @retval PMSTEP_OK
 * @retval PMSTEP_ERR_NULL_ARGUMENT       a pointer is NULL
 * @retval PMSTEP_ERR_BAD_COMMAND_VALUE   @p req or the bus not usable (status says which)
 */
pmstep_status_t pmstep_calibrate_start(pmstep_calibrate_t *cal, const pmstep_calibrate_request_t *req,
                                       const pmstep_config_t *board, float bus_voltage_V);

/**
 * At a period boundary (the core not stepping): advances the calibration by what the core did since
 * the last call. It re-initialises @p inst on @p cfg (which must outlive @p inst) for each run,
 * starts and stops it, and commands its speed. @p period: the index of the next period to step.
 * @return the stage after this call.
 */
pmstep_calibrate_stage_t pmstep_calibrate_boundary(pmstep_calibrate_t *cal, pmstep_t *inst, pmstep_config_t *cfg,
                                                   uint32_t period);

/** Stops a calibration under way (the core stopped, the bridge off): FAILED, ERR_CANCELLED. */
void pmstep_calibrate_cancel(pmstep_calibrate_t *cal, pmstep_t *inst);

/** Whether a calibration is under way (MEASURING or IDENTIFYING). */
bool pmstep_calibrate_active(const pmstep_calibrate_t *cal);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_CALIBRATE_H */
