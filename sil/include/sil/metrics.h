/**
 * @file metrics.h
 * @brief What a closed-loop run is judged by: the per-period sample and the
 *        summary metrics gathered from it. Shared by the SIL runner and the PIL
 *        closed loop on the target, so both compute the same figures.
 */
#ifndef SIL_METRICS_H
#define SIL_METRICS_H

#include <stdbool.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_homing.h"
#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One control period, at sample time t_k (plant state before the period). */
typedef struct {
    long step;
    double t_s;
    double theta_rad, omega_rad_s, i_a_A, i_b_A;
    double cos_ptheta, sin_ptheta; /**< true electrical angle */
    double u_a_V, u_b_V;           /**< voltage the plant sees over [t_k, t_k+1] */
    double load_Nm;                /**< true T_L */
    const pmstep_output_t *out;    /**< the step's output (estimates, mode, fault); in microstep mode the
                                          drive's (sil/microstep.h) */
    pmstep_t *inst;                /**< the core's instance, for tests that inspect or perturb its state
                                          (a change takes effect from the next period); NULL in microstep mode */
    double angle_ref_rad;          /**< microstep mode only (not read otherwise): theta_e*, electrical, unwrapped */
    const pmstep_position_output_t *position; /**< a position scenario's position output; NULL otherwise */
    double position_rad;                      /**< position scenario: true theta from the c-alignment's equilibrium (the
                                          estimate's origin) once RUN began; 0 before */
    double position_estimate_rad;  /**< position scenario, tracked: theta-hat of this period (pmstep_get_position) */
    double position_reference_rad; /**< theta* of this period (pmstep_position_reference) */
    bool position_updated;         /**< this period ran the position update (the output's values are its own) */
    bool stepdir;                  /**< a STEP/DIR scenario (position.source = stepdir): the three below are set */
    int32_t step_count;            /**< the step generator's count at t_k (microsteps, signed) */
    double step_error_full_steps;  /**< count q - theta (the plant's, from the c-alignment's equilibrium) in full
                                          steps pi / (2 p); 0 until the drive follows the count */
    bool diag;                     /**< DIAG after this period (pmstep_stepdir_diag(); false for the baseline) */
} sil_sample_t;

/** Position scenario (issue 13): the moves and the hold, judged on the true position (electrical rad: p times
 *  mechanical) against the commanded one. */
typedef struct {
    int moves;                  /**< moves issued */
    int rejected_moves;         /**< pmstep_position_move_to() refused (none expected) */
    int unfinished_moves;       /**< profile still running when the next move came or the run ended */
    double max_final_error_rad; /**< max |theta - target| p at the end of each move's window (the next
                                                move, the hold window's start, or the end of the run) */
    double mean_final_error_rad;
    int worst_move;                     /**< 1-based index of that maximum */
    double max_overshoot_fraction;      /**< max over moves of (travel beyond the target) / |move| */
    double max_estimate_error_rad;      /**< max |theta-hat - theta| p while tracked */
    double max_tracking_error_rad;      /**< max |theta* - theta| p in position mode */
    double hold_duration_s;             /**< position.hold_start_s to the end (0: no hold window) */
    double hold_max_error_rad;          /**< max |theta - theta*| p over the hold window */
    double hold_max_estimate_error_rad; /**< max |theta-hat - theta| p over it */
    double hold_drift_rad_s;            /**< least-squares slope of (theta - theta*) p over it (electrical rad/s) */
} sil_position_summary_t;

/** A STEP/DIR scenario (issue 53, position.source = stepdir): the drive against the count the step generator put
 *  out. Errors in full steps, pi / (2 p) mechanical rad, signed count q - theta (theta the plant's from the
 *  c-alignment's equilibrium, where count 0 is: positive when the rotor lags a forward move). Both drives. */
