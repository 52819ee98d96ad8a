/**
 * @file pmstep_continuity.h
 * @brief Continuity of the windings and their current measurement: a phase that carries no
 *        current where its voltage or its reference says it must (an open winding or
 *        connector, a current sensor that reads nothing), or whose reading does not move while
 *        its reference does (a stuck sensor). Always on, whatever the detection settings: the
 *        flux integrals and the observer are fed the voltage the core applies, so with an open
 *        phase they follow their own command and nothing else in the core can tell.
 *
 * Alignments: the driven phase's largest |i| since the alignments began (phase a in the
 * lead-in and c-alignment, phase b in s-alignment), compared at the end of its alignment (b at
 * t_s, a at t_c) with PMSTEP_CONTINUITY_FRACTION of the current its voltage drives through the
 * configured R, u/R: the winding settles at its u/R by then (the designer's alignment times),
 * whatever the rotor's swing did on the way. Latency: t_s for phase b, t_c for phase a.
 *
 * RUN: every PMSTEP_CONTINUITY_DECIMATION periods each phase's reading and its reference (the
 * law's (i_d*, i_q*) turned to the stator by the estimate, which is the frame the current loop
 * tracks it in; a vector hold's own current vector) go into a window's sums of x and x^2; checks
 * in which the bus limited the voltage stay out (there the current cannot follow). A window
 * lasts PMSTEP_CONTINUITY_WINDOW_TIME_CONSTANTS of the current loop, 1/(R/L + K_i) (at least 4
 * checks). At its end, for each phase (f = PMSTEP_CONTINUITY_FRACTION, I_min =
 * PMSTEP_CONTINUITY_MIN_CURRENT_PER_SENSE_RANGE of the current sensing's range):
 *   missing: rms(reading) < f rms(reference), where rms(reference) >= I_min;
 *   stuck:   the reading's variance about its mean < f^2 the reference's, where the reference's
 *            standard deviation >= I_min (the reference moves, the reading does not).
 * Two windows that found the condition, with none between them that found the phase following
 * (a window whose reference asked for less than I_min tells nothing and counts neither way),
 * latch PMSTEP_FAULT_OPEN_PHASE_A/B or PMSTEP_FAULT_CURRENT_STUCK_A/B: latency two to three
 * windows while the reference asks for current. With both sensors lost the law's reference can
 * fall below I_min (T_L-hat goes to 0: the currents the observer sees explain no load); the
 * next acceleration asks again. A healthy phase follows
 * within a few time constants, at its sensor's gain (an error of 50 % reads half), with its
 * noise on top: both ratios stay near its gain.
 * A sensor saturated at its end reads beyond the trip (the limits' validation keeps the trip
 * within the sensing range): PMSTEP_FAULT_OVERCURRENT at the first sample.
 */
#ifndef PMSTEP_CONTINUITY_H
#define PMSTEP_CONTINUITY_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** RUN checks every this many periods (the samples of a window spread over the waveform; the
 *  detection's checks fall on other periods). */
#define PMSTEP_CONTINUITY_DECIMATION 8u
/** A phase passes when its reading reaches this fraction of what its voltage or reference asks. */
#define PMSTEP_CONTINUITY_FRACTION 0.25f
/** RUN judges a phase only where its reference reaches this fraction of the current sensing's
 *  range: some 20 codes of a 12-bit ADC, far above a healthy sensor's noise, which is what a
 *  missing current reads. */
#define PMSTEP_CONTINUITY_MIN_CURRENT_PER_SENSE_RANGE 0.01f
/** A RUN window lasts this many time constants of the current loop, 1/(R/L + K_i). */
#define PMSTEP_CONTINUITY_WINDOW_TIME_CONSTANTS 10.0f
/** Windows a condition must be found in (pmstep_continuity_judge()) before its fault latches. */
#define PMSTEP_CONTINUITY_WINDOWS 2u

