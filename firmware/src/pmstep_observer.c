/* Current, speed and load observer of controller (6); speed observer (13) of Remark 1. */
#include "pmstep/pmstep_observer.h"

#include "pmstep/pmstep_rotation.h"
#include "pmstep_internal.h"

void pmstep_observer_coeffs_init(pmstep_observer_coeffs_t *coeffs, const pmstep_config_t *cfg,
                                 const pmstep_electrical_t *model)
{
    const float j = model->inertia_kgm2;
    const float f = model->friction_Nms_rad;
    const float g = cfg->gains.adapt_gamma;
    const float l = cfg->gains.adapt_lambda;
    const float r = cfg->gains.adapt_r;
    const float den = g * g * l + r * f * l * l * j * j;

    coeffs->r_over_l_per_s = model->resistance_Ohm / model->inductance_H;
    coeffs->inv_l_per_H = 1.0f / model->inductance_H;
    coeffs->km_over_l = model->torque_constant_Nm_A / model->inductance_H;
    coeffs->km_over_j = model->torque_constant_Nm_A / j;
    coeffs->f_over_j_per_s = f / j;
    coeffs->inv_j = 1.0f / j;
    coeffs->observer_gain_per_s = cfg->gains.observer_gain_per_s;
    coeffs->pole_pairs = (float)cfg->motor.pole_pairs;
    /* Injection gains of (6); with F = 0 they are 2/lambda and J/gamma. */
    coeffs->speed_injection_gain = (2.0f * g * g + r * f * l * j * j) / den;
    coeffs->load_injection_gain = (2.0f * g * g * f + l * j * g + l * j * j * r * f * f) / den;
    coeffs->inv_lambda = 1.0f / l;
    coeffs->speed_bound_rad_s =
        PMSTEP_ESTIMATE_RANGE_FACTOR * cfg->limits.max_bus_voltage_V / model->torque_constant_Nm_A;
    coeffs->load_bound_Nm =
        PMSTEP_ESTIMATE_RANGE_FACTOR * model->torque_constant_Nm_A * cfg->limits.max_phase_current_A;
    {
        const float half_z = 0.5f * coeffs->r_over_l_per_s * cfg->timing.period_s;
        coeffs->current_decay = (1.0f - half_z) / (1.0f + half_z);
        coeffs->current_step_s = cfg->timing.period_s / (1.0f + half_z);
    }
    {
        const float h = 0.5f * coeffs->pole_pairs * cfg->timing.period_s;
        coeffs->mean_cos_w2 = -(2.0f / 3.0f) * h * h;
        coeffs->mean_sin_w1 = h;
        coeffs->mean_sin_w3 = -(1.0f / 3.0f) * h * h * h;
    }
}

void pmstep_observer_start(pmstep_observer_t *obs, float i_a_A, float i_b_A)
{
    obs->i_a_hat_A = i_a_A;
    obs->i_b_hat_A = i_b_A;
    obs->speed_hat_rad_s = 0.0f;
    obs->load_hat_Nm = 0.0f;
}

pmstep_observer_mech_rates_t pmstep_observer_mech_rates(const pmstep_observer_t *obs,
                                                        const pmstep_observer_coeffs_t *coeffs,
                                                        const pmstep_observer_input_t *in, bool known_load)
{
    pmstep_observer_mech_rates_t rates;
    const float drive = -coeffs->f_over_j_per_s * obs->speed_hat_rad_s + coeffs->km_over_j * in->i_q_A
                        + in->detent_torque_Nm * coeffs->inv_j;

    if (known_load) {
        /* (13): (1/lambda)[p i_q i~_d - p i_d i~_q - (k_M/L) i~_q] */
        const float injection = coeffs->pole_pairs * (in->i_q_A * in->i_d_err_A - in->i_d_A * in->i_q_err_A)
                                - coeffs->km_over_l * in->i_q_err_A;
        rates.speed_hat_rate_rad_s2 = drive - in->known_load_Nm * coeffs->inv_j + coeffs->inv_lambda * injection;
        rates.load_hat_rate_Nm_s = 0.0f;
    } else {
        /* (6): eps = (k_M/L)(s-hat i~_a - c-hat i~_b) */
        const float err_a = in->i_a_A - obs->i_a_hat_A;
        const float err_b = in->i_b_A - obs->i_b_hat_A;
        const float eps = coeffs->km_over_l * (in->sin_hat * err_a - in->cos_hat * err_b);
        rates.speed_hat_rate_rad_s2 = drive - obs->load_hat_Nm * coeffs->inv_j + coeffs->speed_injection_gain * eps;
        rates.load_hat_rate_Nm_s = -coeffs->load_injection_gain * eps;
    }
    return rates;
}

