/**
 * @file record.h
 * @brief The record of a SIL run and its codec: written by the runner
 *        (pmstep-sil --record), read by the PIL replay on the target and by the
 *        host comparison tool. Header-only C99; the one place the word layout lives.
 */
#ifndef SIL_RECORD_H
#define SIL_RECORD_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "pmstep/pmstep.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Record of a run, for replaying the core's inputs on a target (processor in the
 * loop, tests/pil/). The file is a stream of little-endian 32-bit words; a float
 * is stored as its IEEE-754 binary32 bit pattern, so a replay sees the very bits
 * the host core saw.
 *
 *   header  SIL_RECORD_MAGIC, SIL_RECORD_VERSION, SIL_RECORD_CONFIG_WORDS,
 *           SIL_RECORD_IN_WORDS, SIL_RECORD_OUT_WORDS,
 *           the pmstep_config_t fields in declaration order (SIL_RECORD_CONFIG_WORDS
 *           words: float bits, int32_t/uint32_t as integers, bool as 0/1),
 *           i_d* (float, A) given to pmstep_set_id_target()
 *   entries a tag word, then its payload:
 *     SIL_RECORD_TAG_SPEED_TARGET  target (float, rad/s), ramp rate (float, rad/s^2):
 *                                  a pmstep_set_speed_target() call before the next step
 *     SIL_RECORD_TAG_PERIOD        the step's input, pmstep_meas_t (SIL_RECORD_IN_* order),
 *                                  then its output, pmstep_output_t (SIL_RECORD_OUT_* order)
 *     SIL_RECORD_TAG_END           the number of periods
 *
 * The run it records: pmstep_init(config), pmstep_set_id_target(i_d*), pmstep_start(),
 * then the entries in order.
 */
#define SIL_RECORD_MAGIC 0x52534D50u /* "PMSR" */
#define SIL_RECORD_VERSION \
    16u /* 2: calibration, commissioning, angle, detection; 3: voltage bias; 4: residual;
                                 5: identification of J and F; 6: phase-voltage sensing; 7: standstill hold;
                                 8: low-speed drive; 9: the compensation's ripple dead zone;
                                 10: detent torque, current integral gain, detent fade;
                                 11: s-alignment's lead-in; 12: the q axis's current integral gain;
                                 13: the back-EMF angle correction; 14: the angle smoothing, the
                                 standstill's stops-only vector; 15: the transient observer boost;
                                 16: the rated current and the measurement ranges */
#define SIL_RECORD_CONFIG_WORDS 61u
#define SIL_RECORD_TAG_SPEED_TARGET 1u
#define SIL_RECORD_TAG_PERIOD 2u
#define SIL_RECORD_TAG_END 3u

/** Word order of a period's input (pmstep_meas_t). */
enum {
    SIL_RECORD_IN_I_A = 0,
    SIL_RECORD_IN_I_B,
    SIL_RECORD_IN_BUS,
    SIL_RECORD_IN_LOAD,
    SIL_RECORD_IN_U_A,
    SIL_RECORD_IN_U_B,
    SIL_RECORD_IN_WORDS
};

/** Word order of a period's output (pmstep_output_t); integers and bools as integers. */
enum {
    SIL_RECORD_OUT_U_A = 0,
    SIL_RECORD_OUT_U_B,
    SIL_RECORD_OUT_BRIDGE_ENABLE,
    SIL_RECORD_OUT_VOLTAGE_LIMITED,
    SIL_RECORD_OUT_MODE,
    SIL_RECORD_OUT_FAULT,
    SIL_RECORD_OUT_FAULT_STEP,
    SIL_RECORD_OUT_COS_HAT,
    SIL_RECORD_OUT_SIN_HAT,
    SIL_RECORD_OUT_SPEED_HAT,
    SIL_RECORD_OUT_LOAD_HAT,
    SIL_RECORD_OUT_I_A_HAT,
    SIL_RECORD_OUT_I_B_HAT,
    SIL_RECORD_OUT_SPEED_REF,
    SIL_RECORD_OUT_SPEED_REF_DOT,
    SIL_RECORD_OUT_I_D,
    SIL_RECORD_OUT_I_Q,
    SIL_RECORD_OUT_I_D_REF,
    SIL_RECORD_OUT_I_Q_REF,
    SIL_RECORD_OUT_WORDS
};

