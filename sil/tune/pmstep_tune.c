/* pmstep-tune: designs every controller setting for a motor preset (pmstep_design()), prints
 * the design, writes it as a scenario INI and as a C initialiser, and validates it in the SIL. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep/pmstep_design.h"
#include "pmstep/pmstep_text.h"
#include "sil/runner.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: pmstep-tune --motor FILE [--robust] [--set section.key=value]...\n"
            "                   [--write-ini FILE] [--write-c FILE] [--validate]\n"
            "                   [--told-inertia J] [--told-friction F] [--identify [--max-inertia-error PCT]]\n"
            "                   [--identify-in-run]\n"
            "  --motor      motor preset (sil/scenarios/motors/*.ini): [datasheet], [motor], run.bus_voltage_V;\n"
            "               run.period_s, run.delay_periods, [inverter] and [sensors] are the drive's\n"
            "  --robust     robust mode: Remark 2 calibration, commissioned R/L/k_M, drift-free angle,\n"
            "               dead-time compensation of inverter.dead_time_s\n"
            "  --set        override a key of the preset before designing (e.g. run.period_s=25e-6)\n"
            "  --write-ini  the whole scenario with the designed [controller.*] and a validation profile\n"
            "  --write-c    the design as a C99 initialiser of pmstep_config_t\n"
            "  --validate   run the design in the SIL: speed ramps to +-80 %% and +-5 %% of the top speed,\n"
            "               load steps of half the holding torque at 50 %% and 5 %% of it; exit 1 on a miss\n"
            "  --told-inertia, --told-friction  design for this J (kg m^2) / F (N m s/rad) in place of the\n"
            "               preset's; the plant keeps the preset's (a datasheet that is off)\n"
            "  --identify   run commissioning and the identification window in the SIL (ramps to +-80 %% of the\n"
            "               top speed), design again with the identified J and F, print both designs and the\n"
            "               errors against the plant; --validate then validates the second design\n"
            "  --max-inertia-error  with --identify: exit 1 unless J is identified within PCT %% of the plant's\n"
            "  --identify-in-run  the design asks the firmware to identify J and F in each run's first\n"
            "               window and use them (commissioning.use_identified_mechanics)\n");
}

/* Validation profile (DESIGN.md, section 7): hold, +0.8 top, -0.8 top, +0.05 top, -0.05 top, 0. */
#define PROFILE_HOLD_S 0.3
#define RAMP_ACCEL_FRACTION 0.2 /* of the rated acceleration k_M I / J */
#define MIN_RAMP_S 0.05
#define TRACKING_BOUND_OF_TOP 0.02
#define ANGLE_BOUND_RAD 0.05
#define LOAD_STEP_OF_HOLDING 0.5
#define SYNC_ANGLE_BOUND_RAD 0.5

static double ramp_time_s(const sil_scenario_t *sc, double speed_change_rad_s)
{
    const double accel = RAMP_ACCEL_FRACTION * sc->motor.torque_constant_Nm_A * sc->datasheet.rated_current_A
                         / sc->motor.inertia_kgm2;
    const double t = fabs(speed_change_rad_s) / accel;
    return t > MIN_RAMP_S ? t : MIN_RAMP_S;
}

static void add_point(sil_scenario_t *sc, double t_s, double speed_rad_s)
{
    sc->speed_time_s[sc->speed_points] = t_s;
    sc->speed_value_rad_s[sc->speed_points] = speed_rad_s;
    sc->speed_points++;
}

/* A speed profile through @p levels (each held PROFILE_HOLD_S), starting 0.1 s after t_c. */
static void set_profile(sil_scenario_t *sc, const double *levels, int n_levels)
{
    double t = (double)sc->controller.alignment.c_align_time_s
               + (double)sc->controller.commissioning.offset_calibration_time_s;
    double speed = 0.0;
    int k;
    sc->speed_points = 0;
    add_point(sc, 0.0, 0.0);
    t += 0.1;
    add_point(sc, t, 0.0);
    for (k = 0; k < n_levels; ++k) {
        t += ramp_time_s(sc, levels[k] - speed);
        add_point(sc, t, levels[k]);
        t += PROFILE_HOLD_S;
        add_point(sc, t, levels[k]);
        speed = levels[k];
    }
    sc->duration_s = t;
}

