/**
 * @file pmstep_commission.h
 * @brief Remark 2 calibration and self-commissioning from the alignment phases.
 *
 * What the alignments make observable (sample m counts periods from the start of
 * s-alignment; u is the voltage applied over the period that ends at the sample):
 *  - offsets: a phase whose true current is zero (bridge off before s-alignment;
 *    i_a at the end of s-alignment (3) and i_b at the end of c-alignment (5),
 *    where u_a resp. u_b = 0) reads its sensor offset;
 *  - R: the steady states i_b = u_cs/R (end of s-alignment) and i_a = u_cc/R (end
 *    of c-alignment), each over a window of W samples. With the voltage-bias option
 *    the window moves W earlier and the last W run at a fraction f of the voltage;
 *    the last W/2 of those are a second steady state, and per phase
 *      R = (u_1 - u_2)/(i_1 - i_2),   bias = u_1 - R i_1
 *    (the voltage the bridge falls short by at positive current: dead time the
 *    compensation misses, switch drops);
 *  - L: the rise of i_b over N periods early in s-alignment, when the rotor has
 *    hardly moved: L (i_b(m0 + N) - i_b(m0)) = integral of (u_b - R i_b). The window
 *    starts at m0 = 2 + delay, once the current is clear of zero and the dead-time
 *    compensation acts in full. Without that window (N = 0) and with the voltage-bias
 *    option, from each alignment's drop to its lower level instead: the rotor stays at
 *    its equilibrium (the torque keeps its direction), so over the W periods from the last
 *    sample of the full-level window to the end of the alignment
 *      L (i_2 - i_1) = integral of (u - bias - R i)
 *    with i_1, i_2 the two steady states' means and R, bias their fit (the integrand is 0
 *    in both steady states: an error of R weighs only on the decay, L dR/R). Phase b at
 *    the end of s-alignment, phase a (on phase b's sensor scale) at the end of
 *    c-alignment, averaged. The rise needs a rotor that stays put for N periods, which a
 *    hybrid stepper's alignment swing (w_n ~ 1000 rad/s) does not; the drop does not
 *    (where the rotor follows a moving equilibrium down, below, its flux is taken off);
 *  - where the rotor rests: at the direction of the current vector, shifted by the
 *    model's detent torque (Newton steps on the torque balance, configured k_M and T_d),
 *    from each window's mean currents, the undriven phase's included: where the
 *    dead-time compensation exceeds the bridge's dead time, the undriven phase carries
 *    current (0.6 A on a 5 A motor at +10 %) and the rest is 0.2 rad off the phase axis.
 *    RUN starts its angle from c-alignment's rest (pmstep_commissioning_t.equilibrium_*);
 *  - k_M: the flux swing of c-alignment, the rotor turning from its rest at t_s
 *    (sin p theta ~ 1) to its rest at t_c (cos p theta ~ 1). With
 *    x = L i + (k_M/p)(cos p theta, sin p theta) and x' = u - R i (model (1)), over
 *    [t_s, t_c] on the driven phase a:
 *      (k_M/p) (cos p theta_c - cos p theta_s) = integral(u_a - R i_a) - L delta i_a
 *    with phase a's own R, so a current offset cancels, and its voltage bias taken off.
 *    The integral starts at the first sample from t_s at which phase a's current is not
 *    beyond the sign threshold negative: a negative current left in phase a (an
 *    over-compensated undriven phase runs away with its sign: -0.9 A on an AS1050) makes
 *    the bridge apply 2 V_bus t_d / T_s more until it passes zero, a few periods in which
 *    the rotor, at rest and pulled by that small current, has hardly turned. (Phase b's
 *    swing is not used: its current passes through zero, where the dead time makes its
 *    voltage unknown.) With L from the drops, each drop's flux
 *    holds (k_M/p) times the change of its rest's sin (phase b) or cos (phase a) too:
 *    L and k_M are solved together.
 * Currents are integrated by the trapezoid rule, held voltages exactly.
 */
#ifndef PMSTEP_COMMISSION_H
#define PMSTEP_COMMISSION_H

