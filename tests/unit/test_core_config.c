/* Core configuration: each validation cause has its own code and text, and every code is
 * provoked by a test (the lifecycle is test_core.c). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_text.h"

/* Every status code, so the tests below can tell each has its text and its test. */
static const pmstep_status_t all_status_codes[] = {PMSTEP_OK,
                                                   PMSTEP_ERR_NULL_ARGUMENT,
                                                   PMSTEP_ERR_BAD_MODE,
                                                   PMSTEP_ERR_BAD_COMMAND_VALUE,
                                                   PMSTEP_ERR_NONFINITE_PARAMETER,
                                                   PMSTEP_ERR_DERIVED_NONFINITE,
                                                   PMSTEP_ERR_RESISTANCE,
                                                   PMSTEP_ERR_INDUCTANCE,
                                                   PMSTEP_ERR_INERTIA,
                                                   PMSTEP_ERR_TORQUE_CONSTANT,
                                                   PMSTEP_ERR_FRICTION,
                                                   PMSTEP_ERR_POLE_PAIRS,
                                                   PMSTEP_ERR_DETENT_TORQUE,
                                                   PMSTEP_ERR_PERIOD,
                                                   PMSTEP_ERR_DELAY,
                                                   PMSTEP_ERR_SPEED_GAIN,
                                                   PMSTEP_ERR_OBSERVER_GAIN,
                                                   PMSTEP_ERR_CURRENT_GAIN,
                                                   PMSTEP_ERR_ADAPT_GAMMA,
                                                   PMSTEP_ERR_ADAPT_LAMBDA,
                                                   PMSTEP_ERR_ADAPT_R,
                                                   PMSTEP_ERR_SAT_KAPPA,
                                                   PMSTEP_ERR_OBSERVER_GAIN_FOR_PERIOD,
                                                   PMSTEP_ERR_CURRENT_GAIN_FOR_PERIOD,
                                                   PMSTEP_ERR_REFERENCE_BANDWIDTH,
                                                   PMSTEP_ERR_ANGLE_CORRECTION_GAIN,
                                                   PMSTEP_ERR_CURRENT_INTEGRAL_GAIN,
                                                   PMSTEP_ERR_DETENT_FADE_SPEED,
                                                   PMSTEP_ERR_EMF_ANGLE_GAIN,
                                                   PMSTEP_ERR_ANGLE_SMOOTHING,
                                                   PMSTEP_ERR_OBSERVER_BOOST,
                                                   PMSTEP_ERR_MAX_CURRENT,
                                                   PMSTEP_ERR_MIN_BUS,
                                                   PMSTEP_ERR_BUS_ORDER,
                                                   PMSTEP_ERR_TRIP_ABOVE_RATED,
                                                   PMSTEP_ERR_TRIP_ABOVE_SENSE_RANGE,
                                                   PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE,
                                                   PMSTEP_ERR_SENSE_RANGE,
                                                   PMSTEP_ERR_ALIGNMENT_VOLTAGE,
                                                   PMSTEP_ERR_ALIGNMENT_ABOVE_BUS,
                                                   PMSTEP_ERR_ALIGNMENT_CURRENT,
                                                   PMSTEP_ERR_S_ALIGN_TIME,
                                                   PMSTEP_ERR_C_ALIGN_TIME,
                                                   PMSTEP_ERR_ALIGNMENT_TOO_LONG,
                                                   PMSTEP_ERR_ALIGNMENT_CONDITION,
                                                   PMSTEP_ERR_OFFSET_CALIBRATION_TIME,
                                                   PMSTEP_ERR_STEADY_STATE_WINDOW,
                                                   PMSTEP_ERR_INDUCTANCE_WINDOW,
                                                   PMSTEP_ERR_ALIGNMENT_OFFSETS_UNMEASURED,
                                                   PMSTEP_ERR_RESISTANCE_UNMEASURED,
                                                   PMSTEP_ERR_INDUCTANCE_UNMEASURED,
                                                   PMSTEP_ERR_TORQUE_CONSTANT_UNMEASURED,
                                                   PMSTEP_ERR_VOLTAGE_BIAS_FRACTION,
                                                   PMSTEP_ERR_VOLTAGE_BIAS_WINDOW,
                                                   PMSTEP_ERR_VOLTAGE_BIAS_SETTLING,
                                                   PMSTEP_ERR_DEAD_TIME,
                                                   PMSTEP_ERR_DEAD_TIME_BAND,
                                                   PMSTEP_ERR_DETECTION_BOUND,
                                                   PMSTEP_ERR_DETECTION_TIME,
                                                   PMSTEP_ERR_RATED_CURRENT,
                                                   PMSTEP_ERR_BUS_BELOW_RATED,
                                                   PMSTEP_ERR_RATE_TOO_SLOW,
                                                   PMSTEP_ERR_SENSE_RANGE_BELOW_RATED,
                                                   PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT,
                                                   PMSTEP_ERR_DATASHEET_TIME_CONSTANT,
                                                   PMSTEP_ERR_DATASHEET_INERTIA,
                                                   PMSTEP_ERR_DATASHEET_FLUX_RATIO,
                                                   PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT,
                                                   PMSTEP_ERR_IDENTIFICATION_WINDOW,
                                                   PMSTEP_ERR_IDENTIFICATION_SPEED,
                                                   PMSTEP_ERR_MECHANICS_UNIDENTIFIED,
                                                   PMSTEP_ERR_POSITION_GAIN,
                                                   PMSTEP_ERR_POSITION_INTEGRAL_GAIN,
                                                   PMSTEP_ERR_HOLD_CURRENT,
                                                   PMSTEP_ERR_STANDSTILL_KNOWN_LOAD};