/** Words of the header (fixed words, configuration, i_d*) and of one period's entry (without its tag). */
#define SIL_RECORD_HEADER_WORDS (5u + SIL_RECORD_CONFIG_WORDS + 1u)
#define SIL_RECORD_PERIOD_WORDS ((uint32_t)SIL_RECORD_IN_WORDS + (uint32_t)SIL_RECORD_OUT_WORDS)
/** Longest run of words read or written at once. */
#define SIL_RECORD_MAX_WORDS \
    (SIL_RECORD_HEADER_WORDS > 1u + SIL_RECORD_PERIOD_WORDS ? SIL_RECORD_HEADER_WORDS : 1u + SIL_RECORD_PERIOD_WORDS)

static inline uint32_t sil_record_le32(const unsigned char *b)
{
    return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);
}

static inline void sil_record_put_le32(unsigned char *b, uint32_t w)
{
    b[0] = (unsigned char)(w & 0xFFu);
    b[1] = (unsigned char)((w >> 8) & 0xFFu);
    b[2] = (unsigned char)((w >> 16) & 0xFFu);
    b[3] = (unsigned char)((w >> 24) & 0xFFu);
}

static inline float sil_record_float(uint32_t w)
{
    float x;
    memcpy(&x, &w, sizeof x);
    return x;
}

static inline uint32_t sil_record_bits(float x)
{
    uint32_t w;
    memcpy(&w, &x, sizeof w);
    return w;
}

/** Checks the fixed header words; @return 0 when the record is one this code reads. */
static inline int sil_record_check_header(const uint32_t *w)
{
    return (w[0] == SIL_RECORD_MAGIC && w[1] == SIL_RECORD_VERSION && w[2] == SIL_RECORD_CONFIG_WORDS
            && w[3] == (uint32_t)SIL_RECORD_IN_WORDS && w[4] == (uint32_t)SIL_RECORD_OUT_WORDS)
               ? 0
               : -1;
}

