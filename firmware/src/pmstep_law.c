/* Adaptive speed and current law of controller (6); (13) when the load is known. */
#include "pmstep/pmstep_law.h"

#include "pmstep/pmstep_rotation.h"

#include <math.h> /* sqrtf: one vsqrt.f32 / sqrtss with -fno-math-errno, no libm call */

void pmstep_law_coeffs_init(pmstep_law_coeffs_t *coeffs, const pmstep_config_t *cfg, const pmstep_electrical_t *model)
{
    coeffs->j_over_km = model->inertia_kgm2 / model->torque_constant_Nm_A;
    coeffs->f_over_j_per_s = model->friction_Nms_rad / model->inertia_kgm2;
    coeffs->inv_j = 1.0f / model->inertia_kgm2;
    coeffs->speed_gain_per_s = cfg->gains.speed_gain_per_s;
    coeffs->current_gain_per_s = cfg->gains.current_gain_per_s;
    coeffs->r_over_l_per_s = model->resistance_Ohm / model->inductance_H;
    coeffs->km_over_l = model->torque_constant_Nm_A / model->inductance_H;
    coeffs->inductance_H = model->inductance_H;
    coeffs->pole_pairs = (float)cfg->motor.pole_pairs;
    /* kappa bounds the speed correction's torque J k_w kappa: an identified J keeps that bound. */
    coeffs->kappa_rad_s = cfg->gains.sat_kappa_rad_s * (cfg->motor.inertia_kgm2 / model->inertia_kgm2);
    coeffs->linear_speed_term = cfg->known_load_mode;
    coeffs->current_integral_gain_per_s2 = cfg->gains.current_integral_gain_per_s2;
    coeffs->current_integral_gain_q_per_s2 = cfg->gains.current_integral_gain_q_per_s2;
    coeffs->detent_torque_Nm = cfg->motor.detent_torque_Nm;
    coeffs->detent_order = 4.0f * coeffs->pole_pairs;
    {
        const float turn_per_speed = coeffs->pole_pairs * cfg->timing.period_s;
        const float a = turn_per_speed * ((float)cfg->timing.computational_delay_periods + 0.5f);
        const float k = turn_per_speed * turn_per_speed * (1.0f / 24.0f);
        coeffs->turn_cos_w2 = -(0.5f * a * a + k);
        coeffs->turn_cos_w4 = a * a * a * a * (1.0f / 24.0f) + 0.5f * k * a * a;
        coeffs->turn_sin_w1 = a;
        coeffs->turn_sin_w3 = -(a * a * a * (1.0f / 6.0f) + k * a);
    }
}

void pmstep_sat(float x, float kappa, float *sat, float *sat_slope)
{
    const float ratio = x / kappa;
    const float inv_root = 1.0f / sqrtf(1.0f + ratio * ratio);
    *sat = x * inv_root;
    *sat_slope = inv_root * inv_root * inv_root;
}

void pmstep_park(float cos_hat, float sin_hat, float a, float b, float *d, float *q)
{
    *d = cos_hat * a + sin_hat * b;
    *q = -sin_hat * a + cos_hat * b;
}

pmstep_speed_term_t pmstep_law_speed_term(const pmstep_law_coeffs_t *coeffs, float speed_error_rad_s)
{
    pmstep_speed_term_t speed;
    if (coeffs->linear_speed_term) {
        speed.term = coeffs->speed_gain_per_s * speed_error_rad_s;
        speed.slope = coeffs->speed_gain_per_s;
    } else {
        float sat;
        float sat_slope;
        pmstep_sat(speed_error_rad_s, coeffs->kappa_rad_s, &sat, &sat_slope);
        speed.term = coeffs->speed_gain_per_s * sat;
        speed.slope = coeffs->speed_gain_per_s * sat_slope;
    }
    return speed;
}

float pmstep_law_iq_ref(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs, float speed_term,
                        float load_Nm)
{
    return coeffs->j_over_km
           * (coeffs->f_over_j_per_s * refs->speed_ref_rad_s - speed_term + load_Nm * coeffs->inv_j
              + refs->speed_ref_rate_rad_s2);
}

float pmstep_law_iq_ref_rate(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs, float speed_slope,
                             float speed_hat_rate, float load_rate)
{
    return coeffs->j_over_km
           * (coeffs->f_over_j_per_s * refs->speed_ref_rate_rad_s2
              - speed_slope * (speed_hat_rate - refs->speed_ref_rate_rad_s2) + load_rate * coeffs->inv_j
              + refs->speed_ref_accel_rad_s3);
}

void pmstep_law_voltages(const pmstep_law_coeffs_t *coeffs, const pmstep_law_refs_t *refs, float cos_hat, float sin_hat,
                         float i_d_A, float i_q_A, float speed_hat_rad_s, float i_q_ref_A, float i_q_ref_rate,
                         const pmstep_law_integral_t *integral, float *u_a_V, float *u_b_V)
{
    const float pw = coeffs->pole_pairs * speed_hat_rad_s;
    const float phi_d = -coeffs->r_over_l_per_s * refs->i_d_ref_A + pw * i_q_A - refs->i_d_ref_rate_A_s;
    const float phi_q =
        -coeffs->r_over_l_per_s * i_q_ref_A - pw * i_d_A - coeffs->km_over_l * speed_hat_rad_s - i_q_ref_rate;
    const float u_d = coeffs->inductance_H
                      * (-phi_d - coeffs->current_gain_per_s * (i_d_A - refs->i_d_ref_A)
                         - coeffs->current_integral_gain_per_s2 * integral->i_d_error_integral_As);
    const float u_q = coeffs->inductance_H
                      * (-phi_q - coeffs->current_gain_per_s * (i_q_A - i_q_ref_A)
                         - coeffs->current_integral_gain_q_per_s2 * integral->i_q_error_integral_As);
    float cos_act;
    float sin_act;
    /* Inverse Park at the angle the voltage acts at, shortened for the hold. */
    pmstep_law_acting_angle(coeffs, cos_hat, sin_hat, speed_hat_rad_s, &cos_act, &sin_act);
    *u_a_V = cos_act * u_d - sin_act * u_q;
    *u_b_V = sin_act * u_d + cos_act * u_q;
}

void pmstep_law_fade_detent(float fade_speed_rad_s, float speed_hat_rad_s, float accel_rad_s2, pmstep_detent_t *detent)
{
    if (fade_speed_rad_s > 0.0f) {
        const float fade_sq = fade_speed_rad_s * fade_speed_rad_s;
        const float inv_sum = 1.0f / (fade_sq + speed_hat_rad_s * speed_hat_rad_s);
        const float gain = fade_sq * inv_sum;
        const float slope_s_rad = -2.0f * speed_hat_rad_s * gain * inv_sum;
        detent->rate_Nm_s = detent->rate_Nm_s * gain + detent->torque_Nm * slope_s_rad * accel_rad_s2;
        detent->torque_Nm *= gain;
    }
}
