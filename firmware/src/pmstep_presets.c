/* Configurations ready to use: a separate library (pmstep_presets), so an image that brings
 * its own configuration carries none of them. */
#include "pmstep/pmstep.h"

pmstep_config_t pmstep_paper_config(void)
{
    /* A table in flash, copied out: smaller than one store per field. Fields not named are 0 / false:
     * calibration, commissioning, dead-time compensation and the drift-free option are off (the paper). */
    static const pmstep_config_t paper = {
        /* Motor of Section III.B. */
        .motor = {.resistance_Ohm = 3.0f,
                  .inductance_H = 0.006f,
                  .inertia_kgm2 = 0.01f,
                  .friction_Nms_rad = 0.0f,
                  .torque_constant_Nm_A = 2.0f,
                  .pole_pairs = 6,
                  .rated_current_A = 8.0f},
        .timing = {.period_s = 50e-6f, .computational_delay_periods = 0u},
        .alignment = {.s_align_time_s = 0.3f,
                      .c_align_time_s = 0.6f,
                      .s_align_voltage_V = 24.0f,
                      .c_align_voltage_V = 24.0f},
        .gains = {.speed_gain_per_s = 100.0f,
                  .observer_gain_per_s = 100.0f,
                  .current_gain_per_s = 20.0f,
                  .adapt_gamma = 0.01f / 9.0f,
                  .adapt_lambda = 0.2f,
                  .adapt_r = 1.0f,
                  .sat_kappa_rad_s = 9.0f,
                  .reference_bandwidth_rad_s = 300.0f},
        /* Drive limits (not in the paper, which gives no rating): 48 V bus; the alignment's u/R = 8 A
         * taken as the rated current; a drive measuring +/-16.5 A and up to 66 V (the STM32G431
         * port's sensors; a port puts in its own ranges). */
        .limits = {.max_phase_current_A = 15.0f,
                   .min_bus_voltage_V = 30.0f,
                   .max_bus_voltage_V = 60.0f,
                   .current_sense_range_A = 16.5f,
                   .bus_sense_range_V = 66.0f},
        /* Detection (protections, not in the paper): on; far outside what the paper's run reaches. */
        .detection = {.angle_magnitude_bound = 0.25f,
                      .speed_consistency_bound_rad_s = 3.0f,
                      .stall_speed_error_rad_s = 3.0f,
                      .observer_residual_bound_A = 0.3f,
                      .persistence_s = 0.02f}};
    return paper;
}
