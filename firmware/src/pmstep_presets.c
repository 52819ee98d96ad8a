/* Configurations ready to use: a separate library (pmstep_presets), so an image that brings
 * its own configuration carries none of them. */
#include "pmstep/pmstep.h"

pmstep_config_t pmstep_paper_config(void)
{
    /* A table in flash, copied out: smaller than one store per field. Fields not named are 0 / false:
     * calibration, commissioning, dead-time compensation and the drift-free option are off (the paper). */
    static const pmstep_config_t paper = {
        /* Motor of Section III.B. */
        .resistance_ohm = 3.0f,
        .inductance_h = 0.006f,
        .inertia_kg_m2 = 0.01f,
        .torque_constant_nm_per_a = 2.0f,
        .pole_pairs = 6,
        .period_s = 50e-6f,
        .s_align_time_s = 0.3f,
        .c_align_time_s = 0.6f,
        .s_align_voltage_v = 24.0f,
        .c_align_voltage_v = 24.0f,
        .speed_gain_per_s = 100.0f,
        .observer_gain_per_s = 100.0f,
        .current_gain_per_s = 20.0f,
        .adapt_gamma = 0.01f / 9.0f,
        .adapt_lambda = 0.2f,
        .adapt_r = 1.0f,
        .sat_kappa_rad_per_s = 9.0f,
        .reference_bandwidth_rad_per_s = 300.0f,
        /* Drive limits (not in the paper): 48 V bus, alignment draws u/R = 8 A. */
        .max_phase_current_a = 15.0f,
        .min_bus_voltage_v = 30.0f,
        .max_bus_voltage_v = 60.0f,
        /* Detection (protections, not in the paper): on; far outside what the paper's run reaches. */
        .angle_magnitude_bound = 0.25f,
        .speed_consistency_bound_rad_s = 3.0f,
        .stall_speed_error_rad_s = 3.0f,
        .observer_residual_bound_a = 0.3f,
        .detection_time_s = 0.02f
    };
    return paper;
}