/* ---- validation: each cause has its own code and text ---- */

typedef void (*config_edit_t)(pmstep_config_t *cfg);
static void bad_r(pmstep_config_t *c) { c->motor.resistance_Ohm = 0.0f; }
static void negative_detent(pmstep_config_t *c) { c->motor.detent_torque_Nm = -1e-3f; }
static void negative_current_integral(pmstep_config_t *c) { c->gains.current_integral_gain_per_s2 = -1.0f; }
static void negative_q_current_integral(pmstep_config_t *c) { c->gains.current_integral_gain_q_per_s2 = -1.0f; }
static void negative_detent_fade(pmstep_config_t *c) { c->gains.detent_fade_speed_rad_s = -1.0f; }
/* Paper: R/L + K_i = 500 + 20 = 520 1/s, so K_I may reach 520^2/4 = 67600 1/s^2. */
static void current_integral_complex_poles(pmstep_config_t *c) { c->gains.current_integral_gain_per_s2 = 68000.0f; }
static void q_current_integral_complex_poles(pmstep_config_t *c) { c->gains.current_integral_gain_q_per_s2 = 68000.0f; }
static void current_integral_at_bound(pmstep_config_t *c)
{
    c->gains.current_integral_gain_per_s2 = 67000.0f;
    c->gains.current_integral_gain_q_per_s2 = 67000.0f;
}
static void negative_emf_gain(pmstep_config_t *c) { c->gains.emf_angle_gain_per_s = -1.0f; }
static void negative_emf_corner(pmstep_config_t *c) { c->gains.emf_angle_corner_rad_s = -1.0f; }
static void emf_gain_without_corner(pmstep_config_t *c) { c->gains.emf_angle_gain_per_s = 100.0f; }
/* Paper: the residual settles at R/L + K_e = 500 + 100 = 600 1/s; K_theta must stay below. */
static void emf_gain_at_residual_rate(pmstep_config_t *c)
{
    c->gains.emf_angle_gain_per_s = 600.0f;
    c->gains.emf_angle_corner_rad_s = 5.0f;
}
static void negative_angle_smoothing(pmstep_config_t *c) { c->gains.angle_smoothing = -0.1f; }
static void angle_smoothing_of_one(pmstep_config_t *c) { c->gains.angle_smoothing = 1.0f; }
static void negative_observer_boost(pmstep_config_t *c) { c->gains.transient_observer_boost = -1.0f; }
/* With a residual bound, so that only the boost itself is wrong. */
static void observer_boost_below_one(pmstep_config_t *c)
{
    c->detection.observer_residual_bound_A = 0.3f;
    c->gains.transient_observer_boost = 0.5f;
}
static void observer_boost_above_max(pmstep_config_t *c)
{
    c->detection.observer_residual_bound_A = 0.3f;
    c->gains.transient_observer_boost = 4.5f;
}
static void observer_boost_without_bound(pmstep_config_t *c)
{
    c->detection.observer_residual_bound_A = 0.0f;
    c->gains.transient_observer_boost = 3.0f;
}
static void bad_l(pmstep_config_t *c) { c->motor.inductance_H = -1e-3f; }
static void bad_j(pmstep_config_t *c) { c->motor.inertia_kgm2 = 0.0f; }
static void bad_km(pmstep_config_t *c) { c->motor.torque_constant_Nm_A = 0.0f; }
static void bad_f(pmstep_config_t *c) { c->motor.friction_Nms_rad = -0.1f; }
static void bad_p(pmstep_config_t *c) { c->motor.pole_pairs = 0; }
static void bad_period(pmstep_config_t *c) { c->timing.period_s = 0.0f; }
static void bad_k_omega(pmstep_config_t *c) { c->gains.speed_gain_per_s = 0.0f; }
static void bad_k_e(pmstep_config_t *c) { c->gains.observer_gain_per_s = -1.0f; }
static void bad_k_i(pmstep_config_t *c) { c->gains.current_gain_per_s = 0.0f; }
static void bad_gamma(pmstep_config_t *c) { c->gains.adapt_gamma = 0.0f; }
static void bad_lambda(pmstep_config_t *c) { c->gains.adapt_lambda = 0.0f; }
static void bad_r_gain(pmstep_config_t *c) { c->gains.adapt_r = 0.0f; }
static void bad_kappa(pmstep_config_t *c) { c->gains.sat_kappa_rad_s = 0.0f; }
static void observer_too_fast(pmstep_config_t *c) { c->timing.period_s = 9.9e-4f; } /* (500 + 100) * 9.9e-4 >= 0.5 */
static void current_loop_too_fast(pmstep_config_t *c) /* (500 + 1) 9.9e-4 < 0.5 <= (500 + 20) 9.9e-4 */
{
    c->timing.period_s = 9.9e-4f;
    c->gains.observer_gain_per_s = 1.0f;
}
static void zero_max_current(pmstep_config_t *c) { c->limits.max_phase_current_A = 0.0f; }
static void zero_min_bus(pmstep_config_t *c) { c->limits.min_bus_voltage_V = 0.0f; }
static void s_align_too_short(pmstep_config_t *c) { c->alignment.s_align_time_s = 10e-6f; }
static void alignment_too_long(pmstep_config_t *c) { c->alignment.c_align_time_s = 1000.0f; } /* 2e7 periods > 2^24 */
static void bad_condition4(pmstep_config_t *c) { c->alignment.c_align_voltage_V = 1.0f; } /* margin 18.5 - 32.1 < 0 */
static void bad_condition4_slow_motor(pmstep_config_t *c) { c->motor.torque_constant_Nm_A = 0.2f; } /* 44.4 - 64 < 0 */
static void align_voltage_above_bus(pmstep_config_t *c)
{
    c->alignment.s_align_voltage_V = 40.0f;
} /* above min bus 30 V */
static void zero_align_voltage(pmstep_config_t *c) { c->alignment.c_align_voltage_V = 0.0f; }
static void bad_align_current(pmstep_config_t *c) { c->limits.max_phase_current_A = 7.0f; } /* 24 V / 3 Ohm = 8 A */
static void bad_align_time(pmstep_config_t *c) { c->alignment.c_align_time_s = c->alignment.s_align_time_s; }
static void negative_lead_in(pmstep_config_t *c) { c->alignment.s_lead_in_time_s = -1e-3f; }
static void lead_in_fills_s_alignment(pmstep_config_t *c)
{
    c->alignment.s_lead_in_time_s = c->alignment.s_align_time_s;
}
static void bad_bandwidth(pmstep_config_t *c) { c->gains.reference_bandwidth_rad_s = 20000.0f; }
static void bad_limits(pmstep_config_t *c) { c->limits.max_bus_voltage_V = 20.0f; }
static void bad_delay(pmstep_config_t *c) { c->timing.computational_delay_periods = 2u; }
/* The review's values: a trip and an overvoltage limit of 3.4e38 (finite) switched both trips off. */
static void huge_trip(pmstep_config_t *c) { c->limits.max_phase_current_A = 3.4e38f; }
static void huge_max_bus(pmstep_config_t *c) { c->limits.max_bus_voltage_V = 3.4e38f; }
/* Paper: rated 8 A, so the trip may be 24 A at most; with a sensing range of 30 A it is the rating
 * that refuses 24.5 A. */
