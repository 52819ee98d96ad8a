/**
 * @file pil_record.h
 * @brief The target's output file of the PIL replay (the record it replays, and its
 *        codec, are sil/include/sil/record.h), shared by the replay image (target) and
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

#include "sil/record.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PIL_OUTPUT_MAGIC 0x4F534D50u /* "PMSO" */
#define PIL_OUTPUT_END \
    0xFFFFFFFFu /* cannot start a period: word 0 is u_a's bits, never all-ones (a NaN) from the core */

/** Names of the output words, for reports. */
static inline const char *pil_output_word_name(unsigned k)
{
    static const char *const names[SIL_RECORD_OUT_WORDS] = {
        "u_a_V",       "u_b_V",      "bridge_enable", "voltage_limited", "mode",
        "fault",       "fault_step", "cos_hat",       "sin_hat",         "speed_hat_rad_s",
        "load_hat_Nm", "i_a_hat_A",  "i_b_hat_A",     "speed_ref_rad_s", "speed_ref_rate_rad_s2",
        "i_d_A",       "i_q_A",      "i_d_ref_A",     "i_q_ref_A"};
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
