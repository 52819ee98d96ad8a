/* pmstep-tune: the design's input from the preset, the design printed, and the design
 * written as a C initialiser (--write-c). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pmstep_tune.h"

/* The designer's input for the motor the drive is told: the preset's [motor], J and F overridable. */
void design_input(const sil_scenario_t *sc, bool robust, bool low_speed_drive, pmstep_design_input_t *in)
{
    memset(in, 0, sizeof *in);
    in->motor.resistance_Ohm = (float)sc->motor.resistance_Ohm;
    in->motor.inductance_H = (float)sc->motor.inductance_H;
    in->motor.inertia_kgm2 = (float)sc->motor.inertia_kgm2;
    in->motor.friction_Nms_rad = (float)sc->motor.friction_Nms_rad;
    in->motor.torque_constant_Nm_A = (float)sc->motor.torque_constant_Nm_A;
    in->motor.pole_pairs = (int32_t)sc->motor.pole_pairs;
    in->motor.detent_torque_Nm = (float)sc->datasheet.detent_torque_Nm; /* the law compensates the datasheet's */
    in->motor.rated_current_A = (float)sc->datasheet.rated_current_A;
    in->holding_torque_Nm = (float)sc->datasheet.holding_torque_Nm;
    in->current_sense_range_A = sc->controller.limits.current_sense_range_A; /* the scenario's sensors */
    in->bus_sense_range_V = sc->controller.limits.bus_sense_range_V;
    in->bus_voltage_V = (float)sc->bus_voltage_V;
    in->period_s = sc->controller.timing.period_s;
    in->computational_delay_periods = sc->controller.timing.computational_delay_periods;
    in->self_commissioning = robust;
    in->dead_time_s = (float)sc->inverter.dead_time_s;
    in->phase_voltage_sensing = sc->controller.inverter.phase_voltage_sensing;
    in->low_speed_drive = low_speed_drive;
    {
        const double step_A = sc->sensors.adc_bits > 0
                                  ? 2.0 * sc->sensors.current_full_scale_A / (double)(1L << sc->sensors.adc_bits)
                                  : 0.0;
        in->current_resolution_A = (float)(step_A > sc->sensors.noise_rms_A ? step_A : sc->sensors.noise_rms_A);
    }
}
void print_design(const sil_scenario_t *sc, const pmstep_design_report_t *r, bool robust)
{
    const pmstep_config_t *c = &sc->controller;
    printf("pmstep-tune: %s, %s mode, T_s = %g s, delay %u\n", sc->name, robust ? "robust" : "paper",
           (double)c->timing.period_s, (unsigned)c->timing.computational_delay_periods);
    printf("  top speed: %.1f rad/s (%.0f rpm), p w T_s = %.3f rad; the %s's (bus: rated current in 90 %% of %g V at "
           "%.1f rad/s; control rate: %.2f rad per period at %.1f rad/s)\n",
           (double)r->top_speed_rad_s, (double)r->top_speed_rad_s * 60.0 / (2.0 * M_PI),
           (double)r->top_electrical_step_rad, r->bus_speed_rad_s <= r->rate_speed_rad_s ? "bus" : "control rate",
           sc->bus_voltage_V, (double)r->bus_speed_rad_s, (double)PMSTEP_DESIGN_MAX_ELECTRICAL_STEP_RAD,
           (double)r->rate_speed_rad_s);
    printf("  field weakening: up to %.3f A off i_d* (0 = off), bus share %.2f, gain %.1f A/s; top speed with it %.1f "
           "rad/s "
           "(%.0f rpm) at %.0f %% of the holding torque\n",
           (double)c->field_weakening.max_current_A, (double)c->field_weakening.modulation,
           (double)c->field_weakening.gain_A_per_s, (double)r->weakened_speed_rad_s,
           (double)r->weakened_speed_rad_s * 60.0 / (2.0 * M_PI), 100.0 * (double)PMSTEP_DESIGN_WEAKENED_TORQUE_SHARE);
    printf("  bandwidths: current %.0f rad/s, observer %.0f rad/s (triple pole), speed %.0f rad/s\n",
           (double)r->current_bandwidth_rad_s, (double)r->observer_bandwidth_rad_s, (double)r->speed_bandwidth_rad_s);
    printf("  gains: k_w %g, K_e %g, K_i %g, K_I %g (q axis %g), gamma %g, lambda %g, r %g, kappa %g rad/s, varpi_0 %g "
           "rad/s, "
           "g %g 1/s\n",
           (double)c->gains.speed_gain_per_s, (double)c->gains.observer_gain_per_s, (double)c->gains.current_gain_per_s,
           (double)c->gains.current_integral_gain_per_s2, (double)c->gains.current_integral_gain_q_per_s2,
           (double)c->gains.adapt_gamma, (double)c->gains.adapt_lambda, (double)c->gains.adapt_r,
           (double)c->gains.sat_kappa_rad_s, (double)c->gains.reference_bandwidth_rad_s,
           (double)c->gains.angle_correction_gain_per_s);
    printf("  back-EMF angle correction: K_theta %g 1/s, half on at %.2f rad/s (0 = off)\n",
           (double)c->gains.emf_angle_gain_per_s, (double)c->gains.emf_angle_corner_rad_s);
    printf("  angle smoothing: %g of the turned previous estimate (0 = the flux integrals' reading)\n",
           (double)c->gains.angle_smoothing);
    printf("  transient observer boost: %g beyond the residual bound %g A (0 = off)\n",
           (double)c->gains.transient_observer_boost, (double)c->detection.observer_residual_bound_A);
    printf("  detent torque compensated: %g Nm, fading above %.1f rad/s (0 = no fade)\n",
           (double)c->motor.detent_torque_Nm, (double)c->gains.detent_fade_speed_rad_s);
    printf("  alignment: %.3f A (u = %.3f V), lead-in %.2f s, t_s %.2f s, t_c %.2f s; swing %.0f rad/s, "
           "damping %.2f; condition (4) holds %.2fx over, the detent's barrier %.2fx (0 = no detent)\n",
           (double)r->alignment_current_A, (double)c->alignment.s_align_voltage_V,
           (double)c->alignment.s_lead_in_time_s, (double)c->alignment.s_align_time_s,
           (double)c->alignment.c_align_time_s, (double)r->alignment_frequency_rad_s, (double)r->alignment_damping,
           (double)r->condition_4_margin, (double)r->detent_margin);
    printf("  trips: %.2f A, bus %.1f..%.1f V; detection: stall/consistency %.2f rad/s, residual %.3f A, %.3f s\n",
           (double)c->limits.max_phase_current_A, (double)c->limits.min_bus_voltage_V,
           (double)c->limits.max_bus_voltage_V, (double)c->detection.stall_speed_error_rad_s,
           (double)c->detection.observer_residual_bound_A, (double)c->detection.persistence_s);
    printf("  standstill hold in speed mode: %.3f A (0 = off)\n", (double)c->standstill.hold_current_A);
    printf("  low-speed drive (the hold's vector turning) below: %.3f rad/s (0 = off)%s\n",
           (double)c->standstill.vector_speed_rad_s, c->standstill.stops_only ? ", in stops only" : "");
    if (robust) {
        printf("  commissioning: offsets %.3f s, windows %.3f s, L window %.5f s, bias level %.2f, "
               "dead time %g s (band %g A, %s), i_d* %.3f A; RUN uses the measured R%s\n",
               (double)c->commissioning.offset_calibration_time_s, (double)c->commissioning.steady_state_window_s,
               (double)c->commissioning.inductance_window_s, (double)c->commissioning.voltage_bias_level_fraction,
               (double)c->inverter.dead_time_s, (double)c->inverter.dead_time_current_band_A,
               c->inverter.ripple_dead_zone ? "none lost within the PWM ripple" : "no ripple",
               (double)r->magnetising_current_A,
               c->commissioning.use_measured_inductance
                   ? ", L and k_M"
                   : " (L, k_M from the datasheet: the rotor swings within the L window)");
    }
}