/** One phase's sums over a RUN window. */
typedef struct {
    float read_sum_A, read_square_sum_A2; /**< the reading's x and x^2 */
    float ref_sum_A, ref_square_sum_A2;   /**< the reference's */
} pmstep_continuity_sums_t;

/** State of RUN's windows (in RUN's scratch). */
typedef struct {
    pmstep_continuity_sums_t a;
    pmstep_continuity_sums_t b;
    uint16_t window_checks;    /**< checks summed in the present window */
    uint8_t missing_windows_a; /**< windows in a row phase a carried no current */
    uint8_t missing_windows_b;
    uint8_t stuck_windows_a; /**< windows in a row its reading did not move */
    uint8_t stuck_windows_b;
} pmstep_continuity_t;

/** The alignments' peaks (in the alignments' scratch). */
typedef struct {
    float peak_a_A; /**< largest |i_a| while phase a was driven in the alignments */
    float peak_b_A; /**< largest |i_b| while phase b was driven */
} pmstep_continuity_peaks_t;

/** Derived from the configuration. */
typedef struct {
    uint32_t window_checks; /**< checks a RUN window lasts */
} pmstep_continuity_coeffs_t;

/** Coefficients for @p cfg (already validated). */
void pmstep_continuity_coeffs_init(pmstep_continuity_coeffs_t *coeffs, const pmstep_config_t *cfg);

/** A fresh RUN window, nothing persisted. */
void pmstep_continuity_start(pmstep_continuity_t *state);

/**
 * One alignment period: the driven phase's peak, then at the end of s-alignment phase b's check
 * and at the end of c-alignment phase a's.
 * @param[in,out] peaks          the driven phases' peaks so far
 * @param[in] cfg                the configuration: alignment voltages / R set the peak a connected winding reaches
 * @param[in] a_driven           phase a is the driven one (s-alignment's lead-in, c-alignment), else b
 * @param[in] i_a_A, i_b_A       this period's samples (offset-corrected)
 * @param[in] last_s_period      this is the last period of s-alignment
 * @param[in] last_c_period      this is the last period of c-alignment
 * @return PMSTEP_FAULT_OPEN_PHASE_A/B, or PMSTEP_FAULT_NONE.
 */
pmstep_fault_t pmstep_continuity_align(pmstep_continuity_peaks_t *peaks, const pmstep_config_t *cfg, bool a_driven,
                                       float i_a_A, float i_b_A, bool last_s_period, bool last_c_period);

/** One phase's check into its window's sums. */
static inline void pmstep_continuity_add(pmstep_continuity_sums_t *sums, float ref_A, float i_A)
{
    sums->read_sum_A += i_A;
    sums->read_square_sum_A2 += i_A * i_A;
    sums->ref_sum_A += ref_A;
    sums->ref_square_sum_A2 += ref_A * ref_A;
}

/**
 * One RUN check (every PMSTEP_CONTINUITY_DECIMATION periods, not in one the bus limited): the
 * phase currents the control asks for (stator frame), @p ref_a_A and @p ref_b_A, and this
 * period's samples (offset-corrected) into the window. @return true when the window is full:
 * then pmstep_continuity_judge().
 */
static inline bool pmstep_continuity_check(pmstep_continuity_t *state, const pmstep_continuity_coeffs_t *coeffs,
                                           float ref_a_A, float ref_b_A, float i_a_A, float i_b_A)
{
    pmstep_continuity_add(&state->a, ref_a_A, i_a_A);
    pmstep_continuity_add(&state->b, ref_b_A, i_b_A);
    state->window_checks++;
    return state->window_checks >= coeffs->window_checks;
}

/**
 * A full window's verdict; the next window starts.
 * @return PMSTEP_FAULT_OPEN_PHASE_A/B, PMSTEP_FAULT_CURRENT_STUCK_A/B once a condition has held
 *         PMSTEP_CONTINUITY_WINDOWS windows in a row, or PMSTEP_FAULT_NONE.
 */
pmstep_fault_t pmstep_continuity_judge(pmstep_continuity_t *state, const pmstep_config_t *cfg);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_CONTINUITY_H */
