/**
 * @file pil_record.h
 * @brief Reading and writing the SIL record (format in sil/include/sil/runner.h)
 *        and the target's output file, shared by the replay image (target) and
 *        the comparison tool (host). Header-only, C99, no platform header.
 *
 * Target output file ("PMSO"): little-endian 32-bit words
 *   PIL_OUTPUT_MAGIC, SIL_RECORD_VERSION, SIL_RECORD_OUT_WORDS,
 *   then SIL_RECORD_OUT_WORDS words per period (SIL_RECORD_OUT_* order),
 *   then PIL_OUTPUT_END and the number of periods.
 */
#ifndef PIL_RECORD_H
#define PIL_RECORD_H

#include <stdint.h>
#include <string.h>

#include "pmstep/pmstep.h"
#include "sil/runner.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PIL_OUTPUT_MAGIC 0x4F534D50u /* "PMSO" */
#define PIL_OUTPUT_END 0xFFFFFFFFu   /* cannot start a period: word 0 is u_a's bits, never all-ones (a NaN) from the core */
#define PIL_RECORD_HEADER_WORDS (5u + SIL_RECORD_CONFIG_WORDS + 1u)
#define PIL_PERIOD_WORDS ((uint32_t)SIL_RECORD_IN_WORDS + (uint32_t)SIL_RECORD_OUT_WORDS)

static inline uint32_t pil_le32(const unsigned char *b)
{
    return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);
}

static inline void pil_put_le32(unsigned char *b, uint32_t w)
{
    b[0] = (unsigned char)(w & 0xFFu);
    b[1] = (unsigned char)((w >> 8) & 0xFFu);
    b[2] = (unsigned char)((w >> 16) & 0xFFu);
    b[3] = (unsigned char)((w >> 24) & 0xFFu);
}

static inline float pil_float(uint32_t w)
{
    float x;
    memcpy(&x, &w, sizeof x);
    return x;
}

static inline uint32_t pil_bits(float x)
{
    uint32_t w;
    memcpy(&w, &x, sizeof w);
    return w;
}

/** Checks the fixed header words; @return 0 when the record is one this code reads. */
static inline int pil_check_record_header(const uint32_t *w)
{
    return (w[0] == SIL_RECORD_MAGIC && w[1] == SIL_RECORD_VERSION && w[2] == SIL_RECORD_CONFIG_WORDS
            && w[3] == (uint32_t)SIL_RECORD_IN_WORDS && w[4] == (uint32_t)SIL_RECORD_OUT_WORDS)
               ? 0
               : -1;
}

/** The configuration in the record header (words 5 ..). */
static inline void pil_config_from_words(const uint32_t *w, pmstep_config_t *c)
{
    c->resistance_ohm = pil_float(w[0]);
    c->inductance_h = pil_float(w[1]);
    c->inertia_kg_m2 = pil_float(w[2]);
    c->friction_nm_s_per_rad = pil_float(w[3]);
    c->torque_constant_nm_per_a = pil_float(w[4]);
    c->pole_pairs = (int32_t)w[5];
    c->period_s = pil_float(w[6]);
    c->computational_delay_periods = w[7];
    c->s_align_time_s = pil_float(w[8]);
    c->c_align_time_s = pil_float(w[9]);
    c->s_align_voltage_v = pil_float(w[10]);
    c->c_align_voltage_v = pil_float(w[11]);
    c->speed_gain_per_s = pil_float(w[12]);
    c->observer_gain_per_s = pil_float(w[13]);
    c->current_gain_per_s = pil_float(w[14]);
    c->adapt_gamma = pil_float(w[15]);
    c->adapt_lambda = pil_float(w[16]);
    c->adapt_r = pil_float(w[17]);
    c->sat_kappa_rad_per_s = pil_float(w[18]);
    c->reference_bandwidth_rad_per_s = pil_float(w[19]);
    c->known_load_mode = w[20] != 0u;
    c->max_phase_current_a = pil_float(w[21]);
    c->min_bus_voltage_v = pil_float(w[22]);
    c->max_bus_voltage_v = pil_float(w[23]);
}