void pmstep_observer_boost_in_transient(const pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs,
                                        const pmstep_observer_input_t *in, float boost, float residual_bound_A,
                                        pmstep_observer_mech_rates_t *rates)
{
    /* (6)'s residual s-hat i~_a - c-hat i~_b, the q axis's (with its sign reversed) */
    const float residual_A =
        (in->sin_hat * (in->i_a_A - obs->i_a_hat_A)) - (in->cos_hat * (in->i_b_A - obs->i_b_hat_A));
    if ((residual_A > residual_bound_A) || (residual_A < -residual_bound_A)) {
        const float eps = coeffs->km_over_l * residual_A;
        rates->speed_hat_rate_rad_s2 += (boost - 1.0f) * coeffs->speed_injection_gain * eps;
        rates->load_hat_rate_Nm_s -= ((boost * boost) - 1.0f) * coeffs->load_injection_gain * eps;
    }
}

void pmstep_observer_correct_voltage(pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs, float du_a_V,
                                     float du_b_V)
{
    const float input_gain = coeffs->current_step_s * coeffs->inv_l_per_H;
    obs->i_a_hat_A += input_gain * du_a_V;
    obs->i_b_hat_A += input_gain * du_b_V;
}

void pmstep_observer_advance(pmstep_observer_t *obs, const pmstep_observer_coeffs_t *coeffs,
                             const pmstep_observer_input_t *in, const pmstep_observer_mech_rates_t *mech, float u_a_V,
                             float u_b_V, float period_s)
{
    const float err_a = in->i_a_A - obs->i_a_hat_A;
    const float err_b = in->i_b_A - obs->i_b_hat_A;
    const float w = obs->speed_hat_rad_s;
    const float pw = coeffs->pole_pairs * w;
    const float w2 = w * w;
    float mean_cos;
    float mean_sin;
    pmstep_turn(in->cos_hat, in->sin_hat, 1.0f + coeffs->mean_cos_w2 * w2,
                w * (coeffs->mean_sin_w1 + coeffs->mean_sin_w3 * w2), &mean_cos, &mean_sin);
    {
        /* The rates of (6) but -(R/L) i-hat, which the trapezoid rule takes. */
        const float drive_a = coeffs->km_over_l * w * mean_sin + coeffs->inv_l_per_H * u_a_V
                              + coeffs->observer_gain_per_s * err_a + pw * err_b;
        const float drive_b = -coeffs->km_over_l * w * mean_cos + coeffs->inv_l_per_H * u_b_V
                              + coeffs->observer_gain_per_s * err_b - pw * err_a;
        obs->i_a_hat_A = coeffs->current_decay * obs->i_a_hat_A + coeffs->current_step_s * drive_a;
        obs->i_b_hat_A = coeffs->current_decay * obs->i_b_hat_A + coeffs->current_step_s * drive_b;
    }
    /* w-hat held within the range beyond which the supervision takes the observer for lost
     * (PMSTEP_FAULT_ESTIMATE_RANGE at its next check): a lost observer's injections grow with its
     * own speed's powers (the back EMF's mean over the period), and between two checks they would
     * take it to overflow. With w-hat bounded the current estimates are a stable filter of bounded
     * inputs, and T_L-hat grows at most linearly until the check. */
    obs->speed_hat_rad_s =
        pmstep_limit(obs->speed_hat_rad_s + period_s * mech->speed_hat_rate_rad_s2, coeffs->speed_bound_rad_s);
    obs->load_hat_Nm += period_s * mech->load_hat_rate_Nm_s;
}
