/**
 * @file pmstep_actuate.h
 * @brief Actuation stage: dead-time compensation, the bus limit, the output check and the
 *        bookkeeping of the computational delay.
 *
 *  - Each half-bridge loses sign(i) V_bus t_d / T_s to its dead time, so a phase (two
 *    half-bridges) is given (2 V_bus t_d / T_s + bias) sign(i) more, linear in i within
 *    +/- the current band (bias: what commissioning measured, Remark 2).
 *  - The command (u_a, u_b) is scaled, keeping its direction, so neither H-bridge exceeds the
 *    bus measured this period; the scaled components are clamped to +/- the bus so rounding
 *    cannot leave one a unit in the last place above it.
 *  - A command that is not finite is refused: the caller latches STATE_NONFINITE, so the
 *    bridge is never enabled with such a voltage.
 *  - The voltage the bridge applies over the coming period, its dead-time loss taken off,
 *    is what phi1, phi2 and the observer integrate: this period's command (no delay), or
 *    the previous period's (one period of delay).
 */
#ifndef PMSTEP_ACTUATE_H
#define PMSTEP_ACTUATE_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Voltages of the delay line. */
typedef struct {
    float u_applied_a_V; /**< voltage applied over the period that ends at the next sample */
    float u_applied_b_V;
    float u_pending_a_V; /**< computed, waiting one period (delay = 1) */
    float u_pending_b_V;
    float compensation_applied_a_V; /**< dead-time compensation within u_applied + it (same period) */
    float compensation_applied_b_V;
    float compensation_pending_a_V; /**< the compensation within u_pending */
    float compensation_pending_b_V;
} pmstep_actuator_t;

/** Constants derived from the configuration. */
typedef struct {
    float dead_time_duty;         /**< 2 t_d / T_s: compensation at full current, fraction of the bus */
    float inv_band_per_A;         /**< 1 / dead_time_current_band_A (0 without compensation) */
    float sign_threshold_A_per_V; /**< a current's sign is known beyond this x V_bus + sign_threshold_A */
    float sign_threshold_A;
    bool compensate; /**< dead time configured or voltage bias estimated */
    bool sensed;     /**< the phase voltages are sensed: the period's voltage is measured, not estimated */
    bool delayed;    /**< one period of computational delay */
} pmstep_actuate_coeffs_t;

/** Coefficients for @p cfg (already validated). */
void pmstep_actuate_coeffs_init(pmstep_actuate_coeffs_t *coeffs, const pmstep_config_t *cfg);

/** Zero volts applied and pending. */
void pmstep_actuate_reset(pmstep_actuator_t *actuator);

/** Signs of the phase currents and the voltage biases the compensation works from. */
typedef struct {
    float sign_current_a_A, sign_current_b_A; /**< current whose sign (and size within the band) is used */
    float bias_a_V, bias_b_V;                 /**< measured voltage biases (Remark 2), 0 if none */
} pmstep_compensation_input_t;

/**
 * Compensates, limits and checks the command in @p out (u_a_V, u_b_V on entry), sets
 * voltage_limited, and advances the delay line.
 * @param[in,out] actuator   the delay line, advanced by one period on success
 * @param[in] coeffs         from pmstep_actuate_coeffs_init()
 * @param[in] compensation   read only when coeffs->compensate
 * @param[in] bus_voltage_V  the bus measured this period (finite, > 0)
 * @param[in,out] out        the command (u_a_V, u_b_V) on entry; the voltages to apply and
 *                           voltage_limited on return
 * @retval true   @p out holds the finite command to apply, |u| <= bus on each phase
 * @retval false  the command is not finite; the voltages were not advanced (latch a fault; the
 *               compensation's line may have been, and is cleared before the bridge is on again)
 */
bool pmstep_actuate(pmstep_actuator_t *actuator, const pmstep_actuate_coeffs_t *coeffs,
                    const pmstep_compensation_input_t *compensation, float bus_voltage_V, pmstep_output_t *out);

/**
 * One phase's mean dead-time loss over a period, as the current to hand the compensation
 * (pmstep_compensation_input_t): the share of the full loss times @p band_A. Over the period
 * the phase current moves through [i - s, i + s], s = max(@p sweep_A, @p band_A) (the band:
 * the sample noise). Each leg loses at the edge where it turns on against the current and gains
 * at the one where it turns off, and the legs' centred windows put those edges at the PWM
 * ripple's extremes: the loss is sign(i) where the current keeps its sign through the ripple
 * (|i| > h) and 0 where the ripple straddles zero. h = V_bus d (1 - d) T_s / (4 L) at duty
 * d = |u| / V_bus: two pulses of d T_s / 2 at (V_bus - u) / L.
 * @param coeffs  from pmstep_actuate_coeffs_init() (its T_s / (16 L) sets h)
 * @param band_A  the compensation's band (> 0); @param bus_voltage_V  > 0
 * @param current_A  the phase's reference current i over the period
 * @param sweep_A  how far the phase current moves about @p current_A over the period
 * @param u_V  the phase's command; 0 for a bridge without ripple (h = 0)
 * @return within [-band_A, band_A]
 */
float pmstep_actuate_mean_loss_current(const pmstep_actuate_coeffs_t *coeffs, float band_A, float current_A,
                                       float sweep_A, float u_V, float bus_voltage_V);

/** The currents sampled at the two ends of a period, and the voltage biases (Remark 2). */
typedef struct {
    float i_start_a_A, i_start_b_A; /**< at the period's start */
    float i_end_a_A, i_end_b_A;     /**< at its end */
    float bias_a_V, bias_b_V;       /**< measured voltage biases, 0 if none */
} pmstep_period_currents_t;

/**
 * The voltage the bridge applied over the period that has just ended, for the flux integrals.
 * Where a phase current was beyond the sign threshold, with one sign, at both ends of the period,
 * it kept that sign at every switching edge, so the bridge lost (2 V_bus t_d / T + bias) sign(i)
 * whatever the compensation assumed: the command less that loss. Elsewhere (near or through
 * zero, or a command within the dead time of the bus, where a leg hardly switches) the loss is
 * unknown and the compensation's own assumption stands: u_applied.
 * Sign threshold: the PWM ripple's largest half amplitude, V_bus T / (16 L) at d = 1/2 (the
 * edges sit at the ripple's extremes), plus three compensation bands (the sample noise).
 */
void pmstep_actuate_voltage_over_period(const pmstep_actuator_t *actuator, const pmstep_actuate_coeffs_t *coeffs,
                                        const pmstep_period_currents_t *currents, float bus_voltage_V, float *u_a_V,
                                        float *u_b_V);

/** The sign threshold above (A) at the bus voltage @p bus_voltage_V. */
float pmstep_actuate_sign_threshold(const pmstep_actuate_coeffs_t *coeffs, float bus_voltage_V);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_ACTUATE_H */