static void print_design(const sil_scenario_t *sc, const pmstep_design_report_t *r, bool robust)
{
    const pmstep_config_t *c = &sc->controller;
    printf("pmstep-tune: %s, %s mode, T_s = %g s, delay %u\n", sc->name, robust ? "robust" : "paper",
           (double)c->timing.period_s, (unsigned)c->timing.computational_delay_periods);
    printf("  top speed at the bus (rated current, 90 %% of %g V): %.1f rad/s (%.0f rpm), p w T_s = %.3f rad\n",
           sc->bus_voltage_V, (double)r->top_speed_rad_s, (double)r->top_speed_rad_s * 60.0 / (2.0 * M_PI),
           (double)r->top_electrical_step_rad);
    printf("  bandwidths: current %.0f rad/s, observer %.0f rad/s (triple pole), speed %.0f rad/s\n",
           (double)r->current_bandwidth_rad_s, (double)r->observer_bandwidth_rad_s,
           (double)r->speed_bandwidth_rad_s);
    printf("  gains: k_w %g, K_e %g, K_i %g, K_I %g, gamma %g, lambda %g, r %g, kappa %g rad/s, varpi_0 %g rad/s, "
           "g %g 1/s\n",
           (double)c->gains.speed_gain_per_s, (double)c->gains.observer_gain_per_s,
           (double)c->gains.current_gain_per_s, (double)c->gains.current_integral_gain_per_s2,
           (double)c->gains.adapt_gamma, (double)c->gains.adapt_lambda,
           (double)c->gains.adapt_r, (double)c->gains.sat_kappa_rad_s, (double)c->gains.reference_bandwidth_rad_s,
           (double)c->gains.angle_correction_gain_per_s);
    printf("  detent torque compensated: %g Nm\n", (double)c->motor.detent_torque_Nm);
    printf("  alignment: %.3f A (u = %.3f V), t_s %.2f s, t_c %.2f s; swing %.0f rad/s, damping %.2f; "
           "condition (4) holds %.2fx over\n",
           (double)r->alignment_current_A, (double)c->alignment.s_align_voltage_V,
           (double)c->alignment.s_align_time_s, (double)c->alignment.c_align_time_s,
           (double)r->alignment_frequency_rad_s, (double)r->alignment_damping, (double)r->condition_4_margin);
    printf("  trips: %.2f A, bus %.1f..%.1f V; detection: stall/consistency %.2f rad/s, residual %.3f A, %.3f s\n",
           (double)c->limits.max_phase_current_A, (double)c->limits.min_bus_voltage_V,
           (double)c->limits.max_bus_voltage_V, (double)c->detection.stall_speed_error_rad_s,
           (double)c->detection.observer_residual_bound_A, (double)c->detection.persistence_s);
    if (robust) {
        printf("  commissioning: offsets %.3f s, windows %.3f s, L window %.5f s, bias level %.2f, "
               "dead time %g s (band %g A), i_d* %.3f A; RUN uses the measured R%s\n",
               (double)c->commissioning.offset_calibration_time_s, (double)c->commissioning.steady_state_window_s,
               (double)c->commissioning.inductance_window_s, (double)c->commissioning.voltage_bias_level_fraction,
               (double)c->inverter.dead_time_s, (double)c->inverter.dead_time_current_band_A,
               (double)r->magnetising_current_A,
               c->commissioning.use_measured_inductance ? ", L and k_M"
                                                        : " (L, k_M from the datasheet: the rotor swings within the L window)");
    }
}

