/* Continuity of the windings and their current measurement (pmstep_continuity.h). */
#include "pmstep/pmstep_continuity.h"

#include "pmstep_internal.h"

#include <string.h>

/* The longest RUN window, in checks: its count fits the state's uint16_t. */
#define MAX_WINDOW_CHECKS 65535.0f

void pmstep_continuity_coeffs_init(pmstep_continuity_coeffs_t *coeffs, const pmstep_config_t *cfg)
{
    const float check_period_s = (float)PMSTEP_CONTINUITY_DECIMATION * cfg->timing.period_s;
    const float loop_per_s = (cfg->motor.resistance_Ohm / cfg->motor.inductance_H) + cfg->gains.current_gain_per_s;
    float checks = PMSTEP_CONTINUITY_WINDOW_TIME_CONSTANTS / (loop_per_s * check_period_s);
    if (checks > MAX_WINDOW_CHECKS) {
        checks = MAX_WINDOW_CHECKS;
    } else if (checks < 4.0f) {
        checks = 4.0f;
    } else {
        /* within range */
    }
    coeffs->window_checks = (uint32_t)(checks + 0.5f);
}

void pmstep_continuity_start(pmstep_continuity_t *state)
{
    memset(state, 0, sizeof *state);
}

pmstep_fault_t pmstep_continuity_align(pmstep_continuity_peaks_t *peaks, const pmstep_config_t *cfg, bool a_driven,
                                       float i_a_A, float i_b_A, bool last_s_period, bool last_c_period)
{
    const float per_R = PMSTEP_CONTINUITY_FRACTION / cfg->motor.resistance_Ohm;
    if (a_driven) {
        const float i_A = pmstep_abs(i_a_A);
        peaks->peak_a_A = i_A > peaks->peak_a_A ? i_A : peaks->peak_a_A;
    } else {
        const float i_A = pmstep_abs(i_b_A);
        peaks->peak_b_A = i_A > peaks->peak_b_A ? i_A : peaks->peak_b_A;
    }
    if (last_s_period && (peaks->peak_b_A < (per_R * cfg->alignment.s_align_voltage_V))) {
        return PMSTEP_FAULT_OPEN_PHASE_B;
    }
    if (last_c_period && (peaks->peak_a_A < (per_R * cfg->alignment.c_align_voltage_V))) {
        return PMSTEP_FAULT_OPEN_PHASE_A;
    }
    return PMSTEP_FAULT_NONE;
}

/* A window's verdict on one phase into its counts of failed windows: a window whose reference
 * asked for too little to tell leaves them, one that tells the phase follows clears them.
 * @p min_square_sum: N I_min^2. */
static void judge(const pmstep_continuity_sums_t *sums, float checks, float min_square_sum, uint8_t *missing_windows,
                  uint8_t *stuck_windows)
{
    const float f2 = PMSTEP_CONTINUITY_FRACTION * PMSTEP_CONTINUITY_FRACTION;
    const float ref_spread = sums->ref_square_sum_A2 - ((sums->ref_sum_A * sums->ref_sum_A) / checks);
    const float read_spread = sums->read_square_sum_A2 - ((sums->read_sum_A * sums->read_sum_A) / checks);
    if (sums->ref_square_sum_A2 >= min_square_sum) {
        *missing_windows =
            (sums->read_square_sum_A2 < (f2 * sums->ref_square_sum_A2)) ? (uint8_t)(*missing_windows + 1u) : 0u;
    }
    if (ref_spread >= min_square_sum) {
        *stuck_windows = (read_spread < (f2 * ref_spread)) ? (uint8_t)(*stuck_windows + 1u) : 0u;
    }
}

pmstep_fault_t pmstep_continuity_judge(pmstep_continuity_t *state, const pmstep_config_t *cfg)
{
    const float checks = (float)state->window_checks;
    const float min_A = PMSTEP_CONTINUITY_MIN_CURRENT_PER_SENSE_RANGE * cfg->limits.current_sense_range_A;
    pmstep_fault_t fault = PMSTEP_FAULT_NONE;
    judge(&state->a, checks, checks * min_A * min_A, &state->missing_windows_a, &state->stuck_windows_a);
    judge(&state->b, checks, checks * min_A * min_A, &state->missing_windows_b, &state->stuck_windows_b);
    if (state->missing_windows_a >= PMSTEP_CONTINUITY_WINDOWS) {
        fault = PMSTEP_FAULT_OPEN_PHASE_A;
    } else if (state->missing_windows_b >= PMSTEP_CONTINUITY_WINDOWS) {
        fault = PMSTEP_FAULT_OPEN_PHASE_B;
    } else if (state->stuck_windows_a >= PMSTEP_CONTINUITY_WINDOWS) {
        fault = PMSTEP_FAULT_CURRENT_STUCK_A;
    } else if (state->stuck_windows_b >= PMSTEP_CONTINUITY_WINDOWS) {
        fault = PMSTEP_FAULT_CURRENT_STUCK_B;
    } else {
        /* nothing persisted */
    }
    memset(&state->a, 0, sizeof state->a);
    memset(&state->b, 0, sizeof state->b);
    state->window_checks = 0u;
    return fault;
}