#include "pmstep/pmstep_types.h"
#include "pmstep/pmstep_continuity.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The driven phase's mean currents over a steady-state window's halves may differ by this
 *  fraction of the alignment's full-level current. A rotor at rest or still swinging a little
 *  about its rest: within 1 % in the runs traced; in 1600 Monte Carlo runs (4 presets, 2 chains)
 *  only the 5 that started within 31 deg of s-alignment's unstable equilibrium went beyond 5 %;
 *  one tipping over inside the window: 38 % (17HS4401, R read 51 % high). */
#define PMSTEP_ALIGNMENT_STEADY_TOLERANCE 0.05f
/** Repeats of the alignments after a window that was not steady; then
 *  PMSTEP_FAULT_ALIGNMENT_MOTION latches. The first run leaves the rotor at c-alignment's
 *  equilibrium, a quarter turn from s-alignment's unstable one. */
#define PMSTEP_ALIGNMENT_MAX_REPEATS 1u

/** When each measurement is taken, in samples from the start of s-alignment. */
typedef struct {
    uint32_t s_lead_in_steps;       /**< s-alignment's lead-in: its first samples, driven at p theta = 0 */
    uint32_t s_align_steps;         /**< first sample of c-alignment (t_s) */
    uint32_t c_align_end_step;      /**< sample at t_c */
    uint32_t window_steps;          /**< W: steady-state window at the end of each alignment (0 = none) */
    uint32_t inductance_steps;      /**< N: current-rise window (0 = L from the level drops, with bias_estimation) */
    uint32_t inductance_start_step; /**< m0: first sample of the current-rise window (after the lead-in) */
    bool offsets_from_alignment;    /**< take offsets from the alignment steady states too */
    bool bias_estimation;           /**< second, lower steady state at the end of each alignment */
    uint32_t identification_steps;  /**< RUN periods of the J and F identification window from t_c (0 = none) */
} pmstep_commission_plan_t;

/** An integral of u - R i over consecutive samples of one phase (raw samples): the first sample's
 *  current, then each later sample's current and the voltage over the period that ends at it. */
typedef struct {
    float voltage_sum_V; /**< the voltages of the periods after the first sample */
    float current_sum_A; /**< every sample's current, the first included */
    float start_A;       /**< the first sample's current */
    float end_A;         /**< the last sample's current */
} pmstep_flux_sums_t;

/** Sums over one steady-state window of an alignment (raw samples). The driven phase's means over
 *  its two halves are compared: a steady state has the same in both (see pmstep_commission_finish()). */
typedef struct {
    float current_sum_A;      /**< the driven phase's current */
    float voltage_sum_V;      /**< the driven phase's voltage */
    float undriven_sum_A;     /**< the undriven phase's current */
    float late_current_sum_A; /**< the driven phase's current over the window's second half */
} pmstep_window_sums_t;

/** Running sums of one run of the alignments (raw samples); a repeat of the alignments starts
 *  them afresh. */
typedef struct {
    float zero_sum_a_A, zero_sum_b_A; /**< the undriven phase at the ends of the alignments (true current 0) */
    uint32_t zero_count_a, zero_count_b;
    pmstep_flux_sums_t rise;     /**< L from the current rise, phase b */
    pmstep_window_sums_t s_full; /**< end of s-alignment (phase b driven) */
    pmstep_window_sums_t c_full; /**< end of c-alignment (phase a driven) */
    pmstep_window_sums_t s_low;  /**< lower steady state of s-alignment (bias option) */
    pmstep_window_sums_t c_low;  /**< lower steady state of c-alignment */
    pmstep_flux_sums_t swing;    /**< c-alignment from t_s, phase a: k_M (t_c's sample added at the end) */
    pmstep_flux_sums_t s_drop;   /**< L from s-alignment's level drop, phase b */
    pmstep_flux_sums_t c_drop;   /**< L from c-alignment's level drop, phase a */
    uint32_t swing_start_step;   /**< the swing's first sample (0: not yet) */
} pmstep_alignment_sums_t;