/** The configuration in the record header (words 5 ..). */
static inline void sil_record_config_from_words(const uint32_t *w, pmstep_config_t *c)
{
    c->motor.resistance_Ohm = sil_record_float(w[0]);
    c->motor.inductance_H = sil_record_float(w[1]);
    c->motor.inertia_kgm2 = sil_record_float(w[2]);
    c->motor.friction_Nms_rad = sil_record_float(w[3]);
    c->motor.torque_constant_Nm_A = sil_record_float(w[4]);
    c->motor.pole_pairs = (int32_t)w[5];
    c->timing.period_s = sil_record_float(w[6]);
    c->timing.computational_delay_periods = w[7];
    c->alignment.s_align_time_s = sil_record_float(w[8]);
    c->alignment.c_align_time_s = sil_record_float(w[9]);
    c->alignment.s_align_voltage_V = sil_record_float(w[10]);
    c->alignment.c_align_voltage_V = sil_record_float(w[11]);
    c->gains.speed_gain_per_s = sil_record_float(w[12]);
    c->gains.observer_gain_per_s = sil_record_float(w[13]);
    c->gains.current_gain_per_s = sil_record_float(w[14]);
    c->gains.adapt_gamma = sil_record_float(w[15]);
    c->gains.adapt_lambda = sil_record_float(w[16]);
    c->gains.adapt_r = sil_record_float(w[17]);
    c->gains.sat_kappa_rad_s = sil_record_float(w[18]);
    c->gains.reference_bandwidth_rad_s = sil_record_float(w[19]);
    c->known_load_mode = w[20] != 0u;
    c->limits.max_phase_current_A = sil_record_float(w[21]);
    c->limits.min_bus_voltage_V = sil_record_float(w[22]);
    c->limits.max_bus_voltage_V = sil_record_float(w[23]);
    c->commissioning.offset_calibration_time_s = sil_record_float(w[24]);
    c->commissioning.alignment_offset_calibration = w[25] != 0u;
    c->commissioning.steady_state_window_s = sil_record_float(w[26]);
    c->commissioning.inductance_window_s = sil_record_float(w[27]);
    c->commissioning.use_measured_resistance = w[28] != 0u;
    c->commissioning.use_measured_inductance = w[29] != 0u;
    c->commissioning.use_measured_torque_constant = w[30] != 0u;
    c->commissioning.voltage_bias_level_fraction = sil_record_float(w[31]);
    c->inverter.dead_time_s = sil_record_float(w[32]);
    c->inverter.dead_time_current_band_A = sil_record_float(w[33]);
    c->gains.angle_correction_gain_per_s = sil_record_float(w[34]);
    c->detection.angle_magnitude_bound = sil_record_float(w[35]);
    c->detection.speed_consistency_bound_rad_s = sil_record_float(w[36]);
    c->detection.stall_speed_error_rad_s = sil_record_float(w[37]);
    c->detection.observer_residual_bound_A = sil_record_float(w[38]);
    c->detection.persistence_s = sil_record_float(w[39]);
    c->detection.max_realignments = w[40];
    c->commissioning.identification_time_s = sil_record_float(w[41]);
    c->commissioning.identification_min_speed_rad_s = sil_record_float(w[42]);
    c->commissioning.use_identified_mechanics = w[43] != 0u;
    c->inverter.phase_voltage_sensing = w[44] != 0u;
    c->standstill.hold_current_A = sil_record_float(w[45]);
    c->standstill.vector_speed_rad_s = sil_record_float(w[46]);
    c->inverter.ripple_dead_zone = w[47] != 0u;
    c->motor.detent_torque_Nm = sil_record_float(w[48]);
    c->gains.current_integral_gain_per_s2 = sil_record_float(w[49]);
    c->gains.detent_fade_speed_rad_s = sil_record_float(w[50]);
    c->alignment.s_lead_in_time_s = sil_record_float(w[51]);
    c->gains.current_integral_gain_q_per_s2 = sil_record_float(w[52]);
    c->gains.emf_angle_gain_per_s = sil_record_float(w[53]);
    c->gains.emf_angle_corner_rad_s = sil_record_float(w[54]);
    c->gains.angle_smoothing = sil_record_float(w[55]);
    c->standstill.stops_only = w[56] != 0u;
    c->gains.transient_observer_boost = sil_record_float(w[57]);
    c->motor.rated_current_A = sil_record_float(w[58]);
    c->limits.current_sense_range_A = sil_record_float(w[59]);
    c->limits.bus_sense_range_V = sil_record_float(w[60]);
}

static inline void sil_record_meas_from_words(const uint32_t *w, pmstep_meas_t *m)
{
    m->i_a_A = sil_record_float(w[SIL_RECORD_IN_I_A]);
    m->i_b_A = sil_record_float(w[SIL_RECORD_IN_I_B]);
    m->bus_voltage_V = sil_record_float(w[SIL_RECORD_IN_BUS]);
    m->load_torque_Nm = sil_record_float(w[SIL_RECORD_IN_LOAD]);
    m->phase_voltage_a_V = sil_record_float(w[SIL_RECORD_IN_U_A]);
    m->phase_voltage_b_V = sil_record_float(w[SIL_RECORD_IN_U_B]);
}

