/**
 * @file pmstep_angle.h
 * @brief Rotor angle reconstruction from current integrals, controller (6):
 *   c-hat = -(L p / k_M)(i_a - i_a(t_c) - phi1) + 1,  phi1' = -(R/L) i_a + u_a/L
 *   s-hat = -(L p / k_M)(i_b - i_b(t_c) - phi2),      phi2' = -(R/L) i_b + u_b/L
 * with phi1(t_c) = phi2(t_c) = 0. Each period the applied (zero-order-held)
 * voltage is integrated exactly and the sampled current by the trapezoid rule;
 * the sums are compensated (Kahan) so float32 round-off does not drift.
 *
 * Drift-free option (not in the paper): (L/p)(c-hat, s-hat) k_M is the rotor flux
 * estimated by integrating u - R i, whose true magnitude is k_M/p. Offsets and
 * parameter errors make the open integral drift off that circle; the correction
 *   phi1 += g T_s c-hat e / (L p/k_M),  phi2 += g T_s s-hat e / (L p/k_M),  e = 1 - c-hat^2 - s-hat^2
 * pulls (c-hat, s-hat) back to the unit circle at the rate g (1/s), as the
 * gradient flux observers of PMSM sensorless control do with the flux magnitude.
 */
#ifndef PMSTEP_ANGLE_H
#define PMSTEP_ANGLE_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    float phi_a;            /**< phi1, A */
    float phi_b;            /**< phi2, A */
    float phi_a_compensation; /**< Kahan running compensation of phi1 */
    float phi_b_compensation; /**< Kahan running compensation of phi2 */
    float i_a_start_A;      /**< i_a(t_c) */
    float i_b_start_A;      /**< i_b(t_c) */
    float i_a_prev_A;       /**< i_a at the previous sample */
    float i_b_prev_A;       /**< i_b at the previous sample */
} pmstep_angle_t;

/** Constants derived once from the configuration. */
typedef struct {
    float voltage_gain;     /**< T_s / L, A per V */
    float current_gain;     /**< R T_s / (2 L), trapezoid weight */
    float flux_to_angle;    /**< L p / k_M, per A */
    float correction_gain;  /**< g T_s / flux_to_angle of the drift-free option (0 = paper's method), A */
} pmstep_angle_coeffs_t;

/** Coefficients for the period and pole pairs of @p cfg and the electrical model @p model. */
void pmstep_angle_coeffs_init(pmstep_angle_coeffs_t *coeffs, const pmstep_config_t *cfg,
                              const pmstep_electrical_t *model);

/** Starts the integrals at t_c: phi = 0, remembers i(t_c). */
void pmstep_angle_start(pmstep_angle_t *angle, float i_a_A, float i_b_A);

/**
 * Integrates phi1, phi2 over the period that just ended.
 * @param[in] i_a_A, i_b_A   currents sampled at the end of the period
 * @param[in] u_a_V, u_b_V   voltages applied during the period
 */
void pmstep_angle_update(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs,
                         float i_a_A, float i_b_A, float u_a_V, float u_b_V);

/** c-hat and s-hat for the currents sampled now (the same as given to the last update). */
void pmstep_angle_estimate(const pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs,
                           float i_a_A, float i_b_A, float *cos_hat, float *sin_hat);

/**
 * Drift-free option: moves phi1, phi2 so the next estimate is pulled onto the unit
 * circle (see above). No effect with correction_gain = 0.
 * @param[in] cos_hat, sin_hat  the estimate of this period
 */
void pmstep_angle_correct(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat);

/** Moves phi1, phi2 (compensations cleared) so that the estimate for the last sampled currents
 *  (those of the last update) is (@p cos_hat, @p sin_hat). */
void pmstep_angle_set(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_ANGLE_H */
