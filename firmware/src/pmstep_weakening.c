/* Field weakening: the weakening current from the law's voltage against the bus (pmstep_weakening.h). */
#include "pmstep/pmstep_weakening.h"

#include "pmstep_internal.h"

void pmstep_weakening_coeffs_init(pmstep_weakening_coeffs_t *coeffs, const pmstep_config_t *cfg)
{
    const pmstep_field_weakening_config_t *fw = &cfg->field_weakening;
    const float check_period_s = (float)PMSTEP_DETECTION_DECIMATION * cfg->timing.period_s;
    coeffs->modulation_squared = fw->modulation * fw->modulation;
    coeffs->step_A = fw->gain_A_per_s * check_period_s;
    coeffs->max_current_A = fw->max_current_A;
}

float pmstep_weakening_update(pmstep_weakening_t *weakening, const pmstep_weakening_coeffs_t *coeffs, float u_a_V,
                              float u_b_V, float bus_voltage_V, bool helps)
{
    const float demand = (u_a_V * u_a_V) + (u_b_V * u_b_V);
    const float supply = coeffs->modulation_squared * bus_voltage_V * bus_voltage_V;
    const float larger = (supply > demand) ? supply : demand;
    /* a non-finite voltage or bus, or none at all: i_w stays */
    if ((larger > 0.0f) && pmstep_all_finite4(demand, supply, 0.0f, 0.0f)) {
        const float error = (supply - demand) / larger;
        /* an excess a weaker field would not lower (a resistive one) takes i_w back toward 0 */
        const float step_A = coeffs->step_A * (helps ? error : pmstep_abs(error));
        float next_A = weakening->weakening_A + step_A;
        if (next_A > 0.0f) {
            next_A = 0.0f;
        } else if (next_A < -coeffs->max_current_A) {
            next_A = -coeffs->max_current_A;
        } else {
            /* within its range */
        }
        weakening->weakening_A = next_A;
    }
    return weakening->command_A + weakening->weakening_A;
}

bool pmstep_weakening_helps(float r_over_l_per_s, float pole_pairs, float speed_rad_s, float u_d_V, float u_q_V)
{
    return ((r_over_l_per_s * u_d_V) + (pole_pairs * speed_rad_s * u_q_V)) > 0.0f;
}
