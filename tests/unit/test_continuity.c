/* Continuity of the windings and their current measurement (pmstep_continuity.h): the alignments'
 * peaks against u/R, and RUN's windows of reading against reference, on the real module. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_continuity.h"

/* The paper's configuration: u/R = 8 A in both alignments; +/-16.5 A sensed, so I_min = 0.165 A. */
static pmstep_config_t paper(void) { return pmstep_paper_config(); }

/* A driven phase that reaches a quarter of u/R passes; one that stays below it is open. */
static void alignment_peaks_against_u_over_r(void **state)
{
    const pmstep_config_t cfg = paper();
    pmstep_continuity_peaks_t peaks = {0.0f, 0.0f};
    (void)state;
    /* s-alignment drives b: its peak is the largest |i_b|; i_a there counts for nothing. */
    assert_int_equal(pmstep_continuity_align(&peaks, &cfg, false, 50.0f, 1.9f, false, false), PMSTEP_FAULT_NONE);
    assert_int_equal(pmstep_continuity_align(&peaks, &cfg, false, 50.0f, -0.5f, true, false),
                     PMSTEP_FAULT_OPEN_PHASE_B);
    peaks.peak_b_A = 0.0f;
    assert_int_equal(pmstep_continuity_align(&peaks, &cfg, false, 0.0f, -2.01f, false, false), PMSTEP_FAULT_NONE);
    assert_int_equal(pmstep_continuity_align(&peaks, &cfg, false, 0.0f, 0.0f, true, false), PMSTEP_FAULT_NONE);
    /* c-alignment drives a: 1.9 A < 2 A at t_c is open, 2 A is not. */
    assert_int_equal(pmstep_continuity_align(&peaks, &cfg, true, 1.9f, 40.0f, false, true), PMSTEP_FAULT_OPEN_PHASE_A);
    assert_int_equal(pmstep_continuity_align(&peaks, &cfg, true, -2.0f, 0.0f, false, true), PMSTEP_FAULT_NONE);
}

/* Feeds @p windows windows of a rotating reference of @p amplitude_A, the reading being @p gain
 * times it plus @p offset_A (a frozen reading: @p frozen_A if finite); @return the last verdict. */
static pmstep_fault_t feed(pmstep_continuity_t *st, const pmstep_continuity_coeffs_t *coeffs,
                           const pmstep_config_t *cfg, unsigned windows, float amplitude_A, float gain, float frozen_A,
                           float lag_rad)
{
    pmstep_fault_t fault = PMSTEP_FAULT_NONE;
    unsigned k;
    for (k = 0; k < windows * coeffs->window_checks && fault == PMSTEP_FAULT_NONE; ++k) {
        const float angle = 0.3f * (float)k;
        const float ref_a = amplitude_A * cosf(angle);
        const float ref_b = amplitude_A * sinf(angle);
        const float i_a = isfinite(frozen_A) ? frozen_A : gain * amplitude_A * cosf(angle - lag_rad);
        const float i_b = gain * amplitude_A * sinf(angle - lag_rad);
        if (pmstep_continuity_check(st, coeffs, ref_a, ref_b, i_a, i_b)) {
            fault = pmstep_continuity_judge(st, cfg);
        }
    }
    return fault;
}

static void run_windows_tell_missing_stuck_and_following(void **state)
{
    const pmstep_config_t cfg = paper();
    pmstep_continuity_coeffs_t coeffs;
    pmstep_continuity_t st;
    (void)state;
    pmstep_continuity_coeffs_init(&coeffs, &cfg);
    /* 10 / (R/L + K_i) = 10 / 520 s over checks of 8 periods of 50 us: 48 checks. */
    assert_int_equal(coeffs.window_checks, 48u);
    /* Healthy: half the gain, a quarter-turn lag, for 20 windows: nothing. */
    pmstep_continuity_start(&st);
    assert_int_equal(feed(&st, &coeffs, &cfg, 20u, 1.0f, 0.5f, NAN, 1.5f), PMSTEP_FAULT_NONE);
    /* A reading of 0 (open winding or sensor): phase a missing after two windows. */
    pmstep_continuity_start(&st);
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_NONE);
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_OPEN_PHASE_A);
    /* A reading frozen at 0.8 A while the reference turns: stuck (its rms passes the missing test). */
    pmstep_continuity_start(&st);
    assert_int_equal(feed(&st, &coeffs, &cfg, 2u, 1.0f, 1.0f, 0.8f, 0.0f), PMSTEP_FAULT_CURRENT_STUCK_A);
    /* A reference below I_min tells nothing: a dead phase is not judged... */
    pmstep_continuity_start(&st);
    assert_int_equal(feed(&st, &coeffs, &cfg, 5u, 0.1f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_NONE);
    /* ... and a window that tells nothing does not clear one that found the phase missing. */
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_NONE);
    assert_int_equal(feed(&st, &coeffs, &cfg, 3u, 0.1f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_NONE);
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_OPEN_PHASE_A);
    /* One window that finds the phase following clears the count. */
    pmstep_continuity_start(&st);
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_NONE);
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, NAN, 0.0f), PMSTEP_FAULT_NONE);
    assert_int_equal(feed(&st, &coeffs, &cfg, 1u, 1.0f, 1.0f, 0.0f, 0.0f), PMSTEP_FAULT_NONE);
}

/* The window is at least 4 checks and at most 65535, whatever R/L and K_i. */
static void window_bounded(void **state)
{
    pmstep_config_t cfg = paper();
    pmstep_continuity_coeffs_t coeffs;
    (void)state;
    cfg.gains.current_gain_per_s = 9000.0f; /* (500 + 9000) x 50 us < 0.5 */
    pmstep_continuity_coeffs_init(&coeffs, &cfg);
    assert_int_equal(coeffs.window_checks, 4u);
    cfg = paper();
    cfg.motor.resistance_Ohm = 1e-30f;
    cfg.gains.current_gain_per_s = 1e-30f;
    pmstep_continuity_coeffs_init(&coeffs, &cfg);
    assert_int_equal(coeffs.window_checks, 65535u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(alignment_peaks_against_u_over_r),
        cmocka_unit_test(run_windows_tell_missing_stuck_and_following),
        cmocka_unit_test(window_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
