/* Gain designer (pmstep_design.h): what it refuses. The datasheet's plausibility
 * (pmstep_design_check_datasheet()) and the input it cannot design for (pmstep_design_check_input()). */
#include "pmstep/pmstep_design.h"

#include "pmstep/pmstep.h"
#include "pmstep_design_internal.h"

#include <math.h> /* sqrtf, isfinite: one FPU instruction / a classification macro, no libm call */
#include <stddef.h>

bool pmstep_design_finite_input(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m = &in->motor;
    return isfinite(m->resistance_Ohm) && isfinite(m->inductance_H) && isfinite(m->inertia_kgm2)
           && isfinite(m->friction_Nms_rad) && isfinite(m->torque_constant_Nm_A) && isfinite(in->motor.rated_current_A)
           && isfinite(in->bus_voltage_V) && isfinite(in->period_s) && isfinite(in->dead_time_s)
           && isfinite(in->current_resolution_A) && isfinite(in->current_sense_range_A)
           && isfinite(in->bus_sense_range_V) && isfinite(m->detent_torque_Nm) && isfinite(in->holding_torque_Nm);
}

/* The datasheet check's bounds (pmstep_design_check_datasheet()). */
#define DATASHEET_KM_RATIO 2.0f
#define DATASHEET_MIN_TIME_CONSTANT_S 1e-4f
#define DATASHEET_MAX_TIME_CONSTANT_S 2e-2f
#define DATASHEET_INERTIA_RATIO 10.0f
/* p L I / k_M, the winding's flux at rated current over the magnet's, is a property of a frame's
 * magnetic design (a rewound winding scales L I^2 and k_M I alike): 0.5-3 in stepper datasheets. */
#define DATASHEET_MIN_FLUX_RATIO 0.1f
#define DATASHEET_MAX_FLUX_RATIO 10.0f

float pmstep_design_inertia_estimate(float holding_torque_Nm)
{
    return PMSTEP_DESIGN_INERTIA_PER_TORQUE * holding_torque_Nm * sqrtf(holding_torque_Nm);
}

