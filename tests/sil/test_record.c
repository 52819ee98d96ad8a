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
    in.commissioning.offset_calibration_time_s = 0.05f;
    in.commissioning.alignment_offset_calibration = true;
    in.commissioning.steady_state_window_s = 0.04f;
    in.commissioning.inductance_window_s = 0.0005f;
    in.commissioning.use_measured_resistance = true;
    in.commissioning.use_measured_inductance = false;
    in.commissioning.use_measured_torque_constant = true;
    in.commissioning.voltage_bias_level_fraction = 0.5f;
    in.inverter.dead_time_s = 1e-6f;
    in.inverter.dead_time_current_band_A = 0.05f;
    in.gains.angle_correction_gain_per_s = 20.0f;
    in.detection.angle_magnitude_bound = 0.3f;
    in.detection.speed_consistency_bound_rad_s = 5.0f;
    in.detection.stall_speed_error_rad_s = 4.0f;
    in.detection.observer_residual_bound_A = 0.25f;
    in.detection.persistence_s = 0.02f;
    in.detection.max_realignments = 3u;
    in.commissioning.identification_time_s = 0.4f;
    in.commissioning.identification_min_speed_rad_s = 12.5f;
    in.commissioning.use_identified_mechanics = true;
    in.inverter.phase_voltage_sensing = true;
    in.standstill.hold_current_A = 1.75f;
    in.standstill.vector_speed_rad_s = 5.75f;
    in.inverter.ripple_dead_zone = true;
    in.motor.detent_torque_Nm = 0.0625f;
    in.gains.current_integral_gain_per_s2 = 33800.0f;
    in.gains.detent_fade_speed_rad_s = 20.5f;
    in.alignment.s_lead_in_time_s = 0.0625f;
    in.gains.current_integral_gain_q_per_s2 = 6250.0f;
    in.gains.emf_angle_gain_per_s = 1000.0f;
    in.gains.emf_angle_corner_rad_s = 22.5f;
    in.gains.angle_smoothing = 0.5f;
    in.standstill.stops_only = true;
    in.gains.transient_observer_boost = 3.0f;
    in.motor.rated_current_A = 2.5f;
    in.limits.current_sense_range_A = 8.25f;
    in.limits.bus_sense_range_V = 66.5f;
    sil_record_config_to_words(&in, w);
    sil_record_config_from_words(w, &out);
    assert_memory_equal(&in.motor.resistance_Ohm, &out.motor.resistance_Ohm, sizeof(float));
    assert_true(out.motor.pole_pairs == in.motor.pole_pairs
                && out.timing.computational_delay_periods == in.timing.computational_delay_periods);
    assert_true(out.limits.max_bus_voltage_V == in.limits.max_bus_voltage_V
                && out.known_load_mode == in.known_load_mode);
    assert_true(out.commissioning.offset_calibration_time_s == in.commissioning.offset_calibration_time_s);
    assert_true(out.commissioning.alignment_offset_calibration && out.commissioning.use_measured_resistance
                && !out.commissioning.use_measured_inductance && out.commissioning.use_measured_torque_constant);
    assert_true(out.commissioning.steady_state_window_s == in.commissioning.steady_state_window_s
                && out.commissioning.inductance_window_s == in.commissioning.inductance_window_s);
    assert_true(out.inverter.dead_time_s == in.inverter.dead_time_s
                && out.inverter.dead_time_current_band_A == in.inverter.dead_time_current_band_A);
    assert_true(out.commissioning.voltage_bias_level_fraction == in.commissioning.voltage_bias_level_fraction);
    assert_true(out.gains.angle_correction_gain_per_s == in.gains.angle_correction_gain_per_s);
    assert_true(out.detection.angle_magnitude_bound == in.detection.angle_magnitude_bound);
    assert_true(out.detection.speed_consistency_bound_rad_s == in.detection.speed_consistency_bound_rad_s);
    assert_true(out.detection.stall_speed_error_rad_s == in.detection.stall_speed_error_rad_s);
    assert_true(out.detection.observer_residual_bound_A == in.detection.observer_residual_bound_A);
    assert_true(out.detection.persistence_s == in.detection.persistence_s && out.detection.max_realignments == 3u);
    assert_true(out.commissioning.identification_time_s == in.commissioning.identification_time_s
                && out.commissioning.identification_min_speed_rad_s == in.commissioning.identification_min_speed_rad_s
                && out.commissioning.use_identified_mechanics);
    assert_true(out.inverter.phase_voltage_sensing && w[44] == 1u);
    assert_true(out.standstill.hold_current_A == in.standstill.hold_current_A && w[45] == sil_record_bits(1.75f));
    assert_true(out.standstill.vector_speed_rad_s == in.standstill.vector_speed_rad_s
                && w[46] == sil_record_bits(5.75f));
    assert_true(out.inverter.ripple_dead_zone && w[47] == 1u);
    assert_true(out.motor.detent_torque_Nm == 0.0625f && w[48] == sil_record_bits(0.0625f));
    assert_true(out.gains.current_integral_gain_per_s2 == 33800.0f && w[49] == sil_record_bits(33800.0f));
    assert_true(out.gains.detent_fade_speed_rad_s == 20.5f && w[50] == sil_record_bits(20.5f));
    assert_true(out.alignment.s_lead_in_time_s == 0.0625f && w[51] == sil_record_bits(0.0625f));
    assert_true(out.gains.current_integral_gain_q_per_s2 == 6250.0f && w[52] == sil_record_bits(6250.0f));
    assert_true(out.gains.emf_angle_gain_per_s == 1000.0f && w[53] == sil_record_bits(1000.0f));
    assert_true(out.gains.emf_angle_corner_rad_s == 22.5f && w[54] == sil_record_bits(22.5f));
    assert_true(out.gains.angle_smoothing == 0.5f && w[55] == sil_record_bits(0.5f));
    assert_true(out.standstill.stops_only && w[56] == 1u);
    assert_true(out.gains.transient_observer_boost == 3.0f && w[57] == sil_record_bits(3.0f));
    assert_true(out.motor.rated_current_A == 2.5f && w[58] == sil_record_bits(2.5f));
    assert_true(out.limits.current_sense_range_A == 8.25f && w[59] == sil_record_bits(8.25f));
    /* The last word is the last field. */
    assert_true(out.limits.bus_sense_range_V == 66.5f && w[SIL_RECORD_CONFIG_WORDS - 1u] == sil_record_bits(66.5f));
}

/* A period's input, the sensed phase voltages included, comes back bit for bit. */
static void measurement_round_trips_through_the_words(void **state)
{
    uint32_t w[SIL_RECORD_IN_WORDS];
    const pmstep_meas_t in = {0.25f, -1.5f, 47.9f, 0.125f, 3.75f, -0.0625f};
    pmstep_meas_t out;
    (void)state;
    sil_record_meas_to_words(&in, w);
    sil_record_meas_from_words(w, &out);
    assert_memory_equal(&in, &out, sizeof in);
    assert_int_equal(SIL_RECORD_IN_WORDS, 6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(config_round_trips_through_the_words),
        cmocka_unit_test(measurement_round_trips_through_the_words),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
