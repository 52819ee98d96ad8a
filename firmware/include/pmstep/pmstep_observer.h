/**
 * @file pmstep_observer.h
 * @brief Current, speed and load-torque observer of controller (6), and the
 *        speed observer of Remark 1 (13) when the load is known.
 *
 * (6):  i_a-hat' = -(R/L) i_a-hat + (k_M/L) w-hat s-hat + u_a/L + K_e i~_a + p w-hat i~_b
 *       i_b-hat' = -(R/L) i_b-hat - (k_M/L) w-hat c-hat + u_b/L + K_e i~_b - p w-hat i~_a
 *       w-hat'   = -(F/J) w-hat - T_L-hat/J + (k_M/J) i_q + g_w eps
 *       T_L-hat' = -g_T eps,   eps = (k_M/L)(s-hat i~_a - c-hat i~_b)
 * (13): w-hat'   = -(F/J) w-hat + (k_M/J) i_q - T_L^* / J + (1/lambda)[p i_q i~_d - p i_d i~_q - (k_M/L) i~_q]
 * Discretised at the control period T_s so that it stays accurate when the electrical angle
 * turns p w T_s ~ 0.3 rad per period (hybrid steppers at speed):
 *  - currents: the R/L decay by the trapezoid rule (second order, A-stable); the held voltage
 *    exactly; the back-EMF, which turns with the rotor, at its mean over the period (the
 *    angle turned by h = p w-hat T_s/2 and shortened by sin(h)/h: e^{jh} sin(h)/h =
 *    (1 - 2h^2/3) + j h (1 - h^2/3) + O(h^4));
 *    the injections K_e i~ and p w-hat J i~ from the sample (a discrete-time correction:
 *    zero when i-hat matches the sample, so the prediction is the model's alone);
 *  - w-hat, T_L-hat: forward Euler (mechanics are slow against T_s).
 */
#ifndef PMSTEP_OBSERVER_H
#define PMSTEP_OBSERVER_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    float i_a_hat_A;
    float i_b_hat_A;
    float speed_hat_rad_s;
    float load_hat_Nm;
} pmstep_observer_t;

typedef struct {
    float r_over_l_per_s;       /**< R/L */
    float inv_l_per_H;          /**< 1/L */
    float km_over_l;            /**< k_M/L: (V s/rad)/(V s/A) = A/rad */
    float km_over_j;            /**< k_M/J */
    float f_over_j_per_s;       /**< F/J */
    float inv_j;                /**< 1/J */
    float observer_gain_per_s;  /**< K_e */
    float pole_pairs;           /**< p */
    float speed_injection_gain; /**< g_w = (2 g^2 + r F l J^2)/(g^2 l + r F l^2 J^2) */
    float load_injection_gain;  /**< g_T = (2 g^2 F + l J g + l J^2 r F^2)/(g^2 l + r F l^2 J^2) */
    float inv_lambda;           /**< 1/lambda, Remark 1 */
    float current_decay;        /**< (1 - z/2)/(1 + z/2), z = (R/L) T_s: trapezoid-rule decay of i-hat per period */
    float current_step_s;       /**< T_s/(1 + z/2): weight of the current rate's other terms */
    /* The back-EMF's mean over a period: the estimate turned by (1 + c2 w^2, w (s1 + s3 w^2)). */
    float mean_cos_w2;       /**< c2 = -(2/3) h^2, h = p T_s / 2 (per rad/s) */
    float mean_sin_w1;       /**< s1 = h */
    float mean_sin_w3;       /**< s3 = -h^3/3 */
    float speed_bound_rad_s; /**< |w-hat| beyond this is no motor's speed: PMSTEP_ESTIMATE_RANGE_FACTOR x the speed
                                   whose back EMF is the highest bus, max_bus_voltage_V / k_M */
    float load_bound_Nm;     /**< |T_L-hat| beyond this is no load the drive could be holding:
                                   PMSTEP_ESTIMATE_RANGE_FACTOR x k_M x max_phase_current_A */
} pmstep_observer_coeffs_t;

/** How far beyond what the motor and the bus allow the speed and load estimates may go before the
 *  core takes them for lost (PMSTEP_FAULT_ESTIMATE_RANGE): a loaded rotor can be driven past the
 *  bus's speed, and an observer's transient overshoots, by less than this. pmstep_observer_advance()
 *  holds the speed estimate within that range, so that every state stays finite until the check. */
#define PMSTEP_ESTIMATE_RANGE_FACTOR 4.0f

/** Signals the mechanical part of the observer needs at one sample. */
typedef struct {
    float i_a_A, i_b_A;         /**< measured currents */
    float cos_hat, sin_hat;     /**< angle estimate */
    float i_d_A, i_q_A;         /**< Park of the currents with (c-hat, s-hat) */
    float i_d_err_A, i_q_err_A; /**< i_d - i_d*, i_q - i_q* (Remark 1 only) */
    float known_load_Nm;        /**< T_L* (Remark 1 only) */
    float detent_torque_Nm;     /**< the model's detent torque at the estimated angle (0 = none) */
} pmstep_observer_input_t;

/** Time derivatives of the speed and load estimates. */
typedef struct {
    float speed_hat_rate_rad_s2;
    float load_hat_rate_Nm_s;
} pmstep_observer_mech_rates_t;

/** Coefficients for the gains and mechanics of @p cfg and the electrical model @p model. */
void pmstep_observer_coeffs_init(pmstep_observer_coeffs_t *coeffs, const pmstep_config_t *cfg,
                                 const pmstep_electrical_t *model);

/** Starts at t_c: i-hat = i(t_c), w-hat = 0, T_L-hat = 0. */
void pmstep_observer_start(pmstep_observer_t *obs, float i_a_A, float i_b_A);

/**
 * The transient observer boost (gains.transient_observer_boost, unknown load): where (6)'s q residual
 * |s-hat i~_a - c-hat i~_b| is beyond @p residual_bound_A, a load step the observer's bandwidth does not
 * follow, adds to @p rates the speed injection (@p boost - 1) times over and the load injection
 * (@p boost^2 - 1) times over, as if the observer's mechanical part ran @p boost times faster while
 * it lasts (docs/design/18-transient-observer-boost.md). The observer's state, @p in and the residual are this period's,
 * as pmstep_observer_mech_rates took them.
 */
void pmstep_observer_boost_in_transient(const pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs,
                                        const pmstep_observer_input_t *in, float boost, float residual_bound_A,
                                        pmstep_observer_mech_rates_t *rates);

/** w-hat' and T_L-hat' of (6) (adaptive: known_load = false) or (13) (known_load = true). */
pmstep_observer_mech_rates_t pmstep_observer_mech_rates(const pmstep_observer_t *obs,
                                                        const pmstep_observer_coeffs_t *coeffs,
                                                        const pmstep_observer_input_t *in, bool known_load);

/** The last advance redone for the voltage the period really had: the current step is linear
 *  in u, so the estimates move by T/(1 + R T/(2L)) (u_actual - u_assumed)/L. */
void pmstep_observer_correct_voltage(pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs, float du_a_V,
                                     float du_b_V);

/** Step of all four states over the next period (see the discretisation above), with the
 *  voltage applied over that period. */
void pmstep_observer_advance(pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs,
                             const pmstep_observer_input_t *in, const pmstep_observer_mech_rates_t *mech, float u_a_V,
                             float u_b_V, float period_s);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_OBSERVER_H */
