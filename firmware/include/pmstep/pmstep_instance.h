/**
 * @file pmstep_instance.h
 * @brief Layout of the controller instance. Not API: pmstep.h includes it only so that an
 *        application can allocate pmstep_t statically (no heap). Use the functions of
 *        pmstep.h; tests that look inside include this header by name.
 */
#ifndef PMSTEP_INSTANCE_H
#define PMSTEP_INSTANCE_H

#include "pmstep/pmstep_types.h"
#include "pmstep/pmstep_ref.h"
#include "pmstep/pmstep_angle.h"
#include "pmstep/pmstep_observer.h"
#include "pmstep/pmstep_law.h"
#include "pmstep/pmstep_commission.h"
#include "pmstep/pmstep_identify.h"
#include "pmstep/pmstep_detect.h"
#include "pmstep/pmstep_actuate.h"
#include "pmstep/pmstep_hold.h"
#include "pmstep/pmstep_continuity.h"
#include "pmstep/pmstep_weakening.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Everything init derives from the configuration (pmstep_derive.c): the angle, observer and law
 * coefficients again at t_c, for the commissioned model. Validation derives it as init does and
 * checks every float of it finite. */
typedef struct {
    pmstep_commission_plan_t commission_plan; /**< alignment timing (t_s, t_c in periods) and windows */
    uint32_t offset_cal_steps;                /**< periods of bridge-off offset calibration */
    bool optional_inputs;                     /**< a load torque or phase voltages to check each period */
    bool robust_corrections;                  /**< the drift-free or the back-EMF angle correction, or the transient
                                                   observer boost, is on */
    bool angle_smoothing;                     /**< gains.angle_smoothing > 0 */
    bool voltage_corrected;                   /**< the period's voltage is sensed or dead-time compensated */
    pmstep_detect_coeffs_t detect_coeffs;
    pmstep_continuity_coeffs_t continuity_coeffs;
    pmstep_actuate_coeffs_t actuate_coeffs;
    pmstep_ref_coeffs_t ref_coeffs;
    pmstep_angle_coeffs_t angle_coeffs;
    pmstep_observer_coeffs_t observer_coeffs;
    pmstep_law_coeffs_t law_coeffs;
    pmstep_weakening_coeffs_t weakening_coeffs;
} pmstep_derived_t;

/** One controller instance; all state lives here. */
typedef struct {
    const pmstep_config_t *cfg;
    pmstep_derived_t derived; /**< from cfg at init */

    /* Mode machine. */
    pmstep_mode_t mode;
    pmstep_fault_t fault;
    uint32_t fault_step; /**< step_count at which the fault latched */
    uint32_t step_count; /**< periods run since init/reset */
    uint32_t mode_step;  /**< periods since the alignment started */
    bool run_started;    /**< RUN initialised at t_c */
    bool estimate_kept;  /**< the standstill's kept rotor is the period's estimate, not the integrals'
                               (pmstep_hold.h; kept here, in the padding of the flags before it) */

    /* Controller (6) state and commands. */
    pmstep_ref_t speed_ref;
    pmstep_ref_t i_d_ref;
    pmstep_angle_t angle;
    pmstep_observer_t observer;
    pmstep_law_integral_t current_integral; /**< PI current loop (K_I > 0) */
    pmstep_actuator_t actuator;

    pmstep_commissioning_t commissioning; /**< offsets (subtracted from every sample once measured), R, L, k_M, J, F */
    union {
        pmstep_commission_sums_t sums; /**< until t_c */
        struct {
            pmstep_detector_t detector;
            pmstep_ref_t known_load_filter;   /**< T_L* of Remark 1 */
            pmstep_identify_sums_t identify;  /**< J and F fit, while the identification window is open */
            pmstep_standstill_t standstill;   /**< standstill hold in speed mode (pmstep_hold.h) */
            pmstep_angle_smoother_t smoother; /**< the angle smoothing's (gains.angle_smoothing > 0) */
            pmstep_continuity_t continuity;   /**< the windings' and sensors' continuity (pmstep_continuity.h) */
        } run;                                /**< from t_c */
    } scratch;

    pmstep_vector_hold_t hold;    /**< standstill hold by a stator-frame vector (pmstep_hold.h) */
    pmstep_weakening_t weakening; /**< the commanded i_d* and field weakening's share of it */
} pmstep_t;

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_INSTANCE_H */
