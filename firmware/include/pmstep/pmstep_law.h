/**
 * @file pmstep_law.h
 * @brief Adaptive speed and current law of controller (6) (and (13) with a known
 *        load): i_q*, its derivative, phi_d, phi_q, u_d, u_q and the inverse Park
 *        transform with the estimated angle (c-hat, s-hat).
 *
 * sat_kappa(x) = x / sqrt(1 + (x/kappa)^2): smooth, odd, |sat| < kappa, slope 1 at 0.
 * It needs one square root (a single FPU instruction on Cortex-M4F) and no libm call.
 */
#ifndef PMSTEP_LAW_H
#define PMSTEP_LAW_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    float j_over_km;          /**< J/k_M */
    float f_over_j_per_s;     /**< F/J */
    float inv_j;              /**< 1/J */
    float speed_gain_per_s;   /**< k_w */
    float current_gain_per_s; /**< K_i */
    float r_over_l_per_s;     /**< R/L */
    float km_over_l;          /**< k_M/L, A/rad */
    float inductance_H;       /**< L */
    float pole_pairs;         /**< p */
    float kappa_rad_s;        /**< kappa */
    /* The voltage's angle and length (see pmstep_law_voltages), as polynomials in w-hat:
     * (1 - x^2/6)(cos d, sin d), d = p T_s (delay + 1/2) w-hat, x = p T_s w-hat / 2, is
     * (1 + c2 w^2 + c4 w^4, w (s1 + s3 w^2)) to fourth and third order. */
    float turn_cos_w2;        /**< c2 = -(a^2/2 + k), a = p T_s (delay + 1/2), k = (p T_s)^2/24 */
    float turn_cos_w4;        /**< c4 = a^4/24 + k a^2/2 */
    float turn_sin_w1;        /**< s1 = a */
    float turn_sin_w3;        /**< s3 = -(a^3/6 + k a) */
    bool linear_speed_term;   /**< Remark 1 (13): k_w (w-hat - w*) without saturation (last: the floats
                                   before it are checked as a run) */
} pmstep_law_coeffs_t;

/** References at one sample. */
typedef struct {
    float speed_ref_rad_s, speed_ref_rate_rad_s2, speed_ref_accel_rad_s3; /**< w*, w*', w*'' */
    float i_d_ref_A, i_d_ref_rate_A_s;                          /**< i_d*, i_d*' */
} pmstep_law_refs_t;

/** Coefficients for the gains and mechanics of @p cfg and the electrical model @p model. */
void pmstep_law_coeffs_init(pmstep_law_coeffs_t *coeffs, const pmstep_config_t *cfg,
                            const pmstep_electrical_t *model);

/** Smooth saturation and its derivative. */
void pmstep_sat(float x, float kappa, float *sat, float *sat_slope);

/** Park transform with (c, s): d = c a + s b, q = -s a + c b. */
void pmstep_park(float cos_hat, float sin_hat, float a, float b, float *d, float *q);

/** i_q* = (J/k_M)[(F/J) w* - k_w sat(w-hat - w*) + T/J + w*'], T = T_L-hat or T_L*. */
float pmstep_law_iq_ref(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs,
                        float speed_hat_rad_s, float load_Nm);

/** i_q*' = (J/k_M)[(F/J) w*' - k_w sat'(e)(w-hat' - w*') + T'/J + w*'']. */
float pmstep_law_iq_ref_rate(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs,
                             float speed_hat_rad_s, float speed_hat_rate, float load_rate);

/**
 * phi_d = -(R/L) i_d* + p w-hat i_q - i_d*',  phi_q = -(R/L) i_q* - p w-hat i_d - (k_M/L) w-hat - i_q*',
 * u_d = L[-phi_d - K_i (i_d - i_d*)], u_q = L[-phi_q - K_i (i_q - i_q*)],
 * u_a = c u_d - s u_q, u_b = s u_d + c u_q, with (c, s) the estimate turned by the angle the
 * rotor turns from the sample to the middle of the period the voltage acts in (p w-hat T_s
 * (delay + 1/2)) and (u_d, u_q) shortened by 1 - x^2/6, x = p w-hat T_s/2. A voltage held in the
 * stator frame over a period, placed there, drives the currents at the samples as the continuous
 * law's (u_d, u_q) would times 1 + x^2/6 + O(x^3) (steady state of the sampled R-L circuit in the
 * rotor frame; firmware/design/DESIGN.md), so the step stays accurate at p w T_s ~ 0.3 rad.
 */
void pmstep_law_voltages(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs,
                         float cos_hat, float sin_hat, float i_d_A, float i_q_A,
                         float speed_hat_rad_s, float i_q_ref_A, float i_q_ref_rate,
                         float *u_a_V, float *u_b_V);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_LAW_H */
