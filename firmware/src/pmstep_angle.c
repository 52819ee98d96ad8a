/* Angle reconstruction from current integrals, controller (6) (proof of Theorem 3). */
#include "pmstep/pmstep_angle.h"

void pmstep_angle_coeffs_init(pmstep_angle_coeffs_t *coeffs, const pmstep_config_t *cfg)
{
    coeffs->voltage_gain = cfg->period_s / cfg->inductance_h;
    coeffs->current_gain = 0.5f * cfg->resistance_ohm * cfg->period_s / cfg->inductance_h;
    coeffs->flux_to_angle = cfg->inductance_h * (float)cfg->pole_pairs / cfg->torque_constant_nm_per_a;
}

void pmstep_angle_start(pmstep_angle_t *angle, float i_a_a, float i_b_a)
{
    angle->phi_a = 0.0f;
    angle->phi_b = 0.0f;
    angle->phi_a_compensation = 0.0f;
    angle->phi_b_compensation = 0.0f;
    angle->i_a_start_a = i_a_a;
    angle->i_b_start_a = i_b_a;
    angle->i_a_prev_a = i_a_a;
    angle->i_b_prev_a = i_b_a;
}

/* Kahan-compensated sum += increment. */
static void compensated_add(float *sum, float *compensation, float increment)
{
    const float corrected = increment - *compensation;
    const float total = *sum + corrected;
    *compensation = (total - *sum) - corrected;
    *sum = total;
}

void pmstep_angle_update(pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs,
                         float i_a_a, float i_b_a, float u_a_v, float u_b_v)
{
    /* phi' = -(R/L) i + u/L over one period: u held (exact), i by the trapezoid rule. */
    const float increment_a = coeffs->voltage_gain * u_a_v - coeffs->current_gain * (angle->i_a_prev_a + i_a_a);
    const float increment_b = coeffs->voltage_gain * u_b_v - coeffs->current_gain * (angle->i_b_prev_a + i_b_a);
    compensated_add(&angle->phi_a, &angle->phi_a_compensation, increment_a);
    compensated_add(&angle->phi_b, &angle->phi_b_compensation, increment_b);
    angle->i_a_prev_a = i_a_a;
    angle->i_b_prev_a = i_b_a;
}

void pmstep_angle_estimate(const pmstep_angle_t *angle, const pmstep_angle_coeffs_t *coeffs,
                           float i_a_a, float i_b_a, float *cos_hat, float *sin_hat)
{
    const float flux_a = (i_a_a - angle->i_a_start_a) - (angle->phi_a - angle->phi_a_compensation);
    const float flux_b = (i_b_a - angle->i_b_start_a) - (angle->phi_b - angle->phi_b_compensation);
    *cos_hat = 1.0f - coeffs->flux_to_angle * flux_a;
    *sin_hat = -coeffs->flux_to_angle * flux_b;
}