static void trip_above_rated(pmstep_config_t *c)
{
    c->limits.current_sense_range_A = 30.0f;
    c->limits.max_phase_current_A = 24.5f;
}
static void zero_rated_current(pmstep_config_t *c) { c->motor.rated_current_A = 0.0f; }
/* Paper: +/-16.5 A sensed, so a trip up to 15.675 A; 16 A would never see a saturated reading. */
static void trip_above_sense_range(pmstep_config_t *c) { c->limits.max_phase_current_A = 16.0f; }
/* Paper: 66 V sensed, so a trip up to 62.7 V. */
static void max_bus_above_sense_range(pmstep_config_t *c) { c->limits.max_bus_voltage_V = 63.0f; }
static void zero_current_sense_range(pmstep_config_t *c) { c->limits.current_sense_range_A = 0.0f; }
static void negative_bus_sense_range(pmstep_config_t *c) { c->limits.bus_sense_range_V = -66.0f; }
static void nan_param(pmstep_config_t *c) { c->motor.inertia_kgm2 = NAN; }
/* Found by fuzzing (issue 15): each was accepted and failed only in the step. */
static void tiny_dead_time_band(pmstep_config_t *c)
{
    c->inverter.dead_time_s = 1e-6f;
    c->inverter.dead_time_current_band_A = 1e-40f;
}
static void huge_detection_time(pmstep_config_t *c) { c->detection.persistence_s = 858993.4592f; }
static void denormal_period(pmstep_config_t *c) { c->timing.period_s = 1e-40f; }
static void period_above_range(pmstep_config_t *c)
{
    c->timing.period_s = 0.02f;
    c->gains.observer_gain_per_s = 1.0f;
    c->gains.current_gain_per_s = 1.0f;
}
static void gamma_squared_underflows(pmstep_config_t *c) { c->gains.adapt_gamma = 1e-30f; }
static void inertia_squared_overflows(pmstep_config_t *c) { c->motor.inertia_kgm2 = 1e28f; }
static void friction_overflows_load_gain(pmstep_config_t *c) { c->motor.friction_Nms_rad = 3.4e38f; }
static void detection_time_below_four_periods_with_detectors_off(pmstep_config_t *c)
{
    c->detection.angle_magnitude_bound = 0.0f;
    c->detection.speed_consistency_bound_rad_s = 0.0f;
    c->detection.stall_speed_error_rad_s = 0.0f;
    c->detection.observer_residual_bound_A = 0.0f;
    c->detection.persistence_s = 1e-40f;
}