static inline void sil_record_output_to_words(const pmstep_output_t *o, uint32_t *w)
{
    w[SIL_RECORD_OUT_U_A] = sil_record_bits(o->u_a_V);
    w[SIL_RECORD_OUT_U_B] = sil_record_bits(o->u_b_V);
    w[SIL_RECORD_OUT_BRIDGE_ENABLE] = o->bridge_enable ? 1u : 0u;
    w[SIL_RECORD_OUT_VOLTAGE_LIMITED] = o->voltage_limited ? 1u : 0u;
    w[SIL_RECORD_OUT_MODE] = (uint32_t)o->mode;
    w[SIL_RECORD_OUT_FAULT] = (uint32_t)o->fault;
    w[SIL_RECORD_OUT_FAULT_STEP] = o->fault_step;
    w[SIL_RECORD_OUT_COS_HAT] = sil_record_bits(o->cos_hat);
    w[SIL_RECORD_OUT_SIN_HAT] = sil_record_bits(o->sin_hat);
    w[SIL_RECORD_OUT_SPEED_HAT] = sil_record_bits(o->speed_hat_rad_s);
    w[SIL_RECORD_OUT_LOAD_HAT] = sil_record_bits(o->load_hat_Nm);
    w[SIL_RECORD_OUT_I_A_HAT] = sil_record_bits(o->i_a_hat_A);
    w[SIL_RECORD_OUT_I_B_HAT] = sil_record_bits(o->i_b_hat_A);
    w[SIL_RECORD_OUT_SPEED_REF] = sil_record_bits(o->speed_ref_rad_s);
    w[SIL_RECORD_OUT_SPEED_REF_DOT] = sil_record_bits(o->speed_ref_rate_rad_s2);
    w[SIL_RECORD_OUT_I_D] = sil_record_bits(o->i_d_A);
    w[SIL_RECORD_OUT_I_Q] = sil_record_bits(o->i_q_A);
    w[SIL_RECORD_OUT_I_D_REF] = sil_record_bits(o->i_d_ref_A);
    w[SIL_RECORD_OUT_I_Q_REF] = sil_record_bits(o->i_q_ref_A);
}

/** The configuration as the record header's words (pmstep_config_t fields in declaration order). */
static inline void sil_record_config_to_words(const pmstep_config_t *c, uint32_t *w)
{
    w[0] = sil_record_bits(c->motor.resistance_Ohm);
    w[1] = sil_record_bits(c->motor.inductance_H);
    w[2] = sil_record_bits(c->motor.inertia_kgm2);
    w[3] = sil_record_bits(c->motor.friction_Nms_rad);
    w[4] = sil_record_bits(c->motor.torque_constant_Nm_A);
    w[5] = (uint32_t)c->motor.pole_pairs;
    w[6] = sil_record_bits(c->timing.period_s);
    w[7] = c->timing.computational_delay_periods;
    w[8] = sil_record_bits(c->alignment.s_align_time_s);
    w[9] = sil_record_bits(c->alignment.c_align_time_s);
    w[10] = sil_record_bits(c->alignment.s_align_voltage_V);
    w[11] = sil_record_bits(c->alignment.c_align_voltage_V);
    w[12] = sil_record_bits(c->gains.speed_gain_per_s);
    w[13] = sil_record_bits(c->gains.observer_gain_per_s);
    w[14] = sil_record_bits(c->gains.current_gain_per_s);
    w[15] = sil_record_bits(c->gains.adapt_gamma);
    w[16] = sil_record_bits(c->gains.adapt_lambda);
    w[17] = sil_record_bits(c->gains.adapt_r);
    w[18] = sil_record_bits(c->gains.sat_kappa_rad_s);
    w[19] = sil_record_bits(c->gains.reference_bandwidth_rad_s);
    w[20] = c->known_load_mode ? 1u : 0u;
    w[21] = sil_record_bits(c->limits.max_phase_current_A);
    w[22] = sil_record_bits(c->limits.min_bus_voltage_V);
    w[23] = sil_record_bits(c->limits.max_bus_voltage_V);
    w[24] = sil_record_bits(c->commissioning.offset_calibration_time_s);
    w[25] = c->commissioning.alignment_offset_calibration ? 1u : 0u;
    w[26] = sil_record_bits(c->commissioning.steady_state_window_s);
    w[27] = sil_record_bits(c->commissioning.inductance_window_s);
    w[28] = c->commissioning.use_measured_resistance ? 1u : 0u;
    w[29] = c->commissioning.use_measured_inductance ? 1u : 0u;
    w[30] = c->commissioning.use_measured_torque_constant ? 1u : 0u;
    w[31] = sil_record_bits(c->commissioning.voltage_bias_level_fraction);
    w[32] = sil_record_bits(c->inverter.dead_time_s);
    w[33] = sil_record_bits(c->inverter.dead_time_current_band_A);
    w[34] = sil_record_bits(c->gains.angle_correction_gain_per_s);
    w[35] = sil_record_bits(c->detection.angle_magnitude_bound);
    w[36] = sil_record_bits(c->detection.speed_consistency_bound_rad_s);
    w[37] = sil_record_bits(c->detection.stall_speed_error_rad_s);
    w[38] = sil_record_bits(c->detection.observer_residual_bound_A);
    w[39] = sil_record_bits(c->detection.persistence_s);
    w[40] = c->detection.max_realignments;
    w[41] = sil_record_bits(c->commissioning.identification_time_s);
    w[42] = sil_record_bits(c->commissioning.identification_min_speed_rad_s);
    w[43] = c->commissioning.use_identified_mechanics ? 1u : 0u;
    w[44] = c->inverter.phase_voltage_sensing ? 1u : 0u;
    w[45] = sil_record_bits(c->standstill.hold_current_A);
    w[46] = sil_record_bits(c->standstill.vector_speed_rad_s);
    w[47] = c->inverter.ripple_dead_zone ? 1u : 0u;
    w[48] = sil_record_bits(c->motor.detent_torque_Nm);
    w[49] = sil_record_bits(c->gains.current_integral_gain_per_s2);
    w[50] = sil_record_bits(c->gains.detent_fade_speed_rad_s);
    w[51] = sil_record_bits(c->alignment.s_lead_in_time_s);
    w[52] = sil_record_bits(c->gains.current_integral_gain_q_per_s2);
    w[53] = sil_record_bits(c->gains.emf_angle_gain_per_s);
    w[54] = sil_record_bits(c->gains.emf_angle_corner_rad_s);
    w[55] = sil_record_bits(c->gains.angle_smoothing);
    w[56] = c->standstill.stops_only ? 1u : 0u;
    w[57] = sil_record_bits(c->gains.transient_observer_boost);
    w[58] = sil_record_bits(c->motor.rated_current_A);
    w[59] = sil_record_bits(c->limits.current_sense_range_A);
    w[60] = sil_record_bits(c->limits.bus_sense_range_V);
}

