/**
 * @file pmstep_detect.h
 * @brief Detection in RUN (pmstep_detection_config_t): conditions that say the control is
 *        lost, checked every PMSTEP_DETECTION_DECIMATION periods, each acting once it has
 *        persisted persistence_s.
 *
 *  - angle magnitude: |c-hat^2 + s-hat^2 - 1| > bound (the flux estimate left its circle);
 *  - speed consistency: the estimate's electrical step since the last check,
 *      sin(delta) = c_prev s - s_prev c, against p w-hat x check period; the gap is
 *      low-passed (time constant persistence_s / 4) and compared with
 *      bound_rad_s x p x check period;
 *  - stall: |w-hat - w*| > bound;
 *  - observer residual: |i_a - i_a-hat| + |i_b - i_b-hat|, low-passed, > bound (a rotor the
 *    estimate believes elsewhere leaves back-EMF the observer cannot explain).
 */
#ifndef PMSTEP_DETECT_H
#define PMSTEP_DETECT_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Detection state in RUN. */
typedef struct {
    float prev_cos_hat, prev_sin_hat; /**< the estimate at the last check */
    float rotation_gap_rad;           /**< low-passed (angle step - p w-hat x check period), rad per check */
    float residual_A;                 /**< low-passed |i_a - i_a-hat| + |i_b - i_b-hat| */
    uint32_t magnitude_count, consistency_count, stall_count, residual_count; /**< checks each condition held */
} pmstep_detector_t;

/** Constants derived from the configuration. */
typedef struct {
    uint32_t persistence_checks; /**< checks a condition must persist */
    float alpha;                 /**< check period / time constant of the low-passes */
    float angle_step_per_speed;  /**< p x check period: electrical rad per check per rad/s */
    float consistency_bound_rad; /**< speed_consistency_bound_rad_s x angle_step_per_speed */
} pmstep_detect_coeffs_t;

/** Coefficients for @p cfg (already validated). */
void pmstep_detect_coeffs_init(pmstep_detect_coeffs_t *coeffs, const pmstep_config_t *cfg);

/** Fresh state at t_c: (c-hat, s-hat) = (1, 0), nothing persisted. */
void pmstep_detect_start(pmstep_detector_t *detector);

/**
 * One check (call every PMSTEP_DETECTION_DECIMATION periods in RUN).
 * @param[in,out] detector  the detection state, updated by this check
 * @param[in] coeffs  from pmstep_detect_coeffs_init()
 * @param[in] cfg     the detection settings (thresholds; which conditions are checked)
 * @param[in] out     this period's output of the control stage: (c-hat, s-hat), w-hat, w*, i-hat
 * @param[in] sample  this period's currents as the observer sees them (offset-corrected)
 * @return the fault of a condition that has persisted (the last one checked if several),
 *         or PMSTEP_FAULT_NONE.
 */
pmstep_fault_t pmstep_detect_check(pmstep_detector_t *detector, const pmstep_detect_coeffs_t *coeffs,
                                   const pmstep_detection_config_t *cfg, const pmstep_output_t *out,
                                   const pmstep_meas_t *sample);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_DETECT_H */
