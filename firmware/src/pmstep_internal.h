/* Private to the core's sources: helpers shared between its modules, not part of the API. */
#ifndef PMSTEP_INTERNAL_H
#define PMSTEP_INTERNAL_H

#include "pmstep/pmstep.h"

#include <math.h>

/* |x|: fabsf compiles to one instruction (vabs.f32, andps), never a libm call. */
static inline float pmstep_abs(float x)
{
    return fabsf(x);
}

/* x limited to [-bound, bound] (bound >= 0); NaN passes through. One compare on the common path. */
static inline float pmstep_limit(float x, float bound)
{
    if (pmstep_abs(x) > bound) {
        return (x > 0.0f) ? bound : -bound;
    }
    return x;
}

/* x - x is 0 for every finite x and NaN for NaN and +/-Inf, so one compare checks a sum of
 * such differences (cheaper than one isfinite per value on the FPU). */
static inline bool pmstep_all_finite4(float a, float b, float c, float d)
{
    return ((a - a) + (b - b)) + ((c - c) + (d - d)) == 0.0f;
}

/* The same for six values, in one compare. */
static inline bool pmstep_all_finite6(float a, float b, float c, float d, float e, float f)
{
    return (((a - a) + (b - b)) + ((c - c) + (d - d))) + ((e - e) + (f - f)) == 0.0f;
}

/* With phase-voltage sensing: the sensed mean voltages of the period that ends at @p meas, their
 * bridge-off offsets taken off. */
static inline void pmstep_sensed_voltages(const pmstep_t *inst, const pmstep_meas_t *meas, float *u_a_V, float *u_b_V)
{
    *u_a_V = meas->phase_voltage_a_V - inst->commissioning.phase_voltage_offset_a_V;
    *u_b_V = meas->phase_voltage_b_V - inst->commissioning.phase_voltage_offset_b_V;
}

/* Whole periods in @p duration_s, rounded; defined for the durations validation accepts
 * (at most PMSTEP_MAX_DURATION_PERIODS periods). */
static inline uint32_t pmstep_periods_in(float duration_s, float period_s)
{
    return (uint32_t)(duration_s / period_s + 0.5f);
}

/* The rules of every setting, without the derivation (pmstep_config.c): pmstep_validate_config()
 * less its check of the derived coefficients. */
pmstep_status_t pmstep_check_settings(const pmstep_config_t *cfg);

/* Everything init derives from @p cfg, a configuration pmstep_check_settings() accepts
 * (pmstep_derive.c). */
void pmstep_derive(pmstep_derived_t *derived, const pmstep_config_t *cfg);

/* True if every coefficient of @p derived is finite in float32 (pmstep_derive.c). */
bool pmstep_derived_finite(const pmstep_derived_t *derived);

/* Coefficients of the angle, observer and law for the model @p model (pmstep_derive.c). */
void pmstep_apply_model(pmstep_derived_t *derived, const pmstep_config_t *cfg, const pmstep_electrical_t *model);

/* Clears the dynamic state of the strategy; keeps commands (targets) untouched (pmstep_lifecycle.c). */
void pmstep_clear_dynamic_state(pmstep_t *inst);

/* ---- Controller (6) / (13) in RUN (pmstep_control.c) ---- */

/* What the control stage hands to the advance stage within one period. */
typedef struct {
    pmstep_observer_input_t observer_input;
    pmstep_observer_mech_rates_t mech_rates;
} pmstep_control_scratch_t;

/* Control stage: at t_c starts controller (6) (phi = 0, i-hat = i(t_c), w-hat = T_L-hat = 0,
 * references from 0), else integrates phi over the period that ended; then the law's
 * voltage (unlimited) and every telemetry field of @p out. @p sample: offset-corrected. */
void pmstep_control_compute(pmstep_t *inst, const pmstep_meas_t *sample, pmstep_output_t *out,
                            pmstep_control_scratch_t *scratch);

/* Advance stage: the drift-free correction, the observer over the coming period with the
 * voltage the bridge applies (inst->actuator), the reference filters.
 * @return PMSTEP_FAULT_STATE_NONFINITE if an internal estimate is no longer finite, else NONE. */
pmstep_fault_t pmstep_control_advance(pmstep_t *inst, const pmstep_control_scratch_t *scratch,
                                      const pmstep_meas_t *meas, const pmstep_output_t *out);

/* Vector hold (pmstep_hold.c), in place of the law's voltage: the vector turned back by the
 * damping, the PI current loop's errors in its frame into @p obs_in, the voltage into @p out. */
void pmstep_hold_voltages(pmstep_t *inst, pmstep_observer_input_t *obs_in, pmstep_output_t *out);

/* The vector hold's parts the standstill (pmstep_standstill.c) builds on (pmstep_hold.c). */
/* Where a vector is aimed: its direction and the cosine of its load angle delta. */
typedef struct {
    float cos_vector;
    float sin_vector;
    float cos_delta;
} pmstep_hold_aim_t;
/* A time in periods as a count, the longest for NaN or anything outside [0, 1e6). */
uint32_t pmstep_hold_period_count(float periods);
/* sqrt(p k_M I cos(delta) / J), the held rotor's natural frequency (rad/s), the commissioned model's. */
float pmstep_hold_natural_rad_s(const pmstep_law_coeffs_t *law, float current_A, float cos_delta);
/* The vector aimed ahead of the rotor at (c, s) by the load angle of load_Nm + k_M extra_A less
 * the detent torque; false, @p aim untouched, beyond PMSTEP_HOLD_MAX_TORQUE_FRACTION. */
bool pmstep_hold_aim_ahead(const pmstep_law_coeffs_t *law, float c, float s, float current_A, float load_Nm,
                           float extra_A, const pmstep_detent_t *detent, pmstep_hold_aim_t *aim);
/* pmstep_hold_vector's, with the damping term kept whatever the observer's phase where
 * @p always_damped (the standstill's). */
pmstep_status_t pmstep_hold_engage(pmstep_t *inst, float cos_rest, float sin_rest, float current_A, float load_Nm,
                                   bool always_damped);

/* Standstill hold in speed mode (pmstep_hold.h, pmstep_standstill.c): armed at RUN's start, run after each period; a
 * speed command's part (ends a hold, except the standstill's for a zero command; re-arms it). */
void pmstep_standstill_start(pmstep_t *inst);
void pmstep_standstill_advance(pmstep_t *inst, const pmstep_output_t *out);
/* Where the standstill keeps its estimate (pmstep_t.estimate_kept): the period's
 * (cos_hat, sin_hat) from the integrals replaced by the kept rotor (the motion sum reads the
 * integrals again in pmstep_standstill_advance). */
void pmstep_standstill_estimate(const pmstep_t *inst, float *cos_hat, float *sin_hat);
void pmstep_standstill_command(pmstep_t *inst, float target_rad_s);

#endif /* PMSTEP_INTERNAL_H */
