/* Closed loop on the paper's scenario with a realistic measurement chain and inverter:
 * 12-bit current and bus ADC, current-sensor offsets of +20 mA (phase a) and -20 mA
 * (phase b), 5 mA rms noise per phase per sample, one period of computational delay,
 * 1 us dead time per half-bridge; averaged and switching inverter models. The firmware
 * keeps the paper's configuration. The run must reach the end in RUN with no fault. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "pmstep_hal_host.h"
#include "sil/runner.h"

static void realistic(sil_scenario_t *sc, sil_inverter_model_t model)
{
    sil_scenario_paper(sc);
    sc->sensors.adc_bits = 12u;
    sc->sensors.offset_a_a = 0.020;
    sc->sensors.offset_b_a = -0.020;
    sc->sensors.noise_rms_a = 0.005;
    sc->controller.computational_delay_periods = 1u;
    sc->inverter.dead_time_s = 1e-6;
    sc->inverter.model = model;
}

static void run_to_the_end_in_run(sil_inverter_model_t model)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    char err[SIL_ERROR_MAX];
    realistic(&sc, model);
    assert_int_equal(sil_scenario_check(&sc, err, sizeof err), 0);
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    print_message("  %s, seed %u: mode %s, fault '%s' at %.4f s; %ld of %ld periods; tracking max %.4f rms %.4f rad/s, "
                  "transient max %.4f rad/s, T_L-hat %.4f Nm, angle err %.3g/%.3g, max |i| %.3f A, ADC clipped %lu\n",
                  model == SIL_INVERTER_SWITCHING ? "switching" : "averaged", (unsigned)sc.seed,
                  pmstep_mode_str(s.final_mode), pmstep_fault_str(s.fault), s.fault_time_s, s.steps,
                  sil_periods_in(sc.duration_s, (double)sc.controller.period_s), s.tracking_max_speed_error_rad_s,
                  s.tracking_rms_speed_error_rad_s, s.transient_max_speed_error_rad_s, s.final_load_hat_nm,
                  s.max_cos_error, s.max_sin_error, s.max_phase_current_a,
                  pmstep_hal_host_state()->sensors.clipped_current_samples);
    assert_int_equal(s.fault, PMSTEP_FAULT_NONE);
    assert_int_equal(s.final_mode, PMSTEP_MODE_RUN);
    assert_int_equal(s.steps, sil_periods_in(sc.duration_s, (double)sc.controller.period_s));
}

static void averaged_inverter_runs_to_the_end(void **state)
{
    (void)state;
    run_to_the_end_in_run(SIL_INVERTER_AVERAGED);
}

static void switching_inverter_runs_to_the_end(void **state)
{
    (void)state;
    run_to_the_end_in_run(SIL_INVERTER_SWITCHING);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(averaged_inverter_runs_to_the_end),
        cmocka_unit_test(switching_inverter_runs_to_the_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
