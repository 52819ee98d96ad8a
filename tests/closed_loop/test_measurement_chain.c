/* Issue 6 acceptance in closed loop: sil/scenarios/robust.ini (20 kHz, one period of delay,
 * 12-bit ADC, +20/-20 mA offsets, 5 mA noise, plant R +20 %, 1 us dead time) with the
 * firmware's calibration, self-commissioning and drift-free angle on. For 30 s after the
 * transients: angle error < 0.05 rad and |omega - omega*| < 0.5 rad/s, no fault, no NaN;
 * with the averaged and the switching inverter. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "pmstep_hal_host.h"
#include "sil/runner.h"
#include "pmstep/pmstep_text.h"

#define ANGLE_BOUND_RAD 0.05
#define SPEED_BOUND_RAD_S 0.5

static const char *robust_ini; /* argv[1] */

static void acceptance(sil_inverter_model_t model)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    char err[SIL_ERROR_MAX];
    sil_scenario_paper(&sc);
    assert_int_equal(sil_scenario_load(&sc, robust_ini, err, sizeof err), 0);
    sc.inverter.model = model;
    assert_int_equal(sil_scenario_check(&sc, err, sizeof err), 0);
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    print_message("  %s, seed %u: %s, fault %s; after %.2f s: angle error max %.4f rad, |w - w*| max %.4f rad/s "
                  "(rms %.4f); commissioned R %.4f Ohm, L %.3f mH, k_M %.4f Nm/A, offsets %.2f/%.2f mA; "
                  "ADC clipped %lu\n",
                  model == SIL_INVERTER_SWITCHING ? "switching" : "averaged", (unsigned)sc.seed,
                  pmstep_mode_str(s.final_mode), pmstep_fault_str(s.fault), s.settle_time_s, s.max_angle_error_rad,
                  s.max_speed_error_after_settle_rad_s, s.tracking_rms_speed_error_rad_s,
                  (double)s.commissioning.resistance_Ohm, 1e3 * (double)s.commissioning.inductance_H,
                  (double)s.commissioning.torque_constant_Nm_A, 1e3 * (double)s.commissioning.offset_a_A,
                  1e3 * (double)s.commissioning.offset_b_A, pmstep_hal_host_state()->sensors.clipped_current_samples);
    assert_true(sc.duration_s - s.settle_time_s >= 30.0);
    assert_int_equal(s.fault, PMSTEP_FAULT_NONE);
    assert_int_equal(s.final_mode, PMSTEP_MODE_RUN);
    assert_false(s.nonfinite_seen);
    assert_true(s.max_angle_error_rad < ANGLE_BOUND_RAD);
    assert_true(s.max_speed_error_after_settle_rad_s < SPEED_BOUND_RAD_S);
}

static void averaged_inverter_meets_the_bounds(void **state)
{
    (void)state;
    acceptance(SIL_INVERTER_AVERAGED);
}

static void switching_inverter_meets_the_bounds(void **state)
{
    (void)state;
    acceptance(SIL_INVERTER_SWITCHING);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(averaged_inverter_meets_the_bounds),
        cmocka_unit_test(switching_inverter_meets_the_bounds),
    };
    if (argc != 2) {
        print_error("usage: test_measurement_chain sil/scenarios/robust.ini\n");
        return 2;
    }
    robust_ini = argv[1];
    return cmocka_run_group_tests(tests, NULL, NULL);
}