static void negative_identification_window(pmstep_config_t *c) { c->commissioning.identification_time_s = -0.1f; }
static void negative_identification_speed(pmstep_config_t *c)
{
    c->commissioning.identification_min_speed_rad_s = -1.0f;
}
static void identified_mechanics_without_window(pmstep_config_t *c)
{
    c->commissioning.use_identified_mechanics = true;
}
static void measure_only_without_window(pmstep_config_t *c)
{
    c->commissioning.measure_only = true;
    c->commissioning.steady_state_window_s = 0.0f;
}

static const struct {
    config_edit_t edit;
    pmstep_status_t expected;
} validation_cases[] = {
    {negative_identification_window, PMSTEP_ERR_IDENTIFICATION_WINDOW},
    {negative_identification_speed, PMSTEP_ERR_IDENTIFICATION_SPEED},
    {identified_mechanics_without_window, PMSTEP_ERR_MECHANICS_UNIDENTIFIED},
    {measure_only_without_window, PMSTEP_ERR_MEASURE_ONLY_WINDOW},
    {bad_r, PMSTEP_ERR_RESISTANCE},
    {bad_l, PMSTEP_ERR_INDUCTANCE},
    {bad_j, PMSTEP_ERR_INERTIA},
    {bad_km, PMSTEP_ERR_TORQUE_CONSTANT},
    {bad_f, PMSTEP_ERR_FRICTION},
    {bad_p, PMSTEP_ERR_POLE_PAIRS},
    {negative_detent, PMSTEP_ERR_DETENT_TORQUE},
    {negative_current_integral, PMSTEP_ERR_CURRENT_INTEGRAL_GAIN},
    {negative_q_current_integral, PMSTEP_ERR_CURRENT_INTEGRAL_GAIN},
    {negative_detent_fade, PMSTEP_ERR_DETENT_FADE_SPEED},
    {negative_emf_gain, PMSTEP_ERR_EMF_ANGLE_GAIN},
    {negative_emf_corner, PMSTEP_ERR_EMF_ANGLE_GAIN},
    {emf_gain_without_corner, PMSTEP_ERR_EMF_ANGLE_GAIN},
    {emf_gain_at_residual_rate, PMSTEP_ERR_EMF_ANGLE_GAIN},
    {negative_angle_smoothing, PMSTEP_ERR_ANGLE_SMOOTHING},
    {angle_smoothing_of_one, PMSTEP_ERR_ANGLE_SMOOTHING},
    {negative_observer_boost, PMSTEP_ERR_OBSERVER_BOOST},
    {observer_boost_below_one, PMSTEP_ERR_OBSERVER_BOOST},
    {observer_boost_above_max, PMSTEP_ERR_OBSERVER_BOOST},
    {observer_boost_without_bound, PMSTEP_ERR_OBSERVER_BOOST},
    {negative_lead_in, PMSTEP_ERR_S_LEAD_IN_TIME},
    {lead_in_fills_s_alignment, PMSTEP_ERR_S_LEAD_IN_TIME},
    {current_integral_complex_poles, PMSTEP_ERR_CURRENT_INTEGRAL_GAIN},
    {q_current_integral_complex_poles, PMSTEP_ERR_CURRENT_INTEGRAL_GAIN},
    {bad_period, PMSTEP_ERR_PERIOD},
    {bad_k_omega, PMSTEP_ERR_SPEED_GAIN},
    {bad_k_e, PMSTEP_ERR_OBSERVER_GAIN},
    {bad_k_i, PMSTEP_ERR_CURRENT_GAIN},
    {bad_gamma, PMSTEP_ERR_ADAPT_GAMMA},
    {bad_lambda, PMSTEP_ERR_ADAPT_LAMBDA},
    {bad_r_gain, PMSTEP_ERR_ADAPT_R},
    {bad_kappa, PMSTEP_ERR_SAT_KAPPA},
    {observer_too_fast, PMSTEP_ERR_OBSERVER_GAIN_FOR_PERIOD},
    {current_loop_too_fast, PMSTEP_ERR_CURRENT_GAIN_FOR_PERIOD},
    {zero_max_current, PMSTEP_ERR_MAX_CURRENT},
    {zero_min_bus, PMSTEP_ERR_MIN_BUS},
    {s_align_too_short, PMSTEP_ERR_S_ALIGN_TIME},
    {alignment_too_long, PMSTEP_ERR_ALIGNMENT_TOO_LONG},
    {bad_condition4, PMSTEP_ERR_ALIGNMENT_CONDITION},
    {bad_condition4_slow_motor, PMSTEP_ERR_ALIGNMENT_CONDITION},
    {align_voltage_above_bus, PMSTEP_ERR_ALIGNMENT_ABOVE_BUS},
    {zero_align_voltage, PMSTEP_ERR_ALIGNMENT_VOLTAGE},
    {bad_align_current, PMSTEP_ERR_ALIGNMENT_CURRENT},
    {bad_align_time, PMSTEP_ERR_C_ALIGN_TIME},
    {bad_bandwidth, PMSTEP_ERR_REFERENCE_BANDWIDTH},
    {bad_limits, PMSTEP_ERR_BUS_ORDER},
    {huge_trip, PMSTEP_ERR_TRIP_ABOVE_RATED},
    {huge_max_bus, PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE},
    {trip_above_rated, PMSTEP_ERR_TRIP_ABOVE_RATED},
    {zero_rated_current, PMSTEP_ERR_RATED_CURRENT},
    {trip_above_sense_range, PMSTEP_ERR_TRIP_ABOVE_SENSE_RANGE},
    {max_bus_above_sense_range, PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE},
    {zero_current_sense_range, PMSTEP_ERR_SENSE_RANGE},
    {negative_bus_sense_range, PMSTEP_ERR_SENSE_RANGE},
    {bad_delay, PMSTEP_ERR_DELAY},
    {nan_param, PMSTEP_ERR_NONFINITE_PARAMETER},
    {tiny_dead_time_band, PMSTEP_ERR_DEAD_TIME_BAND},
    {huge_detection_time, PMSTEP_ERR_DETECTION_TIME},
    {denormal_period, PMSTEP_ERR_PERIOD},
    {period_above_range, PMSTEP_ERR_PERIOD},
    {gamma_squared_underflows, PMSTEP_ERR_DERIVED_NONFINITE},
    {inertia_squared_overflows, PMSTEP_ERR_DERIVED_NONFINITE},
    {friction_overflows_load_gain, PMSTEP_ERR_DERIVED_NONFINITE},
    {detection_time_below_four_periods_with_detectors_off, PMSTEP_ERR_DETECTION_TIME},
};

