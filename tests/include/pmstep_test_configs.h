/* Configurations the reliability harnesses share (tests/fuzz, tests/eva): one definition of
 * "every optional feature on", so the fuzzer and the proof analyse the same firmware paths. */
#ifndef PMSTEP_TEST_CONFIGS_H
#define PMSTEP_TEST_CONFIGS_H

#include "pmstep/pmstep.h"

/* Every optional feature on: offset calibration, alignment windows with the voltage bias,
 * inductance window, commissioned R, L, k_M used, J and F identified over 20 ms of RUN and
 * used, dead-time compensation, drift-free angle, detent compensation (faded with the speed), PI current loop,
 * every detector (the paper's bounds), two re-alignments, one period of delay, the standstill hold
 * of speed mode at 7.5 A (half the current trip), field weakening (up to 7 A at the designer's gain). */
static inline pmstep_config_t pmstep_test_features_config(void)
{
    pmstep_config_t cfg = pmstep_paper_config();
    cfg.commissioning.offset_calibration_time_s = 0.005f;
    cfg.commissioning.alignment_offset_calibration = true;
    cfg.commissioning.steady_state_window_s = 0.05f;
    cfg.commissioning.voltage_bias_level_fraction = 0.5f;
    cfg.commissioning.inductance_window_s = 0.0005f;
    cfg.commissioning.use_measured_resistance = true;
    cfg.commissioning.use_measured_inductance = true;
    cfg.commissioning.use_measured_torque_constant = true;
    cfg.commissioning.identification_time_s = 0.02f;
    cfg.commissioning.use_identified_mechanics = true;
    cfg.inverter.dead_time_s = 1e-6f;
    cfg.inverter.dead_time_current_band_A = 0.005f;
    cfg.gains.angle_correction_gain_per_s = 20.0f;
    cfg.gains.current_integral_gain_per_s2 = 33800.0f;   /* (R/L + K_i)^2 / 8 = 520^2 / 8 */
    cfg.gains.current_integral_gain_q_per_s2 = 33800.0f; /* the same on the q axis */
    cfg.motor.detent_torque_Nm = 0.05f;
    cfg.gains.detent_fade_speed_rad_s = 166.7f; /* the designer's: 4 p w_f = 2 x 2000 rad/s, p = 6 */
    cfg.detection.max_realignments = 2u;
    cfg.timing.computational_delay_periods = 1u;
    cfg.standstill.hold_current_A = 7.5f;
    cfg.standstill.vector_speed_rad_s = 2.0f; /* the low-speed drive below 2 rad/s */
    cfg.inverter.ripple_dead_zone = true;     /* the compensation's ripple dead zone */
    cfg.field_weakening.max_current_A = 7.0f;
    cfg.field_weakening.modulation = 0.9f;
    cfg.field_weakening.gain_A_per_s = 7850.0f;
    return cfg;
}

#endif /* PMSTEP_TEST_CONFIGS_H */
