/* Angle reconstruction from current integrals, controller (6) (proof of Theorem 3). */
#include "pmstep/pmstep_angle.h"

#include "pmstep/pmstep_rotation.h"

void pmstep_angle_coeffs_init(pmstep_angle_coeffs_t *coeffs, const pmstep_config_t *cfg,
                              const pmstep_electrical_t *model)
{
    coeffs->voltage_gain = cfg->timing.period_s / model->inductance_H;
    coeffs->current_gain = 0.5f * model->resistance_Ohm * cfg->timing.period_s / model->inductance_H;
    coeffs->flux_to_angle = model->inductance_H * (float)cfg->motor.pole_pairs / model->torque_constant_Nm_A;
    /* d c-hat / d phi1 = flux_to_angle, so a change g T_s c e of c-hat is g T_s c e / flux_to_angle of phi1. */
    coeffs->correction_gain = cfg->gains.angle_correction_gain_per_s * cfg->timing.period_s / coeffs->flux_to_angle;
    /* R + L K_e over k_M: the residual per radian of angle error per rad/s (pmstep_angle.h). */
    coeffs->emf_turn_gain = cfg->gains.emf_angle_gain_per_s * cfg->timing.period_s
                            * (model->resistance_Ohm + model->inductance_H * cfg->gains.observer_gain_per_s)
                            / (model->torque_constant_Nm_A * coeffs->flux_to_angle);
    coeffs->emf_corner_squared = cfg->gains.emf_angle_corner_rad_s * cfg->gains.emf_angle_corner_rad_s;
}

void pmstep_angle_start(pmstep_angle_t *angle, float i_a_A, float i_b_A)
{
    angle->phi_a = 0.0f;
    angle->phi_b = 0.0f;
    angle->phi_a_compensation = 0.0f;
    angle->phi_b_compensation = 0.0f;
    angle->i_a_start_A = i_a_A;
    angle->i_b_start_A = i_b_A;
    angle->i_a_prev_A = i_a_A;
    angle->i_b_prev_A = i_b_A;
}

/* Kahan-compensated sum += increment. */
static void compensated_add(float *sum, float *compensation, float increment)
{
    const float corrected = increment - *compensation;
    const float total = *sum + corrected;
    *compensation = (total - *sum) - corrected;
    *sum = total;
}

void pmstep_angle_update(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float i_a_A, float i_b_A,
                         float u_a_V, float u_b_V)
{
    /* phi' = -(R/L) i + u/L over one period: u held (exact), i by the trapezoid rule. */
    const float increment_a = coeffs->voltage_gain * u_a_V - coeffs->current_gain * (angle->i_a_prev_A + i_a_A);
    const float increment_b = coeffs->voltage_gain * u_b_V - coeffs->current_gain * (angle->i_b_prev_A + i_b_A);
    compensated_add(&angle->phi_a, &angle->phi_a_compensation, increment_a);
    compensated_add(&angle->phi_b, &angle->phi_b_compensation, increment_b);
    angle->i_a_prev_A = i_a_A;
    angle->i_b_prev_A = i_b_A;
}

void pmstep_angle_estimate(const pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float i_a_A, float i_b_A,
                           float *cos_hat, float *sin_hat)
{
    const float flux_a = (i_a_A - angle->i_a_start_A) - (angle->phi_a - angle->phi_a_compensation);
    const float flux_b = (i_b_A - angle->i_b_start_A) - (angle->phi_b - angle->phi_b_compensation);
    *cos_hat = 1.0f - coeffs->flux_to_angle * flux_a;
    *sin_hat = -coeffs->flux_to_angle * flux_b;
}

void pmstep_angle_correct(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat)
{
    const float radial_step = coeffs->correction_gain * (1.0f - cos_hat * cos_hat - sin_hat * sin_hat);
    compensated_add(&angle->phi_a, &angle->phi_a_compensation, radial_step * cos_hat);
    compensated_add(&angle->phi_b, &angle->phi_b_compensation, radial_step * sin_hat);
}

void pmstep_angle_follow_emf(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat,
                             float i_d_residual_A, float speed_hat_rad_s)
{
    /* the turn -K_theta T_s delta-hat, over flux_to_angle: phi's step along (-s-hat, c-hat). Plain sums:
     * the correction's own loop takes up their round-off. */
    const float turn = coeffs->emf_turn_gain * i_d_residual_A * speed_hat_rad_s
                       / (speed_hat_rad_s * speed_hat_rad_s + coeffs->emf_corner_squared);
    angle->phi_a -= turn * sin_hat;
    angle->phi_b += turn * cos_hat;
}

void pmstep_angle_smoother_set(pmstep_angle_smoother_t *smoother, float cos_hat, float sin_hat)
{
    smoother->cos_hat = cos_hat;
    smoother->sin_hat = sin_hat;
}

void pmstep_angle_smooth(float share, float turn_rad, pmstep_angle_smoother_t *smoother, float *cos_hat, float *sin_hat)
{
    float cos_turn;
    float sin_turn;
    float cos_turned;
    float sin_turned;
    float off_rad;
    pmstep_small_rotation(turn_rad, &cos_turn, &sin_turn);
    pmstep_turn(smoother->cos_hat, smoother->sin_hat, cos_turn, sin_turn, &cos_turned, &sin_turned);
    off_rad = (cos_turned * *sin_hat) - (sin_turned * *cos_hat); /* the reading's turn off the prediction (its sine) */
    if ((off_rad < PMSTEP_ANGLE_SMOOTHING_GATE_RAD) && (off_rad > -PMSTEP_ANGLE_SMOOTHING_GATE_RAD)) {
        *cos_hat += share * (cos_turned - *cos_hat);
        *sin_hat += share * (sin_turned - *sin_hat);
    }
    smoother->cos_hat = *cos_hat;
    smoother->sin_hat = *sin_hat;
}

void pmstep_angle_set(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs, float cos_hat, float sin_hat)
{
    /* pmstep_angle_estimate() solved for phi at i = i_prev */
    angle->phi_a = (angle->i_a_prev_A - angle->i_a_start_A) - (1.0f - cos_hat) / coeffs->flux_to_angle;
    angle->phi_b = (angle->i_b_prev_A - angle->i_b_start_A) + sin_hat / coeffs->flux_to_angle;
    angle->phi_a_compensation = 0.0f;
    angle->phi_b_compensation = 0.0f;
}