typedef struct {
    uint32_t microsteps;                /**< stepdir.microsteps */
    int moves;                          /**< moves planned */
    double first_move_s;                /**< the first move's start */
    double last_move_end_s;             /**< the last move's end (queued moves included) */
    double peak_speed_rad_s;            /**< the largest |speed| the moves reach (mechanical) */
    double following_start_s;           /**< when the drive began following the count (-1: never) */
    double following_end_s;             /**< when the firmware stopped following (left RUN), -1 if it did not */
    int32_t generator_steps;            /**< the generator's count at the end (microsteps) */
    int32_t drive_steps;                /**< the drive's count at the end (pmstep_stepdir_t::steps; the baseline's
                                                is the generator's) */
    double max_error_moving_full_steps; /**< max |error| while a move runs */
    double rms_error_moving_full_steps; /**< RMS of the error while a move runs */
    double max_error_full_steps;        /**< max |error| from the start of following to the end */
    double rms_error_full_steps;        /**< RMS over the same */
    double final_error_full_steps;      /**< the error at the last period (after the last move) */
    int32_t lost_full_steps;            /**< final_error_full_steps rounded: full steps lost (+: behind) */
    double error_beyond_full_step_s;    /**< the first period with |error| above one full step, -1 if none */
    long diag_periods;                  /**< periods DIAG was asserted (pmstep only) */
    double diag_first_s;                /**< the first of them, -1 if none */
} sil_stepdir_summary_t;

/** A homing scenario's figures (sil/homing_run.h), on the plant's truth. Full steps: pi / (2 p). */
typedef struct {
    pmstep_homing_config_t config;          /**< the settings it ran with */
    pmstep_status_t start_status;           /**< pmstep_homing_start()'s */
    pmstep_homing_state_t state;            /**< at the end of the run */
    double start_s;                         /**< homing started */
    double contact_s;                       /**< the rotor first met the stop, -1 if never */
    double found_s;                         /**< the drive found it (or stopped seeking), -1 if never */
    double done_s;                          /**< backed off, -1 if never */
    bool by_current;                        /**< found by the current test (else by the following error) */
    double zero_rad;                        /**< the stop the drive found, in its frame before the zero */
    double stop_error_full_steps;           /**< that stop less where the rotor meets the stop */
    double contact_peak_current_A;          /**< largest |phase current| from the rotor's contact to the find */
    double seek_peak_stop_torque_Nm;        /**< largest push of the stop on the rotor while seeking */
    double final_from_stop_full_steps;      /**< the rotor's true distance from the stop at the end */
    double final_position_error_full_steps; /**< the drive's position (from its zero) less that distance */
} sil_homing_summary_t;

/** Called once per period; return false to stop the run early. */
typedef bool (*sil_sample_fn)(const sil_sample_t *sample, void *user);

typedef struct {
    long steps;
    double sim_time_s;
    double wall_time_s;
    double cpu_time_s;       /**< CPU time of the process over the same loop (waiting for a core excluded) */
    double plant_time_s;     /**< wall time inside the plant integration (every 16th period timed, scaled) */
    double firmware_time_s;  /**< wall time inside read + pmstep_step + apply (sampled likewise) */
    double real_time_factor; /**< simulated s per wall s */
    /* Alignment residuals, from the plant at the sample nearest t_s and t_c. */
    double cos_ptheta_at_ts, sin_ptheta_at_ts, i_b_residual_at_ts_A;
    double cos_ptheta_at_tc, sin_ptheta_at_tc, i_a_residual_at_tc_A;
    /* Speed error |omega - omega*| on the load transient [t_c, t_c + W) and on tracking [t_c + W, end]. */
    double transient_max_speed_error_rad_s, transient_rms_speed_error_rad_s;
    double tracking_max_speed_error_rad_s, tracking_rms_speed_error_rad_s;
    double final_load_hat_Nm, final_load_Nm, final_load_error_Nm;
    double max_cos_error, max_sin_error; /**< |c-hat - cos p theta|, |s-hat - sin p theta| in RUN */
    double max_phase_voltage_V;          /**< max |u_a|, |u_b| applied */
    double max_phase_current_A;
    long voltage_limited_periods;  /**< periods the core scaled its voltage to the bus */
    long inverter_limited_periods; /**< periods the inverter model clipped */
    pmstep_mode_t final_mode;
    pmstep_fault_t fault;
    long fault_step;
    double fault_time_s;
    pmstep_status_t init_status;
    /* Robustness: ground truth against what the core reported. */
    double run_start_time_s;                   /**< t_c from the start (offset calibration included) */
    double settle_time_s;                      /**< run_start_time_s + transient window: "after transients" */
    double max_angle_error_rad;                /**< max |wrapped angle(c-hat, s-hat) - p theta| in RUN after settle */
    double max_angle_error_time_s;             /**< the time of its first sample; -1 if none */
    double final_angle_error_rad;              /**< at the last RUN sample */
    double max_speed_error_after_settle_rad_s; /**< max |omega - omega*| in RUN after settle */
    double max_speed_error_time_s;             /**< the time of its first sample; -1 if none */
    double loss_of_control_time_s;             /**< first RUN sample with |omega - omega*| or the angle error above the
                                                scenario's loss bounds; -1 if none */
    double detection_latency_s;                /**< fault time - loss time (negative: fault first); NaN if not both */
    bool nonfinite_seen;                       /**< a NaN/Inf in the plant state or the core's output */
    pmstep_commissioning_t commissioning;      /**< what the core measured (pmstep_get_commissioning), last sample */
    /* Both drives (run.controller), for the comparison with the microstepping baseline. */
    double metrics_start_time_s;       /**< start of the window below (run.metrics_start_s or its default) */
    double rms_phase_current_A;        /**< sqrt(mean((i_a^2 + i_b^2)/2)) over the window: per-phase RMS */
    double max_load_angle_rad;         /**< microstep: max |theta_e* - p theta| (unwrapped) over the window;
                                                pmstep: max_angle_error_rad (the angle-estimate error) */
    bool loss_of_synchronism;          /**< microstep: |theta_e* - p theta| > pi at any sample; pmstep: the
                                                angle-estimate error above run.loss_angle_error_rad in RUN */
    double loss_of_synchronism_time_s; /**< its first sample, -1 if none */
    sil_position_summary_t position;   /**< position scenario only (zero otherwise) */
    sil_stepdir_summary_t stepdir;     /**< STEP/DIR scenario only (zero otherwise) */
    sil_homing_summary_t homing;       /**< homing scenario only (zero otherwise) */
    double stop_contact_s;             /**< the rotor first met the plant's hard stop (motor.stop_*), -1 if never */
} sil_summary_t;

