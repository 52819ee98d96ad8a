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
#include "pmstep/pmstep_rotation.h"

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
    float turn_cos_w2;                    /**< c2 = -(a^2/2 + k), a = p T_s (delay + 1/2), k = (p T_s)^2/24 */
    float turn_cos_w4;                    /**< c4 = a^4/24 + k a^2/2 */
    float turn_sin_w1;                    /**< s1 = a */
    float turn_sin_w3;                    /**< s3 = -(a^3/6 + k a) */
    float current_integral_gain_per_s2;   /**< K_I of the PI current loop, d axis (0 = the paper's law) */
    float current_integral_gain_q_per_s2; /**< K_I,q, its q axis (0 = none) */
    float detent_torque_Nm;               /**< T_d of the detent model (0 = none) */
    float detent_order;                   /**< 4 p: the detent's harmonic of the mechanical angle */
    bool linear_speed_term;               /**< Remark 1 (13): k_w (w-hat - w*) without saturation (last: the floats
                                   before it are checked as a run) */
} pmstep_law_coeffs_t;

/** References at one sample. */
typedef struct {
    float speed_ref_rad_s, speed_ref_rate_rad_s2, speed_ref_accel_rad_s3; /**< w*, w*', w*'' */
    float i_d_ref_A, i_d_ref_rate_A_s;                                    /**< i_d*, i_d*' */
} pmstep_law_refs_t;

/** Integrals of the current errors, the PI current loop's state (zero with K_I = 0). */
typedef struct {
    float i_d_error_integral_As; /**< integral of i_d - i_d* */
    float i_q_error_integral_As; /**< integral of i_q - i_q* */
} pmstep_law_integral_t;

/** The detent torque the model expects at the estimated angle, and its rate. */
typedef struct {
    float torque_Nm; /**< -T_d sin(4 p theta-hat) */
    float rate_Nm_s; /**< its derivative along w-hat: -4 p T_d w-hat cos(4 p theta-hat) */
} pmstep_detent_t;

/**
 * Detent torque at (c-hat, s-hat): sin 4x = 2 sin 2x cos 2x with sin 2x = 2 c s and
 * cos 2x = c^2 - s^2 (no libm call). Zero when the model has no detent torque.
 */
static inline pmstep_detent_t pmstep_law_detent(const pmstep_law_coeffs_t *coeffs, float cos_hat, float sin_hat,
                                                float speed_hat_rad_s)
{
    pmstep_detent_t detent = {0.0f, 0.0f};
    if (coeffs->detent_torque_Nm > 0.0f) {
        const float cos_2x = cos_hat * cos_hat - sin_hat * sin_hat;
        const float sin_2x = 2.0f * cos_hat * sin_hat;
        detent.torque_Nm = -coeffs->detent_torque_Nm * 2.0f * sin_2x * cos_2x;
        detent.rate_Nm_s =
            -coeffs->detent_torque_Nm * coeffs->detent_order * speed_hat_rad_s * (cos_2x * cos_2x - sin_2x * sin_2x);
    }
    return detent;
}

/**
 * The detent torque's compensation faded with the speed (gains.detent_fade_speed_rad_s, w_f; none
 * with 0): g = w_f^2 / (w_f^2 + w-hat^2), the rate with g's own, dg/dw-hat = -2 w-hat g /
 * (w_f^2 + w-hat^2), along the acceleration given (the reference's: w-hat' is not known yet, and
 * w-hat follows w*). Beyond w_f the compensation's frequency 4 p w passes the current loop's
 * reach, the angle error enters it 4p-fold, and the inertia filters the torque.
 */
void pmstep_law_fade_detent(float fade_speed_rad_s, float speed_hat_rad_s, float accel_rad_s2, pmstep_detent_t *detent);

/**
 * (c-hat, s-hat) turned from the sample to the middle of the period the voltage acts in,
 * p w-hat T_s (delay + 1/2), and shortened for the hold by 1 - x^2/6 (see pmstep_law_voltages):
 * the turn as (cos, sin) polynomials in w-hat.
 */