static int write_c(const char *path, const sil_scenario_t *sc)
{
    const pmstep_config_t *c = &sc->controller;
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "pmstep-tune: cannot write %s\n", path);
        return -1;
    }
    fprintf(f, "/* Designed by pmstep-tune for %s (firmware/design/DESIGN.md). */\n", sc->name);
    fprintf(f, "#include \"pmstep/pmstep.h\"\n\nconst pmstep_config_t pmstep_designed_config = {\n");
    fprintf(f, "    .motor = {.resistance_Ohm = %.9gf, .inductance_H = %.9gf, .inertia_kgm2 = %.9gf,\n"
               "              .friction_Nms_rad = %.9gf, .torque_constant_Nm_A = %.9gf, .pole_pairs = %d,\n"
               "              .detent_torque_Nm = %.9gf},\n",
            (double)c->motor.resistance_Ohm, (double)c->motor.inductance_H, (double)c->motor.inertia_kgm2,
            (double)c->motor.friction_Nms_rad, (double)c->motor.torque_constant_Nm_A, (int)c->motor.pole_pairs,
            (double)c->motor.detent_torque_Nm);
    fprintf(f, "    .timing = {.period_s = %.9gf, .computational_delay_periods = %uu},\n", (double)c->timing.period_s,
            (unsigned)c->timing.computational_delay_periods);
    fprintf(f, "    .alignment = {.s_align_time_s = %.9gf, .c_align_time_s = %.9gf, .s_align_voltage_V = %.9gf,\n"
               "                  .c_align_voltage_V = %.9gf},\n",
            (double)c->alignment.s_align_time_s, (double)c->alignment.c_align_time_s,
            (double)c->alignment.s_align_voltage_V, (double)c->alignment.c_align_voltage_V);
    fprintf(f, "    .gains = {.speed_gain_per_s = %.9gf, .observer_gain_per_s = %.9gf, .current_gain_per_s = %.9gf,\n"
               "              .adapt_gamma = %.9gf, .adapt_lambda = %.9gf, .adapt_r = %.9gf, .sat_kappa_rad_s = %.9gf,\n"
               "              .reference_bandwidth_rad_s = %.9gf, .angle_correction_gain_per_s = %.9gf,\n"
               "              .current_integral_gain_per_s2 = %.9gf},\n",
            (double)c->gains.speed_gain_per_s, (double)c->gains.observer_gain_per_s,
            (double)c->gains.current_gain_per_s, (double)c->gains.adapt_gamma, (double)c->gains.adapt_lambda,
            (double)c->gains.adapt_r, (double)c->gains.sat_kappa_rad_s, (double)c->gains.reference_bandwidth_rad_s,
            (double)c->gains.angle_correction_gain_per_s, (double)c->gains.current_integral_gain_per_s2);
    fprintf(f, "    .limits = {.max_phase_current_A = %.9gf, .min_bus_voltage_V = %.9gf, .max_bus_voltage_V = %.9gf},\n",
            (double)c->limits.max_phase_current_A, (double)c->limits.min_bus_voltage_V,
            (double)c->limits.max_bus_voltage_V);
    fprintf(f, "    .commissioning = {.offset_calibration_time_s = %.9gf, .alignment_offset_calibration = %s,\n"
               "                      .steady_state_window_s = %.9gf, .inductance_window_s = %.9gf,\n"
               "                      .use_measured_resistance = %s, .use_measured_inductance = %s,\n"
               "                      .use_measured_torque_constant = %s, .voltage_bias_level_fraction = %.9gf,\n"
               "                      .identification_time_s = %.9gf, .identification_min_speed_rad_s = %.9gf,\n"
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
    fprintf(f, "    .inverter = {.dead_time_s = %.9gf, .dead_time_current_band_A = %.9gf},\n",
            (double)c->inverter.dead_time_s, (double)c->inverter.dead_time_current_band_A);
    fprintf(f, "    .detection = {.angle_magnitude_bound = %.9gf, .speed_consistency_bound_rad_s = %.9gf,\n"
               "                  .stall_speed_error_rad_s = %.9gf, .observer_residual_bound_A = %.9gf,\n"
               "                  .persistence_s = %.9gf, .max_realignments = %uu},\n",
            (double)c->detection.angle_magnitude_bound, (double)c->detection.speed_consistency_bound_rad_s,
            (double)c->detection.stall_speed_error_rad_s, (double)c->detection.observer_residual_bound_A,
            (double)c->detection.persistence_s, (unsigned)c->detection.max_realignments);
    fprintf(f, "    .known_load_mode = false,\n};\n");
    if (fclose(f) != 0) {
        fprintf(stderr, "pmstep-tune: error writing %s\n", path);
        return -1;
    }
    return 0;
}

/* After the load step: the largest |omega - omega*| and the last time it was above the bound. */
typedef struct {
    double from_s;
    double bound_rad_s;
    double max_error_rad_s;
    double last_above_s;
} load_watch_t;