static void every_invalid_configuration_has_its_code(void **state)
{
    size_t n;
    pmstep_t inst;
    pmstep_config_t good = pmstep_paper_config();
    (void)state;
    assert_int_equal(pmstep_init(&inst, &good), PMSTEP_OK);
    assert_int_equal(pmstep_init(NULL, &good), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_init(&inst, NULL), PMSTEP_ERR_NULL_ARGUMENT);
    for (n = 0; n < sizeof validation_cases / sizeof validation_cases[0]; ++n) {
        pmstep_config_t cfg = pmstep_paper_config();
        pmstep_status_t status;
        validation_cases[n].edit(&cfg);
        status = pmstep_init(&inst, &cfg);
        print_message("case %u: %d (%s)\n", (unsigned)n, (int)status, pmstep_status_str(status));
        assert_int_equal(status, validation_cases[n].expected);
        assert_true(strcmp(pmstep_status_str(status), "unknown status") != 0);
    }
}

/* Validation without an instance and init agree on every case, and a refused init leaves a
 * prepared instance byte for byte as it was (its derivation is checked before the instance is
 * written). */
static void refused_init_leaves_the_instance_as_it_was(void **state)
{
    size_t n;
    static pmstep_t inst;
    static pmstep_t before;
    const pmstep_config_t good = pmstep_paper_config();
    (void)state;
    assert_int_equal(pmstep_init(&inst, &good), PMSTEP_OK);
    memcpy(&before, &inst, sizeof before);
    for (n = 0; n < sizeof validation_cases / sizeof validation_cases[0]; ++n) {
        pmstep_config_t cfg = pmstep_paper_config();
        validation_cases[n].edit(&cfg);
        assert_int_equal(pmstep_validate_config(&cfg), validation_cases[n].expected);
        assert_int_equal(pmstep_init(&inst, &cfg), validation_cases[n].expected);
        assert_memory_equal(&inst, &before, sizeof inst);
    }
}