static inline void pil_meas_from_words(const uint32_t *w, pmstep_meas_t *m)
{
    m->i_a_a = pil_float(w[SIL_RECORD_IN_I_A]);
    m->i_b_a = pil_float(w[SIL_RECORD_IN_I_B]);
    m->bus_voltage_v = pil_float(w[SIL_RECORD_IN_BUS]);
    m->load_torque_nm = pil_float(w[SIL_RECORD_IN_LOAD]);
}

static inline void pil_output_to_words(const pmstep_output_t *o, uint32_t *w)
{
    w[SIL_RECORD_OUT_U_A] = pil_bits(o->u_a_v);
    w[SIL_RECORD_OUT_U_B] = pil_bits(o->u_b_v);
    w[SIL_RECORD_OUT_BRIDGE_ENABLE] = o->bridge_enable ? 1u : 0u;
    w[SIL_RECORD_OUT_VOLTAGE_LIMITED] = o->voltage_limited ? 1u : 0u;
    w[SIL_RECORD_OUT_MODE] = (uint32_t)o->mode;
    w[SIL_RECORD_OUT_FAULT] = (uint32_t)o->fault;
    w[SIL_RECORD_OUT_FAULT_STEP] = o->fault_step;
    w[SIL_RECORD_OUT_COS_HAT] = pil_bits(o->cos_hat);
    w[SIL_RECORD_OUT_SIN_HAT] = pil_bits(o->sin_hat);
    w[SIL_RECORD_OUT_SPEED_HAT] = pil_bits(o->speed_hat_rad_s);
    w[SIL_RECORD_OUT_LOAD_HAT] = pil_bits(o->load_hat_nm);
    w[SIL_RECORD_OUT_I_A_HAT] = pil_bits(o->i_a_hat_a);
    w[SIL_RECORD_OUT_I_B_HAT] = pil_bits(o->i_b_hat_a);
    w[SIL_RECORD_OUT_SPEED_REF] = pil_bits(o->speed_ref_rad_s);
    w[SIL_RECORD_OUT_SPEED_REF_DOT] = pil_bits(o->speed_ref_dot_rad_s2);
    w[SIL_RECORD_OUT_I_D] = pil_bits(o->i_d_a);
    w[SIL_RECORD_OUT_I_Q] = pil_bits(o->i_q_a);
    w[SIL_RECORD_OUT_I_D_REF] = pil_bits(o->i_d_ref_a);
    w[SIL_RECORD_OUT_I_Q_REF] = pil_bits(o->i_q_ref_a);
}

/** Names of the output words, for reports. */
static inline const char *pil_output_word_name(unsigned k)
{
    static const char *const names[SIL_RECORD_OUT_WORDS] = {
        "u_a_v", "u_b_v", "bridge_enable", "voltage_limited", "mode", "fault", "fault_step",
        "cos_hat", "sin_hat", "speed_hat_rad_s", "load_hat_nm", "i_a_hat_a", "i_b_hat_a",
        "speed_ref_rad_s", "speed_ref_dot_rad_s2", "i_d_a", "i_q_a", "i_d_ref_a", "i_q_ref_a"};
    return k < (unsigned)SIL_RECORD_OUT_WORDS ? names[k] : "?";
}

/** Whether output word @p k holds a float (else an integer or a bool). */
static inline int pil_output_word_is_float(unsigned k)
{
    return !(k == SIL_RECORD_OUT_BRIDGE_ENABLE || k == SIL_RECORD_OUT_VOLTAGE_LIMITED || k == SIL_RECORD_OUT_MODE
             || k == SIL_RECORD_OUT_FAULT || k == SIL_RECORD_OUT_FAULT_STEP);
}

#ifdef __cplusplus
}
#endif

#endif /* PIL_RECORD_H */
