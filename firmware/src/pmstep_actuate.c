/* Actuation: dead-time compensation, bus limit, output check, computational delay (pmstep_actuate.h). */
#include "pmstep/pmstep_actuate.h"

#include "pmstep_internal.h"

void pmstep_actuate_coeffs_init(pmstep_actuate_coeffs_t *coeffs, const pmstep_config_t *cfg)
{
    coeffs->compensate = cfg->inverter.dead_time_s > 0.0f || cfg->commissioning.voltage_bias_level_fraction > 0.0f;
    coeffs->delayed = cfg->timing.computational_delay_periods != 0u;
    coeffs->sensed = cfg->inverter.phase_voltage_sensing;
    coeffs->dead_time_duty = 2.0f * cfg->inverter.dead_time_s / cfg->timing.period_s;
    coeffs->inv_band_per_A = coeffs->compensate ? 1.0f / cfg->inverter.dead_time_current_band_A : 0.0f;
    /* PWM ripple's half amplitude at its largest (d = 1/2): V_bus T / (16 L), plus 3 bands (noise). */
    coeffs->sign_threshold_A_per_V = cfg->timing.period_s / (16.0f * cfg->motor.inductance_H);
    coeffs->sign_threshold_A = 3.0f * cfg->inverter.dead_time_current_band_A;
}

void pmstep_actuate_reset(pmstep_actuator_t *actuator)
{
    actuator->u_applied_a_V = 0.0f;
    actuator->u_applied_b_V = 0.0f;
    actuator->u_pending_a_V = 0.0f;
    actuator->u_pending_b_V = 0.0f;
    actuator->compensation_applied_a_V = 0.0f;
    actuator->compensation_applied_b_V = 0.0f;
    actuator->compensation_pending_a_V = 0.0f;
    actuator->compensation_pending_b_V = 0.0f;
}

/* (2 V_bus t_d / T_s + bias) sign(i), linear in i within the band. */
static float dead_time_voltage(const pmstep_actuate_coeffs_t *coeffs, float current_A, float bus_voltage_V,
                               float bias_V)
{
    const float share = pmstep_limit(current_A * coeffs->inv_band_per_A, 1.0f);
    return (coeffs->dead_time_duty * bus_voltage_V + bias_V) * share;
}

float pmstep_actuate_mean_loss_current(const pmstep_actuate_coeffs_t *coeffs, float band_A, float current_A,
                                       float sweep_A, float u_V, float bus_voltage_V)
{
    const float range_A = sweep_A > band_A ? sweep_A : band_A;
    const float duty = pmstep_abs(u_V) / bus_voltage_V;
    /* h = V_bus d (1 - d) T_s / (4 L); T_s / (4 L) is 4 x sign_threshold_A_per_V, T_s / (16 L).
     * A command beyond the bus (d > 1, limited later) gives h < 0: the share stays within +-1. */
    const float ripple_A = 4.0f * coeffs->sign_threshold_A_per_V * pmstep_abs(u_V) * (1.0f - duty);
    /* the parts of the range beyond +h and below -h, each less half the range */
    const float above_A = pmstep_limit(current_A - ripple_A, range_A);
    const float below_A = pmstep_limit(-current_A - ripple_A, range_A);
    return (above_A - below_A) * band_A / (2.0f * range_A);
}

/* Scales (u_a, u_b) so neither H-bridge exceeds the bus; keeps the vector's direction. */
static bool limit_to_bus(float *u_a_V, float *u_b_V, float bus_voltage_V)
{
    const float largest = pmstep_abs(*u_a_V) > pmstep_abs(*u_b_V) ? pmstep_abs(*u_a_V) : pmstep_abs(*u_b_V);
    if (largest > bus_voltage_V) {
        const float scale = bus_voltage_V / largest;
        *u_a_V = pmstep_limit(*u_a_V * scale, bus_voltage_V);
        *u_b_V = pmstep_limit(*u_b_V * scale, bus_voltage_V);
        return true;
    }
    return false;
}