static bool watch_load(const sil_sample_t *x, void *user)
{
    load_watch_t *w = (load_watch_t *)user;
    if (x->t_s >= w->from_s && x->out->mode == PMSTEP_MODE_RUN) {
        const double error = fabs(x->omega_rad_s - (double)x->out->speed_ref_rad_s);
        if (error > w->max_error_rad_s) {
            w->max_error_rad_s = error;
        }
        if (error > w->bound_rad_s) {
            w->last_above_s = x->t_s;
        }
    }
    return true;
}

static bool run_ok(const char *what, const sil_summary_t *s, int rc)
{
    if (rc != 0 || s->fault != PMSTEP_FAULT_NONE || s->final_mode != PMSTEP_MODE_RUN || s->nonfinite_seen) {
        printf("  %-34s FAIL: %s at %.3f s\n", what,
               rc != 0 ? "init refused" : pmstep_fault_str(s->fault), s->fault_time_s);
        return false;
    }
    return true;
}

/* @p max_inertia_error_pct >= 0: with identification in RUN, the first run must identify J
 * within that many percent of the plant's. */
static int validate(const sil_scenario_t *designed, double top_speed_rad_s, double max_inertia_error_pct)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    const double levels[] = {0.8 * top_speed_rad_s, -0.8 * top_speed_rad_s, 0.05 * top_speed_rad_s,
                             -0.05 * top_speed_rad_s, 0.0};
    const double tracking_bound = TRACKING_BOUND_OF_TOP * top_speed_rad_s;
    const double load_fractions[] = {0.5, 0.05};
    int failures = 0;
    int k;
    int rc;

    sc = *designed;
    set_profile(&sc, levels, 5);
    sc.load.kind = PLANT_LOAD_NONE;
    rc = sil_run(&sc, NULL, NULL, false, &s);
    if (run_ok("ramps to +-80 % and +-5 % of top", &s, rc)) {
        const bool pass = s.max_speed_error_after_settle_rad_s < tracking_bound
                          && s.max_angle_error_rad < ANGLE_BOUND_RAD;
        printf("  %-34s %s: |w - w*| %.3f rad/s (bound %.3f), angle error %.4f rad (bound %.2f)\n",
               "ramps to +-80 % and +-5 % of top", pass ? "pass" : "FAIL", s.max_speed_error_after_settle_rad_s,
               tracking_bound, s.max_angle_error_rad, ANGLE_BOUND_RAD);
        if (s.commissioning.identification != PMSTEP_IDENT_OFF) {
            const double j_error_pct = 100.0 * ((double)s.commissioning.inertia_kgm2 / sc.motor.inertia_kgm2 - 1.0);
            const bool used = s.commissioning.identification == PMSTEP_IDENT_DONE
                              || s.commissioning.identification == PMSTEP_IDENT_FRICTION_NEGATIVE;
            const bool ident_pass = max_inertia_error_pct < 0.0
                                    || (used && fabs(j_error_pct) <= max_inertia_error_pct);
            printf("  %-34s %s: %s, J %.4g kg m^2 (%+.2f %% off the plant's), F %.4g N m s/rad\n", "identified in RUN",
                   ident_pass ? "pass" : "FAIL", pmstep_identification_str(s.commissioning.identification),
                   (double)s.commissioning.inertia_kgm2, j_error_pct, (double)s.commissioning.friction_Nms_rad);
            failures += ident_pass ? 0 : 1;
        }
        failures += pass ? 0 : 1;
    } else {
        ++failures;
    }
    for (k = 0; k < 2; ++k) {
        const double level = load_fractions[k] * top_speed_rad_s;
        const double step_Nm = LOAD_STEP_OF_HOLDING * sc.datasheet.holding_torque_Nm;
        load_watch_t watch;
        char what[64];
        set_profile(&sc, &level, 1);
        sc.load.kind = PLANT_LOAD_STEP;
        sc.load.torque_Nm = step_Nm;
        sc.load.step_time_s = sc.duration_s - 0.5 * PROFILE_HOLD_S;
        sc.duration_s += 0.5 * PROFILE_HOLD_S;
        watch.from_s = sc.load.step_time_s;
        watch.bound_rad_s = tracking_bound;
        watch.max_error_rad_s = 0.0;
        watch.last_above_s = watch.from_s;
        snprintf(what, sizeof what, "%.2f Nm step at %.0f %% of top", step_Nm, 100.0 * load_fractions[k]);
        rc = sil_run(&sc, watch_load, &watch, false, &s);
        if (run_ok(what, &s, rc)) {
            const bool pass = s.max_angle_error_rad < SYNC_ANGLE_BOUND_RAD;
            printf("  %-34s %s: dip %.2f rad/s, back within %.3f rad/s after %.1f ms, angle error %.4f rad\n", what,
                   pass ? "pass" : "FAIL", watch.max_error_rad_s, tracking_bound,
                   1e3 * (watch.last_above_s - watch.from_s), s.max_angle_error_rad);
            failures += pass ? 0 : 1;
        } else {
            ++failures;
        }
    }
    printf("pmstep-tune: validation %s (%d miss%s)\n", failures == 0 ? "passed" : "FAILED", failures,
           failures == 1 ? "" : "es");
    return failures == 0 ? 0 : 1;
}

