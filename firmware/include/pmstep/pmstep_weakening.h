/**
 * @file pmstep_weakening.h
 * @brief Field weakening in RUN (pmstep_field_weakening_config_t): a negative i_d* that keeps the
 *        law's voltage within the bus, so that the motor turns faster than the speed at which its
 *        back EMF and its winding's drop fill the bus with i_d = 0.
 *
 * In the rotor frame (2) gives, in steady state, u_d = R i_d - p w L i_q and
 * u_q = R i_q + p w L i_d + k_M w: a negative i_d takes p w L |i_d| off u_q, the back EMF's side.
 * Every PMSTEP_DETECTION_DECIMATION periods the law's voltage (u_a, u_b), before the dead-time
 * compensation and the bus limit, is compared with the share m of the measured bus V it may take:
 *   e = (m^2 V^2 - |u|^2) / max(m^2 V^2, |u|^2)   (within [-1, 1], no division by 0 unless both are 0),
 * and the weakening current integrates it:
 *   i_w <- min(0, max(-I_w, i_w + g T_c e)),   T_c the check period,
 * where a lower i_d lowers |u|: d|u|^2/di_d = 2 (R u_d + p w L u_q) > 0 in the estimate's frame.
 * Where it does not (at low speed, an excess of the winding's drop R i, which a negative i_d only
 * adds to), an excess takes i_w back toward 0: e is taken as |e|.
 * i_d*'s target is the commanded i_d plus i_w; the reference filter H(s) of i_d* smooths the
 * steps and gives the law (6) the derivative i_d*' it takes. Near m V the loop's rate is
 * g 2 p w L / (m V) (d|u|/di_d = p w L where u_q dominates): the designer sets g from the speed at
 * which weakening starts and the reference filter's bandwidth (docs/design/22-field-weakening.md).
 * I_w bounds the weakening: the designer keeps it within half the magnet's flux in current,
 * k_M / (2 p L), and the rated current's circle with room for the q current.
 */
#ifndef PMSTEP_WEAKENING_H
#define PMSTEP_WEAKENING_H

#include <stdbool.h>

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Constants derived from the configuration. */
typedef struct {
    float modulation_squared; /**< m^2 */
    float step_A;             /**< g T_c: the weakening current's change per check at e = 1 */
    float max_current_A;      /**< I_w; 0 = off */
} pmstep_weakening_coeffs_t;

/** Field weakening's state in RUN. */
typedef struct {
    float command_A;   /**< the commanded i_d* target (pmstep_set_id_target) */
    float weakening_A; /**< i_w, within [-I_w, 0] */
} pmstep_weakening_t;

/** Coefficients for @p cfg (its field_weakening settings and period). */
void pmstep_weakening_coeffs_init(pmstep_weakening_coeffs_t *coeffs, const pmstep_config_t *cfg);

/**
 * One check: i_w from the law's voltage against the bus. A non-finite voltage leaves i_w as it was.
 * @param[in,out] weakening      the command and i_w
 * @param[in]     coeffs         from pmstep_weakening_coeffs_init()
 * @param[in]     u_a_V          the law's voltage, phase a (before compensation and bus limit)
 * @param[in]     u_b_V          the same, phase b
 * @param[in]     bus_voltage_V  the measured bus
 * @param[in]     helps          a lower i_d lowers |u| at this operating point (pmstep_weakening_helps());
 *                               where it does not, an excess takes i_w back toward 0 as a margin does
 * @return the new i_d* target: the command plus i_w
 */
float pmstep_weakening_update(pmstep_weakening_t *weakening, const pmstep_weakening_coeffs_t *coeffs, float u_a_V,
                              float u_b_V, float bus_voltage_V, bool helps);

/**
 * Whether a lower i_d lowers |u|: d|u|^2 / d i_d = 2 (R u_d + p w L u_q) > 0, tested as
 * (R/L) u_d + p w u_q > 0.
 * @param r_over_l_per_s  R/L of the model
 * @param pole_pairs      p
 * @param speed_rad_s     the estimated speed w-hat
 * @param u_d_V           the law's voltage in the estimate's frame, d axis
 * @param u_q_V           the same, q axis
 */
bool pmstep_weakening_helps(float r_over_l_per_s, float pole_pairs, float speed_rad_s, float u_d_V, float u_q_V);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_WEAKENING_H */
