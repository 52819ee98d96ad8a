/* Current, speed and load observer of controller (6); speed observer (13) of Remark 1. */
#include "pmstep/pmstep_observer.h"

void pmstep_observer_coeffs_init(pmstep_observer_coeffs_t *coeffs, const pmstep_config_t *cfg,
                                 const pmstep_electrical_t *model)
{
    const float j = cfg->inertia_kg_m2;
    const float f = cfg->friction_nm_s_per_rad;
    const float g = cfg->adapt_gamma;
    const float l = cfg->adapt_lambda;
    const float r = cfg->adapt_r;
    const float den = g * g * l + r * f * l * l * j * j;

    coeffs->r_over_l_per_s = model->resistance_ohm / model->inductance_h;
    coeffs->inv_l_per_h = 1.0f / model->inductance_h;
    coeffs->km_over_l = model->torque_constant_nm_per_a / model->inductance_h;
    coeffs->km_over_j = model->torque_constant_nm_per_a / j;
    coeffs->f_over_j_per_s = f / j;
    coeffs->inv_j = 1.0f / j;
    coeffs->observer_gain_per_s = cfg->observer_gain_per_s;
    coeffs->pole_pairs = (float)cfg->pole_pairs;
    /* Injection gains of (6); with F = 0 they are 2/lambda and J/gamma. */
    coeffs->speed_injection_gain = (2.0f * g * g + r * f * l * j * j) / den;
    coeffs->load_injection_gain = (2.0f * g * g * f + l * j * g + l * j * j * r * f * f) / den;
    coeffs->inv_lambda = 1.0f / l;
}

void pmstep_observer_start(pmstep_observer_t *obs, float i_a_a, float i_b_a)
{
    obs->i_a_hat_a = i_a_a;
    obs->i_b_hat_a = i_b_a;
    obs->speed_hat_rad_s = 0.0f;
    obs->load_hat_nm = 0.0f;
}

pmstep_observer_mech_rates_t pmstep_observer_mech_rates(const pmstep_observer_t *obs,
                                                        const pmstep_observer_coeffs_t *coeffs,
                                                        const pmstep_observer_input_t *in,
                                                        bool known_load)
{
    pmstep_observer_mech_rates_t rates;
    const float drive = -coeffs->f_over_j_per_s * obs->speed_hat_rad_s + coeffs->km_over_j * in->i_q_a;

    if (known_load) {
        /* (13): (1/lambda)[p i_q i~_d - p i_d i~_q - (k_M/L) i~_q] */
        const float injection = coeffs->pole_pairs * (in->i_q_a * in->i_d_err_a - in->i_d_a * in->i_q_err_a)
                                - coeffs->km_over_l * in->i_q_err_a;
        rates.speed_hat_rate_rad_s2 = drive - in->known_load_nm * coeffs->inv_j + coeffs->inv_lambda * injection;
        rates.load_hat_rate_nm_per_s = 0.0f;
    } else {
        /* (6): eps = (k_M/L)(s-hat i~_a - c-hat i~_b) */
        const float err_a = in->i_a_a - obs->i_a_hat_a;
        const float err_b = in->i_b_a - obs->i_b_hat_a;
        const float eps = coeffs->km_over_l * (in->sin_hat * err_a - in->cos_hat * err_b);
        rates.speed_hat_rate_rad_s2 = drive - obs->load_hat_nm * coeffs->inv_j + coeffs->speed_injection_gain * eps;
        rates.load_hat_rate_nm_per_s = -coeffs->load_injection_gain * eps;
    }
    return rates;
}

void pmstep_observer_advance(pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs,
                             const pmstep_observer_input_t *in,
                             const pmstep_observer_mech_rates_t *mech,
                             float u_a_v, float u_b_v, float period_s)
{
    const float err_a = in->i_a_a - obs->i_a_hat_a;
    const float err_b = in->i_b_a - obs->i_b_hat_a;
    const float w = obs->speed_hat_rad_s;
    const float pw = coeffs->pole_pairs * w;
    const float rate_a = -coeffs->r_over_l_per_s * obs->i_a_hat_a + coeffs->km_over_l * w * in->sin_hat
                         + coeffs->inv_l_per_h * u_a_v + coeffs->observer_gain_per_s * err_a + pw * err_b;
    const float rate_b = -coeffs->r_over_l_per_s * obs->i_b_hat_a - coeffs->km_over_l * w * in->cos_hat
                         + coeffs->inv_l_per_h * u_b_v + coeffs->observer_gain_per_s * err_b - pw * err_a;

    obs->i_a_hat_a += period_s * rate_a;
    obs->i_b_hat_a += period_s * rate_b;
    obs->speed_hat_rad_s += period_s * mech->speed_hat_rate_rad_s2;
    obs->load_hat_nm += period_s * mech->load_hat_rate_nm_per_s;
}
