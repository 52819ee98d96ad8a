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
 *
 * Back-EMF option (not in the paper): the correction above only moves the estimate along its
 * radius, so an error in the voltage the integrals take (a dead time's loss around a current's
 * zero crossing) turns the estimate for good. The observer of (6) models the back EMF along
 * (s-hat, -c-hat); with the estimate delta ahead of the rotor its d-axis residual
 * i~_d = c-hat i~_a + s-hat i~_b settles at -k_M w delta / (R + L K_e), so
 *   delta-hat = -(R + L K_e) i~_d w-hat / (k_M (w-hat^2 + w_theta^2))
 * (faded in with the speed: a voltage error dU_d reads as dU_d / (k_M w), large at low speed),
 * and the estimate is turned by -K_theta T_s delta-hat every period. The caller pauses it while the
 * q residual is beyond the detection's bound: in a transient (a load step, w-hat lagging w) the d
 * residual carries the speed error's share too, and on the 17HS4401 at half its top speed a step
 * of half its holding torque turned the estimate 1.5 rad in 4 ms. It pauses too where the
 * unfaded reading (R + L K_e) |i~_d| / (k_M |w-hat|) is beyond PMSTEP_EMF_ANGLE_MAX_READING_RAD:
 * at RUN's start w-hat swings a few rad/s about a still rotor, and 0.3 A of residual read there
 * as an angle turned the estimate 0.1 rad within 10 ms.
 */
#ifndef PMSTEP_ANGLE_H
#define PMSTEP_ANGLE_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The back-EMF option pauses where its reading would put the estimate more than this off (rad). */
#define PMSTEP_EMF_ANGLE_MAX_READING_RAD 0.25f

typedef struct {
    float phi_a;              /**< phi1, A */
    float phi_b;              /**< phi2, A */
    float phi_a_compensation; /**< Kahan running compensation of phi1 */
    float phi_b_compensation; /**< Kahan running compensation of phi2 */
    float i_a_start_A;        /**< i_a(t_c) */
    float i_b_start_A;        /**< i_b(t_c) */
    float i_a_prev_A;         /**< i_a at the previous sample */
    float i_b_prev_A;         /**< i_b at the previous sample */
} pmstep_angle_t;

/** Constants derived once from the configuration. */
typedef struct {
    float voltage_gain;       /**< T_s / L, A per V */
    float current_gain;       /**< R T_s / (2 L), trapezoid weight */
    float flux_to_angle;      /**< L p / k_M, per A */
    float correction_gain;    /**< g T_s / flux_to_angle of the drift-free option (0 = paper's method), A */
    float emf_turn_gain;      /**< K_theta T_s (R + L K_e) / (k_M flux_to_angle) of the back-EMF option (0 = off),
                                 A s / rad per A of residual */
    float emf_corner_squared; /**< w_theta^2, (rad/s)^2 */
} pmstep_angle_coeffs_t;

/** Coefficients for the period and pole pairs of @p cfg and the electrical model @p model. */
void pmstep_angle_coeffs_init(pmstep_angle_coeffs_t *coeffs, const pmstep_config_t *cfg,
                              const pmstep_electrical_t *model);

/** Starts the integrals at t_c: phi = 0, remembers i(t_c). */
void pmstep_angle_start(pmstep_angle_t *angle, float i_a_A, float i_b_A);

/**
 * Integrates phi1, phi2 over the period that just ended.
 * @param[in,out] angle      the flux integrals
 * @param[in] coeffs         from pmstep_angle_coeffs_init()
 * @param[in] i_a_A, i_b_A   currents sampled at the end of the period
 * @param[in] u_a_V, u_b_V   voltages applied during the period
 */
void pmstep_angle_update(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float i_a_A, float i_b_A,
                         float u_a_V, float u_b_V);

/** c-hat and s-hat for the currents sampled now (the same as given to the last update). */
void pmstep_angle_estimate(const pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float i_a_A, float i_b_A,
                           float *cos_hat, float *sin_hat);

/**
 * Drift-free option: moves phi1, phi2 so the next estimate is pulled onto the unit
 * circle (see above). No effect with correction_gain = 0.
 * @param[in,out] angle         the flux integrals
 * @param[in] coeffs            from pmstep_angle_coeffs_init()
 * @param[in] cos_hat, sin_hat  the estimate of this period
 */
void pmstep_angle_correct(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat);

/**
 * Back-EMF option: turns the next estimate toward the back EMF's direction (see above). Call it
 * only with emf_turn_gain > 0.
 * @param[in,out] angle         the flux integrals
 * @param[in] coeffs            from pmstep_angle_coeffs_init()
 * @param[in] cos_hat, sin_hat  the estimate of this period
 * @param[in] i_d_residual_A    the observer's residual of this sample on cos_hat, sin_hat
 * @param[in] speed_hat_rad_s   the observer's speed
 */
void pmstep_angle_follow_emf(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat,
                             float i_d_residual_A, float speed_hat_rad_s);

/** The angle smoothing's gate (rad): a reading this far or further off its prediction is taken as
 *  it is, the prediction having missed a turn (w-hat behind the rotor in a load step: 0.075 rad a
 *  period on the 17HS4401 stopped by half its holding torque at 34.5 rad/s). The current
 *  samples' noise in the estimate, L p / k_M times theirs, is a few thousandths of a radian (0.0042
 *  rad rms on the 17HS4401 at 5 mA), so its largest readings pass unsmoothed as well; a wider
 *  gate smoothed those and lost the 17HS4401's envelope steps (docs/design/16-angle-smoothing.md). */
#define PMSTEP_ANGLE_SMOOTHING_GATE_RAD 0.02f

/** The angle smoothing's state (gains.angle_smoothing): the previous period's estimate. */
typedef struct {
    float cos_hat;
    float sin_hat;
} pmstep_angle_smoother_t;

/** Starts the smoothing from the estimate (@p cos_hat, @p sin_hat). */
void pmstep_angle_smoother_set(pmstep_angle_smoother_t *smoother, float cos_hat, float sin_hat);

/**
 * Angle smoothing (gains.angle_smoothing): the estimate becomes the previous one turned by
 * @p turn_rad, plus (1 - @p share) of this period's reading's difference from it, unless the
 * reading's turn off that prediction is PMSTEP_ANGLE_SMOOTHING_GATE_RAD or more (the reading
 * itself); either is kept as the next period's previous one. The current samples' noise in the
 * estimate goes down by (1 - share) / (1 + share) in power; a speed error w~ turns it
 * p w~ T_s share / (1 - share) behind.
 * @param[in]     share     a in (0, 1)
 * @param[in]     turn_rad  the rotor's turn over the period, p w-hat T_s (electrical rad)
 *                          (pmstep_small_rotation: within 1e-5 at 0.4 rad)
 * @param[in,out] smoother  the previous period's estimate
 * @param[in,out] cos_hat, sin_hat  this period's reading in, its estimate out
 */
void pmstep_angle_smooth(float share, float turn_rad, pmstep_angle_smoother_t *smoother, float *cos_hat,
                         float *sin_hat);

/** Moves phi1, phi2 (compensations cleared) so that the estimate for the last sampled currents
 *  (those of the last update) is (@p cos_hat, @p sin_hat). */
void pmstep_angle_set(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_ANGLE_H */
