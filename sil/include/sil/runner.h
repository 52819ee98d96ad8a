/**
 * @file runner.h
 * @brief Runs a scenario: the real control core (pmstep_step through the host
 *        HAL port) in closed loop with the plant model, one control period at a
 *        time, and gathers the metrics of the run.
 */
#ifndef SIL_RUNNER_H
#define SIL_RUNNER_H

#include <stdbool.h>
#include <stdio.h>

#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One control period, at sample time t_k (plant state before the period). */
typedef struct {
    long step;
    double t_s;
    double theta_rad, omega_rad_s, i_a_a, i_b_a;
    double cos_ptheta, sin_ptheta;   /**< true electrical angle */
    double u_a_v, u_b_v;             /**< voltage the plant sees over [t_k, t_k+1] */
    double load_nm;                  /**< true T_L */
    const pmstep_output_t *out;      /**< the step's output (estimates, mode, fault) */
    pmstep_t *inst;                  /**< the core's instance, for tests that inspect or perturb its state
                                          (a change takes effect from the next period) */
} sil_sample_t;

/** Called once per period; return false to stop the run early. */
typedef bool (*sil_sample_fn)(const sil_sample_t *sample, void *user);

typedef struct {
    long steps;
    double sim_time_s;
    double wall_time_s;
    double plant_time_s;             /**< wall time inside the plant integration */
    double firmware_time_s;          /**< wall time inside read + pmstep_step + apply */
    double real_time_factor;         /**< simulated s per wall s */
    /* Alignment residuals, from the plant at the sample nearest t_s and t_c. */
    double cos_ptheta_at_ts, sin_ptheta_at_ts, i_b_residual_at_ts_a;
    double cos_ptheta_at_tc, sin_ptheta_at_tc, i_a_residual_at_tc_a;
    /* Speed error |omega - omega*| on the load transient [t_c, t_c + W) and on tracking [t_c + W, end]. */
    double transient_max_speed_error_rad_s, transient_rms_speed_error_rad_s;
    double tracking_max_speed_error_rad_s, tracking_rms_speed_error_rad_s;
    double final_load_hat_nm, final_load_nm, final_load_error_nm;
    double max_cos_error, max_sin_error;   /**< |c-hat - cos p theta|, |s-hat - sin p theta| in RUN */
    double max_phase_voltage_v;            /**< max |u_a|, |u_b| applied */
    double max_phase_current_a;
    long voltage_limited_periods;          /**< periods the core scaled its voltage to the bus */
    long inverter_limited_periods;         /**< periods the inverter model clipped */
    pmstep_mode_t final_mode;
    pmstep_fault_t fault;
    long fault_step;
    double fault_time_s;
    pmstep_status_t init_status;
} sil_summary_t;

/**
 * Runs @p sc. @p on_sample may be NULL. @p progress prints a progress line to
 * stderr. @return 0, or -1 when pmstep_init rejected the configuration
 * (summary->init_status says why).
 */
int sil_run(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *summary);

/*
 * Record of a run, for replaying the core's inputs on a target (processor in the
 * loop, tests/pil/). The file is a stream of little-endian 32-bit words; a float
 * is stored as its IEEE-754 binary32 bit pattern, so a replay sees the very bits
 * the host core saw.
 *
 *   header  SIL_RECORD_MAGIC, SIL_RECORD_VERSION, SIL_RECORD_CONFIG_WORDS,
 *           SIL_RECORD_IN_WORDS, SIL_RECORD_OUT_WORDS,
 *           the pmstep_config_t fields in declaration order (SIL_RECORD_CONFIG_WORDS
 *           words: float bits, int32_t/uint32_t as integers, bool as 0/1),
 *           i_d* (float, A) given to pmstep_set_id_target()
 *   entries a tag word, then its payload:
 *     SIL_RECORD_TAG_SPEED_TARGET  target (float, rad/s), ramp rate (float, rad/s^2):
 *                                  a pmstep_set_speed_target() call before the next step
 *     SIL_RECORD_TAG_PERIOD        the step's input, pmstep_meas_t (SIL_RECORD_IN_* order),
 *                                  then its output, pmstep_output_t (SIL_RECORD_OUT_* order)
 *     SIL_RECORD_TAG_END           the number of periods
 *
 * The run it records: pmstep_init(config), pmstep_set_id_target(i_d*), pmstep_start(),
 * then the entries in order.
 */
#define SIL_RECORD_MAGIC 0x52534D50u /* "PMSR" */
#define SIL_RECORD_VERSION 1u
#define SIL_RECORD_CONFIG_WORDS 24u
#define SIL_RECORD_TAG_SPEED_TARGET 1u
#define SIL_RECORD_TAG_PERIOD 2u
#define SIL_RECORD_TAG_END 3u

/** Word order of a period's input (pmstep_meas_t). */
enum {
    SIL_RECORD_IN_I_A = 0, SIL_RECORD_IN_I_B, SIL_RECORD_IN_BUS, SIL_RECORD_IN_LOAD,
    SIL_RECORD_IN_WORDS
};

/** Word order of a period's output (pmstep_output_t); integers and bools as integers. */
enum {
    SIL_RECORD_OUT_U_A = 0, SIL_RECORD_OUT_U_B, SIL_RECORD_OUT_BRIDGE_ENABLE, SIL_RECORD_OUT_VOLTAGE_LIMITED,
    SIL_RECORD_OUT_MODE, SIL_RECORD_OUT_FAULT, SIL_RECORD_OUT_FAULT_STEP,
    SIL_RECORD_OUT_COS_HAT, SIL_RECORD_OUT_SIN_HAT, SIL_RECORD_OUT_SPEED_HAT, SIL_RECORD_OUT_LOAD_HAT,
    SIL_RECORD_OUT_I_A_HAT, SIL_RECORD_OUT_I_B_HAT, SIL_RECORD_OUT_SPEED_REF, SIL_RECORD_OUT_SPEED_REF_DOT,
    SIL_RECORD_OUT_I_D, SIL_RECORD_OUT_I_Q, SIL_RECORD_OUT_I_D_REF, SIL_RECORD_OUT_I_Q_REF,
    SIL_RECORD_OUT_WORDS
};

/**
 * sil_run() that also writes the record described above to @p record (binary
 * stream; NULL records nothing). @return 0, -1 when pmstep_init rejected the
 * configuration, -2 when writing the record failed.
 */
int sil_run_record(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress,
                   sil_summary_t *summary, FILE *record);

#ifdef __cplusplus
}
#endif

#endif /* SIL_RUNNER_H */