bool pmstep_actuate(pmstep_actuator_t *actuator, const pmstep_actuate_coeffs_t *coeffs,
                    const pmstep_compensation_input_t *compensation, float bus_voltage_V, pmstep_output_t *out)
{
    float dead_time_a_V = 0.0f;
    float dead_time_b_V = 0.0f;
    float next_a_V;
    float next_b_V;
    if (coeffs->compensate) {
        dead_time_a_V =
            dead_time_voltage(coeffs, compensation->sign_current_a_A, bus_voltage_V, compensation->bias_a_V);
        dead_time_b_V =
            dead_time_voltage(coeffs, compensation->sign_current_b_A, bus_voltage_V, compensation->bias_b_V);
        /* The compensation goes down the delay line beside its voltage (a non-finite one latches
         * a fault, and the line is cleared before the bridge is on again). */
        if (!coeffs->delayed) {
            actuator->compensation_pending_a_V = dead_time_a_V;
            actuator->compensation_pending_b_V = dead_time_b_V;
        }
        actuator->compensation_applied_a_V = actuator->compensation_pending_a_V;
        actuator->compensation_applied_b_V = actuator->compensation_pending_b_V;
        actuator->compensation_pending_a_V = dead_time_a_V;
        actuator->compensation_pending_b_V = dead_time_b_V;
    }
    out->u_a_V += dead_time_a_V;
    out->u_b_V += dead_time_b_V;
    out->voltage_limited = limit_to_bus(&out->u_a_V, &out->u_b_V, bus_voltage_V);
    if (!pmstep_all_finite4(out->u_a_V, out->u_b_V, dead_time_a_V, dead_time_b_V)) {
        return false;
    }
    /* The voltage the bridge applies over the coming period (its dead-time loss taken off). */
    if (coeffs->delayed) {
        next_a_V = actuator->u_pending_a_V;
        next_b_V = actuator->u_pending_b_V;
        actuator->u_pending_a_V = out->u_a_V - dead_time_a_V;
        actuator->u_pending_b_V = out->u_b_V - dead_time_b_V;
    } else {
        next_a_V = out->u_a_V - dead_time_a_V;
        next_b_V = out->u_b_V - dead_time_b_V;
    }
    actuator->u_applied_a_V = next_a_V;
    actuator->u_applied_b_V = next_b_V;
    return true;
}

/* +1 or -1 where the current was beyond the threshold, of one sign, at both ends of the period
 * (it kept that sign at every edge), else 0 (unknown: near or through zero). */
static float certain_sign(float i_start_A, float i_end_A, float threshold_A)
{
    if (i_start_A > threshold_A && i_end_A > threshold_A) {
        return 1.0f;
    }
    if (i_start_A < -threshold_A && i_end_A < -threshold_A) {
        return -1.0f;
    }
    return 0.0f;
}

/* One phase: the command less the loss of the known sign, or u_applied where it is unknown or
 * where the command came within the dead time of the bus (a leg that hardly switches loses less). */
static float phase_voltage_over_period(float applied_V, float compensation_V, float loss_full_V, float sign,
                                       float switching_limit_V)
{
    const float command_V = applied_V + compensation_V;
    if (sign == 0.0f || pmstep_abs(command_V) >= switching_limit_V) {
        return applied_V;
    }
    return command_V - loss_full_V * sign;
}

float pmstep_actuate_sign_threshold(const pmstep_actuate_coeffs_t *coeffs, float bus_voltage_V)
{
    return (coeffs->sign_threshold_A_per_V * bus_voltage_V) + coeffs->sign_threshold_A;
}

void pmstep_actuate_voltage_over_period(const pmstep_actuator_t *actuator, const pmstep_actuate_coeffs_t *coeffs,
                                        const pmstep_period_currents_t *currents, float bus_voltage_V, float *u_a_V,
                                        float *u_b_V)
{
    const float threshold_A = pmstep_actuate_sign_threshold(coeffs, bus_voltage_V);
    const float dead_V = coeffs->dead_time_duty * bus_voltage_V;
    const float switching_limit_V = bus_voltage_V - dead_V;
    *u_a_V = phase_voltage_over_period(
        actuator->u_applied_a_V, actuator->compensation_applied_a_V, dead_V + currents->bias_a_V,
        certain_sign(currents->i_start_a_A, currents->i_end_a_A, threshold_A), switching_limit_V);
    *u_b_V = phase_voltage_over_period(
        actuator->u_applied_b_V, actuator->compensation_applied_b_V, dead_V + currents->bias_b_V,
        certain_sign(currents->i_start_b_A, currents->i_end_b_A, threshold_A), switching_limit_V);
}