pmstep_status_t pmstep_design_check_datasheet(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m;
    float km_ratio;
    float time_constant_s;
    if (in == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    m = &in->motor;
    if (!(in->holding_torque_Nm > 0.0f) || !(m->rated_current_A > 0.0f) || !(m->resistance_Ohm > 0.0f)) {
        return PMSTEP_OK; /* nothing to compare with (the designer's own checks name what is missing) */
    }
    km_ratio = m->torque_constant_Nm_A * 1.41421356f * m->rated_current_A / in->holding_torque_Nm;
    if (!(km_ratio >= 1.0f / DATASHEET_KM_RATIO && km_ratio <= DATASHEET_KM_RATIO)) {
        return PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT;
    }
    time_constant_s = m->inductance_H / m->resistance_Ohm;
    if (!(time_constant_s >= DATASHEET_MIN_TIME_CONSTANT_S && time_constant_s <= DATASHEET_MAX_TIME_CONSTANT_S)) {
        return PMSTEP_ERR_DATASHEET_TIME_CONSTANT;
    }
    {
        const float flux_ratio = (float)m->pole_pairs * m->inductance_H * m->rated_current_A
                                 / (in->holding_torque_Nm / (1.41421356f * m->rated_current_A));
        if (!(flux_ratio >= DATASHEET_MIN_FLUX_RATIO && flux_ratio <= DATASHEET_MAX_FLUX_RATIO)) {
            return PMSTEP_ERR_DATASHEET_FLUX_RATIO;
        }
    }
    if (m->inertia_kgm2 > 0.0f) {
        const float j_ratio = m->inertia_kgm2 / pmstep_design_inertia_estimate(in->holding_torque_Nm);
        if (!(j_ratio >= 1.0f / DATASHEET_INERTIA_RATIO && j_ratio <= DATASHEET_INERTIA_RATIO)) {
            return PMSTEP_ERR_DATASHEET_INERTIA;
        }
    }
    return PMSTEP_OK;
}

float pmstep_design_alignment_current(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float condition_limit_A = m->torque_constant_Nm_A / ((float)m->pole_pairs * m->inductance_H);
    const float detent_A =
        DETENT_BARRIER_MARGIN * m->detent_torque_Nm / (DETENT_BARRIER_RATIO * m->torque_constant_Nm_A);
    return min2(in->motor.rated_current_A, max2(CONDITION_4_FRACTION * condition_limit_A,
                                                min2(detent_A, MAX_CONDITION_4_FRACTION * condition_limit_A)));
}

/* The motor's own data: each constant of its model in range. */
static pmstep_status_t check_motor(const pmstep_motor_config_t *m)
{
    if (!(m->resistance_Ohm > 0.0f)) {
        return PMSTEP_ERR_RESISTANCE;
    }
    if (!(m->inductance_H > 0.0f)) {
        return PMSTEP_ERR_INDUCTANCE;
    }
    if (!(m->inertia_kgm2 > 0.0f)) {
        return PMSTEP_ERR_INERTIA;
    }
    if (!(m->torque_constant_Nm_A > 0.0f)) {
        return PMSTEP_ERR_TORQUE_CONSTANT;
    }
    if (!(m->friction_Nms_rad >= 0.0f)) {
        return PMSTEP_ERR_FRICTION;
    }
    if (m->pole_pairs < 1) {
        return PMSTEP_ERR_POLE_PAIRS;
    }
    if (!(m->rated_current_A > 0.0f)) {
        return PMSTEP_ERR_RATED_CURRENT;
    }
    return PMSTEP_OK;
}

/* The drive's: its period and delay, its bus and sensing against the motor's rated current, its
 * dead time. */
static pmstep_status_t check_drive(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m = &in->motor;
    if (!(in->period_s >= PMSTEP_MIN_PERIOD_S && in->period_s <= PMSTEP_MAX_PERIOD_S)) {
        return PMSTEP_ERR_PERIOD;
    }
    if (in->computational_delay_periods > 1u) {
        return PMSTEP_ERR_DELAY;
    }
    if (!(in->bus_voltage_V > 0.0f)
        || !(m->resistance_Ohm * in->motor.rated_current_A < USABLE_BUS_FRACTION * in->bus_voltage_V)) {
        return PMSTEP_ERR_BUS_BELOW_RATED;
    }
    if (!(in->current_sense_range_A > 0.0f) || !(in->bus_sense_range_V > 0.0f)) {
        return PMSTEP_ERR_SENSE_RANGE;
    }
    if (PMSTEP_SENSE_RANGE_USABLE_FRACTION * in->current_sense_range_A
        < MIN_TRIP_CURRENT_PER_RATED * in->motor.rated_current_A) {
        return PMSTEP_ERR_SENSE_RANGE_BELOW_RATED;
    }
    if (PMSTEP_SENSE_RANGE_USABLE_FRACTION * in->bus_sense_range_V < MIN_MAX_BUS_FRACTION * in->bus_voltage_V) {
        return PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE;
    }
    if (!(in->dead_time_s >= 0.0f && 4.0f * in->dead_time_s < in->period_s)) {
        return PMSTEP_ERR_DEAD_TIME;
    }
    return PMSTEP_OK;
}

pmstep_status_t pmstep_design_check_input(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m = &in->motor;
    pmstep_status_t status;
    if (!pmstep_design_finite_input(in)) {
        return PMSTEP_ERR_NONFINITE_PARAMETER;
    }
    status = check_motor(m);
    if (status == PMSTEP_OK) {
        status = check_drive(in);
    }
    if (status != PMSTEP_OK) {
        return status;
    }
    /* The current loop's and the observer's poles lie beyond the winding's own R/L and the
     * mechanics' F/J (K_i, K_e > 0); where R/L or F/J passes the bandwidths the control rate gives
     * them, those are raised to WINDING_RATE_MARGIN times it (current_bandwidth(),
     * observer_bandwidth()), up to what the discretisation takes: (R/L + F/J) T_s at most
     * MAX_WINDING_RATE_X_PERIOD (docs/design/03-observer.md). */
    if (!((m->resistance_Ohm / m->inductance_H + m->friction_Nms_rad / m->inertia_kgm2) * in->period_s
          <= MAX_WINDING_RATE_X_PERIOD)) {
        return PMSTEP_ERR_RATE_TOO_SLOW;
    }
    /* c-alignment turns the rotor a full step; a detent the current it may use cannot pull the rotor
     * across would leave it a full step off the equilibrium the angle starts from. */
    if (!(DETENT_BARRIER_RATIO * m->torque_constant_Nm_A * pmstep_design_alignment_current(in) > m->detent_torque_Nm)) {
        return PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT;
    }
    return PMSTEP_OK;
}