/* The designer's input for the motor the drive is told: the preset's [motor], J and F overridable. */
static void design_input(const sil_scenario_t *sc, bool robust, pmstep_design_input_t *in)
{
    memset(in, 0, sizeof *in);
    in->motor.resistance_Ohm = (float)sc->motor.resistance_Ohm;
    in->motor.inductance_H = (float)sc->motor.inductance_H;
    in->motor.inertia_kgm2 = (float)sc->motor.inertia_kgm2;
    in->motor.friction_Nms_rad = (float)sc->motor.friction_Nms_rad;
    in->motor.torque_constant_Nm_A = (float)sc->motor.torque_constant_Nm_A;
    in->motor.pole_pairs = (int32_t)sc->motor.pole_pairs;
    in->motor.detent_torque_Nm = (float)sc->datasheet.detent_torque_Nm; /* the law compensates the datasheet's */
    in->rated_current_A = (float)sc->datasheet.rated_current_A;
    in->bus_voltage_V = (float)sc->bus_voltage_V;
    in->period_s = sc->controller.timing.period_s;
    in->computational_delay_periods = sc->controller.timing.computational_delay_periods;
    in->self_commissioning = robust;
    in->dead_time_s = (float)sc->inverter.dead_time_s;
    {
        const double step_A = sc->sensors.adc_bits > 0 ? 2.0 * sc->sensors.current_full_scale_A
                                                             / (double)(1L << sc->sensors.adc_bits)
                                                       : 0.0;
        in->current_resolution_A = (float)(step_A > sc->sensors.noise_rms_A ? step_A : sc->sensors.noise_rms_A);
    }
}

/* Identification window over the profile +0.8 top, -0.8 top (each held), from t_c; the lowest
 * speed that enters the fit is the designer's (DESIGN.md, section 10). */
static void set_identification(sil_scenario_t *sc, double top_speed_rad_s, bool use_in_run)
{
    const double levels[] = {0.8 * top_speed_rad_s, -0.8 * top_speed_rad_s};
    const double t_c = (double)sc->controller.alignment.c_align_time_s
                       + (double)sc->controller.commissioning.offset_calibration_time_s;
    set_profile(sc, levels, 2);
    sc->controller.commissioning.identification_time_s = (float)(sc->duration_s - t_c);
    sc->controller.commissioning.use_identified_mechanics = use_in_run;
}

/* --identify: commissioning and the identification window in the SIL with the first design.
 * @return 0 and the identified J, F in @p result; 1 when the run faulted or identified nothing. */