/** Running sums (raw samples; offsets are removed at the end). */
typedef struct {
    float zero_sum_a_A, zero_sum_b_A; /**< bridge off before s-alignment: true currents 0 */
    uint32_t zero_count_a, zero_count_b;
    float zero_voltage_sum_a_V, zero_voltage_sum_b_V; /**< sensed phase voltages with the bridge off (true 0) */
    pmstep_alignment_sums_t alignment;                /**< the alignments' */
    pmstep_continuity_peaks_t continuity;             /**< the driven phases' peaks (pmstep_continuity.h) */
} pmstep_commission_sums_t;

void pmstep_commission_clear(pmstep_commission_sums_t *sums);

/** The bridge-off samples' means into @p result: the current offsets (provisional for the
 *  alignments, refined at t_c with the alignment offsets) and the phase-voltage offsets (final;
 *  0 without sensing). Offsets 0 where no sample was taken. */
void pmstep_commission_take_bridge_off(const pmstep_commission_sums_t *sums, pmstep_commissioning_t *result);

/** A repeat of the alignments (pmstep_commission_finish() found the rotor moving): their sums
 *  start afresh, the bridge-off ones stay; in @p result what the alignment's samples are
 *  calibrated and compensated with (offsets, phase scale, voltage biases) goes back to its value
 *  before the first run, measured to false, and the repeats are counted up (the other values are
 *  the first run's until the repeat's t_c). */
void pmstep_commission_repeat(pmstep_commission_sums_t *sums, pmstep_commissioning_t *result);

/** True from the sample where an alignment ending at sample @p end runs at its lower level. */
bool pmstep_commission_low_level(const pmstep_commission_plan_t *plan, uint32_t sample, uint32_t end);

/** A sample with the bridge off, the motor at rest (true currents and phase voltages zero); the
 *  voltages are the sensed ones (0 without phase-voltage sensing). */
void pmstep_commission_add_bridge_off(pmstep_commission_sums_t *sums, float i_a_A, float i_b_A, float u_a_V,
                                      float u_b_V);

/**
 * Sample @p sample (< c_align_end_step) of the alignment.
 * @param[in,out] sums      the running sums the sample is added to
 * @param[in] plan          when each measurement is taken
 * @param[in] sample        the sample's index, in samples from the start of s-alignment
 * @param[in] i_a_A, i_b_A  currents sampled at the end of the period (raw)
 * @param[in] u_a_V, u_b_V  voltage applied over the period that ends at this sample
 * @param[in] u_a_known     @p u_a_V is the voltage the bridge applied to phase a: sensed, or its
 *                          current not beyond the sign threshold negative (see k_M above)
 */
void pmstep_commission_add_alignment(pmstep_commission_sums_t *sums, const pmstep_commission_plan_t *plan,
                                     uint32_t sample, float i_a_A, float i_b_A, float u_a_V, float u_b_V,
                                     bool u_a_known);

/**
 * At t_c: offsets, R, L and k_M (and the voltage biases) from the sums and the sample
 * i_a at t_c; values not measured are left 0 in @p result. The voltage of phase a over
 * the last period before t_c is @p u_a_V. k_M's flux swing takes the L that RUN will use:
 * the measured one with use_measured_inductance, else the configured one (a rise during which
 * the rotor turns - hybrid steppers - measures back EMF too; the designer then keeps the
 * datasheet's L, and its measurement is only reported).
 * A steady-state window is steady when the driven phase's mean currents over its two halves
 * agree within PMSTEP_ALIGNMENT_STEADY_TOLERANCE of the alignment's full-level current (offset
 * off): a rotor that still moves - an alignment that started it from its unstable
 * equilibrium, where it sits until a small torque tips it over - makes them differ through its
 * back-EMF, and its R, rest and k_M would be wrong.
 * @return PMSTEP_FAULT_NONE; PMSTEP_FAULT_ALIGNMENT_MOTION when a window was not steady; else
 *         PMSTEP_FAULT_COMMISSIONING when R or k_M, or L where RUN takes it, is not finite or
 *         outside [1/2, 2] x the configured one.
 */
pmstep_fault_t pmstep_commission_finish(const pmstep_commission_sums_t *sums, const pmstep_commission_plan_t *plan,
                                        const pmstep_config_t *cfg, float i_a_A, float u_a_V,
                                        pmstep_commissioning_t *result);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_COMMISSION_H */