static inline void sil_record_meas_to_words(const pmstep_meas_t *m, uint32_t *w)
{
    w[SIL_RECORD_IN_I_A] = sil_record_bits(m->i_a_A);
    w[SIL_RECORD_IN_I_B] = sil_record_bits(m->i_b_A);
    w[SIL_RECORD_IN_BUS] = sil_record_bits(m->bus_voltage_V);
    w[SIL_RECORD_IN_LOAD] = sil_record_bits(m->load_torque_Nm);
    w[SIL_RECORD_IN_U_A] = sil_record_bits(m->phase_voltage_a_V);
    w[SIL_RECORD_IN_U_B] = sil_record_bits(m->phase_voltage_b_V);
}

/** Reads @p n (<= SIL_RECORD_MAX_WORDS) little-endian words. @return 0, or -1 on a short read. */
static inline int sil_record_read_words(FILE *f, uint32_t *w, size_t n)
{
    unsigned char bytes[4u * SIL_RECORD_MAX_WORDS];
    size_t k;
    if (n > SIL_RECORD_MAX_WORDS || fread(bytes, 4u, n, f) != n) {
        return -1;
    }
    for (k = 0; k < n; ++k) {
        w[k] = sil_record_le32(&bytes[4u * k]);
    }
    return 0;
}

/** Writes @p n (<= SIL_RECORD_MAX_WORDS) words little-endian. @return 0, or -1 on a write error. */
static inline int sil_record_write_words(FILE *f, const uint32_t *w, size_t n)
{
    unsigned char bytes[4u * SIL_RECORD_MAX_WORDS];
    size_t k;
    if (n > SIL_RECORD_MAX_WORDS) {
        return -1;
    }
    for (k = 0; k < n; ++k) {
        sil_record_put_le32(&bytes[4u * k], w[k]);
    }
    return fwrite(bytes, 4u, n, f) == n ? 0 : -1;
}

#ifdef __cplusplus
}
#endif

#endif /* SIL_RECORD_H */
