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
 */
#ifndef PMSTEP_H
#define PMSTEP_H

#include "pmstep/pmstep_types.h"
#include "pmstep/pmstep_ref.h"
#include "pmstep/pmstep_angle.h"
#include "pmstep/pmstep_observer.h"
#include "pmstep/pmstep_law.h"
#include "pmstep/pmstep_commission.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Detection state in RUN (see pmstep_config_t, "Detection"). */
typedef struct {
    float prev_cos_hat, prev_sin_hat;  /**< the estimate at the last check */
    float rotation_gap_rad;            /**< low-passed (angle step - p w-hat x check period), rad per check */
    float residual_a;                  /**< low-passed |i_a - i_a-hat| + |i_b - i_b-hat| */
    uint32_t magnitude_count, consistency_count, stall_count, residual_count; /**< checks each condition has persisted */
} pmstep_detector_t;

/** One controller instance; all state lives here. Treat the fields as private. */
typedef struct {
    const pmstep_config_t *cfg;
    pmstep_commission_plan_t commission_plan; /**< alignment timing (t_s, t_c in periods) and windows */
    uint32_t offset_cal_steps;    /**< periods of bridge-off offset calibration */
    bool compensate_voltage;      /**< dead time configured or voltage bias estimated */
    uint32_t detection_steps;     /**< checks (one every 4 periods) a condition must persist */
    /* Floats derived at init, from here to the end of law_coeffs' floats: init checks them all finite. */
    float dead_time_duty;         /**< 2 t_d / T_s: compensation at full current, fraction of the bus */
    float inv_dead_time_band_per_a;
    float detection_alpha;        /**< check period / tau of the detection low-passes */
    float angle_step_per_speed;   /**< p x check period: electrical rad per check per rad/s */
    float consistency_bound_rad;  /**< speed_consistency_bound_rad_s x angle_step_per_speed */
    pmstep_ref_coeffs_t ref_coeffs;
    pmstep_angle_coeffs_t angle_coeffs;
    pmstep_observer_coeffs_t observer_coeffs;
    pmstep_law_coeffs_t law_coeffs;

    pmstep_mode_t mode;
    pmstep_fault_t fault;
    uint32_t fault_step;          /**< step_count at which the fault latched */
    uint32_t step_count;          /**< periods run since init/reset */
    uint32_t mode_step;           /**< periods since the alignment started */
    bool run_started;             /**< RUN initialised at t_c */

    pmstep_ref_t speed_ref;
    pmstep_ref_t i_d_ref;
    pmstep_angle_t angle;
    pmstep_observer_t observer;

    float u_applied_a_v;          /**< voltage applied over the period that ends at this sample */
    float u_applied_b_v;
    float u_pending_a_v;          /**< computed, waiting one period (delay = 1) */
    float u_pending_b_v;

    pmstep_commissioning_t commissioning; /**< offsets (subtracted from every sample once measured), R, L, k_M */
    union {
        pmstep_commission_sums_t sums;    /**< until t_c */
        struct {
            pmstep_detector_t detector;
            pmstep_ref_t known_load_filter; /**< T_L* of Remark 1 */
        } run;                            /**< from t_c */
    } scratch;
} pmstep_t;

/** Validates @p cfg and prepares @p inst (mode IDLE). @return PMSTEP_OK or the first violation found. */
pmstep_status_t pmstep_init(pmstep_t *inst, const pmstep_config_t *cfg);

/** The model of the configuration: R, L, k_M as configured. */
pmstep_electrical_t pmstep_configured_electrical(const pmstep_config_t *cfg);

/** Validates a configuration without an instance. */
pmstep_status_t pmstep_validate_config(const pmstep_config_t *cfg);

/** Back to IDLE with every state cleared (fault included); keeps the configuration. */
void pmstep_reset(pmstep_t *inst);

/** IDLE -> OFFSET_CAL (when configured) or S_ALIGN; commissioning restarts. @return PMSTEP_ERR_BAD_MODE unless IDLE. */
pmstep_status_t pmstep_start(pmstep_t *inst);

/** Any mode but FAULT -> IDLE (bridge off). @return PMSTEP_ERR_BAD_MODE in FAULT. */
pmstep_status_t pmstep_stop(pmstep_t *inst);

/** FAULT -> IDLE; the angle is lost, so a new start re-aligns. @return PMSTEP_ERR_BAD_MODE unless FAULT. */
pmstep_status_t pmstep_clear_fault(pmstep_t *inst);

/**
 * Speed set-point: ramps to @p target_rad_s at @p ramp_rate_rad_s2 (> 0), then filtered by H(s).
 * The reference starts at 0 when RUN begins; a target set earlier is followed from then.
 */
pmstep_status_t pmstep_set_speed_target(pmstep_t *inst, float target_rad_s, float ramp_rate_rad_s2);

/** i_d* set-point (A), stepped and filtered by H(s) (default 0). */
pmstep_status_t pmstep_set_id_target(pmstep_t *inst, float target_a);

/** Runs one control period. Never fails; see pmstep_output_t. */
void pmstep_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out);

/** Calibration and commissioning results so far (telemetry; see pmstep_commissioning_t). */
void pmstep_get_commissioning(const pmstep_t *inst, pmstep_commissioning_t *out);

/** Configuration of the paper's Section III (motor, gains, t_s = 0.3 s, t_c = 0.6 s), 20 kHz.
 *  In the library pmstep_presets, apart from the core. */
pmstep_config_t pmstep_paper_config(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_H */