/** Running sums behind the summary. */
typedef struct {
    long ts_step, tc_step, transient_end_step;           /**< sample indices of t_s, t_c, t_c + W (as scheduled) */
    bool run_reached;                                    /**< a RUN sample was seen: the plant at t_c is recorded at the
                                                    first (later than tc_step after a repeat of the alignments) */
    double s_align_current_A, c_align_current_A;         /**< u_cs/R, u_cc/R with the plant's R */
    long settle_step;                                    /**< first sample counted "after transients" */
    double loss_speed_error_rad_s, loss_angle_error_rad; /**< the scenario's loss-of-control bounds */
    double loss_position_error_rad;                      /**< in a position scenario's position mode, for the speed's */
    double transient_sq, tracking_sq;
    long transient_n, tracking_n;
    /* The angle error without an atan2 per period: the error of (x, y) = (cos, sin) of
     * (estimate - p theta) exceeds an angle a in [0, pi) exactly when |y| cos a - x sin a > 0. */
    bool loss_angle_reachable; /**< loss_angle_error_rad < pi */
    double loss_angle_cos, loss_angle_sin;
    double max_angle_cos, max_angle_sin; /**< of summary->max_angle_error_rad */
    double last_angle_x, last_angle_y;   /**< of the last RUN sample (final_angle_error_rad) */
    bool microstep;                      /**< run.controller = microstep */
    double pole_pairs;                   /**< the plant's p */
    long metrics_start_step;             /**< first sample of the RMS-current and load-angle window */
    double current_sq;                   /**< sum of (i_a^2 + i_b^2)/2 over the window */
    long current_n;
    bool load_angle_ready;        /**< the offset below is set (first sample) */
    double load_angle_offset_rad; /**< 2 pi n: the load angle starts in (-pi, pi] */
} sil_metrics_t;

/** Periods nearest to @p duration_s. */
long sil_periods_in(double duration_s, double period_s);

/** Clears @p summary (fault step and time -1) and prepares @p m for @p sc. */
void sil_metrics_init(sil_metrics_t *m, const sil_scenario_t *sc, sil_summary_t *summary);

/** Adds one period. */
void sil_metrics_add(sil_metrics_t *m, const sil_sample_t *x, sil_summary_t *summary);

/** RMS values, the final load error and max_load_angle_rad. */
void sil_metrics_finish(const sil_metrics_t *m, sil_summary_t *summary);

#ifdef __cplusplus
}
#endif

#endif /* SIL_METRICS_H */