static int identify(const sil_scenario_t *designed, double top_speed_rad_s, pmstep_commissioning_t *result)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    int rc;
    sc = *designed;
    set_identification(&sc, top_speed_rad_s, false);
    sc.duration_s += 0.01; /* the window closes on a sample, up to PMSTEP_IDENTIFICATION_DECIMATION periods late */
    sc.load.kind = PLANT_LOAD_NONE;
    rc = sil_run(&sc, NULL, NULL, false, &s);
    if (!run_ok("identification run", &s, rc)) {
        return 1;
    }
    *result = s.commissioning;
    printf("pmstep-tune: identification over %.3f s from t_c (|w*| >= %.1f rad/s): %s\n",
           (double)sc.controller.commissioning.identification_time_s,
           (double)sc.controller.commissioning.identification_min_speed_rad_s,
           pmstep_identification_str(result->identification));
    return result->identification == PMSTEP_IDENT_DONE || result->identification == PMSTEP_IDENT_FRICTION_NEGATIVE
               ? 0
               : 1;
}

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    pmstep_design_input_t in;
    pmstep_design_report_t report;
    pmstep_status_t status;
    const char *motor_path = NULL;
    const char *ini_path = NULL;
    const char *c_path = NULL;
    bool robust = false;
    bool run_validation = false;
    bool run_identification = false;
    bool identify_in_run = false;
    double told_inertia = -1.0;
    double told_friction = -1.0;
    double max_inertia_error_pct = -1.0;
    char err[SIL_ERROR_MAX];
    int k;

    sil_scenario_paper(&sc);
    for (k = 1; k < argc; ++k) {
        if (strcmp(argv[k], "--motor") == 0 && k + 1 < argc) {
            motor_path = argv[++k];
            if (sil_scenario_load(&sc, motor_path, err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-tune: %s\n", err);
                return 2;
            }
        } else if (strcmp(argv[k], "--set") == 0 && k + 1 < argc) {
            if (sil_scenario_set_assignment(&sc, argv[++k], err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-tune: %s\n", err);
                return 2;
            }
        } else if (strcmp(argv[k], "--robust") == 0) {
            robust = true;
        } else if (strcmp(argv[k], "--write-ini") == 0 && k + 1 < argc) {
            ini_path = argv[++k];
        } else if (strcmp(argv[k], "--write-c") == 0 && k + 1 < argc) {
            c_path = argv[++k];
        } else if (strcmp(argv[k], "--validate") == 0) {
            run_validation = true;
        } else if (strcmp(argv[k], "--identify") == 0) {
            run_identification = true;
        } else if (strcmp(argv[k], "--identify-in-run") == 0) {
            identify_in_run = true;
        } else if ((strcmp(argv[k], "--told-inertia") == 0 || strcmp(argv[k], "--told-friction") == 0
                    || strcmp(argv[k], "--max-inertia-error") == 0)
                   && k + 1 < argc) {
            char *end = NULL;
            const char *name = argv[k];
            const double value = strtod(argv[++k], &end);
            if (end == argv[k] || *end != '\0' || !isfinite(value) || value < 0.0) {
                fprintf(stderr, "pmstep-tune: %s needs a finite number >= 0, not '%s'\n", name, argv[k]);
                return 2;
            }
            if (strcmp(name, "--told-inertia") == 0) {
                told_inertia = value;
            } else if (strcmp(name, "--told-friction") == 0) {
                told_friction = value;
            } else {
                max_inertia_error_pct = value;
            }
        } else if (strcmp(argv[k], "--help") == 0) {
            usage(stdout);
            return 0;
        } else {
            usage(stderr);
            return 2;
        }
    }
    if (motor_path == NULL) {
        usage(stderr);
        return 2;
    }

    /* The drive is told the datasheet's motor: the preset's [motor], J and F as --told-* say. */
    design_input(&sc, robust, &in);
    if (told_inertia >= 0.0) {
        in.motor.inertia_kgm2 = (float)told_inertia;
    }
    if (told_friction >= 0.0) {
        in.motor.friction_Nms_rad = (float)told_friction;
    }
    status = pmstep_design(&in, &sc.controller, &report);
    if (status != PMSTEP_OK) {
        fprintf(stderr, "pmstep-tune: %s: cannot design: %s (%d)\n", motor_path, pmstep_status_str(status),
                (int)status);
        return 1;
    }
    sc.id_target_A = (double)report.magnetising_current_A;
    (void)pmstep_position_design(&sc.controller, &sc.position); /* position loop (DESIGN.md section 11) */
    {
        const double top = (double)report.top_speed_rad_s;
        const double levels[] = {0.8 * top, -0.8 * top, 0.05 * top, -0.05 * top, 0.0};
        set_profile(&sc, levels, 5);
    }
    sc.load.kind = PLANT_LOAD_NONE;
    print_design(&sc, &report, robust);
    if (run_identification) {
        pmstep_commissioning_t ident;
        const double j_plant = sc.motor.inertia_kgm2;
        const double f_plant = sc.motor.friction_Nms_rad;
        double j_error_pct;
        if (identify(&sc, (double)report.top_speed_rad_s, &ident) != 0) {
            return 1;
        }
        j_error_pct = 100.0 * ((double)ident.inertia_kgm2 / j_plant - 1.0);
        printf("  told:       J %.4g kg m^2 (%+.1f %% off the plant's %.4g), F %.4g N m s/rad (plant %.4g)\n",
               (double)in.motor.inertia_kgm2, 100.0 * ((double)in.motor.inertia_kgm2 / j_plant - 1.0), j_plant,
               (double)in.motor.friction_Nms_rad, f_plant);
        printf("  identified: J %.4g kg m^2 (%+.2f %% off the plant's), F %.4g N m s/rad (%+.3g off the plant's)\n",
               (double)ident.inertia_kgm2, j_error_pct, (double)ident.friction_Nms_rad,
               (double)ident.friction_Nms_rad - f_plant);
        in.motor.inertia_kgm2 = ident.inertia_kgm2;
        in.motor.friction_Nms_rad = ident.friction_Nms_rad > 0.0f ? ident.friction_Nms_rad : 0.0f;
        status = pmstep_design(&in, &sc.controller, &report);
        if (status != PMSTEP_OK) {
            fprintf(stderr, "pmstep-tune: cannot design for the identified J, F: %s (%d)\n",
                    pmstep_status_str(status), (int)status);
            return 1;
        }
        printf("pmstep-tune: design for the identified J and F\n");
        {
            const double top = (double)report.top_speed_rad_s;
            const double levels[] = {0.8 * top, -0.8 * top, 0.05 * top, -0.05 * top, 0.0};
            set_profile(&sc, levels, 5);
        }
        print_design(&sc, &report, robust);
        if (max_inertia_error_pct >= 0.0 && !(fabs(j_error_pct) <= max_inertia_error_pct)) {
            printf("pmstep-tune: identified J %+.2f %% off the plant's: over the %.1f %% bound\n", j_error_pct,
                   max_inertia_error_pct);
            return 1;
        }
    }
    if (identify_in_run) {
        /* The firmware identifies over the window of the ramps to +-0.8 top, and uses J and F. */
        static sil_scenario_t window;
        window = sc;
        set_identification(&window, (double)report.top_speed_rad_s, true);
        sc.controller.commissioning.identification_time_s = window.controller.commissioning.identification_time_s;
        sc.controller.commissioning.identification_min_speed_rad_s =
            window.controller.commissioning.identification_min_speed_rad_s;
        sc.controller.commissioning.use_identified_mechanics = true;
        printf("  identification in RUN: %.3f s from t_c, |w*| >= %.1f rad/s, identified J and F used\n",
               (double)sc.controller.commissioning.identification_time_s,
               (double)sc.controller.commissioning.identification_min_speed_rad_s);
    }
    printf("  position loop: k_theta %g 1/s, k_I %g 1/s^2\n", (double)sc.position.gain_per_s,
           (double)sc.position.integral_gain_per_s2);
    if (ini_path != NULL) {
        FILE *f = fopen(ini_path, "w");
        if (f == NULL) {
            fprintf(stderr, "pmstep-tune: cannot write %s\n", ini_path);
            return 2;
        }
        fprintf(f, "; Designed by pmstep-tune from %s%s (firmware/design/DESIGN.md).\n", motor_path,
                robust ? " --robust" : "");
        sil_scenario_print(&sc, f);
        if (fclose(f) != 0) {
            fprintf(stderr, "pmstep-tune: error writing %s\n", ini_path);
            return 2;
        }
        printf("pmstep-tune: wrote %s\n", ini_path);
    }
    if (c_path != NULL) {
        if (write_c(c_path, &sc) != 0) {
            return 2;
        }
        printf("pmstep-tune: wrote %s\n", c_path);
    }
    return run_validation ? validate(&sc, (double)report.top_speed_rad_s, max_inertia_error_pct) : 0;
}