/* The validation causes this file does not provoke, and the file that does: test_commission.c
 * (commissioning, inverter, detection and angle-correction settings). */
static const pmstep_status_t codes_tested_in_test_commission[] = {
    PMSTEP_ERR_ANGLE_CORRECTION_GAIN, PMSTEP_ERR_OFFSET_CALIBRATION_TIME,      PMSTEP_ERR_STEADY_STATE_WINDOW,
    PMSTEP_ERR_INDUCTANCE_WINDOW,     PMSTEP_ERR_ALIGNMENT_OFFSETS_UNMEASURED, PMSTEP_ERR_RESISTANCE_UNMEASURED,
    PMSTEP_ERR_INDUCTANCE_UNMEASURED, PMSTEP_ERR_TORQUE_CONSTANT_UNMEASURED,   PMSTEP_ERR_VOLTAGE_BIAS_FRACTION,
    PMSTEP_ERR_VOLTAGE_BIAS_WINDOW,   PMSTEP_ERR_VOLTAGE_BIAS_SETTLING,        PMSTEP_ERR_DEAD_TIME,
    PMSTEP_ERR_DETECTION_BOUND};

static void current_integral_within_its_bound_is_accepted(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    (void)state;
    current_integral_at_bound(&cfg);
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg.motor.detent_torque_Nm = 0.01f;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
}

/* The bounds themselves are accepted: a trip of 3 x rated within the sensing, and trips at 95 % of
 * each range. */
static void limits_at_their_bounds_are_accepted(void **state)
{
    /* The validation's table keeps each float's offset in an unsigned char. */
    assert_true(offsetof(pmstep_config_t, standstill.vector_speed_rad_s) < 256u);
    pmstep_config_t cfg = pmstep_paper_config();
    (void)state;
    cfg.limits.current_sense_range_A = 30.0f;
    cfg.limits.max_phase_current_A = PMSTEP_MAX_TRIP_PER_RATED_CURRENT * cfg.motor.rated_current_A;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg = pmstep_paper_config();
    cfg.limits.max_phase_current_A = PMSTEP_SENSE_RANGE_USABLE_FRACTION * cfg.limits.current_sense_range_A;
    cfg.limits.max_bus_voltage_V = PMSTEP_SENSE_RANGE_USABLE_FRACTION * cfg.limits.bus_sense_range_V;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
}

