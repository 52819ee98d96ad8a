/* The record codec (sil/record.h): every pmstep_config_t field survives the header words. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <string.h>

#include "sil/record.h"

static void config_round_trips_through_the_words(void **state)
{
    pmstep_config_t in, out;
    uint32_t w[SIL_RECORD_CONFIG_WORDS];
    (void)state;
    memset(&in, 0, sizeof in);
    memset(&out, 0, sizeof out);
    in = pmstep_paper_config();
    /* Distinct values in the fields the paper's configuration leaves off. */
    in.offset_calibration_time_s = 0.05f;
    in.alignment_offset_calibration = true;
    in.steady_state_window_s = 0.04f;
    in.inductance_window_s = 0.0005f;
    in.use_commissioned_resistance = true;
    in.use_commissioned_inductance = false;
    in.use_commissioned_torque_constant = true;
    in.voltage_bias_level_fraction = 0.5f;
    in.dead_time_s = 1e-6f;
    in.dead_time_current_band_a = 0.05f;
    in.angle_correction_gain_per_s = 20.0f;
    in.angle_magnitude_bound = 0.3f;
    in.speed_consistency_bound_rad_s = 5.0f;
    in.stall_speed_error_rad_s = 4.0f;
    in.observer_residual_bound_a = 0.25f;
    in.detection_time_s = 0.02f;
    in.max_realignments = 3u;
    sil_record_config_to_words(&in, w);
    sil_record_config_from_words(w, &out);
    assert_memory_equal(&in.resistance_ohm, &out.resistance_ohm, sizeof(float));
    assert_true(out.pole_pairs == in.pole_pairs && out.computational_delay_periods == in.computational_delay_periods);
    assert_true(out.max_bus_voltage_v == in.max_bus_voltage_v && out.known_load_mode == in.known_load_mode);
    assert_true(out.offset_calibration_time_s == in.offset_calibration_time_s);
    assert_true(out.alignment_offset_calibration && out.use_commissioned_resistance && !out.use_commissioned_inductance
                && out.use_commissioned_torque_constant);
    assert_true(out.steady_state_window_s == in.steady_state_window_s && out.inductance_window_s == in.inductance_window_s);
    assert_true(out.dead_time_s == in.dead_time_s && out.dead_time_current_band_a == in.dead_time_current_band_a);
    assert_true(out.voltage_bias_level_fraction == in.voltage_bias_level_fraction);
    assert_true(out.angle_correction_gain_per_s == in.angle_correction_gain_per_s);
    assert_true(out.angle_magnitude_bound == in.angle_magnitude_bound);
    assert_true(out.speed_consistency_bound_rad_s == in.speed_consistency_bound_rad_s);
    assert_true(out.stall_speed_error_rad_s == in.stall_speed_error_rad_s);
    assert_true(out.observer_residual_bound_a == in.observer_residual_bound_a);
    assert_true(out.detection_time_s == in.detection_time_s && out.max_realignments == 3u);
    /* The last word is the last field. */
    assert_true(w[SIL_RECORD_CONFIG_WORDS - 1u] == 3u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(config_round_trips_through_the_words),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