int write_c(const char *path, const sil_scenario_t *sc)
{
    const pmstep_config_t *c = &sc->controller;
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "pmstep-tune: cannot write %s\n", path);
        return -1;
    }
    fprintf(f, "/* Designed by pmstep-tune for %s (docs/design). */\n", sc->name);
    fprintf(f, "#include \"pmstep/pmstep.h\"\n\nconst pmstep_config_t pmstep_designed_config = {\n");
    fprintf(f,
            "    .motor = {.resistance_Ohm = %#.9gf, .inductance_H = %#.9gf, .inertia_kgm2 = %#.9gf,\n"
            "              .friction_Nms_rad = %#.9gf, .torque_constant_Nm_A = %#.9gf, .pole_pairs = %d,\n"
            "              .detent_torque_Nm = %#.9gf, .rated_current_A = %#.9gf},\n",
            (double)c->motor.resistance_Ohm, (double)c->motor.inductance_H, (double)c->motor.inertia_kgm2,
            (double)c->motor.friction_Nms_rad, (double)c->motor.torque_constant_Nm_A, (int)c->motor.pole_pairs,
            (double)c->motor.detent_torque_Nm, (double)c->motor.rated_current_A);
    fprintf(f, "    .timing = {.period_s = %#.9gf, .computational_delay_periods = %uu},\n", (double)c->timing.period_s,
            (unsigned)c->timing.computational_delay_periods);
    fprintf(f,
            "    .alignment = {.s_align_time_s = %#.9gf, .s_lead_in_time_s = %#.9gf, .c_align_time_s = %#.9gf,\n"
            "                  .s_align_voltage_V = %#.9gf, .c_align_voltage_V = %#.9gf},\n",
            (double)c->alignment.s_align_time_s, (double)c->alignment.s_lead_in_time_s,
            (double)c->alignment.c_align_time_s, (double)c->alignment.s_align_voltage_V,
            (double)c->alignment.c_align_voltage_V);
    fprintf(
        f,
        "    .gains = {.speed_gain_per_s = %#.9gf, .observer_gain_per_s = %#.9gf, .current_gain_per_s = %#.9gf,\n"
        "              .adapt_gamma = %#.9gf, .adapt_lambda = %#.9gf, .adapt_r = %#.9gf, .sat_kappa_rad_s = %#.9gf,\n"
        "              .reference_bandwidth_rad_s = %#.9gf, .angle_correction_gain_per_s = %#.9gf,\n"
        "              .current_integral_gain_per_s2 = %#.9gf, .current_integral_gain_q_per_s2 = %#.9gf,\n"
        "              .detent_fade_speed_rad_s = %#.9gf, .emf_angle_gain_per_s = %#.9gf,\n"
        "              .emf_angle_corner_rad_s = %#.9gf, .angle_smoothing = %#.9gf,\n"
        "              .transient_observer_boost = %#.9gf},\n",
        (double)c->gains.speed_gain_per_s, (double)c->gains.observer_gain_per_s, (double)c->gains.current_gain_per_s,
        (double)c->gains.adapt_gamma, (double)c->gains.adapt_lambda, (double)c->gains.adapt_r,
        (double)c->gains.sat_kappa_rad_s, (double)c->gains.reference_bandwidth_rad_s,
        (double)c->gains.angle_correction_gain_per_s, (double)c->gains.current_integral_gain_per_s2,
        (double)c->gains.current_integral_gain_q_per_s2, (double)c->gains.detent_fade_speed_rad_s,
        (double)c->gains.emf_angle_gain_per_s, (double)c->gains.emf_angle_corner_rad_s,
        (double)c->gains.angle_smoothing, (double)c->gains.transient_observer_boost);
    fprintf(f,
            "    .limits = {.max_phase_current_A = %#.9gf, .min_bus_voltage_V = %#.9gf, .max_bus_voltage_V = %#.9gf,\n"
            "               .current_sense_range_A = %#.9gf, .bus_sense_range_V = %#.9gf},\n",
            (double)c->limits.max_phase_current_A, (double)c->limits.min_bus_voltage_V,
            (double)c->limits.max_bus_voltage_V, (double)c->limits.current_sense_range_A,
            (double)c->limits.bus_sense_range_V);
    fprintf(f,
            "    .commissioning = {.offset_calibration_time_s = %#.9gf, .alignment_offset_calibration = %s,\n"
            "                      .steady_state_window_s = %#.9gf, .inductance_window_s = %#.9gf,\n"
            "                      .use_measured_resistance = %s, .use_measured_inductance = %s,\n"
            "                      .use_measured_torque_constant = %s, .voltage_bias_level_fraction = %#.9gf,\n"
            "                      .identification_time_s = %#.9gf, .identification_min_speed_rad_s = %#.9gf,\n"
            "                      .use_identified_mechanics = %s},\n",
            (double)c->commissioning.offset_calibration_time_s,
            c->commissioning.alignment_offset_calibration ? "true" : "false",
            (double)c->commissioning.steady_state_window_s, (double)c->commissioning.inductance_window_s,
            c->commissioning.use_measured_resistance ? "true" : "false",
            c->commissioning.use_measured_inductance ? "true" : "false",
            c->commissioning.use_measured_torque_constant ? "true" : "false",
            (double)c->commissioning.voltage_bias_level_fraction, (double)c->commissioning.identification_time_s,
            (double)c->commissioning.identification_min_speed_rad_s,
            c->commissioning.use_identified_mechanics ? "true" : "false");
    fprintf(f,
            "    .inverter = {.dead_time_s = %#.9gf, .dead_time_current_band_A = %#.9gf,\n"
            "                 .phase_voltage_sensing = %s, .ripple_dead_zone = %s},\n",
            (double)c->inverter.dead_time_s, (double)c->inverter.dead_time_current_band_A,
            c->inverter.phase_voltage_sensing ? "true" : "false", c->inverter.ripple_dead_zone ? "true" : "false");
    fprintf(f,
            "    .detection = {.angle_magnitude_bound = %#.9gf, .speed_consistency_bound_rad_s = %#.9gf,\n"
            "                  .stall_speed_error_rad_s = %#.9gf, .observer_residual_bound_A = %#.9gf,\n"
            "                  .persistence_s = %#.9gf, .max_realignments = %uu},\n",
            (double)c->detection.angle_magnitude_bound, (double)c->detection.speed_consistency_bound_rad_s,
            (double)c->detection.stall_speed_error_rad_s, (double)c->detection.observer_residual_bound_A,
            (double)c->detection.persistence_s, (unsigned)c->detection.max_realignments);
    fprintf(f, "    .standstill = {.hold_current_A = %#.9gf, .vector_speed_rad_s = %#.9gf, .stops_only = %s},\n",
            (double)c->standstill.hold_current_A, (double)c->standstill.vector_speed_rad_s,
            c->standstill.stops_only ? "true" : "false");
    fprintf(f, "    .known_load_mode = false,\n};\n");
    if (fclose(f) != 0) {
        fprintf(stderr, "pmstep-tune: error writing %s\n", path);
        return -1;
    }
    return 0;
}