static inline void pmstep_law_acting_angle(const pmstep_law_coeffs_t *coeffs, float cos_hat, float sin_hat,
                                           float speed_hat_rad_s, float *cos_act, float *sin_act)
{
    const float w2 = speed_hat_rad_s * speed_hat_rad_s;
    const float cos_turn = 1.0f + w2 * (coeffs->turn_cos_w2 + w2 * coeffs->turn_cos_w4);
    const float sin_turn = speed_hat_rad_s * (coeffs->turn_sin_w1 + w2 * coeffs->turn_sin_w3);
    pmstep_turn(cos_hat, sin_hat, cos_turn, sin_turn, cos_act, sin_act);
}

/** Coefficients for the gains and mechanics of @p cfg and the electrical model @p model. */
void pmstep_law_coeffs_init(pmstep_law_coeffs_t *coeffs, const pmstep_config_t *cfg, const pmstep_electrical_t *model);

/** Smooth saturation and its derivative. */
void pmstep_sat(float x, float kappa, float *sat, float *sat_slope);

/** Park transform with (c, s): d = c a + s b, q = -s a + c b. */
void pmstep_park(float cos_hat, float sin_hat, float a, float b, float *d, float *q);

/** The speed correction of (6), k_w sat(e), and its slope k_w sat'(e), e = w-hat - w*
 *  ((13): k_w e and k_w). */
typedef struct {
    float term;  /**< k_w sat(e), rad/s^2 */
    float slope; /**< k_w sat'(e), 1/s */
} pmstep_speed_term_t;

/** The speed correction and its slope for the speed error @p speed_error_rad_s = w-hat - w*. */
pmstep_speed_term_t pmstep_law_speed_term(const pmstep_law_coeffs_t *coeffs, float speed_error_rad_s);

/** i_q* = (J/k_M)[(F/J) w* - k_w sat(w-hat - w*) + T/J + w*'], T = T_L-hat or T_L*;
 *  @p speed_term is k_w sat(w-hat - w*) (pmstep_law_speed_term). */
float pmstep_law_iq_ref(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs, float speed_term,
                        float load_Nm);

/** i_q*' = (J/k_M)[(F/J) w*' - k_w sat'(e)(w-hat' - w*') + T'/J + w*''];
 *  @p speed_slope is k_w sat'(e) (pmstep_law_speed_term). */
float pmstep_law_iq_ref_rate(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs, float speed_slope,
                             float speed_hat_rate, float load_rate);

/**
 * phi_d = -(R/L) i_d* + p w-hat i_q - i_d*',  phi_q = -(R/L) i_q* - p w-hat i_d - (k_M/L) w-hat - i_q*',
 * u_d = L[-phi_d - K_i (i_d - i_d*) - K_I z_d], u_q = L[-phi_q - K_i (i_q - i_q*) - K_I z_q]
 * (z: the integrals of the current errors; K_I = 0 in the paper's law),
 * u_a = c u_d - s u_q, u_b = s u_d + c u_q, with (c, s) the estimate turned by the angle the
 * rotor turns from the sample to the middle of the period the voltage acts in (p w-hat T_s
 * (delay + 1/2)) and (u_d, u_q) shortened by 1 - x^2/6, x = p w-hat T_s/2. A voltage held in the
 * stator frame over a period, placed there, drives the currents at the samples as the continuous
 * law's (u_d, u_q) would times 1 + x^2/6 + O(x^3) (steady state of the sampled R-L circuit in the
 * rotor frame; docs/design), so the step stays accurate at p w T_s ~ 0.3 rad.
 */
void pmstep_law_voltages(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs, float cos_hat, float sin_hat,
                         float i_d_A, float i_q_A, float speed_hat_rad_s, float i_q_ref_A, float i_q_ref_rate,
                         const pmstep_law_integral_t *integral, float *u_a_V, float *u_b_V);

/** Advances the current-error integrals by one period (when K_I > 0; the caller skips periods whose voltage
 *  the bus limited: anti-windup). */
static inline void pmstep_law_integrate(pmstep_law_integral_t *integral, const pmstep_law_coeffs_t *coeffs,
                                        float i_d_error_A, float i_q_error_A, float period_s)
{
    if ((coeffs->current_integral_gain_per_s2 > 0.0f) || (coeffs->current_integral_gain_q_per_s2 > 0.0f)) {
        integral->i_d_error_integral_As += period_s * i_d_error_A;
        integral->i_q_error_integral_As += period_s * i_q_error_A;
    }
}

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_LAW_H */