static void emf_gain_under_the_residual_rate_is_accepted(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    (void)state;
    cfg.gains.emf_angle_gain_per_s = 590.0f;
    cfg.gains.emf_angle_corner_rad_s = 5.0f;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg.gains.emf_angle_gain_per_s = 0.0f; /* off: a corner alone is allowed */
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
}

/* The transient observer boost: 1 and the largest, 4, with a residual bound. */
static void observer_boost_within_range_is_accepted(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    (void)state;
    cfg.detection.observer_residual_bound_A = 0.3f;
    cfg.gains.transient_observer_boost = 1.0f;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg.gains.transient_observer_boost = PMSTEP_OBSERVER_BOOST_MAX;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
}

static void every_validation_code_is_provoked(void **state)
{
    /* Each configuration code (-10 and below) is the expected result of some case above or
     * of test_commission.c's table: one cause, one code, one test. */
    size_t n;
    (void)state;
    for (n = 0; n < sizeof all_status_codes / sizeof all_status_codes[0]; ++n) {
        const pmstep_status_t code = all_status_codes[n];
        bool found = false;
        size_t k;
        if (code > PMSTEP_ERR_NONFINITE_PARAMETER
            || (code <= PMSTEP_ERR_RATED_CURRENT && code >= PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT)
            || code <= PMSTEP_ERR_POSITION_GAIN) {
            continue; /* ok and the command codes: commands_validate_their_values (test_core.c); the
                       * designer's: test_design.c; the position library's: test_position.c */
        }
        for (k = 0; k < sizeof validation_cases / sizeof validation_cases[0]; ++k) {
            found = found || validation_cases[k].expected == code;
        }
        for (k = 0; k < sizeof codes_tested_in_test_commission / sizeof codes_tested_in_test_commission[0]; ++k) {
            found = found || codes_tested_in_test_commission[k] == code;
        }
        print_message("%d %s: %s\n", (int)code, pmstep_status_str(code), found ? "tested" : "NOT TESTED");
        assert_true(found);
    }
}

static void every_code_has_its_own_text(void **state)
{
    size_t n;
    size_t m;
    (void)state;
    for (n = 0; n < sizeof all_status_codes / sizeof all_status_codes[0]; ++n) {
        const char *text = pmstep_status_str(all_status_codes[n]);
        assert_true(strcmp(text, "unknown status") != 0);
        for (m = 0; m < n; ++m) {
            assert_true(all_status_codes[m] != all_status_codes[n]);
            assert_true(strcmp(pmstep_status_str(all_status_codes[m]), text) != 0);
        }
    }
}

static double condition4_margin(double k_m, double u_cs, double u_cc)
{
    const double p = 6.0, l = 0.006, r = 3.0;
    return k_m * u_cc / (p * l * r) - (u_cs * u_cs + u_cc * u_cc) / (2.0 * r * r);
}

static void condition4_cases_are_on_the_right_side(void **state)
{
    /* Keeps the table above honest: paper values 444.4 - 64 > 0, the two bad cases < 0. */
    (void)state;
    assert_true(fabs(condition4_margin(2.0, 24.0, 24.0) - (444.444 - 64.0)) < 1e-3);
    assert_true(condition4_margin(2.0, 24.0, 1.0) < 0.0);
    assert_true(condition4_margin(0.2, 24.0, 24.0) < 0.0);
    assert_true(condition4_margin(2.0, 24.0, 2.0) > 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_invalid_configuration_has_its_code),
        cmocka_unit_test(refused_init_leaves_the_instance_as_it_was),
        cmocka_unit_test(current_integral_within_its_bound_is_accepted),
        cmocka_unit_test(limits_at_their_bounds_are_accepted),
        cmocka_unit_test(emf_gain_under_the_residual_rate_is_accepted),
        cmocka_unit_test(observer_boost_within_range_is_accepted),
        cmocka_unit_test(every_code_has_its_own_text),
        cmocka_unit_test(every_validation_code_is_provoked),
        cmocka_unit_test(condition4_cases_are_on_the_right_side),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
